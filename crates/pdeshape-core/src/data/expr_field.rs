//! Fields given by three expressions.

use super::{Field, VecJet};
use crate::Vec3;
use crate::expr::{Expr, ExprError, Tape};
use crate::jet::{Jet, JetShape};
use crate::taylor::Taylor;

/// A vector field `(x(p), y(p), z(p))` given by three bound expressions in the variables
/// `vars` (slot order), compiled once into one [`Tape`] (sub-expressions shared between the
/// components are evaluated once).
///
/// ```
/// use pdeshape_core::data::{ExprField, Field};
/// use pdeshape_core::jet::JetShape;
/// let f = ExprField::parse(["r*cos(v)", "r*sin(v)", "t"], &["v", "t"], &|p| (p == "r").then_some(2.0)).unwrap();
/// let j = f.jet(&[0.0, 1.0], JetShape::new(&[1, 0]));
/// assert_eq!(j.value().x, 2.0);
/// assert_eq!(j.derivative([1, 0, 0]).y, 2.0);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct ExprField {
    comps: [Expr; 3],
    vars: Vec<String>,
    tape: Tape,
}

impl ExprField {
    /// Parses and binds three component expressions; the error says which component.
    pub fn parse(
        src: [&str; 3],
        vars: &[&str],
        param: &dyn Fn(&str) -> Option<f64>,
    ) -> Result<Self, (usize, ExprError)> {
        let mut comps = Vec::with_capacity(3);
        for (i, s) in src.iter().enumerate() {
            let e = Expr::parse(s).map_err(|e| (i, e))?;
            comps.push(e.bind(vars, param).map_err(|e| (i, e.with_source(s)))?);
        }
        let comps: [Expr; 3] = comps.try_into().expect("three components");
        Ok(ExprField::from_exprs(comps, vars))
    }

    /// A field from three already bound expressions.
    pub fn from_exprs(comps: [Expr; 3], vars: &[&str]) -> Self {
        let tape = Tape::compile(&[&comps[0], &comps[1], &comps[2]]);
        ExprField { comps, vars: vars.iter().map(|s| s.to_string()).collect(), tape }
    }

    /// The component expressions.
    pub fn components(&self) -> &[Expr; 3] {
        &self.comps
    }

    /// The variable names, in slot order.
    pub fn vars(&self) -> &[String] {
        &self.vars
    }

    /// `∂ᵏ/∂(slot)ᵏ` for `k < out.len() ≤ N` by the tape in Taylor series of length `N`.
    fn taylor<const N: usize>(&self, at: &[f64], slot: usize, out: &mut [Vec3]) {
        let vars: Vec<Taylor<N>> = (0..self.vars.len())
            .map(|i| if i == slot { Taylor::variable(at[i]) } else { Taylor::constant(at[i]) })
            .collect();
        let mut regs = Vec::new();
        let o = self.tape.eval(&vars, &Taylor::constant(0.0), &mut regs);
        for (k, d) in out.iter_mut().enumerate() {
            *d = Vec3::new(o[0].derivative(k), o[1].derivative(k), o[2].derivative(k));
        }
    }

    /// [`taylor`](Self::taylor) at many points (`stride` slots each, `k` outputs each) with
    /// one workspace: the same operations per point.
    fn taylor_many<const N: usize>(&self, at: &[f64], stride: usize, slot: usize, k: usize, out: &mut [Vec3]) {
        let nv = self.vars.len();
        let mut vars = vec![Taylor::<N>::constant(0.0); nv];
        let mut regs = Vec::new();
        for (p, dst) in at.chunks_exact(stride).zip(out.chunks_exact_mut(k)) {
            for (i, x) in vars.iter_mut().enumerate() {
                *x = if i == slot { Taylor::variable(p[i]) } else { Taylor::constant(p[i]) };
            }
            let o = self.tape.eval(&vars, &Taylor::constant(0.0), &mut regs);
            for (k, d) in dst.iter_mut().enumerate() {
                *d = Vec3::new(o[0].derivative(k), o[1].derivative(k), o[2].derivative(k));
            }
        }
    }
}

impl Field for ExprField {
    fn arity(&self) -> usize {
        self.vars.len()
    }
    fn expressions(&self) -> Option<(&[Expr; 3], &[String])> {
        Some((&self.comps, &self.vars))
    }

    fn jet(&self, at: &[f64], shape: JetShape) -> VecJet {
        let vars: Vec<Jet> = (0..self.vars.len()).map(|i| Jet::variable(shape, i, at[i])).collect();
        let like = Jet::constant(shape, 0.0);
        let mut regs = Vec::new();
        let mut out = self.tape.eval(&vars, &like, &mut regs);
        VecJet(std::array::from_fn(|_| out.next().cloned().expect("three outputs")))
    }

    fn eval(&self, at: &[f64]) -> Vec3 {
        let mut regs = Vec::new();
        let o = self.tape.eval(&at[..self.vars.len()], &0.0, &mut regs);
        Vec3::new(o[0], o[1], o[2])
    }

    fn derivatives_in(&self, at: &[f64], slot: usize, out: &mut [Vec3]) {
        match out.len() {
            0 => {}
            1 => out[0] = self.eval(at),
            2 => self.taylor::<2>(at, slot, out),
            3 => self.taylor::<3>(at, slot, out),
            4 => self.taylor::<4>(at, slot, out),
            5..=8 => self.taylor::<8>(at, slot, out),
            _ => super::derivatives_by_jet(self, at, slot, out),
        }
    }

    fn derivatives_in_many(&self, at: &[f64], stride: usize, slot: usize, k: usize, out: &mut [Vec3]) {
        match k {
            0 => {}
            1 => {
                let nv = self.vars.len();
                let mut regs = Vec::new();
                for (p, dst) in at.chunks_exact(stride).zip(out.iter_mut()) {
                    let o = self.tape.eval(&p[..nv], &0.0, &mut regs);
                    *dst = Vec3::new(o[0], o[1], o[2]);
                }
            }
            2 => self.taylor_many::<2>(at, stride, slot, k, out),
            3 => self.taylor_many::<3>(at, stride, slot, k, out),
            4 => self.taylor_many::<4>(at, stride, slot, k, out),
            5..=8 => self.taylor_many::<8>(at, stride, slot, k, out),
            _ => {
                for (p, o) in at.chunks_exact(stride).zip(out.chunks_exact_mut(k)) {
                    super::derivatives_by_jet(self, p, slot, o);
                }
            }
        }
    }

    fn is_constant_in(&self, slot: usize) -> bool {
        self.comps.iter().all(|c| !c.depends_on(slot))
    }
}
