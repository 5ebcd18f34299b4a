//! A mesh's topology checked, and its boundary edges chained into loops.
//!
//! In an oriented 2-manifold with boundary each interior edge is run once in each
//! direction by its two triangles and each boundary edge once by its one triangle. The
//! boundary half-edges then follow each other head to tail around every hole, the mesh on
//! their left: a loop is a cycle of them, run the way the mesh runs them. A vertex where
//! more than one boundary half-edge leaves (two holes meeting at a point, or a loop that
//! pinches) makes its loops [`LoopKind::TouchesItself`].
//!
//! **Hole, rim or open end.** Topology alone cannot tell a hole from the rim of an open
//! sheet: both are a loop with the mesh on one side. Geometry can. Let `A = ½ Σ pᵢ × pᵢ₊₁`
//! be the loop's vector area (its axis, by the right-hand rule along the loop) and `N` the
//! sum of the (area-weighted) normals of the triangles at its vertices. Running with the
//! mesh on its left, a loop goes clockwise about the mesh's normal around a hole (the
//! mesh lies outside it) and counter-clockwise along a rim (the mesh lies inside), so the
//! facing `f = Â · N / Σ|nₜ|` — the mean unit normal's component along the loop's axis —
//! is near −1 for a hole in a gently curved surface and near +1 for a rim. Around a tube
//! or a handle (a cylinder's end), or the rim of a bowl, the normals lie across the axis
//! and `f` is near 0. The loop is a hole for `f ≤ −⅓`, a rim for `f ≥ ⅓`, an open end
//! between: a spherical cap hole of half-angle θ gives `f = −cos θ`, a hole up to 70°.

use super::TriMesh;
use crate::Vec3;
use std::collections::HashMap;

/// What makes a mesh unusable, with the element's index.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum TopologyError {
    /// A coordinate is NaN or infinite.
    #[error("vertex {vertex}: a coordinate is not finite")]
    NonFinite {
        /// The vertex (from 0).
        vertex: usize,
    },
    /// A triangle names a vertex that does not exist.
    #[error("triangle {triangle}: vertex index {index} is out of range (the mesh has {count} vertices)")]
    IndexOutOfRange {
        /// The triangle (from 0).
        triangle: usize,
        /// The index.
        index: u32,
        /// The vertex count.
        count: usize,
    },
    /// A triangle repeats a vertex or has no area.
    #[error("triangle {triangle} is degenerate ({why})")]
    Degenerate {
        /// The triangle (from 0).
        triangle: usize,
        /// `a repeated vertex` or `zero area`.
        why: &'static str,
    },
    /// Two triangles on the same three vertices.
    #[error("triangle {triangle} repeats triangle {first} (the same three vertices)")]
    Duplicate {
        /// The later triangle.
        triangle: usize,
        /// The earlier one.
        first: usize,
    },
    /// An edge of more than two triangles.
    #[error("edge ({a}, {b}) is non-manifold: triangles {triangles:?} share it")]
    NonManifold {
        /// Its vertices.
        a: u32,
        /// Its vertices.
        b: u32,
        /// The triangles that share it.
        triangles: Vec<usize>,
    },
    /// Two triangles run an edge the same way: the mesh is not consistently oriented.
    #[error(
        "edge ({a}, {b}) is run the same way by triangles {first} and {second}: the mesh is not consistently oriented"
    )]
    Orientation {
        /// The edge's tail.
        a: u32,
        /// Its head.
        b: u32,
        /// The first triangle.
        first: usize,
        /// The second.
        second: usize,
    },
}

/// What a boundary loop is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LoopKind {
    /// A simple loop with the mesh around it, facing `f ≤ −⅓`: a hole.
    Hole,
    /// A simple loop around the mesh, facing `f ≥ ⅓`: the rim of an open sheet.
    Rim,
    /// A simple loop with the normals across its axis, `|f| < ⅓`: the end of a tube, a
    /// cut through a handle, the rim of a bowl.
    OpenEnd,
    /// The loop passes a vertex where more than one boundary edge leaves.
    TouchesItself,
}

/// A loop of boundary edges.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshLoop {
    /// Its vertices, in the direction the mesh runs its edges (the mesh on the left).
    pub vertices: Vec<u32>,
    /// What it is.
    pub kind: LoopKind,
    /// Its length.
    pub length: f64,
    /// Its bounding box.
    pub bbox: (Vec3, Vec3),
    /// The facing `f` (see the module's documentation): −1 a hole, +1 a rim.
    pub facing: f64,
}

impl LoopKind {
    /// How `holes` names it.
    pub fn name(self) -> &'static str {
        match self {
            LoopKind::Hole => "hole",
            LoopKind::Rim => "rim",
            LoopKind::OpenEnd => "open end",
            LoopKind::TouchesItself => "touches itself",
        }
    }
}

