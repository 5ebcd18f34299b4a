//! A scene as CAD geometry: every patch, and the drawn part of every primary surface,
//! fitted by a measured B-spline surface (`pdeshape_core::fit`) and written as STEP; the
//! seams between the fitted faces measured after the fit.

use crate::export::{StepFace, StepHole, write_atomic, write_step};
use crate::scene::Scene;
use pdeshape_core::Vec3;
use pdeshape_core::fit::{BSplineSurface, FitOptions, FitReport, fit_curve, fit_surface};
use pdeshape_core::num::max_nan;
use pdeshape_core::patch::{PrimarySurface, Surface};
use pdeshape_core::trim::TrimCurve;
use std::path::Path;
use std::sync::Arc;

/// One face: a patch or a primary surface's drawn part as a B-spline surface with its
/// measured maximum deviation.
pub struct CadFace {
    /// The patch's name, or `surface-NAME` for a primary surface.
    pub name: String,
    /// The fitted surface.
    pub surface: BSplineSurface,
    /// What the fit achieved (measured maximum deviation, control points).
    pub report: FitReport,
    /// A primary surface's drawn part (not a patch).
    pub primary: bool,
    /// Holes cut by trim curves: inner boundaries of the face.
    pub holes: Vec<Hole>,
    /// A boundary face of a solid: whether its normal `S_u × S_v` points out of the solid.
    pub outward: Option<bool>,
}

/// A trim curve as an inner boundary: its image on the fitted surface as a space curve.
pub struct Hole {
    /// The trim curve's name.
    pub name: String,
    /// `S(C(t))`, `t ∈ [0, 2π]`, fitted to the face's tolerance — or the boundary
    /// isocurve of the face standing on the hole ([`Hole::root_of`]).
    pub curve: pdeshape_core::fit::BSplineCurve3,
    /// Its measured deviation from the exact `S(C(t))`.
    pub deviation: f64,
    /// `C(t)` in the face's `(u, v)` as a planar spline (`z = 0`), the edge's pcurve.
    pub pcurve: pdeshape_core::fit::BSplineCurve3,
    /// The curve runs counter-clockwise in `(u, v)` (the face's inner loop runs it back).
    pub counter_clockwise: bool,
    /// The face (index) standing on the hole, whose boundary isocurve is the curve.
    pub root_of: Option<usize>,
}

/// Two fitted faces that meet along a boundary isocurve each (`u = 0` or `1` of both,
/// with the same `v`): the exported seam's continuity.
#[derive(Clone, Debug, PartialEq)]
pub struct Seam {
    /// The faces (indices into the fitted faces) and their boundary `u`.
    pub faces: [(usize, f64); 2],
    /// Largest distance between the two faces' boundary points at equal `v`.
    pub gap: f64,
    /// Largest angle (radians) between the two faces' normal lines there.
    pub angle: f64,
    /// Largest difference between the two faces' normal curvatures across the seam (in
    /// the direction of the tangent plane normal to the edge), in 1/length.
    pub curvature_gap: f64,
    /// Points compared.
    pub samples: usize,
}

/// How a scene becomes CAD faces.
#[derive(Clone, Debug, PartialEq)]
pub struct CadOptions {
    /// The measured maximum deviation of every face (absolute); `None`: `relative` ×
    /// each face's bounding-box diagonal.
    pub tolerance: Option<f64>,
    /// The tolerance relative to each face's bounding-box diagonal (default 1e-6).
    pub relative: f64,
    /// B-spline degree: 3 (faces meeting along an edge stay G1), or 5 (the second cross
    /// derivative is interpolated at the edges too, so curvature continuity survives).
    pub degree: usize,
    /// Dynamic blends (and the primary surfaces) at this time (clamped to each blend's
    /// range); `None`: the first time (primary surfaces at 0).
    pub time: Option<f64>,
}

impl Default for CadOptions {
    fn default() -> Self {
        CadOptions { tolerance: None, relative: 1e-6, degree: 3, time: None }
    }
}

