//! N-sided hole filling with exact G1 (order 4) or G2 (order 6) to the neighbouring
//! surfaces (scene `kind = "fill"`).
//!
//! A hole bounded by a loop of `N ≥ 3` edges, each an isoline `s = s₀` of a neighbouring
//! surface `S_k(s, w)` (from `w₀` to `w₁`), is filled by a periodic PDE patch `X(u, v)`
//! ([`SpectralPatch`], order 4 or 6) whose `u = 0` trimline is the loop — edge `k`
//! traversed by `v ∈ [2πk/N, 2π(k+1)/N]` — and which closes at `u = 1` in a pole.
//!
//! **G1 by construction.** At `u = 0` the conditions are `X = S_k(s₀, w(v))` and
//! `X_u = T(v)` with `T` in the neighbour's tangent plane (a combination of `S_s` and
//! `S_w`). The patch meets its conditions exactly (the remainder), so `X_v = λ S_w` and
//! `X_u = T` both lie in the neighbour's tangent plane and the normal `X_u × X_v` is the
//! neighbour's, for every `v`, to round-off — as long as `T` is not parallel to the edge.
//!
//! **G2 by construction (order 6).** With `T = α S_s + β S_w`, the third condition is
//! `X_uu = Q = α² S_ss + 2αβ S_sw + β² S_ww`, the second derivative of the neighbour's curve
//! `u ↦ S(s₀ + αu, w + βu)`. Then the fill's second fundamental form equals the
//! neighbour's: `II(X_u, X_u) = Q·n` is the neighbour's `II(T, T)`; `II(X_v, X_v) = X_vv·n`
//! and `II(X_u, X_v) = ∂_v T·n = λ(α S_sw + β S_ww)·n` are the neighbour's because `X` and
//! `X_u` equal its data along the whole edge (tangential parts of `Q` do not enter).
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
//! At order 6 the two sides' `Q` differ at a corner in their tangential parts (different
//! parametrisations) and, unless the neighbours meet G2 there, in their normal parts; each
//! edge adds `ω(v) (γ S_s + δ S_w + η S_s × S_w)` with the same bump `ω` and constant
//! `(γ, δ, η)` solved at the corner so that both sides reach the mean `Q_c`. The tangential
//! terms leave G2 untouched; `η` is zero when the neighbours meet G2 at the corner and is
//! otherwise reported ([`FillReport::corner_curvature_gaps`]): G2 is then given up within
//! that corner's blend only.
//!
//! **Pole.** `X(1, v) = P`, `X_u(1, v) = −ρ (cos v e₁ + sin v e₂)` and at order 6
//! `X_uu(1, v) = σ n̄`: near the pole `X ≈ P + r ρ (cos v e₁ + sin v e₂) + ½ r² σ n̄`
//! (`r = 1 − u`), a cap of normal curvature `σ/ρ²` perpendicular to `n̄`, the loop's
//! vector-area normal (so the loop and the ring wind the same way); `e₁` points to the
//! loop's `v = 0` point. What the user does not set among `P`, `ρ`, `σ` is chosen by
//! **least bending**: the fill is linear in them, and they minimise
//! `∫∫ |X_rr + X_r/r + X_θθ/r²|² r dr dθ` — the thin-plate energy of `X` as a map of the
//! unit disc (`r = 1 − u`, `θ = v`), whose Laplacian has no singular terms at a smooth
//! pole — by linear least squares (see [`FillOptions`]). `height` scales the chosen pole's
//! offset from the loop's centroid.

mod crease;
mod curve;
mod data;
pub mod disc;
mod family;
mod foot;
mod foot_series;
mod series;

use crate::Vec3;
use crate::data::{Field, FieldRef, VecJet};
use crate::jet::{Jet, JetShape};
use crate::patch::{Condition, Surface, VDomain};
use crate::spectral::{SpectralError, SpectralOptions, SpectralPatch};
pub use curve::{AlongCurve, DomainCurve, Host};
use data::{LoopData, Piece, second_frame};
pub use family::FillFamily;
pub use foot::{FootCurve, FootError, foot_of};
pub use foot_series::FootSeries;
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
    /// Which way the cross tangent points: `Some(1.0)` along `+S_s`, `Some(-1.0)` along
    /// `−S_s`; `None`: towards the loop's centroid (a CAD face's edge knows the side its
    /// material is on, which the centroid does not tell at, e.g., a cylinder's rim).
    pub side: Option<f64>,
    /// The neighbour is known to be `C¹` around the edge and the edge's curve `C¹` (a CAD
    /// face and edge whose knots say so): its frame along the edge cannot jump, and no
    /// crease is looked for. `false` looks (expression surfaces, meshes' collars).
    pub smooth: bool,
}

/// Options of a fill.
#[derive(Clone, Debug)]
pub struct FillOptions {
    /// Half-width of each corner's blend as a fraction of an edge (0 < · ≤ ½).
    pub corner_blend: f64,
    /// The pole; default: least bending (see the module).
    pub pole: Option<Vec3>,
    /// Factor on the default pole's offset from the loop's centroid.
    pub height: f64,
    /// `ρ`, the length of `X_u` at the pole; default: least bending (but `R` × mean
    /// fullness when `pole_curvature` is set, which makes `σ = κρ²` depend on it).
    pub ring: Option<f64>,
    /// Time at which the neighbours are taken.
    pub t: f64,
    /// PDE order: 4 (G1: position and cross tangent at the loop) or 6 (G2: also the
    /// second cross derivative).
    pub order: usize,
    /// Order 6: the normal curvature `κ` of the cap at the pole against `n̄`
    /// (`X_uu(1, v) = κ ρ² n̄`); default: least bending.
    pub pole_curvature: Option<f64>,
    /// The PDE solve.
    pub spectral: SpectralOptions,
    /// Split every edge at the creases of its neighbour inside it ([`crease::creases`]),
    /// making each a corner (default `true`; `false` fills across them, which tears the
    /// fill: for tests of the tear measure).
    pub split_creases: bool,
}

