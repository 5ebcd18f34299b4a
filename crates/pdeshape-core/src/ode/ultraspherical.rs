//! Cardinal functions in plain f64 by the ultraspherical spectral method (Olver & Townsend,
//! "A fast and well-conditioned spectral method", SIAM Review 55, 2013).
//!
//! The exponential basis `uᵏ e^{r u}` of `K = ker P(D)` is ill-conditioned when the roots
//! are small and repeated (order 40 at `c = a·m ≈ 1`: condition numbers of 1e20 and more),
//! but the problem is not: the cardinal functions are smooth and bounded. Here they are
//! computed as Chebyshev series `ℓ(u) = Σ_{m<K} a_m T_m(x)`, `x = 2u − 1`, from a square
//! system that stays well conditioned:
//!
//! - `P(D_u) = Σ_k p_k D_u^k = Σ_k p_k 2^k D_x^k`, and `D_x^k` maps Chebyshev-T
//!   coefficients to coefficients in the ultraspherical basis `C^{(k)}`:
//!   `D_x^k T_m = 2^{k−1}(k−1)! m C^{(k)}_{m−k}` (`m ≥ k ≥ 1`);
//! - conversions `S_λ: C^{(λ)} → C^{(λ+1)}` bring every term to `C^{(n)}` (`n = deg P`):
//!   `T_0 = C^{(1)}_0`, `T_m = ½(C^{(1)}_m − C^{(1)}_{m−2})`, and for `λ ≥ 1`
//!   `C^{(λ)}_m = λ/(m+λ) (C^{(λ+1)}_m − C^{(λ+1)}_{m−2})`; in Horner form
//!   `R ← S_λ R + p_{λ+1} 2^{λ+1} 𝒟_{λ+1}`, each step banded;
//! - the system: the `n` condition rows `ℓ^{(d_i)}(u_i) = Σ_m a_m 2^{d_i} T_m^{(d_i)}(x_i)`
//!   and the first `K − n` rows of `P(D)` in `C^{(n)}` (equal to zero), each row scaled to
//!   unit maximum; one LU solve gives all `n` cardinal functions (right-hand sides `e_i`).
//!
//! The result is accepted only when it is resolved (the last coefficients are below
//! `1e-14` of the largest), meets its conditions to `1e-12`, and the system's condition
//! number (`‖A‖₁‖A⁻¹‖₁`, reported) is below [`ULTRA_COND_LIMIT`]; otherwise the caller
//! falls back to multiple precision. Tested against an independent mpmath table
//! (`tests/cardinal_reference.rs`).

use super::{CondSpec, ExpSpace, OdeError};
use faer::Mat;
use faer::linalg::solvers::Solve;
use std::sync::OnceLock;

/// Largest condition number of the row-scaled ultraspherical system that is accepted: the
/// same bound as the exponential basis's (errors up to about `cond × ε` ≈ 1e-12). Value
/// conditions stay far below it (order 40: 20 … 160); derivative conditions of order 2 and
/// 3 at both ends reach 1e6 (errors of 1e-10, measured against multiple precision), and go
/// to multiple precision.
pub const ULTRA_COND_LIMIT: f64 = 1e4;

/// Cardinal functions as Chebyshev series on `[0, 1]` (see the module docs).
#[derive(Clone, Debug)]
pub struct UltraCardinal {
    /// `coef[k][i]`: Chebyshev coefficients (in `x = 2u − 1`) of `ℓ_i^{(k)}` (derivatives
    /// in `u`).
    coef: Vec<Vec<Vec<f64>>>,
    kmax: usize,
    dim: usize,
    cond: f64,
    size: usize,
    /// Values at the condition points from the system's own rows, `Σ_m a_m 2^k T_m^{(k)}(x_i)`:
    /// the solve makes them cardinal to round-off, while the differentiated series lose
    /// accuracy in high derivatives at the ends (`T_m^{(k)}(±1)` grows like `m^{2k}`).
    at_conditions: Vec<(f64, Vec<Vec<f64>>)>,
    /// The characteristic polynomial (ascending, monic), for the residual.
    p: Vec<f64>,
    /// [`relative_residual`] of `P(D)` on the cardinal functions, the worst of them;
    /// computed on first use.
    residual: OnceLock<f64>,
}

