//! Closed trim curves in the `(u, v)` parameter domain: ellipses, closed cubic B-splines
//! and polygons, all parameterised by `t ∈ [0, 2π)` with exact derivatives.

use crate::Vec3;
use crate::data::{BSplineCurve, BSplineError};
use std::f64::consts::TAU;

/// A point of the parameter domain `(u, v)`.
pub type Uv = [f64; 2];

/// A closed curve in the `(u, v)` parameter domain, `C(t)`, `t ∈ [0, 2π)`, periodic.
///
/// - an ellipse `C(t) = c + (r_u cos t, r_v sin t)` (a circle when `r_u = r_v`);
/// - a closed uniform cubic B-spline through its control polygon (C² everywhere);
/// - a polygon (the closed degree-1 B-spline: each edge gets `2π/n` of the parameter).
///
/// ```
/// use pdeshape_core::trim::TrimCurve;
/// let c = TrimCurve::ellipse([0.5, 0.5], [0.2, 0.1]);
/// let d = c.derivatives(0.0, 1);
/// assert!((d[0][0] - 0.7).abs() < 1e-15 && (d[1][1] - 0.1).abs() < 1e-15);
/// ```
#[derive(Clone, Debug)]
pub enum TrimCurve {
    /// `c + (r_u cos t, r_v sin t)`.
    Ellipse {
        /// Centre.
        center: Uv,
        /// Semi-axes along `u` and `v`.
        radii: Uv,
    },
    /// A closed uniform B-spline (degree 3) or polygon (degree 1), stored with `z = 0`.
    Spline(BSplineCurve),
}

impl TrimCurve {
    /// An axis-aligned ellipse.
    pub fn ellipse(center: Uv, radii: Uv) -> Self {
        TrimCurve::Ellipse { center, radii }
    }

    /// A closed uniform cubic B-spline with the given control points (≥ 4).
    pub fn bspline(control: &[Uv]) -> Result<Self, BSplineError> {
        Self::spline(control, 3)
    }

    /// A closed polygon with the given vertices (≥ 3).
    pub fn polygon(vertices: &[Uv]) -> Result<Self, BSplineError> {
        Self::spline(vertices, 1)
    }

    fn spline(p: &[Uv], degree: usize) -> Result<Self, BSplineError> {
        let pts = p.iter().map(|q| Vec3::new(q[0], q[1], 0.0)).collect();
        Ok(TrimCurve::Spline(BSplineCurve::new(pts, degree, true, (0.0, TAU))?))
    }

    /// The curve with `u` and `v` multiplied by `k[0]` and `k[1]` (an affine image: the
    /// ellipse's centre and radii, the spline's control points).
    pub fn scaled(&self, k: Uv) -> Self {
        match self {
            TrimCurve::Ellipse { center, radii } => TrimCurve::Ellipse {
                center: [center[0] * k[0], center[1] * k[1]],
                radii: [radii[0] * k[0], radii[1] * k[1]],
            },
            TrimCurve::Spline(b) => {
                let pts = b.points().iter().map(|p| Vec3::new(p.x * k[0], p.y * k[1], 0.0)).collect();
                TrimCurve::Spline(
                    BSplineCurve::new(pts, b.degree(), true, b.range()).expect("scaling keeps a valid spline valid"),
                )
            }
        }
    }

    /// `C⁽ᵏ⁾(t)` for `k = 0 … nd` (exact).
    pub fn derivatives(&self, t: f64, nd: usize) -> Vec<Uv> {
        match self {
            TrimCurve::Ellipse { center, radii } => (0..=nd)
                .map(|k| {
                    let phase = t + k as f64 * std::f64::consts::FRAC_PI_2;
                    let c0 = if k == 0 { center[0] } else { 0.0 };
                    let c1 = if k == 0 { center[1] } else { 0.0 };
                    [c0 + radii[0] * phase.cos(), c1 + radii[1] * phase.sin()]
                })
                .collect(),
            TrimCurve::Spline(b) => b.derivatives(t, nd).into_iter().map(|p| [p.x, p.y]).collect(),
        }
    }

    /// `C(t)`.
    pub fn point(&self, t: f64) -> Uv {
        match self {
            TrimCurve::Ellipse { center, radii } => [center[0] + radii[0] * t.cos(), center[1] + radii[1] * t.sin()],
            TrimCurve::Spline(b) => {
                let p = b.derivatives(t, 0)[0];
                [p.x, p.y]
            }
        }
    }

