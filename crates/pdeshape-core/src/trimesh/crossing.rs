//! Do a mesh's new triangles cross anything? The check a hole's fill passes before it is
//! stitched in: no new triangle may cross an input triangle or another new one.
//!
//! **Two triangles cross** when they share more than what their shared vertices allow:
//! a point that is not a shared vertex, or (for a shared edge) a point off that edge.
//! Touching is not crossing: a triangle's vertex on another's plane, or two triangles
//! meeting in a shared vertex or edge. Floating-point predicates with a tolerance, not
//! exact arithmetic: distances below `1e-9` of the pair's longest edge count as zero, so a
//! crossing deeper than that is found and touching within it is not reported.
//!
//! - *Not coplanar* (some vertex farther than the tolerance from the other's plane): the
//!   planes meet in a line `L`, each triangle meets `L` in an interval (where its signed
//!   distances to the other plane change sign, the method of Möller 1997), and the
//!   triangles cross when the intervals overlap by more than the tolerance. Two
//!   triangles on a shared edge then meet only along that edge.
//! - *Coplanar*: the triangles, projected onto their plane, cross when the area of their
//!   intersection (one clipped by the other's three half-planes) exceeds the tolerance
//!   times the longest edge.
//!
//! **Broad phase.** Only triangles whose boxes meet the new triangles' box are looked at,
//! hashed into a grid of cells about one new edge wide (at most 64 a side).

use super::TriMesh;
use crate::Vec3;
use std::collections::HashMap;

/// Relative tolerance: distances and overlaps below this times the pair's longest edge
/// are touching, not crossing. Round-off in the distances is ~1e-16 relative; 1e-9 leaves
/// a wide margin above it and lies far below any crossing a fill could make.
const TOL: f64 = 1e-9;

/// The pairs `(new, other)` of crossing triangles where `new ≥ first_new` indexes a new
/// triangle of `m` and `other` any other triangle (a pair of new triangles once), at most
/// `limit` of them, in increasing order of `new`.
pub fn crossings(m: &TriMesh, first_new: usize, limit: usize) -> Vec<(usize, usize)> {
    crossings_with(m, 0..first_new, first_new, true, limit)
}

/// [`crossings`] of the new triangles with the triangles of `against` only (indices below
/// `first_new`), and with each other when `own`: a fill already checked against the input
/// mesh and itself is checked against the fills before it alone.
pub fn crossings_with(
    m: &TriMesh,
    against: std::ops::Range<usize>,
    first_new: usize,
    own: bool,
    limit: usize,
) -> Vec<(usize, usize)> {
    let nt = m.triangles.len();
    if first_new >= nt || limit == 0 {
        return Vec::new();
    }
    let tri = |t: usize| m.triangles[t].map(|i| m.positions[i as usize]);
    let bbox = |t: usize| {
        let [a, b, c] = tri(t);
        (a.min(b).min(c), a.max(b).max(c))
    };
    // the new triangles' box and their median edge
    let mut lo = Vec3::new(f64::INFINITY, f64::INFINITY, f64::INFINITY);
    let mut hi = Vec3::new(f64::NEG_INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY);
    let mut edges = Vec::with_capacity(nt - first_new);
    for t in first_new..nt {
        let (l, h) = bbox(t);
        lo = lo.min(l);
        hi = hi.max(h);
        let [a, b, c] = tri(t);
        edges.push(crate::num::max_nan((b - a).norm(), crate::num::max_nan((c - b).norm(), (a - c).norm())));
    }
    edges.sort_by(f64::total_cmp);
    let extent = (hi - lo).max_abs();
    let pad = TOL * extent;
    lo -= Vec3::new(pad, pad, pad);
    hi += Vec3::new(pad, pad, pad);
    let cell = crate::num::max_nan(edges[edges.len() / 2], extent / 64.0).max(f64::MIN_POSITIVE);
    let dims = (hi - lo) / cell;
    let dims = [0, 1, 2].map(|k| (dims[k].ceil() as usize).clamp(1, 64));
    let index = |p: Vec3, k: usize| (((p[k] - lo[k]) / cell).floor().max(0.0) as usize).min(dims[k] - 1);
    let cells_of = |t: usize| -> Option<[std::ops::RangeInclusive<usize>; 3]> {
        let (l, h) = bbox(t);
        if (0..3).any(|k| h[k] < lo[k] || l[k] > hi[k]) {
            return None;
        }
        Some([0, 1, 2].map(|k| index(l, k)..=index(h, k)))
    };
    let mut grid: HashMap<(usize, usize, usize), Vec<usize>> = HashMap::new();
    let against = against.start..against.end.min(first_new);
    for t in against.clone().chain(first_new..nt) {
        if let Some([x, y, z]) = cells_of(t) {
            for i in x.clone() {
                for j in y.clone() {
                    for k in z.clone() {
                        grid.entry((i, j, k)).or_default().push(t);
                    }
                }
            }
        }
    }
    let mut seen = vec![usize::MAX; nt];
    let mut out = Vec::new();
    for t in first_new..nt {
        let Some([x, y, z]) = cells_of(t) else { continue };
        let mut candidates = Vec::new();
        for i in x {
            for j in y.clone() {
                for k in z.clone() {
                    for &u in grid.get(&(i, j, k)).map_or(&[][..], |v| v.as_slice()) {
                        // a pair of new triangles is tested once, from the later one
                        if u != t && seen[u] != t && (u < first_new || (own && u < t)) {
                            seen[u] = t;
                            candidates.push(u);
                        }
                    }
                }
            }
        }
        candidates.sort_unstable();
        for u in candidates {
            let shared = m.triangles[t].iter().filter(|i| m.triangles[u].contains(i)).count();
            if triangles_cross(tri(t), tri(u), shared) {
                out.push((t, u));
                if out.len() == limit {
                    return out;
                }
            }
        }
    }
    out
}

