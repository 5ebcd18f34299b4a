//! Rational B-splines (NURBS) with arbitrary knots, as fields: the curves and surfaces of
//! CAD files.
//!
//! A surface is `S(u, v) = A(u, v) / W(u, v)` with the homogeneous sums
//! `A = Σᵢⱼ Nᵢ(u) Mⱼ(v) wᵢⱼ Pᵢⱼ` and `W = Σᵢⱼ Nᵢ(u) Mⱼ(v) wᵢⱼ`; a curve likewise in one
//! parameter. The Taylor coefficients of `A` and `W` at a point are the basis functions'
//! exact derivatives (The NURBS Book, A2.3) over `i! j!`; `S` is then the jet quotient
//! `A / W` — the quotient rule to every order, exact (no finite differences). Without
//! weights (or all weights equal) `W` is constant and the quotient is skipped.
//!
//! Outside the knot range the end spans' polynomials continue (what a Newton step or a
//! reparametrisation around an edge needs); the domain is [`NurbsSurface::domain`].

use super::{Field, VecJet};
use crate::Vec3;
use crate::jet::{Jet, JetShape};

/// Invalid NURBS input.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum NurbsError {
    /// Degree 0 or above 25.
    #[error("degree {0} is not supported (1 … 25)")]
    Degree(usize),
    /// The knot vector does not fit the control points, is not finite or decreases.
    #[error("{0}")]
    Knots(String),
    /// A control point or weight is not finite, or a weight is not positive.
    #[error("{0}")]
    Points(String),
}

const MAX_DEGREE: usize = 25;

fn check_knots(dir: &str, knots: &[f64], n: usize, p: usize) -> Result<(), NurbsError> {
    if !(1..=MAX_DEGREE).contains(&p) {
        return Err(NurbsError::Degree(p));
    }
    if n < p + 1 {
        return Err(NurbsError::Knots(format!("{dir}: {n} control points are too few for degree {p}")));
    }
    if knots.len() != n + p + 1 {
        return Err(NurbsError::Knots(format!(
            "{dir}: {} knots for {n} control points of degree {p} (needs {})",
            knots.len(),
            n + p + 1
        )));
    }
    if let Some(i) = knots.iter().position(|k| !k.is_finite()) {
        return Err(NurbsError::Knots(format!("{dir}: knot {i} is not finite")));
    }
    if let Some(i) = knots.windows(2).position(|w| w[1] < w[0]) {
        return Err(NurbsError::Knots(format!("{dir}: knot {} is less than knot {i}", i + 1)));
    }
    if knots[n] <= knots[p] {
        return Err(NurbsError::Knots(format!("{dir}: the knot range [{}, {}] is empty", knots[p], knots[n])));
    }
    // no knot of multiplicity above p + 1 inside: the basis would be discontinuous there
    // beyond what A2.3 handles (a span of zero length is skipped by the span search)
    Ok(())
}

/// The span `s` with `knots[s] ≤ x < knots[s + 1]`, `p ≤ s < n`, the end spans taken for
/// `x` outside the range (The NURBS Book A2.1, by bisection).
fn find_span(knots: &[f64], n: usize, p: usize, x: f64) -> usize {
    if x >= knots[n] {
        // the last non-empty span
        let mut s = n - 1;
        while s > p && knots[s] >= knots[n] {
            s -= 1;
        }
        return s;
    }
    if x <= knots[p] {
        let mut s = p;
        while s + 1 < n && knots[s + 1] <= knots[p] {
            s += 1;
        }
        return s;
    }
    let (mut lo, mut hi) = (p, n);
    while hi - lo > 1 {
        let mid = (lo + hi) / 2;
        if x < knots[mid] { hi = mid } else { lo = mid }
    }
    lo
}

/// Basis derivatives `dᵏNᵣ/dxᵏ / k!` for `k ≤ nd` (zero above the degree), at span `s`.
fn basis_taylor(knots: &[f64], p: usize, s: usize, x: f64, nd: usize) -> Vec<Vec<f64>> {
    let mut flat = vec![0.0; (nd + 1) * (p + 1)];
    basis_taylor_into(knots, p, s, x, nd, &mut flat);
    flat.chunks(p + 1).map(<[f64]>::to_vec).collect()
}

/// [`basis_taylor`] into `out` (zeros on entry, `nd + 1` rows of width `p + 1`): the rows
/// `k ≤ min(nd, p)` of A2.3 divided by `k!` in place.
fn basis_taylor_into(knots: &[f64], p: usize, s: usize, x: f64, nd: usize, out: &mut [f64]) {
    super::bspline::basis_derivatives_into(knots, p, s, x, nd, out);
    let mut fact = 1.0;
    for (k, row) in out[..(nd.min(p) + 1) * (p + 1)].chunks_mut(p + 1).enumerate() {
        if k > 0 {
            fact *= k as f64;
        }
        for o in row.iter_mut() {
            *o /= fact;
        }
    }
}

