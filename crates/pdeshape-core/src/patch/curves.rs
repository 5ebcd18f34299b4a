//! Curves on a patch with their exact curvature: isoparameter curves `v ↦ X(u₀, v)` (the
//! trimlines of a blend among them) and plane sections, for curvature combs and the
//! editor's section tool.
//!
//! **Isoparameter curve.** For `c(v) = X(u₀, v)` the curvature vector is
//! `k = (c′ × c″) × c′ / |c′|⁴` (`κ = |k|`, pointing to the centre of curvature), from the
//! exact `X_v`, `X_vv`.
//!
//! **Plane section.** On the curve `{X : (X − p)·a = 0}` with `a` the unit plane normal and
//! `n` the unit surface normal, the tangent is `t = (n × a)/|n × a|` and the curvature
//! vector `k` lies in the plane and is perpendicular to `t`: `k = κ_s b` with `b = a × t`.
//! Meusnier: its normal component is the normal curvature, `k·n = II(t, t)`, so
//! `k = b II(t, t) / (b·n)`. `II(t, t) = L α² + 2 M α β + N β²` with `t = α X_u + β X_v`,
//! `(α, β)` solving `[E F; F G] (α, β) = (X_u·t, X_v·t)`. Undefined where the plane is
//! tangent to the surface (`b·n = 0`).
//!
//! Crossings are found on the edges of a parameter grid where `f = (X − p)·a` changes sign
//! and refined to round-off by safeguarded Newton steps on the exact `f` and its derivative
//! along the edge; every cell with crossings gives one or two segments (marching squares;
//! a saddle cell pairs its crossings in edge order).

use super::Surface;
use crate::Vec3;

/// A point of a curve on a surface and its curvature vector (`|k|` = curvature, pointing to
/// the centre of curvature; `NaN` components where it is undefined).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CurvePoint {
    /// The patch parameters.
    pub uv: [f64; 2],
    /// The point.
    pub point: Vec3,
    /// The curvature vector.
    pub curvature: Vec3,
}

/// The curve `v ↦ X(u, v)` at `vs` with exact curvature vectors.
pub fn iso_u_curve(s: &dyn Surface, u: f64, vs: &[f64]) -> Vec<CurvePoint> {
    vs.iter()
        .map(|&v| {
            let d = s.derivatives(u, v, 0, 2);
            let (c1, c2) = (d[1], d[2]);
            let l2 = c1.dot(c1);
            let k = c1.cross(c2).cross(c1) * (1.0 / (l2 * l2));
            CurvePoint { uv: [u, v], point: d[0], curvature: k }
        })
        .collect()
}

/// The curvature vector at `(u, v)` of the section by the plane with unit normal `a` (see
/// the module); NaN where the plane is tangent or the surface degenerate.
pub fn section_curvature(s: &dyn Surface, u: f64, v: f64, a: Vec3) -> Vec3 {
    let [_, xu, xv, xuu, xuv, xvv] = s.jet2(u, v);
    let nan = Vec3::new(f64::NAN, f64::NAN, f64::NAN);
    let Some(n) = xu.cross(xv).normalized() else { return nan };
    let Some(t) = n.cross(a).normalized() else { return nan };
    let b = a.cross(t);
    let (e, f, g) = (xu.dot(xu), xu.dot(xv), xv.dot(xv));
    let det = e * g - f * f;
    let (p, q) = (xu.dot(t), xv.dot(t));
    let (al, be) = ((g * p - f * q) / det, (e * q - f * p) / det);
    let ii = xuu.dot(n) * al * al + 2.0 * xuv.dot(n) * al * be + xvv.dot(n) * be * be;
    let bn = b.dot(n);
    if bn.abs() < 1e-12 {
        return nan;
    }
    b * (ii / bn)
}

