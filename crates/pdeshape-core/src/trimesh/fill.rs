//! A mesh's hole filled: the collar fitted ([`super::collar`]), a fill of order 4 (G1) or
//! 6 (G2) that meets it along the loop, meshed at the density around the hole and stitched
//! to the loop's own vertices.
//!
//! **The fill.** A hole's loop zigzags along the mesh's edges; a fill forced through such
//! a loop would carry the zigzag into its boundary layer. The fill is therefore bounded by
//! a smooth curve `s = σ̄(w)` in the collar's domain just inside the hole (a spline on the
//! spine's breakpoints fitted to `s_i − 0.87 h` at the loop's vertices, lowered as a whole
//! to stay `0.4 h` beyond every loop vertex and `max(0.25 h, 0.35 h_l)` beyond every band
//! vertex, `h_l` the local median edge length where it stands). The fill meets the collar
//! G1 (order 4) or G2 (order 6) along that curve by construction. It is the disc fill
//! ([`super::disc`]: `Δ²X = 0` or `Δ³X = 0` in the unit disc, whose circle is the curve
//! parametrised by the affine angle of a fitted ellipse; it reproduces a quadratic surface
//! over an elliptical hole, where the strip fill lay 1.5e-3 off the saddle of the tests)
//! wherever the curve is star-shaped about that ellipse and the fill does not fold; else
//! the strip fill ([`crate::fill`], the curve cut into four pieces of equal `w`-length, its
//! cross tangent pointing away from the mesh, closed in a pole).
//!
//! **The band.** Between the loop and the fill's boundary lies a band of the collar
//! itself, about one edge wide. Its triangles on the loop's edges have their apexes over
//! the edges ([`super::band`]), so that they crease against the mesh's triangles no more
//! than the mesh's own do; the ring of those apexes is zipped to the fill's boundary.
//! Where that band cannot be built, or its mesh would cross the input, the loop's own
//! vertices are zipped to the fill's boundary (at their mid-`v`: a strip of quads). The
//! mesh's loop vertices lie on the collar up to its fit residual (reported), the band's
//! vertices on the collar, the fill's on the fill.
//!
//! **The mesh.** `h`, the median length of the mesh's edges at the loop's vertices, sets
//! the density: rings `u = u_j` at equal steps of the mean arc length from the boundary to
//! the pole, `round(ℓ / h)` of them, each with `round(perimeter / h)` vertices (at least
//! 3) at equal steps of `v`, staggered from ring to ring, and the pole; on the boundary
//! ring, a vertex within `max(0.4 h, 0.55 h_l)` of a band vertex is left out. The new
//! edges then lie within 2× of the local median edge length (`edge_ratio`). Neighbouring rings are
//! zipped by increasing `v` (the next triangle takes whichever ring's next vertex comes
//! first). Every triangle is clockwise in the `(v, u)` chart, which makes it run each loop
//! edge against the way the mesh runs it: the output is consistently oriented, and each
//! loop edge ends up in exactly two triangles. Last, the new triangles' edges are flipped
//! towards Delaunay ([`super::flip`]), those on the loop's edges kept as placed.
//!
//! **Crossings.** The first of (band, flipped), (loop zipped, flipped), (loop zipped) whose
//! triangles cross neither the input's nor each other ([`super::crossing`]) is taken.

use super::band::{Band, BandInput, BandVertex, SHORTEST, apex_band};
use super::collar::{CollarError, CollarFit, DomainLine, adjacency, fit_collar, triangles_on_loop};
use super::crossing::crossing_free;
use super::disc::DiscSurface;
use super::flip::flip_to_delaunay;
use super::{LoopKind, MeshLoop, TriMesh, position};
use crate::Vec3;
use crate::data::FieldRef;
use crate::fill::{AlongCurve, DomainCurve, EdgeContinuity, FillEdge, FillError, FillFamily, FillOptions, Host};
use crate::num::max_nan;
use crate::patch::Surface;
use faer::linalg::solvers::Solve;
use std::f64::consts::TAU;
use std::sync::Arc;

/// How a loop is filled.
#[derive(Clone, Debug)]
pub struct LoopFillOptions {
    /// 4 (G1) or 6 (G2).
    pub order: usize,
    /// Rings of vertices around the loop that the collar is fitted to (4 by default: the
    /// collar is a quartic across the loop, see [`super::collar`]).
    pub rings: usize,
    /// Most new vertices of one fill (the `vertices` cap: a loop long against its edges
    /// would otherwise ask for a mesh of any size).
    pub max_vertices: usize,
    /// Fill by the disc fill where the loop allows it (`true`, the default), else by the
    /// strip fill (see [`FillShape`]).
    pub disc: bool,
}

impl Default for LoopFillOptions {
    fn default() -> Self {
        LoopFillOptions { order: 4, rings: 4, max_vertices: 4_000_000, disc: true }
    }
}

