//! Fixed linear combinations of a condition set's cardinal functions, evaluated at any `u`
//! without allocating.
//!
//! A spectral patch needs, per Fourier mode, `A(u) = Σ_i ℓ_i(u) a_i` for six fixed numbers
//! per condition (the data's cosine and sine coefficients, three components each). Each
//! way a [`CardinalSet`] is computed writes its functions in a basis,
//! `ℓ_i(u) = Σ_b φ_b(u) C_{bi}`, so
//!
//! ```text
//! F_c(u) = Σ_i ℓ_i(u) W_{ic} = Σ_b φ_b(u) (C W)_{bc}
//! ```
//!
//! and `C W` is computed once. A point then costs the basis at `u` (two exponentials and a
//! polynomial factor per root for the exponential basis, a three-term recurrence for
//! Chebyshev series) and one small matrix–vector product, instead of every cardinal
//! function and then the sum over conditions. The derivatives `F_c^{(k)}` are the same
//! products with the basis's derivatives (exponential basis), with the set's own
//! derivative series (Chebyshev series), or — for polynomials — with the Chebyshev series
//! of `C W` differentiated term by term in double-double, so they are exact in the same
//! sense as [`CardinalSet::eval`]; the two agree to round-off (reassociated sums), which
//! `spectral::batch`'s tests measure. A spectral patch's rows read a polynomial mode
//! through its combination too ([`Combined::polynomial`]), so there both paths give the
//! same numbers.
//!
//! Where the set answers from stored rows (every form at its conditions' places, where
//! the rows are the cardinal property's own)
//! or its basis has no closed form here (clustered roots, piecewise multiple-precision
//! tables), the combination falls back to [`CardinalSet::eval`] and the weights.

use super::{CardinalSet, Root};
use std::sync::Arc;

/// How the combination is evaluated.
#[derive(Clone, Debug)]
enum Kind {
    /// `ker (D² − c²)^N`, `c > 0`, no clustered roots: basis `(u − 1)ᵏ e^{c(u−1)}`,
    /// `k < N`, then `uᵏ e^{−cu}` (the order of [`super::ExpSpace::derivatives`]); `mat`
    /// is `Cᵀ`, `2N × 2N`, row-major (row `i`: `ℓ_i`'s coefficients), then the weights.
    Exp { c: f64, n: usize, mat: Vec<f64> },
    /// A zero root of multiplicity `dim`: `T_b(2u − 1)`, `b < dim`;
    /// `cw[k]` holds the Chebyshev series of `F_c^{(k)}` (`dim × cols`, row-major, each
    /// entry rounded once): `C W` in double-double, differentiated term by term in
    /// double-double (`d_{b−1} = d_{b+1} + 2b c_b`, then `d/du = 2 d/dx`). A point then
    /// costs one `T_b` table and `dim × cols` products per order (mode 0 of an order-40
    /// patch: 40 × 6 instead of 40 × 40 and 40 × 6).
    Poly { dim: usize, cw: Vec<Vec<f64>> },
    /// Chebyshev series in `x = 2u − 1`: `mats[k]` holds the combined series of the
    /// `ℓ_i^{(k)}`, `cols × size`, row `c` the series of `F_c^{(k)}` (one dot product with
    /// `T_m(x)` per column, as [`super::UltraCardinal::eval`] does per function).
    /// `need` is the longest of the `lens`: the terms a point needs.
    Cheb { size: usize, mats: Vec<Vec<f64>>, lens: Vec<Vec<usize>>, need: usize },
    /// Through [`CardinalSet::eval`].
    Generic,
}

/// `F_c(u) = Σ_i ℓ_i(u) W_{ic}` for the columns `c` of fixed weights `W`.
#[derive(Clone, Debug)]
pub struct Combined {
    kind: Kind,
    set: Arc<CardinalSet>,
    /// `W`, `dim × cols`, row-major (the fallback's weights).
    weights: Vec<f64>,
    cols: usize,
    kmax: usize,
    /// Where the set answers from stored rows (sorted): evaluated through the set there,
    /// so that both paths give the stored values.
    stored_at: Vec<f64>,
}