    /// The closest point of the curve to `p`: `(t, distance)`. A polygon is measured
    /// exactly, edge by edge (it is linear in `t` between its vertices); a smooth curve by
    /// a search over a fine polygonisation refined by Newton's method on
    /// `(C(t) − p)·C'(t) = 0` (exact derivatives), never returning a worse point than the
    /// search found.
    pub fn closest(&self, p: Uv) -> (f64, f64) {
        let d2 = |q: Uv| (q[0] - p[0]).powi(2) + (q[1] - p[1]).powi(2);
        if let TrimCurve::Spline(b) = self
            && b.degree() == 1
        {
            let v = self.polygonize(1);
            let n = v.len();
            return (0..n)
                .map(|i| {
                    let (a, c) = (v[i].1, v[(i + 1) % n].1);
                    let e = sub(c, a);
                    let l2 = e[0] * e[0] + e[1] * e[1];
                    let r = sub(p, a);
                    let s = if l2 > 0.0 { ((r[0] * e[0] + r[1] * e[1]) / l2).clamp(0.0, 1.0) } else { 0.0 };
                    let q = [a[0] + s * e[0], a[1] + s * e[1]];
                    (v[i].0 + s * TAU / n as f64, d2(q).sqrt())
                })
                .min_by(|x, y| x.1.total_cmp(&y.1))
                .expect("a polygon has vertices");
        }
        let (t0, q0) = self
            .polygonize(64)
            .into_iter()
            .min_by(|a, b| d2(a.1).total_cmp(&d2(b.1)))
            .expect("a polygonisation is never empty");
        let mut best = (t0, d2(q0));
        let mut t = t0;
        for _ in 0..30 {
            let d = self.derivatives(t, 2);
            let r = sub(d[0], p);
            if d2(d[0]) < best.1 {
                best = (t, d2(d[0]));
            }
            let f = r[0] * d[1][0] + r[1] * d[1][1];
            let fp = d[1][0] * d[1][0] + d[1][1] * d[1][1] + r[0] * d[2][0] + r[1] * d[2][1];
            if fp <= 0.0 {
                break;
            }
            let step = (f / fp).clamp(-0.05, 0.05);
            t -= step;
            if step.abs() < 1e-16 {
                break;
            }
        }
        if d2(self.point(t)) < best.1 {
            best = (t, d2(self.point(t)));
        }
        // Newton stalls where the speed vanishes (a corner from repeated control points):
        // a golden-section search between the neighbouring samples finds the minimum there.
        let h = TAU / (64 * self.knots().len()) as f64; // the spacing of `polygonize(64)`
        let (mut a, mut b) = (t0 - h, t0 + h);
        let g = 0.5 * (5f64.sqrt() - 1.0);
        let f = |t: f64| d2(self.point(t));
        let (mut x1, mut x2) = (b - g * (b - a), a + g * (b - a));
        let (mut f1, mut f2) = (f(x1), f(x2));
        for _ in 0..80 {
            if f1 < f2 {
                (b, x2, f2) = (x2, x1, f1);
                x1 = b - g * (b - a);
                f1 = f(x1);
            } else {
                (a, x1, f1) = (x1, x2, f2);
                x2 = a + g * (b - a);
                f2 = f(x2);
            }
        }
        for (t, v) in [(x1, f1), (x2, f2)] {
            if v < best.1 {
                best = (t, v);
            }
        }
        (best.0.rem_euclid(TAU), best.1.sqrt())
    }

    /// Parameter values at which the curve may have a kink or a knot (polygon vertices,
    /// spline knots); a polygonisation that includes them is exact for polygons.
    pub fn knots(&self) -> Vec<f64> {
        match self {
            TrimCurve::Ellipse { .. } => vec![0.0],
            TrimCurve::Spline(b) => {
                let n = b.points().len();
                (0..n).map(|i| TAU * i as f64 / n as f64).collect()
            }
        }
    }

    /// A polygonisation: `per_piece` points per knot interval (≥ 64 in all), starting at
    /// `t = 0`, as `(t, C(t))`, without repeating the first point.
    pub fn polygonize(&self, per_piece: usize) -> Vec<(f64, Uv)> {
        let knots = self.knots();
        let per = per_piece.max(64usize.div_ceil(knots.len())).max(1);
        let n = knots.len() * per;
        (0..n)
            .map(|k| {
                let t = TAU * k as f64 / n as f64;
                (t, self.point(t))
            })
            .collect()
    }
}

/// Twice the signed area of a closed polygon (positive when counter-clockwise).
pub fn signed_area2(p: &[Uv]) -> f64 {
    let n = p.len();
    (0..n).map(|i| cross(p[i], p[(i + 1) % n])).sum()
}

/// `a × b` in the plane.
pub fn cross(a: Uv, b: Uv) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

/// `a − b`.
pub fn sub(a: Uv, b: Uv) -> Uv {
    [a[0] - b[0], a[1] - b[1]]
}