/// A filled loop: the new vertices and triangles, and what was measured.
pub struct LoopFill {
    /// The collar and its fit.
    pub fit: CollarFit,
    /// Which fill, and its free parameters, chosen for least Willmore energy (see
    /// [`fill_loop`]).
    pub shape: FillShape,
    /// Its Willmore energy `∫ H² dA`.
    pub willmore: f64,
    /// New vertices, to be appended to the mesh's (their indices start at the `base`
    /// given to [`fill_loop`]).
    pub positions: Vec<Vec3>,
    /// New triangles, on the loop's vertices and the new ones.
    pub triangles: Vec<[u32; 3]>,
    /// The fill against the collar along the loop, at 64 points a piece.
    pub continuity: EdgeContinuity,
    /// The largest angle (radians) between a loop edge's mesh triangle and its fill
    /// triangle.
    pub seam_dihedral: f64,
    /// `h`: the median edge length at the loop's vertices.
    pub edge_length: f64,
    /// The shortest and longest new edge divided by the local median edge length at the
    /// loop vertex nearest its midpoint (the median length of the mesh's edges at that
    /// vertex and its neighbours).
    pub edge_ratio: (f64, f64),
    /// Whether the new triangles were checked to cross neither the input mesh nor each
    /// other (false for the last way of stitching, which is kept unchecked: the caller
    /// checks it, [`super::crossings`]).
    pub crossing_free: bool,
}

/// Which fill a loop got, with the parameters that G1 (G2) leaves free, as chosen.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FillShape {
    /// The disc fill ([`super::disc`]): `fullness` scales its radial derivative at the
    /// loop, `mu` times it is added to the second.
    Disc {
        /// `f`.
        fullness: f64,
        /// `μ`.
        mu: f64,
    },
    /// The strip fill closed in a pole ([`crate::fill`]), where the disc fill is not
    /// possible (a loop not star-shaped about its fitted ellipse) or folds.
    Strip {
        /// The cross tangent's length against the loop's mean radius.
        fullness: f64,
        /// The factor on the least-bending pole's offset from the centroid.
        height: f64,
        /// Why not the disc fill: the number of its grid points that turned over (0 when
        /// it could not be set up, or was not asked for).
        disc_folds: usize,
    },
}

/// A loop's fill surface in the strip chart `(u, v)`: `u = 0` the boundary line, `u = 1`
/// the pole (centre), `v = 2π (w − w₀)/L`.
enum Filled {
    Strip(Arc<crate::spectral::SpectralPatch>),
    Disc(Box<DiscSurface>),
}

impl Filled {
    /// Values on the grid `us × vs`.
    fn values(&self, us: &[f64], vs: &[f64]) -> Vec<Vec3> {
        match self {
            Filled::Strip(p) => p.grid_values(us, vs),
            Filled::Disc(d) => d.values(us, vs),
        }
    }

    /// The point at `u = 1`.
    fn pole(&self) -> Vec3 {
        match self {
            Filled::Strip(p) => p.point(1.0, 0.0),
            Filled::Disc(d) => d.pole(),
        }
    }
}

/// What a fill's construction hands the mesher: the surface, its shape and parameters,
/// its Willmore energy, its continuity against the collar.
type Chosen = (Filled, FillShape, f64, EdgeContinuity);

/// The disc fill's member of least Willmore energy over `(f, μ)`, or the number of its grid
/// points that turn over.
fn disc_member(mut disc: DiscSurface, order: usize) -> Result<Chosen, usize> {
    let (rs, wr) = crate::solid::gauss_legendre(16);
    let ts: Vec<f64> = (0..48).map(|j| TAU * j as f64 / 48.0).collect();
    let grids = disc.part_grids(&rs, &ts);
    let search = Search {
        start: [1.0, 0.0],
        bounds: [(0.5, 2.0), (-3.0, 3.0)],
        delta: [0.15, if order >= 6 { 0.5 } else { 0.0 }],
    };
    let ([f, mu], energy) =
        fairest(&search, |[f, mu]| willmore(&DiscSurface::member_grid(&grids, f, mu), &wr, ts.len()));
    disc.choose(f, mu);
    let folds = disc.folds(32, 64);
    if folds > 0 {
        return Err(folds);
    }
    let continuity = disc.continuity(256);
    Ok((Filled::Disc(Box::new(disc)), FillShape::Disc { fullness: f, mu }, energy, continuity))
}