/// `out[c] = Σ_b phi[b] mat[b·cols + c]`.
#[inline]
fn row_times(phi: &[f64], mat: &[f64], cols: usize, out: &mut [f64]) {
    out.fill(0.0);
    for (b, &p) in phi.iter().enumerate() {
        let m = &mat[b * cols..(b + 1) * cols];
        for (o, &x) in out.iter_mut().zip(m) {
            *o += p * x;
        }
    }
}

/// `t[m] = T_m(x)` for `m < t.len()` (at least 2), by the three-term recurrence of
/// [`super::UltraCardinal::eval`].
pub fn chebyshev_t(x: f64, t: &mut [f64]) {
    (t[0], t[1]) = (1.0, x);
    for j in 2..t.len() {
        t[j] = 2.0 * x * t[j - 1] - t[j - 2];
    }
}

/// A double-double number `hi + lo`, `|lo| ≤ ulp(hi) / 2`.
#[derive(Clone, Copy, Debug)]
struct Dd {
    hi: f64,
    lo: f64,
}

impl Dd {
    const ZERO: Dd = Dd { hi: 0.0, lo: 0.0 };

    /// `x y` exactly (FMA).
    fn product(x: f64, y: f64) -> Dd {
        let hi = x * y;
        Dd { hi, lo: x.mul_add(y, -hi) }
    }

    /// The sum, by Knuth's error-free two-sum of the high parts.
    fn add(self, o: Dd) -> Dd {
        let s = self.hi + o.hi;
        let bb = s - self.hi;
        let e = (self.hi - (s - bb)) + (o.hi - bb) + self.lo + o.lo;
        let hi = s + e;
        Dd { hi, lo: e - (hi - s) }
    }

    /// `k · self` for a small integer `k` (the high part's product exact by FMA).
    fn scale(self, k: f64) -> Dd {
        Dd::product(self.hi, k).add(Dd { hi: self.lo * k, lo: 0.0 })
    }

    fn round(self) -> f64 {
        self.hi + self.lo
    }
}

/// The Chebyshev series of `d/du Σ_b c_b T_b(2u − 1)` (`c`: `dim × cols`, row-major, row
/// `b` the coefficients of `T_b`): `d_{b−1} = d_{b+1} + 2b c_b` from the top, `d_0` halved
/// (the series in `x`), then doubled for `dx/du = 2`.
fn chebyshev_derivative(c: &[Dd], dim: usize, cols: usize) -> Vec<Dd> {
    let mut d = vec![Dd::ZERO; dim * cols];
    for col in 0..cols {
        for b in (1..dim).rev() {
            let above = if b + 1 < dim { d[(b + 1) * cols + col] } else { Dd::ZERO };
            d[(b - 1) * cols + col] = above.add(c[b * cols + col].scale(2.0 * b as f64));
        }
        d[col] = d[col].scale(0.5);
    }
    for x in &mut d {
        *x = x.scale(2.0);
    }
    d
}

/// Binomial coefficient as f64 (as in [`super::ExpSpace::derivatives`]).
fn binom(n: usize, k: usize) -> f64 {
    (0..k).fold(1.0, |acc, i| acc * (n - i) as f64 / (i + 1) as f64)
}

