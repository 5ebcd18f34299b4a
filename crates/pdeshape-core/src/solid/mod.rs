//! Solid (volumetric) blends (SPEC §6, paper 000).
//!
//! `(α∂u⁴ + β∂v⁴ + γ∂w⁴) x(u, v, w) = 0` on `[0, 1]³`, with the boundary surfaces
//! `x(u, v, 0) = S₁`, `x_w(u, v, 0) = S₂`, `x(u, v, 1) = S₃`, `x_w(u, v, 1) = S₄`.
//! The solution is `x = H + C`: the cubic Hermite part `H = h₀₀(w)S₁ + h₁₀(w)S₂ + h₀₁(w)S₃ +
//! h₁₁(w)S₄` meets the four conditions exactly, and the correction
//! `C = Σ a_lmn sin(lπu) sin(mπv) ψ_n(w)` (each `ψ_n`, `ψ_n′` zero at `w = 0, 1`) reduces
//! the PDE residual:
//!
//! - [`Trial::Complete`] (default): `ψ_n = sin(πw) sin(nπw)`, a complete space of such
//!   functions, fitted by least squares of the PDE residual on an oversampled Gauss grid.
//!   Because `∫sin lπu sin l′πu = δ/2` (Gauss rules) and `∂u⁴ sin lπu = (lπ)⁴ sin lπu`, the
//!   problem splits into one small least-squares problem per `(l, m)` in `w` alone:
//!   minimise `‖(λ_lm ψ + γψ⁗) a_lm + r_lm‖_{L²(w)}`, `λ_lm = α(lπ)⁴ + β(mπ)⁴`.
//!   [`Trial::Galerkin`] makes the same residual orthogonal to the `ψ_n` instead.
//! - [`Trial::Paper`]: the paper's `ψ_n = sin²(nπw)` collocated at `L·M·N` uniform interior
//!   points. Every `sin²(nπw)` is symmetric about `w = ½`, and so is the grid: rows come in
//!   identical pairs and the square system is singular. It is built, its condition number
//!   measured, and the singularity reported as an error instead of a solution.

mod blend;
mod boundary;
mod face;
mod gauss;
mod mass;
mod sample;

pub use blend::{SolidBlend, SolidOperator, SolidOptions, SolidReport, Trial};
pub use boundary::{boundary_mesh, boundary_mesh_of, cross_section, hex_mesh};
pub use face::{SolidFace, boundary_faces};
pub use gauss::gauss_legendre;
pub use mass::MassProperties;
pub use sample::interior_points;

/// Why a solid blend cannot be built.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SolidError {
    /// Unusable coefficients or sizes.
    #[error("{0}")]
    Input(String),
    /// The collocation system of the paper's trial space is singular.
    #[error(
        "the paper's trial space sin²(nπw) on its uniform collocation grid gives a singular system \
         (condition number {cond:.2e}): every sin²(nπw) is symmetric about w = 1/2, so symmetric \
         collocation points give identical pairs of rows; use trial = \"complete\""
    )]
    PaperSingular {
        /// Measured condition number.
        cond: f64,
    },
    /// Linear algebra failed.
    #[error("solve failed: {0}")]
    Solve(String),
}
