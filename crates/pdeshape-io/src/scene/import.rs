//! `[import.NAME] step = "part.step"`: a CAD model's faces, edges and holes in a scene.
//!
//! The model is read by [`crate::import::step`] (the `model` and `entities` caps apply) and
//! its holes found once. Its parts get names a user reads in `pdeshape holes`:
//!
//! - `NAME.faceID`: the face `#ID` as a primary surface `S(s, v)` in the face surface's own
//!   parameters (`s` = its `u`), usable wherever scenes take a surface (trimlines of blends,
//!   curves on a surface, fill edges); drawn in context as the face, trimmed by its loops
//!   (`model::import_meshes`);
//! - `NAME.edgeID`: the edge `#ID` (an `EDGE_CURVE`), as a fill edge on its face;
//! - `NAME.holeK`: the `K`-th loop of the free boundary, numbered as `holes` numbers them, as
//!   a fill's whole loop.
//!
//! **Where files are read from** ([`ImportRoot`]): a scene read from a file imports paths
//! relative to that file's folder; the editor's requests, whose text comes from a web page,
//! import only the files its own scene imported when it started (a page cannot make it
//! read any other file); scene text without a folder imports nothing.

use crate::import::step::{StepModel, read_step};
use crate::scene::SceneSurface;
use crate::scene::ctx::{Ctx, R, span};
use crate::scene::raw::RawImport;
use indexmap::IndexMap;
use pdeshape_core::brep::{FaceSurface, Hole, HoleKind, HoleUse, holes};
use pdeshape_core::patch::VDomain;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use toml::Spanned;

/// A model read for a scene, with its holes.
pub struct ImportedModel {
    /// The path it was read from.
    pub path: PathBuf,
    /// The model.
    pub model: StepModel,
    /// Its free boundary's loops, numbered from 1 in names.
    pub holes: Vec<Hole>,
    /// Its faces meshed for drawing, made once on first use (the editor redraws them with
    /// every answer).
    meshes: std::sync::OnceLock<Vec<pdeshape_core::mesh::Mesh>>,
}

impl std::fmt::Debug for ImportedModel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ImportedModel")
            .field("path", &self.path)
            .field("faces", &self.model.brep.faces.len())
            .field("holes", &self.holes.len())
            .finish()
    }
}

impl ImportedModel {
    /// Reads the model at `path` with the caps of `limits`.
    pub fn read(path: &Path, limits: &pdeshape_core::limits::Limits) -> Result<ImportedModel, String> {
        let model = read_step(path, limits).map_err(|e| e.to_string())?;
        let holes = holes(&model.brep);
        Ok(ImportedModel { path: path.to_path_buf(), model, holes, meshes: Default::default() })
    }

    /// Its faces meshed for drawing (`faceID`; edges about 1/60 of the model's size):
    /// faces that cannot be meshed — geometry not read, loops that do not close in the
    /// face's parameters — are left out.
    pub fn face_meshes(&self) -> &[pdeshape_core::mesh::Mesh] {
        self.meshes.get_or_init(|| {
            let b = &self.model.brep;
            let target = b.size() / 60.0;
            (0..b.faces.len())
                .filter_map(|k| {
                    let mut m = pdeshape_core::brep::face_mesh(b, k, target).ok()?;
                    m.check_finite().ok()?;
                    m.name = format!("face{}", b.faces[k].id);
                    Some(m)
                })
                .collect()
        })
    }
}

/// Where `[import.*]` files are read from.
#[derive(Clone, Debug, Default)]
pub enum ImportRoot {
    /// Nothing is imported: scene text that came without a folder.
    #[default]
    Refused,
    /// Paths relative to this folder (the scene file's); absolute ones as written.
    Dir(PathBuf),
    /// Only these models, by the path as the scene writes it (what a scene imported
    /// before: the editor's requests, re-solves of a loaded scene).
    Preloaded(Arc<IndexMap<String, Arc<ImportedModel>>>),
}