/// The half-edges of a mesh's first triangles, by tail vertex: `(head, triangle)` for every
/// directed edge `tail → head` a triangle runs, in triangle order. A vertex has a handful,
/// so looking one up scans a few entries where a hash map of all the mesh's half-edges
/// hashed each (three passes of it were most of reading a mesh).
pub(super) struct HalfEdges {
    start: Vec<usize>,
    out: Vec<(u32, usize)>,
}

impl HalfEdges {
    /// Of `m.triangles[..count]`, whose indices must be in range.
    pub(super) fn new(m: &TriMesh, count: usize) -> HalfEdges {
        let tris = &m.triangles[..count];
        let mut start = vec![0usize; m.positions.len() + 1];
        for t in tris {
            for &v in t {
                start[v as usize + 1] += 1;
            }
        }
        for i in 0..m.positions.len() {
            start[i + 1] += start[i];
        }
        let mut fill = start.clone();
        let mut out = vec![(0u32, 0usize); start[m.positions.len()]];
        for (t, &[a, b, c]) in tris.iter().enumerate() {
            for (x, y) in [(a, b), (b, c), (c, a)] {
                out[fill[x as usize]] = (y, t);
                fill[x as usize] += 1;
            }
        }
        HalfEdges { start, out }
    }

    /// The half-edges leaving `x`, in triangle order.
    pub(super) fn from(&self, x: u32) -> &[(u32, usize)] {
        &self.out[self.start[x as usize]..self.start[x as usize + 1]]
    }

    /// The first triangle before `before` that runs `x → y`.
    fn first(&self, x: u32, y: u32, before: usize) -> Option<usize> {
        self.from(x).iter().find(|&&(h, t)| h == y && t < before).map(|&(_, t)| t)
    }

    /// Whether any triangle runs `x → y`.
    fn has(&self, x: u32, y: u32) -> bool {
        self.from(x).iter().any(|&(h, _)| h == y)
    }
}