/// Whether the new triangles `triangles` (on `m`'s vertices and on `positions`, numbered
/// from `base`) cross none of `m`'s triangles and none of each other: [`crossings`] on a
/// local mesh of the new triangles and the input triangles whose boxes meet theirs.
pub(super) fn crossing_free(m: &TriMesh, positions: &[Vec3], triangles: &[[u32; 3]], base: u32) -> bool {
    let at = |i: u32| super::position(m, positions, base, i);
    let mut lo = Vec3::new(f64::INFINITY, f64::INFINITY, f64::INFINITY);
    let mut hi = -lo;
    for t in triangles {
        for &i in t {
            lo = lo.min(at(i));
            hi = hi.max(at(i));
        }
    }
    let pad = TOL * (hi - lo).max_abs();
    let (lo, hi) = (lo - Vec3::new(pad, pad, pad), hi + Vec3::new(pad, pad, pad));
    let near = |t: &[u32; 3]| {
        let [a, b, c] = t.map(|i| m.positions[i as usize]);
        let (l, h) = (a.min(b).min(c), a.max(b).max(c));
        (0..3).all(|k| h[k] >= lo[k] && l[k] <= hi[k])
    };
    let mut local = TriMesh::default();
    let mut index: HashMap<u32, u32> = HashMap::new();
    let mut map = |i: u32, local: &mut TriMesh| {
        *index.entry(i).or_insert_with(|| {
            local.positions.push(at(i));
            local.positions.len() as u32 - 1
        })
    };
    for t in m.triangles.iter().filter(|t| near(t)) {
        let tri = t.map(|i| map(i, &mut local));
        local.triangles.push(tri);
    }
    let first = local.triangles.len();
    for t in triangles {
        let tri = t.map(|i| map(i, &mut local));
        local.triangles.push(tri);
    }
    crossings(&local, first, 1).is_empty()
}

/// Whether triangles `a` and `b`, which share `shared` vertices (by index), cross (see the
/// module's documentation).
pub fn triangles_cross(a: [Vec3; 3], b: [Vec3; 3], shared: usize) -> bool {
    if shared >= 3 {
        return true;
    }
    let longest = [a, b]
        .iter()
        .flat_map(|t| [(t[1] - t[0]).norm(), (t[2] - t[1]).norm(), (t[0] - t[2]).norm()])
        .fold(0.0, crate::num::max_nan);
    if !longest.is_finite() || longest == 0.0 {
        return false;
    }
    let tol = TOL * longest;
    let (Some(na), Some(nb)) =
        ((a[1] - a[0]).cross(a[2] - a[0]).normalized(), (b[1] - b[0]).cross(b[2] - b[0]).normalized())
    else {
        return false;
    };
    let da = b.map(|p| na.dot(p - a[0]));
    let db = a.map(|p| nb.dot(p - b[0]));
    let off = |d: [f64; 3]| d.iter().any(|x| x.abs() > tol);
    let one_side = |d: [f64; 3]| d.iter().all(|&x| x > tol) || d.iter().all(|&x| x < -tol);
    let line = na.cross(nb);
    if !off(da) && !off(db) || line.norm() < 1e-12 {
        if off(da) || off(db) {
            // parallel planes apart
            return false;
        }
        return coplanar_overlap(a, b, na) > tol * longest;
    }
    if shared == 2 || one_side(da) || one_side(db) {
        return false;
    }
    let dir = line / line.norm();
    let (Some(ia), Some(ib)) = (interval(a, db, dir, tol), interval(b, da, dir, tol)) else { return false };
    ia.1.min(ib.1) - ia.0.max(ib.0) > tol
}

