//! The editor's wire format, the answer of `POST /api/model`: a little-endian `u32`, the
//! length of the JSON [`Header`] that follows (padded with spaces to a multiple of 4
//! bytes), then the buffers the header points into as [`Slice`]s — little-endian `f32`
//! positions, normals, curves and fields, `u32` triangle and line indices. `wire.js` is the
//! reading side.

use pdeshape_core::mesh::Mesh;
use pdeshape_io::model;
use pdeshape_io::model::report::SceneReport;
use pdeshape_io::scene::{PatchKind, Scene, ScenePatch, edit};
use serde::Serialize;
use serde_json::Value;

/// What is sent: a solved scene, its (edited) text and meshes.
pub struct Model<'a> {
    /// The scene.
    pub scene: &'a Scene,
    /// Its text after the request's edits.
    pub text: &'a str,
    /// One mesh per patch.
    pub meshes: &'a [Mesh],
    /// The imported models' faces, drawn around the patches (`model::import_meshes`).
    pub context: &'a [Mesh],
    /// Time spent solving and meshing (ms).
    pub solve_ms: f64,
}

/// `count` values from byte `offset` of the buffers.
#[derive(Serialize)]
pub struct Slice {
    offset: usize,
    count: usize,
}

/// A per-vertex field.
#[derive(Serialize)]
struct FieldSlice {
    offset: usize,
    count: usize,
    name: String,
}

/// The header.
#[derive(Serialize)]
struct Header<'a> {
    name: &'a str,
    title: Option<&'a str>,
    text: &'a str,
    params: Vec<Param<'a>>,
    /// A dynamic blend's `[t0, t1]`.
    time_range: Option<[f64; 2]>,
    view: View,
    patches: Vec<Patch<'a>>,
    /// Meshes drawn around the patches: the faces of imported models, named
    /// `MODEL.faceID`.
    context: Vec<ContextMesh<'a>>,
    /// The holes of imported models, named `MODEL.holeK`, each its loop of points.
    holes: Vec<HoleLoop>,
    /// The text's draggable handles and editable trims (`scene::edit`).
    editables: Value,
    /// `model::mesh_hash` of the meshes (tests compare it).
    hash: String,
    solve_ms: f64,
    /// `check`'s report, when asked for.
    diagnostics: Option<SceneReport>,
    /// The curve tools' answer, when asked for.
    curves: Option<Vec<PatchCurves>>,
}

/// A mesh drawn in context.
#[derive(Serialize)]
struct ContextMesh<'a> {
    name: &'a str,
    vertices: usize,
    positions: Slice,
    normals: Slice,
    indices: Slice,
}

/// A hole of an imported model: its name and its loop's points.
#[derive(Serialize)]
struct HoleLoop {
    name: String,
    points: Slice,
}

/// One patch's curves for the curve tools.
#[derive(Serialize)]
#[serde(untagged)]
pub enum PatchCurves {
    /// Curves of this patch are not drawn (trimmed, solid and moving patches).
    None {
        /// The patch.
        name: String,
    },
    /// Its plane section and combs.
    Some {
        /// The patch.
        name: String,
        /// Segments `[x, y, z, kx, ky, kz, x′, y′, z′, k′…]`, when a section was asked for.
        section: Option<Vec<Vec<f64>>>,
        /// Combs along lines `u`.
        combs: Vec<Comb>,
    },
}

/// A curvature comb along the line `u`: points and curvature vectors, flattened.
#[derive(Serialize)]
pub struct Comb {
    /// The line.
    pub u: f64,
    /// `[x, y, z, …]`.
    pub points: Vec<f64>,
    /// `[kx, ky, kz, …]`.
    pub curvature: Vec<f64>,
}

/// A slider.
#[derive(Serialize)]
struct Param<'a> {
    name: &'a str,
    value: f64,
    min: Option<f64>,
    max: Option<f64>,
    step: Option<f64>,
    /// Defined by an expression of other parameters (not a slider).
    derived: bool,
    description: Option<&'a str>,
}

/// The initial camera.
#[derive(Serialize)]
struct View {
    azimuth: f64,
    elevation: f64,
}

/// One patch's mesh.
#[derive(Serialize)]
struct Patch<'a> {
    name: &'a str,
    kind: PatchKind,
    color: Option<[f64; 3]>,
    vertices: usize,
    grid: Option<(usize, usize)>,
    /// The `u` of the patch's seams (continuity colouring).
    seams: Vec<f64>,
    positions: Slice,
    normals: Slice,
    indices: Slice,
    /// Pairs of vertex indices: quad and triangle edges.
    lines: Slice,
    curves: Vec<Slice>,
    fields: Vec<FieldSlice>,
    trim: Option<Trim>,
}

/// A trimmed patch's grid in its parameter domain, thinned for the trim editor.
#[derive(Serialize)]
struct Trim {
    domain: [[f64; 2]; 2],
    #[serde(rename = "loop")]
    outline: Vec<[f64; 2]>,
    spokes: Vec<Vec<[f64; 2]>>,
    rings: Vec<Vec<[f64; 2]>>,
    folds_before: usize,
    folds_after: usize,
}

/// The buffers being written.
struct Buffers(Vec<u8>);

impl Buffers {
    /// Room for `n` more 4-byte values: the answer's buffers grow once per buffer, not
    /// by doubling through a megabyte.
    fn reserve(&mut self, n: usize) {
        self.0.reserve(4 * n);
    }

