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
//! products with the basis's derivatives (exponential basis, polynomials) or with the
//! set's own derivative series (Chebyshev series), so they are exact in the same sense as
//! [`CardinalSet::eval`]; the two agree to round-off (reassociated sums), which
//! `spectral::batch`'s tests measure.
//!
//! Where the set answers from stored rows (the Chebyshev forms at their condition points)
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
    /// A zero root of multiplicity `dim`: `T_b(2u − 1)`, `b < dim`; `mat` is `Cᵀ`, `cw` is
    /// `C W` (`dim × cols`, row-major, each entry rounded once). Values alone go through
    /// `cw` (mode 0 of an order-40 patch: 40 × 6 products a point instead of 40 × 40 and
    /// 40 × 6); derivatives through the cardinal functions as pointwise, since folded they
    /// moved the dolphin body's `X_u` by 1.7e-14 relative, over the 1e-14 the paths agree to.
    Poly { dim: usize, mat: Vec<f64>, cw: Vec<f64> },
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
                        // (C W)_bc = Σ_i C_bi W_ic, each rounded once (compensated: exact
                        // products by FMA, error-free sums), so the folded sums lose no more
                        // than the pointwise ones do
                        let mut cw = vec![0.0; dim * cols];
                        for b in 0..dim {
                            for c in 0..cols {
                                let (mut hi, mut lo) = (0.0f64, 0.0f64);
                                for i in 0..dim {
                                    let (x, w) = (coef[(b, i)], weights[i * cols + c]);
                                    let p = x * w;
                                    let pe = x.mul_add(w, -p);
                                    let s = hi + p;
                                    let bb = s - hi;
                                    lo += (hi - (s - bb)) + (p - bb) + pe;
                                    hi = s;
                                }
                                cw[b * cols + c] = hi + lo;
                            }
                        }
                        Kind::Poly { dim: *mult, mat, cw }
                    }
                    [Root { re: p, im: 0.0, mult: m1 }, Root { re: q, im: 0.0, mult: m2 }]
                        if *p > 0.0 && *q == -*p && m1 == m2 =>
                    {
                        Kind::Exp { c: *p, n: *m1, mat }
                    }
                    _ => Kind::Generic,
                };
                (kind, Vec::new())
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
            Kind::Poly { dim, .. } => (self.kmax + 2) * dim,
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
            Kind::Poly { dim, mat, cw } => {
                let dim = *dim;
                if kmax == 0 && cheb.len() >= dim {
                    // the caller's T_b(2u − 1): the recurrence below, the same numbers
                    row_times(&cheb[..dim], cw, cols, &mut out[..cols]);
                    return;
                }
                let x = 2.0 * u - 1.0;
                // T_b^{(j)} = 2x T_{b−1}^{(j)} + 2j T_{b−1}^{(j−1)} − T_{b−2}^{(j)}, then d/du = 2 d/dx
                for j in 0..=kmax {
                    for b in 0..dim {
                        scratch[j * dim + b] = match (b, j) {
                            (0, 0) => 1.0,
                            (0, _) => 0.0,
                            (1, 0) => x,
                            (1, 1) => 1.0,
                            (1, _) => 0.0,
                            _ => {
                                2.0 * x * scratch[j * dim + b - 1]
                                    + if j > 0 { 2.0 * j as f64 * scratch[(j - 1) * dim + b - 1] } else { 0.0 }
                                    - scratch[j * dim + b - 2]
                            }
                        };
                    }
                }
                for j in 0..=kmax {
                    let scale = 2f64.powi(j as i32);
                    for s in &mut scratch[j * dim..(j + 1) * dim] {
                        *s *= scale;
                    }
                }
                if kmax == 0 {
                    row_times(&scratch[..dim], cw, cols, &mut out[..cols]);
                } else {
                    self.through_cardinals(dim, kmax, mat, scratch, out);
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