/// The strip fill of least Willmore energy over fullness and pole height.
fn strip_fill(
    fit: &CollarFit,
    line: &DomainLine,
    o: &LoopFillOptions,
    disc_folds: usize,
) -> Result<Chosen, LoopFillError> {
    let (period, w0) = (fit.period, fit.params[0].1);
    let along = AlongCurve {
        host: Host::Field(Arc::new(fit.collar.clone())),
        curve: DomainCurve::Field(Arc::new(line.clone())),
    };
    // the fills of several fullnesses ask the collar at the same points: kept per point
    // and each in several shapes: orders 4 and 6 ask for up to 2 derivatives across and
    // up to 3 and 4 along (seen), so a point's jet is computed once in that shape
    let cover = crate::jet::JetShape::new(&[2, o.order / 2 + 1]);
    let surface: FieldRef = Arc::new(crate::data::MemoField::covering(Arc::new(along), cover));
    // the reparametrised collar's σ grows along (−1, σ̄′) in (s, w): into the hole
    let edges: Vec<FillEdge> = (0..4)
        .map(|k| FillEdge {
            surface: surface.clone(),
            s0: 0.0,
            w: (w0 + period * k as f64 / 4.0, w0 + period * (k + 1) as f64 / 4.0),
            fullness: 1.0,
            side: Some(1.0),
            // the collar is not known to be C¹ (its spline may hold C0 knots): looked at
            smooth: false,
        })
        .collect();
    // every fill of the search from the solves of one (`FillFamily`), its energy on the
    // Willmore rule's grid
    let (us, wu) = crate::solid::gauss_legendre(16);
    let vs: Vec<f64> = (0..48).map(|j| TAU * j as f64 / 48.0).collect();
    // the collar (periodic cubic splines in `w`, a quartic in `s`) and the boundary line (a
    // periodic cubic spline) are C2, so the reparametrised collar has no crease for
    // `crease::creases` to look for (512 jets an edge)
    let options = FillOptions { order: o.order, split_creases: false, ..FillOptions::default() };
    let family = FillFamily::new(&edges, &options, &us, &vs)?;
    let search = Search { start: [1.0, 1.0], bounds: [(0.5, 2.0), (0.0, 4.0)], delta: [0.15, 0.4] };
    let ([fullness, height], energy) = fairest(&search, |[f, h]| willmore(&family.grid2(f, h), &wu, vs.len()));
    let fill = family.fill(fullness, height)?;
    if !fill.report().dropped_edges.is_empty() {
        return Err(LoopFillError::Unstitched);
    }
    let folds = fill.folds(32, 64);
    if folds > 0 {
        return Err(LoopFillError::Folds(folds));
    }
    let continuity = fill.edge_continuity(64);
    let shape = FillShape::Strip { fullness, height, disc_folds };
    Ok((Filled::Strip(fill.patch().clone()), shape, energy, continuity))
}

/// Why a loop is not filled.
#[derive(Debug, thiserror::Error)]
pub enum LoopFillError {
    /// Not a simple loop.
    #[error("the loop passes a vertex twice: not a simple hole")]
    NotSimple,
    /// The loop has fewer than 3 vertices.
    #[error("the loop has {0} vertices")]
    TooShort(usize),
    /// The collar.
    #[error(transparent)]
    Collar(#[from] CollarError),
    /// The fill.
    #[error(transparent)]
    Fill(#[from] FillError),
    /// The fill turns over.
    #[error("the fill folds ({0} points of a 32 × 64 grid turn over)")]
    Folds(usize),
    /// The fill's mesh would have more vertices than allowed.
    #[error(
        "the fill's mesh needs more than {limit} vertices (the loop is {ratio:.0} times its median edge length around); raise the cap with `--limit vertices=N`"
    )]
    TooManyVertices {
        /// The cap.
        limit: usize,
        /// Loop length over median edge.
        ratio: f64,
    },
    /// The fill dropped a piece of the loop without length, or its mesh could not be
    /// stitched to every loop edge.
    #[error(
        "the fill could not be stitched to the loop (a piece of the collar without length, or a loop edge left without a new triangle)"
    )]
    Unstitched,
}

/// Fills loop `lp` of `m`; the new vertices are numbered from `base`. The disc fill where
/// the loop is star-shaped about its fitted ellipse and the fill does not fold, else the
/// strip fill ([`FillShape`]); of the fills of either kind that meet the collar G1 (G2),
/// differing in the two parameters G1 (G2) leaves free, the one of least Willmore energy is
/// taken (`fairest`).
pub fn fill_loop(m: &TriMesh, lp: &MeshLoop, base: u32, o: &LoopFillOptions) -> Result<LoopFill, LoopFillError> {
    fill_loop_with(m, &adjacency(m), lp, base, o)
}