impl Default for FillOptions {
    fn default() -> Self {
        FillOptions {
            corner_blend: 0.25,
            pole: None,
            height: 1.0,
            ring: None,
            t: 0.0,
            order: 4,
            pole_curvature: None,
            spectral: SpectralOptions { a: 1.0, modes: 12, omega: None },
            split_creases: true,
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
    /// Order 6: at each corner, the two neighbours' normal curvatures in the corner's cross
    /// direction differ by this (times the loop's mean radius): 0 when they meet G2 there.
    /// Where it is not 0 no surface meets both G2 at the corner, and the second cross
    /// derivative is made continuous by a normal correction that fades within the corner
    /// blend (G2 holds along the rest of both edges).
    pub corner_curvature_gaps: Vec<f64>,
    /// Order 6: the cap's normal curvature at the pole.
    pub pole_curvature: Option<f64>,
    /// Edges of the given loop that had no length (all their points within 1e-12 of the
    /// loop's mean radius) and were dropped: their indices in the given loop. Corners and
    /// edges elsewhere in the report count the remaining edges.
    pub dropped_edges: Vec<usize>,
    /// Creases of a neighbour found inside an edge, where the edge was split and the crease
    /// made a corner: the edge's index in the loop as given (after dropped edges) and the
    /// parameter `w` of the crease.
    pub split_edges: Vec<(usize, f64)>,
}

/// Continuity along the edges.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct EdgeContinuity {
    /// Largest angle (radians) between the fill's and the neighbour's normal lines.
    pub g1: f64,
    /// Largest `|X(0, v) − S|` divided by the loop's mean radius.
    pub gap: f64,
    /// Largest difference of the normal curvatures of the fill and the neighbour over all
    /// tangent directions (the spectral norm of the difference of their second fundamental
    /// forms in a common orthonormal tangent basis), times the loop's mean radius: 0 for G2.
    pub g2: f64,
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

/// Points of a grid of normals (`nu` rows, each closed around `nv` points) whose normal
/// vanishes (below 1e-9 of the median length), is not finite, or makes a cosine of at most
/// `min_cos` with a neighbour's (next in the row, or in the next row).
pub fn count_turns(normals: &[Vec3], nu: usize, nv: usize, min_cos: f64) -> usize {
    let mut lengths: Vec<f64> = normals.iter().map(|n| n.norm()).collect();
    lengths.sort_by(f64::total_cmp);
    let tiny = 1e-9 * lengths[lengths.len() / 2];
    let at = |i: usize, j: usize| normals[i * nv + j % nv];
    let mut folds = 0;
    for i in 0..nu {
        for j in 0..nv {
            let n = at(i, j);
            // the cosine at most min_cos, NaN included
            let against = |m: Vec3| {
                let c = n.dot(m) / (n.norm() * m.norm());
                c.is_nan() || c <= min_cos
            };
            let flips = (i + 1 < nu && against(at(i + 1, j))) || against(at(i, j + 1));
            if flips || n.norm().is_nan() || n.norm() <= tiny {
                folds += 1;
            }
        }
    }
    folds
}

/// A vector of NaNs: what a degenerate direction becomes in the measures.
const NAN3: Vec3 = Vec3::new(f64::NAN, f64::NAN, f64::NAN);

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
    /// `c + ρ (e₁ cos v + e₂ sin v)`: degree 1 (0 without the circle), not depending on time.
    fn trig_degree(&self) -> Option<usize> {
        let finite =
            [self.centre, self.e1, self.e2].iter().all(|p| p.x.is_finite() && p.y.is_finite() && p.z.is_finite());
        (finite && self.rho.is_finite())
            .then(|| usize::from(self.rho != 0.0 && (self.e1 != Vec3::ZERO || self.e2 != Vec3::ZERO)))
    }
    /// `∂ᵏ/∂vᵏ = ρ (e₁ cos(v + kπ/2) + e₂ sin(v + kπ/2))` (plus the centre at `k = 0`).
    fn derivatives_in(&self, at: &[f64], slot: usize, out: &mut [Vec3]) {
        let v = at[0];
        for (k, o) in out.iter_mut().enumerate() {
            *o = if slot != 0 && k > 0 {
                Vec3::ZERO
            } else {
                let ph = if slot == 0 { v + k as f64 * std::f64::consts::FRAC_PI_2 } else { v };
                let base = if k == 0 { self.centre } else { Vec3::ZERO };
                base + (self.e1 * ph.cos() + self.e2 * ph.sin()) * self.rho
            };
        }
    }
}

/// `0` for every `v`.
fn zero_field() -> FieldRef {
    Arc::new(Ring { centre: Vec3::ZERO, e1: Vec3::ZERO, e2: Vec3::ZERO, rho: 0.0 })
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

/// The closest points of segments `[p0, p1]` and `[q0, q1]` (clamped parameters).
fn segment_distance(p0: Vec3, p1: Vec3, q0: Vec3, q1: Vec3) -> (f64, Vec3) {
    let (d1, d2, r) = (p1 - p0, q1 - q0, p0 - q0);
    let (a, e, f) = (d1.dot(d1), d2.dot(d2), d2.dot(r));
    let (c, b) = (d1.dot(r), d1.dot(d2));
    let denom = a * e - b * b;
    let mut s = if denom > 1e-300 { ((b * f - c * e) / denom).clamp(0.0, 1.0) } else { 0.0 };
    let mut t = if e > 1e-300 { (b * s + f) / e } else { 0.0 };
    if t < 0.0 {
        t = 0.0;
        s = if a > 1e-300 { (-c / a).clamp(0.0, 1.0) } else { 0.0 };
    } else if t > 1.0 {
        t = 1.0;
        s = if a > 1e-300 { ((b - c) / a).clamp(0.0, 1.0) } else { 0.0 };
    }
    let (x, y) = (p0 + d1 * s, q0 + d2 * t);
    ((x - y).norm(), x)
}

/// Two segments of the closed polyline `pts` closer than `tol` although the polyline runs
/// at least `4 tol` between them (either way round): the loop comes back to itself. NaN
/// positions count. Their indices and the place.
///
/// The separation is measured along the polyline, not in segment indices: where segments
/// are shorter than `tol` (a loop of hundreds of edges, one short edge) neighbours a few
/// indices apart are close without the loop crossing itself.
///
/// Segments are grouped in runs of 8 whose bounding boxes (grown by `tol`) are compared
/// first; only runs whose boxes meet are compared segment by segment.
fn self_crossing(pts: &[Vec3], tol: f64) -> Option<(usize, usize, Vec3)> {
    let m = pts.len();
    if pts.iter().any(|p| !p.is_finite()) {
        return Some((0, 0, Vec3::new(f64::NAN, f64::NAN, f64::NAN)));
    }
    // cum[i]: the length of the polyline up to point i; cum[m] the whole loop
    let mut cum = Vec::with_capacity(m + 1);
    cum.push(0.0);
    for i in 0..m {
        cum.push(cum[i] + (pts[(i + 1) % m] - pts[i]).norm());
    }
    let total = cum[m];
    // along the loop between segments i < j: from i's end to j's start, or from j's end
    // round to i's start
    let apart = |i: usize, j: usize| (cum[j] - cum[i + 1]).min(total - cum[j + 1] + cum[i]);
    const RUN: usize = 8;
    let runs: Vec<(Vec3, Vec3)> = (0..m.div_ceil(RUN))
        .map(|r| {
            let idx = (r * RUN..((r + 1) * RUN).min(m)).flat_map(|i| [i, (i + 1) % m]);
            let (lo, hi) = idx.fold(
                (
                    Vec3::new(f64::INFINITY, f64::INFINITY, f64::INFINITY),
                    Vec3::new(-f64::INFINITY, -f64::INFINITY, -f64::INFINITY),
                ),
                |(lo, hi), i| (lo.min(pts[i]), hi.max(pts[i])),
            );
            (lo - Vec3::new(tol, tol, tol), hi + Vec3::new(tol, tol, tol))
        })
        .collect();
    let meet = |a: &(Vec3, Vec3), b: &(Vec3, Vec3)| {
        a.0.x <= b.1.x && b.0.x <= a.1.x && a.0.y <= b.1.y && b.0.y <= a.1.y && a.0.z <= b.1.z && b.0.z <= a.1.z
    };
    for (ra, a) in runs.iter().enumerate() {
        for (rb, b) in runs.iter().enumerate().skip(ra) {
            if !meet(a, b) {
                continue;
            }
            for i in ra * RUN..((ra + 1) * RUN).min(m) {
                for j in (rb * RUN).max(i + 2)..((rb + 1) * RUN).min(m) {
                    // NaN lengths count as far apart: the pair is compared
                    if apart(i, j) < 4.0 * tol {
                        continue;
                    }
                    let (d, p) = segment_distance(pts[i], pts[(i + 1) % m], pts[j], pts[(j + 1) % m]);
                    if d.is_nan() || d < tol {
                        return Some((i, j, p));
                    }
                }
            }
        }
    }
    None
}

/// `(γ, δ, η)` with `γ x + δ y + η z = r` (Cramer's rule; `x, y, z` independent).
fn in_frame3(x: Vec3, y: Vec3, z: Vec3, r: Vec3) -> [f64; 3] {
    let det = x.dot(y.cross(z));
    [r.dot(y.cross(z)) / det, x.dot(r.cross(z)) / det, x.dot(y.cross(r)) / det]
}

/// `d²/du² S(s₀ + a u, w + b u)` at `u = 0` from `[S, S_s, S_w, S_ss, S_sw, S_ww]`.
fn second(f: &[Vec3; 6], (a, b): (f64, f64)) -> Vec3 {
    f[3] * (a * a) + f[4] * (2.0 * a * b) + f[5] * (b * b)
}

/// The second fundamental form `[[L, M], [M, N]]` of a surface with tangents `xu`, `xv`
/// and second derivatives `xuu`, `xuv`, `xvv`, against the unit normal `n`, written in the
/// orthonormal tangent basis `(e1, e2)`.
fn second_form_in(d: [Vec3; 5], n: Vec3, e1: Vec3, e2: Vec3) -> [[f64; 2]; 2] {
    let [xu, xv, xuu, xuv, xvv] = d;
    let (ee, ff, gg) = (xu.dot(xu), xu.dot(xv), xv.dot(xv));
    let det = ee * gg - ff * ff;
    // e = p X_u + q X_v from the metric
    let coords = |e: Vec3| {
        let (a, b) = (e.dot(xu), e.dot(xv));
        ((gg * a - ff * b) / det, (ee * b - ff * a) / det)
    };
    let (l, m, nn) = (xuu.dot(n), xuv.dot(n), xvv.dot(n));
    let form = |x: (f64, f64), y: (f64, f64)| l * x.0 * y.0 + m * (x.0 * y.1 + x.1 * y.0) + nn * x.1 * y.1;
    let (c1, c2) = (coords(e1), coords(e2));
    let b12 = form(c1, c2);
    [[form(c1, c1), b12], [b12, form(c2, c2)]]
}

/// The spectral norm of a symmetric 2 × 2 matrix (NaN-propagating).
fn sym_norm(m: [[f64; 2]; 2]) -> f64 {
    let mean = 0.5 * (m[0][0] + m[1][1]);
    let half = 0.5 * (m[0][0] - m[1][1]);
    mean.abs() + (half * half + m[0][1] * m[0][1]).sqrt()
}

///
/// NaN when either normal vanishes: no angle is measured there (it was 0, a perfect G1).
fn line_angle(a: Vec3, b: Vec3) -> f64 {
    if a == Vec3::ZERO || b == Vec3::ZERO {
        return f64::NAN;
    }
    a.cross(b).norm().atan2(a.dot(b).abs())
}

/// The pole's data: position `P`, ring length `ρ`, and (order 6) `σ` in `X_uu = σ n̄`;
/// as flags, which of them are free.
#[derive(Clone, Copy, Debug)]
struct PoleData<T = f64, P = Vec3> {
    pole: P,
    ring: T,
    sigma: T,
}

/// The pole data of least bending: the fill depends linearly on the pole's data,
/// `X = X₀ + Σᵢ xᵢ Bᵢ` (`X₀` with the free data at 0, `Bᵢ` the patch with zero loop data and
/// only datum `i` at 1), so `E = ∫₀¹∫₀^{2π} |L X|² dv du` with `L = ∂u² + a²∂v²` — the
/// energy a biharmonic patch minimises for given boundary data — is least at the solution
/// of a linear least-squares problem in the free data (midpoint rule on [`BendingRule`];
/// the v-rule is exact for the products of the modes).
fn least_bending(
    setup: &LoopSetup,
    fixed_data: &PoleData,
    free: &PoleData<bool, bool>,
    o: &FillOptions,
) -> Result<PoleData, FillError> {
    let rule = BendingRule::new(setup.edges);
    let base = rule.rows(&SpectralPatch::new(
        &setup.with_pole(fixed_data, &setup.conds, o.order),
        VDomain::PERIODIC,
        o.spectral,
    )?);
    let zero_loop = setup.zero_loop();
    let cols: Vec<Vec<Vec3>> = unit_poles(free)
        .iter()
        .map(|d| {
            Ok(rule.rows(&SpectralPatch::new(&setup.with_pole(d, &zero_loop, o.order), VDomain::PERIODIC, o.spectral)?))
        })
        .collect::<Result<_, FillError>>()?;
    let x = bending_solve(&cols, &[base])?;
    let mut out = *fixed_data;
    set_free(&mut out, free, (0..cols.len()).map(|i| x[(i, 0)]));
    Ok(out)
}

/// The midpoint rule of [`least_bending`]'s energy: 32 points in `u`, and in `v` a multiple
/// of the edge count near 64 (so that the rule keeps the loop's symmetries).
struct BendingRule {
    us: Vec<f64>,
    vs: Vec<f64>,
}

impl BendingRule {
    fn new(edges: usize) -> BendingRule {
        let (nu, nv) = (32, edges * 64usize.div_ceil(edges));
        BendingRule {
            us: (0..nu).map(|i| (i as f64 + 0.5) / nu as f64).collect(),
            vs: (0..nv).map(|j| TAU * j as f64 / nv as f64).collect(),
        }
    }

    /// `√r (X_rr + X_r/r + X_θθ/r²)` at the rule's points (`r = 1 − u`), from the patch's
    /// `[X, X_u, X_v, X_uu, X_uv, X_vv]` there.
    fn rows(&self, p: &dyn Surface) -> Vec<Vec3> {
        self.rows_of(&p.grid2(&self.us, &self.vs))
    }

    fn rows_of(&self, g: &[[Vec3; 6]]) -> Vec<Vec3> {
        let nv = self.vs.len();
        g.iter()
            .enumerate()
            .map(|(k, d)| {
                let r = 1.0 - self.us[k / nv];
                (d[3] - d[1] * (1.0 / r) + d[5] * (1.0 / (r * r))) * r.sqrt()
            })
            .collect()
    }
}

/// The unit data, one per free datum in the order pole x, y, z, ring, σ.
fn unit_poles(free: &PoleData<bool, bool>) -> Vec<PoleData> {
    let zero = PoleData { pole: Vec3::ZERO, ring: 0.0, sigma: 0.0 };
    let mut unit = Vec::new();
    if free.pole {
        for e in [Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.0), Vec3::new(0.0, 0.0, 1.0)] {
            unit.push(PoleData { pole: e, ..zero });
        }
    }
    if free.ring {
        unit.push(PoleData { ring: 1.0, ..zero });
    }
    if free.sigma {
        unit.push(PoleData { sigma: 1.0, ..zero });
    }
    unit
}

/// Writes the free data, in [`unit_poles`]' order, into `d`.
fn set_free(d: &mut PoleData, free: &PoleData<bool, bool>, mut x: impl Iterator<Item = f64>) {
    let mut next = || x.next().unwrap_or(f64::NAN);
    if free.pole {
        d.pole = Vec3::new(next(), next(), next());
    }
    if free.ring {
        d.ring = next();
    }
    if free.sigma {
        d.sigma = next();
    }
}

/// The least-squares coefficients `x` with `Σᵢ xᵢ colsᵢ ≈ −base` for each `base`
/// (one column of the result each).
fn bending_solve(cols: &[Vec<Vec3>], bases: &[Vec<Vec3>]) -> Result<faer::Mat<f64>, FillError> {
    let rows = cols[0].len() * 3;
    let a = faer::Mat::<f64>::from_fn(rows, cols.len(), |r, c| cols[c][r / 3][r % 3]);
    let b = faer::Mat::<f64>::from_fn(rows, bases.len(), |r, c| -bases[c][r / 3][r % 3]);
    let (x, _cond) = crate::linalg::least_squares(&a, &b, 1e12)
        .map_err(|e| FillError::Loop(format!("the least-bending pole could not be found: {e}")))?;
    Ok(x)
}

/// A loop made ready for its fill: its conditions at `u = 0` and what the pole's
/// construction needs. The fill is this plus the pole's data ([`LoopSetup::finish`]).
struct LoopSetup {
    /// Position, cross tangent and (order 6) second cross derivative along the loop.
    conds: Vec<Condition>,
    position: Arc<LoopData>,
    /// The pole ring's in-plane frame: `e₁` towards the loop's `v = 0` point, `e₂ = n̄ × e₁`.
    e1: Vec3,
    e2: Vec3,
    /// Edges after dropping point-like ones and splitting at creases.
    edges: usize,
    mean_fullness: f64,
    /// All but the pole's figures.
    report: FillReport,
}

impl Fill {
    /// Fills the hole bounded by `edges` (in loop order).
    pub fn new(edges: &[FillEdge], o: &FillOptions) -> Result<Fill, FillError> {
        let setup = LoopSetup::new(edges, o)?;
        let data = setup.pole_data(o)?;
        setup.finish(o, data)
    }
}

impl LoopSetup {
    fn new(edges: &[FillEdge], o: &FillOptions) -> Result<LoopSetup, FillError> {
        let n = edges.len();
        if n < 3 {
            return Err(FillError::Loop(format!("a hole needs at least 3 edges; got {n}")));
        }
        // below 1e-6 of an edge a corner blend is a jump no mesh or fit resolves (and its
        // derivatives, ~1/width², overflow the report's figures)
        if !(o.corner_blend >= 1e-6 && o.corner_blend <= 0.5) {
            return Err(FillError::Loop(format!("corner_blend = {:e} must be in [1e-6, 0.5]", o.corner_blend)));
        }
        if !o.height.is_finite() {
            return Err(FillError::Loop(format!("height = {} must be finite", o.height)));
        }
        // a negative ring turns the cap inside out, which the fold count reports
        if let Some(r) = o.ring.filter(|r| !r.is_finite()) {
            return Err(FillError::Loop(format!("ring = {r} must be finite")));
        }
        if o.order != 4 && o.order != 6 {
            return Err(FillError::Loop(format!("a fill's order is 4 (G1) or 6 (G2), not {}", o.order)));
        }
        if let Some(k) = o.pole_curvature.filter(|k| !k.is_finite()) {
            return Err(FillError::Loop(format!("pole_curvature = {k} must be finite")));
        }
        let t = o.t;
        // the loop, sampled: closure, orientation, centroid, radius, vector area
        let per = 64;
        let mut samples = Vec::with_capacity(n * (per + 1));
        for (k, e) in edges.iter().enumerate() {
            if !(e.fullness.is_finite() && e.fullness > 0.0) {
                return Err(FillError::Loop(format!("edge {k}: its fullness must be positive, not {}", e.fullness)));
            }
            for i in 0..=per {
                let w = e.w.0 + (e.w.1 - e.w.0) * i as f64 / per as f64;
                let mut p = [Vec3::ZERO];
                e.surface.derivatives_in(&[e.s0, w, t], 1, &mut p);
                samples.push(p[0]);
            }
        }
        // the closed polyline (each edge's last sample is the next one's first)
        let pts: Vec<Vec3> = samples.chunks(per + 1).flat_map(|c| c[..per].iter().copied()).collect();
        let centroid = pts.iter().fold(Vec3::ZERO, |a, p| a + *p) * (1.0 / pts.len() as f64);
        let radius = pts.iter().map(|p| (*p - centroid).norm()).sum::<f64>() / pts.len() as f64;
        if !(radius.is_finite() && radius > 0.0) {
            return Err(FillError::Loop(format!("the loop has no extent (mean radius {radius})")));
        }
        // edges that are one point (every sample within 1e-12 of the loop's radius of the
        // first) are dropped, and the loop is filled without them
        let point_like: Vec<usize> = (0..n)
            .filter(|&k| {
                let s = &samples[k * (per + 1)..(k + 1) * (per + 1)];
                s.iter().all(|p| (*p - s[0]).norm() <= 1e-12 * radius)
            })
            .collect();
        if !point_like.is_empty() {
            let kept: Vec<FillEdge> =
                edges.iter().enumerate().filter(|(k, _)| !point_like.contains(k)).map(|(_, e)| e.clone()).collect();
            if kept.len() < 3 {
                return Err(FillError::Loop(format!(
                    "a hole needs at least 3 edges; {} of the {n} have no length (edges {point_like:?})",
                    point_like.len()
                )));
            }
            let mut setup = LoopSetup::new(&kept, o)?;
            setup.report.dropped_edges = point_like;
            return Ok(setup);
        }
        // creases of a neighbour inside an edge become corners: the edge is split there
        if o.split_creases {
            let mut split = Vec::new();
            let mut pieces = Vec::new();
            for (k, e) in edges.iter().enumerate() {
                let mut start = e.w.0;
                let found = if e.smooth { Vec::new() } else { crease::creases(e, t) };
                for (a, b) in found {
                    pieces.push(FillEdge { w: (start, a), ..e.clone() });
                    split.push((k, a));
                    start = b;
                }
                pieces.push(FillEdge { w: (start, e.w.1), ..e.clone() });
            }
            if !split.is_empty() {
                let mut setup = LoopSetup::new(&pieces, &FillOptions { split_creases: false, ..o.clone() })?;
                setup.report.split_edges = split;
                return Ok(setup);
            }
        }
        for k in 0..n {
            let (e, f) = (&edges[k], &edges[(k + 1) % n]);
            let end = point_frame(e, e.w.1, t).0;
            let start = point_frame(f, f.w.0, t).0;
            let gap = (end - start).norm();
            // NaN gaps fail too
            if gap.is_nan() || gap > 1e-9 * radius {
                let near = |a: Vec3, b: Vec3| (a - b).norm() <= 1e-9 * radius;
                let (e_start, f_end) = (point_frame(e, e.w.0, t).0, point_frame(f, f.w.1, t).0);
                let reversed = if near(end, f_end) {
                    // f ends where e ends
                    Some((k + 1) % n)
                } else if near(e_start, start) {
                    // e starts where f starts
                    Some(k)
                } else if near(e_start, f_end) {
                    // both: e's start meets f's end
                    Some(k)
                } else {
                    None
                };
                return Err(FillError::Loop(if let Some(r) = reversed {
                    format!(
                        "edge {r} is reversed: it runs against the loop's direction (swap the ends of its w or t range)"
                    )
                } else {
                    format!("edges {k} and {} do not meet: gap {gap:.3e} (relative {:.3e})", (k + 1) % n, gap / radius)
                }));
            }
        }
        if let Some(p) = o.pole {
            let d = (p - centroid).scaled_norm();
            if d.is_nan() || d > 1e6 * radius {
                return Err(FillError::Loop(format!(
                    "the pole {p} is {d:.3e} from the loop's centroid, more than 1e6 × the loop's mean radius {radius:.3e}"
                )));
            }
        }
        if let Some((i, j, p)) = self_crossing(&pts, 1e-3 * radius) {
            let (a, b) = (i / per, j / per);
            return Err(FillError::Loop(if a == b {
                format!(
                    "the loop crosses itself: edge {a} comes back within 1e-3 of the loop radius of itself near {p}"
                )
            } else {
                format!("the loop crosses itself: edge {a} comes within 1e-3 of the loop radius of edge {b} near {p}")
            }));
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
            let sign = match e.side {
                Some(s) => s.signum(),
                None if ss.dot(centroid - p) >= 0.0 => 1.0,
                None => -1.0,
            };
            cs.push(sign * e.fullness * radius / ss.norm());
        }
        // corners: the mean cross tangent in each edge's frame
        let mut starts = vec![(0.0, 0.0); n];
        let mut ends = vec![(0.0, 0.0); n];
        // corners whose neighbours are not G1: the part of the mean along each normal
        let (mut starts_n, mut ends_n) = (vec![0.0; n], vec![0.0; n]);
        let mut corner_angles = Vec::with_capacity(n);
        for k in 0..n {
            let k1 = (k + 1) % n;
            let (_, ss0, sw0) = point_frame(&edges[k], edges[k].w.1, t);
            let (_, ss1, sw1) = point_frame(&edges[k1], edges[k1].w.0, t);
            let tc = (ss0 * cs[k] + ss1 * cs[k1]) * 0.5;
            ends[k] = in_frame(ss0, sw0, tc);
            starts[k1] = in_frame(ss1, sw1, tc);
            let angle = line_angle(ss0.cross(sw0), ss1.cross(sw1));
            // as `check` judges corners (1e-9 rad): below, the planes are one and the mean
            // lies in both
            if angle > 1e-9 {
                let normal_part = |ss: Vec3, sw: Vec3, (a, b): (f64, f64)| {
                    let nn = ss.cross(sw);
                    (tc - ss * a - sw * b).dot(nn) / nn.dot(nn)
                };
                ends_n[k] = normal_part(ss0, sw0, ends[k]);
                starts_n[k1] = normal_part(ss1, sw1, starts[k1]);
            }
            corner_angles.push(angle);
        }
        // order 6, corners: the second cross derivative `Q = d²/du² S(s₀ + αu, w + βu)` from
        // each side, their mean `Q_c`, and the correction `Q_c − Q` in each edge's frame
        // `(S_s, S_w, S_s × S_w)`; its normal part is the neighbours' curvature mismatch
        let mut starts2 = vec![[0.0; 3]; n];
        let mut ends2 = vec![[0.0; 3]; n];
        let mut corner_curvature_gaps = Vec::new();
        if o.order == 6 {
            for k in 0..n {
                let k1 = (k + 1) % n;
                let f0 = second_frame(&edges[k].surface, edges[k].s0, edges[k].w.1, t);
                let f1 = second_frame(&edges[k1].surface, edges[k1].s0, edges[k1].w.0, t);
                let (q0, q1) = (second(&f0, ends[k]), second(&f1, starts[k1]));
                let qc = (q0 + q1) * 0.5;
                ends2[k] = in_frame3(f0[1], f0[2], f0[1].cross(f0[2]), qc - q0);
                starts2[k1] = in_frame3(f1[1], f1[2], f1[1].cross(f1[2]), qc - q1);
                let tc = f0[1] * ends[k].0 + f0[2] * ends[k].1;
                let nrm = f0[1].cross(f0[2]).normalized().unwrap_or(NAN3);
                corner_curvature_gaps.push((q1 - q0).dot(nrm).abs() / tc.dot(tc) * radius);
            }
        }
        // each edge's surface kept per point for the conditions: at a `v` the position,
        // the cross tangent (and the second cross derivative) ask its jets at the same
        // point (on CAD faces each jet is a foot and a reparametrisation in Taylor
        // arithmetic), so one jet, across to the conditions' order and along to the
        // second derivative, answers them all
        let cover = JetShape::new(&[if o.order == 6 { 2 } else { 1 }, 2, 0]);
        let pieces: Vec<Piece> = edges
            .iter()
            .enumerate()
            .map(|(k, e)| Piece {
                surface: Arc::new(crate::data::MemoField::covering(e.surface.clone(), cover)),
                s0: e.s0,
                w0: e.w.0,
                lambda: (e.w.1 - e.w.0) * n as f64 / TAU,
                c: cs[k],
                start: starts[k],
                end: ends[k],
                start_n: starts_n[k],
                end_n: ends_n[k],
                start2: starts2[k],
                end2: ends2[k],
            })
            .collect();
        let position = Arc::new(LoopData { pieces: pieces.clone(), order: 0, blend: o.corner_blend });
        let cross = Arc::new(LoopData { pieces: pieces.clone(), order: 1, blend: o.corner_blend });
        // the pole
        let x0 = position.eval(&[0.0, t]);
        let Some(e1) = ((x0 - centroid) - normal * (x0 - centroid).dot(normal)).normalized() else {
            return Err(FillError::Loop("the loop's first point is above its centroid".into()));
        };
        let e2 = normal.cross(e1);
        // the loop's data are asked at the same v by every cell of a grid (and cost much
        // per point on CAD faces): kept per point
        let memo = |f: FieldRef| -> FieldRef { Arc::new(crate::data::MemoField::new(f)) };
        let mut conds = vec![
            Condition { u: 0.0, order: 0, data: memo(position.clone()) },
            Condition { u: 0.0, order: 1, data: memo(cross) },
        ];
        if o.order == 6 {
            let second = Arc::new(LoopData { pieces, order: 2, blend: o.corner_blend });
            conds.push(Condition { u: 0.0, order: 2, data: memo(second) });
        }
        let mean_fullness = edges.iter().map(|e| e.fullness).sum::<f64>() / n as f64;
        let report = FillReport {
            corner_angles,
            pole: Vec3::ZERO,
            centroid,
            radius,
            normal,
            corner_curvature_gaps,
            pole_curvature: None,
            dropped_edges: Vec::new(),
            split_edges: Vec::new(),
        };
        Ok(LoopSetup { conds, position, e1, e2, edges: n, mean_fullness, report })
    }

