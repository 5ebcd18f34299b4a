//! The holes of an imported model: listed (a typed report for `holes` and its JSON), and
//! filled — each hole by a fill of order 4 (G1) or 6 (G2) from the faces around
//! (`pdeshape_core::brep::fill_hole`), fitted by a B-spline face of degree 9 (knots of
//! multiplicity 6 where the fill's corner blends end) that interpolates the fill's cross
//! derivatives at the loop, measured against the exact
//! faces around after the fit, and sewn into the model (`export::sewn_step`).

use crate::export::{SewnFace, sewn_step, write_atomic};
use crate::import::step::StepModel;
use pdeshape_core::Vec3;
use pdeshape_core::brep::{Brep, Hole, HoleKind, HoleUse, box_distance, fill_hole};
use pdeshape_core::fill::{Fill, FillOptions, foot_of};
use pdeshape_core::fit::{BSplineSurface, EdgeTolerance, FitOptions, FitReport, fit_surface};
use pdeshape_core::num::{max_nan, min_nan};
use serde::Serialize;
use std::path::Path;
use std::sync::Arc;

/// Corners whose faces' normals differ by more than this are reported as not G1 (as
/// `check` judges a fill's corners).
pub const G1_CORNER: f64 = 1e-9;

/// What `holes` reports.
#[derive(Clone, Debug, Serialize)]
pub struct HolesReport {
    /// The file.
    pub file: String,
    /// The model's length unit.
    pub unit: String,
    /// Counts of the B-rep's shells, faces, edges.
    pub shells: usize,
    /// Faces.
    pub faces: usize,
    /// Edges.
    pub edges: usize,
    /// Faces and edges on geometry that is not read (`#id TYPE`), by the face or edge.
    pub unsupported: Vec<String>,
    /// Where the file's assembly places each shell (every shell at least once: a shell
    /// outside any product structure where it is, with an empty path).
    pub instances: Vec<InstanceReport>,
    /// The loops of the free boundary, numbered from 1.
    pub holes: Vec<HoleReport>,
}

/// One placed copy of a shell.
#[derive(Clone, Debug, Serialize)]
pub struct InstanceReport {
    /// The shell's id.
    pub shell: u64,
    /// The products from the root assembly down to the part, `name (#id)`.
    pub path: Vec<String>,
    /// The motion from the part's coordinates to the model's, `[R | t]` by rows (`x ↦ R x
    /// + t`).
    pub placement: [[f64; 4]; 3],
    /// The box of the shell's vertices, placed.
    pub vertex_bbox: [[f64; 3]; 2],
}

/// A hole in one placed copy of its shell.
#[derive(Clone, Debug, Serialize)]
pub struct PlacedHole {
    /// The copy: its index in [`HolesReport::instances`].
    pub instance: usize,
    /// The hole's bounding box there (the same points as [`HoleReport::bbox`], placed).
    pub bbox: [[f64; 3]; 2],
}

/// One loop of the free boundary.
#[derive(Clone, Debug, Serialize)]
pub struct HoleReport {
    /// Its number (from 1), as `--holes` takes it.
    pub index: usize,
    /// `hole`, `touches itself` or `open chain`.
    pub kind: &'static str,
    /// Its edges' ids (`#id`) in loop order.
    pub edges: Vec<u64>,
    /// The ids of the faces around, each once.
    pub faces: Vec<u64>,
    /// Its length, in the model's unit.
    pub length: f64,
    /// Its bounding box `[min, max]`.
    pub bbox: [[f64; 3]; 2],
    /// At each corner (the end of each edge): the vertex's id and the angle between the
    /// two faces' normals (radians).
    pub corners: Vec<(u64, f64)>,
    /// Whether the faces meet G1 (angle ≤ [`G1_CORNER`]) at every corner.
    pub g1_corners: bool,
    /// Its bounding box in each placed copy of its shell (a hole is a part's: filled
    /// once, it is filled in every copy).
    pub placed: Vec<PlacedHole>,
}

fn corners(b: (Vec3, Vec3)) -> [[f64; 3]; 2] {
    [[b.0.x, b.0.y, b.0.z], [b.1.x, b.1.y, b.1.z]]
}