/// [`fill_loop`] with the mesh's [`adjacency`] given: a mesh with several holes builds it
/// once (a pass over every triangle; it was three a hole).
pub fn fill_loop_with(
    m: &TriMesh,
    adj: &[Vec<u32>],
    lp: &MeshLoop,
    base: u32,
    o: &LoopFillOptions,
) -> Result<LoopFill, LoopFillError> {
    if lp.kind == LoopKind::TouchesItself {
        return Err(LoopFillError::NotSimple);
    }
    let n = lp.vertices.len();
    if n < 3 {
        return Err(LoopFillError::TooShort(n));
    }
    let original = (m, lp);
    let h = median_edge(m, adj, lp);
    // the loop's sharp notches closed first, by triangles on its own vertices
    let (ears, clipped) = clip_ears(m, adj, lp, h);
    let with_ears;
    let (m, lp, adj) = if ears.is_empty() {
        (m, lp, std::borrow::Cow::Borrowed(adj))
    } else {
        let mut w = m.clone();
        w.triangles.extend(&ears);
        // an ear `[c, b, a]` adds the edge `a c`; `b a` and `c b` are the loop's own
        let mut wadj = adj.to_vec();
        for &[c, _, a] in &ears {
            for (x, y) in [(a, c), (c, a)] {
                let l = &mut wadj[x as usize];
                if let Err(k) = l.binary_search(&y) {
                    l.insert(k, y);
                }
            }
        }
        with_ears = (w, MeshLoop { vertices: clipped, ..lp.clone() });
        (&with_ears.0, &with_ears.1, std::borrow::Cow::Owned(wadj))
    };
    let adj: &[Vec<u32>] = &adj;
    let fit = fit_collar(m, adj, lp, o.rings)?;
    let (period, w0) = (fit.period, fit.params[0].1);
    let loop_pos: Vec<Vec3> = lp.vertices.iter().map(|&v| m.positions[v as usize]).collect();
    let local = local_medians(m, adj, &lp.vertices);
    let band_input = BandInput {
        ids: &lp.vertices,
        pos: &loop_pos,
        params: &fit.params,
        collar: &fit.collar,
        period,
        h,
        local: &local,
    };
    let band = apex_band(&band_input, base);
    let line = boundary_line(&fit, h, band.as_ref().map_or(&[][..], |b| &b.vertices));
    let disc = o.disc.then(|| DiscSurface::new(&fit.collar, &line, period, w0, o.order)).flatten();
    let (filled, shape, willmore_energy, continuity) = match disc {
        Some(disc) => match disc_member(disc, o.order) {
            Ok(chosen) => chosen,
            Err(folds) => strip_fill(&fit, &line, o, folds)?,
        },
        None => strip_fill(&fit, &line, o, 0)?,
    };
    // arc length from the loop to the pole, averaged over v (on a grid: the fills' grid
    // evaluations share their work across rows and columns, scattered points do not)
    let (nsu, nsv) = (65, 16);
    let us: Vec<f64> = (0..nsu).map(|i| i as f64 / (nsu - 1) as f64).collect();
    let vs: Vec<f64> = (0..nsv).map(|j| TAU * j as f64 / nsv as f64).collect();
    let g = filled.values(&us, &vs);
    let mut arc = vec![0.0; nsu];
    for j in 0..nsv {
        for i in 1..nsu {
            arc[i] += (g[i * nsv + j] - g[(i - 1) * nsv + j]).norm() / nsv as f64;
        }
    }
    for i in 1..nsu {
        arc[i] += arc[i - 1];
    }
    let total = arc[nsu - 1];
    let too_many = || LoopFillError::TooManyVertices { limit: o.max_vertices, ratio: lp.length / h };
    let rings_f = (total / h).round();
    if rings_f.is_nan() || rings_f > o.max_vertices as f64 {
        return Err(too_many());
    }
    let rings = (rings_f as usize).max(1);
    let u_at = |target: f64| -> f64 {
        let i = arc.partition_point(|&a| a < target).clamp(1, nsu - 1);
        let (a0, a1) = (arc[i - 1], arc[i]);
        let t = if a1 > a0 { (target - a0) / (a1 - a0) } else { 0.0 };
        us[i - 1] + t * (us[i] - us[i - 1])
    };
    // the rings from the fill's boundary (ring 0, its `v` set by the ring below it) to the
    // pole: (u, vertices)
    let mut plan = Vec::with_capacity(rings);
    // ring 0 and the band have fewer than 2 vertices a loop vertex
    let mut count = 2.0 * n as f64;
    // the rings' perimeters from one grid: the patch's data at each `v` once
    let ring_us: Vec<f64> =
        (0..rings).map(|j| if j == 0 { 0.0 } else { u_at(total * j as f64 / rings as f64) }).collect();
    let around: Vec<f64> = (0..=64).map(|k| TAU * k as f64 / 64.0).collect();
    let ring_pts = filled.values(&ring_us, &around);
    for (j, &u) in ring_us.iter().enumerate() {
        let pts = &ring_pts[j * around.len()..(j + 1) * around.len()];
        let perim: f64 = pts.windows(2).map(|w| (w[1] - w[0]).norm()).sum();
        let nj_f = (perim / h).round();
        if j > 0 {
            count += nj_f;
        }
        if nj_f.is_nan() || count > o.max_vertices as f64 {
            return Err(too_many());
        }
        plan.push((u, (nj_f as usize).max(3)));
    }
    // chart heights: −s in the band (scaled like v), then the fill's u above it
    let y_of_s = |s: f64| -TAU * s / period;
    let v_of_w = |w: f64| TAU * (w - w0).rem_euclid(period) / period;
    let s_top = fit.params.iter().fold(f64::INFINITY, |a, p| a.min(p.0)) - 2.0 * h;
    let lp_ring: Vec<(f64, f64, u32)> =
        fit.params.iter().zip(&lp.vertices).map(|(&(s, w), &v)| (TAU * (w - w0) / period, y_of_s(s), v)).collect();
    // the new triangles on the loop's edges (and the ears' on the input loop's) keep their
    // shape through the flips
    let on_seam: std::collections::HashSet<(u32, u32)> = [&original.1.vertices, &lp.vertices]
        .into_iter()
        .flat_map(|l| (0..l.len()).map(move |i| (l[(i + 1) % l.len()], l[i])))
        .collect();
    // the mesh of the band (or, without one, the loop zipped to the fill's boundary), the
    // rings and the pole, its edges flipped towards Delaunay when asked
    let build = |band: Option<&Band>, flips: bool| -> Option<(Vec<Vec3>, Vec<[u32; 3]>)> {
        let mut positions = Vec::new();
        let mut triangles = ears.clone();
        let mut ring_prev = match band {
            Some(b) => {
                positions.extend(b.vertices.iter().map(|v| v.p));
                triangles.extend(&b.triangles);
                let mut ring: Vec<(f64, f64, u32)> =
                    b.vertices.iter().enumerate().map(|(k, v)| (v_of_w(v.w), y_of_s(v.s), base + k as u32)).collect();
                let first = (0..ring.len()).min_by(|&a, &b| ring[a].0.total_cmp(&ring[b].0))?;
                ring.rotate_left(first);
                // the band's vertices must follow each other around the collar
                if !ring.windows(2).all(|w| w[0].0 < w[1].0) {
                    return None;
                }
                ring
            }
            None => lp_ring.clone(),
        };
        for (j, &(u, nj)) in plan.iter().enumerate() {
            let shift = if j % 2 == 1 { 0.5 } else { 0.0 };
            // the fill's boundary over the loop gets the loop's mid-`v`: a strip of quads
            let ring_v: Vec<f64> = if j == 0 && band.is_some() {
                // the band's vertices are spaced unevenly (splits, merges): evenly spaced
                (0..nj).map(|k| TAU * (k as f64 + 0.5) / nj as f64).collect()
            } else if j == 0 {
                let nl = ring_prev.len();
                (0..nl).map(|i| 0.5 * (ring_prev[i].0 + if i + 1 < nl { ring_prev[i + 1].0 } else { TAU })).collect()
            } else {
                (0..nj).map(|k| TAU * (k as f64 + shift) / nj as f64).collect()
            };
            let mut pts = filled.values(&[u], &ring_v);
            let mut ring_v = ring_v;
            if j == 0 && band.is_some() {
                // a boundary vertex nearer a band vertex than 0.4 h and `SHORTEST` of the
                // local median is left out (never three neighbours): the band's vertices
                // lie unevenly close to the boundary
                let near = |p: Vec3| {
                    band.is_some_and(|b| b.vertices.iter().any(|v| (v.p - p).norm() < max_nan(0.4 * h, SHORTEST * v.h)))
                };
                let mut keep = vec![true; pts.len()];
                for k in 0..pts.len() {
                    let prev_dropped = k > 1 && !keep[k - 1] && !keep[k - 2];
                    if !prev_dropped && near(pts[k]) && keep.iter().filter(|x| **x).count() > 3 {
                        keep[k] = false;
                    }
                }
                if !keep[0] && !keep[pts.len() - 1] {
                    keep[0] = true;
                }
                let mut it = keep.iter();
                pts.retain(|_| *it.next().unwrap_or(&true));
                let mut it = keep.iter();
                ring_v.retain(|_| *it.next().unwrap_or(&true));
            }
            let ring: Vec<(f64, f64, u32)> = ring_v
                .into_iter()
                .zip(pts)
                .map(|(v, p)| {
                    positions.push(p);
                    let y = if j == 0 { y_of_s(line.sigma(w0 + period * v / TAU)) } else { y_of_s(s_top) + u };
                    (v, y, base + positions.len() as u32 - 1)
                })
                .collect();
            let at = |i: u32| position(m, &positions, base, i);
            zip(&ring_prev, &ring, &at, &mut triangles);
            ring_prev = ring;
        }
        positions.push(filled.pole());
        let pole = base + positions.len() as u32 - 1;
        let np = ring_prev.len();
        for i in 0..np {
            triangles.push([ring_prev[(i + 1) % np].2, ring_prev[i].2, pole]);
        }
        if flips {
            let at = |i: u32| position(m, &positions, base, i);
            let exists = |a: u32, b: u32| a < base && b < base && adj[a as usize].binary_search(&b).is_ok();
            let budget = 8 * triangles.len();
            let frozen = |t: &[u32; 3]| (0..3).any(|k| on_seam.contains(&(t[k], t[(k + 1) % 3])));
            flip_to_delaunay(&mut triangles, &at, &exists, &frozen, budget);
        }
        Some((positions, triangles))
    };
    // the band over the loop's edges, flipped; else the loop zipped to the fill's
    // boundary, flipped; else that unflipped: the first whose triangles cross nothing
    let tries: Vec<(Option<&Band>, bool)> =
        band.as_ref().map(|b| (Some(b), true)).into_iter().chain([(None, true), (None, false)]).collect();
    let mut made = None;
    for (k, &(b, flips)) in tries.iter().enumerate() {
        let Some(mesh) = build(b, flips) else { continue };
        if crossing_free(original.0, &mesh.0, &mesh.1, base) {
            made = Some((mesh, true));
            break;
        }
        if k + 1 == tries.len() {
            made = Some((mesh, false));
        }
    }
    let ((positions, triangles), crossing_free) = made.ok_or(LoopFillError::Unstitched)?;
    // measures: the seam's dihedral angles and the new edges' lengths
    let at = |i: u32| position(m, &positions, base, i);
    let normal = |t: &[u32; 3]| (at(t[1]) - at(t[0])).cross(at(t[2]) - at(t[0]));
    let (m, lp) = (original.0, original.1);
    let n = lp.vertices.len();
    let on_loop = triangles_on_loop(m, lp);
    let mut seam_dihedral: f64 = 0.0;
    let mut edge_ratio = (f64::INFINITY, 0.0f64);
    let mut fill_of = std::collections::HashMap::new();
    // the local median at the loop vertex nearest a point (the first of equals; squared
    // distances order the vertices as distances do)
    let local_at = |p: Vec3| {
        let mut near = (f64::INFINITY, h);
        for (q, &l) in loop_pos.iter().zip(&local) {
            let e = *q - p;
            let d = e.dot(e);
            if d < near.0 {
                near = (d, l);
            }
        }
        // a point without a nearest vertex (NaN) has a NaN ratio through its length
        near.1
    };
    for t in &triangles {
        for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
            fill_of.insert((a, b), *t);
            let r = (at(a) - at(b)).norm() / local_at((at(a) + at(b)) * 0.5);
            edge_ratio = (crate::num::min_nan(edge_ratio.0, r), max_nan(edge_ratio.1, r));
        }
    }
    for (i, &tri) in on_loop.iter().enumerate() {
        let (a, b) = (lp.vertices[i], lp.vertices[(i + 1) % n]);
        let Some(ft) = fill_of.get(&(b, a)) else {
            return Err(LoopFillError::Unstitched);
        };
        let (n1, n2) = (m.face_normal(tri), normal(ft));
        let ang = n1.cross(n2).norm().atan2(n1.dot(n2));
        seam_dihedral = max_nan(seam_dihedral, ang);
    }
    Ok(LoopFill {
        fit,
        shape,
        willmore: willmore_energy,
        positions,
        triangles,
        continuity,
        seam_dihedral,
        edge_length: h,
        edge_ratio,
        crossing_free,
    })
}

