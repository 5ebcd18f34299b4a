//! The boundary correspondence of the Laplace map: both boundary curves parameterised by
//! `φ ∈ [0, 2π)` with corresponding starting points (SPEC §7).
//!
//! - The inner loop `C₁` (trim curves and bridges) is parameterised by the measure
//!   `dμ = |dθ| + w·2π ds/L` (`w` = [`ARC_WEIGHT`], or [`ARC_WEIGHT_BRIDGED`] for several curves, which also add
//!   [`TURN_WEIGHT_BRIDGED`] times the turning of the tangent), where `θ` is the polar angle about the trim centre `c`, `s`
//!   arc length and `L` the loop length, normalised to `2π`. For a trim that is
//!   star-shaped about `c` this is close to the polar angle, so the rays `φ = const` of the
//!   map run nearly radially; the arc-length part keeps radial stretches of non-star-shaped
//!   loops from collapsing to a point of the parameter. Points are evaluated exactly on the
//!   curves (the table only chooses the curve parameter).
//! - The outer border `C₂` (the domain rectangle, traversed once counter-clockwise) is
//!   parameterised by the polar angle about `c`, starting on the ray through `C₁(0)`, with
//!   the four corners moved to the nearest mesh column so the mesh keeps the corners.

use super::curve::Uv;
use super::region::{Rect, TrimRegion};
use std::f64::consts::TAU;

/// Weight `w` of arc length in the inner parameterisation of a single trim curve.
pub const ARC_WEIGHT: f64 = 0.15;

/// Weight of the tangent's turning angle in the inner parameterisation of loops joined by
/// bridges: puts columns where small curves bend sharply (the tips of slender holes).
pub const TURN_WEIGHT_BRIDGED: f64 = 1.0;

/// The same for loops joined by bridges: mostly arc length, so that each curve and each
/// bridge gets columns in proportion to its length.
pub const ARC_WEIGHT_BRIDGED: f64 = 4.0;

/// The inner loop `C₁(φ)`.
#[derive(Clone, Debug)]
pub struct InnerParam {
    /// `(μ, piece, fraction)` per sample; `μ` increasing from 0, the loop closes at 2π.
    table: Vec<(f64, usize, f64)>,
    /// Knots `(φ_k, μ_k)` of a piecewise-linear map from `φ` to `μ` that puts the loop's
    /// corners (ends of pieces, polygon vertices) on mesh columns; empty for `φ = μ`.
    snap: Vec<(f64, f64)>,
}

impl InnerParam {
    /// The parameterisation of the region's loop; with `columns`, its corners fall on the
    /// mesh columns `φ = 2πj/columns`.
    pub fn new(region: &TrimRegion, columns: Option<usize>) -> Self {
        let samples = region.samples();
        let c = region.center;
        let n = samples.len();
        let len: f64 = (0..n)
            .map(|k| {
                let (a, b) = (samples[k].2, samples[(k + 1) % n].2);
                (b[0] - a[0]).hypot(b[1] - a[1])
            })
            .sum();
        let angle = |p: Uv| (p[1] - c[1]).atan2(p[0] - c[0]);
        let w = if region.bridges.is_empty() { ARC_WEIGHT } else { ARC_WEIGHT_BRIDGED };
        let mut mu = 0.0;
        let mut table = Vec::with_capacity(n + 1);
        let turn_w = if region.bridges.is_empty() { 0.0 } else { TURN_WEIGHT_BRIDGED };
        let dir = |a: Uv, b: Uv| (b[1] - a[1]).atan2(b[0] - a[0]);
        for k in 0..=n {
            let (piece, s, p) = if k < n { samples[k] } else { (usize::MAX, 0.0, samples[0].2) };
            if k > 0 {
                let q = samples[k - 1].2;
                let mut d = angle(p) - angle(q);
                d -= TAU * (d / TAU).round();
                mu += d.abs() + w * TAU * (p[0] - q[0]).hypot(p[1] - q[1]) / len;
                // turning of the tangent inside a piece (not at the kinks between pieces)
                if turn_w > 0.0 && k >= 2 && k < n && samples[k - 2].0 == piece && samples[k - 1].0 == piece {
                    let mut t = dir(q, p) - dir(samples[k - 2].2, q);
                    t -= TAU * (t / TAU).round();
                    mu += turn_w * t.abs();
                }
            }
            table.push((mu, piece, s));
        }
        let total = mu;
        for r in &mut table {
            r.0 *= TAU / total;
        }
        let mut p = InnerParam { table, snap: vec![] };
        if let Some(n) = columns {
            p.snap = p.snap_corners(region, n);
        }
        p
    }

    /// Snapping knots for the corners of the loop: starts of pieces and, on polygons,
    /// vertices. Corners that would share a column with an earlier one are left alone.
    fn snap_corners(&self, region: &TrimRegion, n: usize) -> Vec<(f64, f64)> {
        let h = TAU / n as f64;
        let mut corners: Vec<f64> = Vec::new();
        for (k, r) in self.table.iter().enumerate() {
            let first_of_piece = k + 1 < self.table.len() && (k == 0 || self.table[k - 1].1 != r.1);
            if first_of_piece || (k + 1 < self.table.len() && region.is_corner(r.1, r.2)) {
                corners.push(r.0);
            }
        }
        let mut knots: Vec<(f64, f64)> = Vec::new();
        for mu in corners {
            let mut psi = (mu / h).round() * h;
            if let Some(l) = knots.last() {
                // keep corners on distinct columns (short bridges keep at least one edge)
                psi = psi.max(l.0 + h);
                if mu <= l.1 {
                    continue;
                }
            }
            if psi >= TAU - 0.5 * h && !knots.is_empty() {
                continue;
            }
            knots.push((psi, mu));
        }
        if knots.is_empty() || knots[0].0 != 0.0 {
            knots.insert(0, (0.0, 0.0));
        }
        knots.push((TAU, TAU));
        knots
    }