/// The reports of `m`'s placed shells.
fn instance_reports(m: &StepModel) -> Vec<InstanceReport> {
    let b = &m.brep;
    // each shell's vertices, once
    let mut of_shell: Vec<Vec<usize>> = vec![Vec::new(); b.shells.len()];
    for f in &b.faces {
        for &(e, _) in f.loops.iter().flatten() {
            of_shell[f.shell].extend(b.edges[e].vertices);
        }
    }
    for v in &mut of_shell {
        v.sort_unstable();
        v.dedup();
    }
    m.instances
        .iter()
        .map(|i| {
            let f = &i.placement;
            let mut lo = Vec3::new(f64::INFINITY, f64::INFINITY, f64::INFINITY);
            let mut hi = -lo;
            for &v in &of_shell[i.shell] {
                let p = f.global(b.vertices[v].1);
                lo = Vec3::new(min_nan(lo.x, p.x), min_nan(lo.y, p.y), min_nan(lo.z, p.z));
                hi = Vec3::new(max_nan(hi.x, p.x), max_nan(hi.y, p.y), max_nan(hi.z, p.z));
            }
            let row = |k: usize| {
                let c = |v: Vec3| [v.x, v.y, v.z][k];
                [c(f.x), c(f.y), c(f.z), c(f.o)]
            };
            InstanceReport {
                shell: b.shells[i.shell].id,
                path: i.path.clone(),
                placement: [row(0), row(1), row(2)],
                vertex_bbox: corners((lo, hi)),
            }
        })
        .collect()
}

fn kind_name(k: HoleKind) -> &'static str {
    match k {
        HoleKind::Simple => "hole",
        HoleKind::TouchesItself => "touches itself",
        HoleKind::Open => "open chain",
    }
}

/// The report of `m`'s holes (`holes` computed by the caller, once).
pub fn holes_report(m: &StepModel, holes: &[Hole]) -> HolesReport {
    let b = &m.brep;
    HolesReport {
        file: m.file.clone(),
        unit: m.unit.0.clone(),
        shells: b.shells.len(),
        faces: b.faces.len(),
        edges: b.edges.len(),
        unsupported: m.unsupported.iter().map(|(id, what)| format!("#{id}: {what}")).collect(),
        instances: instance_reports(m),
        holes: holes
            .iter()
            .enumerate()
            .map(|(i, h)| HoleReport {
                index: i + 1,
                kind: kind_name(h.kind),
                edges: h.uses.iter().map(|u| b.edges[u.edge].id).collect(),
                faces: h.faces().into_iter().map(|f| b.faces[f].id).collect(),
                length: h.length,
                bbox: [[h.bbox.0.x, h.bbox.0.y, h.bbox.0.z], [h.bbox.1.x, h.bbox.1.y, h.bbox.1.z]],
                corners: h.corners.iter().map(|c| (b.vertices[c.vertex].0, c.angle)).collect(),
                g1_corners: h.corners.iter().all(|c| c.angle <= G1_CORNER),
                placed: m
                    .instances
                    .iter()
                    .enumerate()
                    .filter(|(_, i)| i.shell == b.faces[h.uses[0].face].shell)
                    .map(|(k, i)| PlacedHole { instance: k, bbox: corners(h.placed_bbox(b, &i.placement)) })
                    .collect(),
            })
            .collect(),
    }
}

/// How holes are filled.
#[derive(Clone, Debug, PartialEq)]
pub struct FillHolesOptions {
    /// 4 (G1) or 6 (G2).
    pub order: usize,
    /// The holes to fill (numbers from 1); `None`: every simple hole.
    pub holes: Option<Vec<usize>>,
    /// Leave loops of more edges open.
    pub max_edges: Option<usize>,
    /// The fitted faces' measured maximum deviation from their fills, relative to the
    /// model's size.
    pub relative: f64,
}

impl Default for FillHolesOptions {
    fn default() -> Self {
        FillHolesOptions { order: 4, holes: None, max_edges: None, relative: 1e-7 }
    }
}

