//! A penalised least-squares fit whose penalty's weight the data choose: the collar's
//! smoothing.
//!
//! The collar's correction `R(s, w) = Σ_{k<K} s^k D_k(w)` (periodic cubic splines `D_k`)
//! is fitted to a mesh's vertices near a hole. With as many unknowns as vertices it
//! follows every vertex, and on a scan it follows the noise; the fill's G1/G2 data are then
//! the noise's derivatives. The fit minimises instead
//!
//! `‖A x − y‖² + λ E(R)`,  `E(R) = ∫₀^L ∫₀^W Σ_{a=0}^{3} C(3, a) |∂_s^a ∂_w^{3−a} R|² ds dw`,
//!
//! the third-order thin-plate energy (invariant under rotations of the `(s, w)` plane,
//! zero on polynomials of degree two in `(s, w)`, so a curvature across the loop that
//! does not change along it costs nothing), and `λ` minimises the generalised
//! cross-validation score (Craven and Wahba, *Numer. Math.* 31, 1979)
//!
//! `V(λ) = n ‖A x_λ − y‖² / (n − tr H(λ))²`,  `H(λ) = A (AᵀA + λ Ω)⁻¹ Aᵀ`,
//!
//! `n` the rows (the three coordinates share `H`), `tr H` the fit's effective number of
//! unknowns: an estimate, invariant under rotations of the data, of the weight at which
//! leaving a vertex out and predicting it from the others errs least. On the bench's clean
//! meshes it chose weights of 10⁻¹² (torus) to 2e-2, on meshes with noise of a hundredth
//! of an edge 0.4 … 160 (BENCHMARKS.md).
//!
//! **The energy in the fit's unknowns.** In `β = s / W`, with `D̃_k = W^k D_k` and
//! `∂_s = W⁻¹ ∂_β`,
//!
//! `E = Σ_a C(3, a) W^{1−2a} Σ_{k,l} S^a_{kl} ∫₀^L D̃_k^{(3−a)} · D̃_l^{(3−a)} dw`,
//! `S^a_{kl} = ∫₀¹ ∂^a β^k ∂^a β^l dβ = k^{(a)} l^{(a)} / (k + l − 2a + 1)`
//!
//! (`k^{(a)} = k!/(k−a)!`, zero for `k < a`), and the `w` integrals are the Gram matrices of
//! the cubic B-splines' derivatives, by four-point Gauss–Legendre on every span (exact for
//! the products, polynomials of degree six).
//!
//! **`tr H` without the inverse.** `tr H = tr(M⁻¹ AᵀA)` with `M = AᵀA + λ Ω`, and `AᵀA`
//! lies inside `M`'s envelope, so only `M⁻¹`'s entries there are needed
//! ([`ProfileCholesky::trace_of_inverse_times`]): each `λ` costs two envelope passes
//! instead of an `n³` inverse.

use super::PeriodicSpline;
use crate::linalg::{Envelope, LinalgError, ProfileCholesky};
use crate::num::{max_nan, min_nan};
use faer::Mat;

/// `k!/(k − a)!`, zero for `k < a`.
fn falling(k: usize, a: usize) -> f64 {
    if k < a { 0.0 } else { (k + 1 - a..=k).map(|r| r as f64).product() }
}

