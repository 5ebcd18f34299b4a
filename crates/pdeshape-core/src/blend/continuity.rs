//! Continuity of a blend with its primary surfaces along the trimlines.

use crate::Vec3;
use crate::data::{FieldRef, curve_derivative};
use crate::patch::Surface;

/// The gaps at one point of a trimline between the blend `X` at `(u_e, v)` and the
/// primary surface `S`, whose cross derivatives `∂ᵏS/∂uᵏ` (in the blend's `u`, i.e. scaled
/// trimline data) are the fields `data[k]`. Entries are `None` when the needed data are
/// not available.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Gaps {
    /// `|X − S|` (C0).
    pub c0: Option<f64>,
    /// `|X_u − S_u|` (C1, parametric).
    pub c1: Option<f64>,
    /// Angle in radians between the normals `X_u × X_v` and `S_u × S_v` (G1).
    pub g1: Option<f64>,
    /// `|X_uu − S_uu|` (C2, parametric).
    pub c2: Option<f64>,
    /// `|κ_X − κ_S|`: difference of the normal curvatures in the direction across the
    /// trimline (tangent, perpendicular to the trimline) (G2).
    pub g2: Option<f64>,
}

/// Thresholds of the continuity classification: relative to the patch size for C0, C1 and
/// C2, absolute for G1 (radians), and over the size for G2 (a curvature).
pub const CONTINUITY_TOL: f64 = 1e-8;

/// The highest continuity a seam meets at every point (see [`ContinuityClass::of`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ContinuityClass {
    /// Positions differ.
    None,
    /// Positions agree, normals do not.
    C0,
    /// Normals agree (G1), cross derivatives do not, curvature not matched.
    G1,
    /// Cross derivatives agree (C1), curvature not matched.
    C1,
    /// Normal curvature across the seam agrees (G2), second derivatives do not.
    G2,
    /// Second cross derivatives agree too (C2, which includes G2).
    C2,
}

impl ContinuityClass {
    /// The class met at every one of `ends` (worst gaps per seam) for a patch of size
    /// `size`: C0 at `CONTINUITY_TOL · size`, then G1 at `CONTINUITY_TOL` radians, C1 and
    /// C2 at `CONTINUITY_TOL · size`, G2 at `CONTINUITY_TOL / size`. A gap that was not
    /// computed, or is NaN, is not met.
    pub fn of(ends: &[Gaps], size: f64) -> Self {
        let ok = |f: fn(&Gaps) -> Option<f64>, tol: f64| ends.iter().all(|g| f(g).is_some_and(|x| x <= tol));
        let size = if size > 1e-300 { size } else { 1e-300 };
        let tol = CONTINUITY_TOL * size;
        if !ok(|g| g.c0, tol) {
            return ContinuityClass::None;
        }
        if !ok(|g| g.g1, CONTINUITY_TOL) {
            return ContinuityClass::C0;
        }
        let c1 = ok(|g| g.c1, tol);
        if c1 && ok(|g| g.c2, tol) {
            return ContinuityClass::C2;
        }
        if ok(|g| g.g2, CONTINUITY_TOL / size) {
            return ContinuityClass::G2;
        }
        if c1 { ContinuityClass::C1 } else { ContinuityClass::G1 }
    }

    /// `"none"`, `"C0"`, `"G1"`, `"C1"`, `"G2"` or `"C2"` (the reports' spelling).
    pub fn name(self) -> &'static str {
        match self {
            ContinuityClass::None => "none",
            ContinuityClass::C0 => "C0",
            ContinuityClass::G1 => "G1",
            ContinuityClass::C1 => "C1",
            ContinuityClass::G2 => "G2",
            ContinuityClass::C2 => "C2",
        }
    }
}

impl Gaps {
    /// Entry-wise maximum (NaN when either is NaN).
    pub fn max(self, o: Gaps) -> Gaps {
        let m = |a: Option<f64>, b: Option<f64>| match (a, b) {
            (Some(x), Some(y)) => Some(crate::num::max_nan(x, y)),
            (x, None) => x,
            (None, y) => y,
        };
        Gaps {
            c0: m(self.c0, o.c0),
            c1: m(self.c1, o.c1),
            g1: m(self.g1, o.g1),
            c2: m(self.c2, o.c2),
            g2: m(self.g2, o.g2),
        }
    }
}