/// The least room (in `h`) between a band vertex and the fill's boundary.
const BAND_CLEAR: f64 = 0.25;

/// The least room between a band vertex and the fill's boundary in the local median edge
/// length where the vertex stands. With a boundary vertex within `SHORTEST` of it left
/// out, no band edge to the boundary comes out shorter than half the local median on the
/// bench's meshes; at 0.25 the torus's band crossed the mesh (its fallback creased), at
/// 0.55 the boundary, lowered as a whole, moved the fill's largest distance to the torus
/// from 2.3e-3 to 2.7e-3.
const BAND_CLEAR_LOCAL: f64 = 0.35;

/// The fill's boundary in the collar's domain: `σ̄`, a spline on the spine's breakpoints
/// fitted to `s_i − 0.87 h` at the loop's vertices (the height of an equilateral triangle
/// on a loop edge), lowered where it comes within `0.4 h` of a vertex's `s_i` or within
/// `0.25 h` of a band vertex's `s`.
fn boundary_line(fit: &CollarFit, h: f64, band: &[BandVertex]) -> DomainLine {
    let b = &fit.spine_basis;
    let nc = b.len();
    let mut g = faer::Mat::<f64>::zeros(nc, nc);
    let mut r = faer::Mat::<f64>::zeros(nc, 1);
    for &(s, w) in &fit.params {
        let s = s - 0.87 * h;
        let (j0, bas) = b.basis(w, 0);
        for p in 0..4 {
            r[((j0 + p) % nc, 0)] += bas[0][p] * s;
            for q in 0..4 {
                g[((j0 + p) % nc, (j0 + q) % nc)] += bas[0][p] * bas[0][q];
            }
        }
    }
    for i in 0..nc {
        g[(i, i)] += 1e-9;
    }
    let sol = crate::lanes::after(g.full_piv_lu().solve(&r));
    let mut ctrl: Vec<f64> = (0..nc).map(|i| sol[(i, 0)]).collect();
    let line = DomainLine::new(b, &ctrl);
    let over = fit.params.iter().fold(f64::NEG_INFINITY, |a, &(s, w)| max_nan(a, line.sigma(w) - (s - 0.4 * h)));
    let over = band
        .iter()
        .fold(over, |a, b| max_nan(a, line.sigma(b.w) - (b.s - max_nan(BAND_CLEAR * h, BAND_CLEAR_LOCAL * b.h))));
    if over > 0.0 {
        // a spline's values shift with its control points (partition of unity)
        ctrl.iter_mut().for_each(|c| *c -= over);
    }
    DomainLine::new(b, &ctrl)
}

