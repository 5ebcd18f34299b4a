//! Meshes (SPEC §8): structured grid meshes with analytic normals, UVs and scalar fields;
//! hexahedral volume meshes; morph-target animations.

mod grid;

pub use grid::{GridOptions, grid_mesh, grid_mesh_with_curvatures, grid_params};

use crate::Vec3;

/// A named per-vertex (or per-cell) scalar field.
#[derive(Clone, Debug, PartialEq)]
pub struct ScalarField {
    /// Field name (e.g. `residual`, `mean_curvature`, `c1_gap`).
    pub name: String,
    /// One value per vertex (or cell).
    pub values: Vec<f64>,
}

/// A sequence of vertex positions (and normals) over time: a morph-target animation of a
/// mesh whose connectivity does not change.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct MorphAnimation {
    /// Frame times.
    pub times: Vec<f64>,
    /// Positions per frame (each as long as the mesh's vertex list).
    pub positions: Vec<Vec<Vec3>>,
    /// Normals per frame.
    pub normals: Vec<Vec<Vec3>>,
}

/// A surface mesh: quads and/or triangles over shared vertices.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Mesh {
    /// Name (the patch name; a group/node name in exports).
    pub name: String,
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Unit vertex normals (empty or one per vertex).
    pub normals: Vec<Vec3>,
    /// Texture coordinates (empty or one per vertex), the patch parameters scaled to [0, 1].
    pub uvs: Vec<[f64; 2]>,
    /// Quadrilaterals (counter-clockwise about the normal).
    pub quads: Vec<[u32; 4]>,
    /// Triangles (counter-clockwise about the normal).
    pub triangles: Vec<[u32; 3]>,
    /// Per-vertex scalar fields.
    pub fields: Vec<ScalarField>,
    /// `(nu, nv)` vertex counts when the mesh is a structured grid (row-major in `u`).
    pub grid: Option<(usize, usize)>,
    /// Polylines to highlight (boundary curves), drawn by the renderer.
    pub curves: Vec<Vec<Vec3>>,
    /// Optional animation of the vertices.
    pub animation: Option<MorphAnimation>,
}

impl Mesh {
    /// All faces as triangles (quads split along their shorter diagonal).
    pub fn all_triangles(&self) -> Vec<[u32; 3]> {
        let mut t = self.triangles.clone();
        for q in &self.quads {
            let p = |i: usize| self.positions[q[i] as usize];
            if (p(0) - p(2)).norm() <= (p(1) - p(3)).norm() {
                t.push([q[0], q[1], q[2]]);
                t.push([q[0], q[2], q[3]]);
            } else {
                t.push([q[0], q[1], q[3]]);
                t.push([q[1], q[2], q[3]]);
            }
        }
        t
    }

