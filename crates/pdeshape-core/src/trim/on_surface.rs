//! A trim curve carried onto its patch: `g(t) = X(C(t))`, the 3D curve along which the
//! trimmed patch ends (the root curve of an attached patch, paper 004 §4's fins).

use super::curve::TrimCurve;
use crate::Vec3;
use crate::data::{Field, VecJet};
use crate::jet::{Jet, JetShape};
use crate::patch::Surface;
use std::sync::Arc;

/// `g(t) = X(C(t))` for a patch `X` and a closed trim curve `C`, `t ∈ [0, 2π)`; slot 0 is
/// `t`, other slots are ignored.
///
/// Derivatives are exact: with `δu(τ) = C_u(t + τ) − C_u(t)` and `δv` likewise as Taylor
/// series in `τ` (exact derivatives of `C`), `X(C(t + τ)) = Σ_{i+j≤k} ∂ᵢ∂ⱼX/(i! j!) δuⁱ δvʲ`
/// truncated at the requested order `k` (the patch's exact partial derivatives).
#[derive(Clone)]
pub struct CurveOnSurface {
    /// The patch.
    pub surface: Arc<dyn Surface>,
    /// The curve in its parameter domain.
    pub curve: TrimCurve,
}

impl std::fmt::Debug for CurveOnSurface {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "CurveOnSurface({:?})", self.curve)
    }
}

impl Field for CurveOnSurface {
    fn arity(&self) -> usize {
        1
    }

    fn jet(&self, at: &[f64], shape: JetShape) -> VecJet {
        let k = shape.orders()[0];
        let c = self.curve.derivatives(at[0], k);
        let (u0, v0) = (c[0][0], c[0][1]);
        let d = self.surface.derivatives(u0, v0, k, k);
        if k == 0 {
            return VecJet::constant(shape, d[0]);
        }
        // Taylor series of δu, δv in slot 0
        let mut fact = 1.0;
        let mut tu = vec![0.0];
        let mut tv = vec![0.0];
        for (m, cm) in c.iter().enumerate().skip(1) {
            fact *= m as f64;
            tu.push(cm[0] / fact);
            tv.push(cm[1] / fact);
        }
        let var = Jet::variable(shape, 0, at[0]);
        let du = var.compose(&tu);
        let dv = var.compose(&tv);
        let mut out = [Jet::constant(shape, 0.0), Jet::constant(shape, 0.0), Jet::constant(shape, 0.0)];
        let mut du_pow = Jet::constant(shape, 1.0);
        let mut fi = 1.0;
        for i in 0..=k {
            if i > 0 {
                du_pow = du_pow.mul(&du);
                fi *= i as f64;
            }
            let mut dv_pow = Jet::constant(shape, 1.0);
            let mut fj = 1.0;
            for j in 0..=k - i {
                if j > 0 {
                    dv_pow = dv_pow.mul(&dv);
                    fj *= j as f64;
                }
                let coef: Vec3 = d[i * (k + 1) + j] * (1.0 / (fi * fj));
                let term = du_pow.mul(&dv_pow);
                for (o, x) in out.iter_mut().zip([coef.x, coef.y, coef.z]) {
                    *o = o.add(&term.scale(x));
                }
            }
        }
        VecJet(out)
    }

    /// Values (`k = 1`: a condition check's thousand `t`) and values with first derivatives
    /// (`k = 2`: a grid's columns, `g′ = X_u C_u′ + X_v C_v′`) go through the patch's batched
    /// [`Surface::points_at`] / [`Surface::firsts_at`]: the points' `u` are all new, so one
    /// at a time each would compute a row of every mode afresh. Equal to the pointwise
    /// numbers to round-off. Higher derivatives go point by point through [`jet`](Self::jet).
    fn derivatives_in_many(&self, at: &[f64], stride: usize, slot: usize, k: usize, out: &mut [Vec3]) {
        let ts = at.chunks_exact(stride).map(|p| p[0]);
        match (slot, k) {
            (0, 1) => {
                let uv: Vec<[f64; 2]> = ts.map(|t| self.curve.point(t)).collect();
                self.surface.points_at(&uv, &mut out[..uv.len()]);
            }
            (0, 2) => {
                let c: Vec<[[f64; 2]; 2]> = ts
                    .map(|t| {
                        let d = self.curve.derivatives(t, 1);
                        [d[0], d[1]]
                    })
                    .collect();
                let uv: Vec<[f64; 2]> = c.iter().map(|d| d[0]).collect();
                let mut x = vec![[Vec3::ZERO; 3]; uv.len()];
                self.surface.firsts_at(&uv, &mut x);
                for ((o, x), d) in out.chunks_exact_mut(2).zip(&x).zip(&c) {
                    o[0] = x[0];
                    o[1] = x[1] * d[1][0] + x[2] * d[1][1];
                }
            }
            _ => crate::data::derivatives_point_by_point(self, at, stride, slot, k, out),
        }
    }

    fn is_constant_in(&self, slot: usize) -> bool {
        slot > 0
    }

    /// `X_u × X_v` of the trimmed patch at `C(t)`.
    fn host_normal(&self, at: &[f64]) -> Option<Vec3> {
        let [u, v] = self.curve.point(at[0]);
        let d = self.surface.derivatives(u, v, 1, 1);
        Some(d[2].cross(d[1]))
    }
}
