//! The holes of a boundary representation: its free edges (used by one face only)
//! chained into loops.
//!
//! In a consistently oriented shell every loop has its face on the left, so along the
//! free boundary the uses of the free edges follow each other head to tail: a hole is a
//! cycle of such uses, run the way its faces run them.
//!
//! **Parts that touch.** Where two parts of a model touch at a point, each has its own
//! vertex there (different entities at the same place), and the gap between them is a
//! loop that runs along one part's edges and back along the other's. Vertices within
//! 1e-7 of the model's size of each other are one point for the chaining; where more than
//! one free edge leaves such a point, the loop takes the sharpest turn to the right (seen
//! from the face's normal, the side where the hole is, the face being on the left), which
//! closes the smallest loop around the gap. Two free edges leaving the same vertex entity
//! remain a loop that touches itself.

use super::{Brep, BrepFace};
use crate::Vec3;
use crate::classes::Classes;
use crate::data::analytic::Frame;
use crate::fill::foot_of;
use crate::jet::JetShape;
use crate::num::{max_nan, min_nan};

/// One edge of a hole, as the face around it uses it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HoleUse {
    /// The edge (index into [`Brep::edges`]).
    pub edge: usize,
    /// Whether the face runs it from its start to its end vertex.
    pub forward: bool,
    /// The face (index into [`Brep::faces`]).
    pub face: usize,
}

impl HoleUse {
    /// The vertices (indices into [`Brep::vertices`]) the face's run of the edge starts
    /// and ends at.
    pub fn ends(&self, b: &Brep) -> (usize, usize) {
        let v = b.edges[self.edge].vertices;
        if self.forward { (v[0], v[1]) } else { (v[1], v[0]) }
    }
}

/// What a loop of free edges is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum HoleKind {
    /// A simple closed loop: a hole.
    Simple,
    /// The loop passes a vertex twice (where more than one free edge leaves it).
    TouchesItself,
    /// The chain of free edges does not close (the faces around are not oriented
    /// consistently, or an edge is missing).
    Open,
}

/// A corner of a hole: the vertex between two consecutive edges.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Corner {
    /// The vertex (index into [`Brep::vertices`]).
    pub vertex: usize,
    /// The angle (radians) between the two faces' normals there: 0 when they meet G1;
    /// NaN where a surface is singular or the vertex's foot is not found.
    pub angle: f64,
}

/// A loop of free edges.
#[derive(Clone, Debug, PartialEq)]
pub struct Hole {
    /// Its edges in loop order.
    pub uses: Vec<HoleUse>,
    /// What it is.
    pub kind: HoleKind,
    /// Its length.
    pub length: f64,
    /// The corners: at the end of each use (the vertex it shares with the next).
    pub corners: Vec<Corner>,
    /// Bounding box of the edges' points (33 per edge).
    pub bbox: (Vec3, Vec3),
}

/// The bounding box of 33 points per edge of `uses` (ends included), each placed by
/// `placement` (its frame coordinates are the model's points).
fn edge_box(b: &Brep, uses: &[HoleUse], placement: &Frame) -> (Vec3, Vec3) {
    let mut lo = Vec3::new(f64::INFINITY, f64::INFINITY, f64::INFINITY);
    let mut hi = -lo;
    for u in uses {
        let e = &b.edges[u.edge];
        for i in 0..=32 {
            let p = placement.global(e.point(e.range.0 + (e.range.1 - e.range.0) * i as f64 / 32.0));
            lo = Vec3::new(min_nan(lo.x, p.x), min_nan(lo.y, p.y), min_nan(lo.z, p.z));
            hi = Vec3::new(max_nan(hi.x, p.x), max_nan(hi.y, p.y), max_nan(hi.z, p.z));
        }
    }
    (lo, hi)
}

impl Hole {
    /// The bounding box of the hole placed by `placement` (a copy of its part placed by
    /// an assembly): the same points as [`Hole::bbox`], moved.
    pub fn placed_bbox(&self, b: &Brep, placement: &Frame) -> (Vec3, Vec3) {
        edge_box(b, &self.uses, placement)
    }

    /// The faces around, each once, in loop order.
    pub fn faces(&self) -> Vec<usize> {
        let mut out: Vec<usize> = Vec::new();
        for u in &self.uses {
            if !out.contains(&u.face) {
                out.push(u.face);
            }
        }
        out
    }
}

fn oriented_normal(f: &BrepFace, p: Vec3) -> Option<Vec3> {
    let s = f.surface.as_ref()?;
    let c = foot_of(s.field().as_ref(), p, f.start_grid()?.start(p), 0.0)?;
    let n = s.normal(c)?;
    Some(if f.same_sense { n } else { -n })
}

/// For each vertex, the smallest index of the vertices within `tol` of it (transitively):
/// one point where parts touch.
fn touching(b: &Brep, tol: f64) -> Vec<usize> {
    let n = b.vertices.len();
    let mut rep = Classes::new(n);
    if !(tol.is_finite() && tol > 0.0) {
        return rep.all();
    }
    // points hashed to cells of side `tol`: each compared with those of its cell and
    // the 26 around (sorting on one axis went quadratic on a model flat in that axis);
    // NaN points and points beyond the cells' range stay alone
    let cell = |p: Vec3| {
        let c = [p.x / tol, p.y / tol, p.z / tol];
        c.iter().all(|x| x.abs() < 1e15).then(|| c.map(|x| x.floor() as i64))
    };
    let mut cells: std::collections::HashMap<[i64; 3], Vec<usize>> = std::collections::HashMap::new();
    for i in 0..n {
        if let Some(c) = cell(b.vertices[i].1) {
            cells.entry(c).or_default().push(i);
        }
    }
    for i in 0..n {
        let Some(c) = cell(b.vertices[i].1) else { continue };
        for d in 0..27 {
            let key = [c[0] + d % 3 - 1, c[1] + (d / 3) % 3 - 1, c[2] + d / 9 - 1];
            for &j in cells.get(&key).map_or(&[][..], Vec::as_slice) {
                if j > i && (b.vertices[j].1 - b.vertices[i].1).norm() <= tol {
                    rep.join(i, j);
                }
            }
        }
    }
    rep.all()
}

