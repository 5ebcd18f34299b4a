//! Scene files (SPEC §9): a TOML description of parameters, curves, primary surfaces,
//! patches, the picture and the outputs, resolved into core objects.
//!
//! The format is documented, with every key, in `examples/README.md`. Errors name the
//! file, line, column and key, and say what was expected.

// Scene errors carry the place and a source snippet; they are built once per failed load,
// so their size on the error path does not matter.
#![allow(clippy::result_large_err)]

mod build;
mod ctx;
pub mod edit;
mod error;
mod import;
mod kinds;
mod nurbs;
mod raw;
mod sections;
mod trim;

pub use ctx::RESERVED;
pub use error::{SceneError, Source};
pub use import::{ImportRoot, ImportedModel, SceneImport};

use indexmap::IndexMap;
use pdeshape_core::data::FieldRef;
use pdeshape_core::patch::{Condition, Surface, VDomain};
use pdeshape_core::spectral::SpectralPatch;
use std::collections::HashMap;
use std::path::Path;
use std::sync::Arc;

/// A numeric scene parameter (a slider in the editor).
#[derive(Clone, Debug, PartialEq)]
pub struct Param {
    /// Current value.
    pub value: f64,
    /// The expression it was defined by, for derived parameters.
    pub expr: Option<String>,
    /// Slider minimum.
    pub min: Option<f64>,
    /// Slider maximum.
    pub max: Option<f64>,
    /// Slider step.
    pub step: Option<f64>,
    /// Free text.
    pub description: Option<String>,
}

/// A primary surface of the scene.
#[derive(Clone, Debug)]
pub struct SceneSurface {
    /// Name.
    pub name: String,
    /// `S(s, v, t)`.
    pub field: FieldRef,
    /// The part drawn in context, if any.
    pub s_range: Option<(f64, f64)>,
    /// Its v domain.
    pub domain: VDomain,
    /// Context mesh resolution.
    pub resolution: (usize, usize),
}

/// Overrides applied while a scene is resolved.
#[derive(Clone, Debug, Default)]
pub struct LoadOptions {
    /// Parameter values by name.
    pub params: HashMap<String, f64>,
    /// Solver for patches that offer a choice (blends).
    pub solver: Option<String>,
    /// Sine terms `K` for dynamic blends (overrides the scene).
    pub terms: Option<usize>,
    /// Caps on order, modes, collocation size, resolution and memory.
    pub limits: pdeshape_core::limits::Limits,
    /// Where `[import.*]` models are read from (default: nowhere).
    pub imports: ImportRoot,
}

/// What a patch is (serialised by its name in scene files).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum PatchKind {
    /// Ruled/Hermite interpolation in `u` (no PDE).
    Hermite,
    /// `(∂u² + a²∂v²)^N X = 0` by the spectral method (SPEC §3).
    Pde,
    /// A static blend of 2nd, 4th, 6th or mixed order (SPEC §4).
    Blend,
    /// A time-dependent C1 blend (SPEC §5).
    Dynamic,
    /// A volumetric blend between two solids (SPEC §6).
    Solid,
    /// An N-sided hole filled with exact G1 to its neighbours.
    Fill,
}

impl PatchKind {
    /// The name used in scene files (the kind's module in `scene/kinds/`).
    pub fn name(self) -> &'static str {
        kinds::KINDS.iter().find(|k| k.kind == self).map_or("?", |k| k.name)
    }
}

/// A patch of the scene, solved.
#[derive(Clone)]
pub struct ScenePatch {
    /// Name.
    pub name: String,
    /// Kind.
    pub kind: PatchKind,
    /// The solved patch.
    pub surface: Arc<dyn Surface>,
    /// Its conditions.
    pub conditions: Vec<Condition>,
    /// The solve's path as reports name it (`hermite-interpolation`, `spectral`, `exact`,
    /// `collocation`, `mixed (x: …, y: …, z: …)`, a dynamic blend's first frame's, a
    /// solid's method), set by the kind when it solves.
    pub solver: String,
    /// Mesh resolution `(nu, nv)` in vertices.
    pub resolution: (usize, usize),
    /// Display colour.
    pub color: Option<[f64; 3]>,
    /// The spectral solution, for PDE patches (diagnostics).
    pub spectral: Option<Arc<SpectralPatch>>,
    /// The section family the patch interpolates, when it was given by `sections`.
    pub sections: Option<SectionFamily>,
    /// The static blend and the options it was solved with, for blend patches.
    pub blend: Option<BlendSetup>,
    /// The dynamic blend with its time range and frames, for dynamic patches (`surface` is
    /// then the frame at the first time).
    pub dynamic: Option<DynamicSetup>,
    /// The solid blend, for solid patches (`surface` is then its mid cross section w = ½).
    pub solid: Option<SolidSetup>,
    /// The trim and its meshed region, for trimmed patches.
    pub trim: Option<TrimSetup>,
    /// Fills: the solved fill (its report, edge continuity, folds).
    pub fill: Option<Arc<pdeshape_core::fill::Fill>>,
    /// Fills whose loop is a hole of an imported model: which (`build -o OUT.step` sews
    /// the fill into that model).
    pub hole: Option<PatchHole>,
}

