//! From a resolved scene to meshes, pictures and diagnostics.

use crate::render::{CONTEXT_COLOR, Camera, Image, PALETTE, RenderItem, render};
use crate::scene::{RenderSettings, Scene, ScenePatch};
use pdeshape_core::blend::{DynamicFrame, Gaps, Solver, StaticBlend, attached_gaps_at, gaps_at};
use pdeshape_core::data::FieldRef;
use pdeshape_core::mesh::{GridOptions, Mesh, ScalarField, grid_mesh, grid_mesh_with_curvatures};
use pdeshape_core::num::MaxNan;
use pdeshape_core::patch::PrimarySurface;
use pdeshape_core::patch::{CurvatureKind, Surface};

mod diagnose;
mod finite;
pub mod report;
pub use diagnose::{
    LEBESGUE_WARNING, attached_ends, blend_condition_report, condition_report, continuity_report, patch_diagnostics,
    scene_diagnostics,
};
pub use finite::first_non_finite;

/// Number of `v` samples per condition in the exactness check (SPEC §3: ≥ 1000).
pub const CHECK_SAMPLES: usize = 1000;
/// A relative condition error above this is reported as a warning (the solvers meet their
/// conditions to round-off, about 1e-15 … 1e-12).
pub const CONDITION_WARNING: f64 = 1e-8;

/// Meshes one patch at its resolution, with its position conditions as highlighted
/// curves. Fails when the patch is not finite somewhere.
pub fn patch_mesh(p: &ScenePatch) -> Result<Mesh, String> {
    let m = unchecked_mesh(p, &[])?;
    m.check_finite()?;
    Ok(m)
}

/// [`patch_mesh`] before its finiteness check, with the curvature fields `kinds` last
/// among its fields (on an untrimmed grid from the mesh's own evaluation,
/// `grid_mesh_with_curvatures`; none for solids, whose boundary is not one surface).
fn unchecked_mesh(p: &ScenePatch, kinds: &[CurvatureKind]) -> Result<Mesh, String> {
    if let Some(sd) = &p.solid {
        let mut m = pdeshape_core::solid::boundary_mesh(&sd.blend, sd.cells);
        m.name = p.name.clone();
        return Ok(m);
    }
    let (nu, nv) = p.resolution;
    let mut m = match &p.trim {
        // a trimmed patch: the (ρ, φ) grid of its region; the trim loop is its highlighted curve
        Some(t) => pdeshape_core::trim::trimmed_mesh(p.surface.as_ref(), &t.grid),
        None if !kinds.is_empty() => grid_mesh_with_curvatures(p.surface.as_ref(), &GridOptions::new(nu, nv), kinds),
        None => grid_mesh(p.surface.as_ref(), &GridOptions::new(nu, nv)),
    }
    .map_err(|e| format!("patch `{}`: {e}", p.name))?;
    let curvatures = std::mem::take(&mut m.fields);
    m.name = p.name.clone();
    let dom = p.surface.v_domain();
    let n = (4 * nv).max(64);
    // the position conditions' curves (none on a trimmed patch), evaluated together on the
    // grid path (rows shared)
    let us: Vec<f64> = match p.trim {
        Some(_) => Vec::new(),
        None => p.conditions.iter().filter(|c| c.order == 0).map(|c| c.u).collect(),
    };
    if !us.is_empty() {
        let vs: Vec<f64> = (0..=n).map(|k| dom.at(k as f64 / n as f64)).collect();
        let g = p.surface.grid(&us, &vs);
        m.curves.extend(g.chunks(vs.len()).map(|row| row.iter().map(|d| d[0]).collect::<Vec<_>>()));
    }
    if let Some(b) = &p.blend {
        add_continuity_fields(&mut m, p, b.blend.as_ref());
    } else if p.trim.is_none() && p.dynamic.is_none() {
        add_attached_fields(&mut m, p);
    }
    if let Some(d) = &p.dynamic {
        m.animation = Some(dynamic_animation(p, d)?);
    }
    m.fields.extend(curvatures);
    if p.trim.is_some() {
        m.add_curvatures(p.surface.as_ref(), kinds);
    }
    Ok(m)
}

/// The frames of a dynamic blend as morph targets: positions and normals of the same grid
/// at every frame time.
fn dynamic_animation(
    p: &ScenePatch,
    d: &crate::scene::DynamicSetup,
) -> Result<pdeshape_core::mesh::MorphAnimation, String> {
    let times = d.frame_times();
    let mut anim = pdeshape_core::mesh::MorphAnimation { times: times.clone(), positions: vec![], normals: vec![] };
    for &t in &times {
        let (fm, _) = frame_mesh(p, d, t)?;
        anim.positions.push(fm.positions);
        anim.normals.push(fm.normals);
    }
    Ok(anim)
}

/// The editor's mesh of a patch at time `t`: [`patch_mesh_at`] plus every exact curvature
/// field ([`analysis_mesh`] with all of [`CurvatureKind::ALL`]).
pub fn editor_mesh(p: &ScenePatch, t: Option<f64>) -> Result<Mesh, String> {
    analysis_mesh(p, t, &CurvatureKind::ALL)
}

/// The mesh of a patch at time `t` with the exact curvature fields `kinds` (of the frame at
/// `t` for a dynamic blend; none for solids, whose boundary is not one surface).
pub fn analysis_mesh(p: &ScenePatch, t: Option<f64>, kinds: &[CurvatureKind]) -> Result<Mesh, String> {
    let m = match (&p.dynamic, t) {
        _ if p.solid.is_some() => unchecked_mesh(p, &[])?,
        (Some(d), Some(t)) => {
            let (mut m, frame) = frame_mesh(p, d, t.clamp(d.times.0, d.times.1))?;
            m.add_curvatures(&frame, kinds);
            m
        }
        _ => unchecked_mesh(p, kinds)?,
    };
    m.check_finite()?;
    Ok(m)
}

