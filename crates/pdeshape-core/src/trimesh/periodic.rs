//! Periodic cubic B-splines on arbitrary breakpoints: the collar's curves along a loop.
//!
//! With breakpoints `t₀ < … < t_{n−1}` and period `L` (`t_{i+n} = t_i + L`), the `n`
//! control points `Q_j` are wrapped (`Q_{j+n} = Q_j`) over the expanded knot vector
//! `k_j = t_{j−3}`, `j = 0 … n + 6`: the curve `Σ_j N_j(x) Q_{j mod n}` on `[t₀, t₀ + L]`
//! is `L`-periodic with two continuous derivatives everywhere.
//!
//! **Interpolation at the breakpoints.** `N_j` is supported on `[t_{j−3}, t_{j+1}]` and
//! vanishes at its ends, so at `t_i` only `N_i`, `N_{i+1}`, `N_{i+2}` are non-zero: in the
//! unknowns `U_m = Q_{m+1}` the system is cyclic tridiagonal (row `i` touches `U_{i−1}`,
//! `U_i`, `U_{i+1}`) and is solved by the Thomas algorithm with the Sherman–Morrison
//! correction for the two corner entries, in `O(n)`.

use crate::Vec3;
use crate::data::NurbsCurve;

/// A periodic cubic B-spline basis.
#[derive(Clone, Debug, PartialEq)]
pub struct PeriodicSpline {
    breaks: Vec<f64>,
    period: f64,
    knots: Vec<f64>,
}

impl PeriodicSpline {
    /// The basis on increasing `breaks` (at least 3) with period `period` (greater than
    /// `breaks[n−1] − breaks[0]`).
    pub fn new(breaks: Vec<f64>, period: f64) -> Option<Self> {
        let n = breaks.len();
        if n < 3
            || breaks.windows(2).any(|w| w[1] <= w[0] || !w[1].is_finite())
            || !(breaks[0].is_finite() && period.is_finite() && breaks[0] + period > breaks[n - 1])
        {
            return None;
        }
        let t = |i: isize| {
            let k = i.rem_euclid(n as isize) as usize;
            breaks[k] + period * (i - k as isize).div_euclid(n as isize) as f64
        };
        let knots = (0..n + 7).map(|j| t(j as isize - 3)).collect();
        Some(PeriodicSpline { breaks, period, knots })
    }

    /// Number of control points.
    pub fn len(&self) -> usize {
        self.breaks.len()
    }

    /// Never: a basis has at least 3 functions.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// The breakpoints `t₀ < … < t_{n−1}`.
    pub fn breaks(&self) -> &[f64] {
        &self.breaks
    }

    /// The parameter range `[t₀, t₀ + L]`.
    pub fn domain(&self) -> (f64, f64) {
        (self.breaks[0], self.breaks[0] + self.period)
    }

    /// `x` taken into `[t₀, t₀ + L)`.
    pub fn wrap(&self, x: f64) -> f64 {
        let t0 = self.breaks[0];
        let y = t0 + (x - t0).rem_euclid(self.period);
        if y >= t0 + self.period { t0 } else { y }
    }

    /// The four basis functions non-zero at `x` (taken into the period) and their first
    /// `nd` derivatives: `(j, d)` with `d[k][r] = dᵏN/dxᵏ` of control point `(j + r) mod n`.
    pub fn basis(&self, x: f64, nd: usize) -> (usize, Vec<Vec<f64>>) {
        let x = self.wrap(x);
        let i = self.breaks.partition_point(|&b| b <= x).saturating_sub(1);
        (i, crate::data::basis_derivatives(&self.knots, 3, i + 3, x, nd))
    }

    /// The curve with control points `ctrl` (`len()` of them) as a field with exact jets.
    pub fn curve(&self, ctrl: &[Vec3]) -> NurbsCurve {
        let n = self.len();
        let wrapped: Vec<Vec3> = (0..n + 3).map(|j| ctrl[j % n]).collect();
        NurbsCurve::new(3, self.knots.clone(), &wrapped, None).expect("the expanded knots fit the wrapped points")
    }

    /// The control points of the curve through `points[i]` at `breaks[i]`; `None` when the
    /// system is singular to working precision.
    pub fn interpolate(&self, points: &[Vec3]) -> Option<Vec<Vec3>> {
        let n = self.len();
        assert_eq!(points.len(), n, "one point per breakpoint");
        let (mut a, mut b, mut c) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        for i in 0..n {
            let (j, d) = self.basis(self.breaks[i], 0);
            debug_assert_eq!(j, i);
            (a[i], b[i], c[i]) = (d[0][0], d[0][1], d[0][2]);
        }
        let u = cyclic_tridiagonal(&a, &b, &c, points)?;
        Some((0..n).map(|j| u[(j + n - 1) % n]).collect())
    }
}

