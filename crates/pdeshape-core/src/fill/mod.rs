//! N-sided hole filling with exact G1 to the neighbouring surfaces (scene `kind = "fill"`;
//! G2 by a 6th-order operator is still to come).
//!
//! A hole bounded by a loop of `N ≥ 3` edges, each an isoline `s = s₀` of a neighbouring
//! surface `S_k(s, w)` (from `w₀` to `w₁`), is filled by a periodic biharmonic patch
//! `X(u, v)` ([`SpectralPatch`], order 4) whose `u = 0` trimline is the loop — edge `k`
//! traversed by `v ∈ [2πk/N, 2π(k+1)/N]` — and which closes at `u = 1` in a pole.
//!
//! **G1 by construction.** At `u = 0` the conditions are `X = S_k(s₀, w(v))` and
//! `X_u = T(v)` with `T` in the neighbour's tangent plane (a combination of `S_s` and
//! `S_w`). The patch meets its conditions exactly (the remainder), so `X_v = λ S_w` and
//! `X_u = T` both lie in the neighbour's tangent plane and the normal `X_u × X_v` is the
//! neighbour's, for every `v`, to round-off — as long as `T` is not parallel to the edge.
//!
//! **Corners.** Along edge `k`, away from its ends, `T = c_k S_s` (`c_k` scales it to
//! `fullness × R`, `R` the loop's mean radius, and orients it into the hole). At a corner
//! the two edges' `T`s differ, and a jump of `X_u(0, ·)` would tear the patch for `u > 0`.
//! When the neighbours meet G1 at the corner (one tangent plane there), the mean `T_c` of
//! the two lies in that plane and is written in each edge's own frame,
//! `T_c = a S_s + b S_w` at the corner; within a blend length (`corner_blend` of the edge)
//! the edge's `T` is `α(v) S_s + β(v) S_w` with `(α, β)` moving from `(a, b)` to `(c_k, 0)`
//! by a C³ polynomial bump. Each edge's `T` stays in its own neighbour's tangent plane
//! everywhere (G1 exact along the whole edge) and equals `T_c` at the corner from both
//! sides (the patch stays continuous). Neighbours that do not meet G1 at a corner cannot
//! be matched there by any surface; the mismatch is reported ([`FillReport::corner_angles`]).
//!
//! **Pole.** `X(1, v) = P`, `X_u(1, v) = −ρ (cos v e₁ + sin v e₂)`: near the pole
//! `X ≈ P + (1 − u) ρ (cos v e₁ + sin v e₂)`, a disc in the plane ⊥ `n̄`, where `n̄` is the
//! loop's vector-area normal (so the loop and the ring wind the same way) and `e₁` points
//! to the loop's `v = 0` point. By default `P` lies above the loop's centroid by the height
//! of the parabolic profile that leaves the edges at their mean slope `tan φ` and is flat at
//! the centre, `H = R tan φ / 2` (times `height`), and `ρ = R` × the mean fullness.

mod data;

use crate::Vec3;
use crate::data::{Field, FieldRef, VecJet};
use crate::jet::{Jet, JetShape};
use crate::patch::{Condition, Surface, VDomain};
use crate::spectral::{SpectralError, SpectralOptions, SpectralPatch};
use data::{LoopData, Piece};
use std::f64::consts::TAU;
use std::sync::Arc;

/// One edge of the hole: the isoline `s = s0` of `surface` (slots `s, w, t`) from `w.0` to
/// `w.1`.
#[derive(Clone, Debug)]
pub struct FillEdge {
    /// The neighbouring surface `S(s, w, t)`.
    pub surface: FieldRef,
    /// The isoline.
    pub s0: f64,
    /// Its `w` range, in the loop's direction.
    pub w: (f64, f64),
    /// Length of the cross tangent relative to the loop's mean radius (> 0).
    pub fullness: f64,
}

/// Options of a fill.
#[derive(Clone, Debug)]
pub struct FillOptions {
    /// Half-width of each corner's blend as a fraction of an edge (0 < · ≤ ½).
    pub corner_blend: f64,
    /// The pole; default: above the centroid (see the module).
    pub pole: Option<Vec3>,
    /// Factor on the default pole height.
    pub height: f64,
    /// `ρ`, the length of `X_u` at the pole; default `R` × mean fullness.
    pub ring: Option<f64>,
    /// Time at which the neighbours are taken.
    pub t: f64,
    /// The PDE solve.
    pub spectral: SpectralOptions,
}

