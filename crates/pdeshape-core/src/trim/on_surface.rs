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