/// Normal curvature across the curve `v ↦ X(u_e, v)`: with the first fundamental form
/// `E, F, G` and second `L, M, N` (unit normal `n = X_u × X_v / |…|`), the tangent
/// direction perpendicular to `X_v` is `(du, dv) = (1, −F/G)`, so
/// `κ = (L − 2M F/G + N F²/G²) / (E − F²/G)`.
fn cross_curvature(xu: Vec3, xv: Vec3, xuu: Vec3, xuv: Vec3, xvv: Vec3) -> Option<f64> {
    let n = xu.cross(xv).normalized()?;
    let (e, f, g) = (xu.dot(xu), xu.dot(xv), xv.dot(xv));
    if g == 0.0 {
        return None;
    }
    let (l, m, nn) = (xuu.dot(n), xuv.dot(n), xvv.dot(n));
    let lam = f / g;
    let den = e - f * lam;
    (den > 0.0).then(|| (l - 2.0 * m * lam + nn * lam * lam) / den)
}

fn angle(a: Vec3, b: Vec3) -> Option<f64> {
    let (a, b) = (a.normalized()?, b.normalized()?);
    Some(a.cross(b).norm().atan2(a.dot(b)))
}

/// The gaps at `(u_e, v)`; `data[k]` is `∂ᵏS/∂uᵏ` along the trimline, `k = 0, 1, 2`.
pub fn gaps_at(x: &dyn Surface, u_e: f64, v: f64, data: [Option<&FieldRef>; 3]) -> Gaps {
    let d = x.derivatives(u_e, v, 2, 2);
    let at = |i: usize, j: usize| d[i * 3 + j];
    let mut g = Gaps::default();
    let Some(s0) = data[0] else { return g };
    g.c0 = Some((at(0, 0) - s0.eval(&[v, 0.0])).norm());
    let Some(s1) = data[1] else { return g };
    let su = s1.eval(&[v, 0.0]);
    let sv = curve_derivative(s0.as_ref(), v, 0.0, 1);
    g.c1 = Some((at(1, 0) - su).norm());
    g.g1 = angle(at(1, 0).cross(at(0, 1)), su.cross(sv));
    let Some(s2) = data[2] else { return g };
    let suu = s2.eval(&[v, 0.0]);
    g.c2 = Some((at(2, 0) - suu).norm());
    let suv = curve_derivative(s1.as_ref(), v, 0.0, 1);
    let svv = curve_derivative(s0.as_ref(), v, 0.0, 2);
    let kx = cross_curvature(at(1, 0), at(0, 1), at(2, 0), at(1, 1), at(0, 2));
    let ks = cross_curvature(su, sv, suu, suv, svv);
    g.g2 = kx.zip(ks).map(|(a, b)| (a - b).abs());
    g
}

/// The largest gaps over `samples` points of the trimline `u = u_e`.
pub fn continuity(x: &dyn Surface, u_e: f64, data: [Option<&FieldRef>; 3], samples: usize) -> Gaps {
    seam_gaps(x, u_e, data, samples).max
}

/// The largest gaps along a trimline and where they are.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SeamGaps {
    /// Entry-wise maximum over the samples (NaN when any sample is NaN).
    pub max: Gaps,
    /// Per entry, the `v` of its maximum (the first NaN sample when there is one; the first
    /// of equal maxima otherwise).
    pub at: Gaps,
}