/// Four-point Gauss–Legendre on `[−1, 1]`: nodes and weights.
const GAUSS4: [(f64, f64); 4] = [
    (-0.861_136_311_594_052_6, 0.347_854_845_137_453_8),
    (-0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
    (0.339_981_043_584_856_3, 0.652_145_154_862_546_1),
    (0.861_136_311_594_052_6, 0.347_854_845_137_453_8),
];

/// Adds `scale · E` for `R = Σ_{k<blocks} β^k D̃_k(w)` to `m`, `D̃_k` on `basis` (`W` =
/// `width`), column `k · len + j` of the unknowns mapped to `m`'s index by `at`.
pub(super) fn add_thin_plate(
    m: &mut Envelope,
    basis: &PeriodicSpline,
    blocks: usize,
    width: f64,
    scale: f64,
    at: impl Fn(usize) -> usize,
) {
    let len = basis.len();
    // coef[k][l][a] = C(3, a) W^{1−2a} S^a_kl
    let coef: Vec<Vec<[f64; 4]>> = (0..blocks)
        .map(|k| {
            (0..blocks)
                .map(|l| {
                    std::array::from_fn(|a| {
                        let (fk, fl) = (falling(k, a), falling(l, a));
                        let c = [1.0, 3.0, 3.0, 1.0][a] * width.powi(1 - 2 * a as i32);
                        if fk == 0.0 || fl == 0.0 { 0.0 } else { c * fk * fl / (k + l + 1 - 2 * a) as f64 }
                    })
                })
                .collect()
        })
        .collect();
    let breaks = basis.breaks();
    for i in 0..len {
        let (lo, hi) = (breaks[i], if i + 1 < len { breaks[i + 1] } else { basis.domain().1 });
        let (mid, half) = ((lo + hi) / 2.0, (hi - lo) / 2.0);
        for &(x, wq) in &GAUSS4 {
            let (j0, bas) = basis.basis(mid + half * x, 3);
            for (k, ck) in coef.iter().enumerate() {
                for (l, ckl) in ck.iter().enumerate() {
                    for t in 0..4 {
                        for u in 0..4 {
                            let e: f64 = (0..=3).map(|a| ckl[a] * bas[3 - a][t] * bas[3 - a][u]).sum();
                            let (p, q) = (at(k * len + (j0 + t) % len), at(l * len + (j0 + u) % len));
                            if e != 0.0 && q <= p {
                                m.add_lower(p, q, scale * half * wq * e);
                            }
                        }
                    }
                }
            }
        }
    }
}

/// What [`gcv_solve`] found.
#[derive(Clone, Debug)]
pub(super) struct Smoothed {
    /// The unknowns, in `g`'s order, one column per right-hand side.
    pub x: Mat<f64>,
    /// The chosen weight, relative: `λ = weight · tr(AᵀA) / tr(Ω)`.
    pub weight: f64,
    /// `tr H(λ)`: the fit's effective number of unknowns.
    pub dof: f64,
    /// The estimated 1-norm condition number of `AᵀA + λ Ω + base`.
    pub cond: f64,
}

/// The relative weights tried: `10^{−12} … 10^3`, three decades apart, then the best
/// refined by golden sections in `log λ` between its neighbours to a fifth of a decade
/// (`6 · 0.618⁷ ≈ 0.2`).
const DECADES: [f64; 6] = [-12.0, -9.0, -6.0, -3.0, 0.0, 3.0];
const REFINE: usize = 7;

/// Minimises `V(λ)` over `λ` for `min ‖A x − y‖² + λ xᵀ Ω x + xᵀ base x`, given `g = AᵀA`,
/// `r = Aᵀy` (one column a coordinate), `yy = ‖y‖²` summed over the columns, `rows` = the
/// rows of `A`; `base` (a small fixed penalty that keeps the system determined where data
/// are few) counts as part of the fit. `g`, `omega`, `base` share one envelope.
pub(super) fn gcv_solve(
    g: &Envelope,
    omega: &Envelope,
    base: &Envelope,
    r: &Mat<f64>,
    yy: f64,
    rows: usize,
) -> Result<Smoothed, LinalgError> {
    let n = g.len();
    let tr = |m: &Envelope| (0..n).map(|i| m.get(i, i)).sum::<f64>();
    let unit = tr(g) / tr(omega);
    let rhs = r.ncols() as f64;
    // each weight's score, fit, and factorisation (kept for the one chosen)
    let eval = |log_w: f64| -> Result<(f64, Smoothed, ProfileCholesky), LinalgError> {
        let weight = 10f64.powf(log_w);
        let m = g.combination(&[(1.0, g), (weight * unit, omega), (1.0, base)]);
        let f = ProfileCholesky::factor(&m)?;
        let x = f.solve(r);
        // ‖A x − y‖² = ‖y‖² − 2 xᵀ Aᵀy + xᵀ AᵀA x, summed over the columns
        let mut rss = yy;
        let mut col = vec![0.0; n];
        for c in 0..r.ncols() {
            col.iter_mut().enumerate().for_each(|(i, v)| *v = x[(i, c)]);
            let gx = g.mul(&col);
            rss += (0..n).map(|i| col[i] * (gx[i] - 2.0 * r[(i, c)])).sum::<f64>();
        }
        // round-off leaves a tiny negative remainder when the fit interpolates (a NaN stays)
        let rss = if rss < 0.0 { 0.0 } else { rss };
        let dof = f.trace_of_inverse_times(g);
        let free = rows as f64 - dof;
        let v = if free > 0.0 { rss * rhs * rows as f64 / (rhs * free).powi(2) } else { f64::INFINITY };
        if v.is_nan() {
            return Err(LinalgError::NonFinite);
        }
        Ok((v, Smoothed { x, weight, dof, cond: f64::NAN }, f))
    };
    let mut best: Option<(f64, f64, (Smoothed, ProfileCholesky))> = None;
    for e in DECADES {
        let (v, s, f) = eval(e)?;
        if best.as_ref().is_none_or(|b| v < b.0) {
            best = Some((v, e, (s, f)));
        }
    }
    let (mut bv, be, mut bs) = best.expect("decades tried");
    // golden sections on [be − 3, be + 3] ∩ the grid
    let (mut lo, mut hi) = (max_nan(be - 3.0, DECADES[0]), min_nan(be + 3.0, DECADES[DECADES.len() - 1]));
    let phi = (5f64.sqrt() - 1.0) / 2.0;
    let mut a = hi - phi * (hi - lo);
    let mut b = lo + phi * (hi - lo);
    let (mut va, sa, fa) = eval(a)?;
    let (mut vb, sb, fb) = eval(b)?;
    let keep = |v: f64, s: (Smoothed, ProfileCholesky), bv: &mut f64, bs: &mut (Smoothed, ProfileCholesky)| {
        if v < *bv {
            *bv = v;
            *bs = s;
        }
    };
    keep(va, (sa, fa), &mut bv, &mut bs);
    keep(vb, (sb, fb), &mut bv, &mut bs);
    for _ in 0..REFINE {
        if va < vb {
            hi = b;
            (b, vb) = (a, va);
            a = hi - phi * (hi - lo);
            let (v, s, f) = eval(a)?;
            va = v;
            keep(v, (s, f), &mut bv, &mut bs);
        } else {
            lo = a;
            (a, va) = (b, vb);
            b = lo + phi * (hi - lo);
            let (v, s, f) = eval(b)?;
            vb = v;
            keep(v, (s, f), &mut bv, &mut bs);
        }
    }
    // the condition number of the system chosen, from the factorisation the search made
    let (mut fit, f) = bs;
    let m = g.combination(&[(1.0, g), (fit.weight * unit, omega), (1.0, base)]);
    fit.cond = f.with_cond(&m, 1e13)?.cond();
    Ok(fit)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// [`gcv_solve`] against the score computed densely: `H = A (AᵀA + λ Ω + B)⁻¹ Aᵀ` by
    /// faer's dense inverse, `tr H` and `‖(I − H) y‖²` straight from it. A periodic curve
    /// `(cos, sin, sin 3·)` of `2π t` at 300 uneven `t`, each coordinate moved by normal
    /// deviates of 0.05, fitted on 60 control points: the weight chosen scores within 2 %
    /// of the best on a grid of twentieth decades (the golden sections stop at a fifth of
    /// a decade, where the score is flat), its `tr H` and solution are the dense ones, its
    /// condition number is finite, and the curve lies nearer the noiseless one than the
    /// data do.
    #[test]
    fn gcv_matches_the_dense_score() {
        let (len, n) = (60, 300);
        let basis = PeriodicSpline::new((0..len).map(|j| j as f64 / len as f64).collect(), 1.0).unwrap();
        let mut uniform = crate::trimesh::draws::uniform(0x1234_5678_9abc_def1);
        let mut normal = crate::trimesh::draws::normal(0x0fed_cba9_8765_4321);
        let truth = |t: f64| {
            let a = std::f64::consts::TAU * t;
            [a.cos(), a.sin(), (3.0 * a).sin()]
        };
        let mut a = Mat::<f64>::zeros(n, len);
        let mut y = Mat::<f64>::zeros(n, 3);
        let mut ts = Vec::new();
        for i in 0..n {
            let t = (i as f64 + 0.8 * uniform()) / n as f64;
            ts.push(t);
            let (j0, b) = basis.basis(t, 0);
            for (k, bk) in b[0].iter().enumerate() {
                a[(i, (j0 + k) % len)] += bk;
            }
            for (c, v) in truth(t).into_iter().enumerate() {
                y[(i, c)] = v + 0.05 * normal();
            }
        }
        let g = crate::lanes::after(a.transpose() * &a);
        let r = crate::lanes::after(a.transpose() * &y);
        let yy: f64 = (0..n).flat_map(|i| (0..3).map(move |c| (i, c))).map(|(i, c)| y[(i, c)].powi(2)).sum();
        // the base: 10⁻⁶ of the mean diagonal on second differences
        let lam = 1e-6 * (0..len).map(|i| g[(i, i)]).sum::<f64>() / len as f64;
        let base = Mat::<f64>::from_fn(len, len, |i, j| {
            lam * match (i + len - j) % len {
                0 => 6.0,
                1 | 59 => -4.0,
                2 | 58 => 1.0,
                _ => 0.0,
            }
        });
        let mut omega = Envelope::zeros(vec![0; len]);
        add_thin_plate(&mut omega, &basis, 1, 1.0, 1.0, |c| c);
        let full = |m: &Mat<f64>| Envelope::from_dense_in(m, vec![0; len]);
        let fit = gcv_solve(&full(&g), &omega, &full(&base), &r, yy, n).unwrap();
        let om = Mat::<f64>::from_fn(len, len, |i, j| omega.get(i, j));
        let unit = (0..len).map(|i| g[(i, i)]).sum::<f64>() / (0..len).map(|i| om[(i, i)]).sum::<f64>();
        let dense = |w: f64| {
            let m = &g + &om * faer::Scale(w * unit) + &base;
            let llt = faer::linalg::solvers::Llt::new(m.as_ref(), faer::Side::Lower).unwrap();
            let inv = crate::lanes::after(faer::linalg::solvers::DenseSolveCore::inverse(&llt));
            let h = crate::lanes::after(&a * &inv * a.transpose());
            let trh: f64 = (0..n).map(|i| h[(i, i)]).sum();
            let e = crate::lanes::after(&y - &h * &y);
            let rss: f64 = (0..n).flat_map(|i| (0..3).map(move |c| (i, c))).map(|(i, c)| e[(i, c)].powi(2)).sum();
            (rss * n as f64 / (n as f64 - trh).powi(2), trh, crate::lanes::after(&inv * &r))
        };
        let (v, trh, x) = dense(fit.weight);
        // tr H is a sum of 60 terms ~1, each to round-off times the system's condition
        assert!((fit.dof - trh).abs() < 1e-9 * trh, "tr H {} against {trh}", fit.dof);
        let dx = (0..len).flat_map(|i| (0..3).map(move |c| (i, c))).map(|(i, c)| (fit.x[(i, c)] - x[(i, c)]).abs());
        assert!(dx.fold(0.0, max_nan) < 1e-9, "the solution against the dense one");
        let best = (-240..=60).map(|e| dense(10f64.powf(e as f64 / 20.0)).0).fold(f64::INFINITY, crate::num::min_nan);
        assert!(v <= best * 1.02, "score {v:e} at weight {:e}, best on the grid {best:e}", fit.weight);
        assert!(fit.cond.is_finite() && fit.cond > 1.0, "cond {}", fit.cond);
        // the smoothed curve against the truth: nearer than the noise (rms 0.05)
        let mut sq = 0.0;
        for &t in &ts {
            let (j0, b) = basis.basis(t, 0);
            for (c, v) in truth(t).into_iter().enumerate() {
                let p: f64 = (0..4).map(|k| b[0][k] * fit.x[((j0 + k) % len, c)]).sum();
                sq += (p - v).powi(2);
            }
        }
        let rms = (sq / (3 * n) as f64).sqrt();
        eprintln!("gcv: weight {:.3e}, tr H {:.2}, rms to the truth {rms:.3e}", fit.weight, fit.dof);
        assert!(rms < 0.5 * 0.05, "rms {rms:e} to the truth");
    }

    /// A residual that is not a number (data with a NaN) is an error, not a score of zero
    /// (`f64::max` turned it into one, and the NaN fit came back as the chosen one).
    #[test]
    fn nan_data_are_refused() {
        let len = 12;
        let basis = PeriodicSpline::new((0..len).map(|j| j as f64 / len as f64).collect(), 1.0).unwrap();
        let mut g = Envelope::zeros(vec![0; len]);
        let mut r = Mat::<f64>::zeros(len, 3);
        for i in 0..40 {
            let (j0, b) = basis.basis(i as f64 / 40.0, 0);
            for t in 0..4 {
                for u in 0..4 {
                    let (p, q) = ((j0 + t) % len, (j0 + u) % len);
                    if q <= p {
                        g.add_lower(p, q, b[0][t] * b[0][u]);
                    }
                }
                r[((j0 + t) % len, 0)] += b[0][t];
            }
        }
        let mut omega = Envelope::zeros(vec![0; len]);
        add_thin_plate(&mut omega, &basis, 1, 1.0, 1.0, |c| c);
        let base = Envelope::zeros(vec![0; len]);
        // the data (1, 0, 0) at every row: a constant, which the fit meets at any weight
        let f = gcv_solve(&g, &omega, &base, &r, 40.0, 40).unwrap();
        let off = (0..len).map(|i| (f.x[(i, 0)] - 1.0).abs() + f.x[(i, 1)].abs()).fold(0.0, max_nan);
        assert!(off < 1e-12, "{off:e}");
        assert!(matches!(gcv_solve(&g, &omega, &base, &r, f64::NAN, 40), Err(LinalgError::NonFinite)));
    }

    /// The `w` Gram matrices of uniform cubic B-splines of spacing `h`, against their
    /// closed forms (integrals of products of the pieces, by hand): `∫ B_i B_j = h (2416,
    /// 1191, 120, 1)/5040`, `∫ B_i′ B_j′ = (2/3, −1/8, −1/5, −1/120)/h`, `∫ B_i″ B_j″ = (8/3,
    /// −3/2, 0, 1/6)/h³`, `∫ B_i‴ B_j‴ = (20, −15, 6, −1)/h⁵` at offsets `|i − j| = 0 … 3`;
    /// and the `s` factors by a constant `D̃_k` (partition of unity): `E(β^k c) = W^{−5}
    /// (k^{(3)})² / (2k − 5) L |c|²` for `k ≥ 3`, zero for `k ≤ 2`.
    #[test]
    fn thin_plate_energy_matches_closed_forms() {
        let (len, period, width) = (11, 3.3, 0.7);
        let h = period / len as f64;
        let basis = PeriodicSpline::new((0..len).map(|j| period * j as f64 / len as f64).collect(), period).unwrap();
        let want = [
            [2416.0 / 5040.0 * h, 1191.0 / 5040.0 * h, 120.0 / 5040.0 * h, 1.0 / 5040.0 * h],
            [2.0 / 3.0 / h, -1.0 / 8.0 / h, -1.0 / 5.0 / h, -1.0 / 120.0 / h],
            [8.0 / 3.0 / h.powi(3), -1.5 / h.powi(3), 0.0, 1.0 / 6.0 / h.powi(3)],
            [20.0 / h.powi(5), -15.0 / h.powi(5), 6.0 / h.powi(5), -1.0 / h.powi(5)],
        ];
        // one block: only a = 0 survives, E = ∫ D̃‴ · D̃‴: the third derivatives' Gram
        let mut m = Envelope::zeros(vec![0; len]);
        add_thin_plate(&mut m, &basis, 1, width, 1.0, |c| c);
        let w = width;
        for i in 0..len {
            for j in 0..len {
                let off = (i + len - j) % len;
                let off = off.min(len - off);
                let e = if off <= 3 { want[3][off] * w } else { 0.0 };
                // entries ~1e5; the quadrature is exact, so round-off of the sums
                assert!((m.get(i, j) - e).abs() <= 1e-12 * want[3][0] * w, "({i},{j}): {} against {e}", m.get(i, j));
            }
        }
        // four blocks: the block pairs (k, l) weigh the Gram matrices of the lower
        // derivatives; k = l = 1 carries 3 W⁻¹ S¹₁₁ G₂ + W G₃ (S¹₁₁ = 1, S⁰₁₁ = 1/3)
        let mut m = Envelope::zeros(vec![0; 4 * len]);
        add_thin_plate(&mut m, &basis, 4, width, 1.0, |c| c);
        for i in 0..len {
            for j in 0..len {
                let off = (i + len - j) % len;
                let off = off.min(len - off);
                if off > 3 {
                    continue;
                }
                let e = 3.0 / w * want[2][off] + w / 3.0 * want[3][off];
                let got = m.get(len + i, len + j);
                assert!((got - e).abs() <= 1e-12 * (w / 3.0 * want[3][0]), "({i},{j}): {got} against {e}");
                // k = 3, l = 3: W⁻⁵ · 36 · G₀ + 3 W⁻³ (S²₃₃ = 36·… ) …: check only the
                // constant's energy below
            }
        }
        for k in 0..4 {
            let e: f64 = (0..len)
                .flat_map(|i| (0..len).map(move |j| (i, j)))
                .map(|(i, j)| m.get(k * len + i, k * len + j))
                .sum();
            let want = if k < 3 { 0.0 } else { w.powi(-5) * falling(k, 3).powi(2) / (2 * k - 5) as f64 * period };
            // the constant's energy is a sum of entries ~1e5 that cancel for k ≤ 2
            assert!((e - want).abs() <= 1e-9 * (1.0 + want.abs()), "k {k}: {e} against {want}");
        }
    }
}