/// The meshes a picture with the view of `r` needs: [`patch_mesh_at`], with the curvature
/// field of a curvature view.
fn view_mesh(p: &ScenePatch, t: Option<f64>, r: &RenderSettings) -> Result<Mesh, String> {
    match r.view.curvature() {
        Some(k) => analysis_mesh(p, t, &[k]),
        None => patch_mesh_at(p, t),
    }
}

/// The mesh of a patch at time `t` (dynamic blends; other patches ignore `t`).
pub fn patch_mesh_at(p: &ScenePatch, t: Option<f64>) -> Result<Mesh, String> {
    match (&p.dynamic, t) {
        (Some(d), Some(t)) => {
            let (m, _) = frame_mesh(p, d, t.clamp(d.times.0, d.times.1))?;
            m.check_finite()?;
            Ok(m)
        }
        _ => patch_mesh(p),
    }
}

/// The frame meshes of a dynamic patch (`None` for other patches), named `PATCH-NNN`.
pub fn frame_meshes(p: &ScenePatch) -> Option<Result<Vec<Mesh>, String>> {
    let d = p.dynamic.as_ref()?;
    let run = || -> Result<Vec<Mesh>, String> {
        let mut out = Vec::new();
        for (i, t) in d.frame_times().into_iter().enumerate() {
            let (mut m, _) = frame_mesh(p, d, t)?;
            m.name = format!("{}-{i:03}", p.name);
            m.check_finite()?;
            out.push(m);
        }
        Ok(out)
    };
    Some(run())
}

/// The trimline data `∂ᵏS/∂uᵏ`, `k = 0, 1, 2`, at the blend end `u_e`, from the patch's
/// conditions.
pub fn end_data(p: &ScenePatch, u_e: f64) -> [Option<FieldRef>; 3] {
    std::array::from_fn(|k| p.conditions.iter().find(|c| c.u == u_e && c.order == k).map(|c| c.data.clone()))
}

/// Per-vertex continuity fields of a blend: at each vertex, the gap of its `v` on the
/// nearer trimline (`u = 0` for `u < ½`): `c0_gap`, `c1_gap`, `g1_angle` (radians),
/// `c2_gap`, `g2_gap` (SPEC §4 continuity diagnostics).
fn add_continuity_fields(m: &mut Mesh, p: &ScenePatch, s: &dyn pdeshape_core::patch::Surface) {
    use rayon::prelude::*;
    let dom = s.v_domain();
    let ends = [end_data(p, 0.0), end_data(p, 1.0)];
    let at = |e: usize, f: f64| {
        let d = &ends[e];
        gaps_at(s, e as f64, dom.at(f), [d[0].as_ref(), d[1].as_ref(), d[2].as_ref()])
    };
    let gaps: Vec<Gaps> = match m.grid {
        // a grid's column shares its v: the gaps of the 2 nv seam points, spread over the rows
        Some((nu, nv)) if nu * nv == m.uvs.len() => {
            let seams: Vec<Gaps> = (0..2 * nv).into_par_iter().map(|k| at(k / nv, m.uvs[k % nv][1])).collect();
            (0..nu * nv).map(|k| seams[usize::from(m.uvs[k][0] >= 0.5) * nv + k % nv]).collect()
        }
        _ => m.uvs.par_iter().map(|uv| at(usize::from(uv[0] >= 0.5), uv[1])).collect(),
    };
    type Pick = fn(&Gaps) -> Option<f64>;
    let picks: [(&str, Pick); 5] = [
        ("c0_gap", |g| g.c0),
        ("c1_gap", |g| g.c1),
        ("g1_angle", |g| g.g1),
        ("c2_gap", |g| g.c2),
        ("g2_gap", |g| g.g2),
    ];
    for (name, pick) in picks {
        if gaps.iter().all(|g| pick(g).is_some()) {
            let values = gaps.iter().map(|g| pick(g).unwrap_or(0.0)).collect();
            m.fields.push(ScalarField { name: name.into(), values });
        }
    }
}

/// Per-vertex seam fields of a patch attached to trim curves ([`attached_ends`]): at each
/// vertex, `c0_gap` and `g1_angle` of its `v` on the nearest attached end; for a fill also
/// `g2_gap` (the curvature gap of `Fill::edge_gaps_at`).
fn add_attached_fields(m: &mut Mesh, p: &ScenePatch) {
    use rayon::prelude::*;
    let ends = attached_ends(p);
    let Some((nu, nv)) = m.grid.filter(|(nu, nv)| nu * nv == m.uvs.len()) else { return };
    if ends.is_empty() {
        return;
    }
    let s = p.surface.as_ref();
    let dom = s.v_domain();
    // the attached end nearest to each row
    let near =
        |u: f64| ends.iter().enumerate().min_by(|a, b| (a.1.0 - u).abs().total_cmp(&(b.1.0 - u).abs())).unwrap().0;
    let seams: Vec<Gaps> = (0..ends.len() * nv)
        .into_par_iter()
        .map(|k| {
            let (u, data) = &ends[k / nv];
            attached_gaps_at(s, *u, dom.at(m.uvs[k % nv][1]), data)
        })
        .collect();
    let gaps: Vec<Gaps> = (0..nu * nv).map(|k| seams[near(m.uvs[k][0]) * nv + k % nv]).collect();
    for (name, pick) in [("c0_gap", (|g: &Gaps| g.c0) as fn(&Gaps) -> Option<f64>), ("g1_angle", |g| g.g1)] {
        if gaps.iter().all(|g| pick(g).is_some()) {
            let values = gaps.iter().map(|g| pick(g).unwrap_or(0.0)).collect();
            m.fields.push(ScalarField { name: name.into(), values });
        }
    }
    // a fill also knows its neighbours' second fundamental forms: the curvature gap
    // (relative to the loop radius) along its loop, spread over the rows
    if let Some(f) = &p.fill {
        let g2: Vec<f64> = (0..nv).into_par_iter().map(|j| f.edge_gaps_at(dom.at(m.uvs[j][1])).g2).collect();
        m.fields.push(ScalarField { name: "g2_gap".into(), values: (0..nu * nv).map(|k| g2[k % nv]).collect() });
    }
}

