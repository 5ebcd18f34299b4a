//! Uniform B-spline curves: clamped open and periodic closed, of any degree (cubic by
//! default; a polyline is the degree-1 case).

use super::{Field, VecJet};
use crate::Vec3;
use crate::jet::JetShape;

/// Invalid B-spline input.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum BSplineError {
    /// Not enough control points for the curve type.
    #[error("a {kind} needs at least {min} control points, got {got}")]
    TooFewPoints {
        /// Curve description.
        kind: &'static str,
        /// Minimum.
        min: usize,
        /// Given.
        got: usize,
    },
    /// A control point is NaN or infinite.
    #[error("control point {index} is not finite")]
    NonFinite {
        /// Index of the offending point.
        index: usize,
    },
    /// The parameter range is empty or not finite.
    #[error("parameter range [{0}, {1}] is empty or not finite")]
    BadRange(f64, f64),
    /// Degree 0 or above 7.
    #[error("degree {0} is not supported (1 … 7)")]
    BadDegree(usize),
}

/// A uniform B-spline curve `C(v) = Σ_i N_{i,p}(x(v)) P_i` with the knot parameter `x` an
/// affine function of `v ∈ [v₀, v₁]`.
///
/// - Open curves are clamped (end knots of multiplicity `p + 1`): `C(v₀) = P₀`,
///   `C(v₁) = P_{n−1}`.
/// - Closed curves are periodic: uniform knots over the control points wrapped `p` times,
///   so `C` and all its derivatives are `(v₁ − v₀)`-periodic (C^{p−1} everywhere).
///
/// Derivatives are exact: the derivative basis functions of The NURBS Book (A2.3) times
/// `(dx/dv)^k`; derivatives above the degree are zero.
///
/// ```
/// use pdeshape_core::{Vec3, data::{BSplineCurve, Field}};
/// let pts: Vec<Vec3> = (0..4).map(|i| Vec3::new(i as f64, 0.0, 0.0)).collect();
/// let c = BSplineCurve::new(pts, 3, false, (0.0, 1.0)).unwrap();
/// assert_eq!(c.eval(&[1.0]), Vec3::new(3.0, 0.0, 0.0));
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct BSplineCurve {
    points: Vec<Vec3>,
    degree: usize,
    closed: bool,
    range: (f64, f64),
    knots: Vec<f64>,
    /// Control points as used by the basis (wrapped for closed curves).
    ctrl: Vec<Vec3>,
}

impl BSplineCurve {
    /// A curve of the given degree through control points `points` over `range`.
    pub fn new(points: Vec<Vec3>, degree: usize, closed: bool, range: (f64, f64)) -> Result<Self, BSplineError> {
        if degree == 0 || degree > 7 {
            return Err(BSplineError::BadDegree(degree));
        }
        if let Some(index) = points.iter().position(|p| !p.is_finite()) {
            return Err(BSplineError::NonFinite { index });
        }
        if !(range.0.is_finite() && range.1.is_finite() && range.1 > range.0) {
            return Err(BSplineError::BadRange(range.0, range.1));
        }
        let n = points.len();
        let (knots, ctrl) = if closed {
            let min = degree + 1;
            if n < min.max(3) {
                return Err(BSplineError::TooFewPoints { kind: "closed B-spline", min: min.max(3), got: n });
            }
            let ctrl: Vec<Vec3> = (0..n + degree).map(|i| points[i % n]).collect();
            let knots: Vec<f64> = (0..=n + 2 * degree).map(|i| i as f64).collect();
            (knots, ctrl)
        } else {
            if n < 2 {
                return Err(BSplineError::TooFewPoints { kind: "open B-spline", min: 2, got: n });
            }
            let p = degree.min(n - 1);
            let mut knots = vec![0.0; p + 1];
            knots.extend((1..n - p).map(|i| i as f64));
            knots.extend(std::iter::repeat_n((n - p) as f64, p + 1));
            (knots, points.clone())
        };
        let degree = if closed { degree } else { degree.min(n - 1) };
        Ok(BSplineCurve { points, degree, closed, range, knots, ctrl })
    }

    /// The control points as given.
    pub fn points(&self) -> &[Vec3] {
        &self.points
    }

