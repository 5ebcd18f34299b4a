//! A face of a B-rep meshed for drawing: its loops taken into the surface's parameters,
//! the region they bound triangulated there, and the triangles subdivided until their
//! edges are short in space; points and normals are the surface's own (exact), the
//! boundary is the loops' (each edge sampled at [`PER_EDGE`] points).
//!
//! **Loops into parameters.** Each loop is walked edge after edge as the face runs it; a
//! point's parameters are its foot on the surface, found by Newton's method from the
//! previous point's (the first from the surface's own inversion), so on periodic surfaces
//! the walk stays continuous: a cylinder's face bounded by its two rims and the seam run
//! both ways becomes the rectangle `[0, 2π] × [z₀, z₁]`. A loop whose walk does not close
//! in the parameters (a rim without a seam edge) is refused: such faces are not drawn.
//!
//! **Triangulation.** The outer loop (the largest area) is made counter-clockwise and the
//! inner ones clockwise; each inner loop is joined to the outer by a bridge from its
//! rightmost point to a point of the outer polygon it sees (the classic hole elimination),
//! and the one polygon is cut into triangles by ear clipping. Every triangle is then split
//! into `k²` alike (`k` the same for the whole face, so shared edges split alike and the
//! mesh has no cracks) with `k` the smallest that brings the longest edge under the
//! target length.

use super::{Brep, FaceSurface};
use crate::Vec3;
use crate::fill::foot_of;
use crate::jet::JetShape;
use crate::mesh::Mesh;
use crate::num::max_nan;

/// Points sampled on each edge of a loop.
pub const PER_EDGE: usize = 24;

/// Why a face is not meshed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TessellateError {
    /// The face or one of its edges has no geometry that is read.
    #[error("face #{0} has geometry of a kind that is not read")]
    Unsupported(u64),
    /// A loop does not close in the surface's parameters.
    #[error("face #{0}: a loop does not close in the surface's parameters (a rim without a seam edge)")]
    Open(u64),
    /// A point of a loop has no foot on the surface.
    #[error("face #{0}: a point of its loops has no foot on its surface")]
    Foot(u64),
    /// The polygon could not be cut into triangles (it crosses itself).
    #[error("face #{0}: its loops cross in the surface's parameters")]
    Crossing(u64),
}

/// The mesh of face `face` of `b` with triangle edges at most about `target` long (in the
/// model's unit), named by its id.
pub fn face_mesh(b: &Brep, face: usize, target: f64) -> Result<Mesh, TessellateError> {
    let f = &b.faces[face];
    let s = f.surface.as_ref().ok_or(TessellateError::Unsupported(f.id))?;
    let mut loops: Vec<Vec<[f64; 2]>> = Vec::new();
    for l in &f.loops {
        loops.push(loop_parameters(b, s, l, f.id)?);
    }
    let Some(outer) = (0..loops.len()).max_by(|&i, &j| area(&loops[i]).abs().total_cmp(&area(&loops[j]).abs())) else {
        return Ok(Mesh { name: format!("face{}", f.id), ..Default::default() });
    };
    let mut poly = loops[outer].clone();
    if area(&poly) < 0.0 {
        poly.reverse();
    }
    let mut holes: Vec<Vec<[f64; 2]>> = loops
        .iter()
        .enumerate()
        .filter(|(i, _)| *i != outer)
        .map(|(_, h)| {
            let mut h = h.clone();
            if area(&h) > 0.0 {
                h.reverse();
            }
            h
        })
        .collect();
    // bridge the holes from right to left (each bridge then crosses no later hole)
    holes.sort_by(|a, b| rightmost(b).1[0].total_cmp(&rightmost(a).1[0]));
    for h in &holes {
        poly = bridged(&poly, h, &holes).ok_or(TessellateError::Crossing(f.id))?;
    }
    let tris = ear_clip(&poly).ok_or(TessellateError::Crossing(f.id))?;
    let field = s.field();
    let at = |c: [f64; 2]| -> (Vec3, Vec3) {
        let j = field.jet(&[c[0], c[1], 0.0], JetShape::new(&[1, 1]));
        let n = j.derivative([1, 0, 0]).cross(j.derivative([0, 1, 0])).normalized().unwrap_or(Vec3::ZERO);
        (j.derivative([0, 0, 0]), if f.same_sense { n } else { -n })
    };
    // the same k for every triangle: the longest edge in space over the target, at most 24
    let mut longest: f64 = 0.0;
    for t in &tris {
        for k in 0..3 {
            let (a, b) = (poly[t[k]], poly[t[(k + 1) % 3]]);
            longest = max_nan(longest, (field.eval(&[a[0], a[1], 0.0]) - field.eval(&[b[0], b[1], 0.0])).norm());
        }
    }
    let k = if target > 0.0 { ((longest / target).ceil() as usize).clamp(1, 24) } else { 1 };
    let mut m = Mesh { name: format!("face{}", f.id), ..Default::default() };
    for t in &tris {
        let (a, b, c) = (poly[t[0]], poly[t[1]], poly[t[2]]);
        let base = m.positions.len() as u32;
        // vertices (i, j), i + j ≤ k, at a + (i/k)(b − a) + (j/k)(c − a)
        let index = |i: usize, j: usize| base + (j * (2 * k + 3 - j) / 2 + i) as u32;
        for j in 0..=k {
            for i in 0..=k - j {
                let (x, y) = (i as f64 / k as f64, j as f64 / k as f64);
                let c2 = [a[0] + x * (b[0] - a[0]) + y * (c[0] - a[0]), a[1] + x * (b[1] - a[1]) + y * (c[1] - a[1])];
                let (p, n) = at(c2);
                m.positions.push(p);
                m.normals.push(n);
            }
        }
        for j in 0..k {
            for i in 0..k - j {
                let tri = [index(i, j), index(i + 1, j), index(i, j + 1)];
                m.triangles.push(if f.same_sense { tri } else { [tri[0], tri[2], tri[1]] });
                if i + j + 1 < k {
                    let tri = [index(i + 1, j), index(i + 1, j + 1), index(i, j + 1)];
                    m.triangles.push(if f.same_sense { tri } else { [tri[0], tri[2], tri[1]] });
                }
            }
        }
    }
    Ok(m)
}