/// The ends (`u` values) of a patch that are seams with other patches: both trimlines of a
/// blend, the attached ends of a patch on trim curves ([`attached_ends`]).
pub fn seam_ends(p: &ScenePatch) -> Vec<f64> {
    if p.blend.is_some() {
        return vec![0.0, 1.0];
    }
    if p.trim.is_some() || p.dynamic.is_some() || p.solid.is_some() {
        return Vec::new();
    }
    attached_ends(p).iter().map(|e| e.0).collect()
}

/// The hexahedral volume mesh of a solid patch (`None` for other patches).
pub fn solid_volume(p: &ScenePatch) -> Option<pdeshape_core::mesh::HexMesh> {
    let sd = p.solid.as_ref()?;
    let mut h = pdeshape_core::solid::hex_mesh(&sd.blend, sd.cells);
    h.name = p.name.clone();
    Some(h)
}

/// The blended (primary) solids of a solid patch, drawn as extrusions of its end faces
/// along the cross tangents: `S₁ − s S₂` and `S₃ + s S₄`, `s ∈ [0, primary]`.
pub fn solid_context(p: &ScenePatch) -> Vec<Mesh> {
    let Some(sd) = &p.solid else { return vec![] };
    if sd.primary <= 0.0 {
        return vec![];
    }
    let f = &sd.faces;
    let e = sd.primary;
    type Map<'a> = Box<dyn Fn(f64, f64, f64) -> pdeshape_core::Vec3 + Sync + 'a>;
    let ends: [Map; 2] = [
        Box::new(move |u, v, s| f[0].eval(&[u, v]) - f[1].eval(&[u, v]) * (e * s)),
        Box::new(move |u, v, s| f[2].eval(&[u, v]) + f[3].eval(&[u, v]) * (e * s)),
    ];
    ends.iter()
        .enumerate()
        .map(|(k, x)| {
            let mut m = pdeshape_core::solid::boundary_mesh_of(x.as_ref(), (sd.cells.0, sd.cells.1, 5));
            m.name = format!("{}-primary-{}", p.name, k + 1);
            m
        })
        .collect()
}

/// Meshes of all patches, in scene order.
pub fn patch_meshes(scene: &Scene) -> Result<Vec<Mesh>, String> {
    scene.patches.iter().map(patch_mesh).collect()
}

/// A 64-bit fingerprint of every buffer of every mesh, in order: names, the `f64` bits of
/// positions, normals, UVs, fields, curves and animation frames, the face indices and the
/// grid shape, each buffer preceded by its length (so moving a value from one buffer to the
/// next changes the hash). The fingerprint of a model the editor shows to its page and the
/// tests compare with the library's meshes (thread independence, the load test): equal
/// hashes mean bit-identical meshes (up to a collision), not equal `f32` renderings.
///
/// One step per 64-bit word `w`: `h ← m((h ⊕ w) · P)` with FNV's odd prime `P` and
/// `m(x) = x ⊕ (x ≫ 32)`. Each of the three maps is a bijection of `h` for a fixed `w` and of
/// `w` for a fixed `h`, so meshes that differ in one word always hash differently. (The
/// editor answers every request with this hash; FNV-1a a byte at a time was 18 % of the
/// server's time under the load test.)
pub fn mesh_hash(meshes: &[Mesh]) -> String {
    struct Fnv(u64);
    impl Fnv {
        fn word(&mut self, w: u64) {
            let x = (self.0 ^ w).wrapping_mul(0x100000001b3);
            self.0 = x ^ (x >> 32);
        }
        /// Bytes in little-endian words, the last one padded with zeros (the length that
        /// precedes every byte buffer tells the padding apart).
        fn bytes(&mut self, b: &[u8]) {
            for c in b.chunks(8) {
                let mut w = [0u8; 8];
                w[..c.len()].copy_from_slice(c);
                self.word(u64::from_le_bytes(w));
            }
        }
        fn len(&mut self, n: usize) {
            self.word(n as u64);
        }
        fn f64s(&mut self, xs: impl ExactSizeIterator<Item = f64>) {
            self.len(xs.len());
            for x in xs {
                self.word(x.to_bits());
            }
        }
        fn vec3s(&mut self, v: &[pdeshape_core::Vec3]) {
            self.len(3 * v.len());
            for p in v {
                self.word(p.x.to_bits());
                self.word(p.y.to_bits());
                self.word(p.z.to_bits());
            }
        }
        fn u32s(&mut self, xs: &[u32]) {
            self.len(xs.len());
            for x in xs {
                self.word(u64::from(*x));
            }
        }
    }
    let mut h = Fnv(0xcbf29ce484222325);
    h.len(meshes.len());
    for m in meshes {
        h.len(m.name.len());
        h.bytes(m.name.as_bytes());
        h.vec3s(&m.positions);
        h.vec3s(&m.normals);
        h.f64s(m.uvs.as_flattened().iter().copied());
        h.u32s(m.quads.as_flattened());
        h.u32s(m.triangles.as_flattened());
        h.len(m.fields.len());
        for f in &m.fields {
            h.len(f.name.len());
            h.bytes(f.name.as_bytes());
            h.f64s(f.values.iter().copied());
        }
        match m.grid {
            Some((a, b)) => h.u32s(&[1, a as u32, b as u32]),
            None => h.u32s(&[0]),
        }
        h.len(m.curves.len());
        for c in &m.curves {
            h.vec3s(c);
        }
        match &m.animation {
            None => h.len(0),
            Some(a) => {
                h.len(1);
                h.f64s(a.times.iter().copied());
                for f in a.positions.iter().chain(&a.normals) {
                    h.vec3s(f);
                }
            }
        }
    }
    format!("{:016x}", h.0)
}