/// A scratch slice, on the stack up to `N` entries and on the heap beyond: a jet's
/// tables, without an allocation at the degrees and orders of CAD faces.
struct Scratch<T, const N: usize> {
    stack: [T; N],
    heap: Vec<T>,
}

impl<T: Copy + Default, const N: usize> Scratch<T, N> {
    fn new() -> Self {
        Scratch { stack: [T::default(); N], heap: Vec::new() }
    }

    /// `n` entries of `T::default()`.
    fn zeroed(&mut self, n: usize) -> &mut [T] {
        if n <= N {
            let s = &mut self.stack[..n];
            s.fill(T::default());
            s
        } else {
            self.heap.clear();
            self.heap.resize(n, T::default());
            &mut self.heap
        }
    }
}

/// Whether a B-spline of degree `p` on `knots` (`n` control points) is `C¹` on its knot
/// range: every knot strictly inside it of multiplicity at most `p − 1` (the basis is
/// `C^{p−m}` at a knot of multiplicity `m`; weights change nothing).
fn c1_knots(knots: &[f64], n: usize, p: usize) -> bool {
    let (lo, hi) = (knots[p], knots[n]);
    let inner: Vec<f64> = knots.iter().copied().filter(|k| lo < *k && *k < hi).collect();
    inner.chunk_by(|a, b| a == b).all(|run| run.len() < p)
}

fn homogeneous(points: &[Vec3], weights: Option<&[f64]>) -> Result<(Vec<[f64; 4]>, bool), NurbsError> {
    if let Some(i) = points.iter().position(|p| !p.is_finite()) {
        return Err(NurbsError::Points(format!("control point {i} is not finite")));
    }
    let Some(w) = weights else {
        return Ok((points.iter().map(|p| [p.x, p.y, p.z, 1.0]).collect(), false));
    };
    if w.len() != points.len() {
        return Err(NurbsError::Points(format!("{} weights for {} control points", w.len(), points.len())));
    }
    if let Some(i) = w.iter().position(|w| !(w.is_finite() && *w > 0.0)) {
        return Err(NurbsError::Points(format!("weight {i} = {} is not a positive number", w[i])));
    }
    let rational = w.iter().any(|x| *x != w[0]);
    Ok((points.iter().zip(w).map(|(p, w)| [p.x * w, p.y * w, p.z * w, *w]).collect(), rational))
}

/// `A / W` from the homogeneous components' Taylor coefficients, component `q` at
/// `c[q n .. (q + 1) n]` for the shape's `n` (`W` constant when not rational: then each
/// coefficient times `1 / W`).
fn quotient_flat(shape: JetShape, c: &[f64], rational: bool) -> VecJet {
    let n = shape.len();
    let part = |q: usize| &c[q * n..(q + 1) * n];
    if rational {
        let w = Jet::from_slice(shape, part(3));
        VecJet(std::array::from_fn(|q| Jet::from_slice(shape, part(q)).div(&w)))
    } else {
        let s = 1.0 / c[3 * n];
        VecJet(std::array::from_fn(|q| Jet::from_scaled_slice(shape, part(q), s)))
    }
}

/// A NURBS surface `S(u, v)` (slots `u`, `v`; constant in a third).
#[derive(Clone, Debug, PartialEq)]
pub struct NurbsSurface {
    pu: usize,
    pv: usize,
    ku: Vec<f64>,
    kv: Vec<f64>,
    nu: usize,
    nv: usize,
    /// `[w x, w y, w z, w]`, index `i nv + j`.
    cw: Vec<[f64; 4]>,
    rational: bool,
}

impl NurbsSurface {
    /// A surface of degrees `(pu, pv)` on the expanded knot vectors `ku`, `kv` with the
    /// `nu × nv` control points `points[i nv + j]` (`i` along `u`) and optional weights in
    /// the same order.
    pub fn new(
        (pu, pv): (usize, usize),
        ku: Vec<f64>,
        kv: Vec<f64>,
        (nu, nv): (usize, usize),
        points: &[Vec3],
        weights: Option<&[f64]>,
    ) -> Result<Self, NurbsError> {
        check_knots("u", &ku, nu, pu)?;
        check_knots("v", &kv, nv, pv)?;
        if points.len() != nu * nv {
            return Err(NurbsError::Points(format!("{} control points for a {nu} × {nv} net", points.len())));
        }
        let (cw, rational) = homogeneous(points, weights)?;
        Ok(NurbsSurface { pu, pv, ku, kv, nu, nv, cw, rational })
    }