    /// Which of the pole's data the options leave to least bending.
    fn free(o: &FillOptions) -> PoleData<bool, bool> {
        let ring_free = o.ring.is_none() && !(o.order == 6 && o.pole_curvature.is_some());
        PoleData { pole: o.pole.is_none(), ring: ring_free, sigma: o.order == 6 && o.pole_curvature.is_none() }
    }

    /// The pole's data as the options set them, 0 where least bending will choose.
    fn fixed_data(&self, o: &FillOptions) -> PoleData {
        let free = Self::free(o);
        let mut data = PoleData {
            pole: o.pole.unwrap_or(Vec3::ZERO),
            ring: o.ring.unwrap_or(if free.ring { 0.0 } else { self.report.radius * self.mean_fullness }),
            sigma: 0.0,
        };
        if let Some(k) = o.pole_curvature {
            data.sigma = k * data.ring * data.ring;
        }
        data
    }

    /// The pole's data, `X = P`, `X_u = −ρ (cos v e₁ + sin v e₂)`, order 6 also
    /// `X_uu = σ n̄`: what the user did not set is chosen by least bending, and `height`
    /// scales the chosen pole's offset from the centroid.
    fn pole_data(&self, o: &FillOptions) -> Result<PoleData, FillError> {
        let free = Self::free(o);
        let mut data = self.fixed_data(o);
        if free.pole || free.ring || free.sigma {
            data = least_bending(self, &data, &free, o)?;
            if free.pole {
                data.pole = self.report.centroid + (data.pole - self.report.centroid) * o.height;
            }
        }
        Ok(data)
    }

