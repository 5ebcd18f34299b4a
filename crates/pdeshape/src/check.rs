//! `pdeshape check`: the report of a scene, as text or JSON, and with `--cad` the figures of
//! its STEP export; fails when a patch's condition check is not finite.

use anyhow::{Result, anyhow, bail};
use pdeshape_io::model;
use pdeshape_io::model::report::{GapsReport, PatchReport, SceneReport};
use pdeshape_io::scene::Scene;

/// Runs `check` on a loaded scene.
pub fn command(sc: &Scene, json: bool, cad: bool, degree: Option<usize>) -> Result<()> {
    let mut d = model::scene_diagnostics(sc);
    let o = pdeshape_io::cad::CadOptions { degree: degree.unwrap_or(3), ..Default::default() };
    let fitted = if cad { Some(pdeshape_io::cad::fit_scene(sc, &o).map_err(|e| anyhow!(e))?) } else { None };
    d.cad = fitted.as_deref().map(pdeshape_io::cad::CadReport::of);
    // a report with a NaN or inf is an error, not a `null` among the figures
    check_finite_report(&d)?;
    if json {
        outln!("{}", serde_json::to_string_pretty(&d)?);
    } else {
        print_check(sc, &d)?;
        if let Some(f) = &fitted {
            outln!("  CAD (STEP) faces:");
            for line in cad_lines(f) {
                outln!("    {line}");
            }
        }
    }
    Ok(())
}

/// The continuity line of a patch's report: the gaps at both trimlines, the class and
/// where the G1 angle is worst.
pub fn continuity_line(p: &PatchReport) -> Option<String> {
    let c = p.continuity.as_ref()?;
    let f = |x: Option<f64>| x.map(|v| format!("{v:.1e}")).unwrap_or_else(|| "-".into());
    let end =
        |e: &GapsReport| format!("C0 {} C1 {} G1 {} rad C2 {} G2 {}", f(e.c0), f(e.c1), f(e.g1), f(e.c2), f(e.g2));
    let mut line = format!("continuity {}:", c.class);
    if let Some(with) = c.with {
        line.push_str(&format!(" (with a {with})"));
    }
    for (e, u) in [(&c.start, 0), (&c.end, 1)] {
        if let Some(e) = e {
            line.push_str(&format!(" u={u} [{}] ", end(e)));
        }
    }
    let mut line = line.trim_end().to_string();
    if let Some(w) = &c.worst.g1 {
        line.push_str(&format!("; worst G1 angle {} rad at (u, v) = ({}, {:.4})", f(Some(w.value)), w.u, w.v));
    }
    Some(line)
}

/// Refuses a scene whose own condition check is not finite (an overflowing domain, data of
/// 1e300): its meshes would hold finite but meaningless numbers.
///
/// Every other figure of the report must be finite too (a fill whose corner blend
/// underflows, a pole at 1e300): the error names the patch and the figure's key path as
/// `check --json` spells it.
pub fn check_finite_report(d: &SceneReport) -> Result<()> {
    if let Some(p) = d.first_not_finite() {
        bail!(not_finite(&p.name));
    }
    for p in &d.patches {
        if let Some(path) = model::first_non_finite(p) {
            bail!(
                "patch `{}`: its report's `{path}` is not finite (the values overflow or are undefined): the result is not usable; check the scene's parameters and the data's magnitude",
                p.name
            );
        }
    }
    if let Some(path) = d.cad.as_ref().and_then(model::first_non_finite) {
        bail!("the CAD fit's `cad.{path}` is not finite: the STEP faces are not usable");
    }
    Ok(())
}

pub fn not_finite(patch: &str) -> String {
    format!(
        "patch `{patch}`: its condition check is not finite (the values overflow or are undefined): \
         the result is not usable; check the domain and the data's magnitude"
    )
}