/// The hole of an imported model a fill closes.
#[derive(Clone, Debug, PartialEq)]
pub struct PatchHole {
    /// The import's name (`[import.NAME]`).
    pub import: String,
    /// The hole's number (from 1, as `holes` numbers them).
    pub hole: usize,
    /// The fill's order (4: G1, 6: G2).
    pub order: usize,
    /// The largest distance between the hole's edge curves and their faces.
    pub edge_offset: f64,
}

impl ScenePatch {
    /// Vertices of the patch's mesh: the trim grid's when trimmed, else the resolution's
    /// (a solid's boundary mesh counts its six faces).
    pub fn vertices(&self) -> usize {
        if let Some(sd) = &self.solid {
            let (a, b, c) = sd.cells;
            return 2 * (a * b + b * c + a * c);
        }
        match &self.trim {
            Some(t) => t.grid.rings * (t.grid.columns + 1),
            None => self.resolution.0 * self.resolution.1,
        }
    }

    /// Estimated bytes of this patch's meshes (what [`crate::model::patch_mesh`] and the
    /// exporters hold): the surface grid or trimmed grid with its per-vertex fields, every
    /// frame of a dynamic blend, the hexahedral cells of a solid.
    pub fn memory_estimate(&self) -> u128 {
        use pdeshape_core::mesh::Mesh;
        if let Some(sd) = &self.solid {
            // per cell about one vertex (24 bytes), four fields and eight indices; the
            // boundary as a surface mesh
            let (a, b, c) = sd.cells;
            let cells = a as u128 * b as u128 * c as u128;
            return cells * (24 + 8 * 4 + 32) + Mesh::grid_bytes(2 * (a * b + b * c + a * c), 0, 0);
        }
        let vertices = self.vertices();
        let fields = if self.blend.is_some() { 5 } else { 0 };
        let frames = self.dynamic.as_ref().map_or(0, |d| d.frames);
        Mesh::grid_bytes(vertices, fields, frames)
    }
}

/// A patch's trim: the Laplace map of its region and the repaired `(ρ, φ)` grid. The map
/// is solved in the metric-scaled plane `(u, k v)` (see `scale`).
#[derive(Clone, Debug)]
pub struct TrimSetup {
    /// The map (holds the validated region).
    pub map: Arc<pdeshape_core::trim::LaplaceMap>,
    /// The grid in the patch's parameter domain, with its quality report (figures in the
    /// scaled plane).
    pub grid: Arc<pdeshape_core::trim::TrimGrid>,
    /// The trim curves in the patch's parameters.
    pub curves: Vec<(String, pdeshape_core::trim::TrimCurve)>,
    /// The map and the quality figures work in the plane `(u·scale[0], v·scale[1])`.
    pub scale: [f64; 2],
}

/// A solid blend with its mesh settings.
#[derive(Clone, Debug)]
pub struct SolidSetup {
    /// The blend.
    pub blend: Arc<pdeshape_core::solid::SolidBlend>,
    /// The boundary surfaces `S₁ … S₄` (slots `(u, v)`).
    pub faces: [pdeshape_core::data::FieldRef; 4],
    /// Mesh vertices `(nu, nv, nw)`.
    pub cells: (usize, usize, usize),
    /// Extent of the primary solids drawn beyond the end faces.
    pub primary: f64,
}

/// A dynamic blend with its animation settings.
#[derive(Clone, Debug)]
pub struct DynamicSetup {
    /// The blend (frames are solved on demand).
    pub blend: Arc<pdeshape_core::blend::DynamicBlend>,
    /// `[t0, t1]`.
    pub times: (f64, f64),
    /// Number of frames (`t_i = t0 + i (t1 − t0)/(frames − 1)`).
    pub frames: usize,
}

impl DynamicSetup {
    /// The frame times.
    pub fn frame_times(&self) -> Vec<f64> {
        let n = self.frames.max(2);
        (0..n).map(|i| self.times.0 + (self.times.1 - self.times.0) * i as f64 / (n - 1) as f64).collect()
    }
}

/// A solved static blend with what is needed to solve it again another way.
#[derive(Clone, Debug)]
pub struct BlendSetup {
    /// The solution.
    pub blend: Arc<pdeshape_core::blend::StaticBlend>,
    /// The options it was solved with.
    pub options: pdeshape_core::blend::BlendOptions,
}