    /// The knot ranges `([u₀, u₁], [v₀, v₁])`.
    pub fn domain(&self) -> ((f64, f64), (f64, f64)) {
        ((self.ku[self.pu], self.ku[self.nu]), (self.kv[self.pv], self.kv[self.nv]))
    }

    /// Whether the weights differ (a rational surface).
    pub fn is_rational(&self) -> bool {
        self.rational
    }

    /// Control point `P_ij` (`i` along `u`, `j` along `v`): the homogeneous net's point
    /// divided by its weight.
    fn point(&self, i: usize, j: usize) -> Vec3 {
        let c = &self.cw[i * self.nv + j];
        Vec3::new(c[0] / c[3], c[1] / c[3], c[2] / c[3])
    }

    /// The box of the control points `[lo, hi]`: it holds the surface on its knot ranges
    /// (a B-spline with positive weights is a convex combination of its control points).
    pub fn control_box(&self) -> (Vec3, Vec3) {
        let mut lo = Vec3::new(f64::INFINITY, f64::INFINITY, f64::INFINITY);
        let mut hi = -lo;
        for i in 0..self.cw.len() {
            let p = self.point(i / self.nv, i % self.nv);
            // the points are finite (checked by `new`); a NaN would still propagate
            use crate::num::{max_nan, min_nan};
            lo = Vec3::new(min_nan(lo.x, p.x), min_nan(lo.y, p.y), min_nan(lo.z, p.z));
            hi = Vec3::new(max_nan(hi.x, p.x), max_nan(hi.y, p.y), max_nan(hi.z, p.z));
        }
        (lo, hi)
    }

    /// Whether the surface is `C¹` on its knot ranges (no interior knot of multiplicity `p`
    /// or more in either direction).
    pub fn is_c1(&self) -> bool {
        c1_knots(&self.ku, self.nu, self.pu) && c1_knots(&self.kv, self.nv, self.pv)
    }

    /// Whether the surface's two ends in direction `dir` (0: `u`, 1: `v`) meet `C¹` to
    /// round-off, so that evaluated periodically it is `C¹` across that seam: polynomial,
    /// both ends clamped (knots of multiplicity `p + 1`), and the end rows of the net and of
    /// the derivative's net equal to `1e-9` of the largest of each — at a clamped end the
    /// surface is the B-spline in the other direction on the end row `P_0`, and its
    /// derivative across the one on `p (P_1 − P_0)/(t_{p+1} − t_1)` (at the far end
    /// `p (P_{n−1} − P_{n−2})/(t_{n+p−1} − t_{n−1})`). Rational surfaces: `false`.
    pub fn seam_c1(&self, dir: usize) -> bool {
        if self.rational {
            return false;
        }
        let (k, n, p, m) =
            if dir == 0 { (&self.ku, self.nu, self.pu, self.nv) } else { (&self.kv, self.nv, self.pv, self.nu) };
        let clamped = k[..=p].iter().all(|x| *x == k[0]) && k[n..].iter().all(|x| *x == k[n + p]);
        let (d0, d1) = (k[p + 1] - k[1], k[n + p - 1] - k[n - 1]);
        if !(clamped && n >= 2 && d0 > 0.0 && d1 > 0.0) {
            return false;
        }
        // control point (i along `dir`, j across it)
        let point = |i: usize, j: usize| if dir == 0 { self.point(i, j) } else { self.point(j, i) };
        let (mut size, mut slope, mut gap, mut kink) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
        for j in 0..m {
            let (a, b) = (point(0, j), point(n - 1, j));
            let qa = (point(1, j) - a) * (p as f64 / d0);
            let qb = (b - point(n - 2, j)) * (p as f64 / d1);
            use crate::num::max_nan;
            size = max_nan(size, max_nan(a.norm(), b.norm()));
            slope = max_nan(slope, max_nan(qa.norm(), qb.norm()));
            gap = max_nan(gap, (a - b).norm());
            kink = max_nan(kink, (qa - qb).norm());
        }
        gap <= 1e-9 * size && kink <= 1e-9 * slope
    }

