//! A fill's edge that is a curve in a neighbour's parameter domain — an expression curve on a
//! surface, or a trim curve of another patch — seen as an isoline: the neighbour
//! reparametrised around the curve,
//!
//! `R(σ, τ) = S(c(τ) + σ ν(τ))`,  `ν = (−c₂′, c₁′)` (the curve's tangent turned by +90°),
//!
//! whose isoline `σ = 0` is `S(c(τ))`. `R` is the same surface near the curve (a change of
//! parameters), so positions, tangent planes and second fundamental forms along the edge are
//! the neighbour's; the fill's isoline machinery ([`super::FillEdge`]) applies unchanged.
//! Derivatives are exact (exact derivatives of `c` and of `S`, combined by Taylor
//! arithmetic): as `R` is linear in `σ` inside `S`, its coefficient of `δσᵃ` is
//! `Σ_{i+j=a} ν₁ⁱ ν₂ʲ ∂ᵢ∂ⱼS(p(τ))/(i! j!)` with `p = c + σ₀ ν`, and each `∂ᵢ∂ⱼS(p(τ))` is
//! the host's Taylor expansion at `p(τ₀)` composed with `δp(τ)`: products of series in
//! `δτ` alone (see [`AlongCurve`]'s `jet`).

use super::series::{binomial, mul_into};
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
        // With p(τ) = c(τ) + σ₀ ν(τ) and ν = (−c₂′, c₁′), expanding in δσ and then along p,
        //
        //   R(σ₀ + δσ, τ₀ + δτ) = Σ_a δσᵃ Σ_{i+j=a} ν₁ⁱ ν₂ʲ T_ij,
        //   T_ij = ∂ᵢ∂ⱼS(p(τ))/(i! j!) = Σ_{m+n≤K} C(i+m, i) C(j+n, j) d_{i+m, j+n} δp₁ᵐ δp₂ⁿ,
        //
        // with d_IJ the host's Taylor coefficients at p(τ₀) and δp = p(τ) − p(τ₀): every
        // factor a series in δτ alone (truncated at K = kw), so the coefficient of δσᵃ δτᵇ
        // needs only products of one-variable series.
        let n = kw + 1;
        let mut fact = 1.0;
        let (mut dp1, mut dp2, mut nu1, mut nu2) = (vec![0.0; n], vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        for m in 0..=kw {
            if m > 0 {
                fact *= m as f64;
                dp1[m] = (c[m][0] - sigma * c[m + 1][1]) / fact;
                dp2[m] = (c[m][1] + sigma * c[m + 1][0]) / fact;
            }
            nu1[m] = -c[m + 1][1] / fact;
            nu2[m] = c[m + 1][0] / fact;
        }
        // xᵐ for m = 0 … top, each a series of length n, flat
        let powers = |x: &[f64], top: usize| -> Vec<f64> {
            let mut p = vec![0.0; (top + 1) * n];
            p[0] = 1.0;
            for m in 1..=top {
                let (done, next) = p.split_at_mut(m * n);
                mul_into(&done[(m - 1) * n..], x, &mut next[..n]);
            }
            p
        };
        let (pw1, pw2) = (powers(&dp1, kw), powers(&dp2, kw));
        let (nw1, nw2) = (powers(&nu1, ks), powers(&nu2, ks));
        // δp₁ᵐ δp₂ˡ for m + l ≤ kw, with their (m, l)
        let mut mixed = Vec::with_capacity((kw + 1) * (kw + 2) / 2 * n);
        let mut ml = Vec::with_capacity((kw + 1) * (kw + 2) / 2);
        let mut q = vec![0.0; n];
        for m in 0..=kw {
            for l in 0..=kw - m {
                mul_into(&pw1[m * n..(m + 1) * n], &pw2[l * n..(l + 1) * n], &mut q);
                mixed.extend_from_slice(&q);
                ml.push((m, l));
            }
        }
        let mut out = [vec![0.0; shape.len()], vec![0.0; shape.len()], vec![0.0; shape.len()]];
        let (mut tij, mut nn) = (vec![Vec3::ZERO; n], vec![0.0; n]);
        for a in 0..=ks {
            for i in 0..=a {
                let j = a - i;
                tij.iter_mut().for_each(|t| *t = Vec3::ZERO);
                for (&(m, l), q) in ml.iter().zip(mixed.chunks_exact(n)) {
                    let w = d[(i + m) * (k + 1) + j + l] * (binomial(i + m, i) * binomial(j + l, j));
                    for (t, &x) in tij.iter_mut().zip(q) {
                        *t += w * x;
                    }
                }
                mul_into(&nw1[i * n..(i + 1) * n], &nw2[j * n..(j + 1) * n], &mut nn);
                for b in 0..n {
                    let x = (0..=b).fold(Vec3::ZERO, |acc, r| acc + tij[r] * nn[b - r]);
                    let idx = shape.index([a, b, 0]);
                    out[0][idx] += x.x;
                    out[1][idx] += x.y;
                    out[2][idx] += x.z;
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

    /// A transcendental host and an ellipse as the curve, every coefficient up to `∂σ³∂τ⁵`
    /// against the jets of `R(σ, τ) = S(c(τ) + σ ν(τ))` written out as one expression (the
    /// expression engine's own Taylor arithmetic: an independent path). The host's Taylor
    /// coefficients of every order up to 8 enter (a paraboloid's vanish above 2).
    #[test]
    fn along_an_ellipse_on_a_transcendental_host() {
        let host = |s: &str, w: &str| {
            [format!("exp({s})*cos({w})"), format!("exp({s})*sin({w})"), format!("{s}*{w} + sin({s})")]
        };
        let h = host("s", "w");
        let s = ExprField::parse([&h[0], &h[1], &h[2]], &["s", "w", "t"], &|_| None).unwrap();
        // c = (0.3 + 0.5 cos τ, 0.2 + 0.7 sin τ), ν = (−c₂′, c₁′) = (−0.7 cos τ, −0.5 sin τ)
        let c = ExprField::parse(["0.3 + 0.5*cos(t)", "0.2 + 0.7*sin(t)", "0"], &["t"], &|_| None).unwrap();
        let (su, sv) = ("(0.3 + 0.5*cos(t) - q*0.7*cos(t))", "(0.2 + 0.7*sin(t) - q*0.5*sin(t))");
        let composed = host(su, sv);
        let want = ExprField::parse([&composed[0], &composed[1], &composed[2]], &["q", "t", "x"], &|_| None).unwrap();
        let field = AlongCurve { host: Host::Field(Arc::new(s)), curve: DomainCurve::Field(Arc::new(c)) };
        let shape = JetShape::new(&[3, 5, 0]);
        for (sigma, tau) in [(0.0, 0.3), (0.15, 2.0), (-0.2, 4.4)] {
            let got = field.jet(&[sigma, tau, 0.0], shape);
            let exact = want.jet(&[sigma, tau, 0.0], shape);
            for m in shape.multi_indices() {
                for c in 0..3 {
                    let (g, w) = (got.0[c].coeff(m), exact.0[c].coeff(m));
                    // Taylor coefficients of size ≤ ~10, summed in different orders: a few
                    // ulps of the largest terms
                    assert!(
                        (g - w).abs() <= 1e-13 * (1.0 + w.abs()),
                        "{m:?} component {c} at ({sigma}, {tau}): {g} vs {w}"
                    );
                }
            }
        }
    }

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