    /// `loop_conds` (the loop's, or zero data of the same kinds) followed by the pole's.
    fn with_pole(&self, d: &PoleData, loop_conds: &[Condition], order: usize) -> Vec<Condition> {
        let fixed = |centre: Vec3, rho: f64| -> FieldRef { Arc::new(Ring { centre, e1: self.e1, e2: self.e2, rho }) };
        let mut c = loop_conds.to_vec();
        c.push(Condition { u: 1.0, order: 0, data: fixed(d.pole, 0.0) });
        c.push(Condition { u: 1.0, order: 1, data: fixed(Vec3::ZERO, -d.ring) });
        if order == 6 {
            c.push(Condition { u: 1.0, order: 2, data: fixed(self.report.normal * d.sigma, 0.0) });
        }
        c
    }

    /// The loop's conditions with zero data.
    fn zero_loop(&self) -> Vec<Condition> {
        self.conds.iter().map(|c| Condition { u: c.u, order: c.order, data: zero_field() }).collect()
    }

    /// The fill with the pole's data `data`.
    fn finish(self, o: &FillOptions, data: PoleData) -> Result<Fill, FillError> {
        let conds = self.with_pole(&data, &self.conds, o.order);
        let patch = Arc::new(SpectralPatch::new(&conds, VDomain::PERIODIC, o.spectral)?);
        let mut report = self.report;
        report.pole = data.pole;
        report.pole_curvature = (o.order == 6).then(|| data.sigma / (data.ring * data.ring));
        Ok(Fill { patch, conditions: conds, position: self.position, report, t: o.t })
    }
}

impl Fill {
    /// The fill surface.
    pub fn patch(&self) -> &Arc<SpectralPatch> {
        &self.patch
    }

