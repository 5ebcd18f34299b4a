//! Even extension of boundary data on an open interval to a periodic function (SPEC §2).

use super::{Field, FieldRef, VecJet};
use crate::Vec3;
use crate::jet::{Jet, JetShape, MAX_VARS};
use std::f64::consts::PI;

/// The even, 2π-periodic extension `g̃(θ)` of a function `g(v)` on `[v₀, v₁]`:
/// `g̃(θ) = g(v₀ + (v₁ − v₀) θ/π)` for `θ ∈ [0, π]` and `g̃(θ) = g̃(2π − θ)` on `[π, 2π]`.
///
/// `g̃` is continuous and periodic; its Fourier series has cosine terms only and converges
/// like `1/n²`. Derivatives are exact inside each half (`dᵏ/dθᵏ = (±(v₁ − v₀)/π)ᵏ dᵏ/dvᵏ`);
/// at `θ = 0, π` the odd derivatives jump unless `g` has zero slope there.
#[derive(Clone, Debug)]
pub struct EvenExtension {
    inner: FieldRef,
    v0: f64,
    v1: f64,
}

impl EvenExtension {
    /// Extends `inner` (slot 0 = v on `[v0, v1]`; other slots pass through).
    pub fn new(inner: FieldRef, v0: f64, v1: f64) -> Self {
        EvenExtension { inner, v0, v1 }
    }

    /// Maps θ to `(v, dv/dθ)`.
    pub fn map(&self, theta: f64) -> (f64, f64) {
        let th = theta.rem_euclid(2.0 * PI);
        let k = (self.v1 - self.v0) / PI;
        if th <= PI { (self.v0 + k * th, k) } else { (self.v0 + k * (2.0 * PI - th), -k) }
    }
}

impl Field for EvenExtension {
    fn arity(&self) -> usize {
        self.inner.arity().max(1)
    }
    fn jet(&self, at: &[f64], shape: JetShape) -> VecJet {
        let (v, dv) = self.map(at[0]);
        let mut a = at.to_vec();
        a[0] = v;
        let j = self.inner.jet(&a, shape);
        VecJet(std::array::from_fn(|k| {
            let c: Vec<f64> =
                shape.multi_indices().zip(j.0[k].coeffs()).map(|(m, c)| c * dv.powi(m[0] as i32)).collect();
            Jet::from_coeffs(shape, c)
        }))
    }
    /// The inner field's one-slot derivatives at the mapped point, times `(dv/dθ)ᵏ` in slot 0.
    fn derivatives_in(&self, at: &[f64], slot: usize, out: &mut [Vec3]) {
        let (v, dv) = self.map(at[0]);
        let mut a = [0.0; MAX_VARS];
        let n = at.len().min(MAX_VARS);
        a[..n].copy_from_slice(&at[..n]);
        a[0] = v;
        self.inner.derivatives_in(&a[..n], slot, out);
        if slot == 0 {
            let mut f = 1.0;
            for o in out.iter_mut() {
                *o *= f;
                f *= dv;
            }
        }
    }
    /// Every point mapped, the inner field's batch, then `(dv/dθ)ᵏ` in slot 0: the
    /// numbers of [`derivatives_in`](Field::derivatives_in) per point.
    fn derivatives_in_many(&self, at: &[f64], stride: usize, slot: usize, k: usize, out: &mut [Vec3]) {
        let mut mapped = at.to_vec();
        let mut dvs = Vec::with_capacity(at.len() / stride.max(1));
        for p in mapped.chunks_exact_mut(stride) {
            let (v, dv) = self.map(p[0]);
            p[0] = v;
            dvs.push(dv);
        }
        self.inner.derivatives_in_many(&mapped, stride, slot, k, out);
        if slot == 0 && k > 0 {
            for (o, dv) in out.chunks_exact_mut(k).zip(dvs) {
                let mut f = 1.0;
                for x in o {
                    *x *= f;
                    f *= dv;
                }
            }
        }
    }

    fn is_constant_in(&self, slot: usize) -> bool {
        self.inner.is_constant_in(slot)
    }
}