    /// Bounds `[L_u, L_v]` of `|∂S/∂u|` and `|∂S/∂v|` over the knot ranges, or `None` for a
    /// rational surface. `∂S/∂u` is the B-spline of degree `(p_u − 1, p_v)` with control
    /// points `Q_ij = p_u (P_{i+1,j} − P_ij) / (u_{i+p_u+1} − u_{i+1})` (terms over an empty
    /// knot interval vanish), a convex combination of them: `|∂S/∂u| ≤ max |Q_ij|`
    /// (The NURBS Book, eq. 3.17); likewise in `v`. At the ends it is attained.
    pub fn derivative_bounds(&self) -> Option<[f64; 2]> {
        if self.rational {
            return None;
        }
        let mut l = [0.0f64; 2];
        for i in 0..self.nu {
            for j in 0..self.nv {
                if i + 1 < self.nu {
                    let den = self.ku[i + self.pu + 1] - self.ku[i + 1];
                    if den > 0.0 {
                        l[0] = crate::num::max_nan(
                            l[0],
                            self.pu as f64 * (self.point(i + 1, j) - self.point(i, j)).norm() / den,
                        );
                    }
                }
                if j + 1 < self.nv {
                    let den = self.kv[j + self.pv + 1] - self.kv[j + 1];
                    if den > 0.0 {
                        l[1] = crate::num::max_nan(
                            l[1],
                            self.pv as f64 * (self.point(i, j + 1) - self.point(i, j)).norm() / den,
                        );
                    }
                }
            }
        }
        Some(l)
    }

    /// Every evaluation sums `Σ_a N_a Σ_b M_b P_ab` over the homogeneous net `[w x, w y,
    /// w z, w]` for the basis rows `N` (on `u` span `su`) and `M` (on `v` span `sv`) by these
    /// two sums — the inner over a control row, the outer over the rows, skipping
    /// `N_a = 0` — so that their order (and so the bits) is the same everywhere.
    ///
    /// The inner sum `Σ_b M_b P_rb` over control row `r` (the `a`-th of `u` span `su` is
    /// `su − p_u + a`).
    fn inner_sum(&self, r: usize, (sv, rowv): (usize, &[f64])) -> [f64; 4] {
        let base = r * self.nv + sv - self.pv;
        let mut inner = [0.0; 4];
        for (b, mv) in rowv.iter().enumerate() {
            let p = &self.cw[base + b];
            for q in 0..4 {
                inner[q] += mv * p[q];
            }
        }
        inner
    }

    /// The outer sum `Σ_a N_a inner_a`, skipping `N_a = 0`.
    fn outer_sum(rowu: &[f64], inner: &[[f64; 4]]) -> [f64; 4] {
        let mut acc = [0.0; 4];
        for (nu, x) in rowu.iter().zip(inner) {
            if *nu == 0.0 {
                continue;
            }
            for q in 0..4 {
                acc[q] += nu * x[q];
            }
        }
        acc
    }

    /// `S` on the grid `us × vs` (row-major in `u`): each parameter's basis values once,
    /// the inner sums once per control row the grid's `u` spans touch and grid `v`
    /// (they do not depend on `u`), then per point its outer sum — the operations
    /// [`Field::eval`] makes, in the same order (the same bits).
    pub fn grid_values(&self, us: &[f64], vs: &[f64]) -> Vec<Vec3> {
        let basis = |k: &[f64], n: usize, p: usize, x: f64| {
            let s = find_span(k, n, p, x);
            (s, basis_taylor(k, p, s, x, 0).swap_remove(0))
        };
        let bv: Vec<(usize, Vec<f64>)> = vs.iter().map(|&v| basis(&self.kv, self.nv, self.pv, v)).collect();
        let bu: Vec<(usize, Vec<f64>)> = us.iter().map(|&u| basis(&self.ku, self.nu, self.pu, u)).collect();
        // the inner sums of the control rows the grid touches, `inner[r][j]` for grid v `j`
        let mut inner: Vec<Vec<[f64; 4]>> = vec![Vec::new(); self.nu];
        for (su, _) in &bu {
            for (r, row) in inner.iter_mut().enumerate().take(su + 1).skip(su - self.pu) {
                if row.is_empty() {
                    *row = bv.iter().map(|(sv, rowv)| self.inner_sum(r, (*sv, rowv))).collect();
                }
            }
        }
        let mut out = Vec::with_capacity(us.len() * vs.len());
        let mut rows: Vec<[f64; 4]> = vec![[0.0; 4]; self.pu + 1];
        for (su, rowu) in &bu {
            for j in 0..bv.len() {
                for (x, row) in rows.iter_mut().zip(&inner[su - self.pu..]) {
                    *x = row[j];
                }
                let acc = Self::outer_sum(rowu, &rows);
                // as `quotient` divides a constant jet: times the reciprocal of `w`
                let s = 1.0 / acc[3];
                out.push(Vec3::new(acc[0] * s, acc[1] * s, acc[2] * s));
            }
        }
        out
    }
}

impl Field for NurbsSurface {
    fn arity(&self) -> usize {
        2
    }

