//! Mass properties of a solid blend from its analytic Jacobian.

use super::{SolidBlend, gauss_legendre};
use crate::Vec3;

/// Volume, centroid and inertia of the solid `x([0, 1]³)` (unit density), by `q³`-point
/// Gauss quadrature of `det J = x_u · (x_v × x_w)` with exact derivatives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MassProperties {
    /// `∫ |det J|`.
    pub volume: f64,
    /// `∫ x |det J| / V`.
    pub centroid: Vec3,
    /// Inertia tensor about the centroid, `∫ (|r|² I − r rᵀ) |det J|`, `r = x − centroid`.
    pub inertia: [[f64; 3]; 3],
    /// Smallest `det J` at the quadrature points (and an interior grid); a sign change
    /// against `max_jacobian` means the map folds.
    pub min_jacobian: f64,
    /// Largest `det J` at the same points.
    pub max_jacobian: f64,
}

impl MassProperties {
    /// True when `det J` changes sign or vanishes (the solid folds over itself); a
    /// uniformly negative `det J` is only a reversed orientation.
    pub fn folds(&self) -> bool {
        // NaN (a Jacobian that could not be evaluated) counts as a fold: nothing shows
        // that the map is one-to-one there
        !(self.min_jacobian > 0.0 || self.max_jacobian < 0.0)
    }
}

impl SolidBlend {
    /// Mass properties by `q`-point Gauss rules in each direction.
    pub fn mass_properties(&self, q: usize) -> MassProperties {
        let (x, w) = gauss_legendre(q.max(2));
        let mut pts: Vec<(f64, f64, f64, f64)> = Vec::with_capacity(x.len().pow(3));
        for (&u, &wu) in x.iter().zip(&w) {
            for (&v, &wv) in x.iter().zip(&w) {
                for (&t, &wt) in x.iter().zip(&w) {
                    pts.push((u, v, t, wu * wv * wt));
                }
            }
        }
        use rayon::prelude::*;
        let samples: Vec<(Vec3, f64, f64)> = pts
            .par_iter()
            .map(|&(u, v, t, q)| {
                let [xu, xv, xw] = self.jacobian(u, v, t);
                (self.point(u, v, t), xu.dot(xv.cross(xw)), q)
            })
            .collect();
        let (mut vol, mut first) = (0.0, Vec3::ZERO);
        let (mut jmin, mut jmax) = (f64::INFINITY, f64::NEG_INFINITY);
        for &(p, j, q) in &samples {
            vol += q * j.abs();
            first += p * (q * j.abs());
            // a NaN Jacobian makes both NaN, and `folds` then reports a fold
            jmin = crate::num::min_nan(jmin, j);
            jmax = crate::num::max_nan(jmax, j);
        }
        let c = first / vol;
        let mut inertia = [[0.0; 3]; 3];
        for &(p, j, q) in &samples {
            let r = p - c;
            let r2 = r.dot(r);
            for a in 0..3 {
                for b in 0..3 {
                    inertia[a][b] += q * j.abs() * (if a == b { r2 } else { 0.0 } - r[a] * r[b]);
                }
            }
        }
        MassProperties { volume: vol, centroid: c, inertia, min_jacobian: jmin, max_jacobian: jmax }
    }
}
