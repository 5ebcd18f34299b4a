//! Isoparametric faces of a solid blend as surfaces, and which of the parameter cube's six
//! faces bound the solid.
//!
//! The face `axis = value` of `x: [0, 1]³ → R³` is the surface `S(s, t) = x(…)` with the
//! two other parameters as `(s, t)`: in cyclic order `(axis + 1, axis + 2)`, or swapped so
//! that a periodic direction of the solid is the surface's `t` (its `v`, which a surface
//! may close). Since `(axis + 1, axis + 2, axis)` is cyclic, `x_{axis+1} × x_{axis+2} ·
//! x_{axis} = det J`, and `e_axis` points out of the parameter cube at `value = 1`: the
//! face's normal `S_s × S_t` points out of the solid exactly when
//! `(value = 1) ≠ swapped ≠ (det J < 0)`.
//!
//! Not every face of the cube bounds the solid: a face mapped onto a curve or a point
//! (`x_s × x_t ≡ 0`, as the axis `u = 0` of a cylinder in polar parameters) has no area,
//! and the two faces `v = 0` and `v = 1` of a solid periodic in `v` coincide inside it.
//! [`boundary_faces`] keeps the others.

use super::SolidBlend;
use crate::Vec3;
use crate::patch::{Surface, VDomain};
use std::sync::Arc;

/// The face `axis = value` of a solid blend as a surface over `[0, 1]²`.
#[derive(Clone, Debug)]
pub struct SolidFace {
    /// The solid.
    pub blend: Arc<SolidBlend>,
    /// The fixed parameter: 0 (`u`), 1 (`v`) or 2 (`w`).
    pub axis: usize,
    /// Its value, 0 or 1 for a boundary face (any value for a cross section).
    pub value: f64,
    /// The solid's parameters that are the surface's `u` and `v`.
    pub dirs: [usize; 2],
    /// Whether the surface's `v` closes (the solid's faces `v = 0` and `v = 1` coincide).
    /// The correction `sin(mπv)` makes such a seam only C0 in general, so the closure is
    /// in position: a fit keeps clamped knots there.
    pub periodic: bool,
}

impl SolidFace {
    /// The cross section `axis = value` with the other parameters in cyclic order.
    pub fn section(blend: Arc<SolidBlend>, axis: usize, value: f64) -> Self {
        SolidFace { blend, axis, value, dirs: [(axis + 1) % 3, (axis + 2) % 3], periodic: false }
    }

    /// `"u0"`, `"w1"`, … for a boundary face.
    pub fn label(&self) -> String {
        format!("{}{}", ["u", "v", "w"][self.axis], self.value)
    }

    /// The solid's parameters `(u, v, w)` at the surface's `(s, t)`.
    pub fn parameters(&self, s: f64, t: f64) -> [f64; 3] {
        let mut p = [0.0; 3];
        p[self.axis] = self.value;
        p[self.dirs[0]] = s;
        p[self.dirs[1]] = t;
        p
    }

    /// Whether the surface's normal `S_u × S_v` points out of the solid (at `(s, t)`,
    /// decided by the sign of `det J` there; see the module notes).
    pub fn outward_at(&self, s: f64, t: f64) -> bool {
        let [u, v, w] = self.parameters(s, t);
        let [a, b, c] = self.blend.jacobian(u, v, w);
        let det = a.dot(b.cross(c));
        let swapped = self.dirs[0] != (self.axis + 1) % 3;
        ((self.value == 1.0) != swapped) != (det < 0.0)
    }
}

impl Surface for SolidFace {
    fn v_domain(&self) -> VDomain {
        VDomain { start: 0.0, end: 1.0, periodic: self.periodic }
    }

    fn derivatives(&self, u: f64, v: f64, du: usize, dv: usize) -> Vec<Vec3> {
        let [a, b] = self.dirs;
        let t = self.parameters(u, v);
        let mut o = [0usize; 3];
        o[a] = du;
        o[b] = dv;
        let d = self.blend.derivatives(t[0], t[1], t[2], o[0], o[1], o[2]);
        let mut out = Vec::with_capacity((du + 1) * (dv + 1));
        for i in 0..=du {
            for j in 0..=dv {
                let mut m = [0usize; 3];
                m[a] = i;
                m[b] = j;
                out.push(d[(m[0] * (o[1] + 1) + m[1]) * (o[2] + 1) + m[2]]);
            }
        }
        out
    }
}

