//! A primary parametric surface shown as a patch (for context meshes and diagnostics).

use super::{Surface, VDomain};
use crate::Vec3;
use crate::data::FieldRef;
use crate::jet::JetShape;

/// The patch `X(u, v) = S(s₀ + u (s₁ − s₀), v, t)` of a primary surface `S(s, v, t)` over
/// the range `[s₀, s₁]`: its `u`-derivatives carry the chain factor `(s₁ − s₀)ⁱ`.
#[derive(Clone, Debug)]
pub struct PrimarySurface {
    surface: FieldRef,
    s_range: (f64, f64),
    domain: VDomain,
    time: f64,
}

impl PrimarySurface {
    /// The part `s ∈ [s₀, s₁]` of `surface` (slots `(s, v, t)`) over `domain` at time `t`.
    pub fn new(surface: FieldRef, s_range: (f64, f64), domain: VDomain, time: f64) -> Self {
        PrimarySurface { surface, s_range, domain, time }
    }
}

impl Surface for PrimarySurface {
    fn v_domain(&self) -> VDomain {
        self.domain
    }
    fn derivatives(&self, u: f64, v: f64, du: usize, dv: usize) -> Vec<Vec3> {
        let (s0, s1) = self.s_range;
        let shape = JetShape::new(&[du, dv]);
        let j = self.surface.jet(&[s0 + u * (s1 - s0), v, self.time], shape);
        let mut out = Vec::with_capacity((du + 1) * (dv + 1));
        for i in 0..=du {
            for k in 0..=dv {
                out.push(j.derivative([i, k, 0]) * (s1 - s0).powi(i as i32));
            }
        }
        out
    }
}
