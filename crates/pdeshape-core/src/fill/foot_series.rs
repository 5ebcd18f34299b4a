//! A foot curve ([`FootCurve`]) tabulated once as a piecewise Chebyshev series, so that
//! the many evaluations of a fill's boundary data cost a few recurrences each instead of
//! a Newton solve and an order-by-order Taylor expansion.
//!
//! On a piece `[a, b]` with `x = (2τ − a − b)/(b − a)` the series is the interpolant of
//! the exact feet at the Chebyshev–Lobatto points `x_j = cos(πj/N)`, `j = 0 … N`:
//!
//! `c̃(τ) = Σ'' a_k T_k(x)`, `a_k = (2/N) Σ''_j c(τ_j) cos(πjk/N)`
//!
//! (`Σ''`: the first and last terms halved). Its derivatives are the series' own: the
//! coefficients of `dc̃/dx` follow from `b_{k−1} = b_{k+1} + 2k a_k` (`b_0` halved), and
//! `d/dτ = (2/(b − a)) d/dx`; every series is summed by Clenshaw's recurrence.
//!
//! **What changes, and what does not.** The fill's edge runs along `S(c̃(τ))` instead of
//! `S(c(τ))`: both lie on the face exactly, and the reparametrisation `S(c̃ + σ ν̃)` of
//! [`super::AlongCurve`] is the face itself near it, so the fill's G1 (order 4) and G2
//! (order 6) to the face hold as before, by construction. What moves is where along the
//! face the edge runs: `|S(c̃(τ)) − S(c(τ))|`, which is *measured* at the midpoints
//! `cos(π(j + ½)/N)` between the nodes of each piece (not bounded) and kept within the
//! caller's tolerance by halving pieces where it is not met; the series interpolates the
//! exact feet at the ends of every piece (the edge's ends and the corners stay exactly
//! the exact feet). Where a piece cannot be brought within the tolerance (the foot is not
//! smooth enough) after [`MAX_DEPTH`] halvings, no series is made and the caller keeps
//! the exact foot curve.

use super::foot::FootCurve;
use crate::Vec3;
use crate::data::{Field, VecJet};
use crate::jet::{Jet, JetShape};
use crate::num::max_nan;

/// Nodes per piece: `N + 1` Chebyshev–Lobatto points (degree `N`).
const N: usize = 20;

/// Derivative orders whose series are kept per piece (beyond: derived at each call).
const DERIVED: usize = 8;

/// The deepest halving of the edge's range.
pub const MAX_DEPTH: usize = 14;

/// At most this many pieces an edge (beyond it: no series).
const MAX_PIECES: usize = 512;

/// `c̃(τ)` as a field of one slot (components `u`, `v`, `0`), like the [`FootCurve`] it
/// tabulates.
#[derive(Clone, Debug)]
pub struct FootSeries {
    /// Piece ends, increasing: piece `i` is `[breaks[i], breaks[i + 1]]`.
    breaks: Vec<f64>,
    /// Each piece's Chebyshev coefficients of `u` and of `v` (`derived[i][q][0]`, `N + 1`
    /// each, `a_0` and `a_N` already halved for plain summation) and their derivative
    /// series in `x` up to order [`DERIVED`] (`derived[i][q][m]`: [`derivative`] applied `m`
    /// times, padded with zeros, which Clenshaw's recurrence passes through exactly):
    /// computed once, so that an evaluation is a few recurrences and nothing else (the same
    /// bits as deriving anew at each call).
    derived: Vec<[[[f64; N + 1]; DERIVED + 1]; 2]>,
    /// The largest distance `|S(c̃) − S(c)|` measured between the nodes.
    max_error: f64,
}

/// Chebyshev coefficients of the values at the Lobatto points (`vals[j]` at
/// `cos(πj/N)`), with `a_0` and `a_N` halved so that `c̃ = Σ a_k T_k`.
fn coefficients(vals: &[f64; N + 1]) -> [f64; N + 1] {
    let mut a = [0.0; N + 1];
    for (k, ak) in a.iter_mut().enumerate() {
        let mut s = 0.0;
        for (j, v) in vals.iter().enumerate() {
            let w = if j == 0 || j == N { 0.5 } else { 1.0 };
            // cos(πjk/N) through the index's residue, exact at the symmetric points
            s += w * v * (std::f64::consts::PI * ((j * k) % (2 * N)) as f64 / N as f64).cos();
        }
        *ak = s * 2.0 / N as f64;
    }
    a[0] *= 0.5;
    a[N] *= 0.5;
    a
}

