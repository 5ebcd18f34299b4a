//! Creases of a neighbour inside a fill's edge: parameters where the neighbour is only C0
//! across the edge (a polyline's vertex swept into a sheet, a trim curve crossing such a
//! line), so that its cross tangent or normal jumps there.
//!
//! A fill takes its loop data from the neighbour; data that jump inside an edge make the
//! fill tear (its exact remainder carries the jump into the surface). A crease found here is
//! made a corner: the edge is split there, and the corner is blended and reported like any
//! other.
//!
//! Detection. Along the edge the frame `F(w) = (n̂, ŝ, ln|S_s|)` — the unit normal
//! `n̂ ∝ S_s × S_w`, the unit cross tangent `ŝ` and its length — is sampled at 512 points.
//! Where the neighbour is smooth, the change `D` of `F` over an interval shrinks with the
//! interval; across a crease it does not. An interval whose change is a spike (over 4 × that
//! of both neighbours and over 1e-7) is bisected down to adjacent floating-point numbers,
//! always keeping the half that changes more; if the change is still above 1e-6 there, the
//! crease lies between those two numbers.

use super::FillEdge;
use crate::Vec3;
use crate::jet::JetShape;

/// Samples along an edge.
const SAMPLES: usize = 512;

/// The frame at `w`: unit normal, unit cross tangent, length of the cross tangent.
fn frame(e: &FillEdge, w: f64, t: f64) -> (Vec3, Vec3, f64) {
    let j = e.surface.jet(&[e.s0, w, t], JetShape::new(&[1, 1, 0]));
    let g = |m: [usize; 3]| Vec3::new(j.0[0].coeff(m), j.0[1].coeff(m), j.0[2].coeff(m));
    let (ss, sw) = (g([1, 0, 0]), g([0, 1, 0]));
    let nan = Vec3::new(f64::NAN, f64::NAN, f64::NAN);
    let l = ss.norm();
    (ss.cross(sw).normalized().unwrap_or(nan), ss.normalized().unwrap_or(nan), l)
}

/// The change of the frame between two points (NaN when either is degenerate).
fn change(a: &(Vec3, Vec3, f64), b: &(Vec3, Vec3, f64)) -> f64 {
    (a.0 - b.0).norm() + (a.1 - b.1).norm() + (a.2 / b.2).ln().abs()
}

/// The creases strictly inside edge `e` (`t` the time), in increasing order along the edge:
/// each as the two adjacent parameters `(a, b)` between which the neighbour's frame jumps,
/// `a` on the side of `w.0`.
pub fn creases(e: &FillEdge, t: f64) -> Vec<(f64, f64)> {
    let (w0, w1) = e.w;
    let ws: Vec<f64> = (0..=SAMPLES).map(|j| w0 + (w1 - w0) * j as f64 / SAMPLES as f64).collect();
    let frames: Vec<_> = ws.iter().map(|&w| frame(e, w, t)).collect();
    let d: Vec<f64> = frames.windows(2).map(|f| change(&f[0], &f[1])).collect();
    let mut out = Vec::new();
    for j in 0..d.len() {
        let left = if j > 0 { d[j - 1] } else { 0.0 };
        let right = if j + 1 < d.len() { d[j + 1] } else { 0.0 };
        // NaN (a degenerate frame) is no crease of this test's; the fill's own checks name it
        if !(d[j] > 1e-7 && d[j] > 4.0 * left && d[j] > 4.0 * right) {
            continue;
        }
        let (mut a, mut b) = (ws[j], ws[j + 1]);
        let (mut fa, mut fb) = (frames[j], frames[j + 1]);
        loop {
            let m = 0.5 * (a + b);
            if m <= a.min(b) || m >= a.max(b) {
                break;
            }
            let fm = frame(e, m, t);
            if change(&fa, &fm) >= change(&fm, &fb) {
                (b, fb) = (m, fm);
            } else {
                (a, fa) = (m, fm);
            }
        }
        if change(&fa, &fb) > 1e-6 {
            out.push((a, b));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::ExprField;
    use std::sync::Arc;

    fn edge(expr: [&str; 3], w: (f64, f64)) -> FillEdge {
        let f = ExprField::parse(expr, &["s", "w", "t"], &|_| None).unwrap();
        FillEdge { surface: Arc::new(f), s0: 0.0, w, fullness: 1.0, side: None, smooth: false }
    }

    /// The edge crosses the crease line y = 0.3 of the sheet (x, y, |y − 0.3|) diagonally:
    /// `S(s, w) = H(w − s, w + s)`, whose cross tangent and normal jump at w = 0.3; found
    /// between adjacent floats there. A smooth sheet has none.
    #[test]
    fn a_crease_crossed_by_the_edge_is_found_to_the_last_bit() {
        let e = edge(["w - s", "w + s", "abs(w + s - 0.3)"], (0.0, 1.0));
        let c = creases(&e, 0.0);
        assert_eq!(c.len(), 1, "{c:?}");
        let (a, b) = c[0];
        // adjacent floats around 0.3 (one ulp of 0.3 is 5.6e-17)
        assert!(a < b && b - a <= 2.0 * f64::EPSILON * 0.3, "{a} {b}");
        assert!((a - 0.3).abs() <= 2.0 * f64::EPSILON, "{a}");
        let smooth = edge(["w - s", "w + s", "sin(3*(w + s))"], (0.0, 1.0));
        assert!(creases(&smooth, 0.0).is_empty());
    }
}