impl Default for FillOptions {
    fn default() -> Self {
        FillOptions {
            corner_blend: 0.25,
            pole: None,
            height: 1.0,
            ring: None,
            t: 0.0,
            spectral: SpectralOptions { a: 1.0, modes: 12, omega: None },
        }
    }
}

/// Why a fill cannot be built.
#[derive(Debug, thiserror::Error)]
pub enum FillError {
    /// The loop is not a closed chain of at least three transversal edges.
    #[error("{0}")]
    Loop(String),
    /// The PDE solve failed.
    #[error(transparent)]
    Spectral(#[from] SpectralError),
}

/// What the construction found.
#[derive(Clone, Debug, PartialEq)]
pub struct FillReport {
    /// At each corner (edge `k`'s end), the angle (radians) between the two neighbours'
    /// normals: 0 when they meet G1 there.
    pub corner_angles: Vec<f64>,
    /// The pole.
    pub pole: Vec3,
    /// The loop's centroid, mean radius and vector-area normal.
    pub centroid: Vec3,
    /// Mean distance of the loop from its centroid.
    pub radius: f64,
    /// Unit normal of the loop's vector area.
    pub normal: Vec3,
}

/// Continuity along the edges.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EdgeContinuity {
    /// Largest angle (radians) between the fill's and the neighbour's normal lines.
    pub g1: f64,
    /// Largest `|X(0, v) − S|` divided by the loop's mean radius.
    pub gap: f64,
    /// Points sampled.
    pub samples: usize,
}

/// A solved N-sided fill.
pub struct Fill {
    patch: Arc<SpectralPatch>,
    conditions: Vec<Condition>,
    position: Arc<LoopData>,
    report: FillReport,
    t: f64,
}

/// A constant point plus a ring, `centre + ρ (cos v e₁ + sin v e₂)`, exact in `v`.
#[derive(Clone, Debug)]
struct Ring {
    centre: Vec3,
    e1: Vec3,
    e2: Vec3,
    rho: f64,
}

impl Field for Ring {
    fn arity(&self) -> usize {
        2
    }
    fn jet(&self, at: &[f64], shape: JetShape) -> VecJet {
        let v = at[0];
        let mut fact = 1.0;
        let coeffs: Vec<Vec3> = (0..=shape.orders()[0])
            .map(|j| {
                if j > 0 {
                    fact *= j as f64;
                }
                let ph = v + j as f64 * std::f64::consts::FRAC_PI_2;
                let base = if j == 0 { self.centre } else { Vec3::ZERO };
                base + (self.e1 * ph.cos() + self.e2 * ph.sin()) * (self.rho / fact)
            })
            .collect();
        VecJet(std::array::from_fn(|c| {
            let cs: Vec<f64> = shape.multi_indices().map(|[j, l, _]| if l == 0 { coeffs[j][c] } else { 0.0 }).collect();
            Jet::from_coeffs(shape, cs)
        }))
    }
    fn is_constant_in(&self, slot: usize) -> bool {
        slot == 1
    }
}

fn point_frame(e: &FillEdge, w: f64, t: f64) -> (Vec3, Vec3, Vec3) {
    let j = e.surface.jet(&[e.s0, w, t], JetShape::new(&[1, 1, 0]));
    let g = |m: [usize; 3]| Vec3::new(j.0[0].coeff(m), j.0[1].coeff(m), j.0[2].coeff(m));
    (g([0, 0, 0]), g([1, 0, 0]), g([0, 1, 0]))
}

/// Least-squares `(a, b)` with `a x + b y ≈ z`.
fn in_frame(x: Vec3, y: Vec3, z: Vec3) -> (f64, f64) {
    let (xx, xy, yy) = (x.dot(x), x.dot(y), y.dot(y));
    let (xz, yz) = (x.dot(z), y.dot(z));
    let det = xx * yy - xy * xy;
    ((yy * xz - xy * yz) / det, (xx * yz - xy * xz) / det)
}

fn line_angle(a: Vec3, b: Vec3) -> f64 {
    a.cross(b).norm().atan2(a.dot(b).abs())
}