/// `Σ a_k T_k(x)` by Clenshaw's recurrence.
fn clenshaw(a: &[f64], x: f64) -> f64 {
    let (mut b1, mut b2) = (0.0, 0.0);
    for &ak in a.iter().skip(1).rev() {
        let b0 = ak + 2.0 * x * b1 - b2;
        b2 = b1;
        b1 = b0;
    }
    a[0] + x * b1 - b2
}

/// The coefficients of `d/dx Σ a_k T_k` (one shorter).
fn derivative(a: &[f64]) -> Vec<f64> {
    let n = a.len() - 1;
    if n == 0 {
        return vec![0.0];
    }
    let mut b = vec![0.0; n + 1];
    for k in (1..=n).rev() {
        b[k - 1] = b.get(k + 1).copied().unwrap_or(0.0) + 2.0 * k as f64 * a[k];
    }
    b[0] *= 0.5;
    b.truncate(n);
    b
}

impl FootSeries {
    /// Tabulates `foot` over `range` (either order; the foot curve's own range or part of
    /// it), halving pieces until `|S(c̃) − S(c)| ≤ tol` between the nodes (`S` the foot
    /// curve's surface). `None` when a foot is not found or the tolerance is not met within
    /// [`MAX_DEPTH`] halvings or [`MAX_PIECES`] pieces.
    pub fn new(foot: &FootCurve, range: (f64, f64), tol: f64) -> Option<FootSeries> {
        let (lo, hi) = if range.0 <= range.1 { range } else { (range.1, range.0) };
        if !(lo.is_finite() && hi.is_finite() && hi > lo && tol > 0.0) {
            return None;
        }
        let at = |c: [f64; 2]| foot.surface_point(c);
        let mut breaks = vec![lo];
        let mut coeffs = Vec::new();
        let mut max_error: f64 = 0.0;
        // depth-first, left to right, so pieces come out in order
        let mut todo = vec![(lo, hi, 0usize)];
        while let Some((a, b, depth)) = todo.pop() {
            let (mid, half) = (0.5 * (a + b), 0.5 * (b - a));
            let (mut us, mut vs) = ([0.0; N + 1], [0.0; N + 1]);
            for (j, (u, v)) in us.iter_mut().zip(vs.iter_mut()).enumerate() {
                // the ends exactly, not through the cosine
                let tau = match j {
                    0 => b,
                    N => a,
                    _ => mid + half * (std::f64::consts::PI * j as f64 / N as f64).cos(),
                };
                [*u, *v] = foot.foot(tau)?;
            }
            let piece = [coefficients(&us), coefficients(&vs)];
            let mut err: f64 = 0.0;
            for j in 0..N {
                let x = (std::f64::consts::PI * (j as f64 + 0.5) / N as f64).cos();
                let c = foot.foot(mid + half * x)?;
                let s = [clenshaw(&piece[0], x), clenshaw(&piece[1], x)];
                err = max_nan(err, (at(s) - at(c)).norm());
            }
            // NaN fails
            if err <= tol {
                max_error = max_nan(max_error, err);
                breaks.push(b);
                coeffs.push(piece);
                if coeffs.len() > MAX_PIECES {
                    return None;
                }
            } else if depth >= MAX_DEPTH {
                return None;
            } else {
                // right half first on the stack: the left one is done next
                todo.push((mid, b, depth + 1));
                todo.push((a, mid, depth + 1));
            }
        }
        let derived = coeffs
            .iter()
            .map(|piece: &[[f64; N + 1]; 2]| {
                piece.map(|c| {
                    let mut out = [[0.0; N + 1]; DERIVED + 1];
                    let mut s = c.to_vec();
                    for (m, o) in out.iter_mut().enumerate() {
                        if m > 0 {
                            s = derivative(&s);
                        }
                        o[..s.len()].copy_from_slice(&s);
                    }
                    out
                })
            })
            .collect();
        Some(FootSeries { breaks, derived, max_error })
    }

    /// The largest distance `|S(c̃) − S(c)|` measured between the nodes.
    pub fn max_error(&self) -> f64 {
        self.max_error
    }

    /// The number of pieces.
    pub fn pieces(&self) -> usize {
        self.derived.len()
    }