/// Fits every patch of `sc` (a solid blend as the faces that bound it,
/// [`pdeshape_core::solid::boundary_faces`]), then the drawn part of every primary surface
/// (`s_range`), to the tolerance of `o` ([`CadOptions`]). Errors name the patch or surface.
pub fn fit_scene(sc: &Scene, o: &CadOptions) -> Result<Vec<CadFace>, String> {
    let (tolerance, relative, time) = (o.tolerance, o.relative, o.time);
    if o.degree != 3 && o.degree != 5 {
        return Err(format!("degree {}: the faces are of degree 3 or 5", o.degree));
    }
    for t in tolerance.into_iter().chain([relative]) {
        if !(t.is_finite() && t > 0.0) {
            return Err(format!("tolerance {t} is not a positive number"));
        }
    }
    // faces are named as the mesh exporters name them: `x` for a patch, `surface-x`, and
    // `x-u1`, `x-w0`, … for a solid's faces
    struct Job {
        label: String,
        name: String,
        surface: Arc<dyn Surface>,
        v_breaks: Vec<f64>,
        /// The patch whose surface this is (not a solid's face)
        patch: Option<usize>,
        /// A solid's face: (the patch, the solid's directions of the face's u and v,
        /// whether S_u × S_v points out)
        solid: Option<(usize, [usize; 2], bool)>,
    }
    let mut jobs: Vec<Job> = Vec::new();
    for (pi, p) in sc.patches.iter().enumerate() {
        if let Some(sd) = &p.solid {
            for f in pdeshape_core::solid::boundary_faces(&sd.blend) {
                let outward = f.outward_at(0.5, 0.5);
                jobs.push(Job {
                    label: format!("patch `{}`, face {}", p.name, f.label()),
                    name: format!("{}-{}", p.name, f.label()),
                    solid: Some((pi, f.dirs, outward)),
                    surface: Arc::new(f),
                    v_breaks: Vec::new(),
                    patch: None,
                });
            }
            continue;
        }
        let v_breaks = p.fill.as_ref().map(|f| f.corner_parameters()).unwrap_or_default();
        let surface: Arc<dyn Surface> = match (&p.dynamic, time) {
            (Some(d), Some(t)) => {
                let t = t.clamp(d.times.0, d.times.1);
                let f = d.blend.frame(t).map_err(|e| format!("patch `{}` at t = {t}: {e}", p.name))?;
                Arc::new(f)
            }
            _ => p.surface.clone(),
        };
        jobs.push(Job {
            label: format!("patch `{}`", p.name),
            name: p.name.clone(),
            surface,
            v_breaks,
            patch: Some(pi),
            solid: None,
        });
    }
    let n_patch_faces = jobs.len();
    for s in &sc.surfaces {
        let Some(range) = s.s_range else { continue };
        let ps = PrimarySurface::new(s.field.clone(), range, s.domain, time.unwrap_or(0.0));
        jobs.push(Job {
            label: format!("surface `{}`", s.name),
            name: format!("surface-{}", s.name),
            surface: Arc::new(ps),
            v_breaks: Vec::new(),
            patch: None,
            solid: None,
        });
    }
    let fit = |k: usize, u_start: Vec<f64>, v_start: Vec<f64>| -> Result<CadFace, String> {
        let j = &jobs[k];
        let fo = FitOptions {
            tolerance,
            relative,
            degrees: (o.degree, o.degree),
            v_breaks: j.v_breaks.clone(),
            u_start,
            v_start,
            ..Default::default()
        };
        let (surface, report) = fit_surface(j.surface.as_ref(), &fo).map_err(|e| format!("{}: {e}", j.label))?;
        if !report.max_deviation.is_finite() {
            return Err(format!("{}: the measured deviation {} is not finite", j.label, report.max_deviation));
        }
        crate::export::check_uncertainty(&j.name, &surface, report.tolerance)?;
        Ok(CadFace {
            name: j.name.clone(),
            surface,
            report,
            primary: k >= n_patch_faces,
            holes: Vec::new(),
            outward: j.solid.map(|s| s.2),
        })
    };
    let mut out = (0..jobs.len()).map(|k| fit(k, Vec::new(), Vec::new())).collect::<Result<Vec<_>, _>>()?;
    // a solid's faces meet along edges in every direction: each direction of the solid
    // gets the union of its faces' breakpoints, until they all agree (knots only grow)
    let interior = |b: &[f64]| b[1..b.len() - 1].to_vec();
    for pi in 0..sc.patches.len() {
        let members: Vec<(usize, [usize; 2])> =
            jobs.iter().enumerate().filter_map(|(k, j)| j.solid.filter(|s| s.0 == pi).map(|s| (k, s.1))).collect();
        for _ in 0..8 {
            let mut union: [Vec<f64>; 3] = Default::default();
            for &(k, dirs) in &members {
                for (d, b) in dirs.into_iter().zip([out[k].surface.u.breakpoints(), out[k].surface.v.breakpoints()]) {
                    union[d].extend(b);
                }
            }
            for u in &mut union {
                u.sort_by(f64::total_cmp);
                u.dedup();
            }
            let mut changed = false;
            for &(k, [du, dv]) in &members {
                if out[k].surface.u.breakpoints() != union[du] || out[k].surface.v.breakpoints() != union[dv] {
                    out[k] = fit(k, interior(&union[du]), interior(&union[dv]))?;
                    changed = true;
                }
            }
            if !changed {
                break;
            }
        }
    }
    // faces that meet along an edge are refitted from the union of their v breakpoints
    // until they share them (knots only grow, so this ends): their common edge is then
    // one curve and, with the cross derivatives interpolated at the ends, one tangent plane
    let mut group = pdeshape_core::classes::Classes::new(out.len());
    for s in seams(&out, 9) {
        // a solid's faces have their knots already
        if s.faces.iter().any(|f| jobs[f.0].solid.is_some()) {
            continue;
        }
        group.join(s.faces[0].0, s.faces[1].0);
    }
    let breaks = |f: &CadFace| f.surface.v.breakpoints();
    for r in 0..out.len() {
        let mut members: Vec<usize> = (0..out.len()).filter(|&k| group.of(k) == r).collect();
        if members.len() < 2 {
            continue;
        }
        // the face that needed the most v knots leads; the others start from the knots so
        // far, and whoever adds some makes the others refit, until all agree
        members.sort_by_key(|&k| std::cmp::Reverse(out[k].surface.v.count()));
        let mut union = breaks(&out[members[0]]);
        for _ in 0..8 {
            let mut changed = false;
            for &k in &members {
                if breaks(&out[k]) != union {
                    out[k] = fit(k, Vec::new(), interior(&union))?;
                    let mut u: Vec<f64> = union.iter().copied().chain(breaks(&out[k])).collect();
                    u.sort_by(f64::total_cmp);
                    u.dedup();
                    union = u;
                    changed = true;
                }
            }
            if !changed {
                break;
            }
        }
    }
    // trim curves: their images on the final surfaces
    for (pi, p) in sc.patches.iter().enumerate() {
        let Some(t) = &p.trim else { continue };
        let region = t.map.region();
        let Some(k) = jobs.iter().position(|j| j.patch == Some(pi)) else { continue };
        let f = &mut out[k];
        for (i, (name, c)) in t.curves.iter().enumerate() {
            let corners = match c {
                TrimCurve::Spline(b) if b.degree() == 1 => c.knots(),
                _ => Vec::new(),
            };
            let surface = &f.surface;
            let image = |t: f64| {
                let [u, v] = c.point(t);
                surface.point(u, v)
            };
            let tau = std::f64::consts::TAU;
            let (curve, deviation) = fit_curve(&image, 0.0, tau, &corners, f.report.tolerance, 4000)
                .map_err(|e| format!("patch `{}`, trim curve `{name}`: {e}", p.name))?;
            // the pcurve: C(t) itself, a planar spline in (u, v), to the face's tolerance
            // divided by the face's largest |S_u| + |S_v| along the curve (so that its image
            // stays within about the tolerance)
            let stretch = (0..512)
                .map(|k| {
                    let [u, v] = c.point(tau * k as f64 / 512.0);
                    let d = surface.derivatives(u, v, 1, 1);
                    d[2].norm() + d[1].norm()
                })
                .fold(0.0, max_nan);
            let in_domain = |t: f64| {
                let [u, v] = c.point(t);
                Vec3::new(u, v, 0.0)
            };
            let (pcurve, _) = fit_curve(&in_domain, 0.0, tau, &corners, f.report.tolerance / stretch.max(1e-300), 4000)
                .map_err(|e| format!("patch `{}`, trim curve `{name}` in (u, v): {e}", p.name))?;
            let counter_clockwise = region.orientation.get(i).is_none_or(|&o| o > 0.0);
            f.holes.push(Hole { name: name.clone(), curve, pcurve, deviation, counter_clockwise, root_of: None });
        }
    }
    share_roots(&mut out);
    Ok(out)
}

