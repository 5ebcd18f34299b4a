//! The per-component operators of static blends.

use super::BlendError;
use crate::ode::polynomial_roots;

/// `L = Σ_{i=0}^{r} cᵢ ∂u^{2(r−i)} ∂v^{2i}`, the operator of order `2r` acting on one
/// component of a static blend (SPEC §4):
///
/// - `r = 1`: `a ∂u² + b ∂v²`;
/// - `r = 2`: `a ∂u⁴ + b ∂u²∂v² + c ∂v⁴`;
/// - `r = 3`: `a ∂u⁶ + b ∂u⁴∂v² + c ∂u²∂v⁴ + d ∂v⁶`.
///
/// On `X = U(u) g(v)` with `g″ = μ g` it acts as `P_μ(D) U · g` with the characteristic
/// polynomial `P_μ(s) = Σᵢ cᵢ μⁱ s^{2(r−i)}` ([`Operator::characteristic`]).
///
/// **Admissible coefficients.** `a = c₀ ≠ 0` is required: without `∂u^{2r}` the ODE in `u`
/// drops order and cannot take the `2r` conditions (rejected with an error). The
/// operator is *elliptic* when its symbol `Σ cᵢ ξ^{2(r−i)} η^{2i}` vanishes only at
/// `ξ = η = 0`, i.e. `Q(τ) = Σ cᵢ τⁱ` has no root `τ ≥ 0` and `c_r ≠ 0`; that is what makes
/// the blend well posed for all data. A non-elliptic operator with `a ≠ 0` is still solved
/// (the separable solver works per mode, and collocation minimises the residual), but
/// mode systems may be singular — those are reported as errors when they occur — and
/// [`Operator::is_elliptic`] lets the caller warn.
///
/// ```
/// use pdeshape_core::blend::Operator;
/// let bi = Operator::laplacian_power(2); // ∂u⁴ + 2∂u²∂v² + ∂v⁴
/// assert_eq!(bi.coefficients(), &[1.0, 2.0, 1.0]);
/// assert!(bi.is_elliptic());
/// // μ = −1 (cos v): P(s) = s⁴ − 2s² + 1 = (s² − 1)²
/// assert_eq!(bi.characteristic(-1.0), vec![1.0, 0.0, -2.0, 0.0, 1.0]);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct Operator {
    coef: Vec<f64>,
}

impl Operator {
    /// The operator with coefficients `c₀ … c_r` (`c₀` multiplies `∂u^{2r}`).
    pub fn new(coef: Vec<f64>) -> Result<Self, BlendError> {
        if coef.len() < 2 {
            return Err(BlendError::Operator(format!(
                "{} coefficient(s): an operator of order 2r needs r + 1 ≥ 2",
                coef.len()
            )));
        }
        if let Some(k) = coef.iter().position(|c| !c.is_finite()) {
            return Err(BlendError::Operator(format!("coefficient {k} is not finite ({})", coef[k])));
        }
        let scale = coef.iter().fold(0.0f64, |m, c| m.max(c.abs()));
        if coef[0].abs() <= 1e-12 * scale || coef[0] == 0.0 {
            return Err(BlendError::Operator(format!(
                "the coefficient of ∂u^{} is zero: the blend could not take its {} conditions in u",
                2 * (coef.len() - 1),
                2 * (coef.len() - 1)
            )));
        }
        Ok(Operator { coef })
    }

    /// `(∂u² + ∂v²)^r`: binomial coefficients.
    pub fn laplacian_power(r: usize) -> Self {
        let mut c = vec![1.0];
        for _ in 0..r {
            let mut next = vec![0.0; c.len() + 1];
            for (i, x) in c.iter().enumerate() {
                next[i] += x;
                next[i + 1] += x;
            }
            c = next;
        }
        Operator { coef: c }
    }

    /// `r`: the operator has order `2r` and takes the conditions `∂ᵏ/∂uᵏ`, `k < r`, at
    /// `u = 0` and `u = 1`.
    pub fn half_order(&self) -> usize {
        self.coef.len() - 1
    }

    /// `c₀ … c_r`.
    pub fn coefficients(&self) -> &[f64] {
        &self.coef
    }

    /// Whether the symbol vanishes only at the origin (see the type docs).
    pub fn is_elliptic(&self) -> bool {
        let r = self.half_order();
        if self.coef[r] == 0.0 {
            return false;
        }
        match polynomial_roots(&self.coef) {
            Ok(roots) => {
                let scale = roots.roots.iter().fold(1.0f64, |m, x| m.max(x.re.abs()));
                !roots.roots.iter().any(|x| x.im == 0.0 && x.re >= -1e-12 * scale)
            }
            Err(_) => false,
        }
    }

    /// Ascending coefficients of `P_μ(s) = Σᵢ cᵢ μⁱ s^{2(r−i)}`.
    pub fn characteristic(&self, mu: f64) -> Vec<f64> {
        let r = self.half_order();
        let mut p = vec![0.0; 2 * r + 1];
        for (i, c) in self.coef.iter().enumerate() {
            p[2 * (r - i)] += c * mu.powi(i as i32);
        }
        p
    }

    /// `L X` at a point from the partials `d(i, j) = ∂^{i+j}X/∂uⁱ∂vʲ`.
    pub fn apply(&self, d: impl Fn(usize, usize) -> f64) -> f64 {
        let r = self.half_order();
        self.coef.iter().enumerate().map(|(i, c)| c * d(2 * (r - i), 2 * i)).sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn admissibility_and_ellipticity() {
        assert!(Operator::new(vec![0.0, 1.0]).is_err());
        assert!(Operator::new(vec![1.0]).is_err());
        assert!(Operator::new(vec![1.0, f64::NAN]).is_err());
        assert!(Operator::new(vec![2.0, 3.0]).unwrap().is_elliptic());
        // a ∂u² − b ∂v²: the wave operator
        assert!(!Operator::new(vec![1.0, -1.0]).unwrap().is_elliptic());
        // ∂u⁴ − 3∂u²∂v² + ∂v⁴: Q(τ) = 1 − 3τ + τ² has positive roots
        assert!(!Operator::new(vec![1.0, -3.0, 1.0]).unwrap().is_elliptic());
        // no ∂v⁴: symbol vanishes at ξ = 0
        assert!(!Operator::new(vec![1.0, 2.0, 0.0]).unwrap().is_elliptic());
        assert!(Operator::laplacian_power(3).is_elliptic());
        assert_eq!(Operator::laplacian_power(3).coefficients(), &[1.0, 3.0, 3.0, 1.0]);
    }
}