    /// The (effective) degree.
    pub fn degree(&self) -> usize {
        self.degree
    }

    /// True for a periodic closed curve.
    pub fn is_closed(&self) -> bool {
        self.closed
    }

    /// The parameter range `[v₀, v₁]`.
    pub fn range(&self) -> (f64, f64) {
        self.range
    }

    /// Knot parameter `x` and `dx/dv` for the curve parameter `v`.
    fn knot_param(&self, v: f64) -> (f64, f64) {
        let (a, b) = self.range;
        let p = self.degree;
        if self.closed {
            let n = self.points.len() as f64;
            let s = ((v - a) / (b - a)).rem_euclid(1.0);
            (p as f64 + s * n, n / (b - a))
        } else {
            let span = (self.points.len() - p) as f64;
            let s = ((v - a) / (b - a)).clamp(0.0, 1.0);
            (s * span, span / (b - a))
        }
    }

    fn find_span(&self, x: f64) -> usize {
        let p = self.degree;
        let n = self.ctrl.len();
        // Knots are uniform integers inside [p, n): the span is floor(x) clamped.
        let lo = self.knots[p];
        let idx = p + ((x - lo).floor().max(0.0) as usize);
        idx.min(n - 1)
    }

    /// `C⁽ᵏ⁾(v)` for `k = 0 … nd` (exact; zero above the degree).
    pub fn derivatives(&self, v: f64, nd: usize) -> Vec<Vec3> {
        let (x, dxdv) = self.knot_param(v);
        let span = self.find_span(x);
        let ders = self.ders_basis_scaled(span, x, nd);
        let p = self.degree;
        (0..=nd)
            .map(|k| {
                if k > p || k >= ders.len() {
                    return Vec3::ZERO;
                }
                let s: Vec3 = (0..=p).map(|j| self.ctrl[span - p + j] * ders[k][j]).sum();
                s * dxdv.powi(k as i32)
            })
            .collect()
    }

    fn ders_basis_scaled(&self, span: usize, x: f64, nd: usize) -> Vec<Vec<f64>> {
        basis_derivatives(&self.knots, self.degree, span, x, nd)
    }
}

impl Field for BSplineCurve {
    fn arity(&self) -> usize {
        1
    }
    fn jet(&self, at: &[f64], shape: JetShape) -> VecJet {
        let o = shape.orders();
        let d = self.derivatives(at[0], o[0]);
        // Taylor coefficients in slot 0 are C⁽ᵏ⁾/k!; all other slots are constant.
        let mut c = vec![Vec3::ZERO; shape.len()];
        let mut fact = 1.0;
        for (k, dk) in d.iter().enumerate() {
            if k > 0 {
                fact *= k as f64;
            }
            c[shape.index([k, 0, 0])] = *dk / fact;
        }
        VecJet::from_vec_coeffs(shape, &c)
    }
    fn eval(&self, at: &[f64]) -> Vec3 {
        self.derivatives(at[0], 0)[0]
    }
    /// The basis derivatives directly (no jet): the curve's own slot, or constant in the
    /// others.
    fn derivatives_in(&self, at: &[f64], slot: usize, out: &mut [Vec3]) {
        let Some(order) = out.len().checked_sub(1) else { return };
        if slot == 0 {
            out.copy_from_slice(&self.derivatives(at[0], order));
        } else {
            out.fill(Vec3::ZERO);
            out[0] = self.eval(at);
        }
    }
    fn is_constant_in(&self, slot: usize) -> bool {
        slot != 0
    }
}

/// The `p + 1` non-zero B-spline basis functions of degree `p` on `knots` at `x` in knot
/// span `span`, and their derivatives up to order `min(nd, p)`: row `k`, entry `r` is
/// `dᵏ N_{span−p+r}/dxᵏ` (The NURBS Book, A2.3, with its final factor `p!/(p−k)!`).
pub(crate) fn basis_derivatives(knots: &[f64], p: usize, span: usize, x: f64, nd: usize) -> Vec<Vec<f64>> {
    let rows = nd.min(p) + 1;
    let mut flat = vec![0.0; rows * (p + 1)];
    basis_derivatives_into(knots, p, span, x, nd, &mut flat);
    flat.chunks(p + 1).map(<[f64]>::to_vec).collect()
}

