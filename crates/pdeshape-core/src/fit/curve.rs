//! B-spline approximation of space curves (trim edges in 3D).
//!
//! `c(t)`, `t ∈ [t₀, t₁]`, is interpolated at the Greville abscissae of a clamped knot
//! vector of degree 3 (full multiplicity at the given corner parameters, where `c` is only
//! C0). The deviation `|S(t) − c(t)|` is sampled at 16 points per span and maximised
//! around the largest samples of each span by golden-section search; spans above the
//! tolerance are halved until the measured maximum is within it.

use super::{FitError, Knots, interpolate};
use crate::Vec3;

/// A clamped B-spline curve in space.
#[derive(Clone, Debug)]
pub struct BSplineCurve3 {
    /// Knots.
    pub knots: Knots,
    /// Control points.
    pub control: Vec<Vec3>,
}

impl BSplineCurve3 {
    /// `S(t)`.
    pub fn point(&self, t: f64) -> Vec3 {
        let (span, d) = self.knots.basis(t, 0);
        let p = self.knots.degree;
        d[0].iter().enumerate().fold(Vec3::ZERO, |acc, (r, &w)| acc + self.control[span - p + r] * w)
    }
}

/// Samples per span for the measured maximum.
const SAMPLES: usize = 16;

/// Fits `c` on `[t0, t1]` with C0 corners at `corners` to the absolute tolerance `tol`;
/// returns the curve and its measured maximum deviation.
pub fn fit_curve(
    c: &dyn Fn(f64) -> Vec3,
    t0: f64,
    t1: f64,
    corners: &[f64],
    tol: f64,
    max_points: usize,
) -> Result<(BSplineCurve3, f64), FitError> {
    let p = 3;
    let corners: Vec<f64> = corners.iter().copied().filter(|&x| x > t0 && x < t1).collect();
    let mut interior: Vec<f64> = (1..8).map(|i| t0 + (t1 - t0) * i as f64 / 8.0).collect();
    interior.extend(&corners);
    interior.sort_by(f64::total_cmp);
    interior.dedup();
    loop {
        let knots = super::knots_with_breaks(p, t0, t1, &interior, &corners, &[]);
        let g = knots.greville();
        let rows: Vec<(f64, usize)> = g.iter().map(|&t| (t, 0)).collect();
        let rhs: Vec<Vec<Vec3>> = g.iter().map(|&t| vec![c(t)]).collect();
        if let Some(k) = rhs.iter().position(|r| !r[0].is_finite()) {
            return Err(FitError::NotFinite(g[k], f64::NAN));
        }
        let sol = interpolate(&knots, &rows, &rhs)?;
        let curve = BSplineCurve3 { knots: knots.clone(), control: sol.into_iter().map(|r| r[0]).collect() };
        let b = knots.breakpoints();
        let dev = |t: f64| (curve.point(t) - c(t)).norm();
        let mut worst = (0.0_f64, t0);
        let mut split = vec![false; b.len() - 1];
        for (i, w) in b.windows(2).enumerate() {
            let (lo, hi) = (w[0], w[1]);
            let h = (hi - lo) / SAMPLES as f64;
            let mut best = (0.0_f64, lo);
            for k in 0..=SAMPLES {
                let t = lo + h * k as f64;
                let d = dev(t);
                if d.is_nan() || d > best.0 {
                    best = (d, t);
                }
            }
            if best.0.is_nan() {
                return Err(FitError::NotFinite(best.1, f64::NAN));
            }
            // golden-section search on the bracket around the best sample
            let (mut a, mut bb) = ((best.1 - h).max(lo), (best.1 + h).min(hi));
            let r = 0.5 * (5f64.sqrt() - 1.0);
            let (mut x1, mut x2) = (bb - r * (bb - a), a + r * (bb - a));
            let (mut f1, mut f2) = (dev(x1), dev(x2));
            for _ in 0..40 {
                if f1 > f2 {
                    bb = x2;
                    (x2, f2) = (x1, f1);
                    x1 = bb - r * (bb - a);
                    f1 = dev(x1);
                } else {
                    a = x1;
                    (x1, f1) = (x2, f2);
                    x2 = a + r * (bb - a);
                    f2 = dev(x2);
                }
            }
            for (d, t) in [(f1, x1), (f2, x2)] {
                if d.is_nan() || d > best.0 {
                    best = (d, t);
                }
            }
            split[i] = best.0 > tol;
            if best.0.is_nan() || best.0 > worst.0 {
                worst = best;
            }
        }
        if worst.0.is_nan() {
            return Err(FitError::NotFinite(worst.1, f64::NAN));
        }
        if worst.0 <= tol {
            return Ok((curve, worst.0));
        }
        let mut next = Vec::with_capacity(interior.len() * 2);
        for (i, w) in b.windows(2).enumerate() {
            if i > 0 {
                next.push(w[0]);
            }
            if split[i] {
                next.push(0.5 * (w[0] + w[1]));
            }
        }
        if next.len() + corners.len() * (p - 1) + p + 1 > max_points {
            return Err(FitError::Tolerance {
                tolerance: tol,
                deviation: worst.0,
                u: worst.1,
                v: f64::NAN,
                cap: max_points,
            });
        }
        interior = next;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A helix to 1e-9 (measured); a square (C0 corners) reproduced by its corner knots.
    #[test]
    fn a_helix_and_a_square() {
        let helix = |t: f64| Vec3::new(t.cos(), t.sin(), 0.3 * t);
        let (c, dev) = fit_curve(&helix, 0.0, 10.0, &[], 1e-9, 2000).unwrap();
        assert!(dev <= 1e-9);
        let mut worst: f64 = 0.0;
        for k in 0..10_000 {
            let t = 10.0 * (k as f64 + 0.377) / 10_000.0;
            worst = crate::num::max_nan(worst, (c.point(t) - helix(t)).norm());
        }
        // the golden-section search finds each span's maximum to ~1e-8 of the span
        assert!(worst <= dev * (1.0 + 1e-6), "{worst} > {dev}");
        let square = |t: f64| {
            let (k, s) = ((t.floor() as usize).min(3), t - t.floor().min(3.0));
            let c = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [0.0, 0.0]];
            Vec3::new(c[k][0] + s * (c[k + 1][0] - c[k][0]), c[k][1] + s * (c[k + 1][1] - c[k][1]), 0.0)
        };
        let (c, dev) = fit_curve(&square, 0.0, 4.0, &[1.0, 2.0, 3.0], 1e-12, 200).unwrap();
        assert!(dev <= 1e-14, "{dev}");
        assert!(c.control.len() <= 20, "{}", c.control.len());
    }
}