/// Meshes of the primary surfaces drawn in context (those with an `s_range`).
pub fn context_meshes(scene: &Scene) -> Result<Vec<Mesh>, String> {
    context_meshes_at(scene, 0.0)
}

/// The context surfaces at time `t` (moving primary surfaces of dynamic blends).
pub fn context_meshes_at(scene: &Scene, t: f64) -> Result<Vec<Mesh>, String> {
    context_meshes_with(scene, t, &[])
}

/// The context surfaces at time `t` with the exact curvature fields `kinds`.
pub fn context_meshes_with(scene: &Scene, t: f64, kinds: &[CurvatureKind]) -> Result<Vec<Mesh>, String> {
    let mut out = Vec::new();
    for s in &scene.surfaces {
        let Some(range) = s.s_range else { continue };
        let ps = PrimarySurface::new(s.field.clone(), range, s.domain, t);
        let mut m = grid_mesh(&ps, &GridOptions::new(s.resolution.0, s.resolution.1))
            .map_err(|e| format!("surface `{}`: {e}", s.name))?;
        m.name = format!("surface-{}", s.name);
        m.add_curvatures(&ps, kinds);
        m.check_finite()?;
        out.push(m);
    }
    out.extend(import_meshes(scene));
    Ok(out)
}

/// The faces of the scene's imported models, meshed for drawing in context (edges about
/// 1/60 of each model's size; faces that cannot be meshed — geometry not read, loops that
/// do not close in the face's parameters — are left out).
pub fn import_meshes(scene: &Scene) -> Vec<Mesh> {
    let mut out = Vec::new();
    for imp in &scene.imports {
        for m in imp.model.face_meshes() {
            let mut m = m.clone();
            m.name = format!("{}.{}", imp.name, m.name);
            out.push(m);
        }
    }
    out
}

/// The holes of the scene's imported models as polylines (33 points an edge), named
/// `MODEL.holeK` as scenes name them.
pub fn import_hole_loops(scene: &Scene) -> Vec<(String, Vec<pdeshape_core::Vec3>)> {
    let mut out = Vec::new();
    for imp in &scene.imports {
        let b = &imp.model.model.brep;
        for (k, h) in imp.model.holes.iter().enumerate() {
            let mut points = Vec::new();
            for u in &h.uses {
                let e = &b.edges[u.edge];
                let (t0, t1) = if u.forward { e.range } else { (e.range.1, e.range.0) };
                points.extend((0..=32).map(|i| e.point(t0 + (t1 - t0) * i as f64 / 32.0)));
            }
            if points.iter().all(|p| p.x.is_finite() && p.y.is_finite() && p.z.is_finite()) {
                out.push((format!("{}.hole{}", imp.name, k + 1), points));
            }
        }
    }
    out
}

/// Renders patches (coloured) with the context surfaces (neutral), in the view of `r`:
/// zebra stripes and isophotes on everything drawn; a curvature map (its field must be on
/// the meshes: [`analysis_mesh`], [`context_meshes_with`]) on a diverging scale whose
/// symmetric limit is `r.curvature_limit` or the 95th percentile of `|value|` over every
/// mesh drawn, with a legend.
pub fn render_meshes(patches: &[Mesh], context: &[Mesh], colors: &[Option<[f64; 3]>], r: &RenderSettings) -> Image {
    use crate::render::{Paint, View};
    let limit = r.view.curvature().map(|k| {
        let limit = r.curvature_limit.unwrap_or_else(|| {
            let values = patches.iter().chain(context).filter_map(|m| m.field(k.field_name()));
            crate::render::abs_quantile(values.flat_map(|f| f.values.iter().copied()), 0.95)
        });
        // a flat map (all zero) still needs a positive scale
        if limit > 0.0 { limit } else { 1.0 }
    });
    let paint = |field: Option<&String>| match r.view {
        View::Shaded => field.map_or(Paint::Color, |f| Paint::Field(f.clone())),
        View::Zebra => Paint::Zebra { stripes: r.stripes, angle: r.stripe_angle },
        View::Isophotes => Paint::Isophotes { stripes: r.stripes },
        View::Curvature(k) => Paint::Diverging { field: k.field_name().into(), limit: limit.unwrap_or(1.0) },
    };
    let mut items = Vec::new();
    for m in context {
        items.push(RenderItem { mesh: m, color: CONTEXT_COLOR, paint: paint(None), wireframe: false });
    }
    for (k, m) in patches.iter().enumerate() {
        let color = colors.get(k).copied().flatten().map(|c| c.map(|x| x as f32)).unwrap_or(PALETTE[k % PALETTE.len()]);
        items.push(RenderItem { mesh: m, color, paint: paint(r.field.as_ref()), wireframe: r.wireframe });
    }
    let cam = Camera { azimuth: r.azimuth, elevation: r.elevation, zoom: r.zoom, width: r.size.0, height: r.size.1 };
    let mut img = render(&items, &cam);
    if let (Some(k), Some(limit)) = (r.view.curvature(), limit) {
        let title = match k {
            CurvatureKind::Gauss => "Gaussian curvature K",
            CurvatureKind::Mean => "mean curvature H",
            CurvatureKind::K1 => "principal curvature k1 (min)",
            CurvatureKind::K2 => "principal curvature k2 (max)",
        };
        crate::render::draw_legend(&mut img, title, limit);
    }
    img
}