/// Closes the loop's sharp notches: a vertex where the loop turns towards the hole by an
/// interior angle below 100° and whose two neighbours lie within 1.5 `h` of each other gets
/// the triangle on its two edges (the loop then runs straight from one neighbour to the
/// other); never two neighbouring vertices in one pass, two passes, at least four vertices
/// left. Returns the triangles and the loop that remains.
fn clip_ears(m: &TriMesh, adj: &[Vec<u32>], lp: &MeshLoop, h: f64) -> (Vec<[u32; 3]>, Vec<u32>) {
    let on_loop = triangles_on_loop(m, lp);
    let mut verts: Vec<(u32, Vec3)> = lp
        .vertices
        .iter()
        .enumerate()
        .map(|(i, &v)| {
            let prev = on_loop[(i + lp.vertices.len() - 1) % lp.vertices.len()];
            let nrm = m.face_normal(on_loop[i]).normalized().unwrap_or(Vec3::ZERO)
                + m.face_normal(prev).normalized().unwrap_or(Vec3::ZERO);
            (v, nrm)
        })
        .collect();
    let mut ears = Vec::new();
    for _ in 0..2 {
        let n = verts.len();
        let mut clip = vec![false; n];
        for i in 0..n {
            if n - clip.iter().filter(|c| **c).count() <= 4 || clip[(i + n - 1) % n] {
                continue;
            }
            let (a, b, c) = (verts[(i + n - 1) % n].0, verts[i].0, verts[(i + 1) % n].0);
            let [pa, pb, pc] = [a, b, c].map(|v| m.positions[v as usize]);
            let (e1, e2) = (pa - pb, pc - pb);
            let right_turn = (pb - pa).cross(pc - pb).dot(verts[i].1) < 0.0;
            let angle = e1.cross(e2).norm().atan2(e1.dot(e2));
            let known = adj[a as usize].binary_search(&c).is_ok();
            if right_turn && angle < 100f64.to_radians() && (pc - pa).norm() <= 1.5 * h && !known && i + 1 < n {
                clip[i] = true;
                ears.push([c, b, a]);
            }
        }
        if !clip.contains(&true) {
            break;
        }
        verts = verts.into_iter().zip(&clip).filter(|(_, c)| !**c).map(|(v, _)| v).collect();
    }
    (ears, verts.into_iter().map(|v| v.0).collect())
}