/// A filled hole with its fitted face and the continuity measured after the fit.
pub struct FilledHole {
    /// The hole's number (from 1).
    pub index: usize,
    /// The fill.
    pub fill: Arc<Fill>,
    /// The order of its PDE (4: G1, 6: G2).
    pub order: usize,
    /// The largest distance between the hole's edge curves and their faces (as the file
    /// has them).
    pub edge_offset: f64,
    /// Its B-spline face.
    pub surface: BSplineSurface,
    /// The fit.
    pub fit: FitReport,
    /// The seam between the face and the faces around, measured on the written face.
    pub seam: SeamFigures,
}

/// Continuity between a new face and the faces around its hole, at points of its `u = 0`
/// side.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct SeamFigures {
    /// Largest distance to the nearest face around.
    pub gap: f64,
    /// Largest angle (radians) between the normals.
    pub angle: f64,
    /// Largest difference of the normal curvatures across the edge (1/length).
    pub curvature_gap: f64,
    /// Largest curvature of the faces around across the edge there.
    pub curvature: f64,
    /// `curvature_gap` over the larger of `curvature` and 1 / the model's size.
    pub relative_curvature_gap: f64,
    /// Points compared.
    pub samples: usize,
}

/// The normal curvature in the direction `t` and the unit normal from derivatives `d` in
/// the order of `BSplineSurface::derivatives(…, 2, 2)` (index `3i + k` for `∂uⁱ∂vᵏS`).
fn normal_curvature(d: &[Vec3], t: Vec3) -> Option<(f64, Vec3)> {
    pdeshape_core::fit::normal_curvature(d[3], d[1], d[6], d[4], d[2], t)
}

