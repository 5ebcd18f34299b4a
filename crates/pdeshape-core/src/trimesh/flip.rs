//! Edge flips towards a Delaunay triangulation, on a fill's new triangles only.
//!
//! Two triangles `(a, b, c)` and `(b, a, d)` on edge `ab` become `(a, d, c)` and
//! `(d, b, c)` when the angles at `c` and `d` opposite the edge sum to more than π (the
//! Lawson criterion: the flipped pair has the larger smallest angle). On a curved surface
//! the angles are the 3-D ones. A flip is refused when edge `cd` exists already (it would
//! make an edge of three triangles), when a new triangle turns away from the pair's mean
//! normal by more than 60° (it would fold over the quadrilateral's reflex corner) or when
//! an edge is one the caller keeps (the loop's edges, which the mesh's triangles share).
//! Each flip strictly raises the smaller angle sum, so the process ends; a budget caps it.

use crate::Vec3;
use std::collections::{HashMap, HashSet};

/// The cosine of the largest angle between a flipped triangle's normal and the pair's
/// mean normal.
const FACING: f64 = 0.5;

/// Flips edges between triangles of `tris` towards Delaunay (see the module's
/// documentation); `pos` gives a vertex's position, `exists(a, b)` whether the edge `ab`
/// exists outside `tris` (such an edge is never made). At most `budget` flips; returns the
/// number made. Triangles for which `frozen` holds keep their edges.
pub(super) fn flip_to_delaunay(
    tris: &mut [[u32; 3]],
    pos: &dyn Fn(u32) -> Vec3,
    exists: &dyn Fn(u32, u32) -> bool,
    frozen: &dyn Fn(&[u32; 3]) -> bool,
    budget: usize,
) -> usize {
    let mut by_edge: HashMap<(u32, u32), usize> = HashMap::with_capacity(3 * tris.len());
    for (t, tri) in tris.iter().enumerate() {
        if frozen(tri) {
            continue;
        }
        for k in 0..3 {
            by_edge.insert((tri[k], tri[(k + 1) % 3]), t);
        }
    }
    let mut undirected: HashSet<(u32, u32)> = tris
        .iter()
        .flat_map(|t| [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])])
        .map(|(a, b)| (a.min(b), a.max(b)))
        .collect();
    let mut stack: Vec<(u32, u32)> = by_edge.keys().copied().filter(|&(a, b)| a < b).collect();
    stack.sort_unstable();
    let angle = |o: Vec3, p: Vec3, q: Vec3| {
        let (u, v) = (p - o, q - o);
        u.cross(v).norm().atan2(u.dot(v))
    };
    let unit = |a: Vec3, b: Vec3, c: Vec3| (b - a).cross(c - a).normalized();
    let mut flips = 0;
    while let Some((a, b)) = stack.pop() {
        if flips >= budget {
            break;
        }
        let (Some(&t), Some(&u)) = (by_edge.get(&(a, b)), by_edge.get(&(b, a))) else { continue };
        let third = |tri: [u32; 3], x: u32, y: u32| tri.into_iter().find(|&v| v != x && v != y);
        let (Some(c), Some(d)) = (third(tris[t], a, b), third(tris[u], a, b)) else { continue };
        if c == d || undirected.contains(&(c.min(d), c.max(d))) || exists(c, d) {
            continue;
        }
        let [pa, pb, pc, pd] = [a, b, c, d].map(pos);
        // the Lawson criterion, with a margin against flipping back and forth at ties
        if angle(pc, pa, pb) + angle(pd, pb, pa) <= std::f64::consts::PI + 1e-9 {
            continue;
        }
        let (Some(n1), Some(n2)) = (unit(pa, pb, pc), unit(pb, pa, pd)) else { continue };
        let Some(mean) = (n1 + n2).normalized() else { continue };
        let (Some(m1), Some(m2)) = (unit(pa, pd, pc), unit(pd, pb, pc)) else { continue };
        if m1.dot(mean) < FACING || m2.dot(mean) < FACING {
            continue;
        }
        // the flip: (a, b, c), (b, a, d) → (a, d, c), (d, b, c)
        for (x, y) in [(a, b), (b, c), (c, a), (b, a), (a, d), (d, b)] {
            by_edge.remove(&(x, y));
        }
        undirected.remove(&(a.min(b), a.max(b)));
        tris[t] = [a, d, c];
        tris[u] = [d, b, c];
        for (x, y, tri) in [(a, d, t), (d, c, t), (c, a, t), (d, b, u), (b, c, u), (c, d, u)] {
            by_edge.insert((x, y), tri);
        }
        undirected.insert((c.min(d), c.max(d)));
        for (x, y) in [(a, d), (d, b), (b, c), (c, a)] {
            stack.push((x.min(y), x.max(y)));
        }
        flips += 1;
    }
    flips
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A thin quadrilateral's long diagonal is flipped to the short one; the flipped pair
    /// keeps the orientation and is Delaunay (no further flip); an edge that exists elsewhere
    /// is not made.
    #[test]
    fn flips_the_long_diagonal() {
        // a = (0,0), b = (4,1): the long diagonal; c = (1, 0.8) above, d = (3, 0.2) below
        let p =
            [Vec3::new(0.0, 0.0, 0.0), Vec3::new(4.0, 1.0, 0.0), Vec3::new(1.0, 0.8, 0.0), Vec3::new(3.0, 0.2, 0.0)];
        let pos = |i: u32| p[i as usize];
        let mut tris = [[0, 1, 2], [1, 0, 3]];
        assert!((p[1] - p[0]).cross(p[2] - p[0]).z > 0.0, "counter-clockwise");
        let n = flip_to_delaunay(&mut tris, &pos, &|_, _| false, &|_| false, 10);
        assert_eq!(n, 1);
        assert_eq!(tris, [[0, 3, 2], [3, 1, 2]]);
        for t in tris {
            let [a, b, c] = t.map(pos);
            assert!((b - a).cross(c - a).z > 0.0, "{t:?} keeps the orientation");
        }
        assert_eq!(flip_to_delaunay(&mut tris, &pos, &|_, _| false, &|_| false, 10), 0);
        // the same pair when edge cd exists elsewhere, or when one of the pair is frozen:
        // left alone
        let mut tris = [[0, 1, 2], [1, 0, 3]];
        assert_eq!(flip_to_delaunay(&mut tris, &pos, &|x, y| (x, y) == (2, 3) || (x, y) == (3, 2), &|_| false, 10), 0);
        assert_eq!(flip_to_delaunay(&mut tris, &pos, &|_, _| false, &|t| t[2] == 3, 10), 0);
        assert_eq!(tris, [[0, 1, 2], [1, 0, 3]]);
    }
}
