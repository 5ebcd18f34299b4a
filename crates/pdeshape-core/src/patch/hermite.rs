//! Two-point Hermite interpolation in `u` and the ruled/Hermite patch.

use super::{Condition, Surface, VDomain};
use crate::Vec3;
use crate::data::FieldRef;
use crate::jet::JetShape;
use crate::linalg::SquareSolver;
use faer::Mat;

/// A polynomial `Σ cₖ uᵏ` (monomial coefficients, lowest first).
#[derive(Clone, Debug, PartialEq)]
pub struct Poly(pub Vec<f64>);

impl Poly {
    /// `p⁽ᵏ⁾(u)`.
    pub fn derivative(&self, u: f64, k: usize) -> f64 {
        let mut s = 0.0;
        for (i, &c) in self.0.iter().enumerate().skip(k).rev() {
            let f: f64 = ((i - k + 1)..=i).map(|x| x as f64).product();
            s = s * u + c * f;
        }
        s
    }

    /// `p(u)`.
    pub fn eval(&self, u: f64) -> f64 {
        self.derivative(u, 0)
    }
}

/// The two-point Hermite basis of degree `2r − 1`: polynomials `H_{e,d}` (`e ∈ {0, 1}` the
/// end, `d < r` the derivative order) with `H_{e,d}⁽ᵏ⁾(e') = δ_{ee'} δ_{dk}` for `k < r`.
///
/// `r = 1` gives `1 − u, u`; `r = 2` the cubic Hermite polynomials
/// `1 − 3u² + 2u³, u − 2u² + u³, 3u² − 2u³, u³ − u²`.
///
/// ```
/// use pdeshape_core::patch::HermiteBasis;
/// let h = HermiteBasis::new(2);
/// assert!((h.basis(0, 0).eval(0.5) - 0.5).abs() < 1e-15);
/// assert!((h.basis(1, 1).eval(0.5) + 0.125).abs() < 1e-15);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct HermiteBasis {
    r: usize,
    polys: Vec<Poly>,
}

impl HermiteBasis {
    /// The basis with `r` conditions per end (`1 ≤ r ≤ 6`).
    pub fn new(r: usize) -> Self {
        assert!((1..=6).contains(&r), "Hermite basis with {r} conditions per end");
        let n = 2 * r;
        // Row (e, k): the k-th derivative at u = e of each monomial uʲ.
        let a = Mat::from_fn(n, n, |row, j| {
            let (e, k) = (row / r, row % r);
            Poly((0..n).map(|i| if i == j { 1.0 } else { 0.0 }).collect()).derivative(e as f64, k)
        });
        let solver = SquareSolver::new(&a, 1e12).expect("Hermite interpolation is unisolvent");
        let x = solver.solve(&Mat::<f64>::identity(n, n));
        let polys = (0..n).map(|col| Poly((0..n).map(|i| x[(i, col)]).collect())).collect();
        HermiteBasis { r, polys }
    }

    /// Conditions per end.
    pub fn r(&self) -> usize {
        self.r
    }

    /// `H_{e,d}`.
    pub fn basis(&self, end: usize, order: usize) -> &Poly {
        &self.polys[end * self.r + order]
    }
}

/// Errors building a Hermite patch.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum HermitePatchError {
    /// The conditions are not `∂⁰ … ∂^{r−1}` at both `u = 0` and `u = 1`.
    #[error("a Hermite patch needs the same derivative orders 0 … r−1 (r ≤ 3) at u = 0 and at u = 1; got {0}")]
    BadConditions(String),
}

/// The ruled/Hermite patch: no PDE, just two-point Hermite interpolation in `u`,
///
/// `X(u, v) = Σ_{d<r} [H_{0,d}(u) g_{0,d}(v) + H_{1,d}(u) g_{1,d}(v)]`,
///
/// linear (ruled) for positions only, cubic for positions and tangents, quintic with
/// second derivatives. It meets its conditions exactly by construction and is the
/// reference "no PDE" blend in comparisons.
#[derive(Clone, Debug)]
pub struct HermitePatch {
    basis: HermiteBasis,
    ends: [Vec<FieldRef>; 2],
    domain: VDomain,
    time: f64,
}

