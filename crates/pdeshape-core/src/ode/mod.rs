//! Constant-coefficient ODE boundary-value problems in `u` (the exact core of SPEC §3–5).
//!
//! Separating a linear constant-coefficient PDE over a transverse eigenfunction leaves an
//! ODE `P(D) y = 0` in `u`, `D = d/du`, whose characteristic polynomial `P(s)` has roots
//! `r_j` (complex, repeated) of multiplicity `m_j`. Its solutions form the space
//! `K = span{ uᵏ e^{r_j u} : k < m_j }`. Given `dim K` conditions `y^{(d_i)}(u_i) = y_i`, the
//! solution is `y = Σ_i ℓ_i y_i` with the **cardinal functions** `ℓ_i ∈ K`,
//! `ℓ_i^{(d_k)}(u_k) = δ_ik`; they depend only on the roots and the condition set, so one
//! computation serves every Fourier mode's cosine and sine parts and all three components.
//!
//! - [`ExpSpace`] is `K` with a *bounded* real basis: `(u − 1)ᵏ e^{r(u−1)}` for
//!   `Re r > 0`, `uᵏ e^{r u}` otherwise (real and imaginary parts for complex `r`),
//!   every function of modulus ≤ 1 on `[0, 1]` up to the polynomial factor; a zero root of
//!   multiplicity `m` uses Chebyshev polynomials `T_k(2u − 1)`, `k < m`. Distinct roots
//!   closer than [`CLUSTER_GAP`] share the divided differences `e[z_0, …, z_k]` of
//!   `z ↦ e^{z(u − anchor)}` instead, which stay independent as the roots coalesce
//!   (separate exponentials of roots `δ` apart are dependent to `O(δ)`).
//! - [`polynomial_roots`] finds the roots of a general real characteristic polynomial
//!   with their multiplicities, and [`ExpSpace::from_polynomial`] builds `K` from it.
//! - [`Cardinal`] holds the cardinal functions of a condition set, solved by LU with full
//!   pivoting, with the condition number of the condition matrix and the Lebesgue
//!   constant `max_u Σ_i |ℓ_i(u)|` (how much the conditions' data can be amplified between
//!   them).
//! - [`UltraCardinal`] computes the same functions as Chebyshev series from a
//!   well-conditioned ultraspherical system, in f64, where the exponential basis is
//!   ill-conditioned; [`ChebCardinal`] does it in multiple precision, the last resort;
//!   [`CardinalSet`] picks the first that is accurate.
//! - [`Combined`] holds fixed linear combinations of a set's cardinal functions in the
//!   set's own basis, evaluated at any `u` without allocating (a spectral patch's modes at
//!   scattered points).

mod cardinal;
mod combined;
mod poly;
mod precise;
mod set;
mod space;
mod ultraspherical;

pub use cardinal::{Cardinal, CondSpec, OdeError};
pub use combined::{Combined, chebyshev_t};
pub use poly::{CLUSTER_TOL, PolyRoots, polynomial_from_roots, polynomial_roots};
pub use precise::ChebCardinal;
pub use set::{CardinalSet, F64_COND_LIMIT};
pub use space::{CLUSTER_GAP, ExpSpace, Root};
pub use ultraspherical::{ULTRA_COND_LIMIT, UltraCardinal, relative_residual};
