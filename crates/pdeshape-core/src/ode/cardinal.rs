//! Cardinal functions of a condition set.

use super::ExpSpace;
use crate::linalg::{LinalgError, SquareSolver};
use crate::num::MaxNan;
use faer::Mat;

/// A condition `y^{(order)}(u) = …` of the boundary-value problem.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CondSpec {
    /// Where.
    pub u: f64,
    /// Derivative order.
    pub order: usize,
}

/// A boundary-value problem that has no unique solution.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum OdeError {
    /// The number of conditions is not the order of the ODE.
    #[error("{got} conditions for an ODE of order {dim}: exactly {dim} are needed")]
    Count {
        /// Conditions given.
        got: usize,
        /// ODE order.
        dim: usize,
    },
    /// Two conditions are identical.
    #[error("conditions {0} and {1} are identical (both ∂^{2} at u = {3}): they clash")]
    Duplicate(usize, usize, usize, f64),
    /// The characteristic polynomial is unusable (degenerate, not finite).
    #[error("characteristic polynomial: {0}")]
    Polynomial(String),
    /// The condition matrix is singular.
    #[error("the conditions do not determine a unique solution (condition number {cond:.2e}{detail})")]
    Singular {
        /// Condition number.
        cond: f64,
        /// Which conditions, when known.
        detail: String,
    },
}

/// The cardinal functions `ℓ_i ∈ K` of a condition set: `ℓ_i^{(d_k)}(u_k) = δ_ik`.
///
/// ```
/// use pdeshape_core::ode::{Cardinal, CondSpec, ExpSpace};
/// // Cubic Hermite interpolation is the case c = 0, N = 2 with value and slope at 0 and 1.
/// let conds = [CondSpec { u: 0.0, order: 0 }, CondSpec { u: 0.0, order: 1 },
///              CondSpec { u: 1.0, order: 0 }, CondSpec { u: 1.0, order: 1 }];
/// let l = Cardinal::new(ExpSpace::symmetric(0.0, 2), &conds).unwrap();
/// let v = l.eval(0.5, 0);
/// assert!((v[0][0] - 0.5).abs() < 1e-14 && (v[0][3] + 0.125).abs() < 1e-14);
/// ```
#[derive(Clone, Debug)]
pub struct Cardinal {
    space: ExpSpace,
    conds: Vec<CondSpec>,
    /// Column i: the basis coefficients of ℓ_i.
    coef: Mat<f64>,
    cond: f64,
}

/// Largest condition number accepted for the condition matrix in f64.
pub const MAX_COND: f64 = 1e13;

impl Cardinal {
    /// Solves for the cardinal functions of `conds` in `space`.
    pub fn new(space: ExpSpace, conds: &[CondSpec]) -> Result<Self, OdeError> {
        let n = space.dim();
        if conds.len() != n {
            return Err(OdeError::Count { got: conds.len(), dim: n });
        }
        for i in 0..n {
            for j in i + 1..n {
                if conds[i].u == conds[j].u && conds[i].order == conds[j].order {
                    return Err(OdeError::Duplicate(i, j, conds[i].order, conds[i].u));
                }
            }
        }
        let kmax = conds.iter().map(|c| c.order).max().unwrap_or(0);
        // Φ[i][b] = φ_b^{(d_i)}(u_i)
        let rows: Vec<Vec<f64>> = conds.iter().map(|c| space.derivatives(c.u, kmax)[c.order].clone()).collect();
        // Equilibrated: M = D Φ E with E scaling each basis function's column and D each
        // condition's row to unit max-norm (powers of two, so the scaling is exact). The
        // bounded basis can still be badly scaled: for a root ±c of multiplicity 2,
        // `w e^{−c w}` peaks at 1/(e c), and derivative rows carry a factor c, so the raw
        // Φ has κ ≈ c² (6.5e4 at c = 256) where M has κ ≈ 3. LU with full pivoting of M is
        // backward stable for M, so the relative error of each column of M⁻¹ (and so of
        // each cardinal function, measured against the basis functions' own size) is
        // κ(M) ε: κ(M) is the condition number that decides between f64 and the other
        // paths.
        let pow2 = |x: f64| if x > 0.0 && x.is_finite() { 2f64.powi(-(x.log2().round() as i32)) } else { 1.0 };
        let e: Vec<f64> = (0..n).map(|b| pow2(rows.iter().map(|r| r[b].abs()).max_nan())).collect();
        let d: Vec<f64> = rows.iter().map(|r| pow2(r.iter().zip(&e).map(|(x, eb)| (x * eb).abs()).max_nan())).collect();
        let m = Mat::from_fn(n, n, |i, b| d[i] * rows[i][b] * e[b]);
        let solver = SquareSolver::new(&m, MAX_COND).map_err(|e| match e {
            LinalgError::Singular { cond } => OdeError::Singular { cond, detail: String::new() },
            _ => OdeError::Singular { cond: f64::INFINITY, detail: format!(": {e}") },
        })?;
        // ℓ = φ · Φ⁻¹ : coefficients C = Φ⁻¹ = E M⁻¹ D (column i ↦ ℓ_i).
        let mut coef = solver.solve(&Mat::from_fn(n, n, |i, j| if i == j { d[i] } else { 0.0 }));
        for b in 0..n {
            for i in 0..n {
                coef[(b, i)] *= e[b];
            }
        }
        Ok(Cardinal { space, conds: conds.to_vec(), coef, cond: solver.cond() })
    }