/// The gaps of a patch `X` attached along `u = u_e` to a curve `g` that lies on another
/// surface ([`crate::data::Field::host_normal`]; a trim curve of another patch): the
/// position gap `|X − g|` (C0) and the angle between the normal lines of `X` and of the
/// host surface (G1; an unsigned angle in `[0, π/2]`, as the two normals' orientations are
/// unrelated). `None` entries where the data have no host.
pub fn attached_gaps_at(x: &dyn Surface, u_e: f64, v: f64, data: &FieldRef) -> Gaps {
    let d = x.derivatives(u_e, v, 1, 1);
    let mut g = Gaps { c0: Some((d[0] - data.eval(&[v, 0.0])).norm()), ..Gaps::default() };
    g.g1 = data.host_normal(&[v, 0.0]).and_then(|h| {
        let (a, b) = (d[2].cross(d[1]).normalized()?, h.normalized()?);
        Some(a.cross(b).norm().atan2(a.dot(b).abs()))
    });
    g
}

/// [`seam_gaps`] of a patch attached to a curve on another surface ([`attached_gaps_at`]).
pub fn attached_seam_gaps(x: &dyn Surface, u_e: f64, data: &FieldRef, samples: usize) -> SeamGaps {
    seam_with(x, samples, |v| attached_gaps_at(x, u_e, v, data))
}

/// The gaps at `samples` points `v = start + (i + ½)/samples · (end − start)` of the
/// trimline `u = u_e`, their maxima and where the maxima are.
pub fn seam_gaps(x: &dyn Surface, u_e: f64, data: [Option<&FieldRef>; 3], samples: usize) -> SeamGaps {
    seam_with(x, samples, |v| gaps_at(x, u_e, v, data))
}