    fn jet(&self, at: &[f64], shape: JetShape) -> VecJet {
        let [ou, ov, _] = shape.orders();
        let (u, v) = (at[0], at.get(1).copied().unwrap_or(0.0));
        let su = find_span(&self.ku, self.nu, self.pu, u);
        let sv = find_span(&self.kv, self.nv, self.pv, v);
        let (wu, wv) = (self.pu + 1, self.pv + 1);
        // the tables on the stack (a jet is asked for at every Newton step of a foot)
        let (mut bu, mut bv) = (Scratch::<f64, 64>::new(), Scratch::<f64, 64>::new());
        let bu = bu.zeroed((ou + 1) * wu);
        let bv = bv.zeroed((ov + 1) * wv);
        basis_taylor_into(&self.ku, self.pu, su, u, ou, bu);
        basis_taylor_into(&self.kv, self.pv, sv, v, ov, bv);
        let n = shape.len();
        // component `q` at `q n`
        let mut c = Scratch::<f64, 100>::new();
        let c = c.zeroed(4 * n);
        // the inner sums depend on the `v` row alone: made once per row, then summed over
        // `u` (the same operations as in `grid_values` and `eval`, the same bits)
        let mut inner = Scratch::<[f64; 4], 16>::new();
        let inner = inner.zeroed(wu);
        for (k, rowv) in bv.chunks(wv).enumerate() {
            for (a, x) in inner.iter_mut().enumerate() {
                *x = self.inner_sum(su - self.pu + a, (sv, rowv));
            }
            for (i, rowu) in bu.chunks(wu).enumerate() {
                let idx = shape.index([i, k, 0]);
                let acc = Self::outer_sum(rowu, inner);
                for q in 0..4 {
                    c[q * n + idx] = acc[q];
                }
            }
        }
        quotient_flat(shape, c, self.rational)
    }

    fn is_constant_in(&self, slot: usize) -> bool {
        slot >= 2
    }
}

/// A NURBS curve `C(τ)` (slot `τ`; constant in others).
#[derive(Clone, Debug, PartialEq)]
pub struct NurbsCurve {
    p: usize,
    knots: Vec<f64>,
    cw: Vec<[f64; 4]>,
    rational: bool,
}

impl NurbsCurve {
    /// A curve of degree `p` on the expanded knot vector `knots` with optional weights.
    pub fn new(p: usize, knots: Vec<f64>, points: &[Vec3], weights: Option<&[f64]>) -> Result<Self, NurbsError> {
        check_knots("t", &knots, points.len(), p)?;
        let (cw, rational) = homogeneous(points, weights)?;
        Ok(NurbsCurve { p, knots, cw, rational })
    }

    /// The knot range `[τ₀, τ₁]`.
    pub fn domain(&self) -> (f64, f64) {
        (self.knots[self.p], self.knots[self.cw.len()])
    }

    /// Whether the curve is `C¹` on its knot range (no interior knot of multiplicity `p` or
    /// more).
    pub fn is_c1(&self) -> bool {
        c1_knots(&self.knots, self.cw.len(), self.p)
    }

    /// `C` at each of `ts`: per parameter its basis values and the sum [`Field::eval`]
    /// makes, in the same order (the same bits), without a jet.
    pub fn values(&self, ts: &[f64]) -> Vec<Vec3> {
        let n = self.cw.len();
        ts.iter()
            .map(|&t| {
                let s = find_span(&self.knots, n, self.p, t);
                let row = basis_taylor(&self.knots, self.p, s, t, 0).swap_remove(0);
                let mut acc = [0.0; 4];
                for (a, nb) in row.iter().enumerate() {
                    let p = &self.cw[s - self.p + a];
                    for q in 0..4 {
                        acc[q] += nb * p[q];
                    }
                }
                // as `quotient` divides a constant jet: times the reciprocal of `w`
                let r = 1.0 / acc[3];
                Vec3::new(acc[0] * r, acc[1] * r, acc[2] * r)
            })
            .collect()
    }
}

impl Field for NurbsCurve {
    fn arity(&self) -> usize {
        1
    }

    fn jet(&self, at: &[f64], shape: JetShape) -> VecJet {
        let [o, _, _] = shape.orders();
        let n = self.cw.len();
        let s = find_span(&self.knots, n, self.p, at[0]);
        let w = self.p + 1;
        let mut b = Scratch::<f64, 64>::new();
        let b = b.zeroed((o + 1) * w);
        basis_taylor_into(&self.knots, self.p, s, at[0], o, b);
        let n = shape.len();
        let mut c = Scratch::<f64, 100>::new();
        let c = c.zeroed(4 * n);
        for (k, row) in b.chunks(w).enumerate() {
            let idx = shape.index([k, 0, 0]);
            for (a, nb) in row.iter().enumerate() {
                let p = &self.cw[s - self.p + a];
                for q in 0..4 {
                    c[q * n + idx] += nb * p[q];
                }
            }
        }
        quotient_flat(shape, c, self.rational)
    }

