//! A hole of a boundary representation filled by a fill of order 4 (G1) or 6 (G2):
//! each edge of the hole, as its face uses it, becomes a fill edge on that face — the
//! face's surface reparametrised around the edge's foot curve ([`FootCurve`] inside an
//! [`AlongCurve`]) — and the cross tangent points away from the face's side.
//!
//! **Which side.** Along an edge run as its face runs it, the face lies on the left seen
//! from the face's normal. In the surface's `(u, v)`, whose normal is `S_u × S_v`, that
//! is the left of the foot curve's direction when the face is `same_sense`, the right
//! otherwise. The fill edge's `σ` grows along `ν = (−c₂′, c₁′)`, the left of increasing
//! `τ`; with `d = ±1` the direction of `τ` along the run, the hole is on the side
//! `−d ν` (`same_sense`) or `+d ν`, which is [`FillEdge::side`].
//!
//! **The foot curve, tabulated.** The foot curve is found once per piece as a piecewise
//! Chebyshev series ([`FootSeries`], the exact feet interpolated, its distance from them
//! measured between the nodes within [`series_tolerance`]); the fill's data are
//! evaluated at thousands of `v` by the new face's fit, and each exact foot costs a
//! Newton solve and a Taylor expansion. The series lies on the face, so G1/G2 to it are
//! unchanged; where no series meets the tolerance the exact foot curve is used.
//!
//! A loop of fewer than three edges (a single closed edge, two arcs) is cut into three or
//! four pieces at equal parameter steps; the cuts are not corners of the neighbours (one
//! face on both sides), so the fill is G1 there like anywhere along the edge.

use super::{Brep, Hole, HoleKind, HoleUse};
use crate::data::{Field, FieldRef};
use crate::fill::{
    AlongCurve, DomainCurve, Fill, FillEdge, FillError, FillOptions, FootCurve, FootError, FootSeries, Host,
};
use crate::num::max_nan;
use std::sync::Arc;

/// A filled hole.
pub struct HoleFill {
    /// The fill.
    pub fill: Fill,
    /// The fill's edges: (the hole's use, the edge curve's parameter range run).
    pub pieces: Vec<(usize, (f64, f64))>,
    /// The largest distance between an edge's curve and its foot on the face (how far
    /// the file's edges lie off their faces).
    pub edge_offset: f64,
}

