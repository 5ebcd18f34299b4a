//! The holes of a boundary representation: its free edges (used by one face only)
//! chained into loops.
//!
//! In a consistently oriented shell every loop has its face on the left, so along the
//! free boundary the uses of the free edges follow each other head to tail: a hole is a
//! cycle of such uses, run the way its faces run them.

use super::{Brep, FaceSurface};
use crate::Vec3;
use crate::fill::foot_of;
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

impl Hole {
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

fn oriented_normal(s: Option<&FaceSurface>, same_sense: bool, p: Vec3) -> Option<Vec3> {
    let s = s?;
    let c = foot_of(s.field().as_ref(), p, s.invert_near(p), 0.0)?;
    let n = s.normal(c)?;
    Some(if same_sense { n } else { -n })
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
    let ends = |u: &HoleUse| {
        let v = b.edges[u.edge].vertices;
        if u.forward { (v[0], v[1]) } else { (v[1], v[0]) }
    };
    let mut taken = vec![false; free.len()];
    let mut out = Vec::new();
    for first in 0..free.len() {
        if taken[first] {
            continue;
        }
        taken[first] = true;
        let mut uses = vec![free[first]];
        let start = ends(&free[first]).0;
        let mut at = ends(&free[first]).1;
        let mut kind = HoleKind::Simple;
        while at != start {
            let next: Vec<usize> = (0..free.len()).filter(|&k| !taken[k] && ends(&free[k]).0 == at).collect();
            let Some(&k) = next.first() else {
                kind = HoleKind::Open;
                break;
            };
            if next.len() > 1 {
                kind = HoleKind::TouchesItself;
            }
            taken[k] = true;
            uses.push(free[k]);
            at = ends(&free[k]).1;
        }
        // a vertex left by two free edges: the loop touches itself there
        if kind == HoleKind::Simple
            && (0..free.len()).any(|k| !uses.contains(&free[k]) && uses.iter().any(|u| ends(u).0 == ends(&free[k]).0))
        {
            kind = HoleKind::TouchesItself;
        }
        let mut lo = Vec3::new(f64::INFINITY, f64::INFINITY, f64::INFINITY);
        let mut hi = -lo;
        let mut length = 0.0;
        for u in &uses {
            let e = &b.edges[u.edge];
            length += e.length();
            for i in 0..=32 {
                let p = e.point(e.range.0 + (e.range.1 - e.range.0) * i as f64 / 32.0);
                lo = Vec3::new(min_nan(lo.x, p.x), min_nan(lo.y, p.y), min_nan(lo.z, p.z));
                hi = Vec3::new(max_nan(hi.x, p.x), max_nan(hi.y, p.y), max_nan(hi.z, p.z));
            }
        }
        let corners = if kind == HoleKind::Open {
            Vec::new()
        } else {
            (0..uses.len())
                .map(|k| {
                    let (a, c) = (&uses[k], &uses[(k + 1) % uses.len()]);
                    let vertex = ends(a).1;
                    let p = b.vertices[vertex].1;
                    let (fa, fc) = (&b.faces[a.face], &b.faces[c.face]);
                    let angle = match (
                        oriented_normal(fa.surface.as_ref(), fa.same_sense, p),
                        oriented_normal(fc.surface.as_ref(), fc.same_sense, p),
                    ) {
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