/// `T_m^{(d)}(x)` for `m < count`, `d ≤ dmax`: `t[d][m]`, by
/// `T_{m+1}^{(d)} = 2x T_m^{(d)} + 2d T_m^{(d−1)} − T_{m−1}^{(d)}`.
fn chebyshev_derivatives(x: f64, count: usize, dmax: usize) -> Vec<Vec<f64>> {
    let mut t = vec![vec![0.0; count]; dmax + 1];
    for d in 0..=dmax {
        for m in 0..count {
            t[d][m] = match m {
                0 => f64::from(d == 0),
                1 => match d {
                    0 => x,
                    1 => 1.0,
                    _ => 0.0,
                },
                _ => {
                    let lower = if d > 0 { 2.0 * d as f64 * t[d - 1][m - 1] } else { 0.0 };
                    2.0 * x * t[d][m - 1] + lower - t[d][m - 2]
                }
            };
        }
    }
    t
}

/// Coefficients of `f′` (in `x`) from those of `f` (Chebyshev-T).
fn differentiate(a: &[f64]) -> Vec<f64> {
    let k = a.len();
    let mut b = vec![0.0; k + 1];
    for m in (1..k).rev() {
        b[m - 1] = b[m + 1] + 2.0 * m as f64 * a[m];
    }
    b[0] *= 0.5;
    b.truncate(k.max(1));
    b
}

/// Clenshaw's sum `Σ c_m T_m(t)`.
#[cfg(test)]
fn clenshaw(c: &[f64], t: f64) -> f64 {
    let (mut b1, mut b2) = (0.0, 0.0);
    for &cj in c.iter().skip(1).rev() {
        let b0 = 2.0 * t * b1 - b2 + cj;
        b2 = b1;
        b1 = b0;
    }
    t * b1 - b2 + c.first().copied().unwrap_or(0.0)
}

/// `log₂(2^{k−1} (k−1)!)`, the size of `D_x^k`'s entries per unit `m`.
fn log2_dk(k: usize) -> f64 {
    if k == 0 {
        return 0.0;
    }
    (k - 1) as f64 + (1..k).map(|j| (j as f64).log2()).sum::<f64>()
}

impl UltraCardinal {
    /// The cardinal functions of `conds` in `space`, with derivatives up to `kmax`, or an
    /// error when the series is not resolved or the system is too ill-conditioned (the
    /// caller then uses multiple precision).
    pub fn new(space: &ExpSpace, conds: &[CondSpec], kmax: usize) -> Result<Self, OdeError> {
        let n = space.dim();
        if conds.len() != n {
            return Err(OdeError::Count { got: conds.len(), dim: n });
        }
        let c = space.roots().iter().map(|r| r.re.abs() + r.im.abs()).fold(0.0, crate::num::max_nan);
        if !c.is_finite() {
            return Err(OdeError::Polynomial("roots are not finite".into()));
        }
        let mut size = n + 40 + (1.2 * c).ceil() as usize;
        for _ in 0..2 {
            match Self::solve(space, conds, kmax, size) {
                Err(Unresolved) => size = size * 3 / 2,
                Ok(u) => return u,
            }
        }
        Err(OdeError::Singular {
            cond: f64::NAN,
            detail: format!(": the Chebyshev series is not resolved with {size} terms"),
        })
    }