    fn is_constant_in(&self, slot: usize) -> bool {
        slot >= 1
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::FRAC_1_SQRT_2;

    /// `C¹` by the knots: a double knot in a cubic keeps it, a triple one (or a double one
    /// in a quadratic) does not; the ends' multiplicities do not count; weights do not
    /// matter.
    #[test]
    fn c1_by_the_knots() {
        let k = |inner: &[f64], p: usize| [vec![0.0; p + 1], inner.to_vec(), vec![1.0; p + 1]].concat();
        let curve = |inner: &[f64], p: usize| {
            let knots = k(inner, p);
            let n = knots.len() - p - 1;
            let pts: Vec<Vec3> = (0..n).map(|i| Vec3::new(i as f64, (i * i) as f64, 0.0)).collect();
            NurbsCurve::new(p, knots, &pts, Some(&vec![0.5 + 0.0 * n as f64; n])).unwrap()
        };
        assert!(curve(&[], 3).is_c1());
        assert!(curve(&[0.5, 0.5], 3).is_c1());
        assert!(!curve(&[0.5, 0.5, 0.5], 3).is_c1());
        assert!(!curve(&[0.2, 0.5, 0.5], 2).is_c1());
        assert!(curve(&[0.2, 0.5], 2).is_c1());
        assert!(!curve(&[0.5], 1).is_c1());
        let surface = |ku: &[f64], kv: &[f64]| {
            let (ku, kv) = (k(ku, 3), k(kv, 2));
            let (nu, nv) = (ku.len() - 4, kv.len() - 3);
            let pts: Vec<Vec3> =
                (0..nu * nv).map(|i| Vec3::new((i / nv) as f64, (i % nv) as f64, 0.1 * i as f64)).collect();
            NurbsSurface::new((3, 2), ku, kv, (nu, nv), &pts, None).unwrap()
        };
        assert!(surface(&[0.3, 0.3], &[0.6]).is_c1());
        assert!(!surface(&[0.3, 0.3, 0.3], &[0.6]).is_c1());
        assert!(!surface(&[0.3], &[0.6, 0.6]).is_c1());
    }

    /// A curve's values at many parameters are `eval`'s, bit for bit: degree 5 with a
    /// double interior knot, rational and not, at knots, ends and points between. It fails
    /// with `x / w` in place of `x · (1/w)`.
    #[test]
    fn curve_values_are_eval_bit_for_bit() {
        let p = 5;
        let mut k = vec![-0.5; p + 1];
        k.extend([0.1, 0.3, 0.3, 0.8]);
        k.extend(vec![2.0; p + 1]);
        let n = k.len() - p - 1;
        let pts: Vec<Vec3> =
            (0..n).map(|i| Vec3::new(i as f64 * 0.7, (1.1 * i as f64).sin(), 0.3 * (i * i) as f64 - 0.9)).collect();
        let weights: Vec<f64> = (0..n).map(|i| 0.6 + 0.37 * ((i * 5 % 7) as f64)).collect();
        let ts: Vec<f64> = (0..=97).map(|i| -0.5 + 2.5 * i as f64 / 97.0).chain([0.3, 0.1 - 1e-14]).collect();
        for w in [Some(&weights[..]), None] {
            let c = NurbsCurve::new(p, k.clone(), &pts, w).unwrap();
            for (x, t) in c.values(&ts).into_iter().zip(&ts) {
                let e = c.eval(&[*t]);
                let bits = |p: Vec3| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()];
                assert_eq!(bits(x), bits(e), "at {t}: {x} vs {e}");
            }
        }
    }

