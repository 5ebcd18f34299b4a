//! Boundary conditions taken from a primary surface along a trimline (SPEC §2.3).

use super::{Field, FieldRef, VecJet};
use crate::Vec3;
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
    fn derivatives_in(&self, at: &[f64], slot: usize, out: &mut [Vec3]) {
        let t = at.get(1).copied().unwrap_or(0.0);
        let on_surface = [self.s0, at[0], t];
        let d = self.order;
        if d == 0 {
            // the surface's own derivatives along the matching slot
            self.surface.derivatives_in(&on_surface, slot + 1, out);
        } else if out.len() == 1 {
            // the value of the d-th cross derivative: along s at fixed (v, t)
            // on the stack for the orders conditions take (a point of a blend's data)
            let mut stack = [Vec3::ZERO; 9];
            let mut heap = Vec::new();
            let along_s: &mut [Vec3] = if d < stack.len() {
                &mut stack[..=d]
            } else {
                heap.resize(d + 1, Vec3::ZERO);
                &mut heap
            };
            self.surface.derivatives_in(&on_surface, 0, along_s);
            out[0] = along_s[d] * self.scale.powi(d as i32);
        } else {
            super::derivatives_by_jet(self, at, slot, out);
        }
    }
    fn is_constant_in(&self, slot: usize) -> bool {
        // slot 0 of the trimline is the surface's slot 1, and so on.
        self.surface.is_constant_in(slot + 1)
    }

    /// The degree in `v` of an expression surface's components, each proved a
    /// trigonometric polynomial in `v` ([`crate::expr::trig_degree`] on slot 1) that does
    /// not depend on `t`. The rules prove `S(s, v) = Σ_{|n| ≤ d} a_n(s) e^{inv}` with every
    /// `a_n` built from the parts free of `v`; differentiating in `s` (the jets do it by
    /// the same sums, products and quotients) touches only those parts, so
    /// `∂ᵈS/∂sᵈ(s₀, v) = Σ a_n⁽ᵈ⁾(s₀) e^{inv}` has degree at most `d` too.
    fn trig_degree(&self) -> Option<usize> {
        let (comps, vars) = self.surface.expressions()?;
        // slot 0 (`s`) is fixed at `s₀` and may appear; `t` and later may not
        super::components_trig_degree(comps, 1, 2..vars.len())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::{ExprField, derivatives_by_jet};
    use std::sync::Arc;

    /// The fast paths (tape in Taylor series along one slot) against the jets, and a
    /// closed form: on S(s, v, t) = (s² cos v, s² sin v, t s) the first cross derivative at
    /// s₀ scaled by c is c·(2 s₀ cos v, 2 s₀ sin v, t), its v-derivatives follow by hand.
    #[test]
    fn derivatives_along_one_slot_match_jets_and_closed_forms() {
        let s: FieldRef =
            Arc::new(ExprField::parse(["s^2*cos(v)", "s^2*sin(v)", "t*s"], &["s", "v", "t"], &|_| None).unwrap());
        let (s0, c, v, t) = (1.3, 0.7, 0.4, 0.9);
        let tl = Trimline::new(s.clone(), s0, 1, c);
        let mut one = [Vec3::ZERO];
        tl.derivatives_in(&[v, t], 0, &mut one);
        let want = Vec3::new(2.0 * s0 * v.cos(), 2.0 * s0 * v.sin(), t) * c;
        assert!((one[0] - want).norm() < 1e-15, "{} vs {want}", one[0]);
        for order in 0..3 {
            let tl = Trimline::new(s.clone(), s0, order, c);
            for len in 1..5 {
                for slot in 0..2 {
                    let (mut fast, mut slow) = (vec![Vec3::ZERO; len], vec![Vec3::ZERO; len]);
                    tl.derivatives_in(&[v, t], slot, &mut fast);
                    derivatives_by_jet(&tl, &[v, t], slot, &mut slow);
                    for (a, b) in fast.iter().zip(&slow) {
                        // two exact evaluations in different operation orders
                        assert!(
                            (*a - *b).norm() <= 1e-14 * b.norm().max(1.0),
                            "order {order}, slot {slot}: {a} vs {b}"
                        );
                    }
                }
            }
        }
    }

    /// A trimline of an expression surface keeps the surface's degree in `v` at every
    /// order `d` of cross derivative, and the claim is checked independently: the DFT of
    /// the trimline at `8 (d + 1)` points of `v` (enough that nothing aliases) has no
    /// coefficient above the degree beyond round-off. Surfaces the rules cannot prove, or
    /// that depend on `t`, give `None`.
    #[test]
    fn trig_degree_survives_cross_derivatives() {
        let vars = ["s", "v", "t"];
        let field = |e: [&str; 3]| -> FieldRef { Arc::new(ExprField::parse(e, &vars, &|_| None).unwrap()) };
        let cases: [([&str; 3], Option<usize>); 6] = [
            (["s*cos(v)", "s*sin(v)", "0"], Some(1)),
            (["s^2*cos(2*v + s)", "exp(s)*sin(v)^3", "1/(1 + s^2)"], Some(3)),
            (["cos(v)*cos(v)/(2 + s)", "sin(s)", "s^3"], Some(2)),
            (["s*cos(v)", "t*sin(v)", "0"], None),
            (["cos(s*v)", "0", "0"], None),
            (["v", "0", "0"], None),
        ];
        for (e, want) in cases {
            let f = field(e);
            for order in 0..=3 {
                let tl = Trimline::new(f.clone(), 0.7, order, -1.3);
                assert_eq!(tl.trig_degree(), want, "{e:?}, order {order}");
                let Some(d) = want else { continue };
                crate::data::tests::assert_no_modes_above(&tl, d, &format!("{e:?}, order {order}"));
            }
        }
    }
}