    fn solve(
        space: &ExpSpace,
        conds: &[CondSpec],
        kmax: usize,
        size: usize,
    ) -> Result<Result<Self, OdeError>, Unresolved> {
        let n = space.dim();
        let p = super::polynomial_from_roots(space.roots()); // ascending, monic, degree n
        debug_assert_eq!(p.len(), n + 1);
        let r = operator_rows(&p, size, 1.0);
        // the system: condition rows, then K − n operator rows, each scaled to unit maximum
        let mut a = Mat::<f64>::zeros(size, size);
        let mut b = Mat::<f64>::zeros(size, n);
        for (i, cd) in conds.iter().enumerate() {
            let t = chebyshev_derivatives(2.0 * cd.u - 1.0, size, cd.order);
            let scale = 2f64.powi(cd.order as i32);
            let row: Vec<f64> = t[cd.order].iter().map(|x| x * scale).collect();
            let mx = row.iter().fold(0.0, |m: f64, x| crate::num::max_nan(m, x.abs()));
            if !(mx.is_finite() && mx > 0.0) {
                return Ok(Err(OdeError::Singular {
                    cond: f64::INFINITY,
                    detail: format!(": condition row {i} is not finite"),
                }));
            }
            for (m, x) in row.iter().enumerate() {
                a[(i, m)] = x / mx;
            }
            b[(i, i)] = 1.0 / mx;
        }
        for j in 0..size - n {
            let mx = r[j].iter().fold(0.0, |m: f64, x| crate::num::max_nan(m, x.abs()));
            if !mx.is_finite() {
                return Ok(Err(OdeError::Singular { cond: f64::INFINITY, detail: ": operator rows overflow".into() }));
            }
            let mx = if mx > 0.0 { mx } else { 1.0 };
            for m in 0..size {
                a[(n + j, m)] = r[j][m] / mx;
            }
        }
        let lu = crate::lanes::after(a.partial_piv_lu());
        let x = crate::lanes::after(lu.solve(&b));
        // condition number ‖A‖₁ ‖A⁻¹‖₁, the second factor estimated (a few solves instead of
        // the inverse's K: most of this function's time went there)
        let norm1 = |m: &Mat<f64>| {
            (0..m.ncols()).map(|c| (0..m.nrows()).map(|r| m[(r, c)].abs()).sum::<f64>()).fold(0.0, crate::num::max_nan)
        };
        let cond = norm1(&a) * crate::linalg::inverse_norm1_estimate(&lu, size);
        if !(cond.is_finite() && cond <= ULTRA_COND_LIMIT) {
            return Ok(Err(OdeError::Singular { cond, detail: " (ultraspherical system)".into() }));
        }
        let base: Vec<Vec<f64>> = (0..n).map(|i| (0..size).map(|m| x[(m, i)]).collect()).collect();
        // resolved: the last four coefficients are negligible against the largest
        for c in &base {
            let big = c.iter().fold(0.0, |m: f64, x| crate::num::max_nan(m, x.abs()));
            let tail = c[size - 4..].iter().fold(0.0, |m: f64, x| crate::num::max_nan(m, x.abs()));
            if !(big.is_finite() && tail <= 1e-14 * big) {
                return Err(Unresolved);
            }
        }
        // derivative series in u (each x-derivative times 2)
        let mut coef = vec![base.clone()];
        for k in 0..kmax {
            let next: Vec<Vec<f64>> =
                coef[k].iter().map(|c| differentiate(c).into_iter().map(|x| 2.0 * x).collect()).collect();
            coef.push(next);
        }
        let mut at_conditions: Vec<(f64, Vec<Vec<f64>>)> = Vec::new();
        for cd in conds {
            if at_conditions.iter().any(|(u, _)| *u == cd.u) {
                continue;
            }
            let t = chebyshev_derivatives(2.0 * cd.u - 1.0, size, kmax);
            let rows = (0..=kmax)
                .map(|k| {
                    let s = 2f64.powi(k as i32);
                    base.iter().map(|c| s * c.iter().zip(&t[k]).map(|(a, tk)| a * tk).sum::<f64>()).collect()
                })
                .collect();
            at_conditions.push((cd.u, rows));
        }
        // the residual is a diagnostic, computed when a report asks for it (dense in the
        // K + 2n operator rows: a tenth of a Klein-bottle solve when done here)
        let out = UltraCardinal { coef, kmax, dim: n, cond, size, at_conditions, p, residual: OnceLock::new() };
        // the cardinal property at the conditions, to round-off
        for (i, cd) in conds.iter().enumerate() {
            if cd.order > kmax {
                continue;
            }
            let e = out.eval(cd.u, cd.order);
            let scale = out.coef[cd.order]
                .iter()
                .map(|c| c.iter().map(|x| x.abs()).sum::<f64>())
                .fold(1.0, crate::num::max_nan);
            for (k, &val) in e[cd.order].iter().enumerate() {
                let want = f64::from(k == i);
                // written so that a NaN fails too
                let ok = (val - want).abs() <= 1e-12 * scale;
                if !ok {
                    return Ok(Err(OdeError::Singular {
                        cond,
                        detail: format!(
                            ": ultraspherical cardinal function {k} misses condition {i} by {:.1e}",
                            val - want
                        ),
                    }));
                }
            }
        }
        Ok(Ok(out))
    }