/// A patch that stands on a hole (its `u = 0` or `1` condition is the trim curve carried
/// onto the trimmed patch: the dolphin's fins) ends in the hole's curve. Where a face's
/// boundary isocurve runs along a hole's curve at the same parameter (`v = t`, within the
/// two tolerances at 17 probes), the hole takes that isocurve — control points and knots —
/// as its curve, so that the STEP writer writes one edge for both and they are one shell.
/// The isocurve lies within the standing face's measured deviation of the exact curve, and
/// so within the sum of both tolerances of the trimmed face.
fn share_roots(out: &mut [CadFace]) {
    for b in 0..out.len() {
        for h in 0..out[b].holes.len() {
            let hole = &out[b].holes[h].curve;
            let (t0, t1) = (hole.knots.breakpoints()[0], *hole.knots.breakpoints().last().expect("knots"));
            let found = (0..out.len()).filter(|&f| f != b && out[f].surface.periodic_v).find_map(|f| {
                let s = &out[f].surface;
                let vb = s.v.breakpoints();
                if (vb[0], vb[vb.len() - 1]) != (t0, t1) {
                    return None;
                }
                // the hole curve lies within the trimmed face's tolerance of its fitted surface,
                // which lies within it of the exact one
                let tol = out[f].report.tolerance + 2.0 * out[b].report.tolerance;
                [0.0, 1.0].into_iter().find_map(|u| {
                    let on = (0..17).all(|k| {
                        let t = t0 + (t1 - t0) * (k as f64 + 0.5) / 17.0;
                        (s.point(u, t) - hole.point(t)).norm() <= tol
                    });
                    on.then_some((f, u))
                })
            });
            if let Some((f, u)) = found {
                let s = &out[f].surface;
                let curve = pdeshape_core::fit::BSplineCurve3 { knots: s.v.clone(), control: s.u_edge(u == 1.0) };
                let deviation = out[f].report.max_deviation;
                let hole = &mut out[b].holes[h];
                (hole.curve, hole.deviation, hole.root_of) = (curve, deviation, Some(f));
            }
        }
    }
}