/// Where triangle `t`, whose vertices lie at signed distances `d` from a plane, meets
/// that plane, as an interval of positions along `dir`.
fn interval(t: [Vec3; 3], d: [f64; 3], dir: Vec3, tol: f64) -> Option<(f64, f64)> {
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    let mut take = |p: Vec3| {
        let s = dir.dot(p);
        lo = lo.min(s);
        hi = hi.max(s);
    };
    for i in 0..3 {
        if d[i].abs() <= tol {
            take(t[i]);
        }
        let j = (i + 1) % 3;
        if (d[i] > tol && d[j] < -tol) || (d[i] < -tol && d[j] > tol) {
            take(t[i] + (t[j] - t[i]) * (d[i] / (d[i] - d[j])));
        }
    }
    (lo <= hi).then_some((lo, hi))
}

/// The area of the intersection of coplanar triangles `a` and `b` (normal `n`).
fn coplanar_overlap(a: [Vec3; 3], b: [Vec3; 3], n: Vec3) -> f64 {
    // drop the normal's largest coordinate
    let k = (0..3).max_by(|&i, &j| n[i].abs().total_cmp(&n[j].abs())).unwrap_or(2);
    let (x, y) = ((k + 1) % 3, (k + 2) % 3);
    let flat = |t: [Vec3; 3]| {
        let mut p = t.map(|v| [v[x], v[y]]);
        if cross2(p[0], p[1], p[2]) < 0.0 {
            p.swap(1, 2);
        }
        p
    };
    let (pa, pb) = (flat(a), flat(b));
    let mut poly: Vec<[f64; 2]> = pa.to_vec();
    for i in 0..3 {
        let (e0, e1) = (pb[i], pb[(i + 1) % 3]);
        let side = |p: [f64; 2]| cross2(e0, e1, p);
        let mut next = Vec::with_capacity(poly.len() + 1);
        for j in 0..poly.len() {
            let (p, q) = (poly[j], poly[(j + 1) % poly.len()]);
            let (sp, sq) = (side(p), side(q));
            if sp >= 0.0 {
                next.push(p);
            }
            if (sp > 0.0 && sq < 0.0) || (sp < 0.0 && sq > 0.0) {
                let s = sp / (sp - sq);
                next.push([p[0] + s * (q[0] - p[0]), p[1] + s * (q[1] - p[1])]);
            }
        }
        poly = next;
        if poly.len() < 3 {
            return 0.0;
        }
    }
    // the projection shrinks areas by |n_k|; undo it
    let area: f64 = (1..poly.len() - 1).map(|j| cross2(poly[0], poly[j], poly[j + 1])).sum::<f64>() / 2.0;
    area / n[k].abs()
}