    /// `out[k][i] = ℓ_i^{(k)}(u)` for `k = 0 … kmax`.
    ///
    /// At a condition's own place and order the row is the exact unit vector the cardinal
    /// property defines, `ℓ_i^{(k_c)}(u_c) = δ_ic`, as the tabulated sets store theirs: the
    /// sums in f64 carry `φ^{(k)}`'s size (`ω⁹ ≈ 4e7` for a ninth derivative at `ω = 7`)
    /// times the coefficients' round-off, and a ninth-derivative condition then held to
    /// 3e-10 only.
    pub fn eval(&self, u: f64, kmax: usize) -> Vec<Vec<f64>> {
        let d = self.space.derivatives(u, kmax);
        let n = self.space.dim();
        let mut out: Vec<Vec<f64>> =
            d.iter().map(|row| (0..n).map(|i| (0..n).map(|b| row[b] * self.coef[(b, i)]).sum()).collect()).collect();
        for (c, cd) in self.conds.iter().enumerate() {
            if cd.u == u && cd.order <= kmax {
                out[cd.order] = (0..n).map(|i| f64::from(i == c)).collect();
            }
        }
        out
    }

    /// The places of the conditions, sorted, each once: where [`eval`](Self::eval) answers
    /// rows of the cardinal property itself.
    pub fn condition_places(&self) -> Vec<f64> {
        let mut at: Vec<f64> = self.conds.iter().map(|c| c.u).collect();
        at.sort_by(f64::total_cmp);
        at.dedup();
        at
    }

    /// The 2-norm condition number of the condition matrix in the bounded basis, rows and
    /// columns equilibrated (the one that bounds the cardinal functions' relative error).
    pub fn condition_number(&self) -> f64 {
        self.cond
    }

    /// The conditions.
    pub fn conditions(&self) -> &[CondSpec] {
        &self.conds
    }

    /// The space.
    pub fn space(&self) -> &ExpSpace {
        &self.space
    }

    /// `C`: column `i` holds the coefficients of `ℓ_i` in the space's basis
    /// ([`ExpSpace::derivatives`]' order), `ℓ_i = Σ_b φ_b C_{bi}`.
    pub fn coefficients(&self) -> &Mat<f64> {
        &self.coef
    }