    /// Its conditions: loop, cross tangent (and, order 6, second cross derivative) at
    /// `u = 0`; pole, ring (and the cap's second derivative) at `u = 1`.
    /// The loop's data answer [`Field::host_normal`] with the neighbour's normal.
    pub fn conditions(&self) -> &[Condition] {
        &self.conditions
    }

    /// What the construction found.
    pub fn report(&self) -> &FillReport {
        &self.report
    }

    /// The corners' `v` inside the loop's period: edge `k` spans `[2πk/N, 2π(k+1)/N]`, and
    /// across these lines the fill is only C0 (the loop turns at its corners).
    pub fn corner_parameters(&self) -> Vec<f64> {
        let n = self.position.pieces.len();
        (1..n).map(|k| TAU * k as f64 / n as f64).collect()
    }

    /// Where the corner blends end, with the fill's smoothness across them (`(v, 3)`):
    /// the blends' bump is a polynomial of degree 7 joined to 0 with three vanishing
    /// derivatives, so the cross derivatives `X_u` (and `X_uu`) are only C³ in `v` there
    /// (blends that change nothing left out). A B-spline fit puts knots of multiplicity
    /// `degree − 3` there ([`crate::fit::FitOptions::v_joins`]).
    pub fn blend_joins(&self) -> Vec<(f64, usize)> {
        self.position.blend_joins(self.t)
    }