impl Combined {
    /// Combines the functions of `set` with `weights` (`dim × cols`, row-major: row `i`
    /// weighs `ℓ_i`); derivatives up to `kmax` will be asked for.
    pub fn new(set: &Arc<CardinalSet>, weights: Vec<f64>, cols: usize, kmax: usize) -> Self {
        let dim = weights.len() / cols.max(1);
        let (kind, stored_at) = match set.as_ref() {
            CardinalSet::Direct(card) => {
                let space = card.space();
                let coef = card.coefficients();
                // C itself: ℓ first, then the weights, the association of
                // `CardinalSet::eval` and the pointwise sum over conditions (the
                // exponential basis of slow modes is far from orthogonal, and `C W`
                // reassociated moved the sums by ~1e-13 relative at c = 0.9, N = 3)
                let mat: Vec<f64> =
                    (0..dim).flat_map(|i| (0..dim).map(move |b| (b, i))).map(|(b, i)| coef[(b, i)]).collect();
                let kind = match space.roots() {
                    _ if space.clustered() => Kind::Generic,
                    [Root { re, im: 0.0, mult }] if *re == 0.0 => {
                        // (C W)_bc = Σ_i C_bi W_ic in double-double (exact products by FMA,
                        // error-free sums), its derivative series in double-double too, each
                        // rounded once: the folded sums lose no more than the pointwise ones
                        let mut ddw = vec![Dd::ZERO; dim * cols];
                        for b in 0..dim {
                            for c in 0..cols {
                                ddw[b * cols + c] = (0..dim)
                                    .fold(Dd::ZERO, |acc, i| acc.add(Dd::product(coef[(b, i)], weights[i * cols + c])));
                            }
                        }
                        // the derivatives up to kmax; those above the degree vanish
                        let mut cw = vec![ddw.iter().map(|d| d.round()).collect::<Vec<f64>>()];
                        for _ in 0..kmax.min(dim.saturating_sub(1)) {
                            ddw = chebyshev_derivative(&ddw, dim, cols);
                            cw.push(ddw.iter().map(|d| d.round()).collect());
                        }
                        Kind::Poly { dim: *mult, cw }
                    }
                    [Root { re: p, im: 0.0, mult: m1 }, Root { re: q, im: 0.0, mult: m2 }]
                        if *p > 0.0 && *q == -*p && m1 == m2 =>
                    {
                        Kind::Exp { c: *p, n: *m1, mat }
                    }
                    _ => Kind::Generic,
                };
                // at the conditions' places the set answers the cardinal property's rows
                (kind, card.condition_places())
            }
            CardinalSet::Ultraspherical(card) if card.kmax() >= kmax => {
                let size = card.terms();
                let mats = (0..=kmax)
                    .map(|k| {
                        // row c: Σ_i W_ic (series of ℓ_i^{(k)}), i ascending
                        let s = card.series(k);
                        let mut m = vec![0.0; cols * size];
                        for c in 0..cols {
                            for (i, ser) in s.iter().enumerate() {
                                let w = weights[i * cols + c];
                                for (dst, x) in m[c * size..(c + 1) * size].iter_mut().zip(ser) {
                                    *dst += w * x;
                                }
                            }
                        }
                        m
                    })
                    .collect::<Vec<_>>();
                // each combined series ends at its last coefficient above 2⁻⁵⁶ of its
                // largest: the terms dropped change a value by less than that in all (|T_m| ≤
                // 1). The solve's series carry ~40 terms of margin (order 40: 82 … 106
                // terms, none above 1e-17 after the 48th … 64th), which cost a point half
                // its time.
                let lens: Vec<Vec<usize>> = mats
                    .iter()
                    .map(|m| {
                        m.chunks_exact(size)
                            .map(|ser| {
                                let big = ser.iter().fold(0.0f64, |a, x| crate::num::max_nan(a, x.abs()));
                                let mut tail = 0.0;
                                let mut len = size;
                                while len > 0 && tail + ser[len - 1].abs() <= big * 2f64.powi(-56) {
                                    tail += ser[len - 1].abs();
                                    len -= 1;
                                }
                                len
                            })
                            .collect()
                    })
                    .collect();
                let need = lens.iter().flatten().copied().max().unwrap_or(0);
                let mut at = card.stored_points();
                at.sort_by(f64::total_cmp);
                (Kind::Cheb { size, mats, lens, need }, at)
            }
            _ => (Kind::Generic, Vec::new()),
        };
        Combined { kind, set: set.clone(), weights, cols, kmax, stored_at }
    }

    /// Columns.
    pub fn cols(&self) -> usize {
        self.cols
    }

