//! Closed-form surfaces with hand-derived derivatives, for tests.

use super::{Surface, VDomain};
use crate::Vec3;

/// The sphere of radius r: X = r (sin πu cos v, sin πu sin v, cos πu), poles at u = 0, 1;
/// `∂ⁱ/∂uⁱ sin πu = πⁱ sin(πu + iπ/2)`, likewise in v.
pub(crate) struct Sphere(pub f64);

impl Surface for Sphere {
    fn v_domain(&self) -> VDomain {
        VDomain::PERIODIC
    }
    fn derivatives(&self, u: f64, v: f64, du: usize, dv: usize) -> Vec<Vec3> {
        let pi = std::f64::consts::PI;
        let mut out = Vec::new();
        for i in 0..=du {
            for j in 0..=dv {
                let a = self.0 * pi.powi(i as i32);
                let su = (pi * u + i as f64 * pi / 2.0).sin() * a;
                let cu = (pi * u + i as f64 * pi / 2.0).cos() * a;
                let cv = (v + j as f64 * pi / 2.0).cos();
                let sv = (v + j as f64 * pi / 2.0).sin();
                out.push(Vec3::new(su * cv, su * sv, if j == 0 { cu } else { 0.0 }));
            }
        }
        out
    }
}

/// The paraboloid `X = (u, v, u² + v²)` over the whole plane (derivatives by hand).
pub(crate) struct Paraboloid;

impl Surface for Paraboloid {
    fn v_domain(&self) -> VDomain {
        VDomain::open(-10.0, 10.0)
    }
    fn derivatives(&self, u: f64, v: f64, du: usize, dv: usize) -> Vec<Vec3> {
        let mut out = Vec::new();
        for i in 0..=du {
            for j in 0..=dv {
                let x = match (i, j) {
                    (0, 0) => u,
                    (1, 0) => 1.0,
                    _ => 0.0,
                };
                let y = match (i, j) {
                    (0, 0) => v,
                    (0, 1) => 1.0,
                    _ => 0.0,
                };
                let z = match (i, j) {
                    (0, 0) => u * u + v * v,
                    (1, 0) => 2.0 * u,
                    (0, 1) => 2.0 * v,
                    (2, 0) | (0, 2) => 2.0,
                    _ => 0.0,
                };
                out.push(Vec3::new(x, y, z));
            }
        }
        out
    }
}
