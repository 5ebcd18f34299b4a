//! A scene as CAD geometry: every patch fitted by a certified B-spline surface
//! (`pdeshape_core::fit`) and written as STEP.

use crate::export::{StepFace, write_atomic, write_step};
use crate::scene::{Scene, ScenePatch};
use pdeshape_core::fit::{BSplineSurface, FitOptions, FitReport, fit_surface};
use std::path::Path;

/// One patch as a B-spline surface with its certificate.
pub struct CadPatch {
    /// The patch's name.
    pub name: String,
    /// The fitted surface.
    pub surface: BSplineSurface,
    /// What the fit achieved (certified maximum deviation, control points).
    pub report: FitReport,
}

/// Why a patch cannot be exported (yet), or its fit failed.
fn exportable(p: &ScenePatch) -> Result<(), String> {
    if p.trim.is_some() {
        return Err(format!(
            "patch `{}` is trimmed: trimmed faces (B-spline pcurves) are not written to STEP yet; leave the trim out to export the whole patch",
            p.name
        ));
    }
    if p.solid.is_some() {
        return Err(format!("patch `{}` is a solid blend: solids (closed shells) are not written to STEP yet", p.name));
    }
    Ok(())
}

/// Fits every patch of `sc` (dynamic blends at their first time) to `tolerance` (absolute;
/// `None`: 1e-6 × each patch's bounding-box diagonal). Errors name the patch.
pub fn fit_scene(sc: &Scene, tolerance: Option<f64>) -> Result<Vec<CadPatch>, String> {
    if let Some(t) = tolerance
        && !(t.is_finite() && t > 0.0)
    {
        return Err(format!("tolerance {t} is not a positive number"));
    }
    let mut out = Vec::with_capacity(sc.patches.len());
    for p in &sc.patches {
        exportable(p)?;
        let v_breaks = p.fill.as_ref().map(|f| f.corner_parameters()).unwrap_or_default();
        let o = FitOptions { tolerance, v_breaks, ..Default::default() };
        let (surface, report) = fit_surface(p.surface.as_ref(), &o).map_err(|e| format!("patch `{}`: {e}", p.name))?;
        out.push(CadPatch { name: p.name.clone(), surface, report });
    }
    Ok(out)
}

/// Writes `patches` to `path` as one STEP product named after the scene (atomically); the
/// file's uncertainty is the smallest tolerance.
pub fn write_scene_step(path: &Path, sc: &Scene, patches: &[CadPatch]) -> std::io::Result<()> {
    let faces: Vec<StepFace> = patches.iter().map(|p| StepFace { name: &p.name, surface: &p.surface }).collect();
    let unc = patches.iter().map(|p| p.report.tolerance).fold(f64::INFINITY, f64::min);
    write_atomic(path, |w| write_step(w, &sc.name, &faces, unc))
}