    /// The Lebesgue constant `max_u Σ_i |ℓ_i(u)|` estimated on `samples` equispaced points
    /// (and the condition points): the factor by which the data can be amplified between
    /// the conditions.
    pub fn lebesgue(&self, samples: usize) -> f64 {
        let pts = (0..=samples).map(|k| k as f64 / samples as f64).chain(self.conds.iter().map(|c| c.u));
        pts.map(|u| self.eval(u, 0)[0].iter().map(|x| x.abs()).sum::<f64>()).max_nan()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check_cardinal(l: &Cardinal, tol: f64) {
        let kmax = l.conditions().iter().map(|c| c.order).max().unwrap();
        for (k, c) in l.conditions().iter().enumerate() {
            let v = l.eval(c.u, kmax);
            for (i, x) in v[c.order].iter().enumerate() {
                let want = if i == k { 1.0 } else { 0.0 };
                assert!((x - want).abs() < tol, "ℓ_{i}^({})({}) = {x}", c.order, c.u);
            }
        }
    }

    #[test]
    fn cardinal_functions_meet_their_conditions() {
        let four = [0.0, 0.3, 0.7, 1.0].map(|u| CondSpec { u, order: 0 });
        for c in [0.0, 0.5, 1.1, 4.4, 25.0] {
            check_cardinal(&Cardinal::new(ExpSpace::symmetric(c, 2), &four).unwrap(), 1e-12);
        }
        let mixed = [(0.0, 0), (0.0, 1), (0.0, 2), (0.5, 0), (1.0, 0), (1.0, 1), (1.0, 2), (0.5, 3)]
            .map(|(u, order)| CondSpec { u, order });
        for c in [0.0, 1.0, 3.0, 12.0] {
            check_cardinal(&Cardinal::new(ExpSpace::symmetric(c, 4), &mixed).unwrap(), 1e-10);
        }
    }

    /// High Fourier modes of a 4th-order patch (rates c = a·m in the hundreds) are well
    /// conditioned once the bounded basis is equilibrated: before, the raw condition
    /// number (≈ c²) sent them to multiple precision, whose Chebyshev tables did not
    /// resolve `e^{−cu}` (a four-curve patch with M = 256 met its conditions to 4e-6).
    /// Independent closed forms for c ≥ 50, where `e^{−c}` terms are below 1e-19: the
    /// value cardinal at 0 is `(1 + cu) e^{−cu}` (value 1, slope 0 at 0) and the slope
    /// cardinal at 0 is `u e^{−cu}`.
    #[test]
    fn steep_modes_are_well_conditioned_in_f64() {
        let conds = [(0.0, 0), (0.0, 1), (1.0, 0), (1.0, 1)].map(|(u, order)| CondSpec { u, order });
        for c in [50.0, 100.0, 256.0, 1000.0, 4000.0] {
            let set = crate::ode::CardinalSet::new(ExpSpace::symmetric(c, 2), &conds, 1).unwrap();
            assert_eq!(set.method(), "f64", "c = {c}");
            // κ of the equilibrated matrix is a small constant (measured 2.6 … 3.1)
            assert!(set.condition_number() < 10.0, "c = {c}: κ = {}", set.condition_number());
            for k in 0..=200 {
                let u = (k as f64 / 200.0).powi(3); // dense near u = 0, where the functions vary
                let l = set.eval(u, 1);
                let e = (-c * u).exp();
                let (value, slope) = ((1.0 + c * u) * e, u * e);
                // round-off of O(1) values times κ; the slope cardinal is O(1/c), so its
                // error is measured against 1/c, its size
                assert!((l[0][0] - value).abs() < 1e-14, "c = {c}, u = {u}: {} vs {value}", l[0][0]);
                assert!((l[0][1] - slope).abs() * c < 1e-14, "c = {c}, u = {u}: {} vs {slope}", l[0][1]);
                assert!((l[1][0] + c * c * u * e).abs() / c < 1e-13, "c = {c}, u = {u}: slope of ℓ_0");
            }
        }
    }

    #[test]
    fn clashing_conditions_are_named() {
        let dup = [(0.0, 0), (0.5, 0), (0.5, 0), (1.0, 0)].map(|(u, order)| CondSpec { u, order });
        let e = Cardinal::new(ExpSpace::symmetric(1.0, 2), &dup).unwrap_err();
        assert_eq!(e, OdeError::Duplicate(1, 2, 0, 0.5));
        let few = [CondSpec { u: 0.0, order: 0 }];
        assert!(matches!(Cardinal::new(ExpSpace::symmetric(1.0, 2), &few), Err(OdeError::Count { .. })));
    }
}