    /// `dᵐc̃/dτᵐ` of `u` and `v` for `m = 0 … k` (the outermost pieces extrapolate).
    pub fn derivatives(&self, tau: f64, k: usize) -> Vec<[f64; 2]> {
        let i = self.breaks[1..self.breaks.len() - 1].partition_point(|&b| b <= tau);
        let (a, b) = (self.breaks[i], self.breaks[i + 1]);
        let x = (2.0 * tau - a - b) / (b - a);
        let scale = 2.0 / (b - a);
        let mut out = vec![[0.0; 2]; k + 1];
        for q in 0..2 {
            let kept = &self.derived[i][q];
            let mut s = Vec::new();
            let mut f = 1.0;
            for (m, o) in out.iter_mut().enumerate() {
                if m > 0 {
                    f *= scale;
                }
                o[q] = if m <= DERIVED {
                    clenshaw(&kept[m], x) * f
                } else {
                    s = derivative(if m == DERIVED + 1 { &kept[DERIVED][..N + 1 - DERIVED] } else { &s });
                    clenshaw(&s, x) * f
                };
            }
        }
        out
    }
}

impl Field for FootSeries {
    fn arity(&self) -> usize {
        1
    }

    fn jet(&self, at: &[f64], shape: JetShape) -> VecJet {
        let k = shape.orders()[0];
        let d = self.derivatives(at[0], k);
        let comp = |q: usize| {
            let mut v = vec![0.0; shape.len()];
            let mut fact = 1.0;
            for (m, dm) in d.iter().enumerate() {
                if m > 0 {
                    fact *= m as f64;
                }
                v[shape.index([m, 0, 0])] = dm[q] / fact;
            }
            Jet::from_coeffs(shape, v)
        };
        VecJet([comp(0), comp(1), Jet::constant(shape, 0.0)])
    }

    fn derivatives_in(&self, at: &[f64], slot: usize, out: &mut [Vec3]) {
        if out.is_empty() {
            return;
        }
        if slot != 0 {
            out[0] = self.eval(at);
            out[1..].fill(Vec3::ZERO);
            return;
        }
        let d = self.derivatives(at[0], out.len() - 1);
        for (o, d) in out.iter_mut().zip(d) {
            *o = Vec3::new(d[0], d[1], 0.0);
        }
    }

    fn eval(&self, at: &[f64]) -> Vec3 {
        let d = self.derivatives(at[0], 0);
        Vec3::new(d[0][0], d[0][1], 0.0)
    }

