//! Curvatures of a parametric surface from its exact first and second derivatives.
//!
//! With the first fundamental form `E = X_u·X_u`, `F = X_u·X_v`, `G = X_v·X_v` and the
//! second `L = X_uu·n`, `M = X_uv·n`, `N = X_vv·n` against the unit normal
//! `n = X_u × X_v / |X_u × X_v|` (note `|X_u × X_v|² = E G − F²`):
//!
//! - Gaussian curvature `K = (L N − M²) / (E G − F²)` (independent of the normal's sign);
//! - mean curvature `H = (E N − 2 F M + G L) / (2 (E G − F²))` (positive where the surface
//!   bends towards `n`);
//! - principal curvatures `κ₁ ≤ κ₂`, the eigenvalues of the shape operator, the roots of
//!   `κ² − 2 H κ + K = 0`: `κ₁,₂ = H ∓ √(H² − K)`. `H² − K = ((κ₂ − κ₁)/2)² ≥ 0` holds
//!   exactly; a negative value from round-off (umbilics) is taken as 0.
//!
//! The normal curvature in a tangent direction `(du, dv)` is
//! `κₙ = (L du² + 2 M du dv + N dv²) / (E du² + 2 F du dv + G dv²)` (Euler/Meusnier), the
//! quantity the seam diagnostics compare across a trimline.

use crate::Vec3;

/// Curvatures at one point, all relative to the normal `X_u × X_v` (see the module).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Curvature {
    /// Gaussian curvature `K = κ₁ κ₂`.
    pub gauss: f64,
    /// Mean curvature `H = (κ₁ + κ₂) / 2`.
    pub mean: f64,
    /// The smaller principal curvature `κ₁`.
    pub k1: f64,
    /// The larger principal curvature `κ₂`.
    pub k2: f64,
}

/// The curvatures from the jets `[X, X_u, X_v, X_uu, X_uv, X_vv]`; `None` where
/// `X_u × X_v` vanishes (a pole) or is not finite.
///
/// ```
/// use pdeshape_core::{Vec3, patch::curvature};
/// // the saddle z = x y as (u, v, u v) at the origin: K = −1, H = 0, κ = ∓1
/// let j = [Vec3::ZERO, Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.0),
///          Vec3::ZERO, Vec3::new(0.0, 0.0, 1.0), Vec3::ZERO];
/// let c = curvature(&j).unwrap();
/// assert_eq!((c.gauss, c.mean, c.k1, c.k2), (-1.0, 0.0, -1.0, 1.0));
/// ```
pub fn curvature(j: &[Vec3; 6]) -> Option<Curvature> {
    let [_, xu, xv, xuu, xuv, xvv] = *j;
    let n = xu.cross(xv);
    let area2 = n.dot(n);
    let (e, f, g) = (xu.dot(xu), xu.dot(xv), xv.dot(xv));
    if !(area2 > 1e-24 * e * g && area2.is_finite()) {
        return None;
    }
    let n = n * (1.0 / area2.sqrt());
    let (l, m, nn) = (xuu.dot(n), xuv.dot(n), xvv.dot(n));
    let gauss = (l * nn - m * m) / area2;
    let mean = (e * nn - 2.0 * f * m + g * l) / (2.0 * area2);
    // H² − K ≥ 0 exactly; clamp the round-off below zero (at umbilics)
    let disc = mean * mean - gauss;
    let r = if disc > 0.0 { disc.sqrt() } else { 0.0 * disc };
    Some(Curvature { gauss, mean, k1: mean - r, k2: mean + r })
}

/// Which curvature a field or a picture shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum CurvatureKind {
    /// Gaussian curvature `K`.
    Gauss,
    /// Mean curvature `H`.
    Mean,
    /// The smaller principal curvature `κ₁`.
    K1,
    /// The larger principal curvature `κ₂`.
    K2,
}

impl CurvatureKind {
    /// All kinds, in the order of their fields.
    pub const ALL: [CurvatureKind; 4] =
        [CurvatureKind::Gauss, CurvatureKind::Mean, CurvatureKind::K1, CurvatureKind::K2];

