//! Choosing between f64 and multiple-precision cardinal functions.

use super::{Cardinal, ChebCardinal, CondSpec, ExpSpace, OdeError, UltraCardinal};
use crate::num::MaxNan;

/// Condition number below which the f64 solve is used directly.
pub const F64_COND_LIMIT: f64 = 1e4;

/// The cardinal functions of a condition set, computed the cheapest exact way: in f64 in
/// the exponential basis when its condition matrix is well conditioned (≤
/// [`F64_COND_LIMIT`]), else in f64 as Chebyshev series from the ultraspherical system
/// when that is resolved and well conditioned, else in multiple precision.
#[derive(Clone, Debug)]
pub enum CardinalSet {
    /// Solved in f64 in the exponential basis.
    Direct(Cardinal),
    /// Solved in f64 by the ultraspherical method (Chebyshev series).
    Ultraspherical(UltraCardinal),
    /// Solved in multiple precision, evaluated from f64 Chebyshev series.
    Tabulated(ChebCardinal),
}

impl CardinalSet {
    /// Builds the cardinal functions; `kmax` is the highest derivative that will be
    /// evaluated (used by the tabulated form).
    pub fn new(space: ExpSpace, conds: &[CondSpec], kmax: usize) -> Result<Self, OdeError> {
        let real = space.roots().iter().all(|r| r.im == 0.0);
        let direct = match Cardinal::new(space.clone(), conds) {
            Ok(c) if c.condition_number() <= F64_COND_LIMIT => return Ok(CardinalSet::Direct(c)),
            Err(e @ (OdeError::Count { .. } | OdeError::Duplicate(..))) => return Err(e),
            other => other,
        };
        if let Ok(u) = UltraCardinal::new(&space, conds, kmax) {
            return Ok(CardinalSet::Ultraspherical(u));
        }
        match direct {
            // complex roots: no multiple-precision path; the f64 solve with its condition number
            Ok(c) if !real => Ok(CardinalSet::Direct(c)),
            Err(e) if !real => Err(e),
            _ => Ok(CardinalSet::Tabulated(ChebCardinal::new(&space, conds, kmax)?)),
        }
    }

    /// `out[k][i] = ℓ_i^{(k)}(u)`.
    pub fn eval(&self, u: f64, kmax: usize) -> Vec<Vec<f64>> {
        match self {
            CardinalSet::Direct(c) => c.eval(u, kmax),
            CardinalSet::Ultraspherical(c) => c.eval(u, kmax),
            CardinalSet::Tabulated(c) => c.eval(u, kmax),
        }
    }

    /// The ODE residual of the cardinal functions, relative to its terms: for Chebyshev
    /// series (ultraspherical, multiple precision) computed in coefficient space through
    /// the banded operators ([`super::ultraspherical::relative_residual`]); 0 for the
    /// exponential basis, whose functions `uʲ e^{ru}` solve the ODE exactly for the roots
    /// it is given (the symmetric operators' `±c` are exact).
    pub fn residual(&self) -> f64 {
        match self {
            CardinalSet::Direct(_) => 0.0,
            CardinalSet::Ultraspherical(c) => c.residual(),
            CardinalSet::Tabulated(c) => c.residual(),
        }
    }

    /// Highest derivative order available (unbounded for the direct form).
    pub fn kmax(&self) -> usize {
        match self {
            CardinalSet::Direct(_) => usize::MAX,
            CardinalSet::Ultraspherical(c) => c.kmax(),
            CardinalSet::Tabulated(c) => c.kmax(),
        }
    }

    /// The condition number of the f64 condition matrix, or the size of the inverse
    /// computed in multiple precision (a lower bound of the condition number).
    pub fn condition_number(&self) -> f64 {
        match self {
            CardinalSet::Direct(c) => c.condition_number(),
            CardinalSet::Ultraspherical(c) => c.condition_number(),
            CardinalSet::Tabulated(c) => c.max_inverse(),
        }
    }

    /// Which method ran.
    pub fn method(&self) -> &'static str {
        match self {
            CardinalSet::Direct(_) => "f64",
            CardinalSet::Ultraspherical(_) => "f64-ultraspherical",
            CardinalSet::Tabulated(_) => "multiprecision",
        }
    }

    /// `max_u Σ_i |ℓ_i(u)|` on `samples + 1` equispaced points.
    pub fn lebesgue(&self, samples: usize) -> f64 {
        (0..=samples).map(|k| self.eval(k as f64 / samples as f64, 0)[0].iter().map(|x| x.abs()).sum::<f64>()).max_nan()
    }
}
