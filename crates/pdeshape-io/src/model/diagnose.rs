//! Computes the typed [`SceneReport`](super::report::SceneReport) of a solved scene: each
//! patch's condition check and the sections of its kind. Printers (`check`, the gallery,
//! the editor, Python) read the result; nothing here formats text except warnings.

use super::report::*;
use super::{CHECK_SAMPLES, CONDITION_WARNING, end_data};
use crate::scene::{BlendSetup, DynamicSetup, Scene, ScenePatch, SectionFamily, SolidSetup, TrimSetup};
use pdeshape_core::blend::{ContinuityClass, Gaps, SeamGaps, Solver, StaticBlend, attached_seam_gaps, seam_gaps};
use pdeshape_core::data::FieldRef;
use pdeshape_core::num::{MaxNan, max_nan};
use pdeshape_core::patch::{Condition, ConditionReport, Surface, check_conditions};

/// Lebesgue constant above which `check` warns that the condition set amplifies its data
/// (SPEC §3 "Many sections").
pub const LEBESGUE_WARNING: f64 = 1e3;

/// Points per seam in the continuity sections.
const SEAM_SAMPLES: usize = 400;

/// The report of a scene: every patch's, in order.
pub fn scene_diagnostics(scene: &Scene) -> SceneReport {
    SceneReport {
        scene: scene.name.clone(),
        title: scene.title.clone(),
        parameters: scene.params.iter().map(|(k, p)| (k.clone(), p.value)).collect(),
        patches: scene.patches.iter().map(patch_diagnostics).collect(),
        cad: None,
    }
}

/// The report of one patch, as `check --json` prints it.
pub fn patch_diagnostics(p: &ScenePatch) -> PatchReport {
    if let Some(sd) = &p.solid {
        return solid_diagnostics(p, sd);
    }
    let dom = p.surface.v_domain();
    let mut d = PatchReport {
        name: p.name.clone(),
        kind: p.kind,
        solver: p.solver.clone(),
        conditions: p.conditions.iter().map(|c| ConditionKey::Surface { u: c.u, order: c.order }).collect(),
        v_domain: Some(VDomain { start: dom.start, end: dom.end, periodic: dom.periodic }),
        resolution: Some([p.resolution.0, p.resolution.1]),
        condition_error: ConditionError { samples: CHECK_SAMPLES, max_abs: 0.0, max_rel: 0.0, patch_size: 0.0 },
        warnings: Vec::new(),
        trim: p.trim.as_ref().map(trim_report),
        section_reference_distance: None,
        section_reference_distance_linear_s: None,
        section_reference_worst: None,
        blend: None,
        continuity: None,
        fill: None,
        dynamic: None,
        spectral: None,
        solid: None,
        mass_properties: None,
    };
    // the condition check, once, by kind
    let rep = if let Some(b) = &p.blend {
        blend_condition_report(b.blend.as_ref(), &p.conditions)
    } else if let Some(dy) = &p.dynamic {
        let (rep, section) = dynamic_report(p, dy);
        d.dynamic = Some(section);
        rep
    } else {
        check_conditions(p.surface.as_ref(), &p.conditions, 0.0, CHECK_SAMPLES)
    };
    d.condition_error =
        ConditionError { samples: CHECK_SAMPLES, max_abs: rep.max_abs, max_rel: rep.max_rel, patch_size: rep.size };
    if let Some(fam) = &p.sections {
        section_distances(p, fam, &mut d);
    }
    if let Some(b) = &p.blend {
        blend_sections(p, b, &mut d, rep.size);
    } else if p.dynamic.is_none() && p.trim.is_none() && !attached_ends(p).is_empty() {
        d.continuity = Some(attached_continuity(p, rep.size));
    }
    if let Some(f) = &p.fill {
        d.fill = Some(fill_report(f, &mut d.warnings));
    }
    if rep.max_rel.is_finite() && rep.max_rel > CONDITION_WARNING {
        d.warnings.push(format!(
            "the patch meets its conditions only to {:.2e} (relative): the data are not resolved on this domain \
             (data varying much faster than the modes, or an extreme domain); the result does not interpolate them",
            rep.max_rel
        ));
    }
    if let Some(dy) = &p.dynamic
        && dy.blend.operator().beta == 0.0
    {
        d.warnings.push(
            "beta = 0: the operator has no ∂⁴/∂u⁴ term, so it cannot take the four C1 conditions; they are met by \
             the trial functions (cubic Hermite part) and the sine terms only minimise the residual of a 2nd-order \
             operator in u: the closed form does not apply and the shape depends on the collocation grid and K"
                .into(),
        );
    }
    if let Some(sp) = &p.spectral {
        d.spectral = Some(spectral_report(p, sp, &mut d.warnings));
    }
    d
}