/// An `[import.NAME]` of a scene, read.
#[derive(Clone, Debug)]
pub struct SceneImport {
    /// `NAME`.
    pub name: String,
    /// The path as the scene writes it.
    pub step: String,
    /// The model.
    pub model: Arc<ImportedModel>,
}

/// Reads every `[import.*]` of a scene from `root`.
pub(in crate::scene) fn read_imports(
    ctx: &Ctx,
    raw: &IndexMap<String, Spanned<RawImport>>,
    root: &ImportRoot,
) -> R<Vec<SceneImport>> {
    let mut out = Vec::new();
    for (name, imp) in raw {
        let key = format!("import.{name}.step");
        let step = imp.get_ref().step.get_ref().clone();
        let sp = span(&imp.get_ref().step);
        let model = match root {
            ImportRoot::Refused => {
                return Err(ctx.err(
                    sp,
                    key,
                    "this scene was not read from a file, so it has no folder to import from (load the scene from its file)",
                ));
            }
            ImportRoot::Preloaded(models) => models.get(&step).cloned().ok_or_else(|| {
                let known: Vec<&str> = models.keys().map(String::as_str).collect();
                ctx.err(
                    sp.clone(),
                    &key,
                    format!(
                        "only the models the scene imported when it was opened can be imported here ({})",
                        if known.is_empty() { "none".to_string() } else { known.join(", ") }
                    ),
                )
            })?,
            ImportRoot::Dir(dir) => {
                let path = dir.join(&step);
                Arc::new(ImportedModel::read(&path, &ctx.limits).map_err(|e| ctx.err(sp.clone(), &key, e))?)
            }
        };
        out.push(SceneImport { name: name.clone(), step, model });
    }
    Ok(out)
}

/// The faces of the imports as primary surfaces `NAME.faceID` (faces on geometry that is
/// not read are left out; naming one is an error saying so).
pub(in crate::scene) fn import_surfaces(imports: &[SceneImport]) -> Vec<SceneSurface> {
    let mut out = Vec::new();
    for imp in imports {
        let b = &imp.model.model.brep;
        for f in &b.faces {
            let Some(s) = &f.surface else { continue };
            out.push(SceneSurface {
                name: format!("{}.face{}", imp.name, f.id),
                field: s.field(),
                s_range: None,
                domain: face_v_domain(s),
                resolution: (17, 65),
            });
        }
    }
    out
}

/// The `v` domain of a face's surface: a B-spline's knot range; the analytic surfaces'
/// angle `[0, 2π)` where `v` is an angle (sphere's latitude `[−π/2, π/2]`), else unbounded
/// directions as `[−1, 1]` (faces are drawn from their loops, not from this domain, so it
/// only names the surface's own range).
fn face_v_domain(s: &FaceSurface) -> VDomain {
    use pdeshape_core::data::analytic::AnalyticKind;
    match s {
        FaceSurface::Nurbs(n) => {
            let (_, (v0, v1)) = n.domain();
            VDomain::open(v0, v1)
        }
        FaceSurface::Analytic(a) => match a.kind {
            AnalyticKind::Torus { .. } => VDomain::PERIODIC,
            AnalyticKind::Sphere { .. } => VDomain::open(-std::f64::consts::FRAC_PI_2, std::f64::consts::FRAC_PI_2),
            _ => VDomain::open(-1.0, 1.0),
        },
    }
}