/// The continuity of `s` (its `u = 0` side) against the faces `faces` of `b` (whose size
/// is `size`) at `samples` points.
pub fn measure_seam(b: &Brep, faces: &[usize], s: &BSplineSurface, samples: usize, size: f64) -> SeamFigures {
    let mut out = SeamFigures { samples, ..Default::default() };
    let v1 = s.v.knots.last().copied().unwrap_or(1.0);
    let v0 = s.v.knots.first().copied().unwrap_or(0.0);
    // each face's last foot seeds the next (a grid search for every point costs thousands
    // of evaluations of a B-spline face)
    let mut seeds: Vec<Option<[f64; 2]>> = vec![None; faces.len()];
    // each face's field made once (a closed B-spline face's is periodic, `FaceSurface::field`)
    let fields: Vec<Option<_>> = faces.iter().map(|&fi| b.faces[fi].surface.as_ref().map(|s| s.field())).collect();
    // each face's box; its start grid is the face's own, made once per model
    // (`BrepFace::start_grid`): the faces next to the nearest are searched afresh at most
    // samples of a many-sided hole (their feet from the last leave the face)
    let boxes: Vec<Option<_>> =
        faces.iter().map(|&fi| b.faces[fi].surface.as_ref().and_then(|s| s.bounding_box())).collect();
    // the face chosen for the previous sample (its foot is found first, and bounds which
    // faces can be nearer)
    let mut previous: Option<usize> = None;
    for i in 0..samples {
        let v = v0 + (v1 - v0) * (i as f64 + 0.5) / samples as f64;
        let d = s.derivatives(0.0, v, 2, 2);
        let p = d[0];
        // face k's foot of p from its last foot, and its distance
        let foot = |k: usize, seed: Option<[f64; 2]>| -> Option<([f64; 2], f64)> {
            let face = &b.faces[faces[k]];
            let (Some(fs), Some(field)) = (&face.surface, &fields[k]) else { return None };
            // a foot outside a B-spline face's domain (the last foot carried across a closed
            // face's seam) is on its extrapolation, not on the face: from there moved by the
            // period, or searched afresh
            let settle = |start: [f64; 2]| {
                let c = foot_of(field.as_ref(), p, start, 0.0)?;
                if fs.in_domain(c) {
                    return Some(c);
                }
                foot_of(field.as_ref(), p, fs.wrap(c), 0.0).filter(|c| fs.in_domain(*c))
            };
            let c = seed.and_then(settle).or_else(|| settle(face.start_grid()?.start(p)))?;
            Some((c, (field.eval(&c) - p).norm()))
        };
        let first = previous.map(|k| (k, foot(k, seeds[k])));
        // branch and bound: no face whose surface lies farther than the nearest foot found
        // so far can be the nearest, so the faces are tried nearest box first and skipped
        // once their box, or their start grid less its slack, lies farther than that foot
        // (plus a margin: a foot may lie up to 1e-6 of the domain beyond it, on the
        // extrapolation; the margin is far above the grid's round-off). A many-sided hole
        // is spared a search on every far face, also where the samples pass from one face
        // to the next and the last face's foot leaves it.
        let margin = 1e-6 * size;
        let mut best: Option<(f64, usize, [f64; 2])> = None;
        if let Some((k, Some((c, dist)))) = first {
            seeds[k] = Some(c);
            best = Some((dist, k, c));
        }
        let mut others: Vec<(f64, usize)> = (0..faces.len())
            .filter(|k| first.is_none_or(|(kp, _)| kp != *k))
            .map(|k| (boxes[k].map_or(0.0, |x| box_distance(x, p)), k))
            .collect();
        others.sort_by(|x, y| x.0.total_cmp(&y.0));
        for (near, k) in others {
            let bound = best.map_or(f64::INFINITY, |x| x.0 + margin);
            // (a NaN is never skipped)
            if near > bound {
                continue;
            }
            if b.faces[faces[k]].start_grid().and_then(|g| g.distance_bound(p)).is_some_and(|x| x > bound) {
                continue;
            }
            let Some((c, dist)) = foot(k, seeds[k]) else { continue };
            seeds[k] = Some(c);
            if best.is_none_or(|x| dist < x.0) {
                best = Some((dist, k, c));
            }
        }
        previous = best.map(|x| x.1);
        let Some((dist, k, c)) = best else {
            out.gap = f64::NAN;
            continue;
        };
        out.gap = max_nan(out.gap, dist);
        let field = fields[k].as_ref().expect("chosen among faces with surfaces");
        let nd = {
            let j = field.jet(&[c[0], c[1], 0.0], pdeshape_core::jet::JetShape::new(&[2, 2]));
            // the face's derivatives in the order of `BSplineSurface::derivatives`
            let mut v = Vec::with_capacity(9);
            for a in 0..=2 {
                for k in 0..=2 {
                    v.push(j.derivative([a, k, 0]));
                }
            }
            v
        };
        // across the edge: the new face's S_u without its part along the edge
        let tangent = d[1].normalized().unwrap_or(Vec3::ZERO);
        let across = (d[3] - tangent * d[3].dot(tangent)).normalized().unwrap_or(Vec3::ZERO);
        match (normal_curvature(&d, across), normal_curvature(&nd, across)) {
            (Some((k1, n1)), Some((k2, n2))) => {
                let angle = n1.cross(n2).norm().atan2(n1.dot(n2).abs());
                out.angle = max_nan(out.angle, angle);
                // the normals' orientations may differ: curvature against one normal
                let k2 = if n1.dot(n2) < 0.0 { -k2 } else { k2 };
                out.curvature_gap = max_nan(out.curvature_gap, (k1 - k2).abs());
                out.curvature = max_nan(out.curvature, k2.abs());
            }
            _ => out.angle = f64::NAN,
        }
    }
    out.relative_curvature_gap = out.curvature_gap / max_nan(out.curvature, 1.0 / size);
    out
}

