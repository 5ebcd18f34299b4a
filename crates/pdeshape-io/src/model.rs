//! From a resolved scene to meshes, pictures and diagnostics.

use crate::render::{CONTEXT_COLOR, Camera, Image, PALETTE, RenderItem, render};
use crate::scene::{RenderSettings, Scene, ScenePatch};
use pdeshape_core::mesh::{GridOptions, Mesh, grid_mesh};
use pdeshape_core::patch::{PrimarySurface, check_conditions};
use serde_json::{Value, json};

/// Number of `v` samples per condition in the exactness check (SPEC §3: ≥ 1000).
pub const CHECK_SAMPLES: usize = 1000;

/// Meshes one patch at its resolution, with its position conditions as highlighted
/// curves. Fails when the patch is not finite somewhere.
pub fn patch_mesh(p: &ScenePatch) -> Result<Mesh, String> {
    let (nu, nv) = p.resolution;
    let mut m =
        grid_mesh(p.surface.as_ref(), &GridOptions::new(nu, nv)).map_err(|e| format!("patch `{}`: {e}", p.name))?;
    m.name = p.name.clone();
    let dom = p.surface.v_domain();
    let n = (4 * nv).max(64);
    for c in p.conditions.iter().filter(|c| c.order == 0) {
        let pts: Vec<_> = (0..=n).map(|k| p.surface.point(c.u, dom.at(k as f64 / n as f64))).collect();
        m.curves.push(pts);
    }
    m.check_finite()?;
    Ok(m)
}

/// Meshes of all patches, in scene order.
pub fn patch_meshes(scene: &Scene) -> Result<Vec<Mesh>, String> {
    scene.patches.iter().map(patch_mesh).collect()
}

/// Meshes of the primary surfaces drawn in context (those with an `s_range`).
pub fn context_meshes(scene: &Scene) -> Result<Vec<Mesh>, String> {
    let mut out = Vec::new();
    for s in &scene.surfaces {
        let Some(range) = s.s_range else { continue };
        let ps = PrimarySurface::new(s.field.clone(), range, s.domain, 0.0);
        let mut m = grid_mesh(&ps, &GridOptions::new(s.resolution.0, s.resolution.1))
            .map_err(|e| format!("surface `{}`: {e}", s.name))?;
        m.name = format!("surface-{}", s.name);
        m.check_finite()?;
        out.push(m);
    }
    Ok(out)
}

/// Renders patches (coloured) with the context surfaces (neutral).
pub fn render_meshes(patches: &[Mesh], context: &[Mesh], colors: &[Option<[f64; 3]>], r: &RenderSettings) -> Image {
    let mut items = Vec::new();
    for m in context {
        items.push(RenderItem { mesh: m, color: CONTEXT_COLOR, field: None, wireframe: false });
    }
    for (k, m) in patches.iter().enumerate() {
        let color = colors.get(k).copied().flatten().map(|c| c.map(|x| x as f32)).unwrap_or(PALETTE[k % PALETTE.len()]);
        items.push(RenderItem { mesh: m, color, field: r.field.clone(), wireframe: r.wireframe });
    }
    let cam = Camera { azimuth: r.azimuth, elevation: r.elevation, zoom: r.zoom, width: r.size.0, height: r.size.1 };
    render(&items, &cam)
}

/// Renders the whole scene.
pub fn render_scene(scene: &Scene) -> Result<Image, String> {
    let patches = patch_meshes(scene)?;
    let context = context_meshes(scene)?;
    let colors: Vec<_> = scene.patches.iter().map(|p| p.color).collect();
    Ok(render_meshes(&patches, &context, &colors, &scene.render))
}

/// Lebesgue constant above which `check` warns that the condition set amplifies its data
/// (SPEC §3 "Many sections").
pub const LEBESGUE_WARNING: f64 = 1e3;