impl Fill {
    /// Fills the hole bounded by `edges` (in loop order).
    pub fn new(edges: &[FillEdge], o: &FillOptions) -> Result<Fill, FillError> {
        let n = edges.len();
        if n < 3 {
            return Err(FillError::Loop(format!("a hole needs at least 3 edges; got {n}")));
        }
        if !(o.corner_blend > 0.0 && o.corner_blend <= 0.5) {
            return Err(FillError::Loop(format!("corner_blend = {} must be in (0, 0.5]", o.corner_blend)));
        }
        let t = o.t;
        // the loop, sampled: closure, orientation, centroid, radius, vector area
        let per = 64;
        let mut pts = Vec::with_capacity(n * per);
        for e in edges {
            if !(e.fullness.is_finite() && e.fullness > 0.0) {
                return Err(FillError::Loop(format!("an edge's fullness must be positive, not {}", e.fullness)));
            }
            for i in 0..per {
                let w = e.w.0 + (e.w.1 - e.w.0) * i as f64 / per as f64;
                let mut p = [Vec3::ZERO];
                e.surface.derivatives_in(&[e.s0, w, t], 1, &mut p);
                pts.push(p[0]);
            }
        }
        let centroid = pts.iter().fold(Vec3::ZERO, |a, p| a + *p) * (1.0 / pts.len() as f64);
        let radius = pts.iter().map(|p| (*p - centroid).norm()).sum::<f64>() / pts.len() as f64;
        if !(radius.is_finite() && radius > 0.0) {
            return Err(FillError::Loop(format!("the loop has no extent (mean radius {radius})")));
        }
        for k in 0..n {
            let (e, f) = (&edges[k], &edges[(k + 1) % n]);
            let end = point_frame(e, e.w.1, t).0;
            let start = point_frame(f, f.w.0, t).0;
            let gap = (end - start).norm();
            // NaN gaps fail too
            if gap.is_nan() || gap > 1e-9 * radius {
                let reversed = (end - point_frame(f, f.w.1, t).0).norm() <= 1e-9 * radius;
                return Err(FillError::Loop(if reversed {
                    format!("edge {} runs the wrong way: it ends where edge {k} ends (swap its w range)", (k + 1) % n)
                } else {
                    format!("edges {k} and {} do not meet: gap {gap:.3e} (relative {:.3e})", (k + 1) % n, gap / radius)
                }));
            }
        }
        let area =
            (0..pts.len()).fold(Vec3::ZERO, |a, i| a + (pts[i] - centroid).cross(pts[(i + 1) % pts.len()] - centroid));
        let Some(normal) = area.normalized() else {
            return Err(FillError::Loop("the loop encloses no area".into()));
        };
        // cross tangents: c_k S_s, into the hole, of length fullness × R
        let mut cs = Vec::with_capacity(n);
        for (k, e) in edges.iter().enumerate() {
            let (p, ss, sw) = point_frame(e, 0.5 * (e.w.0 + e.w.1), t);
            let area = ss.cross(sw).norm();
            if area.is_nan() || area <= 1e-12 * ss.norm() * sw.norm() {
                return Err(FillError::Loop(format!("edge {k}: the neighbour's s-derivative is parallel to the edge")));
            }
            let sign = if ss.dot(centroid - p) >= 0.0 { 1.0 } else { -1.0 };
            cs.push(sign * e.fullness * radius / ss.norm());
        }
        // corners: the mean cross tangent in each edge's frame
        let mut starts = vec![(0.0, 0.0); n];
        let mut ends = vec![(0.0, 0.0); n];
        let mut corner_angles = Vec::with_capacity(n);
        for k in 0..n {
            let k1 = (k + 1) % n;
            let (_, ss0, sw0) = point_frame(&edges[k], edges[k].w.1, t);
            let (_, ss1, sw1) = point_frame(&edges[k1], edges[k1].w.0, t);
            let tc = (ss0 * cs[k] + ss1 * cs[k1]) * 0.5;
            ends[k] = in_frame(ss0, sw0, tc);
            starts[k1] = in_frame(ss1, sw1, tc);
            corner_angles.push(line_angle(ss0.cross(sw0), ss1.cross(sw1)));
        }
        let pieces: Vec<Piece> = edges
            .iter()
            .enumerate()
            .map(|(k, e)| Piece {
                surface: e.surface.clone(),
                s0: e.s0,
                w0: e.w.0,
                lambda: (e.w.1 - e.w.0) * n as f64 / TAU,
                c: cs[k],
                start: starts[k],
                end: ends[k],
            })
            .collect();
        let position = Arc::new(LoopData { pieces: pieces.clone(), order: 0, blend: o.corner_blend });
        let cross = Arc::new(LoopData { pieces, order: 1, blend: o.corner_blend });
        // the pole
        let x0 = position.eval(&[0.0, t]);
        let Some(e1) = ((x0 - centroid) - normal * (x0 - centroid).dot(normal)).normalized() else {
            return Err(FillError::Loop("the loop's first point is above its centroid".into()));
        };
        let e2 = normal.cross(e1);
        let mean_tan = (0..n)
            .map(|k| {
                let e = &edges[k];
                let (_, ss, _) = point_frame(e, 0.5 * (e.w.0 + e.w.1), t);
                let d = (ss * cs[k]).normalized().unwrap_or(Vec3::ZERO);
                let up = d.dot(normal);
                up / (1.0 - up * up).max(1e-12).sqrt()
            })
            .sum::<f64>()
            / n as f64;
        let pole = o.pole.unwrap_or(centroid + normal * (o.height * radius * mean_tan / 2.0));
        let rho = o.ring.unwrap_or(radius * edges.iter().map(|e| e.fullness).sum::<f64>() / n as f64);
        let fixed = |centre: Vec3, rho: f64| -> FieldRef { Arc::new(Ring { centre, e1, e2, rho }) };
        let conds = [
            Condition { u: 0.0, order: 0, data: position.clone() },
            Condition { u: 0.0, order: 1, data: cross },
            Condition { u: 1.0, order: 0, data: fixed(pole, 0.0) },
            Condition { u: 1.0, order: 1, data: fixed(Vec3::ZERO, -rho) },
        ];
        let patch = Arc::new(SpectralPatch::new(&conds, VDomain::PERIODIC, o.spectral)?);
        let report = FillReport { corner_angles, pole, centroid, radius, normal };
        Ok(Fill { patch, conditions: conds.to_vec(), position, report, t })
    }