/// Solves the cyclic tridiagonal system `a_i x_{i−1} + b_i x_i + c_i x_{i+1} = r_i`
/// (indices mod `n`, `n ≥ 3`) by Sherman–Morrison (Numerical Recipes §2.7).
fn cyclic_tridiagonal(a: &[f64], b: &[f64], c: &[f64], r: &[Vec3]) -> Option<Vec<Vec3>> {
    let n = b.len();
    let (alpha, beta) = (c[n - 1], a[0]);
    let gamma = -b[0];
    let mut bb = b.to_vec();
    bb[0] = b[0] - gamma;
    bb[n - 1] = b[n - 1] - alpha * beta / gamma;
    let x = tridiagonal(a, &bb, c, r)?;
    let mut u = vec![Vec3::ZERO; n];
    u[0] = Vec3::new(gamma, 0.0, 0.0);
    u[n - 1] = Vec3::new(alpha, 0.0, 0.0);
    let z: Vec<f64> = tridiagonal(a, &bb, c, &u)?.iter().map(|p| p.x).collect();
    let den = 1.0 + z[0] + beta * z[n - 1] / gamma;
    if den == 0.0 || !den.is_finite() {
        return None;
    }
    let fact = (x[0] + x[n - 1] * (beta / gamma)) * (1.0 / den);
    Some(x.iter().zip(&z).map(|(xi, zi)| *xi - fact * *zi).collect())
}

/// The Thomas algorithm for `a_i x_{i−1} + b_i x_i + c_i x_{i+1} = r_i` (`a₀`, `c_{n−1}`
/// ignored).
fn tridiagonal(a: &[f64], b: &[f64], c: &[f64], r: &[Vec3]) -> Option<Vec<Vec3>> {
    let n = b.len();
    let mut cp = vec![0.0; n];
    let mut x = vec![Vec3::ZERO; n];
    let mut piv = b[0];
    if piv == 0.0 {
        return None;
    }
    x[0] = r[0] * (1.0 / piv);
    for i in 1..n {
        cp[i - 1] = c[i - 1] / piv;
        piv = b[i] - a[i] * cp[i - 1];
        if piv == 0.0 || !piv.is_finite() {
            return None;
        }
        x[i] = (r[i] - x[i - 1] * a[i]) * (1.0 / piv);
    }
    for i in (0..n - 1).rev() {
        x[i] = x[i] - x[i + 1] * cp[i];
    }
    Some(x)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::Field;

    /// The interpolant of a circle sampled at uneven parameters passes through every
    /// sample (to round-off: the residual of an `O(n)` solve with pivots near 2/3) and is
    /// periodic with its first two derivatives.
    #[test]
    fn interpolates_and_closes() {
        let n = 17;
        let breaks: Vec<f64> = (0..n).map(|i| i as f64 + 0.3 * ((i * 7) % 5) as f64 / 5.0).collect();
        let period = n as f64;
        let s = PeriodicSpline::new(breaks.clone(), period).unwrap();
        let pts: Vec<Vec3> = breaks
            .iter()
            .map(|&t| {
                let a = std::f64::consts::TAU * t / period;
                Vec3::new(a.cos(), a.sin(), 0.1 * (2.0 * a).sin())
            })
            .collect();
        let q = s.interpolate(&pts).unwrap();
        let c = s.curve(&q);
        for (t, p) in breaks.iter().zip(&pts) {
            assert!((c.eval(&[*t]) - *p).norm() < 1e-14, "{t}");
        }
        let (t0, t1) = s.domain();
        let shape = crate::jet::JetShape::new(&[2]);
        let (j0, j1) = (c.jet(&[t0], shape), c.jet(&[t1], shape));
        for k in 0..3 {
            let d = j0.derivative([k, 0, 0]) - j1.derivative([k, 0, 0]);
            assert!(d.norm() < 1e-12, "derivative {k} jumps by {}", d.norm());
        }
        // basis: partition of unity at an arbitrary point, control indices wrapping
        let (j, d) = s.basis(t1 - 0.25, 1);
        assert_eq!(j, n - 1);
        assert!((d[0].iter().sum::<f64>() - 1.0).abs() < 1e-15);
        assert!(d[1].iter().sum::<f64>().abs() < 1e-14);
    }
}