/// The text report of `check`.
fn print_check(sc: &Scene, d: &SceneReport) -> Result<()> {
    outln!("scene {}{}", sc.name, sc.title.as_ref().map(|t| format!(": {t}")).unwrap_or_default());
    for p in &d.patches {
        outln!(
            "  patch {:<16} kind {:<10} solver {:<22} conditions {:>2}  max condition error {:.2e} abs, {:.2e} rel",
            p.name,
            p.kind.name(),
            p.solver,
            p.conditions.len(),
            p.condition_error.max_abs,
            p.condition_error.max_rel,
        );
        if let Some(sp) = &p.spectral {
            outln!(
                "      order {}, M = {}{}, ω = {}, max mode condition {:.2e} ({} modes f64, {} multiprecision), Lebesgue {:.3}, truncated-part residual {:.1e} (relative)",
                sp.order,
                sp.modes,
                if sp.modes_kept < sp.modes {
                    format!(
                        " (data of degree ≤ {}: modes above it and the remainder are zero, not solved)",
                        sp.modes_kept
                    )
                } else {
                    String::new()
                },
                json_text(&sp.omega),
                sp.max_mode_condition_number,
                sp.modes_solved_in_f64,
                sp.modes_solved_in_multiprecision,
                sp.lebesgue_mode0,
                sp.truncated_residual_relative,
            );
        }
        if let Some(line) = continuity_line(p) {
            outln!("      {line}");
        }
        if let Some(f) = &p.fill {
            outln!(
                "      fill (order {}): {} edges, {} points: G1 angle ≤ {:.1e} rad, gap ≤ {:.1e}, curvature gap ≤ {:.1e} (relative); folds {}; pole {}",
                f.order,
                f.edges,
                f.edge_samples,
                f.g1_max_radians,
                f.gap_max_relative,
                f.g2_max_relative,
                f.folds,
                json_text(&f.pole),
            );
        }
        if let (Some(so), Some(mp)) = (&p.solid, &p.mass_properties) {
            outln!(
                "      terms {}, condition {:.2e}, RMS residual {:.3e}; volume {:.6}, centroid {}, det J in [{:.3e}, {:.3e}]",
                json_text(&so.terms),
                so.condition_number,
                so.rms_residual,
                mp.volume,
                json_text(&mp.centroid),
                mp.min_jacobian,
                mp.max_jacobian,
            );
        }
        if let Some(b) = &p.blend {
            for c in &b.components {
                outln!(
                    "      {}: order {}, solver {}, {} basis functions, condition {:.2e}{}",
                    c.component,
                    c.order,
                    c.solver,
                    c.basis.len(),
                    c.condition_number,
                    c.collocation_rms_residual
                        .map(|r| format!(", collocation RMS residual {r:.2e}"))
                        .unwrap_or_default()
                );
            }
            if let Some(x) = b.exact_vs_collocation_max_distance {
                outln!("      max distance between the exact and the collocation solution: {x:.3e}");
            }
        }
        if let Some(x) = p.section_reference_distance {
            let lin = p.section_reference_distance_linear_s.unwrap_or(f64::NAN);
            outln!(
                "      max distance to the section family at the fractional section index: {x:.4} \
                     (s linear in u between sections: {lin:.4})"
            );
        }
        for w in &p.warnings {
            outln!("      warning: {w}");
        }
    }
    Ok(())
}

/// A small array as compact JSON (`[1.0,2.0,3.0]`), the way the text report has always
/// printed points and term counts.
fn json_text<T: serde::Serialize>(x: &T) -> String {
    serde_json::to_string(x).unwrap_or_default()
}

/// The figures of a scene's CAD fit, one line each: faces (net, measured deviation,
/// holes) and seams (gap and normal angle after the fit).
pub fn cad_lines(fitted: &[pdeshape_io::cad::CadFace]) -> Vec<String> {
    let mut out = Vec::new();
    for f in fitted {
        let r = &f.report;
        out.push(format!(
            "face {}: B-spline {} × {} control points, measured deviation {:.3e} ≤ {:.3e}",
            f.name, r.points.0, r.points.1, r.max_deviation, r.tolerance
        ));
        for h in &f.holes {
            out.push(format!(
                "  hole {}: B-spline curve, {} control points, measured deviation {:.3e} from the face",
                h.name,
                h.curve.control.len(),
                h.deviation
            ));
        }
    }
    for s in pdeshape_io::cad::reported_seams(fitted) {
        let [(a, ua), (b, ub)] = s.faces;
        out.push(format!(
            "seam {} u={ua} | {} u={ub}: gap {:.2e}, normal angle {:.2e} rad, cross curvature gap {:.2e} ({} points, after export)",
            fitted[a].name, fitted[b].name, s.gap, s.angle, s.curvature_gap, s.samples
        ));
    }
    out
}