    fn f32s(&mut self, xs: impl ExactSizeIterator<Item = f32>) -> Slice {
        self.words(xs.map(f32::to_le_bytes))
    }

    fn u32s(&mut self, xs: impl Iterator<Item = u32>) -> Slice {
        self.words(xs.map(u32::to_le_bytes))
    }

    /// 4-byte values in order, room for those the iterator promises reserved first.
    fn words(&mut self, xs: impl Iterator<Item = [u8; 4]>) -> Slice {
        self.reserve(xs.size_hint().0);
        let offset = self.0.len();
        let mut count = 0;
        for x in xs {
            self.0.extend_from_slice(&x);
            count += 1;
        }
        Slice { offset, count }
    }

    fn points(&mut self, ps: &[pdeshape_core::Vec3]) -> Slice {
        self.reserve(3 * ps.len());
        let offset = self.0.len();
        for p in ps {
            for x in [p.x, p.y, p.z] {
                self.0.extend_from_slice(&(x as f32).to_le_bytes());
            }
        }
        Slice { offset, count: 3 * ps.len() }
    }
}

fn trim(p: &ScenePatch) -> Option<Trim> {
    let t = p.trim.as_ref()?;
    let g = &t.grid;
    let step = (g.columns / 48).max(1);
    let dom = p.surface.v_domain();
    Some(Trim {
        domain: [[0.0, dom.start], [1.0, dom.end]],
        outline: (0..=g.columns).map(|j| g.points[g.index(0, j)]).collect(),
        spokes: (0..g.columns).step_by(step).map(|j| (0..g.rings).map(|i| g.points[g.index(i, j)]).collect()).collect(),
        rings: (0..g.rings)
            .step_by((g.rings / 12).max(1))
            .map(|i| (0..=g.columns).map(|j| g.points[g.index(i, j)]).collect())
            .collect(),
        folds_before: g.report.folds_before,
        folds_after: g.report.folds_after,
    })
}

/// The answer's bytes; `diagnostics`: compute and include the report.
pub fn encode(s: &Model, diagnostics: bool, curves: Option<Vec<PatchCurves>>) -> Vec<u8> {
    let mut buf = Buffers(Vec::new());
    let mut patches = Vec::new();
    for (m, p) in s.meshes.iter().zip(&s.scene.patches) {
        let positions = buf.points(&m.positions);
        let normals = buf.points(&m.normals);
        let indices = buf.u32s(m.all_triangles().as_flattened().iter().copied());
        // wireframe: quad edges (and triangle edges)
        let quad_edges = m.quads.iter().flat_map(|q| (0..4).flat_map(move |k| [q[k], q[(k + 1) % 4]]));
        let tri_edges = m.triangles.iter().flat_map(|t| (0..3).flat_map(move |k| [t[k], t[(k + 1) % 3]]));
        buf.reserve(8 * m.quads.len() + 6 * m.triangles.len());
        let lines = buf.u32s(quad_edges.chain(tri_edges));
        let curves = m.curves.iter().map(|c| buf.points(c)).collect();
        let fields = m
            .fields
            .iter()
            .map(|f| {
                let Slice { offset, count } = buf.f32s(f.values.iter().map(|x| *x as f32));
                FieldSlice { offset, count, name: f.name.clone() }
            })
            .collect();
        patches.push(Patch {
            name: &m.name,
            kind: p.kind,
            color: p.color,
            vertices: m.positions.len(),
            grid: m.grid,
            seams: model::seam_ends(p),
            positions,
            normals,
            indices,
            lines,
            curves,
            fields,
            trim: trim(p),
        });
    }
    let context = s
        .context
        .iter()
        .map(|m| ContextMesh {
            name: &m.name,
            vertices: m.positions.len(),
            positions: buf.points(&m.positions),
            normals: buf.points(&m.normals),
            indices: buf.u32s(m.all_triangles().as_flattened().iter().copied()),
        })
        .collect();
    let holes = model::import_hole_loops(s.scene)
        .into_iter()
        .map(|(name, points)| HoleLoop { name, points: buf.points(&points) })
        .collect();
    let header = Header {
        name: &s.scene.name,
        title: s.scene.title.as_deref(),
        text: s.text,
        params: s
            .scene
            .params
            .iter()
            .map(|(k, p)| Param {
                name: k,
                value: p.value,
                min: p.min,
                max: p.max,
                step: p.step,
                derived: p.expr.is_some(),
                description: p.description.as_deref(),
            })
            .collect(),
        time_range: s.scene.patches.iter().find_map(|p| p.dynamic.as_ref()).map(|d| [d.times.0, d.times.1]),
        view: View { azimuth: s.scene.render.azimuth, elevation: s.scene.render.elevation },
        patches,
        context,
        holes,
        editables: edit::editables(s.text),
        hash: model::mesh_hash(s.meshes),
        solve_ms: s.solve_ms,
        diagnostics: diagnostics.then(|| model::scene_diagnostics(s.scene)),
        curves,
    };
    // Plain structs of numbers and strings always serialise.
    let mut h = serde_json::to_vec(&header).unwrap_or_default();
    while !h.len().is_multiple_of(4) {
        h.push(b' ');
    }
    let mut out = Vec::with_capacity(4 + h.len() + buf.0.len());
    out.extend_from_slice(&(h.len() as u32).to_le_bytes());
    out.extend_from_slice(&h);
    out.extend_from_slice(&buf.0);
    out
}