    /// G1 angle, position gap and curvature gap against the neighbours at `per_edge` points
    /// of every edge (its start corner included), NaN-propagating.
    pub fn edge_continuity(&self, per_edge: usize) -> EdgeContinuity {
        let n = self.position.pieces.len();
        let vs: Vec<f64> = (0..n * per_edge).map(|k| TAU * k as f64 / (n * per_edge) as f64).collect();
        // the fill's side on one grid row (its work shared across the row)
        let row = self.patch.grid2(&[0.0], &vs);
        let mut out = EdgeContinuity::default();
        for (d, &v) in row.iter().zip(&vs) {
            let p = self.gaps(d, v);
            out.g1 = crate::num::max_nan(out.g1, p.g1);
            out.gap = crate::num::max_nan(out.gap, p.gap);
            out.g2 = crate::num::max_nan(out.g2, p.g2);
            out.samples += 1;
        }
        out
    }

    /// The continuity measures of [`EdgeContinuity`] at the loop's point `v` (`samples` 1).
    pub fn edge_gaps_at(&self, v: f64) -> EdgeContinuity {
        // index i·3 + j holds ∂uⁱ∂vʲ
        let d = self.patch.derivatives(0.0, v, 2, 2);
        self.gaps(&[d[0], d[3], d[1], d[6], d[4], d[2]], v)
    }