fn seam_with(x: &dyn Surface, samples: usize, gaps: impl Fn(f64) -> Gaps) -> SeamGaps {
    let dom = x.v_domain();
    let mut out = SeamGaps::default();
    for i in 0..samples {
        let v = dom.at((i as f64 + 0.5) / samples as f64);
        let g = gaps(v);
        let take = |best: &mut Option<f64>, at: &mut Option<f64>, new: Option<f64>| {
            if let Some(y) = new {
                let replace = match *best {
                    None => true,
                    Some(b) => !b.is_nan() && (y.is_nan() || y > b),
                };
                if replace {
                    *best = Some(y);
                    *at = Some(v);
                }
            }
        };
        take(&mut out.max.c0, &mut out.at.c0, g.c0);
        take(&mut out.max.c1, &mut out.at.c1, g.c1);
        take(&mut out.max.g1, &mut out.at.g1, g.g1);
        take(&mut out.max.c2, &mut out.at.c2, g.c2);
        take(&mut out.max.g2, &mut out.at.g2, g.g2);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn continuity_classes_from_hand_made_gaps() {
        let g = |c0, c1, g1, c2, g2| Gaps { c0, c1, g1, c2, g2 };
        let z = Some(0.0);
        let big = Some(1e-3);
        let class = |gs: &[Gaps]| ContinuityClass::of(gs, 2.0);
        assert_eq!(class(&[g(z, z, z, z, z)]), ContinuityClass::C2);
        assert_eq!(class(&[g(z, z, z, big, z)]), ContinuityClass::G2);
        assert_eq!(class(&[g(z, z, z, big, big)]), ContinuityClass::C1);
        assert_eq!(class(&[g(z, big, z, None, None)]), ContinuityClass::G1);
        assert_eq!(class(&[g(z, z, big, z, z)]), ContinuityClass::C0);
        assert_eq!(class(&[g(big, z, z, z, z)]), ContinuityClass::None);
        // not computed, or NaN, is not met; the worst end decides
        assert_eq!(class(&[g(None, z, z, z, z)]), ContinuityClass::None);
        assert_eq!(class(&[g(Some(f64::NAN), z, z, z, z)]), ContinuityClass::None);
        assert_eq!(class(&[g(z, z, z, z, z), g(z, z, Some(f64::NAN), z, z)]), ContinuityClass::C0);
        // C0, C1, C2 scale with the size (1e-8 × 2 here), G1 does not
        assert_eq!(class(&[g(Some(1.5e-8), z, z, z, z)]), ContinuityClass::C2);
        assert_eq!(class(&[g(Some(2.5e-8), z, z, z, z)]), ContinuityClass::None);
        assert_eq!(ContinuityClass::G2.name(), "G2");
    }
    use crate::data::{ExprField, Trimline};
    use crate::patch::VDomain;
    use std::sync::Arc;

    /// A cylinder of radius 2 as its own "blend": every gap vanishes against its trimline
    /// data, and the cross curvature of the sphere of radius 3 is 1/3 in magnitude.
    struct Param(ExprField);
    impl Surface for Param {
        fn v_domain(&self) -> VDomain {
            VDomain::PERIODIC
        }
        fn derivatives(&self, u: f64, v: f64, du: usize, dv: usize) -> Vec<Vec3> {
            let j = crate::data::Field::jet(&self.0, &[u, v, 0.0], crate::jet::JetShape::new(&[du, dv]));
            let mut out = Vec::new();
            for i in 0..=du {
                for k in 0..=dv {
                    out.push(j.derivative([i, k, 0]));
                }
            }
            out
        }
    }

    #[test]
    fn identical_surfaces_have_no_gaps_and_curvature_is_right() {
        let e = ["3*sin(s)*cos(v)", "3*sin(s)*sin(v)", "3*cos(s)"];
        let f = ExprField::parse(e, &["s", "v", "t"], &|_| None).unwrap();
        let fr: FieldRef = Arc::new(f.clone());
        let data: Vec<FieldRef> =
            (0..3).map(|k| Arc::new(Trimline::new(fr.clone(), 1.0, k, 1.0)) as FieldRef).collect();
        let g = continuity(&Param(f.clone()), 1.0, [Some(&data[0]), Some(&data[1]), Some(&data[2])], 50);
        for x in [g.c0, g.c1, g.g1, g.c2, g.g2] {
            assert!(x.unwrap() < 1e-13, "{g:?}");
        }
        let d = Param(f).derivatives(1.0, 0.4, 2, 2);
        let k = cross_curvature(d[3], d[1], d[6], d[4], d[2]).unwrap();
        assert!((k.abs() - 1.0 / 3.0).abs() < 1e-13, "{k}");
    }

    /// Against a sphere whose radius is 3 + 0.1 (1 + cos(v − 1.3)), the position gap along
    /// the trimline is 0.1 (1 + cos(v − 1.3)) (same direction, different radius): largest,
    /// 0.2, at v = 1.3, which the samples find to within half their spacing.
    #[test]
    fn seam_gaps_find_the_worst_place() {
        let e = ["3*sin(s)*cos(v)", "3*sin(s)*sin(v)", "3*cos(s)"];
        let f = ExprField::parse(e, &["s", "v", "t"], &|_| None).unwrap();
        let r = "(3 + 0.1*(1 + cos(v - 1.3)))";
        let o = [format!("{r}*sin(s)*cos(v)"), format!("{r}*sin(s)*sin(v)"), format!("{r}*cos(s)")];
        let other: FieldRef =
            Arc::new(ExprField::parse(o.each_ref().map(|x| x.as_str()), &["s", "v", "t"], &|_| None).unwrap());
        let data: Vec<FieldRef> =
            (0..3).map(|k| Arc::new(Trimline::new(other.clone(), 1.0, k, 1.0)) as FieldRef).collect();
        let n = 400;
        let g = seam_gaps(&Param(f), 1.0, [Some(&data[0]), Some(&data[1]), Some(&data[2])], n);
        let (v, c0) = (g.at.c0.unwrap(), g.max.c0.unwrap());
        let half = std::f64::consts::PI / n as f64;
        assert!((v - 1.3).abs() <= half, "{v}");
        // 0.1 (1 + cos δ) with |δ| ≤ half a spacing
        assert!(c0 <= 0.2 && c0 >= 0.1 * (1.0 + half.cos()) - 1e-15, "{c0}");
        assert_eq!(
            g.max,
            continuity(
                &Param(ExprField::parse(e, &["s", "v", "t"], &|_| None).unwrap()),
                1.0,
                [Some(&data[0]), Some(&data[1]), Some(&data[2])],
                n
            )
        );
        for at in [g.at.c1, g.at.g1, g.at.c2, g.at.g2] {
            assert!(at.is_some_and(|v| (0.0..2.0 * std::f64::consts::PI).contains(&v)));
        }
    }
}