/// Checks that `m` is an oriented 2-manifold with boundary and returns its boundary loops
/// (longest first is not implied: in the order their first half-edges appear).
///
/// The first triangle (in order) with something wrong is reported: its own faults (an
/// index out of range, a repeated vertex, no area) before those it has with the triangles
/// before it (the same three vertices, an edge run twice the same way, or by a third).
pub fn boundary(m: &TriMesh) -> Result<Vec<MeshLoop>, TopologyError> {
    let nv = m.positions.len();
    if let Some(vertex) = m.positions.iter().position(|p| !p.is_finite()) {
        return Err(TopologyError::NonFinite { vertex });
    }
    // the first triangle faulty on its own; the half-edges of those before it
    let own = m.triangles.iter().enumerate().find_map(|(t, tri)| {
        if let Some(&index) = tri.iter().find(|&&i| i as usize >= nv) {
            return Some(TopologyError::IndexOutOfRange { triangle: t, index, count: nv });
        }
        let [a, b, c] = *tri;
        if a == b || b == c || a == c {
            return Some(TopologyError::Degenerate { triangle: t, why: "a repeated vertex" });
        }
        (m.face_normal(t) == Vec3::ZERO).then_some(TopologyError::Degenerate { triangle: t, why: "zero area" })
    });
    let count = match &own {
        Some(TopologyError::IndexOutOfRange { triangle, .. } | TopologyError::Degenerate { triangle, .. }) => *triangle,
        _ => m.triangles.len(),
    };
    let half = HalfEdges::new(m, count);
    for (t, tri) in m.triangles[..count].iter().enumerate() {
        let [a, b, c] = *tri;
        let mut key = *tri;
        key.sort_unstable();
        // an earlier triangle on the same three vertices runs an edge of this one
        let same = |&(h, s): &(u32, usize)| {
            s < t && tri.contains(&h) && {
                let mut k = m.triangles[s];
                k.sort_unstable();
                k == key
            }
        };
        if let Some(first) = tri.iter().flat_map(|&v| half.from(v).iter().filter(|e| same(e))).map(|e| e.1).min() {
            return Err(TopologyError::Duplicate { triangle: t, first });
        }
        for (x, y) in [(a, b), (b, c), (c, a)] {
            if let Some(first) = half.first(x, y, t) {
                // a third triangle on an edge run both ways already is non-manifold
                if let Some(other) = half.first(y, x, t) {
                    return Err(TopologyError::NonManifold {
                        a: x.min(y),
                        b: x.max(y),
                        triangles: vec![first, other, t],
                    });
                }
                return Err(TopologyError::Orientation { a: x, b: y, first, second: t });
            }
        }
    }
    if let Some(e) = own {
        return Err(e);
    }
    // more than two triangles on one undirected edge shows as both directions taken and a
    // third use; caught above. Boundary half-edges: those whose twin is missing.
    let mut out: HashMap<u32, Vec<u32>> = HashMap::new();
    let mut starts: Vec<(usize, u32, u32)> = Vec::new();
    for (t, tri) in m.triangles.iter().enumerate() {
        let [a, b, c] = *tri;
        for (x, y) in [(a, b), (b, c), (c, a)] {
            if !half.has(y, x) {
                starts.push((t, x, y));
                out.entry(x).or_default().push(y);
            }
        }
    }
    for v in out.values_mut() {
        v.sort_unstable();
    }
    let mut used: HashMap<(u32, u32), bool> = HashMap::new();
    let mut loops = Vec::new();
    for &(_, x0, y0) in &starts {
        if used.contains_key(&(x0, y0)) {
            continue;
        }
        let mut vertices = vec![x0];
        let mut pinched = out[&x0].len() > 1;
        let (mut x, mut y) = (x0, y0);
        loop {
            used.insert((x, y), true);
            if y == x0 {
                break;
            }
            vertices.push(y);
            let next = &out[&y];
            pinched |= next.len() > 1;
            // the first unused boundary half-edge leaving y (every vertex of a boundary
            // half-edge's head has one leaving it: the mesh's edges are paired)
            let Some(&z) = next.iter().find(|&&z| !used.contains_key(&(y, z))) else { break };
            (x, y) = (y, z);
        }
        let pts: Vec<Vec3> = vertices.iter().map(|&i| m.positions[i as usize]).collect();
        let length = (0..pts.len()).map(|i| (pts[(i + 1) % pts.len()] - pts[i]).norm()).sum();
        let bbox = pts.iter().fold((pts[0], pts[0]), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
        // simple loops are told apart by `classify`
        let kind = if pinched { LoopKind::TouchesItself } else { LoopKind::Hole };
        loops.push(MeshLoop { vertices, kind, length, bbox, facing: f64::NAN });
    }
    classify(m, &mut loops);
    Ok(loops)
}

/// Sets the facing of every loop, and the kind of the simple ones.
fn classify(m: &TriMesh, loops: &mut [MeshLoop]) {
    let mut on_loop: HashMap<u32, (Vec3, f64)> = HashMap::new();
    for l in loops.iter() {
        for &v in &l.vertices {
            on_loop.insert(v, (Vec3::ZERO, 0.0));
        }
    }
    for (t, tri) in m.triangles.iter().enumerate() {
        let n = m.face_normal(t);
        for v in tri {
            if let Some(acc) = on_loop.get_mut(v) {
                acc.0 += n;
                acc.1 += n.norm();
            }
        }
    }
    for l in loops.iter_mut() {
        let p = |i: usize| m.positions[l.vertices[i % l.vertices.len()] as usize];
        // about the loop's first vertex, to keep the cross products small
        let area: Vec3 = (1..l.vertices.len()).map(|i| (p(i) - p(0)).cross(p(i + 1) - p(0))).sum::<Vec3>() * 0.5;
        let (n, total) = l.vertices.iter().fold((Vec3::ZERO, 0.0), |(n, s), v| (n + on_loop[v].0, s + on_loop[v].1));
        l.facing = match area.normalized() {
            Some(axis) if total > 0.0 => axis.dot(n) / total,
            _ => 0.0,
        };
        if l.kind != LoopKind::TouchesItself {
            l.kind = if l.facing <= -1.0 / 3.0 {
                LoopKind::Hole
            } else if l.facing >= 1.0 / 3.0 {
                LoopKind::Rim
            } else {
                LoopKind::OpenEnd
            };
        }
    }
}

/// The angle (radians) between the normals of the two triangles of every interior edge,
/// with the edge, NaN where a triangle has no normal.
pub fn dihedral_angles(m: &TriMesh) -> Vec<((u32, u32), f64)> {
    let half = HalfEdges::new(m, m.triangles.len());
    let mut out = Vec::new();
    for x in 0..m.positions.len() as u32 {
        for &(y, t) in half.from(x) {
            // the last triangle of each direction, should an edge be run twice one way
            if x < y
                && half.from(x).iter().rev().find(|e| e.0 == y).map(|e| e.1) == Some(t)
                && let Some(&(_, s)) = half.from(y).iter().rev().find(|e| e.0 == x)
            {
                let (n1, n2) = (m.face_normal(t), m.face_normal(s));
                let c = n1.dot(n2) / (n1.norm() * n2.norm());
                let sn = n1.cross(n2).norm() / (n1.norm() * n2.norm());
                out.push(((x, y), sn.atan2(c)));
            }
        }
    }
    out.sort_by_key(|e| e.0);
    out
}

/// The `q`-quantile (0 ≤ q ≤ 1) of `values` by the nearest rank, NaN if any value is NaN.
pub fn quantile(values: &[f64], q: f64) -> f64 {
    if values.iter().any(|v| v.is_nan()) || values.is_empty() {
        return f64::NAN;
    }
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    let k = ((q * v.len() as f64).ceil() as usize).clamp(1, v.len()) - 1;
    v[k]
}