    /// The measures at `v` from the fill's `[X, X_u, X_v, X_uu, X_uv, X_vv]` there.
    fn gaps(&self, d: &[Vec3; 6], v: f64) -> EdgeContinuity {
        let [x, xu, xv, xuu, xuv, xvv] = *d;
        let f = self.position.frame2(v, self.t);
        // both second fundamental forms against the fill's normal, in one orthonormal basis
        // of its tangent plane
        // a degenerate normal or tangent is NaN, so every measure there is NaN (not 0)
        let nrm = xu.cross(xv).normalized().unwrap_or(NAN3);
        let e1 = xv.normalized().unwrap_or(NAN3);
        let e2 = nrm.cross(e1);
        let fill = second_form_in([xu, xv, xuu, xuv, xvv], nrm, e1, e2);
        let nb = second_form_in([f[1], f[2], f[3], f[4], f[5]], nrm, e1, e2);
        let diff = [[fill[0][0] - nb[0][0], fill[0][1] - nb[0][1]], [fill[1][0] - nb[1][0], fill[1][1] - nb[1][1]]];
        EdgeContinuity {
            g1: line_angle(xu.cross(xv), f[1].cross(f[2])),
            gap: (x - f[0]).norm() / self.report.radius,
            g2: sym_norm(diff) * self.report.radius,
            samples: 1,
        }
    }