    /// `out[k][i] = ℓ_i^{(k)}(u)`, `k ≤ kmax`; orders above the tabulated ones are
    /// differentiated from the highest tabulated series on demand.
    pub fn eval(&self, u: f64, kmax: usize) -> Vec<Vec<f64>> {
        if kmax > self.kmax {
            // orders beyond the table: their series by differentiating the highest
            // tabulated one (exact in coefficient arithmetic; `Surface::derivatives`
            // promises any order, and a deep request must not panic)
            let mut rows = self.eval(u, self.kmax);
            let mut series = self.coef[self.kmax].clone();
            let tj = chebyshev_derivatives(2.0 * u - 1.0, self.size.max(2), 0).swap_remove(0);
            for _ in self.kmax..kmax {
                series = series.iter().map(|c| differentiate(c).into_iter().map(|x| 2.0 * x).collect()).collect();
                rows.push(series.iter().map(|c| crate::num::dot(c, &tj)).collect());
            }
            return rows;
        }
        if let Some((_, rows)) = self.at_conditions.iter().find(|(c, _)| *c == u) {
            return rows[..=kmax].to_vec();
        }
        // T_j(t) once, then one dot product per function and order (vectorised; Clenshaw's
        // serial recurrence per function was most of a Klein-bottle mesh's time).
        let t = 2.0 * u - 1.0;
        let mut tj = vec![0.0; self.size.max(2)];
        (tj[0], tj[1]) = (1.0, t);
        for j in 2..tj.len() {
            tj[j] = 2.0 * t * tj[j - 1] - tj[j - 2];
        }
        (0..=kmax).map(|k| (0..self.dim).map(|i| crate::num::dot(&self.coef[k][i], &tj)).collect()).collect()
    }

    /// Highest tabulated derivative order.
    pub fn kmax(&self) -> usize {
        self.kmax
    }

    /// The Chebyshev series (in `x = 2u − 1`) of every `ℓ_i^{(k)}`, `k ≤ kmax`: what
    /// [`eval`](Self::eval) sums away from the condition points.
    pub fn series(&self, k: usize) -> &[Vec<f64>] {
        &self.coef[k]
    }

    /// The points where [`eval`](Self::eval) answers from the system's own rows.
    pub fn stored_points(&self) -> Vec<f64> {
        self.at_conditions.iter().map(|(u, _)| *u).collect()
    }

    /// Condition number `‖A‖₁‖A⁻¹‖₁` of the row-scaled system (`‖A⁻¹‖₁` estimated, a lower
    /// bound within a factor of about 3: [`crate::linalg::inverse_norm1_estimate`]).
    pub fn condition_number(&self) -> f64 {
        self.cond
    }

    /// Chebyshev coefficients per function.
    pub fn terms(&self) -> usize {
        self.size
    }

    /// The ODE residual of the cardinal functions, relative, in Chebyshev coefficients
    /// ([`relative_residual`]; the worst function).
    pub fn residual(&self) -> f64 {
        *self.residual.get_or_init(|| {
            let r = operator_rows(&self.p, self.size, 1.0);
            self.coef[0].iter().map(|c| residual_of(&r, c)).fold(0.0, crate::num::max_nan)
        })
    }
}