/// The unit normal `S_u × S_v` of a fitted face, or NaN where it degenerates.
///
/// The normal is `None` at a pole — where the isocurve `u = const` is one point (`|S_v|` at
/// most 1e-12 of `|S_u|`), so no normal is defined and the seam's angle leaves the point
/// out. A normal that vanishes or is not finite anywhere else is NaN, and the seam's
/// angle becomes NaN with it.
fn normal(b: &BSplineSurface, u: f64, v: f64) -> (Vec3, Option<Vec3>) {
    let d = b.derivatives(u, v, 1, 1);
    if d[1].max_abs() <= 1e-12 * d[2].max_abs() {
        return (d[0], None);
    }
    let n = d[2].cross(d[1]);
    let len = n.norm();
    (d[0], Some(if len > 0.0 { n * (1.0 / len) } else { Vec3::new(f64::NAN, f64::NAN, f64::NAN) }))
}

/// The normal curvature of a fitted face at `(u, v)` in the tangent direction normal to
/// the isocurve `u = const` (`t ∝ n × S_v`), with the normal `n` given (so that two faces'
/// curvatures have the same sign convention): `κ = II(t, t)` for the unit `t = a S_u + b S_v`.
fn cross_curvature(b: &BSplineSurface, u: f64, v: f64, n: Vec3) -> f64 {
    // index i (dv + 1) + j of ∂^{i+j}/∂u^i∂v^j
    let d = b.derivatives(u, v, 2, 2);
    let (su, sv, suu, suv, svv) = (d[3], d[1], d[6], d[4], d[2]);
    let t = n.cross(sv);
    let t = t * (1.0 / t.norm());
    // t = a S_u + b S_v: the 2 × 2 Gram system
    let (e, f, g) = (su.dot(su), su.dot(sv), sv.dot(sv));
    let (p, q) = (t.dot(su), t.dot(sv));
    let det = e * g - f * f;
    let (a, c) = ((p * g - q * f) / det, (e * q - f * p) / det);
    a * a * suu.dot(n) + 2.0 * a * c * suv.dot(n) + c * c * svv.dot(n)
}

