//! The `u = 0` edge of a fit to its own tolerances: gap, normal angle and normal curvature
//! across the edge (where a fitted face meets the faces it was built to meet).
//!
//! The fit ([`super::fit_on`]) determines the net's first three `u` rows from the patch's
//! `X`, `X_u` and `X_uu` at `u = 0` alone (at a clamped end only `N₀`, `N₀…N₁` and
//! `N₀…N₂` reach the value, first and second derivative), interpolated in `v` at the
//! Greville points of the `v` knots. So along the edge the spline's
//!
//! ```text
//! S = I[X],  S_v = I[X]',  S_vv = I[X]'',  S_u = I[X_u],  S_uv = I[X_u]',  S_uu = I[X_uu]
//! ```
//!
//! with `I` the one-dimensional interpolant on those `v` knots, independently of the knots
//! in `u`. The edge's accuracy is thus a property of the `v` knots alone, and is reached
//! here, before the surface fit, by refining the `v` spans where the interpolant of the
//! three rows misses a tolerance (cheap: one-dimensional, no surface samples). The surface
//! fit then starts from those knots (`FitOptions::v_start`); its own refinement only adds
//! knots.
//!
//! What is compared at every sample (`K` per span, at the middles of its `K` equal parts:
//! a span's ends may be C0 lines, where the patch's value depends on the side):
//!
//! - **gap** `|S − X|`;
//! - **angle** between the normals `S_u × S_v` and `X_u × X_v`;
//! - **normal curvature across the edge** (order-6 fills' G2): `II(t, t) / I(t, t)` in
//!   the direction `t` across the edge (`X_u` without its part along `X_v`), for both, the
//!   difference over `max(|κ|, 1 / scale)`.
//!
//! These are sampled values, not bounds: a deviation narrower than the sample spacing can
//! lie between samples. The written face is measured again against the faces themselves.

use super::basis::Knots;
use super::{FitError, interpolate, knots_with_breaks};
use crate::Vec3;
use crate::num::max_nan;
use crate::patch::Surface;

/// Tolerances for the fit's `u = 0` edge.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EdgeTolerance {
    /// Largest distance between the spline's edge and the patch's.
    pub gap: f64,
    /// Largest angle (radians) between their normals.
    pub angle: f64,
    /// Largest difference of their normal curvatures across the edge, relative to
    /// `max(|κ|, 1 / scale)`; `None`: not compared (G1 faces).
    pub curvature: Option<f64>,
    /// The length for the curvature's floor (the model's size).
    pub scale: f64,
}

/// The normal curvature `II(t̂, t̂) / I(t̂, t̂)` in the direction `t` (projected into the
/// tangent plane: `t̂ = a S_u + b S_v` solves the normal equations of `t ≈ a S_u + b S_v`),
/// and the unit normal `S_u × S_v / |…|`, from `[S_u, S_v, S_uu, S_uv, S_vv]`. `None` where
/// the tangents are parallel.
pub fn normal_curvature(su: Vec3, sv: Vec3, suu: Vec3, suv: Vec3, svv: Vec3, t: Vec3) -> Option<(f64, Vec3)> {
    let n = su.cross(sv).normalized()?;
    let (e, f, g) = (su.dot(su), su.dot(sv), sv.dot(sv));
    let det = e * g - f * f;
    let (tu, tv) = (t.dot(su), t.dot(sv));
    let a = (g * tu - f * tv) / det;
    let b = (e * tv - f * tu) / det;
    let second = suu * (a * a) + suv * (2.0 * a * b) + svv * (b * b);
    let first = (su * a + sv * b).dot(su * a + sv * b);
    Some((second.dot(n) / first, n))
}

/// What one sample of the edge missed by, each as a multiple of its tolerance (NaN where
/// a quantity is not finite).
fn misses(tol: &EdgeTolerance, s: [Vec3; 6], x: [Vec3; 6]) -> f64 {
    // [X, X_u, X_v, X_uu, X_uv, X_vv]
    let gap = (s[0] - x[0]).norm() / tol.gap;
    let along = x[2].normalized().unwrap_or(Vec3::ZERO);
    let across = x[1] - along * x[1].dot(along);
    let (Some((ks, ns)), Some((kx, nx))) = (
        normal_curvature(s[1], s[2], s[3], s[4], s[5], across),
        normal_curvature(x[1], x[2], x[3], x[4], x[5], across),
    ) else {
        return f64::NAN;
    };
    let angle = ns.cross(nx).norm().atan2(ns.dot(nx)) / tol.angle;
    let mut worst = max_nan(gap, angle);
    if let Some(c) = tol.curvature {
        let floor = max_nan(kx.abs(), 1.0 / tol.scale);
        worst = max_nan(worst, (ks - kx).abs() / floor / c);
    }
    worst
}

