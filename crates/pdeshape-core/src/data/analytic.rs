//! The analytic surfaces and curves of CAD files in their standard parametrisations
//! (ISO 10303-42), as fields with exact derivatives (jets of `cos`, `sin`), and the
//! closed-form inverse of each surface (the parameters of a point's foot).
//!
//! With a right-handed orthonormal frame `(o; x, y, z)` and `e(u) = cos u x + sin u y`:
//!
//! | surface | `S(u, v)` |
//! |---|---|
//! | plane | `o + u x + v y` |
//! | cylinder, radius `r` | `o + r e(u) + v z` |
//! | cone, radius `r` at `v = 0`, semi-angle `α` | `o + (r + v tan α) e(u) + v z` |
//! | sphere, radius `r` | `o + r cos v e(u) + r sin v z` |
//! | torus, radii `R`, `r` | `o + (R + r cos v) e(u) + r sin v z` |
//!
//! Curves: line `o + τ d`; circle `o + r e(τ)`; ellipse `o + a cos τ x + b sin τ y`.

use super::{Field, VecJet};
use crate::Vec3;
use crate::jet::{Jet, JetShape};

/// A right-handed orthonormal frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    /// The origin.
    pub o: Vec3,
    /// The first axis.
    pub x: Vec3,
    /// The second axis, `z × x`.
    pub y: Vec3,
    /// The third axis.
    pub z: Vec3,
}

impl Frame {
    /// The frame of an axis placement: `z` the axis, `x` the reference direction made
    /// orthogonal to it (its default when `None` or parallel to `z`: the first world axis
    /// not parallel to `z`, as ISO 10303-42 prescribes). `None` for a zero axis.
    pub fn new(o: Vec3, axis: Vec3, reference: Option<Vec3>) -> Option<Frame> {
        let z = axis.normalized()?;
        let project = |r: Vec3| (r - z * r.dot(z)).normalized();
        let x = reference.and_then(project).or_else(|| {
            [Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.0), Vec3::new(0.0, 0.0, 1.0)]
                .into_iter()
                .filter(|a| a.cross(z).norm() > 1e-6)
                .find_map(project)
        })?;
        Some(Frame { o, x, y: z.cross(x), z })
    }

    /// `(p − o)` in the frame's coordinates.
    pub fn local(&self, p: Vec3) -> Vec3 {
        let d = p - self.o;
        Vec3::new(d.dot(self.x), d.dot(self.y), d.dot(self.z))
    }

    /// The world frame.
    pub const WORLD: Frame =
        Frame { o: Vec3::ZERO, x: Vec3::new(1.0, 0.0, 0.0), y: Vec3::new(0.0, 1.0, 0.0), z: Vec3::new(0.0, 0.0, 1.0) };

    /// The point of frame coordinates `q`: `o + q.x x + q.y y + q.z z` (the inverse of
    /// [`local`](Self::local)); as a rigid motion, the frame placed where it is.
    pub fn global(&self, q: Vec3) -> Vec3 {
        self.o + self.rotate(q)
    }

    /// The direction of frame coordinates `d`: `d.x x + d.y y + d.z z`.
    pub fn rotate(&self, d: Vec3) -> Vec3 {
        self.x * d.x + self.y * d.y + self.z * d.z
    }

    /// The motion `p ↦ self.global(inner.global(p))`: `inner`, then `self`.
    pub fn then_in(&self, inner: &Frame) -> Frame {
        Frame { o: self.global(inner.o), x: self.rotate(inner.x), y: self.rotate(inner.y), z: self.rotate(inner.z) }
    }

    /// The inverse motion, `p ↦ self.local(p)`: the rows of the rotation are its columns.
    pub fn inverse(&self) -> Frame {
        let t = |k: usize| {
            let c = |v: Vec3| [v.x, v.y, v.z][k];
            Vec3::new(c(self.x), c(self.y), c(self.z))
        };
        let (x, y, z) = (t(0), t(1), t(2));
        let r = Frame { o: Vec3::ZERO, x, y, z };
        Frame { o: -r.rotate(self.o), x, y, z }
    }
}

