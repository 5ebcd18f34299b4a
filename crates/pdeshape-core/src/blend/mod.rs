//! Static blends of 2nd, 4th, 6th and mixed order (SPEC §4, paper 001).
//!
//! A blend joins two primary surfaces along trimlines mapped to `u = 0` and `u = 1`. Each
//! component `X_t` solves its own operator `L_t` of order `2r_t` ([`Operator`]) with the
//! conditions `∂ᵏX_t/∂uᵏ`, `k < r_t`, at both ends: positions for 2nd order (C0), plus
//! cross tangents for 4th (C1), plus second cross derivatives for 6th (C2). The boundary
//! data are decomposed over basis functions `g_j(v)` ([`decompose`]) and solved
//!
//! - exactly when every `g_j` is an eigenfunction of `∂v²` ([`Solver::Exact`]: the PDE
//!   separates into constant-coefficient ODEs in `u` solved by [`crate::ode`]), or
//! - by the paper's collocation least squares with Hermite part and bubble functions
//!   ([`Solver::Collocation`], [`bubbles`]).
//!
//! [`continuity`] measures what each order achieves at the trimlines: C0, C1, G1, C2, G2.
//!
//! [`DynamicBlend`] is the time-dependent C1 blend of SPEC §5 (paper 002).

mod basis;
mod bubble;
mod continuity;
mod dynamic;
mod operator;
mod solve;

pub use basis::{BasisFn, Decomposition, MAX_SPLIT_MODES, decompose};
pub use bubble::bubbles;
pub use continuity::{
    CONTINUITY_TOL, ContinuityClass, Gaps, SeamGaps, attached_gaps_at, attached_seam_gaps, continuity, gaps_at,
    seam_gaps,
};
pub use dynamic::{DynBasis, DynamicBlend, DynamicFrame, DynamicOperator, DynamicOptions, DynamicReport, zeta};
pub use operator::Operator;
pub use solve::{BlendOptions, ComponentReport, Solver, StaticBlend};

/// Why a static blend cannot be built.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum BlendError {
    /// Unusable operator coefficients.
    #[error("operator: {0}")]
    Operator(String),
    /// Missing or misplaced conditions.
    #[error("conditions: {0}")]
    Conditions(String),
    /// The boundary basis does not represent the data.
    #[error("basis: {0}")]
    Basis(String),
    /// The solve failed.
    #[error("solver: {0}")]
    Solver(String),
    /// The solve would need more memory than the cap allows.
    #[error(transparent)]
    Limit(#[from] crate::limits::LimitError),
}

#[cfg(test)]
mod tests;