/// The import and the number after `what` in a name `NAME.whatN` (`part.hole2`,
/// `part.edge17`); errors at `key` say what names exist.
fn split_name<'i>(
    ctx: &Ctx,
    imports: &'i [SceneImport],
    name: &Spanned<String>,
    what: &str,
    key: &str,
) -> R<(&'i SceneImport, u64)> {
    let text = name.get_ref();
    let bad = |msg: String| ctx.err(span(name), key, msg);
    let Some((model, rest)) = text.split_once('.') else {
        return Err(bad(format!("`{text}` is not an imported {what}'s name (`MODEL.{what}N`, e.g. `part.{what}1`)")));
    };
    let imp = imports.iter().find(|i| i.name == model).ok_or_else(|| {
        let known: Vec<&str> = imports.iter().map(|i| i.name.as_str()).collect();
        bad(format!(
            "no model `{model}` is imported (imported: {})",
            if known.is_empty() { "none".to_string() } else { known.join(", ") }
        ))
    })?;
    let number = rest.strip_prefix(what).and_then(|n| n.parse::<u64>().ok()).ok_or_else(|| {
        bad(format!("`{text}` is not an imported {what}'s name (`{model}.{what}N`, e.g. `{model}.{what}1`)"))
    })?;
    Ok((imp, number))
}

/// The hole `NAME.holeK` (a simple loop).
pub(in crate::scene) fn find_hole<'i>(
    ctx: &Ctx,
    imports: &'i [SceneImport],
    name: &Spanned<String>,
    key: &str,
) -> R<(&'i SceneImport, &'i Hole)> {
    let (imp, k) = split_name(ctx, imports, name, "hole", key)?;
    let n = imp.model.holes.len();
    let hole = (k >= 1).then(|| imp.model.holes.get(k as usize - 1)).flatten().ok_or_else(|| {
        ctx.err(
            span(name),
            key,
            format!("`{}` has {n} hole(s), numbered from 1 (`pdeshape holes` lists them)", imp.name),
        )
    })?;
    if hole.kind != HoleKind::Simple {
        let what = match hole.kind {
            HoleKind::TouchesItself => "a loop that touches itself",
            _ => "an open chain of edges",
        };
        return Err(ctx.err(span(name), key, format!("`{}` is {what}, not a simple hole", name.get_ref())));
    }
    Ok((imp, hole))
}

/// The edge `NAME.edgeID` as a face runs it: the face named by `face` (`NAME.faceID`), or
/// the edge's only face (a free edge).
pub(in crate::scene) fn find_edge_use<'i>(
    ctx: &Ctx,
    imports: &'i [SceneImport],
    edge: &Spanned<String>,
    face: Option<&Spanned<String>>,
    key: &str,
) -> R<(&'i SceneImport, HoleUse)> {
    let (imp, id) = split_name(ctx, imports, edge, "edge", &format!("{key}.edge"))?;
    let b = &imp.model.model.brep;
    let index = b
        .edges
        .iter()
        .position(|e| e.id == id)
        .ok_or_else(|| ctx.err(span(edge), format!("{key}.edge"), format!("`{}` has no edge #{id}", imp.name)))?;
    let uses = b.uses_of(index);
    let faces: Vec<String> = uses.iter().map(|u| format!("{}.face{}", imp.name, b.faces[u.face].id)).collect();
    let chosen = match face {
        Some(f) => {
            let (fimp, fid) = split_name(ctx, imports, f, "face", &format!("{key}.face"))?;
            if fimp.name != imp.name {
                return Err(ctx.err(span(f), format!("{key}.face"), "the face and the edge are of different models"));
            }
            uses.iter().find(|u| b.faces[u.face].id == fid).copied().ok_or_else(|| {
                ctx.err(
                    span(f),
                    format!("{key}.face"),
                    format!("face #{fid} does not bound edge #{id} (its faces: {})", faces.join(", ")),
                )
            })?
        }
        None => match uses.as_slice() {
            [u] => *u,
            [] => return Err(ctx.err(span(edge), format!("{key}.edge"), format!("edge #{id} bounds no face"))),
            _ => {
                return Err(ctx.err(
                    span(edge),
                    format!("{key}.edge"),
                    format!(
                        "edge #{id} bounds {} faces ({}): name the one the fill meets with `face`",
                        uses.len(),
                        faces.join(", ")
                    ),
                ));
            }
        },
    };
    Ok((imp, chosen))
}
