//! The holes of a triangle mesh: listed (a typed report for `holes` and its JSON), and
//! filled — each simple loop by [`pdeshape_core::trimesh::fill_loop_with`] — with the new
//! vertices and triangles appended to the mesh (every input vertex and triangle kept, in
//! its place) and written in the format the output's extension names.

use crate::export::{Format, write_meshes};
use crate::holes::FillHolesOptions;
use crate::import::mesh::MeshFile;
use pdeshape_core::Vec3;
use pdeshape_core::limits::Limits;
use pdeshape_core::mesh::Mesh;
use pdeshape_core::num::max_nan;
use pdeshape_core::trimesh::{
    FillShape, LoopFillOptions, LoopKind, MeshLoop, TriMesh, adjacency, crossings, crossings_with, dihedral_angles,
    fill_loop_with, quantile,
};
use serde::Serialize;
use std::path::Path;

/// What `holes` reports for a mesh.
#[derive(Clone, Debug, Serialize)]
pub struct MeshHolesReport {
    /// The file.
    pub file: String,
    /// `OBJ`, `PLY` or `STL`.
    pub format: &'static str,
    /// Vertices (those used by a triangle and not).
    pub vertices: usize,
    /// Triangles.
    pub triangles: usize,
    /// Polygons of more than three vertices split into triangles on reading.
    pub polygons_split: usize,
    /// The 99th percentile of the mesh's own dihedral angles (radians), against which a
    /// fill's seam is judged.
    pub dihedral_p99: f64,
    /// The boundary loops, numbered from 1.
    pub holes: Vec<MeshHoleReport>,
}

/// One boundary loop.
#[derive(Clone, Debug, Serialize)]
pub struct MeshHoleReport {
    /// Its number (from 1), as `--holes` takes it.
    pub index: usize,
    /// `hole`, `rim` (of an open sheet), `open end` (of a tube or handle, or a bowl's rim)
    /// or `touches itself`; only holes are filled unless asked for by number.
    pub kind: &'static str,
    /// The mean unit normal of the mesh at the loop along the loop's axis: −1 around a
    /// hole, +1 along a rim, near 0 at an open end.
    pub facing: f64,
    /// Its number of edges.
    pub edges: usize,
    /// Its first vertex (from 0), where it starts.
    pub first_vertex: u32,
    /// Its length.
    pub length: f64,
    /// Its bounding box `[min, max]`.
    pub bbox: [[f64; 3]; 2],
}

/// The report of a mesh's loops (`loops` from [`pdeshape_core::trimesh::boundary`]).
pub fn mesh_holes_report(mf: &MeshFile, loops: &[MeshLoop]) -> MeshHolesReport {
    let angles: Vec<f64> = dihedral_angles(&mf.mesh).into_iter().map(|e| e.1).collect();
    MeshHolesReport {
        file: mf.file.clone(),
        format: mf.format.name(),
        vertices: mf.mesh.positions.len(),
        triangles: mf.mesh.triangles.len(),
        polygons_split: mf.polygons_split,
        dihedral_p99: quantile(&angles, 0.99),
        holes: loops
            .iter()
            .enumerate()
            .map(|(i, l)| MeshHoleReport {
                index: i + 1,
                kind: l.kind.name(),
                facing: l.facing,
                edges: l.vertices.len(),
                first_vertex: l.vertices[0],
                length: l.length,
                bbox: [[l.bbox.0.x, l.bbox.0.y, l.bbox.0.z], [l.bbox.1.x, l.bbox.1.y, l.bbox.1.z]],
            })
            .collect(),
    }
}