/// An analytic surface's kind and size.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AnalyticKind {
    /// A plane.
    Plane,
    /// A cylinder of radius `r`.
    Cylinder {
        /// The radius.
        r: f64,
    },
    /// A cone of radius `r` at `v = 0` and semi-angle `alpha` (radians).
    Cone {
        /// The radius at `v = 0`.
        r: f64,
        /// The semi-angle.
        alpha: f64,
    },
    /// A sphere of radius `r`.
    Sphere {
        /// The radius.
        r: f64,
    },
    /// A torus of major radius `major` and minor radius `minor`.
    Torus {
        /// Distance from the axis to the tube's centre circle.
        major: f64,
        /// The tube's radius.
        minor: f64,
    },
}

/// An analytic surface `S(u, v)` (slots `u`, `v`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AnalyticSurface {
    /// The kind and size.
    pub kind: AnalyticKind,
    /// The placement.
    pub frame: Frame,
}

/// `a x + b y + c z + o` of jets.
fn combine(f: &Frame, a: &Jet, b: &Jet, c: &Jet, origin: bool) -> VecJet {
    let comp = |k: usize| {
        let o = if origin { f.o[k] } else { 0.0 };
        a.scale(f.x[k]).add(&b.scale(f.y[k])).add(&c.scale(f.z[k])).add_scalar(o)
    };
    VecJet([comp(0), comp(1), comp(2)])
}

/// The representative of the angle `a` within `π` of `near` (the one continuation keeps).
pub fn unwrap_angle(a: f64, near: f64) -> f64 {
    let tau = std::f64::consts::TAU;
    a + tau * ((near - a) / tau).round()
}

impl AnalyticSurface {
    /// The parameters of the foot of `p` on the surface (closed form); angles are taken
    /// nearest to `near`'s (when given), so that a walk along a curve stays continuous.
    pub fn invert(&self, p: Vec3, near: Option<[f64; 2]>) -> [f64; 2] {
        let l = self.frame.local(p);
        let u = l.y.atan2(l.x);
        let rho = l.x.hypot(l.y);
        let h = l.z;
        let uw = |u: f64| near.map_or(u, |n| unwrap_angle(u, n[0]));
        let vw = |v: f64| near.map_or(v, |n| unwrap_angle(v, n[1]));
        match self.kind {
            AnalyticKind::Plane => [l.x, l.y],
            AnalyticKind::Cylinder { .. } => [uw(u), h],
            // the foot on the nearer of the two generators `(±(r + v tan α), v)` in the
            // point's plane through the axis: the cone is double, and past the apex
            // (`r + v tan α < 0`) the point's own half-plane holds the other nappe, whose
            // angle is `u + π`
            AnalyticKind::Cone { r, alpha } => {
                let (s, c) = alpha.sin_cos();
                let t = s / c;
                let foot = |x: f64| ((x - r) * t + h) * c * c;
                if (rho - r - h * t).abs() <= (-rho - r - h * t).abs() {
                    [uw(u), foot(rho)]
                } else {
                    [uw(u + std::f64::consts::PI), foot(-rho)]
                }
            }
            AnalyticKind::Sphere { .. } => [uw(u), h.atan2(rho)],
            // the nearer of the two tube circles in the point's plane through the axis:
            // on a spindle torus (minor > major) the inner, lemon-shaped part (`major +
            // minor cos v < 0`) lies in the half-plane of angle `u + π`
            AnalyticKind::Torus { major, minor } => {
                let own = ((rho - major).hypot(h) - minor).abs();
                let opposite = ((rho + major).hypot(h) - minor).abs();
                if own <= opposite {
                    [uw(u), vw(h.atan2(rho - major))]
                } else {
                    [uw(u + std::f64::consts::PI), vw(h.atan2(-rho - major))]
                }
            }
        }
    }

    /// Whether the surface is periodic in `u` (period 2π) and in `v`.
    pub fn periodic(&self) -> [bool; 2] {
        match self.kind {
            AnalyticKind::Plane => [false, false],
            AnalyticKind::Torus { .. } => [true, true],
            _ => [true, false],
        }
    }
}