/// The loop `l` of a face on `s` as a closed polygon in the surface's parameters (the
/// last point not repeated).
fn loop_parameters(
    b: &Brep,
    s: &FaceSurface,
    l: &[(usize, bool)],
    face: u64,
) -> Result<Vec<[f64; 2]>, TessellateError> {
    let field = s.field();
    let mut out: Vec<[f64; 2]> = Vec::new();
    for &(e, forward) in l {
        let edge = &b.edges[e];
        if edge.curve.is_none() {
            return Err(TessellateError::Unsupported(face));
        }
        let (t0, t1) = if forward { edge.range } else { (edge.range.1, edge.range.0) };
        for i in 0..PER_EDGE {
            let p = edge.point(t0 + (t1 - t0) * i as f64 / PER_EDGE as f64);
            let seed = out.last().copied().unwrap_or_else(|| s.invert_near(p));
            let c = foot_of(field.as_ref(), p, seed, 0.0).ok_or(TessellateError::Foot(face))?;
            out.push(c);
        }
    }
    // closed: the walk comes back to its start (not a period away)
    if let (Some(first), Some(last)) = (out.first(), out.last()) {
        let step = out.windows(2).map(|w| dist(w[0], w[1])).fold(0.0, max_nan);
        // a NaN step or gap counts as not closed
        let gap = dist(*first, *last);
        if gap.is_nan() || step.is_nan() || gap > 4.0 * max_nan(step, 1e-12) {
            return Err(TessellateError::Open(face));
        }
    }
    Ok(out)
}

fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

fn cross(o: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])
}

/// The signed area of a closed polygon (positive counter-clockwise).
fn area(p: &[[f64; 2]]) -> f64 {
    let n = p.len();
    (0..n).map(|i| p[i][0] * p[(i + 1) % n][1] - p[(i + 1) % n][0] * p[i][1]).sum::<f64>() / 2.0
}

/// The index and point of largest `u`.
fn rightmost(p: &[[f64; 2]]) -> (usize, [f64; 2]) {
    let i = (0..p.len()).max_by(|&i, &j| p[i][0].total_cmp(&p[j][0])).unwrap_or(0);
    (i, p.get(i).copied().unwrap_or([0.0, 0.0]))
}

/// Whether the open segments `ab` and `cd` cross.
fn segments_cross(a: [f64; 2], b: [f64; 2], c: [f64; 2], d: [f64; 2]) -> bool {
    let (d1, d2) = (cross(a, b, c), cross(a, b, d));
    let (d3, d4) = (cross(c, d, a), cross(c, d, b));
    d1 * d2 < 0.0 && d3 * d4 < 0.0
}