/// The patch's condition check alone (what `check` reports as `condition_error`, without
/// the rest of the diagnostics): every condition at [`CHECK_SAMPLES`] points, every frame
/// of a dynamic blend, a solid's four faces. NaN when anything evaluated is NaN.
pub fn condition_report(p: &ScenePatch) -> ConditionReport {
    if let Some(sd) = &p.solid {
        return solid_condition_report(sd);
    }
    if let Some(b) = &p.blend {
        return blend_condition_report(b.blend.as_ref(), &p.conditions);
    }
    if let Some(dy) = &p.dynamic {
        return dynamic_report(p, dy).0;
    }
    check_conditions(p.surface.as_ref(), &p.conditions, 0.0, CHECK_SAMPLES)
}

/// A solid's four face conditions on a 50 × 50 grid of each face.
fn solid_condition_report(sd: &SolidSetup) -> ConditionReport {
    let s = sd.blend.as_ref();
    let (mut worst, mut size) = (0.0f64, 0.0f64);
    for i in 0..50 {
        for j in 0..50 {
            let (u, v) = (i as f64 / 49.0, j as f64 / 49.0);
            for (w, k, f) in [(0.0, 0, 0), (0.0, 1, 1), (1.0, 0, 2), (1.0, 1, 3)] {
                let d = s.derivatives(u, v, w, 0, 0, 1)[k];
                let g = sd.faces[f].eval(&[u, v]);
                worst = max_nan(worst, (d - g).norm());
                size = max_nan(size, g.norm());
            }
        }
    }
    let rel = worst / max_nan(size, f64::MIN_POSITIVE);
    ConditionReport { max_abs: worst, max_rel: rel, size }
}

/// Diagnostics of a solid patch: the four boundary conditions on a 50 × 50 grid of
/// `(u, v)`, the solve, mass properties, the RMS PDE residual at interior points.
fn solid_diagnostics(p: &ScenePatch, sd: &SolidSetup) -> PatchReport {
    let s = sd.blend.as_ref();
    let check = solid_condition_report(sd);
    let mp = s.mass_properties(16);
    // interior points (boundary surfaces may have singular derivatives on the edges)
    let n = 512;
    let r2: f64 =
        pdeshape_core::solid::interior_points(n).into_iter().map(|[u, v, w]| s.residual(u, v, w).norm().powi(2)).sum();
    let rep = s.report();
    let mut warnings = Vec::new();
    if mp.folds() {
        warnings.push(format!(
            "the solid folds: det J ranges over [{:.3e}, {:.3e}]; raise lmn or change the boundary surfaces",
            mp.min_jacobian, mp.max_jacobian
        ));
    }
    PatchReport {
        name: p.name.clone(),
        kind: p.kind,
        solver: p.solver.clone(),
        conditions: [(0, 0), (0, 1), (1, 0), (1, 1)].map(|(w, order)| ConditionKey::Solid { w, order }).to_vec(),
        v_domain: None,
        resolution: None,
        condition_error: ConditionError {
            samples: 2500,
            max_abs: check.max_abs,
            max_rel: check.max_rel,
            patch_size: check.size,
        },
        warnings,
        trim: None,
        section_reference_distance: None,
        section_reference_distance_linear_s: None,
        section_reference_worst: None,
        blend: None,
        continuity: None,
        fill: None,
        dynamic: None,
        spectral: None,
        solid: Some(SolidReport {
            terms: [rep.terms.0, rep.terms.1, rep.terms.2],
            condition_number: rep.condition_number,
            max_coefficient: rep.max_coefficient,
            rms_residual: (r2 / n as f64).sqrt(),
            cells: [sd.cells.0, sd.cells.1, sd.cells.2],
        }),
        mass_properties: Some(MassReport {
            volume: mp.volume,
            centroid: [mp.centroid.x, mp.centroid.y, mp.centroid.z],
            inertia: mp.inertia,
            min_jacobian: mp.min_jacobian,
            max_jacobian: mp.max_jacobian,
            folds: mp.folds(),
        }),
    }
}