impl Field for AnalyticSurface {
    fn arity(&self) -> usize {
        2
    }

    /// In closed form: in the frame, every kind but the plane is `(ρ(v) cos u, ρ(v) sin u,
    /// ζ(v))` (cylinder `ρ = r, ζ = v`; cone `ρ = r + v tan α, ζ = v`; sphere `ρ = r cos v,
    /// ζ = r sin v`; torus `ρ = R + r cos v, ζ = r sin v`), so its Taylor coefficients are
    /// products `ρⱼ cᵢ`, `ρⱼ sᵢ`, `ζⱼ` (`i = 0`) of the univariate ones, with
    /// `cᵢ = cos(u₀ + iπ/2)/i!`, `sᵢ = sin(u₀ + iπ/2)/i!` — no jet arithmetic (the faces
    /// of CAD models are evaluated at every point of a fill's fit).
    fn jet(&self, at: &[f64], shape: JetShape) -> VecJet {
        let [ou, ov, _] = shape.orders();
        let (u0, v0) = (at[0], at.get(1).copied().unwrap_or(0.0));
        let n = shape.len();
        let (mut a, mut b, mut c) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
        let at_ij = |i: usize, j: usize| shape.index([i, j, 0]);
        // cos and sin of `x₀ + kπ/2` over k!, k = 0 … m
        let turns = |x0: f64, m: usize| -> Vec<(f64, f64)> {
            let (s0, c0) = x0.sin_cos();
            let mut fact = 1.0;
            (0..=m)
                .map(|k| {
                    if k > 0 {
                        fact *= k as f64;
                    }
                    let (cs, sn) = match k % 4 {
                        0 => (c0, s0),
                        1 => (-s0, c0),
                        2 => (-c0, -s0),
                        _ => (s0, -c0),
                    };
                    (cs / fact, sn / fact)
                })
                .collect()
        };
        match self.kind {
            AnalyticKind::Plane => {
                a[0] = u0;
                b[0] = v0;
                if ou >= 1 {
                    a[at_ij(1, 0)] = 1.0;
                }
                if ov >= 1 {
                    b[at_ij(0, 1)] = 1.0;
                }
            }
            kind => {
                // ρⱼ and ζⱼ, j = 0 … ov
                let mut rho = vec![0.0; ov + 1];
                let mut zeta = vec![0.0; ov + 1];
                let line = |z: &mut Vec<f64>| {
                    z[0] = v0;
                    if ov >= 1 {
                        z[1] = 1.0;
                    }
                };
                match kind {
                    AnalyticKind::Cylinder { r } => {
                        rho[0] = r;
                        line(&mut zeta);
                    }
                    AnalyticKind::Cone { r, alpha } => {
                        let t = alpha.tan();
                        rho[0] = r + v0 * t;
                        if ov >= 1 {
                            rho[1] = t;
                        }
                        line(&mut zeta);
                    }
                    AnalyticKind::Sphere { r } | AnalyticKind::Torus { minor: r, .. } => {
                        for (j, (cv, sv)) in turns(v0, ov).into_iter().enumerate() {
                            rho[j] = r * cv;
                            zeta[j] = r * sv;
                        }
                        if let AnalyticKind::Torus { major, .. } = kind {
                            rho[0] += major;
                        }
                    }
                    AnalyticKind::Plane => unreachable!("handled above"),
                }
                for (i, (cu, su)) in turns(u0, ou).into_iter().enumerate() {
                    for (j, &rj) in rho.iter().enumerate() {
                        a[at_ij(i, j)] = rj * cu;
                        b[at_ij(i, j)] = rj * su;
                    }
                }
                for (j, &zj) in zeta.iter().enumerate() {
                    c[at_ij(0, j)] = zj;
                }
            }
        }
        let f = &self.frame;
        VecJet(std::array::from_fn(|k| {
            let mut out: Vec<f64> = (0..n).map(|q| a[q] * f.x[k] + b[q] * f.y[k] + c[q] * f.z[k]).collect();
            out[0] += f.o[k];
            Jet::from_coeffs(shape, out)
        }))
    }

