//! A fill's edge that is a curve in a neighbour's parameter domain — an expression curve on a
//! surface, or a trim curve of another patch — seen as an isoline: the neighbour
//! reparametrised around the curve,
//!
//! `R(σ, τ) = S(c(τ) + σ ν(τ))`,  `ν = (−c₂′, c₁′)` (the curve's tangent turned by +90°),
//!
//! whose isoline `σ = 0` is `S(c(τ))`. `R` is the same surface near the curve (a change of
//! parameters), so positions, tangent planes and second fundamental forms along the edge are
//! the neighbour's; the fill's isoline machinery ([`super::FillEdge`]) applies unchanged.
//! Derivatives are exact: with `δu(σ, τ)`, `δv(σ, τ)` the Taylor polynomials of the map
//! `(σ, τ) ↦ c(τ) + σ ν(τ)` around the point (exact derivatives of `c`),
//! `R = Σ_{i+j≤K} ∂ᵢ∂ⱼS/(i! j!) δuⁱ δvʲ` truncated at the requested total order `K`.

use crate::Vec3;
use crate::data::{Field, FieldRef, VecJet};
use crate::jet::{Jet, JetShape};
use crate::patch::Surface;
use crate::trim::TrimCurve;
use std::sync::Arc;

/// What the curve lies on.
#[derive(Clone)]
pub enum Host {
    /// A surface `S(s, w, t)` given as a field (slots `s`, `w`, `t`).
    Field(FieldRef),
    /// A patch `X(u, v)`.
    Patch(Arc<dyn Surface>),
}

/// The curve in the host's parameter domain.
#[derive(Clone, Debug)]
pub enum DomainCurve {
    /// Components 0 and 1 of a field of one slot `τ` (e.g. compiled expressions).
    Field(FieldRef),
    /// A trim curve, `τ ∈ [0, 2π)`.
    Trim(TrimCurve),
}

/// `R(σ, τ) = S(c(τ) + σ ν(τ))` (slots `σ`, `τ`, `t`).
#[derive(Clone)]
pub struct AlongCurve {
    /// The neighbour.
    pub host: Host,
    /// The curve in its domain.
    pub curve: DomainCurve,
}

impl std::fmt::Debug for AlongCurve {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "AlongCurve({:?})", self.curve)
    }
}

impl AlongCurve {
    /// `c⁽ᵐ⁾(τ)` for `m = 0 … k`.
    pub fn curve_derivatives(&self, tau: f64, k: usize) -> Vec<[f64; 2]> {
        match &self.curve {
            DomainCurve::Trim(c) => c.derivatives(tau, k),
            DomainCurve::Field(f) => {
                let mut d = vec![Vec3::ZERO; k + 1];
                f.derivatives_in(&[tau], 0, &mut d);
                d.iter().map(|x| [x.x, x.y]).collect()
            }
        }
    }

    /// Taylor coefficients `∂ᵢ∂ⱼS/(i! j!)` of the host at `(u, v)` for `i, j ≤ k`, at index
    /// `i (k + 1) + j`.
    fn host_taylor(&self, u: f64, v: f64, t: f64, k: usize) -> Vec<Vec3> {
        match &self.host {
            Host::Field(f) => {
                let j = f.jet(&[u, v, t], JetShape::new(&[k, k, 0]));
                (0..=k)
                    .flat_map(|i| (0..=k).map(move |l| [i, l, 0]))
                    .map(|m| Vec3::new(j.0[0].coeff(m), j.0[1].coeff(m), j.0[2].coeff(m)))
                    .collect()
            }
            Host::Patch(s) => {
                let d = s.derivatives(u, v, k, k);
                let fact: Vec<f64> = (0..=k)
                    .scan(1.0, |f, i| Some(if i == 0 { 1.0 } else { *f * i as f64 }).inspect(|x| *f = *x))
                    .collect();
                (0..=k)
                    .flat_map(|i| (0..=k).map(move |l| (i, l)))
                    .map(|(i, l)| d[i * (k + 1) + l] * (1.0 / (fact[i] * fact[l])))
                    .collect()
            }
        }
    }

    /// The host's domain point `c(τ) + σ ν(τ)`.
    pub fn domain_point(&self, sigma: f64, tau: f64) -> [f64; 2] {
        let c = self.curve_derivatives(tau, 1);
        [c[0][0] - sigma * c[1][1], c[0][1] + sigma * c[1][0]]
    }
}

impl Field for AlongCurve {
    fn arity(&self) -> usize {
        3
    }