/// A dynamic blend: every frame checked against the data at its own time; the worst
/// frame's check (a frame that fails, or a NaN, is the worst of all) and the section.
fn dynamic_report(p: &ScenePatch, dy: &DynamicSetup) -> (ConditionReport, DynamicReport) {
    let mut frames = Vec::new();
    let mut worst = ConditionReport { max_abs: 0.0, max_rel: 0.0, size: 0.0 };
    let mut report = None;
    for t in dy.frame_times() {
        let r = match dy.blend.frame(t) {
            Ok(f) => {
                let r = check_conditions(&f, &p.conditions, t, CHECK_SAMPLES);
                frames.push(FrameCheck::Checked { t, max_abs: r.max_abs, max_rel: r.max_rel });
                report.get_or_insert_with(|| f.report().clone());
                r
            }
            Err(e) => {
                frames.push(FrameCheck::Failed { t, error: e.to_string() });
                ConditionReport { max_abs: f64::NAN, max_rel: f64::NAN, size: f64::NAN }
            }
        };
        if r.max_rel.is_nan() || (!worst.max_rel.is_nan() && r.max_rel >= worst.max_rel) {
            worst = r;
        }
    }
    let op = dy.blend.operator();
    let r = report.unwrap_or_else(|| pdeshape_core::blend::DynamicReport {
        solver: "none",
        basis: vec![],
        exact_available: false,
        condition_number: f64::NAN,
    });
    let section = DynamicReport {
        operator: DynamicOperator { beta: op.beta, gamma: op.gamma, lambda: op.lambda, rho: op.rho, eta: op.eta },
        solver: r.solver.to_string(),
        exact_available: r.exact_available,
        basis: r.basis,
        condition_number: r.condition_number,
        time: [dy.times.0, dy.times.1],
        frames,
    };
    (worst, section)
}

/// The trim section: fold counts before and after repair, cell angles, the area ratio,
/// and how far the mesh boundary lies from the trim loop (parameter space).
fn trim_report(t: &TrimSetup) -> TrimReport {
    let g = &t.grid;
    let r = &g.report;
    let region = t.map.region();
    let k = t.scale;
    let boundary =
        (0..g.columns).map(|j| region.loop_distance([g.points[j][0] * k[0], g.points[j][1] * k[1]])).max_nan();
    TrimReport {
        curves: region.curves.iter().map(|c| c.0.clone()).collect(),
        bridges: region.bridges.len(),
        metric_scale: k,
        rings: r.rings,
        columns: r.columns,
        modes: r.modes,
        omega: r.omega,
        folds_before: r.folds_before,
        folds_after: r.folds_after,
        inside_before: r.inside_before,
        inside_after: r.inside_after,
        repair_sweeps: r.sweeps,
        untangle_moves: r.untangle_moves,
        min_angle_deg: r.min_angle,
        max_angle_deg: r.max_angle,
        area_ratio: r.area_ratio,
        cell_area_ratio: r.cell_area_ratio,
        boundary_error: boundary,
    }
}

/// How far the patch strays from the section family between its sections: at the
/// fractional section index and with `s` linear in `u`.
fn section_distances(p: &ScenePatch, fam: &SectionFamily, d: &mut PatchReport) {
    let dom = p.surface.v_domain();
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
                // NaN wins over numbers
                if dist.is_nan() || dist > worst {
                    (worst, at) = (dist, [u, v, s]);
                }
                if worst.is_nan() {
                    return (worst, at);
                }
            }
        }
        (worst, at)
    };
    let (worst, at) = distance(&|u| fam.s_at(u));
    d.section_reference_distance = Some(worst);
    d.section_reference_distance_linear_s = Some(distance(&|u| fam.s_linear(u)).0);
    d.section_reference_worst = Some(SectionWorst { u: at[0], v: at[1], s: at[2] });
}