/// The seams between fitted faces: boundary isocurves `u = 0 | 1` of two faces that lie
/// within `10 ×` the larger tolerance of each other at 9 probe values of `v` (same `v`
/// domain). Each is then measured at `n` values of `v` (pole points, where a normal is
/// undefined, are left out of the angle).
pub fn seams(faces: &[CadFace], n: usize) -> Vec<Seam> {
    let mut out = Vec::new();
    for a in 0..faces.len() {
        for b in a + 1..faces.len() {
            let (fa, fb) = (&faces[a].surface, &faces[b].surface);
            let (da, db) = (fa.v.breakpoints(), fb.v.breakpoints());
            let (v0, v1) = (da[0], da[da.len() - 1]);
            if v0 != db[0] || v1 != db[db.len() - 1] {
                continue;
            }
            let tol = 10.0 * faces[a].report.tolerance.max(faces[b].report.tolerance);
            for ua in [0.0, 1.0] {
                for ub in [0.0, 1.0] {
                    let probe = (0..9).all(|k| {
                        let v = v0 + (v1 - v0) * (k as f64 + 0.5) / 9.0;
                        (fa.point(ua, v) - fb.point(ub, v)).norm() <= tol
                    });
                    if !probe {
                        continue;
                    }
                    let (mut gap, mut angle, mut curvature_gap) = (0.0_f64, 0.0_f64, 0.0_f64);
                    for k in 0..n {
                        let v = v0 + (v1 - v0) * k as f64 / (n - 1).max(1) as f64;
                        let ((pa, na), (pb, nb)) = (normal(fa, ua, v), normal(fb, ub, v));
                        gap = max_nan(gap, (pa - pb).norm());
                        if let (Some(na), Some(nb)) = (na, nb) {
                            // normal lines: the faces may be oriented either way
                            angle = max_nan(angle, na.cross(nb).norm().min(1.0).asin());
                            let (ka, kb) = (cross_curvature(fa, ua, v, na), cross_curvature(fb, ub, v, na));
                            curvature_gap = max_nan(curvature_gap, (ka - kb).abs());
                        }
                    }
                    out.push(Seam { faces: [(a, ua), (b, ub)], gap, angle, curvature_gap, samples: n });
                }
            }
        }
    }
    out
}

/// The seams `check` and `build` report: [`seams`] at 200 points, without a solid's edges
/// (its faces meet at an angle by construction) and without those between alternative
/// patches that join the same surfaces (both patches, the same boundary).
pub fn reported_seams(fitted: &[CadFace]) -> Vec<Seam> {
    seams(fitted, 200)
        .into_iter()
        .filter(|s| {
            let [(a, ua), (b, ub)] = s.faces;
            let solid = fitted[a].outward.is_some() && fitted[b].outward.is_some();
            !solid && (fitted[a].primary || fitted[b].primary || ua != ub)
        })
        .collect()
}

/// The CAD fit of a scene as `check --json --cad` reports it.
#[derive(Clone, Debug, serde::Serialize)]
pub struct CadReport {
    /// The fitted faces.
    pub faces: Vec<CadFaceReport>,
    /// The seams between them ([`reported_seams`]).
    pub seams: Vec<CadSeamReport>,
}