/// What filling one loop found.
#[derive(Clone, Debug, Serialize)]
pub struct MeshFillReport {
    /// The hole's number (from 1).
    pub index: usize,
    /// New vertices and triangles.
    pub new_vertices: usize,
    /// New triangles.
    pub new_triangles: usize,
    /// The collar's fit: vertices fitted, root mean square and largest residual.
    pub collar_points: usize,
    /// Root mean square residual.
    pub collar_rms: f64,
    /// Largest residual.
    pub collar_max: f64,
    /// The collar's smoothing weight that cross-validation chose (relative to the data;
    /// near 10⁻¹² the collar follows every vertex, from about 1 on it averages noise).
    pub collar_smoothing: f64,
    /// The collar's effective number of unknowns (`tr H`, at most `collar_points`).
    pub collar_dof: f64,
    /// The fill against the collar: G1 angle (radians), gap and curvature gap (relative
    /// to the loop's radius), sampled along its boundary.
    pub g1: f64,
    /// Gap.
    pub gap: f64,
    /// Curvature gap.
    pub g2: f64,
    /// The largest dihedral angle across the former border (radians).
    pub seam_dihedral: f64,
    /// Which fill: `"disc"` (the disc fill, `Δ³X = 0` in the unit disc) or `"strip"` (the
    /// strip fill closed in a pole, where the disc fill is not possible or folds).
    pub shape: &'static str,
    /// Its fullness (the disc fill's radial derivative scale; the strip fill's cross
    /// tangent against the loop's mean radius), chosen for least Willmore energy.
    pub fullness: f64,
    /// The disc fill's `μ` (`μ X_r` added to `X_rr`).
    pub mu: Option<f64>,
    /// The strip fill's pole height (factor on the least-bending pole's offset).
    pub height: Option<f64>,
    /// Its Willmore energy `∫ H² dA`.
    pub willmore: f64,
    /// The shortest and longest new edge over the local median edge length.
    pub edge_ratio: (f64, f64),
}

/// Fills the loops of `mf` that `o` asks for (every one asked must be fillable) and
/// returns the mesh with the fills appended, and what each fill found. A fill whose
/// triangles would cross the mesh, an earlier fill or each other is an error, not a
/// fill ([`pdeshape_core::trimesh::crossings`]).
pub fn fill_mesh_holes(
    mf: &MeshFile,
    loops: &[MeshLoop],
    o: &FillHolesOptions,
    limits: &Limits,
) -> Result<(TriMesh, Vec<MeshFillReport>), String> {
    if o.order != 4 && o.order != 6 {
        return Err(format!("the order is 4 (G1) or 6 (G2), not {}", o.order));
    }
    let chosen: Vec<usize> = match &o.holes {
        Some(list) => {
            for &i in list {
                if i == 0 || i > loops.len() {
                    return Err(format!("hole {i} does not exist: the mesh has {} (numbered from 1)", loops.len()));
                }
            }
            list.iter().map(|i| i - 1).collect()
        }
        None => (0..loops.len())
            .filter(|&i| loops[i].kind == LoopKind::Hole)
            .filter(|&i| o.max_edges.is_none_or(|n| loops[i].vertices.len() <= n))
            .collect(),
    };
    let mut out = mf.mesh.clone();
    let input = out.triangles.len();
    // (first triangle, hole number) of each fill appended
    let mut owner: Vec<(usize, usize)> = Vec::new();
    let mut reports = Vec::with_capacity(chosen.len());
    let lo = LoopFillOptions { order: o.order, max_vertices: limits.vertices, ..Default::default() };
    let adj = adjacency(&mf.mesh);
    for i in chosen {
        // each loop's collar is fitted to the input mesh: fills do not see each other
        let f = fill_loop_with(&mf.mesh, &adj, &loops[i], out.positions.len() as u32, &lo)
            .map_err(|e| format!("hole {}: {e}", i + 1))?;
        reports.push(MeshFillReport {
            index: i + 1,
            new_vertices: f.positions.len(),
            new_triangles: f.triangles.len(),
            collar_points: f.fit.points,
            collar_rms: f.fit.rms,
            collar_max: max_nan(f.fit.max_residual, f.fit.loop_residual),
            collar_smoothing: f.fit.smoothing,
            collar_dof: f.fit.dof,
            g1: f.continuity.g1,
            gap: f.continuity.gap,
            g2: f.continuity.g2,
            seam_dihedral: f.seam_dihedral,
            shape: match f.shape {
                FillShape::Disc { .. } => "disc",
                FillShape::Strip { .. } => "strip",
            },
            fullness: match f.shape {
                FillShape::Disc { fullness, .. } | FillShape::Strip { fullness, .. } => fullness,
            },
            mu: match f.shape {
                FillShape::Disc { mu, .. } => Some(mu),
                FillShape::Strip { .. } => None,
            },
            height: match f.shape {
                FillShape::Disc { .. } => None,
                FillShape::Strip { height, .. } => Some(height),
            },
            willmore: f.willmore,
            edge_ratio: f.edge_ratio,
        });
        let first = out.triangles.len();
        out.positions.extend(&f.positions);
        out.triangles.extend(&f.triangles);
        // no new triangle may cross the input or an earlier fill, nor another of its own
        // (the fill checked the first and the last itself when it says so)
        let crossing = if f.crossing_free {
            crossings_with(&out, input..first, first, false, 1)
        } else {
            crossings(&out, first, 1)
        };
        if let Some(&(t, u)) = crossing.first() {
            let other = if u >= first {
                format!("its own triangle {}", u - first)
            } else if u >= input {
                let j = owner.iter().rev().find(|o| o.0 <= u).map_or(0, |o| o.1);
                format!("a triangle of hole {j}'s fill")
            } else {
                format!("input triangle {u}")
            };
            return Err(format!(
                "hole {}: the fill would cross the mesh (its triangle {} crosses {other}); not filled (choose holes with --holes)",
                i + 1,
                t - first
            ));
        }
        owner.push((first, i + 1));
    }
    Ok((out, reports))
}