/// Fills the holes of `m` that `o` asks for; every asked hole must be fillable.
pub fn fill_holes(m: &StepModel, holes: &[Hole], o: &FillHolesOptions) -> Result<Vec<FilledHole>, String> {
    if o.order != 4 && o.order != 6 {
        return Err(format!("the order is 4 (G1) or 6 (G2), not {}", o.order));
    }
    let chosen: Vec<usize> = match &o.holes {
        Some(list) => {
            for &i in list {
                if i == 0 || i > holes.len() {
                    return Err(format!("hole {i} does not exist: the model has {} (numbered from 1)", holes.len()));
                }
            }
            list.iter().map(|i| i - 1).collect()
        }
        None => (0..holes.len())
            .filter(|&i| holes[i].kind == HoleKind::Simple)
            .filter(|&i| o.max_edges.is_none_or(|n| holes[i].uses.len() <= n))
            .collect(),
    };
    // a shell the file calls closed that lost faces must get every hole back filled:
    // said before any fill is made
    for (k, h) in holes.iter().enumerate() {
        let shell = &m.brep.shells[m.brep.faces[h.uses[0].face].shell];
        let lost = m.shell_lost_faces(shell.id);
        if lost && shell.closed && !chosen.contains(&k) {
            return Err(format!(
                "hole {} is not asked for, but faces of the closed shell #{} were replaced: every hole they leave must be filled",
                k + 1,
                shell.id
            ));
        }
    }
    // a hole between parts of different shells: its face would join the shells, which
    // the writer does not do (`export::step_sew`); said before any fill is made
    for &k in &chosen {
        let shell_id = |u: &HoleUse| m.brep.shells[m.brep.faces[u.face].shell].id;
        let first = shell_id(&holes[k].uses[0]);
        if let Some(other) = holes[k].uses.iter().map(shell_id).find(|&s| s != first) {
            return Err(format!(
                "hole {}: it runs along faces of the shells #{first} and #{other} (parts that touch): a new face joining two shells is not written",
                k + 1
            ));
        }
    }
    let mut out = Vec::with_capacity(chosen.len());
    for i in chosen {
        let opts = FillOptions { order: o.order, ..Default::default() };
        let fill = fill_hole(&m.brep, &holes[i], &opts).map_err(|e| format!("hole {}: {e}", i + 1))?;
        out.push(fit_filled(m, holes, i + 1, Arc::new(fill.fill), o.order, fill.edge_offset, o.relative)?);
    }
    Ok(out)
}

/// What the written face's edge along its hole is fitted to (against the fill, which
/// meets the faces around to round-off): gap 3e-10 of the model's size, normals within
/// 3e-9 rad, and at order 6 the normal curvature across the edge within 3e-7 of
/// `max(|κ|, 1 / size)` — a third of what the faces are measured against afterwards
/// (gap 1e-9, 1e-8 rad, 1e-6), since the fit's check samples where the final measure
/// lands elsewhere.
pub fn seam_tolerance(order: usize, size: f64) -> EdgeTolerance {
    EdgeTolerance { gap: 3e-10 * size, angle: 3e-9, curvature: (order >= 6).then_some(3e-7), scale: size }
}

/// Fits the fill `fill` (of order `order`) of hole `index` (from 1) of `m` by a B-spline
/// face of degree 9 (interpolating the fill's first and second cross derivatives along the
/// loop) to `relative` of the model's size, its edge along the loop to [`seam_tolerance`],
/// and measures the seam of the face against the faces around.
pub fn fit_filled(
    m: &StepModel,
    holes: &[Hole],
    index: usize,
    fill: Arc<Fill>,
    order: usize,
    edge_offset: f64,
    relative: f64,
) -> Result<FilledHole, String> {
    let fail = |e: String| format!("hole {index}: {e}");
    let h = holes.get(index.wrapping_sub(1)).ok_or_else(|| fail("no such hole".into()))?;
    // a fill whose parametrisation turns over would be written as a face folded onto
    // itself (OpenCASCADE reads such a solid as invalid, of negative volume): e.g. the rim
    // of a removed boss's wall, where the face around turns away from the loop — a gap
    // between two loops, not a hole one cap closes
    let (nu, nv) = (41, 200);
    let folds = fill.turn_overs(nu, nv);
    if folds > 0 {
        return Err(fail(format!(
            "the fill folds over ({folds} of {} points of a {nu} × {nv} grid turn its normal by more than 120°): the faces around turn away from the hole, which no cap closes without folding; not filled",
            nu * nv
        )));
    }
    let size = m.brep.size();
    // degree 9 in both directions, with knots of multiplicity 6 where the corner blends
    // end (the fill is C³ there): against degree 5 without them, the four OCCT models'
    // holes need 2–4× fewer control points along the loop and less time, their seams
    // within the same tolerances (BENCHMARKS.md, "fill-holes: knots where the corner
    // blends end")
    let fo = FitOptions {
        tolerance: Some(relative * size),
        degrees: (9, 9),
        v_breaks: fill.corner_parameters(),
        v_joins: fill.blend_joins(),
        edge: Some(seam_tolerance(order, size)),
        // the cap of the control points along the loop (a rounded box's corner at order 6
        // takes 214)
        max_points: 1000,
        ..Default::default()
    };
    let (surface, fit) = fit_surface(fill.patch().as_ref(), &fo).map_err(|e| fail(e.to_string()))?;
    if !fit.max_deviation.is_finite() {
        return Err(fail(format!("the fit's measured deviation {} is not finite", fit.max_deviation)));
    }
    let seam = measure_seam(&m.brep, &h.faces(), &surface, 400, size);
    Ok(FilledHole { index, fill, order, edge_offset, surface, fit, seam })
}