/// The section of the patch by the plane through `p` with unit normal `a`, found on the
/// grid `us × vs`: segments between crossings on cell edges, each end refined on the exact
/// surface, with section curvature vectors.
pub fn plane_section(s: &dyn Surface, us: &[f64], vs: &[f64], p: Vec3, a: Vec3) -> Vec<[CurvePoint; 2]> {
    use rayon::prelude::*;
    let nv = vs.len();
    let g = s.grid(us, vs);
    let f: Vec<f64> = g.iter().map(|d| (d[0] - p).dot(a)).collect();
    // the crossing on the edge from grid node k0 to k1 (along u when `along_u`)
    let crossing = |k0: usize, k1: usize, along_u: bool| -> CurvePoint {
        let (i0, j0, i1, j1) = (k0 / nv, k0 % nv, k1 / nv, k1 % nv);
        let (mut lo, mut hi) = if along_u { (us[i0], us[i1]) } else { (vs[j0], vs[j1]) };
        let (mut flo, fixed) = (f[k0], if along_u { vs[j0] } else { us[i0] });
        let at = |x: f64| if along_u { (x, fixed) } else { (fixed, x) };
        let mut x = lo + (hi - lo) * flo / (flo - f[k1]);
        for _ in 0..60 {
            let (u, v) = at(x);
            let d = s.derivatives(u, v, 1, 1);
            let fx = (d[0] - p).dot(a);
            if fx == 0.0 {
                break;
            }
            // keep the bracket
            if (fx < 0.0) == (flo < 0.0) {
                lo = x;
                flo = fx;
            } else {
                hi = x;
            }
            let dfx = if along_u { d[2] } else { d[1] }.dot(a);
            let newton = x - fx / dfx;
            let next = if newton > lo.min(hi) && newton < lo.max(hi) { newton } else { 0.5 * (lo + hi) };
            if (next - x).abs() <= 4.0 * f64::EPSILON * x.abs().max(1.0) {
                x = next;
                break;
            }
            x = next;
        }
        let (u, v) = at(x);
        CurvePoint { uv: [u, v], point: s.point(u, v), curvature: section_curvature(s, u, v, a) }
    };
    let cells: Vec<(usize, usize)> =
        (0..us.len().saturating_sub(1)).flat_map(|i| (0..nv.saturating_sub(1)).map(move |j| (i, j))).collect();
    cells
        .par_iter()
        .flat_map_iter(|&(i, j)| {
            let k = |i: usize, j: usize| i * nv + j;
            // the cell's edges in order around it
            let edges = [
                (k(i, j), k(i + 1, j), true),
                (k(i + 1, j), k(i + 1, j + 1), false),
                (k(i, j + 1), k(i + 1, j + 1), true),
                (k(i, j), k(i, j + 1), false),
            ];
            let pts: Vec<CurvePoint> = edges
                .iter()
                .filter(|(a0, a1, _)| (f[*a0] < 0.0) != (f[*a1] < 0.0))
                .map(|&(a0, a1, along_u)| crossing(a0, a1, along_u))
                .collect();
            pts.chunks_exact(2).map(|c| [c[0], c[1]]).collect::<Vec<_>>()
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::patch::test_shapes::Sphere;

    /// A latitude circle u = u₀ of the sphere of radius r has radius ρ = r sin πu₀ and its
    /// curvature vector points to the axis: k = −(x, y, 0)/ρ².
    #[test]
    fn latitude_circles_have_curvature_one_over_their_radius() {
        let r = 2.5;
        let vs: Vec<f64> = (0..13).map(|j| j as f64 * 0.5).collect();
        for u in [0.2, 0.5, 0.83] {
            let rho = r * (std::f64::consts::PI * u).sin();
            for c in iso_u_curve(&Sphere(r), u, &vs) {
                let want = Vec3::new(-c.point.x, -c.point.y, 0.0) * (1.0 / (rho * rho));
                assert!((c.curvature - want).norm() < 1e-14 / rho, "{u}: {:?} vs {want:?}", c.curvature);
            }
        }
    }

    /// A plane at distance h from the centre of the sphere of radius r cuts a circle of
    /// radius √(r² − h²): every crossing lies on it (to round-off), and the section's
    /// curvature vector points from the point to the circle's centre with length 1/ρ.
    #[test]
    fn plane_sections_of_a_sphere_are_circles_with_exact_curvature() {
        let r = 2.0;
        let us: Vec<f64> = (0..=24).map(|i| i as f64 / 24.0).collect();
        let vs: Vec<f64> = (0..=48).map(|j| j as f64 / 48.0 * 2.0 * std::f64::consts::PI).collect();
        for (a, h) in
            [(Vec3::new(0.0, 0.0, 1.0), 0.7), (Vec3::new(0.6, 0.0, 0.8), -1.1), (Vec3::new(0.0, 1.0, 0.0), 0.0)]
        {
            let centre = a * h;
            let rho = (r * r - h * h).sqrt();
            let segs = plane_section(&Sphere(r), &us, &vs, centre, a);
            assert!(segs.len() > 40, "{a:?}: {} segments", segs.len());
            for c in segs.iter().flatten() {
                assert!((c.point - centre).dot(a).abs() < 1e-13, "on the plane");
                assert!(((c.point - centre).norm() - rho).abs() < 1e-13, "on the circle");
                if c.curvature.x.is_nan() {
                    // only at a pole of the parametrisation (the y = 0 plane passes through
                    // both): no normal there, so no curvature (documented)
                    assert!(c.uv[0] == 0.0 || c.uv[0] == 1.0, "{c:?}");
                    continue;
                }
                let want = (centre - c.point) * (1.0 / (rho * rho));
                assert!((c.curvature - want).norm() < 1e-11 / rho, "{a:?} {h}: {:?} vs {want:?}", c.curvature);
            }
        }
        // a plane that misses the sphere cuts nothing
        assert!(plane_section(&Sphere(r), &us, &vs, Vec3::new(0.0, 0.0, 2.5), Vec3::new(0.0, 0.0, 1.0)).is_empty());
    }
}