/// Renders the whole scene. A scene of several blends between the same surfaces (an
/// order study) becomes a strip with one panel per blend ([`blend_strip`]).
pub fn render_scene(scene: &Scene) -> Result<Image, String> {
    render_scene_with(scene, &scene.render)
}

/// One curvature-map limit for several panels (so their colours compare): the 95th
/// percentile of `|value|` over all their meshes; `None` for other views.
fn shared_limit<'a>(r: &RenderSettings, meshes: impl Iterator<Item = &'a Mesh>) -> Option<f64> {
    let k = r.view.curvature()?;
    let values = meshes.filter_map(|m| m.field(k.field_name())).flat_map(|f| f.values.iter().copied());
    let l = crate::render::abs_quantile(values, 0.95);
    (l > 0.0).then_some(l)
}

/// [`render_scene`] with other render settings (e.g. another view).
pub fn render_scene_with(scene: &Scene, r: &RenderSettings) -> Result<Image, String> {
    if let Some(strip) = blend_strip_with(scene, r) {
        return strip;
    }
    if let Some(strip) = dynamic_strip_with(scene, r) {
        return strip;
    }
    let patches = scene.patches.iter().map(|p| view_mesh(p, None, r)).collect::<Result<Vec<_>, _>>()?;
    let mut context = context_meshes_with(scene, 0.0, r.view.curvature().as_slice())?;
    for p in &scene.patches {
        context.extend(solid_context(p));
    }
    let colors: Vec<_> = scene.patches.iter().map(|p| p.color).collect();
    Ok(render_meshes(&patches, &context, &colors, r))
}

/// For scenes whose patches are all blends (two or more): one panel per blend, drawn with
/// the primary surfaces, and its continuity numbers printed under it.
pub fn blend_strip(scene: &Scene) -> Option<Result<Image, String>> {
    blend_strip_with(scene, &scene.render)
}

/// [`blend_strip`] with the render settings `r`.
fn blend_strip_with(scene: &Scene, r0: &RenderSettings) -> Option<Result<Image, String>> {
    if scene.patches.len() < 2 || scene.patches.iter().any(|p| p.blend.is_none()) {
        return None;
    }
    let run = || -> Result<Image, String> {
        let context = context_meshes_with(scene, 0.0, r0.view.curvature().as_slice())?;
        let n = scene.patches.len() as u32;
        let mut r = r0.clone();
        let w = (r0.size.0 * 2 / n.min(3)).clamp(64, 520);
        r.size = (w, w * 5 / 4);
        let caption_h = 118;
        let meshes = scene.patches.iter().map(|p| view_mesh(p, None, &r)).collect::<Result<Vec<_>, _>>()?;
        r.curvature_limit = r.curvature_limit.or_else(|| shared_limit(&r, meshes.iter().chain(&context)));
        let mut panels = Vec::new();
        for (k, (p, m)) in scene.patches.iter().zip(&meshes).enumerate() {
            let img = render_meshes(std::slice::from_ref(m), &context, &[p.color.or(Some(palette(k)))], &r);
            let mut panel = Image::new(img.width, img.height + caption_h, [255, 255, 255]);
            panel.paste(&img, 0, 0);
            let c = continuity_report(p);
            let c = c.as_ref();
            let f = |e: &str, pick: fn(&report::GapsReport) -> Option<f64>| {
                let at = |g: Option<&report::GapsReport>| g.and_then(pick);
                match (at(c.and_then(|c| c.start.as_ref())), at(c.and_then(|c| c.end.as_ref()))) {
                    (Some(a), Some(b)) => format!("{:.1e}", pdeshape_core::num::max_nan(a, b)),
                    _ => "-".into(),
                }
                .replace("e0", "")
                    + e
            };
            let text = format!(
                "{}  ({})\nC0 gap {}\nG1 angle {}\nC2 gap {}   G2 {}",
                p.name,
                c.map_or("?", |c| c.class),
                f("", |g| g.c0),
                f(" rad", |g| g.g1),
                f("", |g| g.c2),
                f("", |g| g.g2),
            );
            crate::render::draw_text(&mut panel, 14.0, img.height as f32 + 6.0, 20.0, &text, [30, 30, 40]);
            panels.push(panel);
        }
        Ok(Image::strip(&panels, 6, [255, 255, 255]))
    };
    Some(run())
}

/// For scenes with a dynamic blend: one panel per frame time (patches and moving primary
/// surfaces at that time), captioned with the time.
pub fn dynamic_strip(scene: &Scene) -> Option<Result<Image, String>> {
    dynamic_strip_with(scene, &scene.render)
}