/// A family of cross sections `C(v; s)` placed at `(u_i, s_i)`, against which `check`
/// measures how far the patch strays between its sections.
///
/// Between sections the reference is `C(v; s(i(u)))` at the *fractional section index*
/// `i(u)`: the inverse of the spacing map (`u_i = i/m` for uniform,
/// `u_i = (1 − cos(πi/m))/2` for Chebyshev spacing, `m = count − 1`; linear between explicit
/// `u_i`), with `s` the scene's `s(i)` expression. [`SectionFamily::s_linear`] is the cruder
/// reference with `s` linear in `u` between neighbouring sections.
#[derive(Clone, Debug)]
pub struct SectionFamily {
    /// Section positions `u_i` (increasing).
    pub us: Vec<f64>,
    /// Section parameters `s_i`.
    pub ss: Vec<f64>,
    /// How the `u_i` were placed.
    pub spacing: Spacing,
    /// `s(i)`, the section parameter at a (fractional) index.
    pub s_of_index: pdeshape_core::expr::Expr,
    /// `C(v, t, s)`.
    pub curve: Arc<pdeshape_core::data::ExprField>,
}

/// The placement of sections in `u`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Spacing {
    /// `u_i = i/m`.
    Uniform,
    /// `u_i = (1 − cos(πi/m))/2`.
    Chebyshev,
    /// Given explicitly.
    Explicit,
}

impl SectionFamily {
    /// The fractional section index `i(u)` (inverse of the spacing map).
    pub fn index_at(&self, u: f64) -> f64 {
        let m = (self.us.len() - 1) as f64;
        match self.spacing {
            Spacing::Uniform => u * m,
            Spacing::Chebyshev => m * (1.0 - 2.0 * u).clamp(-1.0, 1.0).acos() / std::f64::consts::PI,
            Spacing::Explicit => {
                let k = self.us.partition_point(|&x| x <= u).clamp(1, self.us.len() - 1);
                let (u0, u1) = (self.us[k - 1], self.us[k]);
                (k - 1) as f64 + if u1 > u0 { (u - u0) / (u1 - u0) } else { 0.0 }
            }
        }
    }

    /// `s(i(u))`: the section parameter at the fractional index of `u`.
    pub fn s_at(&self, u: f64) -> f64 {
        self.s_of_index.eval(&[self.index_at(u)])
    }

    /// `s(u)`, linear between neighbouring sections.
    pub fn s_linear(&self, u: f64) -> f64 {
        let k = self.us.partition_point(|&x| x <= u).clamp(1, self.us.len() - 1);
        let (u0, u1) = (self.us[k - 1], self.us[k]);
        let f = if u1 > u0 { (u - u0) / (u1 - u0) } else { 0.0 };
        self.ss[k - 1] + f * (self.ss[k] - self.ss[k - 1])
    }
}

impl std::fmt::Debug for ScenePatch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ScenePatch")
            .field("name", &self.name)
            .field("kind", &self.kind)
            .field("resolution", &self.resolution)
            .finish()
    }
}

/// Picture settings.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderSettings {
    /// Camera azimuth (degrees).
    pub azimuth: f64,
    /// Camera elevation (degrees).
    pub elevation: f64,
    /// Image size.
    pub size: (u32, u32),
    /// Draw mesh lines.
    pub wireframe: bool,
    /// Colour by this field.
    pub field: Option<String>,
    /// Zoom factor.
    pub zoom: f64,
    /// What the surfaces show: shading, zebra, isophotes or a curvature map.
    pub view: crate::render::View,
    /// Zebra and isophote stripes (black and white each, over a half turn).
    pub stripes: f64,
    /// Zebra stripe direction in the screen plane (degrees from horizontal).
    pub stripe_angle: f64,
    /// Symmetric limit of a curvature map's colour scale; `None`: the 95th percentile of
    /// `|value|` over everything drawn.
    pub curvature_limit: Option<f64>,
}

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            azimuth: 35.0,
            elevation: 25.0,
            size: (800, 600),
            wireframe: false,
            field: None,
            zoom: 1.0,
            view: crate::render::View::Shaded,
            stripes: 8.0,
            stripe_angle: 0.0,
            curvature_limit: None,
        }
    }
}

/// A parameter study: the scene re-solved for each value of one parameter.
#[derive(Clone, Debug, PartialEq)]
pub struct Study {
    /// Caption of the strip.
    pub title: String,
    /// Parameters fixed for the whole study.
    pub set: Vec<(String, f64)>,
    /// The varying parameter.
    pub vary: String,
    /// Its values, one panel each.
    pub values: Vec<f64>,
}