impl HermitePatch {
    /// Builds the patch from conditions at `u = 0` and `u = 1`.
    pub fn new(conds: &[Condition], domain: VDomain) -> Result<Self, HermitePatchError> {
        let describe = || conds.iter().map(|c| format!("∂^{} at u = {}", c.order, c.u)).collect::<Vec<_>>().join(", ");
        let mut ends: [Vec<Option<FieldRef>>; 2] = [vec![None; 3], vec![None; 3]];
        for c in conds {
            let e = if c.u == 0.0 {
                0
            } else if c.u == 1.0 {
                1
            } else {
                return Err(HermitePatchError::BadConditions(describe()));
            };
            if c.order >= 3 || ends[e][c.order].is_some() {
                return Err(HermitePatchError::BadConditions(describe()));
            }
            ends[e][c.order] = Some(c.data.clone());
        }
        let r = conds.len() / 2;
        if r == 0 || !conds.len().is_multiple_of(2) {
            return Err(HermitePatchError::BadConditions(describe()));
        }
        let take = |e: usize| -> Option<Vec<FieldRef>> { (0..r).map(|d| ends[e][d].clone()).collect() };
        let (Some(e0), Some(e1)) = (take(0), take(1)) else {
            return Err(HermitePatchError::BadConditions(describe()));
        };
        Ok(HermitePatch { basis: HermiteBasis::new(r), ends: [e0, e1], domain, time: 0.0 })
    }

    /// The same patch with its data evaluated at time `t`.
    pub fn at_time(&self, t: f64) -> Self {
        HermitePatch { time: t, ..self.clone() }
    }
}

impl Surface for HermitePatch {
    fn v_domain(&self) -> VDomain {
        self.domain
    }

    fn derivatives(&self, u: f64, v: f64, du: usize, dv: usize) -> Vec<Vec3> {
        let shape = JetShape::new(&[dv]);
        let mut out = vec![Vec3::ZERO; (du + 1) * (dv + 1)];
        for (e, fields) in self.ends.iter().enumerate() {
            for (d, g) in fields.iter().enumerate() {
                let gj = g.jet(&[v, self.time], shape);
                let h = self.basis.basis(e, d);
                for i in 0..=du {
                    let hi = h.derivative(u, i);
                    if hi == 0.0 {
                        continue;
                    }
                    for j in 0..=dv {
                        out[i * (dv + 1) + j] += gj.derivative([j, 0, 0]) * hi;
                    }
                }
            }
        }
        out
    }
}

/// The cubic Hermite functions `h₀₀ = 1 − 3u² + 2u³`, `h₁₀ = u(1 − u)²`, `h₀₁ = u²(3 − 2u)`,
/// `h₁₁ = u²(u − 1)` (value and slope at 0, value and slope at 1) and their derivatives:
/// `out[i][k] = h_i^{(k)}(u)`, `k ≤ 4`.
///
/// ```
/// use pdeshape_core::patch::cubic_hermite;
/// let h = cubic_hermite(1.0);
/// assert_eq!([h[0][0], h[1][1], h[2][0], h[3][1]], [0.0, 0.0, 1.0, 1.0]);
/// ```
pub fn cubic_hermite(u: f64) -> [[f64; 5]; 4] {
    let (u2, u3) = (u * u, u * u * u);
    [
        [1.0 - 3.0 * u2 + 2.0 * u3, -6.0 * u + 6.0 * u2, -6.0 + 12.0 * u, 12.0, 0.0],
        [u - 2.0 * u2 + u3, 1.0 - 4.0 * u + 3.0 * u2, -4.0 + 6.0 * u, 6.0, 0.0],
        [3.0 * u2 - 2.0 * u3, 6.0 * u - 6.0 * u2, 6.0 - 12.0 * u, -12.0, 0.0],
        [u3 - u2, 3.0 * u2 - 2.0 * u, 6.0 * u - 2.0, 6.0, 0.0],
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hermite_basis_meets_its_conditions() {
        for r in 1..=4 {
            let h = HermiteBasis::new(r);
            for e in 0..2 {
                for d in 0..r {
                    for e2 in 0..2 {
                        for k in 0..r {
                            let want = if e == e2 && d == k { 1.0 } else { 0.0 };
                            let got = h.basis(e, d).derivative(e2 as f64, k);
                            assert!((got - want).abs() < 1e-12, "r {r} H_{e},{d}^({k})({e2}) = {got}");
                        }
                    }
                }
            }
        }
        // The paper's cubic Hermite polynomials (paper 002 ξ₁…ξ₄).
        let h = HermiteBasis::new(2);
        for &u in &[0.1f64, 0.4, 0.9] {
            assert!((h.basis(0, 0).eval(u) - (1.0 - 3.0 * u * u + 2.0 * u.powi(3))).abs() < 1e-14);
            assert!((h.basis(0, 1).eval(u) - (u - 2.0 * u * u + u.powi(3))).abs() < 1e-14);
            assert!((h.basis(1, 0).eval(u) - (3.0 * u * u - 2.0 * u.powi(3))).abs() < 1e-14);
            assert!((h.basis(1, 1).eval(u) - (u.powi(3) - u * u)).abs() < 1e-14);
        }
    }
}
