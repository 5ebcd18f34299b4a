//! The solution space of `P(D) y = 0` with a bounded basis.

use num_complex::Complex64;

/// A root of the characteristic polynomial with its multiplicity. Complex roots are given
/// once, with `im > 0`; their conjugate is implied.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Root {
    /// Real part.
    pub re: f64,
    /// Imaginary part (≥ 0; > 0 means a conjugate pair).
    pub im: f64,
    /// Multiplicity.
    pub mult: usize,
}

/// `K = ker P(D)`, the solutions of a constant-coefficient ODE, with a bounded real basis.
///
/// ```
/// use pdeshape_core::ode::ExpSpace;
/// // (D² − 4)² : roots ±2, each double: basis (u−1)e^{2(u−1)}… of dimension 4.
/// let k = ExpSpace::symmetric(2.0, 2);
/// assert_eq!(k.dim(), 4);
/// let d = k.derivatives(0.3, 1);
/// assert_eq!(d.len(), 2);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct ExpSpace {
    roots: Vec<Root>,
    dim: usize,
}

/// Binomial coefficient as f64.
fn binom(n: usize, k: usize) -> f64 {
    (0..k).fold(1.0, |acc, i| acc * (n - i) as f64 / (i + 1) as f64)
}

impl ExpSpace {
    /// The space of the given roots.
    pub fn from_roots(roots: Vec<Root>) -> Self {
        let dim = roots.iter().map(|r| if r.im > 0.0 { 2 * r.mult } else { r.mult }).sum();
        ExpSpace { roots, dim }
    }

    /// `ker P(D)` for `P(s) = Σ_k c[k] s^k` (real coefficients, any roots): see
    /// [`polynomial_roots`](super::polynomial_roots).
    ///
    /// ```
    /// use pdeshape_core::ode::ExpSpace;
    /// // y⁗ + 2y″ + y = 0: roots ±i, each double.
    /// let k = ExpSpace::from_polynomial(&[1.0, 0.0, 2.0, 0.0, 1.0]).unwrap();
    /// assert_eq!(k.dim(), 4);
    /// assert_eq!(k.roots()[0].mult, 2);
    /// ```
    pub fn from_polynomial(c: &[f64]) -> Result<Self, super::OdeError> {
        Ok(Self::from_roots(super::polynomial_roots(c)?.roots))
    }

    /// `ker (D² − c²)^N`: roots `±c` of multiplicity `N` (polynomials of degree `2N − 1`
    /// when `c = 0`). This is mode `n` of `(∂u² + a²∂v²)^N` with `c = a n`.
    pub fn symmetric(c: f64, n: usize) -> Self {
        let c = c.abs();
        if c == 0.0 {
            Self::from_roots(vec![Root { re: 0.0, im: 0.0, mult: 2 * n }])
        } else {
            Self::from_roots(vec![Root { re: c, im: 0.0, mult: n }, Root { re: -c, im: 0.0, mult: n }])
        }
    }

    /// The dimension (the order of the ODE).
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// The roots.
    pub fn roots(&self) -> &[Root] {
        &self.roots
    }

    /// `out[j][b] = φ_b^{(j)}(u)` for `j = 0 … kmax` and every basis function `b`.
    pub fn derivatives(&self, u: f64, kmax: usize) -> Vec<Vec<f64>> {
        let mut out = vec![Vec::with_capacity(self.dim); kmax + 1];
        for r in &self.roots {
            if r.re == 0.0 && r.im == 0.0 {
                // Polynomials of degree < mult: Chebyshev T_k(x), x = 2u − 1, with
                // derivatives by the recurrence of the derivative tables.
                let m = r.mult;
                let x = 2.0 * u - 1.0;
                // t[j][k] = d^j/dx^j T_k(x)
                let mut t = vec![vec![0.0; m.max(1)]; kmax + 1];
                for j in 0..=kmax {
                    for k in 0..m {
                        t[j][k] = match (k, j) {
                            (0, 0) => 1.0,
                            (0, _) => 0.0,
                            (1, 0) => x,
                            (1, 1) => 1.0,
                            (1, _) => 0.0,
                            // T_{k}^{(j)} = 2x T_{k-1}^{(j)} + 2j T_{k-1}^{(j-1)} − T_{k-2}^{(j)}
                            _ => {
                                2.0 * x * t[j][k - 1] + if j > 0 { 2.0 * j as f64 * t[j - 1][k - 1] } else { 0.0 }
                                    - t[j][k - 2]
                            }
                        };
                    }
                }
                for (j, row) in out.iter_mut().enumerate() {
                    let scale = 2f64.powi(j as i32); // d/du = 2 d/dx
                    row.extend(t[j].iter().take(m).map(|v| v * scale));
                }
                continue;
            }
            let anchor = if r.re > 0.0 { 1.0 } else { 0.0 };
            let w = u - anchor;
            let rc = Complex64::new(r.re, r.im);
            let e = (rc * w).exp();
            for k in 0..r.mult {
                for (j, row) in out.iter_mut().enumerate() {
                    // d^j/du^j [w^k e^{rw}] = Σ_i C(j,i) k!/(k−i)! w^{k−i} r^{j−i} e^{rw}
                    let mut s = Complex64::new(0.0, 0.0);
                    let mut fall = 1.0;
                    for i in 0..=j.min(k) {
                        if i > 0 {
                            fall *= (k - i + 1) as f64;
                        }
                        s += rc.powu((j - i) as u32) * (binom(j, i) * fall * w.powi((k - i) as i32));
                    }
                    let v = s * e;
                    row.push(v.re);
                    if r.im > 0.0 {
                        row.push(v.im);
                    }
                }
            }
        }
        out
    }
}

#[cfg(test)]
#[allow(clippy::needless_range_loop)] // derivative tables are indexed [order][basis]
mod tests {
    use super::*;

    /// Each basis function solves the ODE: for (D² − c²)^N, apply the operator through
    /// the derivative table and check the result vanishes.
    #[test]
    fn basis_functions_solve_the_ode() {
        for (c, n) in [(0.0, 3), (1.5, 2), (7.0, 3), (30.0, 2)] {
            let k = ExpSpace::symmetric(c, n);
            let d = k.derivatives(0.37, 2 * n);
            // coefficients of (s² − c²)^N in s: Σ_j C(N,j) (−c²)^{N−j} s^{2j}
            for b in 0..k.dim() {
                let mut acc = 0.0;
                let mut scale: f64 = 0.0;
                for j in 0..=n {
                    let coef = binom(n, j) * (-c * c).powi((n - j) as i32);
                    acc += coef * d[2 * j][b];
                    scale = scale.max((coef * d[2 * j][b]).abs());
                }
                assert!(acc.abs() <= 1e-12 * scale.max(1.0), "c {c} N {n} basis {b}: residual {acc}");
            }
        }
        // complex roots: e^{(α ± iβ)u} solve D² − 2αD + α² + β² = 0
        let k = ExpSpace::from_roots(vec![Root { re: -0.5, im: 2.0, mult: 1 }]);
        let d = k.derivatives(0.8, 2);
        for b in 0..2 {
            let r = d[2][b] + 1.0 * d[1][b] + (0.25 + 4.0) * d[0][b];
            assert!(r.abs() < 1e-13);
        }
    }
}