/// The faces of the parameter cube that bound the solid (see the module notes): faces with
/// `max |x_s × x_t| ≤ 1e-12 · size²` on a 9 × 9 grid are dropped, and so are both faces
/// `v = 0, 1` when they coincide to `1e-9 · size` (`size`: the diagonal of the bounding
/// box of 125 points); the faces then take `v` as the closing direction.
pub fn boundary_faces(blend: &Arc<SolidBlend>) -> Vec<SolidFace> {
    let grid = |n: usize| (0..n).map(move |i| i as f64 / (n - 1) as f64);
    let mut lo = Vec3::new(f64::INFINITY, f64::INFINITY, f64::INFINITY);
    let mut hi = lo * -1.0;
    for u in grid(5) {
        for v in grid(5) {
            for w in grid(5) {
                let p = blend.point(u, v, w);
                (lo, hi) = (lo.min(p), hi.max(p));
            }
        }
    }
    let size = (hi - lo).norm();
    let periodic_v =
        grid(9).all(|u| grid(9).all(|w| (blend.point(u, 0.0, w) - blend.point(u, 1.0, w)).norm() <= 1e-9 * size));
    let mut out = Vec::new();
    for axis in 0..3 {
        if axis == 1 && periodic_v {
            continue;
        }
        for value in [0.0, 1.0] {
            let (p, q) = ((axis + 1) % 3, (axis + 2) % 3);
            // the periodic direction becomes the surface's v
            let dirs = if periodic_v && p == 1 { [q, p] } else { [p, q] };
            let f = SolidFace { blend: blend.clone(), axis, value, dirs, periodic: periodic_v && dirs[1] == 1 };
            let area = grid(9)
                .flat_map(|s| grid(9).map(move |t| (s, t)))
                .map(|(s, t)| {
                    let d = f.derivatives(s, t, 1, 1);
                    d[2].cross(d[1]).norm()
                })
                .fold(0.0, crate::num::max_nan);
            // written so that a NaN keeps the face (and its fit reports it)
            if area > 1e-12 * size * size || area.is_nan() {
                out.push(f);
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::super::blend::tests::{cubes, cylinders};
    use super::super::{SolidOperator, SolidOptions, gauss_legendre};
    use super::*;

    /// `V = ⅓ ∮ x · n dA` over the faces, each with its outward sign, by Gauss–Legendre.
    fn divergence_volume(faces: &[SolidFace], q: usize) -> f64 {
        let (x, w) = gauss_legendre(q);
        let mut v = 0.0;
        for f in faces {
            let sign = if f.outward_at(0.5, 0.5) { 1.0 } else { -1.0 };
            for (&s, &ws) in x.iter().zip(&w) {
                for (&t, &wt) in x.iter().zip(&w) {
                    let d = f.derivatives(s, t, 1, 1);
                    v += sign * ws * wt * d[0].dot(d[2].cross(d[1])) / 3.0;
                }
            }
        }
        v
    }

    #[test]
    fn the_faces_that_bound_the_solids_and_their_enclosed_volume() {
        let op = SolidOperator::new(1.0, 1.0, 1.0).unwrap();
        for (name, data, want) in [
            ("cylinders", cylinders(), ["u1", "w0", "w1"].as_slice()),
            ("cubes", cubes(), &["u0", "u1", "v0", "v1", "w0", "w1"]),
        ] {
            let s = Arc::new(SolidBlend::new(op, data, SolidOptions::default()).unwrap());
            let faces = boundary_faces(&s);
            let labels: Vec<String> = faces.iter().map(|f| f.label()).collect();
            assert_eq!(labels, want, "{name}");
            // periodic in v exactly for the cylinders, whose v is then every face's v
            assert!(faces.iter().all(|f| f.periodic == (name == "cylinders")), "{name}");
            if name == "cylinders" {
                assert!(faces.iter().all(|f| f.dirs[1] == 1));
            }
            // the outward side does not change over a face (det J keeps its sign)
            for f in &faces {
                let o = f.outward_at(0.5, 0.5);
                assert!(
                    (1..8).all(|i| (1..8).all(|j| f.outward_at(i as f64 / 8.0, j as f64 / 8.0) == o)),
                    "{name} {}",
                    f.label()
                );
            }
            // two independent volumes: ∫ det J over the cube, ⅓ ∮ x·n over the faces; both
            // quadratures converged (32 points on trigonometric terms of frequency ≤ 8π),
            // so they agree to round-off of the sums
            let by_faces = divergence_volume(&faces, 32);
            let by_jacobian = s.mass_properties(32).volume;
            assert!(
                by_faces > 0.0 && (by_faces - by_jacobian).abs() <= 1e-12 * by_jacobian,
                "{name}: {by_faces} vs {by_jacobian}"
            );
        }
    }

    #[test]
    fn a_section_is_the_solid_at_fixed_parameter() {
        let op = SolidOperator::new(1.0, 2.0, 1.0).unwrap();
        let s = Arc::new(
            SolidBlend::new(op, cylinders(), SolidOptions { terms: (3, 3, 3), ..Default::default() }).unwrap(),
        );
        let f = SolidFace::section(s.clone(), 2, 0.3);
        let d = f.derivatives(0.4, 0.7, 1, 1);
        let e = s.derivatives(0.4, 0.7, 0.3, 1, 1, 0);
        // (u, v) = (s, t): S = x, S_v = x_v, S_u = x_u, S_uv = x_uv, index (a (1 + 1) + b)
        assert_eq!([d[0], d[1], d[2], d[3]], [e[0], e[1], e[2], e[3]]);
    }
}
