//! Boundary conditions taken from a primary surface along a trimline (SPEC §2.3).

use super::{Field, FieldRef, VecJet};
use crate::jet::{Jet, JetShape};

/// The curve `g(v, t) = κᵈ ∂ᵈS/∂sᵈ (s₀, v, t)` cut from a primary surface `S(s, v, t)` at
/// the trimline `s = s₀`: position (`d = 0`), cross tangent (`d = 1`), second cross
/// derivative (`d = 2`), …, scaled by the reparameterisation factor `κ = ds/du` that maps
/// the blend parameter `u` onto the surface parameter `s` (chain rule: `∂ᵈ/∂uᵈ = κᵈ ∂ᵈ/∂sᵈ`
/// for an affine map). Derivatives in `v` and `t` are exact mixed partials of `S`.
///
/// ```
/// use std::sync::Arc;
/// use pdeshape_core::data::{ExprField, Field, Trimline};
/// let cyl = Arc::new(ExprField::parse(["cos(v)", "sin(v)", "2*s"], &["s", "v", "t"], &|_| None).unwrap());
/// let tangent = Trimline::new(cyl, 0.5, 1, -1.0);
/// assert_eq!(tangent.eval(&[0.3, 0.0]).z, -2.0);
/// ```
#[derive(Clone, Debug)]
pub struct Trimline {
    surface: FieldRef,
    s0: f64,
    order: usize,
    scale: f64,
}

impl Trimline {
    /// The `order`-th cross derivative of `surface` (slots `(s, v, t)`) at `s = s0`, times
    /// `scale^order`.
    pub fn new(surface: FieldRef, s0: f64, order: usize, scale: f64) -> Self {
        Trimline { surface, s0, order, scale }
    }

    /// The primary surface.
    pub fn surface(&self) -> &FieldRef {
        &self.surface
    }

    /// `s₀`.
    pub fn s0(&self) -> f64 {
        self.s0
    }
}

impl Field for Trimline {
    fn arity(&self) -> usize {
        2
    }
    fn jet(&self, at: &[f64], shape: JetShape) -> VecJet {
        let [ov, ot, _] = shape.orders();
        let d = self.order;
        let big = JetShape::new(&[d, ov, ot]);
        let t = at.get(1).copied().unwrap_or(0.0);
        let sj = self.surface.jet(&[self.s0, at[0], t], big);
        let f = (1..=d).map(|k| k as f64).product::<f64>() * self.scale.powi(d as i32);
        VecJet(std::array::from_fn(|k| {
            let c: Vec<f64> = shape.multi_indices().map(|[j, l, _]| sj.0[k].coeff([d, j, l]) * f).collect();
            Jet::from_coeffs(shape, c)
        }))
    }
    fn is_constant_in(&self, slot: usize) -> bool {
        // slot 0 of the trimline is the surface's slot 1, and so on.
        self.surface.is_constant_in(slot + 1)
    }
}