/// Above this a fill's tear ratio ([`FillReport::tear_ratio_max`]) is a warning: a smooth
/// fill measures 1 plus a term of the grid spacing (at most 1.004 on the examples), a torn
/// one `|jump| / (h |∂X|)`, over 10 for a jump of 2 % of the loop's radius.
pub const TEAR_WARNING: f64 = 2.0;

/// A fill's section; warnings for corners where the neighbours themselves disagree.
fn fill_report(f: &pdeshape_core::fill::Fill, warnings: &mut Vec<String>) -> FillReport {
    let r = f.report();
    let e = f.edge_continuity(1000);
    for (k, w) in &r.split_edges {
        warnings.push(format!(
            "edge {k}: its neighbour has a crease (only C0) at w = {w}: the edge was split there and the crease made a corner (corners are numbered over the split edges)"
        ));
    }
    for k in &r.dropped_edges {
        warnings.push(format!(
            "edge {k} has no length and was dropped: the loop is filled by the other edges (corners are numbered over those)"
        ));
    }
    for (k, a) in r.corner_angles.iter().enumerate() {
        if a.is_nan() || *a > 1e-9 {
            warnings.push(format!(
                "corner {k}: the neighbours' tangent planes differ by {a:.2e} rad there, so no surface meets both G1 at that corner"
            ));
        }
    }
    for (k, g) in r.corner_curvature_gaps.iter().enumerate() {
        if g.is_nan() || *g > 1e-8 {
            warnings.push(format!(
                "corner {k}: the neighbours' normal curvatures across the corner differ by {g:.2e} (relative), so no surface meets both G2 there; G2 is given up within that corner's blend"
            ));
        }
    }
    let (tear, (tu, tv)) = f.tear(41, 4000);
    if tear.is_nan() || tear > TEAR_WARNING {
        warnings.push(format!(
            "the fill jumps near (u, v) = ({tu:.4}, {tv:.4}): a step between neighbouring points is {tear:.3e} × what its derivatives allow; the loop's data are not continuous there"
        ));
    }
    FillReport {
        tear_ratio_max: tear,
        edges: r.corner_angles.len(),
        edge_samples: e.samples,
        g1_max_radians: e.g1,
        gap_max_relative: e.gap,
        g2_max_relative: e.g2,
        order: f.patch().order(),
        corner_normal_angles_radians: r.corner_angles.clone(),
        folds: f.folds(41, 400),
        pole: [r.pole.x, r.pole.y, r.pole.z],
        loop_radius: r.radius,
        pole_curvature: r.pole_curvature,
        corner_curvature_gaps_relative: r.pole_curvature.map(|_| r.corner_curvature_gaps.clone()),
    }
}

/// A spectral patch's section: modes, paths, residuals; a warning when the condition set's
/// Lebesgue constant is large.
fn spectral_report(
    p: &ScenePatch,
    sp: &pdeshape_core::spectral::SpectralPatch,
    warnings: &mut Vec<String>,
) -> SpectralReport {
    let dom = p.surface.v_domain();
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
    let leb = pdeshape_core::num::max_nan(r.lebesgue.0, r.lebesgue.1.unwrap_or(0.0));
    if leb > LEBESGUE_WARNING {
        warnings.push(format!(
            "the condition set amplifies its data by up to {leb:.3e} between conditions (Lebesgue constant): \
             many sections at equispaced u make high-order interpolation swing; place them at \
             Chebyshev-distributed u (sections.spacing = \"chebyshev\") or use fewer sections"
        ));
    }
    SpectralReport {
        order: r.order,
        modes: r.modes,
        modes_kept: r.kept,
        omega: r.omega,
        max_mode_condition_number: r.max_mode_condition,
        modes_solved_in_f64: r.methods.0,
        modes_solved_in_multiprecision: r.methods.1,
        mode_paths: r.mode_paths.clone(),
        mode_residuals_relative: r.mode_residuals.clone(),
        truncated_residual_relative: r.mode_residuals[..r.mode_residuals.len() - 1].iter().copied().max_nan(),
        lebesgue_mode0: r.lebesgue.0,
        lebesgue_mode1: r.lebesgue.1,
        rms_residual_truncated: (have_t && residuals).then(|| (t2 / n).sqrt()),
        rms_residual_remainder: residuals.then(|| (r2 / n).sqrt()),
        rms_residual_whole: (have_t && residuals).then(|| (w2 / n).sqrt()),
    }
}