    fn is_constant_in(&self, slot: usize) -> bool {
        slot >= 2
    }
}

/// An analytic curve `C(τ)` (slot `τ`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AnalyticCurve {
    /// `o + τ d`.
    Line {
        /// A point.
        o: Vec3,
        /// The direction times the speed.
        d: Vec3,
    },
    /// `o + a cos τ x + b sin τ y` (a circle when `a = b`).
    Ellipse {
        /// The placement.
        frame: Frame,
        /// The semi-axis along `x`.
        a: f64,
        /// The semi-axis along `y`.
        b: f64,
    },
}

impl AnalyticCurve {
    /// The parameter of the foot of `p` (closed form for lines and circles; for an
    /// ellipse the eccentric angle of the point's projection, exact on the curve).
    pub fn invert(&self, p: Vec3) -> f64 {
        match *self {
            AnalyticCurve::Line { o, d } => (p - o).dot(d) / d.dot(d),
            AnalyticCurve::Ellipse { frame, a, b } => {
                let l = frame.local(p);
                (l.y / b).atan2(l.x / a)
            }
        }
    }

    /// Whether the curve is closed (period 2π).
    pub fn is_closed(&self) -> bool {
        matches!(self, AnalyticCurve::Ellipse { .. })
    }
}

impl Field for AnalyticCurve {
    fn arity(&self) -> usize {
        1
    }

    fn jet(&self, at: &[f64], shape: JetShape) -> VecJet {
        let t = Jet::variable(shape, 0, at[0]);
        match *self {
            AnalyticCurve::Line { o, d } => {
                VecJet([t.scale(d.x).add_scalar(o.x), t.scale(d.y).add_scalar(o.y), t.scale(d.z).add_scalar(o.z)])
            }
            AnalyticCurve::Ellipse { frame, a, b } => {
                combine(&frame, &t.cos().scale(a), &t.sin().scale(b), &Jet::constant(shape, 0.0), true)
            }
        }
    }

