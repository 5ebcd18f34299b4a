//! A space curve that lies on a surface, seen in the surface's domain: the foot-point
//! map `c(τ) = argmin_{(u,v)} |S(u, v) − C(τ)|²` — a CAD edge on its face, where the file
//! gives the edge's 3D curve `C` and the face's surface `S`.
//!
//! **Derivatives, exactly.** `c` solves `F(c, τ) = (S_u·(S − C), S_v·(S − C)) = 0`.
//! Writing `c(τ₀ + h) = Σ cₘ hᵐ`, the coefficient of `hᵐ` in `F` is
//! `H cₘ + rₘ(c₀ … cₘ₋₁)` with `H = ∂F/∂c` at the foot (the Hessian of `½|S − C|²`:
//! `[S_u·S_u + S_uu·d, S_u·S_v + S_uv·d; ·, S_v·S_v + S_vv·d]`, `d = S − C`), so each
//! coefficient follows from the ones before by one 2 × 2 solve: `cₘ = −H⁻¹ rₘ`, with `rₘ`
//! the `hᵐ` coefficient of `F` evaluated in truncated Taylor arithmetic with `cₘ = 0`
//! (`S`, `S_u`, `S_v` along `c` from the surface's Taylor coefficients at `c₀`). This is
//! the implicit function theorem order by order, exact to round-off; no finite
//! differences.
//!
//! **The foot itself** is found by Newton's method on `F` from the nearest of the feet
//! computed at construction by continuation along the curve (so a periodic surface's
//! angle stays on one branch).

use crate::Vec3;
use crate::data::{Field, FieldRef, VecJet};
use crate::jet::{Jet, JetShape};

/// `c(τ)` as a field of one slot (components `u`, `v`, `0`).
#[derive(Clone, Debug)]
pub struct FootCurve {
    host: FieldRef,
    curve: FieldRef,
    t: f64,
    /// Feet at increasing or decreasing `τ`, in the order of the walk.
    seeds: Vec<(f64, [f64; 2])>,
    max_distance: f64,
}

/// Why the foot curve cannot be made.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum FootError {
    /// Newton's method did not settle at some `τ`.
    #[error("the curve's foot on the surface is not found near τ = {0}")]
    NoFoot(f64),
    /// The surface is singular (its tangent plane undefined) under the curve.
    #[error("the surface is singular under the curve at τ = {0}")]
    Singular(f64),
}

struct Local {
    s: Vec3,
    su: Vec3,
    sv: Vec3,
    suu: Vec3,
    suv: Vec3,
    svv: Vec3,
}

fn local(host: &dyn Field, c: [f64; 2], t: f64) -> Local {
    let j = host.jet(&[c[0], c[1], t], JetShape::new(&[2, 2]));
    Local {
        s: j.value(),
        su: j.derivative([1, 0, 0]),
        sv: j.derivative([0, 1, 0]),
        suu: j.derivative([2, 0, 0]),
        suv: j.derivative([1, 1, 0]),
        svv: j.derivative([0, 2, 0]),
    }
}

/// `H` and the gradient `g` of `½|S − p|²` at `c`.
fn hessian(l: &Local, p: Vec3) -> ([[f64; 2]; 2], [f64; 2]) {
    let d = l.s - p;
    let h = [
        [l.su.dot(l.su) + l.suu.dot(d), l.su.dot(l.sv) + l.suv.dot(d)],
        [l.su.dot(l.sv) + l.suv.dot(d), l.sv.dot(l.sv) + l.svv.dot(d)],
    ];
    (h, [l.su.dot(d), l.sv.dot(d)])
}

/// `H⁻¹ r`, `None` when `H` is singular relative to its size.
fn solve2(h: [[f64; 2]; 2], r: [f64; 2]) -> Option<[f64; 2]> {
    let det = h[0][0] * h[1][1] - h[0][1] * h[1][0];
    let size = (h[0][0].abs() + h[0][1].abs()) * (h[1][0].abs() + h[1][1].abs());
    // NaN fails too
    if det.abs().is_nan() || det.abs() <= 1e-13 * size {
        return None;
    }
    Some([(h[1][1] * r[0] - h[0][1] * r[1]) / det, (h[0][0] * r[1] - h[1][0] * r[0]) / det])
}