    /// Folds: points of an `nu × nv` grid (`u ≤ 0.98`, away from the pole) where the
    /// parametrisation degenerates or turns over: `X_u × X_v` vanishes (below 1e-9 of its
    /// median length), is not finite, or points against its value at the next grid point in
    /// `u` or in `v`. A surface that curves round (a fill wrapping a wing's nose) keeps its
    /// orientation from point to point, so only a real fold is counted.
    pub fn folds(&self, nu: usize, nv: usize) -> usize {
        self.turns(nu, nv, 0.0)
    }

    /// Turn-overs: as [`folds`](Self::folds), but a normal counts as turned over only past
    /// 120° from its neighbour's (cosine below −½). At a corner of the loop where the faces
    /// around meet at a right angle (not G1) the normal turns by that angle from one side
    /// of the corner to the other — `folds` counts it, this does not — while a cap folded
    /// onto itself reverses its normal (cosine near −1).
    pub fn turn_overs(&self, nu: usize, nv: usize) -> usize {
        self.turns(nu, nv, -0.5)
    }

    /// Grid points whose normal vanishes, is not finite, or makes a cosine of at most
    /// `min_cos` with a neighbour's (next in `u` or in `v`).
    fn turns(&self, nu: usize, nv: usize, min_cos: f64) -> usize {
        let us: Vec<f64> = (0..nu).map(|i| 0.98 * i as f64 / (nu - 1) as f64).collect();
        let vs: Vec<f64> = (0..nv).map(|j| TAU * (j as f64 + 0.5) / nv as f64).collect();
        let g = self.patch.grid(&us, &vs);
        let normals: Vec<Vec3> = g.iter().map(|d| d[1].cross(d[2])).collect();
        count_turns(&normals, nu, nv, min_cos)
    }

    /// The fill's own continuity, measured on an `nu × nv` grid (`u ≤ 0.98`, away from the
    /// pole): between neighbouring grid points the step `|ΔX|` over the grid spacing `h`
    /// times the larger `|∂X|` at its two ends, maximised over all steps in `u` and in `v`,
    /// with the place of the largest. Where `X` is continuously differentiable,
    /// `|ΔX| ≤ h max|∂X| + h²/2 max|∂²X|`, so the ratio is 1 plus a term that vanishes with
    /// `h`; a jump of the surface (data that jump inside an edge) between two grid points
    /// makes it `|jump| / (h |∂X|)`, far above 1 at any `nv` in the thousands. NaN
    /// propagates.
    pub fn tear(&self, nu: usize, nv: usize) -> (f64, (f64, f64)) {
        let us: Vec<f64> = (0..nu).map(|i| 0.98 * i as f64 / (nu - 1) as f64).collect();
        let vs: Vec<f64> = (0..nv).map(|j| TAU * (j as f64 + 0.5) / nv as f64).collect();
        let g = self.patch.grid(&us, &vs);
        let at = |i: usize, j: usize| &g[i * nv + j % nv];
        let (hu, hv) = (0.98 / (nu - 1) as f64, TAU / nv as f64);
        // a step of 0 is no tear (also where the derivative is 0 too); NaN stays NaN
        let ratio = |a: &[Vec3; 4], b: &[Vec3; 4], k: usize, h: f64| {
            let step = (b[0] - a[0]).norm();
            if step == 0.0 { 0.0 } else { step / (h * crate::num::max_nan(a[k].norm(), b[k].norm())) }
        };
        let (mut worst, mut place) = (0.0, (0.0, 0.0));
        for (i, &u) in us.iter().enumerate() {
            for (j, &v) in vs.iter().enumerate() {
                let p = at(i, j);
                let mut r = ratio(p, at(i, j + 1), 2, hv);
                if i + 1 < nu {
                    r = crate::num::max_nan(r, ratio(p, at(i + 1, j), 1, hu));
                }
                if r.is_nan() {
                    return (f64::NAN, (u, v));
                }
                if r > worst {
                    (worst, place) = (r, (u, v));
                }
            }
        }
        (worst, place)
    }
}

#[cfg(test)]
mod tests;