/// [`dynamic_strip`] with the render settings `r`.
fn dynamic_strip_with(scene: &Scene, r0: &RenderSettings) -> Option<Result<Image, String>> {
    let d = scene.patches.iter().find_map(|p| p.dynamic.as_ref())?;
    let run = || -> Result<Image, String> {
        let times = d.frame_times();
        let mut r = r0.clone();
        let w = (r0.size.0 * 3 / times.len().max(3) as u32).clamp(64, 400);
        r.size = (w, w * 4 / 3);
        let mut frames = Vec::new();
        for &t in &times {
            let context = context_meshes_with(scene, t, r.view.curvature().as_slice())?;
            let meshes = scene.patches.iter().map(|p| view_mesh(p, Some(t), &r)).collect::<Result<Vec<_>, _>>()?;
            frames.push((t, meshes, context));
        }
        let all = frames.iter().flat_map(|(_, m, c)| m.iter().chain(c));
        r.curvature_limit = r.curvature_limit.or_else(|| shared_limit(&r, all));
        let colors: Vec<_> = scene.patches.iter().map(|p| p.color).collect();
        let mut panels = Vec::new();
        for (t, meshes, context) in &frames {
            let img = render_meshes(meshes, context, &colors, &r);
            panels.push(captioned(&img, &format!("t = {t:.2}"), 34, 22.0));
        }
        Ok(Image::strip(&panels, 4, [255, 255, 255]))
    };
    Some(run())
}

/// A parameter study as an image strip: the scene re-solved for each value of the varying
/// parameter (other parameters as in `study.set`), drawn at its first time, captioned.
pub fn study_strip(scene: &Scene, study: &crate::scene::Study) -> Result<Image, String> {
    let mut panels = Vec::new();
    for &x in &study.values {
        let mut over: std::collections::HashMap<String, f64> = study.set.iter().cloned().collect();
        over.insert(study.vary.clone(), x);
        // the scene's own caps, solver and terms; the study's parameters
        let opts = crate::scene::LoadOptions { params: over, imports: scene.imported(), ..scene.options.clone() };
        let sc = Scene::parse_with(&scene.source, &scene.file, &scene.name, &opts).map_err(|e| e.to_string())?;
        let t0 = sc.patches.iter().find_map(|p| p.dynamic.as_ref().map(|d| d.times.0)).unwrap_or(0.0);
        let patches = patch_meshes(&sc)?;
        let context = context_meshes_at(&sc, t0)?;
        let colors: Vec<_> = sc.patches.iter().map(|p| p.color).collect();
        let mut r = sc.render.clone();
        r.size = (360, 420);
        let img = render_meshes(&patches, &context, &colors, &r);
        panels.push(captioned(&img, &format!("{} = {x}", study.vary), 34, 22.0));
    }
    let strip = Image::strip(&panels, 4, [255, 255, 255]);
    let mut out = Image::new(strip.width, strip.height + 40, [255, 255, 255]);
    out.paste(&strip, 0, 40);
    crate::render::draw_text(&mut out, 10.0, 6.0, 24.0, &study.title, [20, 20, 30]);
    Ok(out)
}

/// `img` with `text` printed under it on a white band.
fn captioned(img: &Image, text: &str, band: u32, size: f32) -> Image {
    let mut panel = Image::new(img.width, img.height + band, [255, 255, 255]);
    panel.paste(img, 0, 0);
    crate::render::draw_text(&mut panel, 10.0, img.height as f32 + 4.0, size, text, [30, 30, 40]);
    panel
}

/// The mesh of a dynamic patch's frame at time `t`, at the patch's resolution, and the
/// frame surface it meshes.
fn frame_mesh(p: &ScenePatch, dy: &crate::scene::DynamicSetup, t: f64) -> Result<(Mesh, DynamicFrame), String> {
    let f = dy.blend.frame(t).map_err(|e| format!("patch `{}` at t = {t}: {e}", p.name))?;
    let mut m = grid_mesh(&f, &GridOptions::new(p.resolution.0, p.resolution.1))
        .map_err(|e| format!("patch `{}` at t = {t}: {e}", p.name))?;
    m.name = p.name.clone();
    Ok((m, f))
}

fn palette(k: usize) -> [f64; 3] {
    PALETTE[k % PALETTE.len()].map(f64::from)
}

/// The trim of a patch in its parameter domain: the `(ρ, φ)` grid, the trim curves, the
/// bridges and the domain border (paper 003, Figs. 3, 5a–7a).
pub fn trim_picture(p: &ScenePatch) -> Option<Result<Image, String>> {
    use crate::render::{Layer, polyline_plot};
    use pdeshape_core::trim::Piece;
    let t = p.trim.as_ref()?;
    let g = &t.grid;
    let region = t.map.region();
    let k = t.scale;
    let pt = |q: [f64; 2]| (q[0] / k[0], q[1] / k[1]);
    let grid_pt = |q: [f64; 2]| (q[0], q[1]);
    let rings: Vec<Vec<(f64, f64)>> =
        (0..g.rings).map(|i| (0..=g.columns).map(|j| grid_pt(g.points[g.index(i, j)])).collect()).collect();
    let cols: Vec<Vec<(f64, f64)>> =
        (0..g.columns).map(|j| (0..g.rings).map(|i| grid_pt(g.points[g.index(i, j)])).collect()).collect();
    let curves: Vec<Vec<(f64, f64)>> = region
        .curves
        .iter()
        .map(|(_, c)| {
            let mut l: Vec<_> = c.polygonize(64).into_iter().map(|x| pt(x.1)).collect();
            l.push(l[0]);
            l
        })
        .collect();
    let bridges: Vec<Vec<(f64, f64)>> = region
        .pieces
        .iter()
        .filter_map(|q| match q {
            Piece::Segment { a, b } => Some(vec![pt(*a), pt(*b)]),
            _ => None,
        })
        .collect();
    let d = pdeshape_core::trim::Rect {
        min: [region.domain.min[0] / k[0], region.domain.min[1] / k[1]],
        max: [region.domain.max[0] / k[0], region.domain.max[1] / k[1]],
    };
    let border = vec![vec![
        (d.min[0], d.min[1]),
        (d.max[0], d.min[1]),
        (d.max[0], d.max[1]),
        (d.min[0], d.max[1]),
        (d.min[0], d.min[1]),
    ]];
    let layers = [
        Layer { lines: cols, rgb: [225, 150, 150], width: 1, label: String::new() },
        Layer { lines: rings, rgb: [150, 170, 230], width: 1, label: String::new() },
        Layer { lines: border, rgb: [40, 40, 40], width: 2, label: "border C₂".into() },
        Layer { lines: curves, rgb: [0, 0, 0], width: 2, label: "trim curves".into() },
        Layer { lines: bridges, rgb: [220, 120, 0], width: 3, label: "bridges".into() },
    ];
    let pad = 0.03 * (d.max[0] - d.min[0]).max(d.max[1] - d.min[1]);
    let title = format!(
        "{}: trim in (u, v), {} × {} grid, {} folds repaired",
        p.name, g.rings, g.columns, g.report.folds_before
    );
    Some(polyline_plot(
        &title,
        ("u", "v"),
        ((d.min[0] - pad, d.max[0] + pad), (d.min[1] - pad, d.max[1] + pad)),
        &layers,
        (600, 600),
    ))
}