/// The local median edge length at each loop vertex: the median length of the mesh's
/// edges at it and at its neighbours (some 20–30 edges: on a mesh whose edges differ by
/// direction, a vertex's own few edges on the loop's side would miss the mesh's density).
fn local_medians(m: &TriMesh, adj: &[Vec<u32>], verts: &[u32]) -> Vec<f64> {
    let len = |v: u32, w: u32| (m.positions[v as usize] - m.positions[w as usize]).norm();
    verts
        .iter()
        .map(|&v| {
            let mut lens: Vec<f64> = std::iter::once(v)
                .chain(adj[v as usize].iter().copied())
                .flat_map(|a| adj[a as usize].iter().map(move |&b| (a, b)))
                .filter(|&(a, b)| a == v || b != v)
                .map(|(a, b)| len(a, b))
                .collect();
            lens.sort_by(f64::total_cmp);
            lens[lens.len() / 2]
        })
        .collect()
}

/// The median length of the mesh's edges at the loop's vertices.
fn median_edge(m: &TriMesh, adj: &[Vec<u32>], lp: &MeshLoop) -> f64 {
    let mut lens: Vec<f64> = lp
        .vertices
        .iter()
        .flat_map(|&v| adj[v as usize].iter().map(move |&w| (v, w)))
        .map(|(v, w)| (m.positions[v as usize] - m.positions[w as usize]).norm())
        .collect();
    lens.sort_by(f64::total_cmp);
    lens[lens.len() / 2]
}

/// Triangulates the band between rings `a` and `b`, each `(v, y, vertex)` with `v`
/// increasing in `[0, 2π)` and `y` the height in a chart where `b` lies above `a`. Each
/// step adds the triangle that advances along `a` or along `b`: the one whose next vertex
/// comes first in `v` (the shorter new edge in space when the two are close), unless that
/// triangle is not clockwise in the chart `(v, y)` (it would turn over) and the other is.
fn zip(a: &[(f64, f64, u32)], b: &[(f64, f64, u32)], pos: &dyn Fn(u32) -> Vec3, out: &mut Vec<[u32; 3]>) {
    // the v-order step, unless its triangle turns over in the chart and the other does not
    let (na, nb) = (a.len(), b.len());
    let pa = |i: usize| if i < na { (a[i].0, a[i].1) } else { (a[i - na].0 + TAU, a[i - na].1) };
    let pb = |k: usize| if k < nb { (b[k].0, b[k].1) } else { (b[k - nb].0 + TAU, b[k - nb].1) };
    let cw = |p: (f64, f64), q: (f64, f64), r: (f64, f64)| (q.0 - p.0) * (r.1 - p.1) - (q.1 - p.1) * (r.0 - p.0) < 0.0;
    let (mut i, mut k) = (0, 0);
    while i < na || k < nb {
        let ok_a = i < na && cw(pa(i + 1), pa(i), pb(k));
        let ok_b = k < nb && cw(pa(i), pb(k), pb(k + 1));
        let by_v = k == nb || (i < na && pa(i + 1).0 <= pb(k + 1).0);
        let advance_a = match (ok_a, ok_b) {
            (true, true) => {
                // near a tie in v, the shorter new edge
                let da = (pos(a[(i + 1) % na].2) - pos(b[k % nb].2)).norm();
                let db = (pos(a[i % na].2) - pos(b[(k + 1) % nb].2)).norm();
                let (ga, gb) = (pa(i + 1).0 - pb(k).0, pb(k + 1).0 - pa(i).0);
                if (ga - gb).abs() < 0.25 * (ga + gb).abs() { da <= db } else { by_v }
            }
            (true, false) => true,
            (false, true) => false,
            (false, false) => by_v,
        };
        if advance_a {
            out.push([a[(i + 1) % na].2, a[i % na].2, b[k % nb].2]);
            i += 1;
        } else {
            out.push([a[i % na].2, b[k % nb].2, b[(k + 1) % nb].2]);
            k += 1;
        }
    }
}