    /// The loop measure `μ` for the mesh parameter `φ`.
    fn mu(&self, phi: f64) -> f64 {
        let x = phi.rem_euclid(TAU);
        if self.snap.is_empty() {
            return x;
        }
        let k = self.snap.partition_point(|r| r.0 <= x).clamp(1, self.snap.len() - 1) - 1;
        let ((p0, m0), (p1, m1)) = (self.snap[k], self.snap[k + 1]);
        m0 + (x - p0) / (p1 - p0) * (m1 - m0)
    }

    /// `C₁(φ)`, exactly on the trim curves or bridges.
    pub fn point(&self, region: &TrimRegion, phi: f64) -> Uv {
        let x = self.mu(phi);
        let k = self.table.partition_point(|r| r.0 <= x).clamp(1, self.table.len() - 1) - 1;
        let (m0, piece, s0) = self.table[k];
        let (m1, p1, s1) = self.table[k + 1];
        let f = if m1 > m0 { (x - m0) / (m1 - m0) } else { 0.0 };
        let s_end = if p1 == piece { s1 } else { 1.0 };
        region.piece_point(piece, s0 + f * (s_end - s0))
    }
}

/// The outer border `C₂(φ)`.
#[derive(Clone, Debug)]
pub struct OuterParam {
    rect: Rect,
    center: Uv,
    theta0: f64,
    /// Knots `(φ_k, α_k)` of the piecewise-linear map from `φ` to the angle `α` past `θ₀`,
    /// one per corner, increasing, plus the first repeated at `+2π`.
    knots: Vec<(f64, f64)>,
    /// The corners in the order of `knots`.
    corners: Vec<Uv>,
}

impl OuterParam {
    /// The border seen from `center`, starting at angle `theta0`; with `columns`, the
    /// corners fall on the mesh columns `φ = 2πj/columns`.
    pub fn new(rect: Rect, center: Uv, theta0: f64, columns: Option<usize>) -> Self {
        let mut corners: Vec<(f64, Uv)> = rect
            .corners()
            .iter()
            .map(|q| (((q[1] - center[1]).atan2(q[0] - center[0]) - theta0).rem_euclid(TAU), *q))
            .collect();
        corners.sort_by(|a, b| a.0.total_cmp(&b.0));
        let alpha: Vec<f64> = corners.iter().map(|c| c.0).collect();
        let mut phi = alpha.clone();
        if let Some(n) = columns {
            let h = TAU / n as f64;
            let snapped: Vec<f64> = alpha.iter().map(|a| (a / h).round() * h).collect();
            let ok = snapped.windows(2).all(|w| w[1] > w[0]) && snapped[3] < TAU && snapped[0] >= 0.0;
            if ok {
                phi = snapped;
            }
        }
        let mut knots: Vec<(f64, f64)> = phi.iter().copied().zip(alpha.iter().copied()).collect();
        knots.push((phi[0] + TAU, alpha[0] + TAU));
        let corners = corners.iter().map(|c| c.1).collect();
        OuterParam { rect, center, theta0, knots, corners }
    }

    /// `C₂(φ)`, exactly on the rectangle.
    pub fn point(&self, phi: f64) -> Uv {
        let mut x = phi.rem_euclid(TAU);
        if x < self.knots[0].0 {
            x += TAU;
        }
        let k = self.knots.partition_point(|r| r.0 <= x).clamp(1, self.knots.len() - 1) - 1;
        let ((p0, a0), (p1, a1)) = (self.knots[k], self.knots[k + 1]);
        if (x - p0).abs() <= 1e-12 {
            return self.corners[k % 4];
        }
        let a = a0 + (x - p0) / (p1 - p0) * (a1 - a0);
        ray_to_rect(self.rect, self.center, self.theta0 + a)
    }
}

/// The point where the ray from `c` (inside `r`) at angle `theta` leaves `r`.
pub fn ray_to_rect(r: Rect, c: Uv, theta: f64) -> Uv {
    let d = [theta.cos(), theta.sin()];
    let mut best = (f64::INFINITY, 0, 0.0);
    for k in 0..2 {
        let bound = if d[k] > 0.0 {
            r.max[k]
        } else if d[k] < 0.0 {
            r.min[k]
        } else {
            continue;
        };
        let t = (bound - c[k]) / d[k];
        if t < best.0 {
            best = (t, k, bound);
        }
    }
    let (t, k, bound) = best;
    let mut p = [c[0] + t * d[0], c[1] + t * d[1]];
    p[k] = bound; // exactly on the border
    let o = 1 - k;
    p[o] = p[o].clamp(r.min[o], r.max[o]);
    p
}