    /// The grid evaluation is `eval` at every grid point, bit for bit: a rational surface of
    /// degrees (13, 3) with interior knots (a double one too), and a polynomial one, on
    /// grids that hit knots, the ends and points between.
    #[test]
    fn grid_values_are_eval_bit_for_bit() {
        let (pu, pv, nu, nv) = (13, 3, 18, 6);
        let mut ku = vec![0.0; pu + 1];
        ku.extend([0.2, 0.45, 0.45, 0.7]);
        ku.extend(vec![1.0; pu + 1]);
        let mut kv = vec![-1.0; pv + 1];
        kv.extend([0.0, 0.5]);
        kv.extend(vec![2.0; pv + 1]);
        let pts: Vec<Vec3> = (0..nu * nv)
            .map(|k| {
                let (i, j) = ((k / nv) as f64, (k % nv) as f64);
                Vec3::new(i + 0.1 * j * j, j - 0.05 * i * j, (0.7 * i).sin() + (1.3 * j).cos())
            })
            .collect();
        let weights: Vec<f64> = (0..nu * nv).map(|k| 1.0 + 0.4 * ((k * 7 % 11) as f64 / 11.0)).collect();
        let us: Vec<f64> = (0..=40).map(|i| i as f64 / 40.0).chain([0.45, 0.2 + 1e-13]).collect();
        let vs: Vec<f64> = (0..=30).map(|j| -1.0 + 3.0 * j as f64 / 30.0).chain([0.5]).collect();
        for w in [Some(&weights[..]), None] {
            let s = NurbsSurface::new((pu, pv), ku.clone(), kv.clone(), (nu, nv), &pts, w).unwrap();
            let g = s.grid_values(&us, &vs);
            for (k, x) in g.iter().enumerate() {
                let e = s.eval(&[us[k / vs.len()], vs[k % vs.len()]]);
                let bits = |p: Vec3| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()];
                assert_eq!(bits(*x), bits(e), "at index {k}: {x} vs {e}");
            }
        }
    }

    /// The quarter circle as a rational quadratic Bézier (control points (1,0), (1,1),
    /// (0,1), weights 1, √2/2, 1) against its homogeneous polynomials written out by hand,
    /// `A = (1 + (2w−2)τ + (1−2w)τ², 2wτ + (1−2w)τ²)`, `W = 1 + (2w−2)τ + (2−2w)τ²`, and
    /// the quotient rule to the second derivative.
    #[test]
    fn quarter_circle_against_the_quotient_rule_by_hand() {
        let w = FRAC_1_SQRT_2;
        let pts = [Vec3::new(1.0, 0.0, 0.0), Vec3::new(1.0, 1.0, 0.0), Vec3::new(0.0, 1.0, 0.0)];
        let c = NurbsCurve::new(2, vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0], &pts, Some(&[1.0, w, 1.0])).unwrap();
        for t in [0.0, 0.3, 0.71, 1.0] {
            // A = (a0 + a1 t + a2 t², …), W = w0 + w1 t + w2 t²: coefficients by hand
            let ax = [1.0, 2.0 * w - 2.0, 1.0 - 2.0 * w];
            let ay = [0.0, 2.0 * w, 1.0 - 2.0 * w];
            let ww = [1.0, 2.0 * w - 2.0, 2.0 - 2.0 * w];
            let poly = |c: &[f64; 3], t: f64| [c[0] + c[1] * t + c[2] * t * t, c[1] + 2.0 * c[2] * t, 2.0 * c[2]];
            let (x, y, wv) = (poly(&ax, t), poly(&ay, t), poly(&ww, t));
            // quotient rule: f = a/w, f' = (a' − f w')/w, f'' = (a'' − 2 f' w' − f w'')/w
            let q = |a: [f64; 3]| {
                let f0 = a[0] / wv[0];
                let f1 = (a[1] - f0 * wv[1]) / wv[0];
                let f2 = (a[2] - 2.0 * f1 * wv[1] - f0 * wv[2]) / wv[0];
                [f0, f1, f2]
            };
            let (fx, fy) = (q(x), q(y));
            let j = c.jet(&[t], JetShape::new(&[2]));
            for k in 0..3 {
                let d = j.derivative([k, 0, 0]);
                // a few ulps of the values (≤ 2 in size): round-off of the jet division
                assert!((d.x - fx[k]).abs() < 1e-14 && (d.y - fy[k]).abs() < 1e-14, "t {t} k {k}: {d}");
            }
            // on the unit circle
            assert!((j.value().norm() - 1.0).abs() < 1e-15);
        }
    }

    /// A bilinear-times-quadratic surface with distinct inner knots against its closed
    /// form: the tensor product of a degree-1 curve in `u` (knots 0 0 1 2 2: the hat
    /// functions) and a clamped quadratic Bézier in `v`, weights all 2 (not rational).
    #[test]
    fn tensor_product_against_the_closed_form() {
        let ku = vec![0.0, 0.0, 1.0, 2.0, 2.0];
        let kv = vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0];
        let mut pts = Vec::new();
        for i in 0..3 {
            for j in 0..3 {
                pts.push(Vec3::new(i as f64, j as f64, (i * j) as f64));
            }
        }
        let s = NurbsSurface::new((1, 2), ku, kv, (3, 3), &pts, Some(&[2.0; 9])).unwrap();
        assert!(!s.is_rational());
        // x = u (hat functions interpolate i at u = i), y = 2v (Bézier of 0,1,2), z = Σ i j …
        for (u, v) in [(0.3, 0.2), (1.5, 0.9), (1.0, 0.5)] {
            let j = s.jet(&[u, v], JetShape::new(&[1, 2]));
            let bz = |c: [f64; 3], v: f64| c[0] * (1.0 - v).powi(2) + 2.0 * c[1] * v * (1.0 - v) + c[2] * v * v;
            // x(u) = u, y = 2v, z = u · (Bézier of 0, 1, 2) = u · 2v
            let want = Vec3::new(u, bz([0.0, 1.0, 2.0], v), u * bz([0.0, 1.0, 2.0], v));
            assert!((j.value() - want).norm() < 1e-15, "{u} {v}");
            assert!((j.derivative([1, 1, 0]) - Vec3::new(0.0, 0.0, 2.0)).norm() < 1e-14);
            assert!((j.derivative([0, 2, 0])).norm() < 1e-13);
        }
    }

    /// Bézier surfaces of degrees (17, 9) and (5, 2) whose net gives `x = u`, `y = v`,
    /// `z = u³ v²` (`uᵏ = Σᵢ C(i, k)/C(p, k) Bᵢᵖ(u)`), against the Taylor coefficients of
    /// `u³ v²` by hand, `C(3, i) u³⁻ⁱ C(2, j) v²⁻ʲ`, through shapes `[5, 5]` and `[2, 2]`:
    /// the jet's tables on the heap (degree 17, 36 coefficients) and on the stack.
    #[test]
    fn high_degree_jets_against_the_power_form() {
        let c =
            |n: usize, k: usize| if k > n { 0.0 } else { (0..k).map(|i| (n - i) as f64 / (k - i) as f64).product() };
        for ((pu, pv), o) in [((17, 9), 5), ((5, 2), 2), ((9, 3), 3)] {
            let knots = |p: usize| [vec![0.0; p + 1], vec![1.0; p + 1]].concat();
            let pts: Vec<Vec3> = (0..(pu + 1) * (pv + 1))
                .map(|k| {
                    let (i, j) = (k / (pv + 1), k % (pv + 1));
                    let z = c(i, 3) / c(pu, 3) * c(j, 2) / c(pv, 2);
                    Vec3::new(i as f64 / pu as f64, j as f64 / pv as f64, z)
                })
                .collect();
            let s = NurbsSurface::new((pu, pv), knots(pu), knots(pv), (pu + 1, pv + 1), &pts, None).unwrap();
            for (u, v) in [(0.3, 0.8), (0.91, 0.05), (0.5, 0.5)] {
                let shape = JetShape::new(&[o, o]);
                let j = s.jet(&[u, v], shape);
                for i in 0..=o {
                    for k in 0..=o {
                        let m = [i, k, 0];
                        let z = c(3, i) * u.powi(3 - i.min(3) as i32) * c(2, k) * v.powi(2 - k.min(2) as i32);
                        let x = [u, 1.0][..].get(i).copied().filter(|_| k == 0).unwrap_or(0.0);
                        let y = [v, 1.0][..].get(k).copied().filter(|_| i == 0).unwrap_or(0.0);
                        let got = Vec3::new(j.0[0].coeff(m), j.0[1].coeff(m), j.0[2].coeff(m));
                        // round-off: the sum cancels basis coefficients of size `Σ|Nᵢ|Σ|Mₖ|`
                        // (up to 1e4 at degree 17, order 5) over a net of points ≤ 1, a few
                        // dozen ulps of that
                        let size = |k: &[f64], p: usize, x: f64, r: usize| {
                            basis_taylor(k, p, p, x, r)[r].iter().map(|b| b.abs()).sum::<f64>()
                        };
                        let tol = 64.0 * f64::EPSILON * size(&knots(pu), pu, u, i) * size(&knots(pv), pv, v, k);
                        assert!(
                            (got - Vec3::new(x, y, z)).norm() <= tol,
                            "{pu} {pv} ({u}, {v}) {m:?}: {got} tol {tol}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn bad_input_is_named() {
        let pts = [Vec3::ZERO; 3];
        let e = NurbsCurve::new(2, vec![0.0, 0.0, 1.0, 1.0], &pts, None).unwrap_err();
        assert_eq!(e.to_string(), "t: 4 knots for 3 control points of degree 2 (needs 6)");
        let e = NurbsCurve::new(2, vec![0.0, 0.0, 0.0, 1.0, 1.0, 1.0], &pts, Some(&[1.0, 0.0, 1.0])).unwrap_err();
        assert_eq!(e.to_string(), "weight 1 = 0 is not a positive number");
        let e = NurbsCurve::new(2, vec![0.0, 0.0, 0.0, 1.0, 0.5, 1.0], &pts, None).unwrap_err();
        assert_eq!(e.to_string(), "t: knot 4 is less than knot 3");
    }
}
