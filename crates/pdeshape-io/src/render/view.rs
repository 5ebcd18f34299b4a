//! Surface-quality views: zebra stripes, isophotes and curvature maps (a diverging colour
//! scale centred at zero with a legend).
//!
//! **Zebra (reflection lines).** The environment is a set of parallel light tubes along an
//! axis `a` in the screen plane (`a = right cos α + up sin α`, `α` the stripe angle): a
//! direction `r` sees tube number `⌊φ(r) · n / π⌋` where `φ = atan2(r·b, r·w)` is the angle
//! of `r` about `a` (`w` towards the viewer, `b = w × a`). A pixel shows the tube its view
//! ray reflects to, `r = d − 2 (d·n) n` with `d` the view direction and `n` the exact
//! normal interpolated over the triangle, black for even and white for odd tube numbers.
//! The stripes depend on the normal only: across a seam with a position gap they jump,
//! with a G1 kink (C0 only) they break at an angle, with a curvature jump (G1 but not G2)
//! they are continuous but kinked, and they run smoothly across a G2 seam.
//!
//! **Isophotes.** Bands of equal illumination `n·l` (`l` the key light): `⌊acos(n·l) · n / π⌋`
//! alternates between the shaded colour and a darker one.

use super::Image;
use pdeshape_core::patch::CurvatureKind;
use std::str::FromStr;

/// What the renderer shows on a surface.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum View {
    /// Smooth shading (the default).
    #[default]
    Shaded,
    /// Reflection lines of parallel light tubes (see the module).
    Zebra,
    /// Bands of equal illumination.
    Isophotes,
    /// A curvature map on a diverging colour scale.
    Curvature(CurvatureKind),
}

impl View {
    /// Every view with its command-line name.
    pub const NAMES: [(&'static str, View); 7] = [
        ("shaded", View::Shaded),
        ("zebra", View::Zebra),
        ("isophotes", View::Isophotes),
        ("gauss", View::Curvature(CurvatureKind::Gauss)),
        ("mean", View::Curvature(CurvatureKind::Mean)),
        ("k1", View::Curvature(CurvatureKind::K1)),
        ("k2", View::Curvature(CurvatureKind::K2)),
    ];

    /// The command-line name.
    pub fn name(self) -> &'static str {
        View::NAMES.iter().find(|(_, v)| *v == self).map_or("shaded", |(n, _)| n)
    }

    /// The curvature this view needs as a mesh field.
    pub fn curvature(self) -> Option<CurvatureKind> {
        match self {
            View::Curvature(k) => Some(k),
            _ => None,
        }
    }
}

impl FromStr for View {
    type Err = String;
    fn from_str(s: &str) -> Result<View, String> {
        View::NAMES.iter().find(|(n, _)| *n == s).map(|(_, v)| *v).ok_or_else(|| {
            let names: Vec<&str> = View::NAMES.iter().map(|(n, _)| *n).collect();
            format!("unknown view `{s}` (one of: {})", names.join(", "))
        })
    }
}

/// A diverging colour map (blue – light grey – red, after Moreland's "cool to warm"),
/// `x ∈ [−1, 1]`, 0 at the neutral centre; NaN maps to magenta so it cannot hide.
pub fn diverging(x: f64) -> [f32; 3] {
    const C: [[f32; 3]; 5] = [
        [0.230, 0.299, 0.754],
        [0.552, 0.690, 0.996],
        [0.865, 0.865, 0.865],
        [0.958, 0.604, 0.482],
        [0.706, 0.016, 0.150],
    ];
    if x.is_nan() {
        return [1.0, 0.0, 1.0];
    }
    let t = (x.clamp(-1.0, 1.0) + 1.0) * 2.0;
    let i = (t.floor() as usize).min(3);
    let f = (t - i as f64) as f32;
    std::array::from_fn(|k| C[i][k] * (1.0 - f) + C[i + 1][k] * f)
}

/// The `q`-quantile (`0 ≤ q ≤ 1`) of `|x|` over finite values; NaN when there are none.
pub fn abs_quantile(values: impl Iterator<Item = f64>, q: f64) -> f64 {
    let mut a: Vec<f64> = values.filter(|x| x.is_finite()).map(f64::abs).collect();
    if a.is_empty() {
        return f64::NAN;
    }
    let k = ((a.len() - 1) as f64 * q.clamp(0.0, 1.0)).round() as usize;
    *a.select_nth_unstable_by(k, f64::total_cmp).1
}

/// Draws a horizontal legend for the diverging scale `[−limit, limit]` into the bottom of
/// `img`: the bar, the title, and the numbers at both ends and the centre.
pub fn draw_legend(img: &mut Image, title: &str, limit: f64) {
    let (w, h) = (img.width as i64, img.height as i64);
    let bar_w = (w * 6 / 10).max(40);
    let (x0, y0, bar_h) = ((w - bar_w) / 2, h - 46, 12);
    for x in 0..bar_w {
        let c = diverging(2.0 * x as f64 / (bar_w - 1).max(1) as f64 - 1.0).map(|c| (c * 255.0).round() as u8);
        img.fill_rect(x0 + x, y0, 1, bar_h, c);
    }
    let size = 15.0;
    let ink = [30, 30, 40];
    let lo = format!("{:.3e}", -limit);
    let hi = format!("{:.3e}", limit);
    super::draw_text(img, x0 as f32, (y0 + bar_h + 3) as f32, size, &lo, ink);
    super::draw_text(img, (x0 + bar_w / 2 - 4) as f32, (y0 + bar_h + 3) as f32, size, "0", ink);
    let wid = hi.len() as f32 * size * 0.55;
    super::draw_text(img, (x0 + bar_w) as f32 - wid, (y0 + bar_h + 3) as f32, size, &hi, ink);
    super::draw_text(img, x0 as f32, (y0 - 19) as f32, size, title, ink);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_and_unknown_views_are_errors() {
        for (n, v) in View::NAMES {
            assert_eq!(n.parse::<View>().unwrap(), v);
            assert_eq!(v.name(), n);
        }
        let e = "stripes".parse::<View>().unwrap_err();
        assert!(e.contains("unknown view `stripes`") && e.contains("zebra, isophotes, gauss"), "{e}");
    }

    #[test]
    fn diverging_scale_is_neutral_at_zero_and_ordered() {
        assert_eq!(diverging(0.0), [0.865, 0.865, 0.865]);
        assert_eq!(diverging(-1.0), [0.230, 0.299, 0.754]);
        assert_eq!(diverging(5.0), diverging(1.0));
        assert_eq!(diverging(f64::NAN), [1.0, 0.0, 1.0]);
        // negative values are blue (b > r), positive ones red (r > b), symmetric in distance
        // from the neutral centre
        for k in 1..=20 {
            let x = k as f64 / 20.0;
            let (n, p) = (diverging(-x), diverging(x));
            assert!(n[2] > n[0] && p[0] > p[2], "{x}: {n:?} {p:?}");
            let dist = |c: [f32; 3]| c.iter().map(|v| (v - 0.865).abs()).sum::<f32>();
            assert!(dist(n) > 0.0 && dist(p) > 0.0);
        }
    }

    #[test]
    fn quantiles_of_magnitudes() {
        let v = [-4.0, 1.0, f64::NAN, 2.0, -3.0, 0.0];
        assert_eq!(abs_quantile(v.iter().copied(), 1.0), 4.0);
        assert_eq!(abs_quantile(v.iter().copied(), 0.0), 0.0);
        assert_eq!(abs_quantile(v.iter().copied(), 0.5), 2.0);
        assert!(abs_quantile([f64::NAN].into_iter(), 0.9).is_nan());
    }
}
