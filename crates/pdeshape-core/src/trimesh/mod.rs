//! Triangle meshes from outside (scans, printed parts): their holes found and filled.
//!
//! A [`TriMesh`] is what a mesh file holds: shared vertices and triangles. [`boundary`]
//! checks that it is an oriented 2-manifold with boundary (every edge in one or two
//! triangles, run in opposite directions by two) and chains its boundary edges into loops
//! ([`MeshLoop`]). [`fill_loop`] fills a simple loop by a fill of order 4 (G1) or 6 (G2):
//! the surface around the loop is estimated by a [`Collar`] fitted to the vertices within
//! a few rings of it, the fill meets the collar G1/G2 along the loop, and the fill is
//! meshed at the density of the mesh around it and stitched to the loop's own vertices
//! through a band whose triangles on the loop's edges are shaped like the mesh's own.
//! [`crossings`] checks that no new triangle crosses another.

mod band;
mod collar;
mod crossing;
mod disc;
mod fill;
mod flip;
mod loops;
mod periodic;
pub mod shapes;
mod smoothing;

pub use collar::{Collar, CollarError, CollarFit, adjacency, fit_collar};
pub use crossing::{crossings, crossings_with, triangles_cross};
pub use fill::{FillShape, LoopFill, LoopFillError, LoopFillOptions, fill_loop, fill_loop_with};
pub use loops::{LoopKind, MeshLoop, TopologyError, boundary, dihedral_angles, quantile};
pub use periodic::PeriodicSpline;

use crate::Vec3;

/// A triangle mesh: vertex positions and triangles of vertex indices, counter-clockwise
/// about their outward side.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TriMesh {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Triangles.
    pub triangles: Vec<[u32; 3]>,
}

impl TriMesh {
    /// The unnormalised normal `(b − a) × (c − a)` of triangle `t`.
    pub fn face_normal(&self, t: usize) -> Vec3 {
        let [a, b, c] = self.triangles[t].map(|i| self.positions[i as usize]);
        (b - a).cross(c - a)
    }
}

/// Vertex `i` of a fill: input vertex `i` of `m` below `base`, else new vertex `i − base`
/// of `new`.
fn position(m: &TriMesh, new: &[Vec3], base: u32, i: u32) -> Vec3 {
    if i < base { m.positions[i as usize] } else { new[(i - base) as usize] }
}

#[cfg(test)]
mod tests;

/// The tests' fixed draws: xorshift64 from a seed.
#[cfg(test)]
pub(crate) mod draws {
    /// Uniform in `(0, 1)`.
    pub fn uniform(mut seed: u64) -> impl FnMut() -> f64 {
        move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            ((seed >> 11) as f64 + 0.5) / (1u64 << 53) as f64
        }
    }

    /// Standard normal (Box–Muller on [`uniform`]).
    pub fn normal(seed: u64) -> impl FnMut() -> f64 {
        let mut u = uniform(seed);
        move || (-2.0 * u().ln()).sqrt() * (std::f64::consts::TAU * u()).cos()
    }
}