/// [`basis_derivatives`] into `ders`, row `k` (of width `p + 1`) at `k (p + 1)`, for
/// `k ≤ min(nd, p)`; `ders` holds at least that many rows, those beyond are left alone.
/// Nothing is allocated. Degrees 1 … 7 (the faces of CAD files, the fits' cubics and
/// quintics) each get their own instance, whose loops the compiler unrolls and whose
/// indices it checks once; the operations are the same at every degree (the same bits).
pub(crate) fn basis_derivatives_into(knots: &[f64], p: usize, span: usize, x: f64, nd: usize, ders: &mut [f64]) {
    match p {
        1 => a23::<2>(knots, 1, span, x, nd, ders),
        2 => a23::<3>(knots, 2, span, x, nd, ders),
        3 => a23::<4>(knots, 3, span, x, nd, ders),
        4 => a23::<5>(knots, 4, span, x, nd, ders),
        5 => a23::<6>(knots, 5, span, x, nd, ders),
        6 => a23::<7>(knots, 6, span, x, nd, ders),
        7 => a23::<8>(knots, 7, span, x, nd, ders),
        // (tables sized to the degree: they are zeroed at every call)
        8..=11 => a23::<12>(knots, p, span, x, nd, ders),
        _ => a23::<{ MAX_BASIS_DEGREE + 1 }>(knots, p, span, x, nd, ders),
    }
}

/// The highest degree [`basis_derivatives`] takes (that of the NURBS a file may hold).
const MAX_BASIS_DEGREE: usize = 25;