/// The convergence study of a PDE patch over an interior grid for `M = 1 … 16` modes
/// (ω = a (M + 1)), as a plot: max and RMS PDE residual of the whole patch, and the size of
/// the remainder. For data whose derivatives of order 2N are not continuous (polylines,
/// B-splines) the pointwise residual of the remainder grows with M — it contains the
/// 2N-th derivative of a Fourier tail — while the remainder itself shrinks. `None` for other
/// patches and for orders above 8 (where the study would be slow to compute).
pub fn convergence_plot(p: &ScenePatch) -> Option<Result<Image, String>> {
    use pdeshape_core::spectral::{SpectralOptions, SpectralPatch};
    let sp = p.spectral.as_ref()?;
    if sp.order() > 8 {
        return None;
    }
    let dom = p.surface.v_domain();
    let a = sp.options().a;
    let (mut max_pts, mut rms_pts, mut rem_pts) = (Vec::new(), Vec::new(), Vec::new());
    for m in 1..=16usize {
        let Ok(q) = SpectralPatch::new(&p.conditions, dom, SpectralOptions { a, modes: m, omega: None }) else {
            continue;
        };
        let (mut mx, mut s2, mut n, mut rem) = (0.0f64, 0.0, 0.0, 0.0f64);
        for i in 1..16 {
            for j in 0..32 {
                let (u, v) = (i as f64 / 16.0, dom.at((j as f64 + 0.5) / 32.0));
                rem = pdeshape_core::num::max_nan(rem, q.remainder(u, v).norm());
                if let Some(r) = q.residual(u, v).whole {
                    mx = pdeshape_core::num::max_nan(mx, r);
                    s2 += r * r;
                    n += 1.0;
                }
            }
        }
        rem_pts.push((m as f64, rem));
        if n > 0.0 {
            max_pts.push((m as f64, mx));
            rms_pts.push((m as f64, (s2 / n).sqrt()));
        }
    }
    Some(crate::render::line_plot(
        &format!("{}: convergence in the number of Fourier modes", p.name),
        "modes M",
        "size",
        &[
            crate::render::Series { label: "max PDE residual".into(), points: max_pts },
            crate::render::Series { label: "RMS PDE residual".into(), points: rms_pts },
            crate::render::Series { label: "max |remainder R|".into(), points: rem_pts },
        ],
        true,
        (640, 420),
    ))
}

/// The convergence of the collocation solver to the exact one on eigenfunction data: for
/// each blend patch of the scene whose data allow the exact solver, the max distance
/// between the two surfaces on a 41 × 48 grid for `B = 1 … 14` bubble functions. `None`
/// when no patch qualifies.
pub fn blend_convergence_plot(scene: &Scene) -> Option<Result<Image, String>> {
    use pdeshape_core::blend::BlendOptions;
    let mut series = Vec::new();
    for p in &scene.patches {
        let Some(setup) = &p.blend else { continue };
        let b = setup.blend.as_ref();
        if !b.reports().iter().all(|r| r.exact_available) {
            continue;
        }
        let dom = b.v_domain();
        let opts = |solver, bubbles| BlendOptions { solver, bubbles, collocation: None, ..setup.options.clone() };
        let Ok(exact) = StaticBlend::new(b.operators().clone(), &p.conditions, dom, &opts(Solver::Exact, 1)) else {
            continue;
        };
        let mut pts = Vec::new();
        for nb in 1..=14usize {
            let Ok(q) = StaticBlend::new(b.operators().clone(), &p.conditions, dom, &opts(Solver::Collocation, nb))
            else {
                continue;
            };
            let mut worst: f64 = 0.0;
            for i in 0..=40 {
                for j in 0..48 {
                    let (u, v) = (i as f64 / 40.0, dom.at((j as f64 + 0.5) / 48.0));
                    worst = pdeshape_core::num::max_nan(worst, (q.point(u, v) - exact.point(u, v)).norm());
                }
            }
            // exact agreement shows as the round-off floor
            pts.push((nb as f64, worst.max(1e-16)));
        }
        series.push(crate::render::Series { label: p.name.clone(), points: pts });
    }
    if series.is_empty() {
        return None;
    }
    Some(crate::render::line_plot(
        "collocation vs exact: max distance as the bubble count grows",
        "bubble functions B",
        "max |X_collocation − X_exact|",
        &series,
        true,
        (640, 420),
    ))
}