/// The foot of `p` on `host` (slots `u`, `v`, `t`) by Newton's method from `c`; `None`
/// when it does not settle in 40 steps.
pub fn foot_of(host: &dyn Field, p: Vec3, c: [f64; 2], t: f64) -> Option<[f64; 2]> {
    newton(host, p, c, t).map(|(c, _)| c)
}

/// [`foot_of`], with the surface's local data at the last Newton step's start (less than
/// round-off of the point's size from the foot).
fn newton(host: &dyn Field, p: Vec3, mut c: [f64; 2], t: f64) -> Option<([f64; 2], Local)> {
    for _ in 0..40 {
        let l = local(host, c, t);
        let (h, g) = hessian(&l, p);
        // far from the surface the full Hessian may be indefinite: Gauss–Newton then
        let step = solve2(h, g)
            .filter(|_| h[0][0] > 0.0 && h[0][0] * h[1][1] > h[0][1] * h[1][0])
            .or_else(|| solve2([[l.su.dot(l.su), l.su.dot(l.sv)], [l.su.dot(l.sv), l.sv.dot(l.sv)]], g))?;
        c = [c[0] - step[0], c[1] - step[1]];
        if !(c[0].is_finite() && c[1].is_finite()) {
            return None;
        }
        // the step in space below round-off of the point's size
        let moved = (l.su * step[0] + l.sv * step[1]).norm();
        if moved <= 1e-15 * (1.0 + l.s.norm()) {
            return Some((c, l));
        }
    }
    None
}

impl FootCurve {
    /// The foot curve of `curve` (slot `τ`) on `host` (slots `u`, `v`, `t`) for
    /// `τ ∈ range` (either order), starting from the foot `start` of `C(range.0)` (or a
    /// point near it).
    pub fn new(host: FieldRef, curve: FieldRef, range: (f64, f64), start: [f64; 2], t: f64) -> Result<Self, FootError> {
        let steps = 128;
        let mut seeds = Vec::with_capacity(steps + 1);
        let mut max_distance: f64 = 0.0;
        // each foot checked: not singular, by the tangents of its last Newton step (at the
        // foot to round-off), and how far the curve lies off the surface, at the foot
        let mut check = |tau: f64, p: Vec3, c: [f64; 2], l: &Local| {
            if l.su.cross(l.sv).norm() <= 1e-12 * l.su.norm() * l.sv.norm() {
                return Err(FootError::Singular(tau));
            }
            max_distance = crate::num::max_nan(max_distance, (host.eval(&[c[0], c[1], t]) - p).norm());
            Ok(())
        };
        let p0 = curve.eval(&[range.0]);
        let (mut c, l) = newton(host.as_ref(), p0, start, t).ok_or(FootError::NoFoot(range.0))?;
        check(range.0, p0, c, &l)?;
        seeds.push((range.0, c));
        for i in 1..=steps {
            let tau = range.0 + (range.1 - range.0) * i as f64 / steps as f64;
            let p = curve.eval(&[tau]);
            // Newton starts from the last two feet's line (off the foot by the square of
            // the step, where the last foot alone is off by the step; from the last foot
            // where that fails)
            let guess = match seeds.len() {
                1 => c,
                n => {
                    let b = seeds[n - 2].1;
                    [2.0 * c[0] - b[0], 2.0 * c[1] - b[1]]
                }
            };
            let l;
            (c, l) = newton(host.as_ref(), p, guess, t)
                .or_else(|| newton(host.as_ref(), p, c, t))
                .ok_or(FootError::NoFoot(tau))?;
            check(tau, p, c, &l)?;
            seeds.push((tau, c));
        }
        Ok(FootCurve { host, curve, t, seeds, max_distance })
    }

    /// The largest distance between the curve and its foot at the construction's samples
    /// (how far the file's curve lies off the surface).
    pub fn max_distance(&self) -> f64 {
        self.max_distance
    }

    /// The surface's point at domain parameters `c` (at the curve's time).
    pub fn surface_point(&self, c: [f64; 2]) -> Vec3 {
        self.host.eval(&[c[0], c[1], self.t])
    }