    /// The volume a closed, outward-oriented triangle mesh encloses, by the divergence
    /// theorem: `Σ a · (b × c) / 6` over its triangles (quads split as in
    /// [`all_triangles`](Self::all_triangles)). Negative for an inward orientation.
    ///
    /// ```
    /// use pdeshape_core::{Vec3, mesh::Mesh};
    /// // the unit tetrahedron, faces outward: volume 1/6
    /// let m = Mesh {
    ///     positions: vec![Vec3::ZERO, Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.0), Vec3::new(0.0, 0.0, 1.0)],
    ///     triangles: vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
    ///     ..Default::default()
    /// };
    /// assert!((m.enclosed_volume() - 1.0 / 6.0).abs() < 1e-15);
    /// ```
    pub fn enclosed_volume(&self) -> f64 {
        self.all_triangles()
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| self.positions[i as usize]);
                a.dot(b.cross(c)) / 6.0
            })
            .sum()
    }

    /// Axis-aligned bounds `(min, max)`; `None` for an empty mesh.
    pub fn bounds(&self) -> Option<(Vec3, Vec3)> {
        let mut it = self.positions.iter();
        let first = *it.next()?;
        Some(it.fold((first, first), |(lo, hi), p| (lo.min(*p), hi.max(*p))))
    }

    /// The field with the given name.
    pub fn field(&self, name: &str) -> Option<&ScalarField> {
        self.fields.iter().find(|f| f.name == name)
    }

    /// Bytes held by the mesh's vertex, face, field and animation arrays (not the curves).
    pub fn bytes(&self) -> usize {
        let v3 = std::mem::size_of::<Vec3>();
        let frames = self.animation.as_ref().map_or(0, |a| {
            a.positions.iter().chain(&a.normals).map(|f| f.len() * v3).sum::<usize>() + a.times.len() * 8
        });
        (self.positions.len() + self.normals.len()) * v3
            + self.uvs.len() * 16
            + self.quads.len() * 16
            + self.triangles.len() * 12
            + self.fields.iter().map(|f| f.values.len() * 8).sum::<usize>()
            + frames
    }

    /// An upper bound of [`bytes`](Self::bytes) for a structured grid mesh of `vertices`
    /// vertices with normals, UVs, quads (fewer than one per vertex), `fields` per-vertex
    /// fields and `frames` animation frames: `80 + 8·fields + 48·frames` bytes per vertex.
    pub fn grid_bytes(vertices: usize, fields: usize, frames: usize) -> u128 {
        vertices as u128 * (24 + 24 + 16 + 16 + 8 * fields as u128 + 48 * frames as u128)
    }

    /// Checks that every coordinate, normal and field value is finite.
    pub fn check_finite(&self) -> Result<(), String> {
        if let Some(i) = self.positions.iter().position(|p| !p.is_finite()) {
            return Err(format!("mesh `{}`: vertex {i} has a non-finite position", self.name));
        }
        if let Some(i) = self.normals.iter().position(|p| !p.is_finite()) {
            return Err(format!("mesh `{}`: vertex {i} has a non-finite normal", self.name));
        }
        for f in &self.fields {
            if let Some(i) = f.values.iter().position(|x| !x.is_finite()) {
                return Err(format!("mesh `{}`: field `{}` is not finite at vertex {i}", self.name, f.name));
            }
        }
        Ok(())
    }

    /// Checks that every value a single-precision format stores — positions, normals,
    /// UVs, field values, highlighted curves and animation frames — is a finite `f32` after
    /// rounding (`|x| < f32::MAX` plus half an ulp); the error names the mesh, the array
    /// and the index. `format` names the format in the message.
    ///
    /// ```
    /// use pdeshape_core::{Vec3, mesh::Mesh};
    /// let mut m = Mesh { name: "p".into(), positions: vec![Vec3::new(1e30, 0.0, 0.0)], ..Default::default() };
    /// assert!(m.check_fits_f32("STL").is_ok());
    /// m.positions[0].x = 1e39;
    /// let e = m.check_fits_f32("STL").unwrap_err();
    /// assert!(e.contains("vertex 0") && e.contains("STL"), "{e}");
    /// ```
    pub fn check_fits_f32(&self, format: &str) -> Result<(), String> {
        self.check_finite()?;
        let fits = |x: f64| (x as f32).is_finite();
        let fits3 = |p: &Vec3| fits(p.x) && fits(p.y) && fits(p.z);
        let err = |what: &str, i: usize| {
            Err(format!(
                "mesh `{}`: {what} {i} does not fit the single-precision floats of {format} (|x| ≤ {:e}); scale the scene down",
                self.name,
                f32::MAX
            ))
        };
        if let Some(i) = self.positions.iter().position(|p| !fits3(p)) {
            return err("vertex", i);
        }
        if let Some(i) = self.normals.iter().position(|p| !fits3(p)) {
            return err("the normal of vertex", i);
        }
        if let Some(i) = self.uvs.iter().position(|t| !(fits(t[0]) && fits(t[1]))) {
            return err("the texture coordinate of vertex", i);
        }
        for f in &self.fields {
            if let Some(i) = f.values.iter().position(|x| !fits(*x)) {
                return err(&format!("field `{}` at vertex", f.name), i);
            }
        }
        for (k, c) in self.curves.iter().enumerate() {
            if let Some(i) = c.iter().position(|p| !fits3(p)) {
                return err(&format!("curve {k}, point"), i);
            }
        }
        if let Some(a) = &self.animation {
            if let Some(i) = a.times.iter().position(|t| !fits(*t)) {
                return err("animation frame time", i);
            }
            for (k, frame) in a.positions.iter().chain(&a.normals).enumerate() {
                if let Some(i) = frame.iter().position(|p| !fits3(p)) {
                    return err(&format!("animation array {k}, vertex"), i);
                }
            }
        }
        Ok(())
    }
}

/// A hexahedral volume mesh (VTK cell ordering: bottom face counter-clockwise, then top).
#[derive(Clone, Debug, PartialEq, Default)]
pub struct HexMesh {
    /// Name.
    pub name: String,
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Hexahedra, 8 vertex indices each.
    pub hexes: Vec<[u32; 8]>,
    /// Per-vertex fields.
    pub point_fields: Vec<ScalarField>,
    /// Per-cell fields.
    pub cell_fields: Vec<ScalarField>,
}