    /// The combination with every derivative order, when the set's functions are
    /// polynomials held in the Chebyshev basis (a single zero root, not clustered): a
    /// point then costs `T_b(2u − 1)` and one product per order, and the derivatives'
    /// series are exact to one rounding of each coefficient. None for any other set.
    pub fn polynomial(set: &Arc<CardinalSet>, weights: Vec<f64>, cols: usize) -> Option<Self> {
        let c = Combined::new(set, weights, cols, usize::MAX);
        matches!(c.kind, Kind::Poly { .. }).then_some(c)
    }

    /// The rate `c` when the basis is `e^{±c…}` (the caller may pass the exponentials).
    pub fn rate(&self) -> Option<f64> {
        match self.kind {
            Kind::Exp { c, .. } => Some(c),
            _ => None,
        }
    }

    /// Scratch length that [`eval`](Self::eval) needs.
    pub fn scratch_len(&self) -> usize {
        match &self.kind {
            // the basis table and one row of cardinal functions
            Kind::Exp { n, .. } => (self.kmax + 2) * 2 * n,
            Kind::Poly { dim, .. } => (*dim).max(2),
            Kind::Cheb { size, .. } => (*size).max(2),
            Kind::Generic => 0,
        }
    }

    /// Chebyshev terms `T_m(2u − 1)` that [`eval`](Self::eval) reads (0 unless the
    /// functions are Chebyshev series or polynomials in the Chebyshev basis).
    pub fn chebyshev_terms(&self) -> usize {
        match &self.kind {
            // the longest combined series, not the solve's (its margin is dropped)
            Kind::Cheb { need, .. } => *need,
            // the basis itself, for values
            Kind::Poly { dim, .. } => *dim,
            _ => 0,
        }
    }

    /// `out[k·cols + c] = F_c^{(k)}(u)` for `k ≤ kmax` (`kmax` at most the one given to
    /// [`new`](Self::new)). `exps`, when given, is `(e^{c(u−1)}, e^{−cu})` for the rate
    /// of [`rate`](Self::rate) (a caller running over modes `c = a m` gets them by
    /// products); `cheb` is `T_m(2u − 1)` for `m < cheb.len()`, computed once per point by
    /// a caller with several combinations (when shorter than
    /// [`chebyshev_terms`](Self::chebyshev_terms), computed here); `scratch` is at least
    /// [`scratch_len`](Self::scratch_len) long.
    pub fn eval(
        &self,
        u: f64,
        kmax: usize,
        exps: Option<(f64, f64)>,
        cheb: &[f64],
        scratch: &mut [f64],
        out: &mut [f64],
    ) {
        assert!(kmax <= self.kmax, "derivative order {kmax} was not combined (at most {})", self.kmax);
        let cols = self.cols;
        let generic = matches!(self.kind, Kind::Generic)
            || (!self.stored_at.is_empty() && self.stored_at.binary_search_by(|x| x.total_cmp(&u)).is_ok());
        if generic {
            let rows = self.set.eval(u, kmax);
            for (k, row) in rows.iter().enumerate() {
                row_times(row, &self.weights, cols, &mut out[k * cols..(k + 1) * cols]);
            }
            return;
        }
        match &self.kind {
            Kind::Exp { c, n, mat } => {
                let (n, c) = (*n, *c);
                let dim = 2 * n;
                let (ep, em) = exps.unwrap_or_else(|| ((c * (u - 1.0)).exp(), (-c * u).exp()));
                // φ^{(j)} of wᵏ e^{rw} = e^{rw} Σ_i C(j,i) k!/(k−i)! w^{k−i} r^{j−i}: for
                // j ≤ 2 written out over the powers of w, above by the sum
                for (side, (r, w, e)) in [(c, u - 1.0, ep), (-c, u, em)].into_iter().enumerate() {
                    let mut wk = [1.0, 0.0, 0.0]; // w^k, w^{k−1}, w^{k−2} (0 for negative powers)
                    for k in 0..n {
                        let kf = k as f64;
                        for j in 0..=kmax {
                            let v = match j {
                                0 => wk[0],
                                1 => r * wk[0] + kf * wk[1],
                                2 => r * r * wk[0] + 2.0 * r * kf * wk[1] + kf * (kf - 1.0) * wk[2],
                                _ => {
                                    let mut s = 0.0;
                                    let mut fall = 1.0;
                                    for i in 0..=j.min(k) {
                                        if i > 0 {
                                            fall *= (k - i + 1) as f64;
                                        }
                                        s += r.powi((j - i) as i32) * (binom(j, i) * fall * w.powi((k - i) as i32));
                                    }
                                    s
                                }
                            };
                            scratch[j * dim + side * n + k] = v * e;
                        }
                        wk = [wk[0] * w, wk[0], wk[1]];
                    }
                }
                self.through_cardinals(dim, kmax, mat, scratch, out);
            }
            Kind::Poly { dim, cw, .. } => {
                let dim = *dim;
                let tj: &[f64] = if cheb.len() >= dim {
                    // the caller's T_b(2u − 1): the same recurrence, the same numbers
                    &cheb[..dim]
                } else {
                    chebyshev_t(2.0 * u - 1.0, &mut scratch[..dim.max(2)]);
                    &scratch[..dim]
                };
                for k in 0..=kmax {
                    let dst = &mut out[k * cols..(k + 1) * cols];
                    match cw.get(k) {
                        Some(series) => row_times(tj, series, cols, dst),
                        None => dst.fill(0.0),
                    }
                }
            }
            Kind::Cheb { size, mats, lens, need } => {
                let size = *size;
                let tj: &[f64] = if cheb.len() >= *need {
                    &cheb[..*need]
                } else {
                    chebyshev_t(2.0 * u - 1.0, &mut scratch[..(*need).max(2)]);
                    &scratch[..*need]
                };
                for (k, (mat, lens)) in mats.iter().zip(lens).enumerate().take(kmax + 1) {
                    let dst = &mut out[k * cols..(k + 1) * cols];
                    for ((o, series), &len) in dst.iter_mut().zip(mat.chunks_exact(size)).zip(lens) {
                        *o = crate::num::dot(&series[..len], &tj[..len]);
                    }
                }
            }
            Kind::Generic => unreachable!("handled above"),
        }
    }