    fn is_constant_in(&self, slot: usize) -> bool {
        slot >= 1
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame() -> Frame {
        Frame::new(Vec3::new(0.5, -1.0, 2.0), Vec3::new(1.0, 2.0, 2.0), Some(Vec3::new(1.0, 0.0, 0.0))).unwrap()
    }

    /// The closed-form jets against the same surfaces written in jet arithmetic (`cos`,
    /// `sin`, products of truncated series: an independent path), every coefficient up to
    /// `∂u⁴∂v⁵` (and a `t` slot of order 1, on which nothing depends), at several points.
    #[test]
    fn closed_form_jets_match_jet_arithmetic() {
        let f = frame();
        let kinds = [
            AnalyticKind::Plane,
            AnalyticKind::Cylinder { r: 1.3 },
            AnalyticKind::Cone { r: 0.7, alpha: 0.4 },
            AnalyticKind::Sphere { r: 2.1 },
            AnalyticKind::Torus { major: 3.0, minor: 0.8 },
            AnalyticKind::Torus { major: 0.5, minor: 1.2 },
        ];
        let shape = JetShape::new(&[4, 5, 1]);
        for kind in kinds {
            let s = AnalyticSurface { kind, frame: f };
            for (u0, v0) in [(0.0, 0.0), (0.7, -0.3), (-2.9, 1.1), (5.5, 2.4)] {
                let u = Jet::variable(shape, 0, u0);
                let v = Jet::variable(shape, 1, v0);
                let zero = Jet::constant(shape, 0.0);
                let want = match kind {
                    AnalyticKind::Plane => combine(&f, &u, &v, &zero, true),
                    AnalyticKind::Cylinder { r } => combine(&f, &u.cos().scale(r), &u.sin().scale(r), &v, true),
                    AnalyticKind::Cone { r, alpha } => {
                        let rad = v.scale(alpha.tan()).add_scalar(r);
                        combine(&f, &rad.mul(&u.cos()), &rad.mul(&u.sin()), &v, true)
                    }
                    AnalyticKind::Sphere { r } => {
                        let rad = v.cos().scale(r);
                        combine(&f, &rad.mul(&u.cos()), &rad.mul(&u.sin()), &v.sin().scale(r), true)
                    }
                    AnalyticKind::Torus { major, minor } => {
                        let rad = v.cos().scale(minor).add_scalar(major);
                        combine(&f, &rad.mul(&u.cos()), &rad.mul(&u.sin()), &v.sin().scale(minor), true)
                    }
                };
                let got = s.jet(&[u0, v0, 0.3], shape);
                for m in shape.multi_indices() {
                    for k in 0..3 {
                        let (g, w) = (got.0[k].coeff(m), want.0[k].coeff(m));
                        // coefficients of size ≤ ~4, a few roundings on either path
                        assert!((g - w).abs() <= 4e-15, "{kind:?} at ({u0}, {v0}) {m:?}[{k}]: {g} vs {w}");
                    }
                }
            }
        }
    }

    /// Motions as frames: `global` undoes `local`, `then_in` is applying one after the
    /// other, `inverse` composed either way is the identity — against a quarter turn
    /// about z written out by hand.
    #[test]
    fn frames_compose_and_invert_as_motions() {
        let f = frame();
        let g =
            Frame::new(Vec3::new(3.0, 0.0, -1.0), Vec3::new(0.0, 0.0, 1.0), Some(Vec3::new(0.0, 1.0, 0.0))).unwrap();
        let p = Vec3::new(0.3, -2.0, 1.7);
        // g turns x onto y and moves by (3, 0, -1): (x, y, z) ↦ (3 − y, x, z − 1)
        let want = Vec3::new(3.0 - p.y, p.x, p.z - 1.0);
        assert!((g.global(p) - want).norm() < 1e-15, "{}", g.global(p));
        for q in [f.global(f.local(p)), f.local(f.global(p)), f.inverse().global(f.global(p))] {
            // a few roundings of coordinates of size ~3
            assert!((q - p).norm() < 4e-15, "{q}");
        }
        let both = f.then_in(&g);
        assert!((both.global(p) - f.global(g.global(p))).norm() < 4e-15);
        for id in [f.then_in(&f.inverse()), f.inverse().then_in(&f)] {
            for (a, b) in [(id.o, Vec3::ZERO), (id.x, Frame::WORLD.x), (id.y, Frame::WORLD.y), (id.z, Frame::WORLD.z)] {
                assert!((a - b).norm() < 4e-15, "{a} vs {b}");
            }
        }
    }

    /// Each surface's inverse returns the parameters it was evaluated at, and its first
    /// derivatives are the closed forms' (written out per kind).
    #[test]
    fn inverses_and_derivatives_by_hand() {
        let f = frame();
        let kinds = [
            AnalyticKind::Plane,
            AnalyticKind::Cylinder { r: 1.5 },
            AnalyticKind::Cone { r: 1.5, alpha: 0.4 },
            AnalyticKind::Sphere { r: 2.0 },
            AnalyticKind::Torus { major: 3.0, minor: 0.7 },
        ];
        for kind in kinds {
            let s = AnalyticSurface { kind, frame: f };
            for (u, v) in [(0.3, 0.2), (2.9, -0.4), (-1.2, 1.1)] {
                let j = s.jet(&[u, v], JetShape::new(&[1, 1]));
                let back = s.invert(j.value(), Some([u, v]));
                // round-off of atan2 and of the frame's dot products, values ≤ 5
                assert!((back[0] - u).abs() < 1e-14 && (back[1] - v).abs() < 1e-14, "{kind:?} {u} {v}: {back:?}");
                let e = f.x * u.cos() + f.y * u.sin();
                let e1 = f.y * u.cos() - f.x * u.sin();
                let (su, sv) = match kind {
                    AnalyticKind::Plane => (f.x, f.y),
                    AnalyticKind::Cylinder { r } => (e1 * r, f.z),
                    AnalyticKind::Cone { r, alpha } => (e1 * (r + v * alpha.tan()), e * alpha.tan() + f.z),
                    AnalyticKind::Sphere { r } => (e1 * (r * v.cos()), (e * -v.sin() + f.z * v.cos()) * r),
                    AnalyticKind::Torus { major, minor } => {
                        (e1 * (major + minor * v.cos()), (e * -v.sin() + f.z * v.cos()) * minor)
                    }
                };
                assert!((j.derivative([1, 0, 0]) - su).norm() < 1e-14, "{kind:?} S_u");
                assert!((j.derivative([0, 1, 0]) - sv).norm() < 1e-14, "{kind:?} S_v");
            }
        }
    }

    /// A cone is double: past its apex (`r + v tan α < 0`, where files such as EUCLID's
    /// put faces) the point lies in the half-plane of angle `u + π`, and its foot is on
    /// that nappe, not at the apex.
    #[test]
    fn a_point_past_a_cone_apex_is_inverted_onto_its_own_nappe() {
        let s =
            AnalyticSurface { kind: AnalyticKind::Cone { r: 7.5, alpha: std::f64::consts::FRAC_PI_4 }, frame: frame() };
        for (u, v) in [(0.3, -17.5), (2.0, -7.6), (-2.5, -30.0), (1.0, 4.0)] {
            let p = s.eval(&[u, v]);
            for near in [None, Some([u, v])] {
                let back = s.invert(p, near);
                // the same point back to round-off (coordinates ≤ 40)
                assert!((s.eval(&back) - p).norm() < 1e-13, "{u} {v} {near:?}: {back:?}");
                assert!((back[1] - v).abs() < 1e-13, "{u} {v}: {back:?}");
            }
        }
    }

    /// A spindle torus (minor radius above the major, as EUCLID writes a screw's domed
    /// head): where `major + minor cos v < 0` the point lies in the half-plane of angle
    /// `u + π`, and its foot is on that tube circle.
    #[test]
    fn a_point_on_a_spindle_torus_lemon_is_inverted_onto_it() {
        let s = AnalyticSurface { kind: AnalyticKind::Torus { major: 8.25, minor: 54.87 }, frame: frame() };
        for (u, v) in [(0.3, 1.75), (2.0, -1.9), (-2.5, 0.2), (1.0, 2.9)] {
            let p = s.eval(&[u, v]);
            for near in [None, Some([u, v])] {
                let back = s.invert(p, near);
                // the same point back to round-off (coordinates ≤ 70)
                assert!((s.eval(&back) - p).norm() < 1e-12, "{u} {v} {near:?}: {back:?}");
            }
            let back = s.invert(p, Some([u, v]));
            assert!((back[0] - u).abs() < 1e-13 && (back[1] - v).abs() < 1e-13, "{u} {v}: {back:?}");
        }
    }

    #[test]
    fn frames_follow_iso_10303_42() {
        // reference direction not orthogonal: made so; missing: the first world axis
        let f = Frame::new(Vec3::ZERO, Vec3::new(0.0, 0.0, 2.0), Some(Vec3::new(1.0, 0.0, 1.0))).unwrap();
        assert_eq!((f.x, f.y, f.z), (Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 1.0, 0.0), Vec3::new(0.0, 0.0, 1.0)));
        let g = Frame::new(Vec3::ZERO, Vec3::new(1.0, 0.0, 0.0), None).unwrap();
        assert_eq!((g.x, g.y), (Vec3::new(0.0, 1.0, 0.0), Vec3::new(0.0, 0.0, 1.0)));
        assert!(Frame::new(Vec3::ZERO, Vec3::ZERO, None).is_none());
    }

    #[test]
    fn curves_invert() {
        let l = AnalyticCurve::Line { o: Vec3::new(1.0, 2.0, 3.0), d: Vec3::new(0.0, 2.0, 0.0) };
        assert_eq!(l.invert(l.eval(&[0.75])), 0.75);
        let c = AnalyticCurve::Ellipse { frame: frame(), a: 2.0, b: 1.0 };
        assert!((c.invert(c.eval(&[2.5])) - 2.5).abs() < 1e-15);
    }
}