/// `P(D_u)` for `u` on an interval of length `h` (`x = 2(u − a)/h − 1`) as rows in the
/// `C^{(n)}` basis acting on `K = size` Chebyshev-T coefficients, `K + 2n` rows so that no
/// conversion is truncated, divided by the largest term's scale `2^top` (see the module
/// docs: `P(D_u) = Σ_k p_k (2/h)^k D_x^k`, in Horner form over the conversions `S_λ`).
pub fn operator_rows(p: &[f64], size: usize, h: f64) -> Vec<Vec<f64>> {
    let n = p.len() - 1;
    // scales: term k has entries p_k (2/h)^k 2^{k−1}(k−1)! · m; normalise by the largest
    let logs: Vec<f64> =
        p.iter()
            .enumerate()
            .map(|(k, pk)| {
                if *pk == 0.0 { f64::NEG_INFINITY } else { pk.abs().log2() + k as f64 * (2.0 / h).log2() + log2_dk(k) }
            })
            .collect();
    let top = logs.iter().copied().fold(f64::NEG_INFINITY, crate::num::max_nan);
    let factor = |k: usize| if logs[k].is_finite() { p[k].signum() * (logs[k] - top).exp2() } else { 0.0 };
    let rows = size + 2 * n;
    let mut r = vec![vec![0.0; size]; rows];
    for (j, row) in r.iter_mut().enumerate().take(size) {
        row[j] = factor(0);
    }
    for lam in 0..n {
        // S_λ on every column: row j ← s1(j) row j + s2(j) row j+2
        for j in 0..rows {
            let (s1, s2) = if lam == 0 {
                (if j == 0 { 1.0 } else { 0.5 }, -0.5)
            } else {
                let l = lam as f64;
                (l / (j as f64 + l), -l / (j as f64 + 2.0 + l))
            };
            let (head, tail) = r.split_at_mut(j + 1);
            let row = &mut head[j];
            match tail.get(1) {
                Some(below) => row.iter_mut().zip(below).for_each(|(x, b)| *x = s1 * *x + s2 * b),
                None => row.iter_mut().for_each(|x| *x *= s1),
            }
        }
        // + p_{λ+1} (2/h)^{λ+1} D_{λ+1}: entry (j, j + k) = 2^{k−1}(k−1)! (j + k), scaled
        let k = lam + 1;
        let f = factor(k);
        if f != 0.0 {
            for (j, row) in r.iter_mut().enumerate() {
                if j + k < size {
                    row[j + k] += f * (j + k) as f64;
                }
            }
        }
    }
    r
}

/// The residual of `P(D_u) ℓ = 0` for the Chebyshev series `c` of `ℓ` on an interval of
/// length `h`, computed in coefficient space through the banded operators (no derivative
/// is evaluated): `max_j |(R c)_j| / max_j (|R| |c|)_j` with `R` the operator in the
/// `C^{(n)}` basis — the part of the operator's terms `p_k ℓ^{(k)}` that does not cancel,
/// relative to the terms. Coefficients below `K ε ‖c‖∞` (the representation's round-off,
/// which the operator would amplify into noise of its own size) are dropped first, so a
/// function the operator annihilates exactly (a polynomial of degree `< 2N` under
/// `D^{2N}`) gives 0. Exact solutions give round-off (`~1e-15`); a function solving a
/// different ODE gives the ratio of its residual to its terms (`e^{au}` under
/// `(D² − c²)^N`: `((a² − c²)/(a² + c²))^N`); the last rows, which the ultraspherical
/// system leaves out, hold the truncation (tau) residual of a finite series.
pub fn relative_residual(p: &[f64], h: f64, c: &[f64]) -> f64 {
    residual_of(&operator_rows(p, c.len(), h), c)
}

/// [`relative_residual`] with the operator's rows built once for many series (all of
/// length `r[0].len()`).
pub fn residual_of(r: &[Vec<f64>], c: &[f64]) -> f64 {
    let cn = c.iter().map(|x| x.abs()).fold(0.0, crate::num::max_nan);
    let floor = c.len() as f64 * f64::EPSILON * cn;
    let c: Vec<f64> = c.iter().map(|&x| if x.abs() <= floor { 0.0 } else { x }).collect();
    let (mut res, mut size) = (0.0_f64, 0.0_f64);
    for row in r {
        let (mut x, mut a) = (0.0, 0.0);
        for (rj, cj) in row.iter().zip(&c) {
            x += rj * cj;
            a += (rj * cj).abs();
        }
        res = crate::num::max_nan(res, x.abs());
        size = crate::num::max_nan(size, a);
    }
    if size > 0.0 { res / size } else { res }
}