/// The convergence study of a solid patch: for `L = M = N = 2 … 12`, the max change of the
/// solid from the previous `L` at 300 interior points and the RMS PDE residual there.
pub fn solid_convergence_plot(p: &ScenePatch) -> Option<Result<Image, String>> {
    use pdeshape_core::solid::{SolidBlend, SolidOptions};
    let sd = p.solid.as_ref()?;
    // the trial space it was solved with (the report's method name used to be parsed
    // back, which sent the paper's trial space to the complete one)
    let trial = sd.blend.options().trial;
    let pts: Vec<(f64, f64, f64)> =
        pdeshape_core::solid::interior_points(300).into_iter().map(|[u, v, w]| (u, v, w)).collect();
    let (mut change, mut rms) = (Vec::new(), Vec::new());
    let mut prev: Option<Vec<pdeshape_core::Vec3>> = None;
    let top = if trial == pdeshape_core::solid::Trial::Collocation { 8 } else { 12 };
    for n in 2..=top {
        let opts = SolidOptions { trial, terms: (n, n, n) };
        let Ok(s) = SolidBlend::new(sd.blend.operator(), sd.faces.clone(), opts) else { continue };
        let xs: Vec<_> = pts.iter().map(|&(u, v, w)| s.point(u, v, w)).collect();
        let r2: f64 = pts.iter().map(|&(u, v, w)| s.residual(u, v, w).norm().powi(2)).sum::<f64>() / pts.len() as f64;
        rms.push((n as f64, r2.sqrt().max(1e-16)));
        if let Some(pv) = &prev {
            let d = pv.iter().zip(&xs).map(|(a, b)| (*a - *b).norm()).max_nan();
            change.push((n as f64, d.max(1e-16)));
        }
        prev = Some(xs);
    }
    Some(crate::render::line_plot(
        &format!("{}: convergence in the number of terms L = M = N", p.name),
        "L = M = N",
        "size",
        &[
            crate::render::Series { label: "max change from L − 1".into(), points: change },
            crate::render::Series { label: "RMS PDE residual".into(), points: rms },
        ],
        true,
        (640, 420),
    ))
}

/// Iso-parametric cross sections of a solid patch (w = ¼, ½, ¾ and v = ¼, ¾) with their
/// parameter lines: the papers' Figs. 1b–3b.
pub fn solid_sections_picture(scene: &Scene, p: &ScenePatch) -> Option<Result<Image, String>> {
    let sd = p.solid.as_ref()?;
    let mut meshes = Vec::new();
    for (axis, value) in [(2, 0.25), (2, 0.5), (2, 0.75), (1, 0.25), (1, 0.75)] {
        let mut m = pdeshape_core::solid::cross_section(&sd.blend, axis, value, 33);
        m.name = format!("{}-section-{axis}-{value}", p.name);
        meshes.push(m);
    }
    let colors = vec![p.color; meshes.len()];
    let mut r = scene.render.clone();
    r.wireframe = true;
    Some(Ok(render_meshes(&meshes, &[], &colors, &r)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use pdeshape_core::Vec3;

    fn mesh() -> Mesh {
        Mesh {
            name: "m".into(),
            positions: vec![Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.0)],
            normals: vec![Vec3::new(0.0, 0.0, 1.0); 3],
            uvs: vec![[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]],
            triangles: vec![[0, 1, 2]],
            ..Default::default()
        }
    }

    /// Regression: the hash read only the f32-rounded positions, so meshes that differ in
    /// their normals, UVs, faces or below f32 precision compared equal.
    #[test]
    fn the_hash_sees_every_buffer_and_every_bit() {
        let h = mesh_hash(&[mesh()]);
        assert_eq!(h, mesh_hash(&[mesh()]));
        let mut changes: Vec<Mesh> = Vec::new();
        let mut m = mesh();
        m.positions[1].x = f64::from_bits(1f64.to_bits() + 1); // below f32 resolution
        changes.push(m);
        let mut m = mesh();
        m.normals[2].z = f64::from_bits(1f64.to_bits() - 1);
        changes.push(m);
        let mut m = mesh();
        m.uvs[0][1] = 1e-300;
        changes.push(m);
        let mut m = mesh();
        m.triangles[0] = [0, 2, 1];
        changes.push(m);
        let mut m = mesh();
        m.fields.push(pdeshape_core::mesh::ScalarField { name: "f".into(), values: vec![0.0; 3] });
        changes.push(m);
        let mut m = mesh();
        m.name = "n".into();
        changes.push(m);
        // two signs (the top bits of two words): with `h ← (h ⊕ w) · P` alone a top-bit
        // difference stays in the top bit and the second cancels the first
        let mut m = mesh();
        m.positions[1].x = -1.0;
        m.positions[2].y = -1.0;
        changes.push(m);
        // a zero byte appended to a name (the same padded word; the length tells them apart)
        let mut m = mesh();
        m.name = "m\0".into();
        changes.push(m);
        for (k, m) in changes.iter().enumerate() {
            assert_ne!(mesh_hash(std::slice::from_ref(m)), h, "change {k} not seen");
        }
        // a value moved from one buffer to the next changes the hash
        let mut a = mesh();
        a.uvs.pop();
        let mut b = mesh();
        b.uvs.pop();
        b.normals.push(Vec3::ZERO);
        a.normals.pop();
        assert_ne!(mesh_hash(&[a]), mesh_hash(&[b]));
    }
}
