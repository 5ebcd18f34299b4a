//! Headless pictures (SPEC §8): a software rasterizer for shaded meshes (no GPU) with
//! surface-quality views (zebra, isophotes, curvature maps), text captions, image strips,
//! and 2D plots.

mod image;
mod plot;
mod raster;
mod text;
mod view;

pub use image::Image;
pub use plot::{Layer, Series, line_plot, polyline_plot};
pub use raster::{Camera, Paint, RenderItem, render};
pub use text::draw_text;
pub use view::{View, abs_quantile, diverging, draw_legend};

/// Colours for patches, cycled.
pub const PALETTE: [[f32; 3]; 8] = [
    [0.42, 0.62, 0.86],
    [0.90, 0.58, 0.32],
    [0.48, 0.75, 0.48],
    [0.84, 0.45, 0.52],
    [0.62, 0.52, 0.82],
    [0.85, 0.78, 0.38],
    [0.40, 0.76, 0.78],
    [0.70, 0.70, 0.70],
];

/// The neutral colour of primary (context) surfaces.
pub const CONTEXT_COLOR: [f32; 3] = [0.80, 0.80, 0.78];

/// A perceptually ordered colour map (viridis, piecewise linear), `x ∈ [0, 1]`.
pub fn colormap(x: f64) -> [f32; 3] {
    const C: [[f32; 3]; 6] = [
        [0.267, 0.005, 0.329],
        [0.254, 0.265, 0.530],
        [0.164, 0.471, 0.558],
        [0.135, 0.659, 0.518],
        [0.478, 0.821, 0.319],
        [0.993, 0.906, 0.144],
    ];
    let x = if x.is_finite() { x.clamp(0.0, 1.0) } else { 0.0 } * 5.0;
    let i = (x.floor() as usize).min(4);
    let f = (x - i as f64) as f32;
    std::array::from_fn(|k| C[i][k] * (1.0 - f) + C[i + 1][k] * f)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plots_and_text_draw_pixels() {
        let s = Series { label: "error".into(), points: (1..8).map(|k| (k as f64, 10f64.powi(-k))).collect() };
        let img = line_plot("convergence", "M", "error", &[s], true, (400, 300)).unwrap();
        let dark = img.data.chunks(4).filter(|p| p[0] < 100).count();
        assert!(dark > 500, "the plot draws axes, labels and a line ({dark} dark pixels)");
        let mut im = Image::new(200, 40, [255, 255, 255]);
        let w = draw_text(&mut im, 2.0, 2.0, 20.0, "C1 gap 1e-12", [0, 0, 0]);
        assert!(w > 50.0);
        assert!(im.data.chunks(4).any(|p| p[0] < 50));
    }
}