/// A loaded and resolved scene.
#[derive(Debug)]
pub struct Scene {
    /// The file label (path or name).
    pub file: String,
    /// The file stem, used for output names.
    pub name: String,
    /// The source text.
    pub source: String,
    /// `[scene] title`.
    pub title: Option<String>,
    /// `[scene] description`.
    pub description: Option<String>,
    /// `[scene] reference`.
    pub reference: Option<String>,
    /// Parameters in file order.
    pub params: IndexMap<String, Param>,
    /// `[import.*]`: the CAD models read, in file order.
    pub imports: Vec<SceneImport>,
    /// Named curves.
    pub curves: IndexMap<String, FieldRef>,
    /// Primary surfaces.
    pub surfaces: Vec<SceneSurface>,
    /// Patches in file order.
    pub patches: Vec<ScenePatch>,
    /// Picture settings.
    pub render: RenderSettings,
    /// Output formats (file extensions) for directory builds and the gallery.
    pub formats: Vec<String>,
    /// Parameter studies (`[[studies]]`).
    pub studies: Vec<Study>,
    /// The options it was resolved with (re-solves — parameter studies — keep its caps,
    /// solver and terms).
    pub options: LoadOptions,
}

/// Reads a scene file: a regular file (not a device, FIFO or directory: `/dev/zero` would
/// never end) of at most `limits.scene` MiB, in UTF-8. Errors name the file and the cause.
pub fn read_scene_file(path: &Path, limits: &pdeshape_core::limits::Limits) -> Result<String, SceneError> {
    use std::io::Read;
    let file = path.display().to_string();
    let fail = |message: String| SceneError {
        file: file.clone(),
        line: None,
        column: None,
        key: String::new(),
        message,
        snippet: None,
        caret: 0,
    };
    let meta = std::fs::metadata(path).map_err(|e| fail(format!("cannot read the scene file: {e}")))?;
    if !meta.is_file() {
        let what = if meta.is_dir() { "a directory" } else { "not a regular file (a device, FIFO or socket)" };
        return Err(fail(format!("cannot read the scene file: it is {what}")));
    }
    let cap = limits.scene as u64 * (1 << 20);
    let too_big = |len: u64| {
        limits
            .check(pdeshape_core::limits::Cap::Scene, len.div_ceil(1 << 20), "the scene file's size")
            .map_err(|e| fail(e.to_string()))
    };
    too_big(meta.len())?;
    let mut bytes = Vec::new();
    std::fs::File::open(path)
        .and_then(|f| f.take(cap + 1).read_to_end(&mut bytes))
        .map_err(|e| fail(format!("cannot read the scene file: {e}")))?;
    too_big(bytes.len() as u64)?; // it grew while being read
    String::from_utf8(bytes).map_err(|e| {
        fail(format!("the scene file is not UTF-8 text (invalid byte at offset {})", e.utf8_error().valid_up_to()))
    })
}

/// The folder a scene file's imports are relative to (`.` for a bare file name).
pub fn scene_folder(path: &Path) -> std::path::PathBuf {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => std::path::PathBuf::from("."),
    }
}

impl Scene {
    /// Loads a scene file (its imports relative to its folder).
    pub fn load(path: &Path) -> Result<Scene, SceneError> {
        let file = path.display().to_string();
        let text = read_scene_file(path, &pdeshape_core::limits::Limits::default())?;
        let name = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "scene".into());
        let opts = LoadOptions { imports: ImportRoot::Dir(scene_folder(path)), ..Default::default() };
        Scene::parse_with(&text, &file, &name, &opts)
    }

    /// The models this scene imported, by the path as it wrote them: what re-solves of it
    /// (and the editor's requests on it) may import without reading files again.
    pub fn imported(&self) -> ImportRoot {
        ImportRoot::Preloaded(Arc::new(self.imports.iter().map(|i| (i.step.clone(), i.model.clone())).collect()))
    }

    /// Parses scene text. `overrides` replace parameter values (by name) before anything
    /// is resolved — the live editor's sliders.
    pub fn parse(text: &str, file: &str, name: &str, overrides: &HashMap<String, f64>) -> Result<Scene, SceneError> {
        build::build(Source { file, text }, name, &LoadOptions { params: overrides.clone(), ..Default::default() })
    }

    /// Parses scene text with parameter overrides and a solver override for every patch
    /// that offers a choice of solver (blends: `auto`, `exact`, `collocation`).
    pub fn parse_with(text: &str, file: &str, name: &str, opts: &LoadOptions) -> Result<Scene, SceneError> {
        build::build(Source { file, text }, name, opts)
    }

    /// The patch with the given name.
    pub fn patch(&self, name: &str) -> Option<&ScenePatch> {
        self.patches.iter().find(|p| p.name == name)
    }
}

#[cfg(test)]
mod tests;