    /// The fill surface.
    pub fn patch(&self) -> &Arc<SpectralPatch> {
        &self.patch
    }

    /// Its four conditions: loop and cross tangent at `u = 0`, pole and ring at `u = 1`.
    /// The loop's data answer [`Field::host_normal`] with the neighbour's normal.
    pub fn conditions(&self) -> &[Condition] {
        &self.conditions
    }

    /// What the construction found.
    pub fn report(&self) -> &FillReport {
        &self.report
    }

    /// G1 angle and position gap against the neighbours at `per_edge` points of every edge
    /// (its start corner included), NaN-propagating.
    pub fn edge_continuity(&self, per_edge: usize) -> EdgeContinuity {
        let n = self.position.pieces.len();
        let mut out = EdgeContinuity::default();
        for k in 0..n * per_edge {
            let v = TAU * k as f64 / (n * per_edge) as f64;
            let d = self.patch.derivatives(0.0, v, 1, 1);
            let (p, ss, sw) = self.position.frame(v, self.t);
            out.g1 = crate::num::max_nan(out.g1, line_angle(d[2].cross(d[1]), ss.cross(sw)));
            out.gap = crate::num::max_nan(out.gap, (d[0] - p).norm() / self.report.radius);
            out.samples += 1;
        }
        out
    }

    /// Folds: grid points `(u, v)`, `u < 1`, where `X_u × X_v` vanishes or turns against
    /// the loop's normal orientation, on an `nu × nv` grid.
    pub fn folds(&self, nu: usize, nv: usize) -> usize {
        let us: Vec<f64> = (0..nu).map(|i| 0.98 * i as f64 / (nu - 1) as f64).collect();
        let vs: Vec<f64> = (0..nv).map(|j| TAU * (j as f64 + 0.5) / nv as f64).collect();
        let g = self.patch.grid(&us, &vs);
        let signs: Vec<f64> = g.iter().map(|d| d[1].cross(d[2]).dot(self.report.normal)).collect();
        let pos = signs.iter().filter(|s| **s > 0.0).count();
        let majority = if 2 * pos >= signs.len() { 1.0 } else { -1.0 };
        // zero or NaN counts as a fold
        signs.iter().filter(|s| (**s * majority).is_nan() || **s * majority <= 0.0).count()
    }
}

#[cfg(test)]
mod tests;
