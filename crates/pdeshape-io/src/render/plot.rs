//! 2D line plots (convergence studies, timings) drawn with `plotters`.

use super::Image;
use plotters::prelude::*;
use std::sync::Once;

/// One plotted line.
#[derive(Clone, Debug, PartialEq)]
pub struct Series {
    /// Legend label.
    pub label: String,
    /// Points `(x, y)`.
    pub points: Vec<(f64, f64)>,
}

fn register_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The bytes are 'static, so registration cannot fail for lifetime reasons; an
        // unparsable font would only lose the labels.
        let _ = plotters::style::register_font("sans-serif", FontStyle::Normal, epaint_default_fonts::UBUNTU_LIGHT);
    });
}

/// A line plot with markers; `log_y` plots `log10 y` (non-positive values are dropped).
pub fn line_plot(
    title: &str,
    xlabel: &str,
    ylabel: &str,
    series: &[Series],
    log_y: bool,
    size: (u32, u32),
) -> Result<Image, String> {
    register_font();
    let (w, h) = size;
    let mut buf = vec![255u8; (w * h * 3) as usize];
    let tr = |y: f64| if log_y { y.log10() } else { y };
    let pts: Vec<Vec<(f64, f64)>> = series
        .iter()
        .map(|s| {
            s.points
                .iter()
                .filter(|p| p.0.is_finite() && p.1.is_finite() && (!log_y || p.1 > 0.0))
                .map(|p| (p.0, tr(p.1)))
                .collect()
        })
        .collect();
    let all: Vec<&(f64, f64)> = pts.iter().flatten().collect();
    if all.is_empty() {
        return Err(format!("plot `{title}` has no finite points"));
    }
    let (mut x0, mut x1, mut y0, mut y1) =
        all.iter().fold((f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY), |a, p| {
            (a.0.min(p.0), a.1.max(p.0), a.2.min(p.1), a.3.max(p.1))
        });
    if x1 <= x0 {
        x0 -= 1.0;
        x1 += 1.0;
    }
    if y1 <= y0 {
        y0 -= 1.0;
        y1 += 1.0;
    }
    let pad = 0.05 * (y1 - y0);
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 22))
            .margin(12)
            .x_label_area_size(42)
            .y_label_area_size(64)
            .build_cartesian_2d(x0..x1, (y0 - pad)..(y1 + pad))
            .map_err(|e| e.to_string())?;
        let ylab = if log_y { format!("log10 {ylabel}") } else { ylabel.to_string() };
        chart
            .configure_mesh()
            .x_desc(xlabel)
            .y_desc(ylab)
            .label_style(("sans-serif", 15))
            .draw()
            .map_err(|e| e.to_string())?;
        for (k, (s, p)) in series.iter().zip(&pts).enumerate() {
            let c = super::PALETTE[k % super::PALETTE.len()];
            let col = RGBColor((c[0] * 200.0) as u8, (c[1] * 200.0) as u8, (c[2] * 200.0) as u8);
            chart
                .draw_series(LineSeries::new(p.iter().copied(), col.stroke_width(2)))
                .map_err(|e| e.to_string())?
                .label(s.label.clone())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], col.stroke_width(2)));
            chart.draw_series(p.iter().map(|q| Circle::new(*q, 3, col.filled()))).map_err(|e| e.to_string())?;
        }
        chart
            .configure_series_labels()
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .label_font(("sans-serif", 15))
            .draw()
            .map_err(|e| e.to_string())?;
        root.present().map_err(|e| e.to_string())?;
    }
    Ok(to_image(&buf, w, h))
}

/// A layer of polylines for [`polyline_plot`]: lines, colour, stroke width.
pub struct Layer {
    /// Polylines.
    pub lines: Vec<Vec<(f64, f64)>>,
    /// Colour.
    pub rgb: [u8; 3],
    /// Stroke width in pixels.
    pub width: u32,
    /// Legend label (none when empty).
    pub label: String,
}

/// Polylines in a fixed rectangle `x0..x1 × y0..y1`, drawn in layer order (a parameter
/// space picture).
pub fn polyline_plot(
    title: &str,
    labels: (&str, &str),
    range: ((f64, f64), (f64, f64)),
    layers: &[Layer],
    size: (u32, u32),
) -> Result<Image, String> {
    register_font();
    let (w, h) = size;
    let mut buf = vec![255u8; (w * h * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, (w, h)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| e.to_string())?;
        let ((x0, x1), (y0, y1)) = range;
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 20))
            .margin(12)
            .x_label_area_size(36)
            .y_label_area_size(48)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(|e| e.to_string())?;
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc(labels.0)
            .y_desc(labels.1)
            .label_style(("sans-serif", 15))
            .draw()
            .map_err(|e| e.to_string())?;
        let mut legend = false;
        for l in layers {
            let col = RGBColor(l.rgb[0], l.rgb[1], l.rgb[2]);
            let style = col.stroke_width(l.width);
            let mut first = true;
            for line in &l.lines {
                let a = chart.draw_series(LineSeries::new(line.iter().copied(), style)).map_err(|e| e.to_string())?;
                if first && !l.label.is_empty() {
                    a.label(l.label.clone()).legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], style));
                    legend = true;
                }
                first = false;
            }
        }
        if legend {
            chart
                .configure_series_labels()
                .background_style(WHITE.mix(0.85))
                .border_style(BLACK)
                .label_font(("sans-serif", 14))
                .draw()
                .map_err(|e| e.to_string())?;
        }
        root.present().map_err(|e| e.to_string())?;
    }
    Ok(to_image(&buf, w, h))
}

/// An RGB buffer as an image.
fn to_image(buf: &[u8], w: u32, h: u32) -> Image {
    let mut img = Image::new(w, h, [255, 255, 255]);
    for (i, px) in buf.chunks(3).enumerate() {
        img.data[4 * i..4 * i + 3].copy_from_slice(px);
    }
    img
}