    /// The name of the per-vertex mesh field holding it.
    pub fn field_name(self) -> &'static str {
        match self {
            CurvatureKind::Gauss => "gaussian_curvature",
            CurvatureKind::Mean => "mean_curvature",
            CurvatureKind::K1 => "k1",
            CurvatureKind::K2 => "k2",
        }
    }

    /// The value of this kind.
    pub fn of(self, c: &Curvature) -> f64 {
        match self {
            CurvatureKind::Gauss => c.gauss,
            CurvatureKind::Mean => c.mean,
            CurvatureKind::K1 => c.k1,
            CurvatureKind::K2 => c.k2,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::patch::{Surface, VDomain};

    /// Closed-form surfaces with hand-derived derivatives.
    enum Shape {
        /// (r sin u cos v, r sin u sin v, r cos u): X_u × X_v = r² sin u (outward) …
        Sphere(f64),
        /// (r cos v, r sin v, u): X_u × X_v = (−r cos v, −r sin v, 0), pointing to the axis.
        Cylinder(f64),
        /// (u, v, u v).
        Saddle,
    }
    impl Surface for Shape {
        fn v_domain(&self) -> VDomain {
            VDomain::PERIODIC
        }
        fn derivatives(&self, u: f64, v: f64, du: usize, dv: usize) -> Vec<Vec3> {
            let mut out = Vec::new();
            for i in 0..=du {
                for k in 0..=dv {
                    // d^i/du^i sin u = sin(u + iπ/2)
                    let s = |x: f64, d: usize| (x + d as f64 * std::f64::consts::FRAC_PI_2).sin();
                    let c = |x: f64, d: usize| (x + d as f64 * std::f64::consts::FRAC_PI_2).cos();
                    out.push(match self {
                        Shape::Sphere(r) => Vec3::new(
                            r * s(u, i) * c(v, k),
                            r * s(u, i) * s(v, k),
                            if k == 0 { r * c(u, i) } else { 0.0 },
                        ),
                        Shape::Cylinder(r) => Vec3::new(
                            if i == 0 { r * c(v, k) } else { 0.0 },
                            if i == 0 { r * s(v, k) } else { 0.0 },
                            match (i, k) {
                                (0, 0) => u,
                                (1, 0) => 1.0,
                                _ => 0.0,
                            },
                        ),
                        Shape::Saddle => {
                            let z = match (i, k) {
                                (0, 0) => u * v,
                                (1, 0) => v,
                                (0, 1) => u,
                                (1, 1) => 1.0,
                                _ => 0.0,
                            };
                            let x = match (i, k) {
                                (0, 0) => u,
                                (1, 0) => 1.0,
                                _ => 0.0,
                            };
                            let y = match (i, k) {
                                (0, 0) => v,
                                (0, 1) => 1.0,
                                _ => 0.0,
                            };
                            Vec3::new(x, y, z)
                        }
                    });
                }
            }
            out
        }
    }

    // Tolerances: K and H to a few ulps of their scale (~20 flops each); the principal
    // curvatures of the umbilic sphere to √ε (they are H ∓ √(H² − K) with H² − K pure
    // round-off there).
    #[test]
    fn sphere_cylinder_and_saddle_match_their_closed_forms() {
        for r in [0.5, 1.0, 3.7] {
            for (u, v) in [(0.3, 0.1), (1.2, 2.5), (2.9, 5.0)] {
                let c = curvature(&Shape::Sphere(r).jet2(u, v)).unwrap();
                // X_u × X_v points outward, the surface bends away from it: H = −1/r
                assert!((c.gauss - 1.0 / (r * r)).abs() < 1e-14 / (r * r), "{r} {c:?}");
                assert!((c.mean + 1.0 / r).abs() < 1e-14 / r, "{r} {c:?}");
                assert!((c.k1 + 1.0 / r).abs() < 1e-7 / r && (c.k2 + 1.0 / r).abs() < 1e-7 / r, "{c:?}");
                let c = curvature(&Shape::Cylinder(r).jet2(u, v)).unwrap();
                // the normal points to the axis: κ = 1/r across, 0 along; K = 0, H = 1/(2r)
                assert!(c.gauss.abs() < 1e-15 / (r * r), "{c:?}");
                assert!((c.mean - 0.5 / r).abs() < 1e-15 / r, "{c:?}");
                assert!(c.k1.abs() < 1e-15 / r && (c.k2 - 1.0 / r).abs() < 1e-15 / r, "{c:?}");
            }
        }
        let c = curvature(&Shape::Saddle.jet2(0.0, 0.0)).unwrap();
        assert_eq!((c.gauss, c.mean, c.k1, c.k2), (-1.0, 0.0, -1.0, 1.0));
        // away from the origin: K = −1/(1 + u² + v²)², H = −u v/(1 + u² + v²)^{3/2}
        for (u, v) in [(0.5, -0.25), (-1.5, 2.0)] {
            let w: f64 = 1.0 + u * u + v * v;
            let c = curvature(&Shape::Saddle.jet2(u, v)).unwrap();
            assert!((c.gauss + 1.0 / (w * w)).abs() < 1e-15, "{c:?}");
            assert!((c.mean + u * v / w.powf(1.5)).abs() < 1e-15, "{c:?}");
            assert!((c.k1 * c.k2 - c.gauss).abs() < 1e-15 && (c.k1 + c.k2 - 2.0 * c.mean).abs() < 1e-15);
        }
    }

    #[test]
    fn poles_and_nan_give_none() {
        // X_v = 0 at the sphere's pole
        assert!(curvature(&Shape::Sphere(1.0).jet2(0.0, 1.0)).is_none());
        let mut j = Shape::Saddle.jet2(0.2, 0.3);
        j[3].x = f64::NAN;
        let c = curvature(&j).unwrap();
        assert!(c.gauss.is_nan() || c.mean.is_nan(), "NaN data give NaN curvature: {c:?}");
        j[1] = Vec3::new(f64::NAN, 0.0, 0.0);
        assert!(curvature(&j).is_none());
    }
}