/// Point in polygon by the winding rule (even–odd crossing count).
pub fn inside_polygon(p: Uv, poly: &[Uv]) -> bool {
    let n = poly.len();
    let mut inside = false;
    let mut j = n - 1;
    for i in 0..n {
        let (a, b) = (poly[i], poly[j]);
        if (a[1] > p[1]) != (b[1] > p[1]) {
            let x = a[0] + (p[1] - a[1]) * (b[0] - a[0]) / (b[1] - a[1]);
            if p[0] < x {
                inside = !inside;
            }
        }
        j = i;
    }
    inside
}

/// Distance from `p` to the closed polygon's edges.
pub fn distance_to_polygon(p: Uv, poly: &[Uv]) -> f64 {
    let n = poly.len();
    (0..n).map(|i| distance_to_segment(p, poly[i], poly[(i + 1) % n])).fold(f64::INFINITY, f64::min)
}

/// Distance from `p` to the segment `ab`.
pub fn distance_to_segment(p: Uv, a: Uv, b: Uv) -> f64 {
    let ab = sub(b, a);
    let l2 = ab[0] * ab[0] + ab[1] * ab[1];
    let s = if l2 > 0.0 { (((p[0] - a[0]) * ab[0] + (p[1] - a[1]) * ab[1]) / l2).clamp(0.0, 1.0) } else { 0.0 };
    let q = [a[0] + s * ab[0] - p[0], a[1] + s * ab[1] - p[1]];
    q[0].hypot(q[1])
}

/// True when the closed segments `ab` and `cd` intersect (touching included).
pub fn segments_intersect(a: Uv, b: Uv, c: Uv, d: Uv) -> bool {
    let o = |p: Uv, q: Uv, r: Uv| cross(sub(q, p), sub(r, p));
    let (d1, d2, d3, d4) = (o(c, d, a), o(c, d, b), o(a, b, c), o(a, b, d));
    if ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0)) && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0)) {
        return true;
    }
    let on = |p: Uv, q: Uv, r: Uv, d: f64| {
        d == 0.0 && r[0] >= p[0].min(q[0]) && r[0] <= p[0].max(q[0]) && r[1] >= p[1].min(q[1]) && r[1] <= p[1].max(q[1])
    };
    on(c, d, a, d1) || on(c, d, b, d2) || on(a, b, c, d3) || on(a, b, d, d4)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spline_derivatives_match_the_curve() {
        let c = TrimCurve::bspline(&[[0.2, 0.2], [0.8, 0.3], [0.7, 0.8], [0.3, 0.7], [0.25, 0.5]]).unwrap();
        // Exact derivative against a high-order difference only as a cross-check of the
        // chain factor 2π ↔ knot parameter (the derivative itself is the exact formula).
        let t = 1.234;
        let d = c.derivatives(t, 1);
        let h = 1e-6;
        let (a, b) = (c.point(t + h), c.point(t - h));
        assert!(((a[0] - b[0]) / (2.0 * h) - d[1][0]).abs() < 1e-6);
        assert!(((a[1] - b[1]) / (2.0 * h) - d[1][1]).abs() < 1e-6);
        // periodic
        let (p0, p1) = (c.point(0.0), c.point(TAU));
        assert!((p0[0] - p1[0]).abs() < 1e-14 && (p0[1] - p1[1]).abs() < 1e-14);
    }

    #[test]
    fn polygon_passes_through_its_vertices() {
        let v = [[0.1, 0.1], [0.9, 0.1], [0.5, 0.8]];
        let c = TrimCurve::polygon(&v).unwrap();
        for (k, t) in c.knots().into_iter().enumerate() {
            let p = c.point(t);
            assert!((p[0] - v[k][0]).abs() < 1e-15 && (p[1] - v[k][1]).abs() < 1e-15, "{k}: {p:?}");
        }
        let poly: Vec<Uv> = c.polygonize(4).into_iter().map(|x| x.1).collect();
        assert!((signed_area2(&poly) / 2.0 - 0.8 * 0.7 / 2.0).abs() < 1e-12);
        assert!(inside_polygon([0.5, 0.3], &poly) && !inside_polygon([0.1, 0.5], &poly));
    }

    #[test]
    fn segment_tests() {
        assert!(segments_intersect([0.0, 0.0], [1.0, 1.0], [0.0, 1.0], [1.0, 0.0]));
        assert!(!segments_intersect([0.0, 0.0], [1.0, 0.0], [0.0, 1.0], [1.0, 1.0]));
        assert!(segments_intersect([0.0, 0.0], [1.0, 0.0], [1.0, 0.0], [2.0, 1.0]));
        assert!((distance_to_segment([0.5, 1.0], [0.0, 0.0], [1.0, 0.0]) - 1.0).abs() < 1e-15);
    }
}