/// The NURBS Book's A2.3 for degree `p < W` in tables of `W × W`: `ndu[j][r]` for `r < j`
/// the knot differences, for `r ≥ j` the basis functions of degree `j`; `a` the two rows
/// of derivative coefficients in turn.
#[inline(always)]
fn a23<const W: usize>(u: &[f64], p: usize, span: usize, x: f64, nd: usize, ders: &mut [f64]) {
    assert!(p < W, "degree {p} above {}", W - 1);
    let w = p + 1;
    let mut ndu = [[0.0; W]; W];
    let (mut left, mut right) = ([0.0; W], [0.0; W]);
    ndu[0][0] = 1.0;
    for j in 1..=p {
        left[j] = x - u[span + 1 - j];
        right[j] = u[span + j] - x;
        let mut saved = 0.0;
        for r in 0..j {
            ndu[j][r] = right[r + 1] + left[j - r];
            let temp = ndu[r][j - 1] / ndu[j][r];
            ndu[r][j] = saved + right[r + 1] * temp;
            saved = left[j - r] * temp;
        }
        ndu[j][j] = saved;
    }
    let nd = nd.min(p);
    for (j, d) in ders[..w].iter_mut().enumerate() {
        *d = ndu[j][p];
    }
    let mut a = [[0.0; W]; 2];
    for r in 0..=p {
        let (mut s1, mut s2) = (0, 1);
        a[0][0] = 1.0;
        for k in 1..=nd {
            let mut d = 0.0;
            let rk = r as isize - k as isize;
            let pk = p - k;
            if r >= k {
                a[s2][0] = a[s1][0] / ndu[pk + 1][rk as usize];
                d = a[s2][0] * ndu[rk as usize][pk];
            }
            let j1 = if rk >= -1 { 1 } else { (-rk) as usize };
            let j2 = if (r as isize - 1) <= pk as isize { k - 1 } else { p - r };
            for j in j1..=j2 {
                let idx = (rk + j as isize) as usize;
                a[s2][j] = (a[s1][j] - a[s1][j - 1]) / ndu[pk + 1][idx];
                d += a[s2][j] * ndu[idx][pk];
            }
            if r <= pk {
                a[s2][k] = -a[s1][k - 1] / ndu[pk + 1][r];
                d += a[s2][k] * ndu[r][pk];
            }
            ders[k * w + r] = d;
            std::mem::swap(&mut s1, &mut s2);
        }
    }
    let mut f = p as f64;
    for (k, row) in ders[..(nd + 1) * w].chunks_mut(w).enumerate().skip(1) {
        for x in row.iter_mut() {
            *x *= f;
        }
        f *= (p - k) as f64;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::Field;

    /// A2.3 at every degree 1 … 25 (each of its table sizes) against the Cox–de Boor
    /// recursion and its derivative `N⁽ᵏ⁾ᵢ,q = q (N⁽ᵏ⁻¹⁾ᵢ,q₋₁/(uᵢ₊q − uᵢ) −
    /// N⁽ᵏ⁻¹⁾ᵢ₊₁,q₋₁/(uᵢ₊q₊₁ − uᵢ₊₁))` (terms over empty intervals dropped), tabulated bottom
    /// up: clamped knots with a double interior knot, at points inside spans, at a knot and
    /// at the ends, derivatives to order 4. A table one entry too small, or a degree sent
    /// to the wrong instance, fails.
    #[test]
    fn a23_against_cox_de_boor() {
        for p in 1..=25usize {
            let inner = [0.13, 0.4, 0.4, 0.55, 0.9];
            let u: Vec<f64> = [vec![0.0; p + 1], inner.to_vec(), vec![1.0; p + 1]].concat();
            let n = u.len() - p - 1;
            for x in [0.0, 0.07, 0.4, 0.47, 0.731, 1.0] {
                // the span as the evaluators find it (the last non-empty one at the end)
                let span = (p..n).rev().find(|&s| u[s] <= x && u[s] < u[s + 1]).unwrap();
                let nd = 4;
                let rows = nd.min(p) + 1;
                let mut got = vec![f64::NAN; rows * (p + 1)];
                basis_derivatives_into(&u, p, span, x, nd, &mut got);
                // cdb[k][q][i]: dᵏ N_{i,q} / dxᵏ, the degree-0 functions of span `span`
                let m = u.len() - 1;
                let mut cdb = vec![vec![vec![0.0; m]; p + 1]; nd + 1];
                cdb[0][0][span] = 1.0;
                let ratio = |a: f64, b: f64| if b == 0.0 { 0.0 } else { a / b };
                for q in 1..=p {
                    for i in 0..m - q {
                        let (l, r) = (u[i + q] - u[i], u[i + q + 1] - u[i + 1]);
                        cdb[0][q][i] =
                            ratio(x - u[i], l) * cdb[0][q - 1][i] + ratio(u[i + q + 1] - x, r) * cdb[0][q - 1][i + 1];
                        for k in 1..=nd {
                            cdb[k][q][i] =
                                q as f64 * (ratio(cdb[k - 1][q - 1][i], l) - ratio(cdb[k - 1][q - 1][i + 1], r));
                        }
                    }
                }
                for k in 0..rows {
                    let want: Vec<f64> = (0..=p).map(|r| cdb[k][p][span - p + r]).collect();
                    let size = want.iter().map(|w| w.abs()).fold(1.0, crate::num::max_nan);
                    for r in 0..=p {
                        let g = got[k * (p + 1) + r];
                        // both sum the same terms in other orders: round-off of the row's
                        // largest entry times the degree
                        assert!(
                            (g - want[r]).abs() <= 1e-14 * (p * p) as f64 * size,
                            "p {p} x {x} k {k} r {r}: {g} vs {}",
                            want[r]
                        );
                    }
                }
            }
        }
    }

    /// The one-slot path and the jet path give the same derivatives (to round-off: both
    /// sum the same basis derivatives, the jet divides by k! and multiplies back), in the
    /// curve's slot and in a slot it does not depend on, closed and open, degrees 1 … 5,
    /// also through an even extension (chain rule `(±(v₁ − v₀)/π)ᵏ` on either half).
    #[test]
    fn one_slot_derivatives_match_the_jets() {
        use crate::data::{EvenExtension, derivatives_by_jet};
        for degree in 1..=5 {
            for closed in [false, true] {
                let c = std::sync::Arc::new(BSplineCurve::new(pts(9), degree, closed, (0.0, 2.0)).unwrap());
                let e = EvenExtension::new(c.clone(), 0.0, 2.0);
                for k in 0..40 {
                    let x = 0.05 * k as f64 + 0.013;
                    for slot in [0, 1] {
                        // the extension over θ ∈ [0, 6]: both halves
                        let cases: [(&dyn Field, f64); 2] = [(c.as_ref(), 1.0), (&e, 3.0)];
                        for (f, stretch) in cases {
                            let at = [stretch * x, 0.4];
                            let (mut fast, mut jet) = ([Vec3::ZERO; 7], [Vec3::ZERO; 7]);
                            f.derivatives_in(&at, slot, &mut fast);
                            derivatives_by_jet(f, &at, slot, &mut jet);
                            for (j, (a, b)) in fast.iter().zip(&jet).enumerate() {
                                let scale = 1.0 + b.norm();
                                assert!(
                                    (*a - *b).norm() <= 1e-12 * scale,
                                    "degree {degree}, closed {closed}, at {at:?}, slot {slot}, order {j}: {a:?} vs {b:?}"
                                );
                            }
                        }
                    }
                }
            }
        }
    }

    fn pts(n: usize) -> Vec<Vec3> {
        (0..n)
            .map(|i| {
                let a = i as f64 * 0.9;
                Vec3::new(a.cos() * (1.0 + 0.3 * i as f64), a.sin(), (i * i) as f64 * 0.1)
            })
            .collect()
    }

    /// Exact derivatives must agree with the difference quotient of the next lower one
    /// (a consistency check of the derivative algorithm, not a way of computing them).
    #[test]
    fn derivatives_are_consistent() {
        for closed in [false, true] {
            for deg in 1..=4 {
                let c = BSplineCurve::new(pts(7), deg, closed, (0.0, 2.0)).unwrap();
                for &v in &[0.13, 0.77, 1.31, 1.9] {
                    let h = 1e-6;
                    let d0 = c.derivatives(v, deg);
                    let d1 = c.derivatives(v + h, deg);
                    for k in 0..deg {
                        let fd = (d1[k] - d0[k]) / h;
                        let tol = 1e-3 * (1.0 + d0[k + 1].norm());
                        assert!(
                            (fd - d0[k + 1]).norm() < tol,
                            "closed {closed} deg {deg} k {k}: {fd:?} vs {:?}",
                            d0[k + 1]
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn clamped_ends_and_periodicity() {
        let p = pts(6);
        let c = BSplineCurve::new(p.clone(), 3, false, (0.0, 1.0)).unwrap();
        assert!((c.eval(&[0.0]) - p[0]).norm() < 1e-15);
        assert!((c.eval(&[1.0]) - p[5]).norm() < 1e-14);
        // Clamped end tangent: p (P1 − P0) / (knot span) · dx/dv
        let d = c.derivatives(0.0, 1)[1];
        assert!((d - (p[1] - p[0]) * 3.0 * 3.0).norm() < 1e-12, "{d:?}");
        let c = BSplineCurve::new(p, 3, true, (0.0, 2.0 * std::f64::consts::PI)).unwrap();
        let a = c.derivatives(0.0, 3);
        let b = c.derivatives(2.0 * std::f64::consts::PI, 3);
        for k in 0..3 {
            assert!((a[k] - b[k]).norm() < 1e-9 * (1.0 + a[k].norm()));
        }
        // partition of unity: a closed curve of identical points is that point
        let c = BSplineCurve::new(vec![Vec3::new(1.0, 2.0, 3.0); 5], 3, true, (0.0, 1.0)).unwrap();
        assert!((c.eval(&[0.37]) - Vec3::new(1.0, 2.0, 3.0)).norm() < 1e-14);
    }

    #[test]
    fn bad_input_is_rejected() {
        assert!(BSplineCurve::new(vec![Vec3::ZERO], 3, false, (0.0, 1.0)).is_err());
        assert!(BSplineCurve::new(vec![Vec3::ZERO; 3], 3, true, (0.0, 1.0)).is_err());
        assert!(BSplineCurve::new(vec![Vec3::new(f64::NAN, 0.0, 0.0); 5], 3, true, (0.0, 1.0)).is_err());
        assert!(BSplineCurve::new(vec![Vec3::ZERO; 5], 3, true, (1.0, 1.0)).is_err());
    }
}
