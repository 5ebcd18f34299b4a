//! # pdeshape-core
//!
//! The mathematics of PDE-based shape design: surfaces, blends, solids and trims that are
//! solutions of elliptic partial differential equations whose boundary conditions are
//! curves or surfaces in 3-space with prescribed derivatives.
//!
//! The module tree follows the specification:
//!
//! - [`jet`], [`expr`]: exact derivatives and the expression language of boundary data;
//! - [`data`]: boundary data — curves, primary surfaces, Fourier analysis (SPEC §2);
//! - [`patch`]: the patch abstraction and the ruled/Hermite patch;
//! - [`mesh`]: structured grid meshes with analytic normals (SPEC §8);
//! - [`trim`]: trimming by curves in the parameter domain (SPEC §7).
//!
//! This crate has no CLI, server or file-format dependencies.

#![warn(missing_docs)]

pub mod blend;
pub mod brep;
pub mod cancel;
pub mod classes;
pub mod data;
pub mod expr;
pub mod fill;
pub mod fit;
pub mod jet;
pub mod lanes;
pub mod limits;
pub mod linalg;
pub mod memo;
pub mod mesh;
pub mod num;
pub mod ode;
pub mod patch;
pub mod solid;
pub mod solves;
pub mod spectral;
pub mod taylor;
pub mod trim;
pub mod trimesh;
mod vec3;

pub use vec3::Vec3;