/// Writes `m` to `path` in the format of its extension (`obj`, `ply`, `stl`), atomically.
pub fn write_trimesh(path: &Path, m: &TriMesh) -> Result<(), String> {
    let format = path
        .extension()
        .and_then(|e| e.to_str())
        .and_then(Format::from_extension)
        .filter(|f| matches!(f, Format::Obj | Format::Ply | Format::Stl))
        .ok_or_else(|| format!("{}: the output must be .obj, .ply or .stl", path.display()))?;
    let mesh = Mesh {
        name: "filled".into(),
        positions: m.positions.clone(),
        triangles: m.triangles.clone(),
        ..Default::default()
    };
    write_meshes(path, format, &[&mesh]).map_err(|e| format!("{}: {e}", path.display()))
}

/// The smooth-shading normals of `m`: at each vertex the sum of its triangles' normals
/// weighted by their angle there (the weighting that makes the normal of a vertex on a
/// smooth surface independent of how the triangles around it are cut), normalised.
pub fn vertex_normals(m: &TriMesh) -> Vec<Vec3> {
    let mut n = vec![Vec3::ZERO; m.positions.len()];
    for t in 0..m.triangles.len() {
        let Some(unit) = m.face_normal(t).normalized() else { continue };
        let tri = m.triangles[t];
        for k in 0..3 {
            let p = m.positions[tri[k] as usize];
            let (a, b) = (m.positions[tri[(k + 1) % 3] as usize] - p, m.positions[tri[(k + 2) % 3] as usize] - p);
            let angle = a.cross(b).norm().atan2(a.dot(b));
            n[tri[k] as usize] += unit * angle;
        }
    }
    n.into_iter().map(|v| v.normalized().unwrap_or(Vec3::ZERO)).collect()
}

/// Whether a mesh file can be drawn in `view`: shaded, zebra stripes or isophotes, not a
/// curvature map (a mesh file carries no exact curvature).
pub fn mesh_view(view: crate::render::View) -> Result<(), String> {
    match view.curvature() {
        Some(_) => Err(format!(
            "a mesh file renders shaded, zebra or isophotes; the {} view needs a scene's exact curvature",
            view.name()
        )),
        None => Ok(()),
    }
}

/// `m` as a picture in the view of `r` ([`mesh_view`]), smooth-shaded with
/// [`vertex_normals`].
pub fn render_trimesh(m: &TriMesh, r: &crate::scene::RenderSettings) -> Result<crate::render::Image, String> {
    mesh_view(r.view)?;
    let mesh = Mesh {
        name: "mesh".into(),
        positions: m.positions.clone(),
        normals: vertex_normals(m),
        triangles: m.triangles.clone(),
        ..Default::default()
    };
    Ok(crate::model::render_meshes(&[mesh], &[], &[], r))
}