    /// The foot at `τ`, from the nearest seed.
    pub fn foot(&self, tau: f64) -> Option<[f64; 2]> {
        let (t0, t1) = (self.seeds[0].0, self.seeds[self.seeds.len() - 1].0);
        let x = if t1 == t0 { 0.0 } else { (tau - t0) / (t1 - t0) * (self.seeds.len() - 1) as f64 };
        let i = x.round().clamp(0.0, (self.seeds.len() - 1) as f64) as usize;
        foot_of(self.host.as_ref(), self.curve.eval(&[tau]), self.seeds[i].1, self.t)
    }
}

/// `Σ_{i+j ≤ m} coef(i, j) δuⁱ δvʲ` for vector coefficients.
fn compose(shape: JetShape, m: usize, du: &Jet, dv: &Jet, coef: impl Fn(usize, usize) -> Vec3) -> [Jet; 3] {
    let mut out = std::array::from_fn(|_| Jet::constant(shape, 0.0));
    let mut pu = Jet::constant(shape, 1.0);
    for i in 0..=m {
        if i > 0 {
            pu = pu.mul(du);
        }
        let mut term = pu.clone();
        for j in 0..=m - i {
            if j > 0 {
                term = term.mul(dv);
            }
            let c = coef(i, j);
            for (o, x) in out.iter_mut().zip([c.x, c.y, c.z]) {
                *o = o.add(&term.scale(x));
            }
        }
    }
    out
}

fn dot3(a: &[Jet; 3], b: &[Jet; 3]) -> Jet {
    a[0].mul(&b[0]).add(&a[1].mul(&b[1])).add(&a[2].mul(&b[2]))
}

impl Field for FootCurve {
    fn arity(&self) -> usize {
        1
    }

    fn jet(&self, at: &[f64], shape: JetShape) -> VecJet {
        let k = shape.orders()[0];
        let tau = at[0];
        let nan = || VecJet::constant(shape, Vec3::new(f64::NAN, f64::NAN, f64::NAN));
        let Some(c0) = self.foot(tau) else { return nan() };
        // Taylor coefficients of S at the foot, T[i][j] = ∂ᵢ∂ⱼS / (i! j!), i, j ≤ k + 1
        let hj = self.host.jet(&[c0[0], c0[1], self.t], JetShape::new(&[k + 1, k + 1]));
        let tc = |i: usize, j: usize| {
            if i > k + 1 || j > k + 1 {
                return Vec3::ZERO;
            }
            Vec3::new(hj.0[0].coeff([i, j, 0]), hj.0[1].coeff([i, j, 0]), hj.0[2].coeff([i, j, 0]))
        };
        let cj = self.curve.jet(&[tau], JetShape::new(&[k]));
        let ct = |m: usize| Vec3::new(cj.0[0].coeff([m, 0, 0]), cj.0[1].coeff([m, 0, 0]), cj.0[2].coeff([m, 0, 0]));
        let l =
            Local { s: tc(0, 0), su: tc(1, 0), sv: tc(0, 1), suu: tc(2, 0) * 2.0, suv: tc(1, 1), svv: tc(0, 2) * 2.0 };
        let (h, _) = hessian(&l, ct(0));
        let (mut a, mut b) = (vec![c0[0]], vec![c0[1]]);
        for m in 1..=k {
            let sh = JetShape::new(&[m]);
            let poly = |c: &[f64]| {
                let mut v = vec![0.0; m + 1];
                v[1..c.len()].copy_from_slice(&c[1..]);
                Jet::from_coeffs(sh, v)
            };
            let (du, dv) = (poly(&a), poly(&b));
            let s = compose(sh, m, &du, &dv, tc);
            let su = compose(sh, m, &du, &dv, |i, j| tc(i + 1, j) * (i + 1) as f64);
            let sv = compose(sh, m, &du, &dv, |i, j| tc(i, j + 1) * (j + 1) as f64);
            let cm: [Jet; 3] =
                std::array::from_fn(|q| Jet::from_coeffs(sh, (0..=m).map(|i| cj.0[q].coeff([i, 0, 0])).collect()));
            let d: [Jet; 3] = std::array::from_fn(|q| s[q].sub(&cm[q]));
            let r = [dot3(&su, &d).coeff([m, 0, 0]), dot3(&sv, &d).coeff([m, 0, 0])];
            let Some(x) = solve2(h, r) else { return nan() };
            a.push(-x[0]);
            b.push(-x[1]);
        }
        let comp = |c: &[f64]| {
            let mut v = vec![0.0; shape.len()];
            for (i, x) in c.iter().enumerate() {
                v[shape.index([i, 0, 0])] = *x;
            }
            Jet::from_coeffs(shape, v)
        };
        VecJet([comp(&a), comp(&b), Jet::constant(shape, 0.0)])
    }