/// The series needs more terms.
struct Unresolved;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chebyshev_helpers_match_closed_forms() {
        // T_3 = 4x³ − 3x: T_3′ = 12x² − 3, T_3″ = 24x
        let t = chebyshev_derivatives(0.3, 5, 2);
        assert!((t[0][3] - (4.0 * 0.027 - 0.9)).abs() < 1e-15);
        assert!((t[1][3] - (12.0 * 0.09 - 3.0)).abs() < 1e-14);
        assert!((t[2][3] - 7.2).abs() < 1e-14);
        // d/dx (T_2 + T_3) = 4x + 12x² − 3 = 4 T_1 + 6 T_2 + 3 T_0
        let d = differentiate(&[0.0, 0.0, 1.0, 1.0]);
        assert_eq!(d, vec![3.0, 4.0, 6.0, 0.0]);
        assert!((clenshaw(&[3.0, 4.0, 6.0], 0.3) - (4.0 * 0.3 + 12.0 * 0.09 - 3.0)).abs() < 1e-14);
    }

    /// Order 40 at small rates, where the exponential basis needs multiple precision: the
    /// ultraspherical system is well conditioned and its functions are cardinal.
    #[test]
    fn order_forty_is_well_conditioned() {
        for c in [0.0, 0.3, 1.0, 5.0, 18.0] {
            let nodes: Vec<CondSpec> = (0..40)
                .map(|i| CondSpec { u: (1.0 - (std::f64::consts::PI * i as f64 / 39.0).cos()) / 2.0, order: 0 })
                .collect();
            let u = UltraCardinal::new(&ExpSpace::symmetric(c, 20), &nodes, 2).unwrap();
            assert!(u.condition_number() < 1e4, "c = {c}: {:e}", u.condition_number());
            for (i, cd) in nodes.iter().enumerate() {
                let e = u.eval(cd.u, 0);
                for (k, x) in e[0].iter().enumerate() {
                    assert!((x - f64::from(k == i)).abs() < 1e-13, "c = {c}: ℓ_{k}(u_{i}) = {x}");
                }
            }
            // Between the nodes, the dot product with the recurrence's T_j(t) is Clenshaw's sum
            // to round-off: both err by O(terms · ε · Σ|c_j|), so that sum sets the tolerance.
            for j in 0..50 {
                let x = (j as f64 + 0.37) / 50.0;
                let e = u.eval(x, 2);
                for (k, ek) in e.iter().enumerate() {
                    for (i, got) in ek.iter().enumerate() {
                        let coef = &u.coef[k][i];
                        let want = clenshaw(coef, 2.0 * x - 1.0);
                        let scale: f64 = coef.iter().map(|c| c.abs()).sum();
                        assert!((got - want).abs() <= 1e-13 * scale, "c = {c}, order {k}, ℓ_{i}({x}): {got} vs {want}");
                    }
                }
            }
        }
    }

    /// Chebyshev coefficients (in `x = 2u − 1`) of `f` on `[0, 1]` by interpolation at
    /// `n` Chebyshev points of the first kind (the discrete cosine sums).
    fn interpolate(f: impl Fn(f64) -> f64, n: usize) -> Vec<f64> {
        let pi = std::f64::consts::PI;
        let vals: Vec<f64> = (0..n).map(|j| f((1.0 + (pi * (j as f64 + 0.5) / n as f64).cos()) / 2.0)).collect();
        (0..n)
            .map(|k| {
                let s: f64 =
                    vals.iter().enumerate().map(|(j, v)| v * (pi * k as f64 * (j as f64 + 0.5) / n as f64).cos()).sum();
                s * if k == 0 { 1.0 } else { 2.0 } / n as f64
            })
            .collect()
    }

    /// The coefficient-space residual, against functions built independently of the
    /// solver (interpolated from closed forms): exact solutions of `(D² − c²)^N` give
    /// round-off, a function that solves a neighbouring ODE does not, and the cardinal
    /// functions of order 40 solve theirs to round-off.
    #[test]
    fn coefficient_residuals_of_exact_and_wrong_solutions() {
        // (from order 8 on an interpolant's ε-errors in high coefficients, amplified by D^2N,
        // outweigh the terms: the solver's own series are checked below instead)
        for (c, n) in [(0.0, 1usize), (3.0, 1), (3.0, 3)] {
            let p = super::super::polynomial_from_roots(ExpSpace::symmetric(c, n).roots());
            // u^{N−1} e^{cu} (an exact solution: root c of multiplicity N) and, for c = 0,
            // a polynomial of degree 2N − 1
            let k = (n - 1) as i32;
            let exact = interpolate(|u| u.powi(k) * (c * u).exp(), 60);
            let r = relative_residual(&p, 1.0, &exact);
            // round-off of a 60-term interpolant: its coefficients carry errors of about
            // ε ‖f‖ each, which the high derivatives amplify (measured up to 3.5e-13)
            assert!(r < 1e-11, "c = {c}, N = {n}: exact solution's residual {r:e}");
            // e^{(c + 2) u} solves a neighbouring ODE (roots ±(c + 2)), not this one: its
            // residual relative to its terms is ((a² − c²)/(a² + c²))^N, a = c + 2
            let a = c + 2.0;
            let wrong = interpolate(|u| (a * u).exp(), 60);
            let w = relative_residual(&p, 1.0, &wrong);
            let want = ((a * a - c * c) / (a * a + c * c)).powi(n as i32);
            assert!(w > 0.01 * want, "c = {c}, N = {n}: a wrong solution's residual {w:e}, expected about {want:e}");
        }
        // on a piece of length h the derivatives scale by 2/h: e^{5u} on [0, 0.2] is
        // e^{x/2}·const in x, which solves (D_u² − 25) only with the scaling
        let p = super::super::polynomial_from_roots(ExpSpace::symmetric(5.0, 1).roots());
        let piece = interpolate(|t| (5.0 * 0.2 * t).exp(), 40);
        assert!(relative_residual(&p, 0.2, &piece) < 1e-13);
        assert!(relative_residual(&p, 1.0, &piece) > 1e-3);
        // the Klein bottle's order: cardinal functions of (D² − c²)^20 at 40 Chebyshev nodes
        let nodes: Vec<CondSpec> = (0..40)
            .map(|i| CondSpec { u: (1.0 - (std::f64::consts::PI * i as f64 / 39.0).cos()) / 2.0, order: 0 })
            .collect();
        for c in [0.0, 1.4, 7.0] {
            let u = UltraCardinal::new(&ExpSpace::symmetric(c, 20), &nodes, 2).unwrap();
            // measured 5.7e-12 at c = 1.4 (the Klein bottle's own modes: 4.6e-16)
            assert!(u.residual() < 1e-10, "c = {c}: {:e}", u.residual());
            // the same series with a 1e-10 error in one coefficient no longer solves it
            let mut bad = u.coef[0][7].clone();
            bad[45] += 1e-10 * bad.iter().map(|x| x.abs()).fold(0.0, crate::num::max_nan);
            let p = super::super::polynomial_from_roots(ExpSpace::symmetric(c, 20).roots());
            let r = relative_residual(&p, 1.0, &bad);
            assert!(r > 1e3 * u.residual().max(1e-16), "c = {c}: a perturbed series' residual {r:e}");
        }
    }

    /// Orders above the table are differentiated on demand instead of panicking; the ODE
    /// itself checks them: for `(D² − c²)²`, `ℓ⁗ = 2c² ℓ″ − c⁴ ℓ`.
    #[test]
    #[allow(clippy::needless_range_loop)] // i indexes every derivative row of d
    fn derivatives_beyond_the_table_satisfy_the_ode() {
        let c: f64 = 2.5;
        let conds = [(0.0, 0), (0.0, 1), (1.0, 0), (1.0, 1)].map(|(u, order)| CondSpec { u, order });
        let card = UltraCardinal::new(&ExpSpace::symmetric(c, 2), &conds, 2).unwrap();
        assert_eq!(card.kmax(), 2);
        for u in [0.0, 0.13, 0.5, 0.91, 1.0] {
            let d = card.eval(u, 4);
            assert_eq!(d.len(), 5);
            for i in 0..4 {
                let want = 2.0 * c * c * d[2][i] - c.powi(4) * d[0][i];
                let scale = (2.0 * c * c * d[2][i]).abs() + (c.powi(4) * d[0][i]).abs() + 1.0;
                // series differentiated twice: round-off grows like the terms' size K⁴ε
                assert!((d[4][i] - want).abs() <= 1e-9 * scale, "u = {u}, ℓ_{i}: {} vs {want}", d[4][i]);
            }
        }
    }
}