/// Diagnostics of one patch, as `check --json` prints them.
pub fn patch_diagnostics(p: &ScenePatch) -> Value {
    let rep = check_conditions(p.surface.as_ref(), &p.conditions, 0.0, CHECK_SAMPLES);
    let dom = p.surface.v_domain();
    let mut d = json!({
        "name": p.name,
        "kind": p.kind.name(),
        "solver": match p.kind {
            crate::scene::PatchKind::Hermite => "hermite-interpolation",
            crate::scene::PatchKind::Pde => "spectral",
        },
        "conditions": p.conditions.iter().map(|c| json!({"u": c.u, "order": c.order})).collect::<Vec<_>>(),
        "v_domain": {"start": dom.start, "end": dom.end, "periodic": dom.periodic},
        "resolution": [p.resolution.0, p.resolution.1],
        "condition_error": {
            "samples": CHECK_SAMPLES,
            "max_abs": rep.max_abs,
            "max_rel": rep.max_rel,
            "patch_size": rep.size,
        },
        "warnings": [],
    });
    if let Some(fam) = &p.sections {
        // How far the patch strays from the section family between its sections.
        let distance = |s_of: &dyn Fn(f64) -> f64| {
            let (mut worst, mut at): (f64, [f64; 3]) = (0.0, [0.0; 3]);
            for i in 0..=400 {
                let u = i as f64 / 400.0;
                let s = s_of(u);
                for j in 0..48 {
                    let v = dom.at((j as f64 + 0.25) / 48.0);
                    let x = p.surface.point(u, v);
                    let r = pdeshape_core::data::Field::eval(fam.curve.as_ref(), &[v, 0.0, s]);
                    let dist = (x - r).norm();
                    if dist > worst {
                        (worst, at) = (dist, [u, v, s]);
                    }
                }
            }
            (worst, at)
        };
        let (worst, at) = distance(&|u| fam.s_at(u));
        d["section_reference_distance"] = json!(worst);
        d["section_reference_distance_linear_s"] = json!(distance(&|u| fam.s_linear(u)).0);
        d["section_reference_worst"] = json!({"u": at[0], "v": at[1], "s": at[2]});
    }
    if let Some(sp) = &p.spectral {
        let r = sp.report();
        // The 2N-th derivatives behind the residual are evaluated in f64; above N = 10 their
        // round-off swamps the residual, so it is reported only up to order 20.
        let residuals = r.order <= 20;
        // RMS residuals on an interior grid
        let (mut t2, mut w2, mut r2, mut n, mut have_t) = (0.0, 0.0, 0.0, 0.0, true);
        for i in 1..if residuals { 12 } else { 0 } {
            for j in 0..24 {
                let v = dom.at((j as f64 + 0.5) / 24.0);
                let res = sp.residual(i as f64 / 12.0, v);
                r2 += res.remainder.unwrap_or(f64::NAN).powi(2);
                match (res.truncated, res.whole) {
                    (Some(t), Some(w)) => {
                        t2 += t * t;
                        w2 += w * w;
                    }
                    _ => have_t = false,
                }
                n += 1.0;
            }
        }
        d["spectral"] = json!({
            "order": r.order,
            "modes": r.modes,
            "omega": r.omega,
            "max_mode_condition_number": r.max_mode_condition,
            "modes_solved_in_f64": r.methods.0,
            "modes_solved_in_multiprecision": r.methods.1,
            "lebesgue_mode0": r.lebesgue.0,
            "lebesgue_mode1": r.lebesgue.1,
            "rms_residual_truncated": if have_t && residuals { json!((t2 / n).sqrt()) } else { Value::Null },
            "rms_residual_remainder": if residuals { json!((r2 / n).sqrt()) } else { Value::Null },
            "rms_residual_whole": if have_t && residuals { json!((w2 / n).sqrt()) } else { Value::Null },
        });
        let leb = r.lebesgue.0.max(r.lebesgue.1.unwrap_or(0.0));
        if leb > LEBESGUE_WARNING {
            let msg = format!(
                "the condition set amplifies its data by up to {leb:.3e} between conditions (Lebesgue constant): \
                 many sections at equispaced u make high-order interpolation swing; place them at \
                 Chebyshev-distributed u (sections.spacing = \"chebyshev\") or use fewer sections"
            );
            if let Some(w) = d["warnings"].as_array_mut() {
                w.push(json!(msg));
            }
        }
    }
    d
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
                rem = rem.max(q.remainder(u, v).norm());
                if let Some(r) = q.residual(u, v).whole {
                    mx = mx.max(r);
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

/// Diagnostics of a scene.
pub fn scene_diagnostics(scene: &Scene) -> Value {
    json!({
        "scene": scene.name,
        "title": scene.title,
        "parameters": scene.params.iter().map(|(k, p)| (k.clone(), json!(p.value))).collect::<serde_json::Map<_, _>>(),
        "patches": scene.patches.iter().map(patch_diagnostics).collect::<Vec<_>>(),
    })
}
