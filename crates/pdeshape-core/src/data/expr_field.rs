//! Fields given by three expressions.

use super::{Field, VecJet};
use crate::Vec3;
use crate::expr::{Expr, ExprError};
use crate::jet::{Jet, JetShape};

/// A vector field `(x(p), y(p), z(p))` given by three bound expressions in the variables
/// `vars` (slot order).
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
        Ok(ExprField { comps, vars: vars.iter().map(|s| s.to_string()).collect() })
    }

    /// A field from three already bound expressions.
    pub fn from_exprs(comps: [Expr; 3], vars: &[&str]) -> Self {
        ExprField { comps, vars: vars.iter().map(|s| s.to_string()).collect() }
    }

    /// The component expressions.
    pub fn components(&self) -> &[Expr; 3] {
        &self.comps
    }

    /// The variable names, in slot order.
    pub fn vars(&self) -> &[String] {
        &self.vars
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
        VecJet(std::array::from_fn(|k| self.comps[k].eval_jet(&vars)))
    }

    fn eval(&self, at: &[f64]) -> Vec3 {
        let at = &at[..self.vars.len()];
        Vec3::new(self.comps[0].eval(at), self.comps[1].eval(at), self.comps[2].eval(at))
    }

    fn is_constant_in(&self, slot: usize) -> bool {
        self.comps.iter().all(|c| !c.depends_on(slot))
    }
}