/// The member of least Willmore energy `∫ H² dA` among a fill's two-parameter family,
/// `energy` giving it for `[x₀, x₁]` — the strip fill's fullness and pole height (from
/// `(1, 1)` within `[0.5, 2] × [0, 4]`, steps `(0.15, 0.4)`), the disc fill's `f` and `μ`
/// (from `(1, 0)` within `[0.5, 2] × [−3, 3]`, steps `(0.15, 0.5)`; order 4 has no `μ`).
/// Two rounds of coordinate descent: in each coordinate the energy at `x ± δ`, the vertex
/// of the parabola through the three (when it opens upwards; within `3δ` and the bounds),
/// and the lowest point kept; `δ` halved for the second round. Returns the member and its
/// energy.
///
/// Why this energy: G1 fixes the fill's boundary and tangent planes, so by Gauss–Bonnet
/// `∫ K dA` is fixed and `∫ (κ₁² + κ₂²) dA = ∫ (4H² − 2K) dA` differs from `4 ∫ H² dA`
/// by a constant: the fairest fill bends least. A sphere is a critical point of it, and
/// for a nearly flat surface `z(x, y)` it is `¼ ∫ (Δz)²`, whose minimisers (biharmonic
/// `z`) include every quadratic — what a hole in a smooth surface should be filled with.
/// The two parameters are what the G1/G2 conditions leave free to the fill's construction.
fn fairest(search: &Search, energy: impl Fn([f64; 2]) -> f64) -> ([f64; 2], f64) {
    let mut x = search.start;
    let mut e = energy(x);
    // NaN (a degenerate fill) never wins
    let better = |a: f64, b: f64| a < b || (b.is_nan() && !a.is_nan());
    let mut delta = search.delta;
    for _round in 0..2 {
        for k in [1, 0] {
            let d = delta[k];
            if d == 0.0 {
                continue;
            }
            let at = |t: f64| {
                let mut y = x;
                y[k] = t;
                energy(y)
            };
            let (lo, hi) = search.bounds[k];
            let (xm, xp) = ((x[k] - d).max(lo), (x[k] + d).min(hi));
            let (em, ep) = (at(xm), at(xp));
            let mut candidates = vec![(xm, em), (xp, ep)];
            if let Some(t) = vertex(xm, x[k], xp, em, e, ep) {
                let t = t.clamp(x[k] - 3.0 * d, x[k] + 3.0 * d).clamp(lo, hi);
                candidates.push((t, at(t)));
            }
            for (t, et) in candidates {
                if better(et, e) {
                    e = et;
                    x[k] = t;
                }
            }
        }
        delta = delta.map(|d| d / 2.0);
    }
    (x, e)
}

/// Where [`fairest`] starts, its bounds and its first steps (a zero step leaves that
/// coordinate alone).
struct Search {
    start: [f64; 2],
    bounds: [(f64, f64); 2],
    delta: [f64; 2],
}

/// The abscissa of the vertex of the parabola through `(a, fa)`, `(b, fb)`, `(c, fc)`
/// (`a < b < c`), when it opens upwards.
fn vertex(a: f64, b: f64, c: f64, fa: f64, fb: f64, fc: f64) -> Option<f64> {
    if !(a < b && b < c) {
        return None;
    }
    let (p, q) = ((b - a) * (fb - fc), (b - c) * (fb - fa));
    let den = 2.0 * (p - q);
    let opens_up = (fb - fa) / (b - a) < (fc - fb) / (c - b);
    (opens_up && den != 0.0).then(|| b - ((b - a) * p - (b - c) * q) / den)
}

/// `∫ H² dA` over the patch (`u ∈ [0, 1]`, periodic `v`) from its exact first and second
/// derivatives `g` on the grid of Gauss–Legendre nodes in `u` (weights `wu`) × `nv` even
/// points in `v` (the trapezoidal rule, spectrally accurate for periodic integrands).
/// `H = (L G − 2 M F + N E) / 2(EG − F²)`; points where `X_u × X_v` vanishes (the pole)
/// carry no area.
fn willmore(g: &[[Vec3; 6]], wu: &[f64], nv: usize) -> f64 {
    let mut sum = 0.0;
    for (i, w) in wu.iter().enumerate() {
        for j in 0..nv {
            let [_, xu, xv, xuu, xuv, xvv] = g[i * nv + j];
            let n = xu.cross(xv);
            let a = n.norm();
            if a == 0.0 {
                continue;
            }
            let n = n / a;
            let (e, f, gg) = (xu.dot(xu), xu.dot(xv), xv.dot(xv));
            let (l, m, nn) = (xuu.dot(n), xuv.dot(n), xvv.dot(n));
            let h = (l * gg - 2.0 * m * f + nn * e) / (2.0 * (e * gg - f * f));
            sum += w * (TAU / nv as f64) * h * h * a;
        }
    }
    sum
}

#[cfg(test)]
mod fairness_tests {
    use super::vertex;

    /// The vertex of `3 (x − 0.7)² + 2` from three points, on uneven spacing; none for a
    /// parabola opening downwards or points out of order.
    #[test]
    fn parabola_vertex() {
        let f = |x: f64| 3.0 * (x - 0.7) * (x - 0.7) + 2.0;
        let (a, b, c) = (0.2, 0.5, 1.3);
        let v = vertex(a, b, c, f(a), f(b), f(c)).unwrap();
        // three values of size ~2 and a division by differences of ~1: round-off ~1e-15
        assert!((v - 0.7).abs() < 1e-14, "{v}");
        assert_eq!(vertex(a, b, c, -f(a), -f(b), -f(c)), None);
        assert_eq!(vertex(a, a, c, f(a), f(a), f(c)), None);
    }
}