    /// From the basis table `scratch[j·dim + b] = φ_b^{(j)}`: `ℓ^{(j)} = φ^{(j)} C` (`ct`
    /// = `Cᵀ`) into the scratch's second half, then the weights.
    fn through_cardinals(&self, dim: usize, kmax: usize, ct: &[f64], scratch: &mut [f64], out: &mut [f64]) {
        let cols = self.cols;
        let (phi, ell) = scratch.split_at_mut((kmax + 1) * dim);
        for j in 0..=kmax {
            let l = &mut ell[..dim];
            let p = &phi[j * dim..(j + 1) * dim];
            // ℓ_i = Σ_b φ_b C_bi, b ascending (as `Cardinal::eval`)
            for (li, row) in l.iter_mut().zip(ct.chunks_exact(dim)) {
                *li = p.iter().zip(row).map(|(x, y)| x * y).sum();
            }
            row_times(l, &self.weights, cols, &mut out[j * cols..(j + 1) * cols]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::num::max_nan;
    use crate::ode::{CondSpec, ExpSpace};
    use astro_float::{BigFloat, RoundingMode};

    /// `∂ᵏ/∂uᵏ Σ_b T_b(2u − 1) Σ_i C_bi W_ic` in 256-bit arithmetic from the f64 `C` and
    /// `W`: the `T_b^{(k)}` by their own recurrence, not by differentiated series.
    fn exact(c: &faer::Mat<f64>, w: &[f64], cols: usize, col: usize, u: f64, k: usize) -> f64 {
        const P: usize = 256;
        let rm = RoundingMode::ToEven;
        let f = |x: f64| BigFloat::from_f64(x, P);
        let dim = c.nrows();
        let x = f(2.0).mul(&f(u), P, rm).sub(&f(1.0), P, rm);
        // t[j][b] = T_b^{(j)}(x)
        let mut t = vec![vec![f(0.0); dim]; k + 1];
        for j in 0..=k {
            for b in 0..dim {
                t[j][b] = match (b, j) {
                    (0, 0) => f(1.0),
                    (0, _) => f(0.0),
                    (1, 0) => x.clone(),
                    (1, 1) => f(1.0),
                    (1, _) => f(0.0),
                    _ => {
                        let a = f(2.0).mul(&x, P, rm).mul(&t[j][b - 1], P, rm);
                        let d = if j > 0 { f(2.0 * j as f64).mul(&t[j - 1][b - 1], P, rm) } else { f(0.0) };
                        a.add(&d, P, rm).sub(&t[j][b - 2], P, rm)
                    }
                };
            }
        }
        let mut s = f(0.0);
        for b in 0..dim {
            let mut cw = f(0.0);
            for i in 0..dim {
                cw = cw.add(&f(c[(b, i)]).mul(&f(w[i * cols + col]), P, rm), P, rm);
            }
            s = s.add(&cw.mul(&t[k][b], P, rm), P, rm);
        }
        // d/du = 2 d/dx, exact in f64
        s.to_string().parse::<f64>().expect("a number") * 2f64.powi(k as i32)
    }

    /// A polynomial combination's derivatives (series differentiated in double-double,
    /// each coefficient rounded once) are within a few ulps of the exact derivatives of
    /// the stored `C` and `W`, near `u = 1` too, where `T_b′` grows like `b²`: the dolphin
    /// body's 14 sections at Chebyshev points, `x = 10 s` (its `X_u` is 10) and a wavy
    /// column. Through the cardinal functions' `T_b^{(k)}` (the earlier path) orders 1, 2
    /// and 3 were 5.4e-14, 6.5e-13 and 5.3e-12 relative off.
    #[test]
    fn polynomial_derivatives_are_exact_to_round_off() {
        let n = 14;
        let us: Vec<f64> = (0..n).map(|i| (1.0 - (std::f64::consts::PI * i as f64 / 13.0).cos()) / 2.0).collect();
        let conds: Vec<CondSpec> = us.iter().map(|&u| CondSpec { u, order: 0 }).collect();
        let space = ExpSpace::from_roots(vec![Root { re: 0.0, im: 0.0, mult: n }]);
        let set = Arc::new(CardinalSet::new(space, &conds, 3).expect("solves"));
        let CardinalSet::Direct(card) = set.as_ref() else { panic!("f64 in the polynomial basis") };
        let w: Vec<f64> = us.iter().flat_map(|&u| [10.0 * u, (7.0 * u).sin() + 0.3 * u * u]).collect();
        let comb = Combined::polynomial(&set, w.clone(), 2).expect("a polynomial combination");
        let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
        let mut next = || {
            x = x.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (x >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut pts: Vec<f64> = (0..60).map(|_| next()).collect();
        pts.extend((0..20).map(|_| 1.0 - 1e-3 * next()));
        // beside the conditions' places (there the set's own rows answer, `δ_ic` at a
        // condition's order)
        pts.extend([1e-9, 1.0 - 1e-9, us[5] + 1e-9]);
        let kmax = 3;
        let mut scratch = vec![0.0; comb.scratch_len()];
        let mut out = vec![0.0; (kmax + 1) * 2];
        let (mut err, mut size) = ([0.0f64; 4], [0.0f64; 4]);
        for &u in &pts {
            comb.eval(u, kmax, None, &[], &mut scratch, &mut out);
            for k in 0..=kmax {
                for col in 0..2 {
                    let want = exact(card.coefficients(), &w, 2, col, u, k);
                    err[k] = max_nan(err[k], (out[k * 2 + col] - want).abs());
                    size[k] = max_nan(size[k], want.abs());
                }
            }
        }
        for k in 0..=kmax {
            // one rounding per folded coefficient and a sum of 14 terms with |T_b| ≤ 1:
            // a few ulps of the largest value (2.9e-16 … 3.6e-16 seen)
            assert!(err[k] <= 4e-15 * size[k], "order {k}: {:e} of {:e}", err[k], size[k]);
        }
    }
}