fn cross2(o: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64, z: f64) -> Vec3 {
        Vec3::new(x, y, z)
    }

    #[test]
    fn pairs_worked_by_hand() {
        let base = [v(0.0, 0.0, 0.0), v(1.0, 0.0, 0.0), v(0.0, 1.0, 0.0)];
        // a vertical triangle piercing the base's interior
        assert!(triangles_cross(base, [v(0.2, 0.2, -0.5), v(0.3, 0.2, 0.5), v(0.2, 0.3, 0.5)], 0));
        // the same lifted clear of the base: its box meets the base's, it does not
        assert!(!triangles_cross(base, [v(0.2, 0.2, 0.1), v(0.3, 0.2, 1.0), v(0.2, 0.3, 1.0)], 0));
        // touching the base's interior with one vertex: touching, not crossing
        assert!(!triangles_cross(base, [v(0.2, 0.2, 0.0), v(0.3, 0.2, 1.0), v(0.2, 0.3, 1.0)], 0));
        // sharing the edge (0,0,0)-(1,0,0), bent up: a crease, not a crossing
        assert!(!triangles_cross(base, [v(1.0, 0.0, 0.0), v(0.0, 0.0, 0.0), v(0.5, -0.5, 0.3)], 2));
        // sharing that edge and folded back onto the base: coplanar, overlapping
        assert!(triangles_cross(base, [v(1.0, 0.0, 0.0), v(0.0, 0.0, 0.0), v(0.3, 0.3, 0.0)], 2));
        // sharing that edge, flat and on the other side: a plane's neighbours
        assert!(!triangles_cross(base, [v(1.0, 0.0, 0.0), v(0.0, 0.0, 0.0), v(0.5, -0.5, 0.0)], 2));
        // sharing vertex (0,0,0) and dipping through the base's interior
        assert!(triangles_cross(base, [v(0.0, 0.0, 0.0), v(0.4, 0.4, -0.5), v(0.4, 0.4, 0.5)], 1));
        // sharing vertex (0,0,0), fanned away below it
        assert!(!triangles_cross(base, [v(0.0, 0.0, 0.0), v(-0.4, -0.1, -0.5), v(-0.1, -0.4, -0.5)], 1));
        // coplanar, sharing a vertex, the wedges overlapping
        assert!(triangles_cross(base, [v(0.0, 0.0, 0.0), v(1.0, 1.0, 0.0), v(-1.0, 1.0, 0.0)], 1));
        // coplanar, sharing a vertex, the wedges apart
        assert!(!triangles_cross(base, [v(0.0, 0.0, 0.0), v(-1.0, 0.0, 0.0), v(0.0, -1.0, 0.0)], 1));
        // coplanar and disjoint but for a common corner point of different indices
        assert!(!triangles_cross(base, [v(1.0, 0.0, 0.0), v(2.0, 0.0, 0.0), v(1.0, 1.0, 0.0)], 0));
        // coplanar, one inside the other, no shared vertex
        assert!(triangles_cross(base, [v(0.1, 0.1, 0.0), v(0.2, 0.1, 0.0), v(0.1, 0.2, 0.0)], 0));
        // parallel planes apart
        assert!(!triangles_cross(base, [v(0.1, 0.1, 1e-3), v(0.2, 0.1, 1e-3), v(0.1, 0.2, 1e-3)], 0));
    }

    /// A unit square of two triangles and a third triangle through the first of them.
    fn square_and_through() -> TriMesh {
        TriMesh {
            positions: vec![
                v(0.0, 0.0, 0.0),
                v(1.0, 0.0, 0.0),
                v(1.0, 1.0, 0.0),
                v(0.0, 1.0, 0.0),
                v(0.6, 0.3, -0.2),
                v(0.7, 0.3, 0.2),
                v(0.6, 0.4, 0.2),
            ],
            triangles: vec![[0, 1, 2], [0, 2, 3], [4, 5, 6]],
        }
    }

    #[test]
    fn the_crossing_is_found_in_a_mesh() {
        // a square of two triangles and a third triangle through it, then lifted off it
        let mut m = square_and_through();
        assert_eq!(crossings(&m, 2, 10), vec![(2, 0)]);
        for i in 4..7 {
            m.positions[i].z += 0.25;
        }
        assert_eq!(crossings(&m, 2, 10), vec![]);
        // the square's own triangles, as new ones, do not cross each other
        assert_eq!(crossings(&m, 0, 10), vec![]);
    }

    /// Only the triangles asked for are crossed: the new triangle through the square's
    /// first triangle crosses it when that one is in `against`, not when only the second
    /// is; two new triangles that cross each other count only with `own`.
    #[test]
    fn crossings_with_checks_only_what_it_is_given() {
        let mut m = square_and_through();
        assert_eq!(crossings_with(&m, 0..2, 2, false, 10), vec![(2, 0)]);
        assert_eq!(crossings_with(&m, 0..1, 2, false, 10), vec![(2, 0)]);
        assert_eq!(crossings_with(&m, 1..2, 2, false, 10), vec![]);
        // the square's two triangles made new and a third through the first
        m.triangles = vec![[4, 5, 6], [0, 1, 2], [0, 2, 3]];
        assert_eq!(crossings_with(&m, 0..0, 0, false, 10), vec![]);
        assert_eq!(crossings_with(&m, 0..0, 0, true, 10), vec![(1, 0)]);
        assert_eq!(crossings(&m, 0, 10), vec![(1, 0)]);
    }
}