/// The condition check of a blend: each component against the conditions its order takes
/// (a 2nd-order component takes positions only, and is not expected to meet the others).
pub fn blend_condition_report(b: &StaticBlend, conds: &[Condition]) -> ConditionReport {
    let positions: Vec<Condition> = conds.iter().filter(|c| c.order == 0).cloned().collect();
    let mut rep = check_conditions(b, &positions, 0.0, CHECK_SAMPLES);
    let dom = b.v_domain();
    for (t, op) in b.operators().iter().enumerate() {
        for c in conds.iter().filter(|c| c.order < op.half_order()) {
            for i in 0..CHECK_SAMPLES {
                let v = dom.at((i as f64 + 0.37) / CHECK_SAMPLES as f64);
                let e = (b.u_derivative(c.u, v, c.order)[t] - c.data.eval(&[v, 0.0])[t]).abs();
                rep.max_abs = max_nan(rep.max_abs, e);
            }
        }
    }
    rep.max_rel = rep.max_abs / max_nan(rep.size, f64::MIN_POSITIVE);
    rep
}

/// The ends `u = 0`, `u = 1` of a (non-blend) patch whose position there is a curve on
/// another surface (a trim curve of an earlier patch: a fin on a body), with that data.
pub fn attached_ends(p: &ScenePatch) -> Vec<(f64, FieldRef)> {
    if p.blend.is_some() {
        return Vec::new();
    }
    p.conditions
        .iter()
        .filter(|c| c.order == 0 && (c.u == 0.0 || c.u == 1.0) && c.data.host_normal(&[0.0, 0.0]).is_some())
        .map(|c| (c.u, c.data.clone()))
        .collect()
}

/// The seams of a patch attached to other patches' trim curves (or a fill's neighbours):
/// position gap and G1 angle against the host surface, the class and the worst places
/// (`start` for `u = 0`, `end` for `u = 1`).
fn attached_continuity(p: &ScenePatch, size: f64) -> ContinuityReport {
    let s = p.surface.as_ref();
    let ends = attached_ends(p);
    let seams: Vec<SeamGaps> = ends.iter().map(|(u, data)| attached_seam_gaps(s, *u, data, SEAM_SAMPLES)).collect();
    let mut c = ContinuityReport {
        class: ContinuityClass::of(&seams.iter().map(|g| g.max).collect::<Vec<_>>(), size).name(),
        samples: SEAM_SAMPLES,
        with: Some(if p.fill.is_some() { "neighbouring surface" } else { "trim curve" }),
        start: None,
        end: None,
        worst: WorstPlaces::default(),
    };
    // worst_places names the ends by their index: put each seam where its u says
    let mut by_end = [SeamGaps::default(), SeamGaps::default()];
    for ((u, _), g) in ends.iter().zip(&seams) {
        if *u == 0.0 {
            c.start = Some(g.max.into());
        } else {
            c.end = Some(g.max.into());
        }
        by_end[usize::from(*u == 1.0)] = *g;
    }
    c.worst = worst_places(s, &by_end);
    c
}

/// Per measure, the worst place over both trimlines (the larger end wins; NaN wins over
/// numbers; the start wins ties).
fn worst_places(b: &dyn Surface, seams: &[SeamGaps]) -> WorstPlaces {
    let pick = |m: fn(&Gaps) -> Option<f64>| {
        let mut best: Option<(f64, usize, f64)> = None;
        for (e, sg) in seams.iter().enumerate() {
            if let (Some(x), Some(v)) = (m(&sg.max), m(&sg.at)) {
                let better = match best {
                    None => true,
                    Some((b, ..)) => !b.is_nan() && (x.is_nan() || x > b),
                };
                if better {
                    best = Some((x, e, v));
                }
            }
        }
        best.map(|(value, e, v)| {
            let u = e as f64;
            let q = b.point(u, v);
            WorstPlace { end: ["start", "end"][e], u, v, point: [q.x, q.y, q.z], value }
        })
    };
    WorstPlaces { c0: pick(|g| g.c0), c1: pick(|g| g.c1), g1: pick(|g| g.g1), c2: pick(|g| g.c2), g2: pick(|g| g.g2) }
}