/// `poly` with the hole `h` joined by a bridge from the hole's rightmost point to the
/// nearest point of `poly` it sees (crossing no edge of `poly` or of any hole).
fn bridged(poly: &[[f64; 2]], h: &[[f64; 2]], holes: &[Vec<[f64; 2]>]) -> Option<Vec<[f64; 2]>> {
    let (hi, m) = rightmost(h);
    let edges =
        |p: &[[f64; 2]]| -> Vec<([f64; 2], [f64; 2])> { (0..p.len()).map(|i| (p[i], p[(i + 1) % p.len()])).collect() };
    let mut all = edges(poly);
    for other in holes {
        all.extend(edges(other));
    }
    let mut order: Vec<usize> = (0..poly.len()).collect();
    order.sort_by(|&i, &j| dist(poly[i], m).total_cmp(&dist(poly[j], m)));
    let pi = order.into_iter().find(|&i| {
        let p = poly[i];
        all.iter().all(|&(a, b)| a == p || b == p || a == m || b == m || !segments_cross(m, p, a, b))
    })?;
    let mut out = Vec::with_capacity(poly.len() + h.len() + 2);
    out.extend_from_slice(&poly[..=pi]);
    for k in 0..=h.len() {
        out.push(h[(hi + k) % h.len()]);
    }
    out.extend_from_slice(&poly[pi..]);
    Some(out)
}

/// Triangles (indices into `p`) covering the counter-clockwise polygon `p` (which may
/// touch itself along bridges), by ear clipping; `None` when no ear is left (the polygon
/// crosses itself).
fn ear_clip(p: &[[f64; 2]]) -> Option<Vec<[usize; 3]>> {
    let mut idx: Vec<usize> = (0..p.len()).collect();
    let mut out = Vec::with_capacity(p.len());
    let scale = max_nan(p.iter().fold(0.0_f64, |a, q| max_nan(max_nan(a, q[0].abs()), q[1].abs())), 1e-300);
    let eps = 1e-14 * scale * scale;
    while idx.len() > 3 {
        let n = idx.len();
        let mut clipped = false;
        for k in 0..n {
            let (i0, i1, i2) = (idx[(k + n - 1) % n], idx[k], idx[(k + 1) % n]);
            let (a, b, c) = (p[i0], p[i1], p[i2]);
            if cross(a, b, c) <= eps {
                continue; // reflex or flat
            }
            // no other vertex inside the ear (vertices equal to its corners, as bridges
            // repeat them, do not count)
            let inside = idx.iter().any(|&j| {
                let q = p[j];
                j != i0
                    && j != i1
                    && j != i2
                    && q != a
                    && q != b
                    && q != c
                    && cross(a, b, q) >= 0.0
                    && cross(b, c, q) >= 0.0
                    && cross(c, a, q) >= 0.0
            });
            if inside {
                continue;
            }
            out.push([i0, i1, i2]);
            idx.remove(k);
            clipped = true;
            break;
        }
        if !clipped {
            // only flat corners left (collinear runs): drop one, else give up
            let flat = (0..n).find(|&k| cross(p[idx[(k + n - 1) % n]], p[idx[k]], p[idx[(k + 1) % n]]).abs() <= eps)?;
            idx.remove(flat);
        }
    }
    if idx.len() == 3 && cross(p[idx[0]], p[idx[1]], p[idx[2]]) > eps {
        out.push([idx[0], idx[1], idx[2]]);
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_square_with_a_square_hole_has_its_area() {
        let outer = vec![[0.0, 0.0], [4.0, 0.0], [4.0, 4.0], [0.0, 4.0]];
        let hole = vec![[1.0, 1.0], [1.0, 2.0], [2.0, 2.0], [2.0, 1.0]];
        let p = bridged(&outer, &hole, std::slice::from_ref(&hole)).unwrap();
        let t = ear_clip(&p).unwrap();
        let sum: f64 = t.iter().map(|t| cross(p[t[0]], p[t[1]], p[t[2]]) / 2.0).sum();
        // 16 − 1, each triangle's area exact in binary
        assert_eq!(sum, 15.0);
        assert!(t.iter().all(|t| cross(p[t[0]], p[t[1]], p[t[2]]) > 0.0));
    }

    #[test]
    fn a_u_shape_is_cut_into_its_area() {
        // non-convex: a 3 × 3 square with a 1 × 2 notch from the top
        let p = vec![[0.0, 0.0], [3.0, 0.0], [3.0, 3.0], [2.0, 3.0], [2.0, 1.0], [1.0, 1.0], [1.0, 3.0], [0.0, 3.0]];
        let t = ear_clip(&p).unwrap();
        assert_eq!(t.len(), 6);
        let sum: f64 = t.iter().map(|t| cross(p[t[0]], p[t[1]], p[t[2]]) / 2.0).sum();
        assert_eq!(sum, 7.0);
    }
}