/// Why a hole is not filled.
#[derive(Debug, thiserror::Error)]
pub enum HoleFillError {
    /// Not a simple loop.
    #[error("the loop is not a simple hole ({0:?})")]
    NotSimple(HoleKind),
    /// An edge's foot curve on its face.
    #[error("edge #{edge} on face #{face}: {err}")]
    Foot {
        /// The edge's id.
        edge: u64,
        /// The face's id.
        face: u64,
        /// What failed.
        err: FootError,
    },
    /// A face or edge of the hole has geometry of a kind not read.
    #[error("{0} has geometry of a kind that is not read")]
    Unsupported(String),
    /// The fill.
    #[error(transparent)]
    Fill(#[from] FillError),
}

/// Fills `hole` of `b` with `options` (its order 4 or 6).
pub fn fill_hole(b: &Brep, hole: &Hole, options: &FillOptions) -> Result<HoleFill, HoleFillError> {
    if hole.kind != HoleKind::Simple {
        return Err(HoleFillError::NotSimple(hole.kind));
    }
    fill_uses(b, &hole.uses, options)
}

/// Fills the loop of edges `uses` of `b` (each run as its face runs it, each ending where
/// the next starts, the last where the first starts) with `options`: what [`fill_hole`]
/// does for a hole, for any closed chain of edges a caller names.
pub fn fill_uses(b: &Brep, uses: &[HoleUse], options: &FillOptions) -> Result<HoleFill, HoleFillError> {
    let cuts = pieces_per_edge(uses.len());
    let mut pieces = Vec::new();
    let mut edges = Vec::new();
    let mut edge_offset: f64 = 0.0;
    for (k, u) in uses.iter().enumerate() {
        let p = edge_pieces(b, u, cuts, options.t)?;
        edge_offset = max_nan(edge_offset, p.offset);
        pieces.extend(p.ranges.into_iter().map(|r| (k, r)));
        edges.extend(p.edges);
    }
    let fill = Fill::new(&edges, options)?;
    Ok(HoleFill { fill, pieces, edge_offset })
}

/// Into how many fill edges each edge of a loop of `n` edges is cut: a loop of fewer than
/// three edges is cut into three or four pieces (module docs).
pub fn pieces_per_edge(n: usize) -> usize {
    match n {
        1 => 3,
        2 => 2,
        _ => 1,
    }
}

/// An edge of a B-rep as fill edges on its face.
pub struct EdgePieces {
    /// The fill edges, in the order the face runs the edge (cross tangent away from the
    /// face, fullness 1).
    pub edges: Vec<FillEdge>,
    /// Each piece's range of the edge curve's parameter, as run.
    pub ranges: Vec<(f64, f64)>,
    /// The largest distance between the edge's curve and its foot on the face.
    pub offset: f64,
}

/// The edge of `u`, run as its face runs it, cut into `cuts` fill edges of equal
/// parameter steps on the face's surface reparametrised around the edge's foot curve (at
/// time `t`).
pub fn edge_pieces(b: &Brep, u: &HoleUse, cuts: usize, t: f64) -> Result<EdgePieces, HoleFillError> {
    let e = &b.edges[u.edge];
    let f = &b.faces[u.face];
    let (a, z) = if u.forward { e.range } else { (e.range.1, e.range.0) };
    let (Some(surface), Some(ec)) = (&f.surface, &e.curve) else {
        let what = if f.surface.is_none() { format!("face #{}", f.id) } else { format!("edge #{}", e.id) };
        return Err(HoleFillError::Unsupported(what));
    };
    let host = surface.field();
    let curve = ec.field();
    // a C¹ face and a C¹ edge curve: the face's frame along the edge has no jump, and no
    // crease is looked for
    let smooth_face = surface.is_c1();
    let mut out = EdgePieces { edges: Vec::new(), ranges: Vec::new(), offset: 0.0 };
    for c in 0..cuts {
        let ta = a + (z - a) * c as f64 / cuts as f64;
        let tb = a + (z - a) * (c + 1) as f64 / cuts as f64;
        let start = f.start_grid().expect("the face has a surface").start(curve.eval(&[ta]));
        let foot = FootCurve::new(host.clone(), curve.clone(), (ta, tb), start, t)
            .map_err(|err| HoleFillError::Foot { edge: e.id, face: f.id, err })?;
        out.offset = max_nan(out.offset, foot.max_distance());
        let dir = if tb >= ta { 1.0 } else { -1.0 };
        let side = if f.same_sense { -dir } else { dir };
        let domain: FieldRef = match FootSeries::new(&foot, (ta, tb), series_tolerance(&*curve, (ta, tb))) {
            Some(series) => Arc::new(series),
            None => Arc::new(foot),
        };
        let along = AlongCurve { host: Host::Field(host.clone()), curve: DomainCurve::Field(domain) };
        out.edges.push(FillEdge {
            surface: Arc::new(along),
            s0: 0.0,
            w: (ta, tb),
            fullness: 1.0,
            side: Some(side),
            smooth: smooth_face && ec.is_c1(),
        });
        out.ranges.push((ta, tb));
    }
    Ok(out)
}

/// How far the tabulated foot ([`FootSeries`]) may move the fill's edge along the face:
/// 1e-13 of the edge's size (the largest coordinate of its ends and midpoint, plus its
/// chord), a few hundred units of round-off of its coordinates. The seam tolerances of
/// the new faces' fits are 3e-10 of the model's size and above.
fn series_tolerance(curve: &dyn Field, (a, b): (f64, f64)) -> f64 {
    let p = [curve.eval(&[a]), curve.eval(&[0.5 * (a + b)]), curve.eval(&[b])];
    let size = p.iter().fold(0.0, |m, q| max_nan(m, q.norm())) + (p[2] - p[0]).norm() + (p[1] - p[0]).norm();
    1e-13 * size
}