/// The unit tangent of `u` at its start (`end = false`) or end, in the direction the face
/// runs it (NaN without a curve).
fn tangent(b: &Brep, u: &HoleUse, end: bool) -> Vec3 {
    let e = &b.edges[u.edge];
    let Some(c) = &e.curve else { return Vec3::new(f64::NAN, f64::NAN, f64::NAN) };
    let (a, z) = if u.forward { e.range } else { (e.range.1, e.range.0) };
    let tau = if end { z } else { a };
    let d = c.field().jet(&[tau], JetShape::new(&[1])).derivative([1, 0, 0]);
    let d = if (z - a) >= 0.0 { d } else { -d };
    d.normalized().unwrap_or(Vec3::new(f64::NAN, f64::NAN, f64::NAN))
}

/// The free boundary of `b` as loops, in the order of their first edge in the file.
pub fn holes(b: &Brep) -> Vec<Hole> {
    let mut count = vec![0usize; b.edges.len()];
    let mut owner = vec![None; b.edges.len()];
    for (fi, f) in b.faces.iter().enumerate() {
        for l in &f.loops {
            for &(e, fwd) in l {
                count[e] += 1;
                owner[e] = Some(HoleUse { edge: e, forward: fwd, face: fi });
            }
        }
    }
    let free: Vec<HoleUse> = (0..b.edges.len()).filter(|&e| count[e] == 1).filter_map(|e| owner[e]).collect();
    let ends = |u: &HoleUse| u.ends(b);
    // (a NaN size merges nothing)
    let rep = touching(b, 1e-7 * b.size());
    let at_rep = |u: &HoleUse| {
        let (s, e) = ends(u);
        (rep[s], rep[e])
    };
    let mut taken = vec![false; free.len()];
    let mut out = Vec::new();
    for first in 0..free.len() {
        if taken[first] {
            continue;
        }
        taken[first] = true;
        let mut uses = vec![free[first]];
        let start = at_rep(&free[first]).0;
        let mut at = at_rep(&free[first]).1;
        let mut kind = HoleKind::Simple;
        while at != start {
            let next: Vec<usize> = (0..free.len()).filter(|&k| !taken[k] && at_rep(&free[k]).0 == at).collect();
            let last = *uses.last().expect("a loop has its first use");
            // two free uses leaving the vertex entity this one ends at: the loop
            // touches itself there
            if next.iter().filter(|&&k| ends(&free[k]).0 == ends(&last).1).count() > 1 {
                kind = HoleKind::TouchesItself;
            }
            let k = if next.len() > 1 {
                // where parts touch: the sharpest turn to the right, about the normal of
                // the face arriving (NaN turns last)
                let p = b.vertices[ends(&last).1].1;
                let f = &b.faces[last.face];
                let n = oriented_normal(f, p);
                let t_in = tangent(b, &last, true);
                let turn = |k: usize| {
                    let t = tangent(b, &free[k], false);
                    let a = n.map_or(f64::NAN, |n| n.dot(t_in.cross(t)).atan2(t_in.dot(t)));
                    if a.is_nan() { f64::INFINITY } else { a }
                };
                next.iter().copied().min_by(|&i, &j| turn(i).total_cmp(&turn(j)))
            } else {
                next.first().copied()
            };
            let Some(k) = k else {
                kind = HoleKind::Open;
                break;
            };
            taken[k] = true;
            uses.push(free[k]);
            at = at_rep(&free[k]).1;
        }
        // a vertex entity left by two free edges: the loop touches itself there
        if kind == HoleKind::Simple
            && (0..free.len()).any(|k| !uses.contains(&free[k]) && uses.iter().any(|u| ends(u).0 == ends(&free[k]).0))
        {
            kind = HoleKind::TouchesItself;
        }
        // a point passed twice
        let mut passed: Vec<usize> = uses.iter().map(|u| at_rep(u).0).collect();
        passed.sort_unstable();
        if kind == HoleKind::Simple && passed.windows(2).any(|w| w[0] == w[1]) {
            kind = HoleKind::TouchesItself;
        }
        let length: f64 = uses.iter().map(|u| b.edges[u.edge].length()).sum();
        let (lo, hi) = edge_box(b, &uses, &Frame::WORLD);
        let corners = if kind == HoleKind::Open {
            Vec::new()
        } else {
            (0..uses.len())
                .map(|k| {
                    let (a, c) = (&uses[k], &uses[(k + 1) % uses.len()]);
                    let vertex = ends(a).1;
                    let p = b.vertices[vertex].1;
                    let (fa, fc) = (&b.faces[a.face], &b.faces[c.face]);
                    let angle = match (oriented_normal(fa, p), oriented_normal(fc, p)) {
                        (Some(n), Some(m)) => n.cross(m).norm().atan2(n.dot(m)),
                        _ => f64::NAN,
                    };
                    Corner { vertex, angle }
                })
                .collect()
        };
        out.push(Hole { uses, kind, length, corners, bbox: (lo, hi) });
    }
    out
}