    fn is_constant_in(&self, slot: usize) -> bool {
        slot >= 1
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::ExprField;
    use crate::data::tests::Counted;
    use std::sync::Arc;

    /// A helix on a cylinder of radius 2 whose foot curve is known in closed form:
    /// `C(τ) = (2 cos τ², 2 sin τ², τ³)` on `S(u, v) = (2 cos u, 2 sin u, v)` has
    /// `c(τ) = (τ², τ³)`; every derivative to the fourth against it. Then the same curve
    /// lifted 1e-3 off the cylinder along the normal: the foot is unchanged (the normal
    /// offset is orthogonal to the tangent plane), so the derivatives are the same — which
    /// the Hessian's curvature terms must get right.
    #[test]
    fn derivatives_against_the_closed_form() {
        let host = Arc::new(ExprField::parse(["2*cos(u)", "2*sin(u)", "v"], &["u", "v", "t"], &|_| None).unwrap());
        for lift in [0.0, 1e-3] {
            let r = 2.0 + lift;
            let curve = Arc::new(
                ExprField::parse(
                    [format!("{r}*cos(s*s)").as_str(), format!("{r}*sin(s*s)").as_str(), "s*s*s"],
                    &["s"],
                    &|_| None,
                )
                .unwrap(),
            );
            let f = FootCurve::new(host.clone(), curve, (0.5, 1.5), [0.25, 0.1], 0.0).unwrap();
            assert!((f.max_distance() - lift).abs() < 1e-14, "{}", f.max_distance());
            for tau in [0.5, 0.77, 1.3] {
                let j = f.jet(&[tau], JetShape::new(&[4]));
                let want_u = [tau * tau, 2.0 * tau, 2.0, 0.0, 0.0];
                let want_v = [tau.powi(3), 3.0 * tau * tau, 6.0 * tau, 6.0, 0.0];
                for m in 0..=4 {
                    let d = j.derivative([m, 0, 0]);
                    // round-off grows with the order (each order divides by H once)
                    let tol = 1e-13 * 10f64.powi(m as i32);
                    assert!((d.x - want_u[m]).abs() < tol, "lift {lift} τ {tau} u({m}) {} vs {}", d.x, want_u[m]);
                    assert!((d.y - want_v[m]).abs() < tol, "lift {lift} τ {tau} v({m}) {} vs {}", d.y, want_v[m]);
                }
            }
        }
    }

    /// The construction's walk along the helix of the test above, lifted 1e-3, for
    /// `τ ∈ [0.5, 2.5]`: its 129 feet are the closed form's `(τ², τ³)` to round-off, the
    /// distance is the lift, and each foot costs four jets of the surface: three Newton
    /// steps from the line through the two feet before (the third finds its step below
    /// round-off, and its tangents check the foot) and the foot's point. Newton from the
    /// last foot alone takes 598 in all, with a separate check of each foot 643 (both
    /// checked).
    #[test]
    fn the_walk_predicts_each_foot() {
        let host = ExprField::parse(["2*cos(u)", "2*sin(u)", "v"], &["u", "v", "t"], &|_| None).unwrap();
        let curve =
            Arc::new(ExprField::parse(["2.001*cos(s*s)", "2.001*sin(s*s)", "s*s*s"], &["s"], &|_| None).unwrap());
        let counted = Arc::new(Counted::new(host));
        let f = FootCurve::new(counted.clone(), curve, (0.5, 2.5), [0.25, 0.1], 0.0).unwrap();
        assert!((f.max_distance() - 1e-3).abs() < 1e-14, "{}", f.max_distance());
        assert_eq!(f.seeds.len(), 129);
        for &(tau, c) in &f.seeds {
            // Newton settles to round-off of the parameters' size (up to 15.6)
            let tol = 4.0 * f64::EPSILON * (1.0 + tau.powi(3));
            assert!((c[0] - tau * tau).abs() < tol && (c[1] - tau.powi(3)).abs() < tol, "{tau}: {c:?}");
        }
        let jets = counted.count();
        assert!(jets <= 4 * 129, "{jets} jets of the surface for 129 feet");
    }
}