/// Writes `m` with the filled holes sewn in to `out` (atomically).
pub fn write_filled(m: &StepModel, holes: &[Hole], filled: &[FilledHole], out: &Path) -> Result<(), String> {
    let bytes = filled_bytes(m, holes, filled)?;
    write_atomic(out, |w| w.write_all(&bytes)).map_err(|e| format!("{}: {e}", out.display()))
}

/// The bytes of `m` with the filled holes sewn in (what [`write_filled`] writes).
pub fn filled_bytes(m: &StepModel, holes: &[Hole], filled: &[FilledHole]) -> Result<Vec<u8>, String> {
    let size = m.brep.size();
    // a shell is closed when all its holes are filled
    let shell_of = |h: &Hole| m.brep.faces[h.uses[0].face].shell;
    let faces: Vec<SewnFace> = filled
        .iter()
        .map(|f| {
            let h = &holes[f.index - 1];
            let closes_shell = holes
                .iter()
                .enumerate()
                .filter(|(_, g)| shell_of(g) == shell_of(h))
                .all(|(j, _)| filled.iter().any(|x| x.index == j + 1));
            SewnFace { surface: &f.surface, hole: h, closes_shell }
        })
        .collect();
    // the new faces' corners meet the hole's vertices within the fit's tolerance and the
    // file's edges' offset from their faces
    let edge_offset = filled.iter().fold(0.0, |a, f| max_nan(a, f.edge_offset));
    let tol = 10.0 * (1e-7 * size + edge_offset);
    sewn_step(m, &faces, tol)
}

/// The fills of a scene that imports a model, fitted for [`write_filled`]: every patch must
/// fill a hole of one imported model (`hole = "MODEL.holeK"`, or `edges` that are exactly a
/// hole's), each hole once. Fitted as `fill-holes` fits (to `relative` of the model's size).
pub fn scene_fills(
    sc: &crate::scene::Scene,
    relative: f64,
) -> Result<(Arc<crate::scene::ImportedModel>, Vec<FilledHole>), String> {
    let Some(first) = sc.imports.first() else {
        return Err(format!("the scene {} imports no model", sc.file));
    };
    let mut import = None;
    let mut out: Vec<FilledHole> = Vec::new();
    for p in &sc.patches {
        let (Some(h), Some(fill)) = (&p.hole, &p.fill) else {
            return Err(format!(
                "patch `{}` does not fill a hole of the imported model: a STEP file of a scene that imports a model is that model with the fills of its holes sewn in (use a mesh format for other patches)",
                p.name
            ));
        };
        let imp = sc.imports.iter().find(|i| i.name == h.import).unwrap_or(first);
        if *import.get_or_insert(&imp.name) != &imp.name {
            return Err(format!(
                "patch `{}` fills a hole of `{}`, another patch one of `{}`: one model is written back at a time",
                p.name,
                imp.name,
                import.map_or("", |s| s.as_str())
            ));
        }
        if let Some(other) = out.iter().position(|f| f.index == h.hole) {
            return Err(format!(
                "patches `{}` and `{}` fill the same hole {}.hole{}",
                sc.patches[other].name, p.name, imp.name, h.hole
            ));
        }
        let m = &imp.model;
        let f = fit_filled(&m.model, &m.holes, h.hole, fill.clone(), h.order, h.edge_offset, relative)
            .map_err(|e| format!("patch `{}`: {e}", p.name))?;
        out.push(f);
    }
    if out.is_empty() {
        return Err(format!("the scene {} has no fills to sew into its imported model", sc.file));
    }
    let name = import.unwrap_or(&first.name);
    let model = sc.imports.iter().find(|i| i.name == *name).map_or(first.model.clone(), |i| i.model.clone());
    Ok((model, out))
}