/// Samples per span at which the edge is compared.
const K: usize = 8;

/// The `v` interior breakpoints (C0 lines `c0` kept, of full multiplicity, and `Cᵏ` lines
/// `joins`, of multiplicity `p − k`) from which the fit of `s` of degree `p` on `[lo, hi]`
/// meets `tol` along its `u = 0` edge: a span that misses by a factor `m` is cut into
/// `⌈(1.2 m)^(1/p)⌉` equal pieces (at least two; the edge's angle error falls like `hᵖ`
/// with the span `h`, its gap like `hᵖ⁺¹`), until every sample meets it or the net would
/// exceed `max_points` in `v` (then the breakpoints reached; the final measure of the
/// written face reports the edge).
pub(super) fn edge_breakpoints(
    s: &dyn Surface,
    p: usize,
    (lo, hi): (f64, f64),
    start: Vec<f64>,
    (c0, joins): (&[f64], &[(f64, usize)]),
    tol: &EdgeTolerance,
    max_points: usize,
) -> Result<Vec<f64>, FitError> {
    let mut interior = start;
    loop {
        crate::cancel::checkpoint();
        let kv = knots_with_breaks(p, lo, hi, &interior, c0, joins);
        let miss = span_misses(s, &kv, tol)?;
        if miss.iter().all(|&m| m <= 1.0) {
            return Ok(interior);
        }
        let b = kv.breakpoints();
        let mut next = Vec::with_capacity(interior.len() * 2);
        for (i, w) in b.windows(2).enumerate() {
            if i > 0 {
                next.push(w[0]);
            }
            if miss[i] > 1.0 {
                let pieces = ((1.2 * miss[i]).powf(1.0 / p as f64).ceil() as usize).clamp(2, 16);
                next.extend((1..pieces).map(|k| w[0] + (w[1] - w[0]) * k as f64 / pieces as f64));
            }
        }
        let count = super::control_count(p, next.len(), c0, joins);
        if count > max_points {
            return Ok(interior);
        }
        interior = next;
    }
}

/// By how much each span of `kv` (between distinct breakpoints) misses `tol`: the largest
/// of its samples' [`misses`].
fn span_misses(s: &dyn Surface, kv: &Knots, tol: &EdgeTolerance) -> Result<Vec<f64>, FitError> {
    let gv = kv.greville();
    let data = s.grid2(&[0.0], &gv);
    // the three rows the fit interpolates at u = 0: X, X_u, X_uu
    let rhs: Vec<Vec<Vec3>> = data.iter().map(|d| vec![d[0], d[1], d[3]]).collect();
    if let Some(j) = rhs.iter().position(|r| r.iter().any(|p| !p.is_finite())) {
        return Err(FitError::NotFinite(0.0, gv[j]));
    }
    let rows: Vec<(f64, usize)> = gv.iter().map(|&v| (v, 0)).collect();
    let c = interpolate(kv, &rows, &rhs)?;
    let bk = kv.breakpoints();
    let mut vs = Vec::with_capacity((bk.len() - 1) * K);
    for w in bk.windows(2) {
        for a in 0..K {
            vs.push(w[0] + (w[1] - w[0]) * (a as f64 + 0.5) / K as f64);
        }
    }
    let exact = s.grid2(&[0.0], &vs);
    let q = kv.degree;
    let mut out = vec![0.0_f64; bk.len() - 1];
    for (k, (&v, x)) in vs.iter().zip(&exact).enumerate() {
        let span_index = k / K;
        let (sp, d) = kv.basis(v, 2);
        let mut r = [[Vec3::ZERO; 3]; 3]; // r[row][derivative in v]
        for (order, w) in d.iter().enumerate() {
            for (i, &wi) in w.iter().enumerate() {
                for (row, rr) in r.iter_mut().enumerate() {
                    rr[order] += c[sp - q + i][row] * wi;
                }
            }
        }
        let sj = [r[0][0], r[1][0], r[0][1], r[2][0], r[1][1], r[0][2]];
        let m = misses(tol, sj, *x);
        if m.is_nan() {
            return Err(FitError::NotFinite(0.0, v));
        }
        out[span_index] = max_nan(out[span_index], m);
    }
    Ok(out)
}