/// One fitted face.
#[derive(Clone, Debug, serde::Serialize)]
pub struct CadFaceReport {
    /// The patch's name, or `surface-NAME`.
    pub name: String,
    /// A primary surface's drawn part.
    pub primary: bool,
    /// Control points `[nu, nv]`.
    pub control_points: [usize; 2],
    /// The tolerance the fit was held to.
    pub tolerance: f64,
    /// The measured maximum deviation.
    pub measured_deviation: f64,
    /// The face's holes.
    pub holes: Vec<CadHoleReport>,
}

/// One hole of a fitted face.
#[derive(Clone, Debug, serde::Serialize)]
pub struct CadHoleReport {
    /// The trim curve's name.
    pub name: String,
    /// Control points of its space curve.
    pub control_points: usize,
    /// Its measured deviation from the exact curve on the face.
    pub measured_deviation: f64,
}

/// One seam between fitted faces.
#[derive(Clone, Debug, serde::Serialize)]
pub struct CadSeamReport {
    /// The two faces' names.
    pub faces: [String; 2],
    /// Their boundary `u`.
    pub u: [f64; 2],
    /// Largest gap.
    pub gap: f64,
    /// Largest normal angle (radians).
    #[serde(rename = "normal_angle_radians")]
    pub angle: f64,
    /// Largest cross-curvature gap.
    pub curvature_gap: f64,
    /// Points compared.
    pub samples: usize,
}

impl CadReport {
    /// The report of fitted faces.
    pub fn of(fitted: &[CadFace]) -> CadReport {
        let faces = fitted
            .iter()
            .map(|f| CadFaceReport {
                name: f.name.clone(),
                primary: f.primary,
                control_points: [f.report.points.0, f.report.points.1],
                tolerance: f.report.tolerance,
                measured_deviation: f.report.max_deviation,
                holes: f
                    .holes
                    .iter()
                    .map(|h| CadHoleReport {
                        name: h.name.clone(),
                        control_points: h.curve.control.len(),
                        measured_deviation: h.deviation,
                    })
                    .collect(),
            })
            .collect();
        let seams = reported_seams(fitted)
            .iter()
            .map(|s| {
                let [(a, ua), (b, ub)] = s.faces;
                CadSeamReport {
                    faces: [fitted[a].name.clone(), fitted[b].name.clone()],
                    u: [ua, ub],
                    gap: s.gap,
                    angle: s.angle,
                    curvature_gap: s.curvature_gap,
                    samples: s.samples,
                }
            })
            .collect();
        CadReport { faces, seams }
    }
}

/// `faces` as the bytes of one STEP product named after the scene (the editor's download).
pub fn step_bytes(sc: &Scene, faces: &[CadFace]) -> std::io::Result<Vec<u8>> {
    let mut out = Vec::new();
    write_step(&mut out, &sc.name, &step_faces(faces), uncertainty(faces))?;
    Ok(out)
}

fn step_faces(faces: &[CadFace]) -> Vec<StepFace<'_>> {
    faces
        .iter()
        .map(|p| StepFace {
            name: &p.name,
            surface: &p.surface,
            holes: p
                .holes
                .iter()
                .map(|h| StepHole { curve: &h.curve, pcurve: Some(&h.pcurve), counter_clockwise: h.counter_clockwise })
                .collect(),
            outward: p.outward,
        })
        .collect()
}

fn uncertainty(faces: &[CadFace]) -> f64 {
    faces.iter().map(|p| p.report.tolerance).fold(f64::INFINITY, pdeshape_core::num::min_nan)
}

/// Writes `faces` to `path` as one STEP product named after the scene (atomically); the
/// file's uncertainty is the smallest tolerance.
pub fn write_scene_step(path: &Path, sc: &Scene, faces: &[CadFace]) -> std::io::Result<()> {
    let (fs, unc) = (step_faces(faces), uncertainty(faces));
    write_atomic(path, |w| write_step(w, &sc.name, &fs, unc))
}