/// A blend's seams at both trimlines against the surfaces' data there; `size` (the patch's)
/// sets the class's thresholds.
fn blend_continuity(p: &ScenePatch, b: &StaticBlend, size: f64) -> ContinuityReport {
    let seams: Vec<SeamGaps> = [0.0, 1.0]
        .iter()
        .map(|&u| {
            let e = end_data(p, u);
            seam_gaps(b, u, [e[0].as_ref(), e[1].as_ref(), e[2].as_ref()], SEAM_SAMPLES)
        })
        .collect();
    let ends: Vec<Gaps> = seams.iter().map(|s| s.max).collect();
    ContinuityReport {
        class: ContinuityClass::of(&ends, size).name(),
        samples: SEAM_SAMPLES,
        with: None,
        start: Some(ends[0].into()),
        end: Some(ends[1].into()),
        worst: worst_places(b, &seams),
    }
}

/// The continuity section of a patch's report alone (what the blend strip's captions
/// print), without the rest of the report and its extra solves: `None` for patches
/// without seams.
pub fn continuity_report(p: &ScenePatch) -> Option<ContinuityReport> {
    if let Some(b) = &p.blend {
        let size = blend_condition_report(b.blend.as_ref(), &p.conditions).size;
        return Some(blend_continuity(p, b.blend.as_ref(), size));
    }
    if p.solid.is_some() || p.dynamic.is_some() || p.trim.is_some() || attached_ends(p).is_empty() {
        return None;
    }
    let size = check_conditions(p.surface.as_ref(), &p.conditions, 0.0, CHECK_SAMPLES).size;
    Some(attached_continuity(p, size))
}

/// A static blend's sections: the components' solves, the distance between the two
/// solvers' surfaces when both apply, the seams at both trimlines; warnings for operators
/// that are not elliptic.
fn blend_sections(p: &ScenePatch, setup: &BlendSetup, d: &mut PatchReport, size: f64) {
    let b = setup.blend.as_ref();
    let components = b
        .reports()
        .iter()
        .zip(["x", "y", "z"])
        .zip(b.operators())
        .map(|((r, axis), op)| ComponentReport {
            component: axis,
            order: r.order,
            coefficients: op.coefficients().to_vec(),
            elliptic: r.elliptic,
            solver: r.solver,
            exact_available: r.exact_available,
            basis: r.basis.clone(),
            condition_number: r.condition_number,
            collocation_rms_residual: r.collocation_rms,
            collocation: r.collocation.map(|(u_points, v_points, bubbles)| Collocation { u_points, v_points, bubbles }),
        })
        .collect();
    // When both solvers apply, how far apart their surfaces are.
    let both = b.reports().iter().all(|r| r.exact_available);
    let distance = both
        .then(|| {
            let ran_exact = b.reports().iter().all(|r| r.solver == "exact");
            let other = pdeshape_core::blend::BlendOptions {
                solver: if ran_exact { Solver::Collocation } else { Solver::Exact },
                ..setup.options.clone()
            };
            let q = StaticBlend::new(b.operators().clone(), &p.conditions, b.v_domain(), &other).ok()?;
            let dom = b.v_domain();
            let mut worst: f64 = 0.0;
            for i in 0..=50 {
                for j in 0..50 {
                    let (u, v) = (i as f64 / 50.0, dom.at((j as f64 + 0.5) / 50.0));
                    worst = max_nan(worst, (b.point(u, v) - q.point(u, v)).norm());
                }
            }
            Some(worst)
        })
        .flatten();
    d.blend = Some(BlendReport { components, exact_vs_collocation_max_distance: distance });
    d.continuity = Some(blend_continuity(p, b, size));
    for (r, axis) in b.reports().iter().zip(["x", "y", "z"]) {
        if !r.elliptic {
            d.warnings.push(format!(
                "component {axis}: the operator is not elliptic; the blend is solved per mode but is not well posed for all data"
            ));
        }
    }
}
