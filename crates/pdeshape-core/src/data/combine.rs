//! Linear combinations of fields (paper 004 eqs. 30–33: `α (d₁ − p₂)`).

use super::{Field, FieldRef, VecJet};
use crate::Vec3;
use crate::jet::JetShape;

/// `Σ_k w_k f_k + c`: a linear combination of fields plus a constant vector.
///
/// ```
/// use std::sync::Arc;
/// use pdeshape_core::{Vec3, data::{Combination, Field, PointField}};
/// let p = Arc::new(PointField { point: Vec3::new(1.0, 0.0, 0.0), arity: 1 });
/// let q = Arc::new(PointField { point: Vec3::new(0.0, 2.0, 0.0), arity: 1 });
/// let c = Combination::new(vec![(0.5, p), (-1.0, q)], Vec3::ZERO);
/// assert_eq!(c.eval(&[0.0]), Vec3::new(0.5, -2.0, 0.0));
/// ```
#[derive(Clone, Debug)]
pub struct Combination {
    terms: Vec<(f64, FieldRef)>,
    constant: Vec3,
}

impl Combination {
    /// The combination `Σ w_k f_k + constant`.
    pub fn new(terms: Vec<(f64, FieldRef)>, constant: Vec3) -> Self {
        Combination { terms, constant }
    }

    /// The weighted terms.
    pub fn terms(&self) -> &[(f64, FieldRef)] {
        &self.terms
    }
}

impl Field for Combination {
    fn arity(&self) -> usize {
        self.terms.iter().map(|(_, f)| f.arity()).max().unwrap_or(1)
    }
    fn jet(&self, at: &[f64], shape: JetShape) -> VecJet {
        let mut acc = VecJet::constant(shape, self.constant);
        for (w, f) in &self.terms {
            let j = f.jet(at, shape);
            for k in 0..3 {
                acc.0[k] = acc.0[k].add(&j.0[k].scale(*w));
            }
        }
        acc
    }
    fn eval(&self, at: &[f64]) -> Vec3 {
        self.terms.iter().map(|(w, f)| f.eval(at) * *w).sum::<Vec3>() + self.constant
    }
    fn is_constant_in(&self, slot: usize) -> bool {
        self.terms.iter().all(|(_, f)| f.is_constant_in(slot))
    }

    /// The largest of the terms' degrees when every term is proved a trigonometric
    /// polynomial (a finite sum of them is one, of at most that degree) and the weights and
    /// the constant are finite.
    fn trig_degree(&self) -> Option<usize> {
        if !self.constant.is_finite() {
            return None;
        }
        self.terms
            .iter()
            .try_fold(0, |acc, (w, f)| w.is_finite().then(|| f.trig_degree()).flatten().map(|d| acc.max(d)))
    }
}