    fn jet(&self, at: &[f64], shape: JetShape) -> VecJet {
        let [ks, kw, _] = shape.orders();
        let (sigma, tau) = (at[0], at.get(1).copied().unwrap_or(0.0));
        let t = at.get(2).copied().unwrap_or(0.0);
        let k = ks + kw;
        let c = self.curve_derivatives(tau, kw + 1);
        let (u0, v0) = (c[0][0] - sigma * c[1][1], c[0][1] + sigma * c[1][0]);
        let d = self.host_taylor(u0, v0, t, k);
        if k == 0 {
            return VecJet::constant(shape, d[0]);
        }
        // Taylor series in τ of c and ν = (−c₂′, c₁′)
        let mut fact = 1.0;
        let (mut cu, mut cv, mut nu, mut nv) = (vec![], vec![], vec![], vec![]);
        for m in 0..=kw {
            if m > 0 {
                fact *= m as f64;
            }
            cu.push(c[m][0] / fact);
            cv.push(c[m][1] / fact);
            nu.push(-c[m + 1][1] / fact);
            nv.push(c[m + 1][0] / fact);
        }
        // δu(σ, τ) = c₁(τ) + σ ν₁(τ) − u₀ as a jet in (δσ, δτ): the Taylor coefficients
        // of c₁ + σ₀ ν₁ along τ, those of ν₁ one order up in σ (the value cancels u₀)
        let offset = |c: &[f64], n: &[f64]| {
            let mut x = vec![0.0; shape.len()];
            for j in 1..=kw {
                x[shape.index([0, j, 0])] = c[j] + sigma * n[j];
                if ks >= 1 {
                    x[shape.index([1, j, 0])] = n[j];
                }
            }
            if ks >= 1 {
                x[shape.index([1, 0, 0])] = n[0];
            }
            Jet::from_coeffs(shape, x)
        };
        let (du, dv) = (offset(&cu, &nu), offset(&cv, &nv));
        let mut out = [vec![0.0; shape.len()], vec![0.0; shape.len()], vec![0.0; shape.len()]];
        let mut du_pow = Jet::constant(shape, 1.0);
        for i in 0..=k {
            if i > 0 {
                du_pow = du_pow.mul(&du);
            }
            let mut term = du_pow.clone();
            for j in 0..=k - i {
                if j > 0 {
                    term = term.mul(&dv);
                }
                let coef = d[i * (k + 1) + j];
                for (o, x) in out.iter_mut().zip([coef.x, coef.y, coef.z]) {
                    for (a, t) in o.iter_mut().zip(term.coeffs()) {
                        *a += x * t;
                    }
                }
            }
        }
        VecJet(out.map(|c| Jet::from_coeffs(shape, c)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::ExprField;

    /// A curve on a paraboloid against the closed form: `S(s, w) = (s, w, s² + w²)`,
    /// `c(τ) = (cos τ, sin τ)` (the unit circle), so `ν = (−cos τ, −sin τ)` and
    /// `R(σ, τ) = ((1 − σ) cos τ, (1 − σ) sin τ, (1 − σ)²)`: every derivative up to
    /// `∂σ²∂τ³` by hand, through the field host and through the patch host.
    #[test]
    fn along_a_circle_on_a_paraboloid() {
        let s = ExprField::parse(["s", "w", "s*s + w*w"], &["s", "w", "t"], &|_| None).unwrap();
        let c = ExprField::parse(["cos(t)", "sin(t)", "0"], &["t"], &|_| None).unwrap();
        let field = AlongCurve { host: Host::Field(Arc::new(s)), curve: DomainCurve::Field(Arc::new(c)) };
        let trim = AlongCurve {
            host: Host::Patch(Arc::new(crate::patch::test_shapes::Paraboloid)),
            curve: DomainCurve::Trim(TrimCurve::ellipse([0.0, 0.0], [1.0, 1.0])),
        };
        for r in [&field, &trim] {
            for (sigma, tau) in [(0.0, 0.3), (0.2, 2.0), (-0.1, 4.4)] {
                let j = r.jet(&[sigma, tau, 0.0], JetShape::new(&[2, 3, 0]));
                let a = 1.0 - sigma;
                for i in 0..=2usize {
                    for l in 0..=3usize {
                        // ∂σⁱ∂τˡ of (a cos τ, a sin τ, a²) with a = 1 − σ
                        let da = [a, -1.0, 0.0][i];
                        let da2 = [a * a, -2.0 * a, 2.0][i];
                        let ph = tau + l as f64 * std::f64::consts::FRAC_PI_2;
                        let want = Vec3::new(da * ph.cos(), da * ph.sin(), if l == 0 { da2 } else { 0.0 });
                        let f = |n: usize| (1..=n).product::<usize>() as f64;
                        let got = Vec3::new(j.0[0].coeff([i, l, 0]), j.0[1].coeff([i, l, 0]), j.0[2].coeff([i, l, 0]))
                            * (f(i) * f(l));
                        assert!((got - want).norm() < 1e-13, "{i} {l} at ({sigma}, {tau}): {got} vs {want}");
                    }
                }
            }
        }
    }
}