    fn is_constant_in(&self, slot: usize) -> bool {
        slot >= 1
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::{ExprField, FieldRef};
    use std::sync::Arc;

    /// The helix on a cylinder of radius 2 of the foot curve's own test, whose foot is
    /// `c(τ) = (τ², τ³)` in closed form: the series' values and derivatives to the fourth
    /// against it at points between the nodes, and its measured error.
    /// The derivative series kept per piece (orders ≤ `DERIVED`) and those derived at the
    /// call (above) give the bits of deriving anew from the coefficients, orders 0 to 14.
    #[test]
    fn kept_derivative_series_are_those_derived_anew() {
        let host: FieldRef =
            Arc::new(ExprField::parse(["2*cos(u)", "2*sin(u)", "v"], &["u", "v", "t"], &|_| None).unwrap());
        let curve = Arc::new(ExprField::parse(["2*cos(s*s)", "2*sin(s*s)", "s*s*s"], &["s"], &|_| None).unwrap());
        let f = FootCurve::new(host, curve, (0.5, 1.5), [0.25, 0.1], 0.0).unwrap();
        let s = FootSeries::new(&f, (0.5, 1.5), 1e-13).unwrap();
        for tau in [0.5, 0.77, 1.2, 1.5] {
            let d = s.derivatives(tau, 14);
            let i = s.breaks[1..s.breaks.len() - 1].partition_point(|&b| b <= tau);
            let (a, b) = (s.breaks[i], s.breaks[i + 1]);
            let (x, scale) = ((2.0 * tau - a - b) / (b - a), 2.0 / (b - a));
            for q in 0..2 {
                let mut c = s.derived[i][q][0].to_vec();
                let mut f = 1.0;
                for (m, dm) in d.iter().enumerate() {
                    if m > 0 {
                        c = derivative(&c);
                        f *= scale;
                    }
                    assert_eq!((clenshaw(&c, x) * f).to_bits(), dm[q].to_bits(), "order {m} at {tau}");
                }
            }
        }
    }

    #[test]
    fn a_helix_foot_against_the_closed_form() {
        let host: FieldRef =
            Arc::new(ExprField::parse(["2*cos(u)", "2*sin(u)", "v"], &["u", "v", "t"], &|_| None).unwrap());
        let curve = Arc::new(ExprField::parse(["2*cos(s*s)", "2*sin(s*s)", "s*s*s"], &["s"], &|_| None).unwrap());
        for range in [(0.5, 1.5), (1.5, 0.5)] {
            let f = FootCurve::new(host.clone(), curve.clone(), range, [0.25, 0.1], 0.0).unwrap();
            let s = FootSeries::new(&f, range, 1e-13).unwrap();
            // τ² and τ³ are polynomials of degree ≤ N: one piece, exact but for round-off
            assert_eq!(s.pieces(), 1);
            assert!(s.max_error() <= 1e-13, "{}", s.max_error());
            for tau in [0.5, 0.61, 0.977, 1.3, 1.5] {
                let d = s.derivatives(tau, 4);
                let want_u = [tau * tau, 2.0 * tau, 2.0, 0.0, 0.0];
                let want_v = [tau.powi(3), 3.0 * tau * tau, 6.0 * tau, 6.0, 0.0];
                for m in 0..=4 {
                    // the m-th derivative of an interpolant of values exact to ~1e-16
                    // loses about N² per order (Markov's inequality on [−1, 1], here
                    // with the factor 2 of the half-width 0.5)
                    let tol = 4e-15 * (2.0 * (N * N) as f64).powi(m as i32);
                    assert!((d[m][0] - want_u[m]).abs() <= tol, "τ {tau} u({m}) {} vs {}", d[m][0], want_u[m]);
                    assert!((d[m][1] - want_v[m]).abs() <= tol, "τ {tau} v({m}) {} vs {}", d[m][1], want_v[m]);
                }
                let j = s.jet(&[tau], JetShape::new(&[2]));
                assert_eq!(j.0[1].coeff([2, 0, 0]), d[2][1] / 2.0);
            }
        }
    }

    /// A foot that is not a polynomial: the circle `τ ↦ (cos τ, sin τ)`
    /// on the plane `(u, v, 0)`, over three quarters of a turn; then the foot of a curve
    /// with a kink in its third derivative, `v = |τ − 0.3|³`, which takes halvings (and
    /// meets the tolerance by them), and one with a corner, which does not.
    #[test]
    fn smooth_feet_in_one_or_a_few_pieces_and_a_kink_by_halving() {
        let plane: FieldRef = Arc::new(ExprField::parse(["u", "v", "0"], &["u", "v", "t"], &|_| None).unwrap());
        let circle = Arc::new(ExprField::parse(["cos(s)", "sin(s)", "0"], &["s"], &|_| None).unwrap());
        let range = (0.0, 4.7);
        let f = FootCurve::new(plane.clone(), circle, range, [1.0, 0.0], 0.0).unwrap();
        let s = FootSeries::new(&f, range, 1e-13).unwrap();
        for tau in [0.1, 1.234, 3.3, 4.69] {
            let d = s.derivatives(tau, 2);
            // one piece of degree 20 over 4.7 rad: seen 1.2e-15 (values), 2e-14 (first
            // derivative, worst at the end), 1.6e-12 (second); each order loses ~N
            assert!((d[0][0] - tau.cos()).abs() <= 1e-14 && (d[0][1] - tau.sin()).abs() <= 1e-14, "{tau}: {d:?}");
            assert!((d[1][0] + tau.sin()).abs() <= 2e-13 && (d[1][1] - tau.cos()).abs() <= 2e-13, "{tau}: {d:?}");
            assert!((d[2][0] + tau.cos()).abs() <= 2e-11 && (d[2][1] + tau.sin()).abs() <= 2e-11, "{tau}: {d:?}");
        }
        let kink = Arc::new(ExprField::parse(["s", "abs(s - 0.3)^3", "0"], &["s"], &|_| None).unwrap());
        let f = FootCurve::new(plane.clone(), kink, (0.0, 1.0), [0.0, 0.0], 0.0).unwrap();
        let s = FootSeries::new(&f, (0.0, 1.0), 1e-13).unwrap();
        // seen: 11 pieces, 1.0e-14
        assert!(s.pieces() > 4, "{} pieces", s.pieces());
        assert!(s.max_error() <= 1e-13, "{}", s.max_error());
        for tau in [0.0, 0.1, 0.29, 0.3, 0.31, 0.8, 1.0] {
            let v = s.derivatives(tau, 0)[0][1];
            assert!((v - (tau - 0.3f64).abs().powi(3)).abs() <= 1e-13, "{tau}: {v}");
        }
        // a corner of the foot (`|τ − 0.3|`) is not met by halving: no series, the caller
        // keeps the exact foot curve
        let corner = Arc::new(ExprField::parse(["s", "abs(s - 0.3)", "0"], &["s"], &|_| None).unwrap());
        let f = FootCurve::new(plane.clone(), corner, (0.0, 1.0), [0.0, 0.0], 0.0).unwrap();
        assert!(FootSeries::new(&f, (0.0, 1.0), 1e-13).is_none());
    }
}
