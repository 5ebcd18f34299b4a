//! The boundary data of an N-sided fill along its loop: positions and cross tangents taken
//! from the neighbouring surfaces, with the cross tangent rotated within each neighbour's
//! tangent plane near the corners so that it is continuous (see the module `fill`).

use super::series::{binomial, mul};
use crate::Vec3;
use crate::data::{Field, FieldRef, VecJet};
use crate::jet::{Jet, JetShape};
use std::f64::consts::TAU;

/// One edge of the loop: the isoline `s = s0` of a neighbour `S(s, w, t)` from `w0` to `w1`,
/// traversed by the fill's `v ∈ [V_k, V_{k+1}]` (`V_k = 2πk/N`) through
/// `w(v) = w0 + λ (v − V_k)`, `λ = (w1 − w0) N / 2π`.
#[derive(Clone, Debug)]
pub(crate) struct Piece {
    pub surface: FieldRef,
    pub s0: f64,
    pub w0: f64,
    pub lambda: f64,
    /// The cross tangent along the edge, away from the corners: `c S_s`.
    pub c: f64,
    /// At the start corner: `T_c = a S_s + b S_w` there; likewise at the end corner.
    pub start: (f64, f64),
    pub end: (f64, f64),
    /// At a corner whose neighbours are not G1 the common cross tangent `T_c` lies in
    /// neither tangent plane: its part along `N = S_s × S_w`, `T_c = a S_s + b S_w + g N`,
    /// faded by the same bumps (0 at G1 corners). Without it the cross tangent would jump
    /// at the corner and the fill with it; with it G1 is given up within that corner's
    /// blend only, where no surface can meet both neighbours G1.
    pub start_n: f64,
    pub end_n: f64,
    /// Second cross derivative (order 2 only): the corrections `γ S_s + δ S_w + η N` that
    /// make it continuous at the start and end corners (`N = S_s × S_w`), faded by the
    /// same bumps as the cross tangent's weights.
    pub start2: [f64; 3],
    pub end2: [f64; 3],
}

/// `1 − (35x⁴ − 84x⁵ + 70x⁶ − 20x⁷)` on `[0, 1]`, 0 beyond: 1 at the corner, 0 at the
/// blend's end, with three vanishing derivatives at both ends (C³ joins). Returns the
/// Taylor coefficients in `v` (`x = (v − v_c)/h` or its mirror, `dx/dv = slope`) up to
/// `order`.
fn bump(x: f64, slope: f64, order: usize) -> Vec<f64> {
    let mut out = vec![0.0; order + 1];
    if !(0.0..1.0).contains(&x) {
        return out;
    }
    // p(x) = 1 − 35x⁴ + 84x⁵ − 70x⁶ + 20x⁷ as coefficients in x
    let p = [1.0, 0.0, 0.0, 0.0, -35.0, 84.0, -70.0, 20.0];
    // Taylor coefficients at x: p⁽ᵏ⁾(x)/k!, then scaled by slopeᵏ
    for (k, o) in out.iter_mut().enumerate() {
        let mut acc = 0.0;
        for (n, &a) in p.iter().enumerate().skip(k) {
            // C(n, k) x^(n−k)
            acc += a * binomial(n, k) * x.powi((n - k) as i32);
        }
        *o = acc * slope.powi(k as i32);
    }
    out
}

fn add(a: &[f64], b: &[f64]) -> Vec<f64> {
    a.iter().zip(b).map(|(x, y)| x + y).collect()
}

fn sub(a: &[f64], b: &[f64]) -> Vec<f64> {
    a.iter().zip(b).map(|(x, y)| x - y).collect()
}

/// `[S, S_s, S_w, S_ss, S_sw, S_ww]` of `surface` at `(s, w, t)`.
pub(crate) fn second_frame(surface: &FieldRef, s: f64, w: f64, t: f64) -> [Vec3; 6] {
    let j = surface.jet(&[s, w, t], JetShape::new(&[2, 2, 0]));
    let g = |m: [usize; 3], f: f64| Vec3::new(j.0[0].coeff(m), j.0[1].coeff(m), j.0[2].coeff(m)) * f;
    [g([0, 0, 0], 1.0), g([1, 0, 0], 1.0), g([0, 1, 0], 1.0), g([2, 0, 0], 2.0), g([1, 1, 0], 1.0), g([0, 2, 0], 2.0)]
}

/// The loop data: `order` 0 (position), 1 (cross tangent) or 2 (second cross derivative).
#[derive(Clone, Debug)]
pub(crate) struct LoopData {
    pub pieces: Vec<Piece>,
    pub order: usize,
    /// The corner blend's half-width as a fraction of an edge's `v`-range (≤ ½).
    pub blend: f64,
}

impl LoopData {
    /// The edge holding `v` (taken modulo 2π; a corner belongs to the edge it starts) and
    /// `v − V_k`.
    fn locate(&self, v: f64) -> (usize, f64) {
        let n = self.pieces.len();
        let dv = TAU / n as f64;
        let v = v.rem_euclid(TAU);
        let k = ((v / dv).floor() as usize).min(n - 1);
        (k, v - k as f64 * dv)
    }

    /// Taylor coefficients in `v` (up to `order`) of the three components, at `v`.
    pub fn series(&self, v: f64, t: f64, order: usize) -> [Vec<f64>; 3] {
        let (k, dv) = self.locate(v);
        let p = &self.pieces[k];
        let w = p.w0 + p.lambda * dv;
        let ds = self.order.max(1);
        let sj = p.surface.jet(&[p.s0, w, t], JetShape::new(&[ds, order + ds, 0]));
        let lam_pow: Vec<f64> = (0..=order + ds).map(|j| p.lambda.powi(j as i32)).collect();
        if self.order == 0 {
            return std::array::from_fn(|c| (0..=order).map(|j| sj.0[c].coeff([0, j, 0]) * lam_pow[j]).collect());
        }
        // weights of S_s and S_w: α = (1 − ω_s − ω_e) c + ω_s a_s + ω_e a_e, β = ω_s b_s + ω_e b_e
        let span = TAU / self.pieces.len() as f64;
        let h = self.blend * span;
        let ws = bump(dv / h, 1.0 / h, order);
        let we = bump((span - dv) / h, -1.0 / h, order);
        let alpha: Vec<f64> = (0..=order)
            .map(|j| {
                let one = if j == 0 { 1.0 } else { 0.0 };
                (one - ws[j] - we[j]) * p.c + ws[j] * p.start.0 + we[j] * p.end.0
            })
            .collect();
        let beta: Vec<f64> = (0..=order).map(|j| ws[j] * p.start.1 + we[j] * p.end.1).collect();
        // S_s(s0, w(v)) and S_w(s0, w(v)) as series in v
        let ss: [Vec<f64>; 3] =
            std::array::from_fn(|c| (0..=order).map(|j| sj.0[c].coeff([1, j, 0]) * lam_pow[j]).collect());
        let sw: [Vec<f64>; 3] = std::array::from_fn(|c| {
            (0..=order).map(|j| (j + 1) as f64 * sj.0[c].coeff([0, j + 1, 0]) * lam_pow[j]).collect()
        });
        let n: [Vec<f64>; 3] = std::array::from_fn(|c| {
            let (c1, c2) = ((c + 1) % 3, (c + 2) % 3);
            sub(&mul(&ss[c1], &sw[c2]), &mul(&ss[c2], &sw[c1]))
        });
        if self.order == 1 {
            // T = α S_s + β S_w + ν N, ν = ω_s g_s + ω_e g_e (0 unless a corner is not G1)
            if p.start_n == 0.0 && p.end_n == 0.0 {
                return std::array::from_fn(|c| add(&mul(&alpha, &ss[c]), &mul(&beta, &sw[c])));
            }
            let nu: Vec<f64> = (0..=order).map(|j| ws[j] * p.start_n + we[j] * p.end_n).collect();
            return std::array::from_fn(|c| add(&add(&mul(&alpha, &ss[c]), &mul(&beta, &sw[c])), &mul(&nu, &n[c])));
        }
        // Q = α² S_ss + 2αβ S_sw + β² S_ww + ω_s (γ S_s + δ S_w + η N)_s + ω_e (…)_e
        let aa = mul(&alpha, &alpha);
        let ab: Vec<f64> = mul(&alpha, &beta).iter().map(|x| 2.0 * x).collect();
        let bb = mul(&beta, &beta);
        std::array::from_fn(|c| {
            let sss: Vec<f64> = (0..=order).map(|j| 2.0 * sj.0[c].coeff([2, j, 0]) * lam_pow[j]).collect();
            let ssw: Vec<f64> =
                (0..=order).map(|j| (j + 1) as f64 * sj.0[c].coeff([1, j + 1, 0]) * lam_pow[j]).collect();
            let sww: Vec<f64> =
                (0..=order).map(|j| ((j + 1) * (j + 2)) as f64 * sj.0[c].coeff([0, j + 2, 0]) * lam_pow[j]).collect();
            let mut q = add(&add(&mul(&aa, &sss), &mul(&ab, &ssw)), &mul(&bb, &sww));
            for (w, [g, d, e]) in [(&ws, p.start2), (&we, p.end2)] {
                let corr: Vec<f64> = (0..=order).map(|j| g * ss[c][j] + d * sw[c][j] + e * n[c][j]).collect();
                q = add(&q, &mul(w, &corr));
            }
            q
        })
    }

    /// The cross tangent's weights and their `v`-derivatives, `[(α, α′), (β, β′)]`.
    fn weights_series(&self, p: &Piece, dv: f64) -> [(f64, f64); 2] {
        let span = TAU / self.pieces.len() as f64;
        let h = self.blend * span;
        let (ws, we) = (bump(dv / h, 1.0 / h, 1), bump((span - dv) / h, -1.0 / h, 1));
        let w = |k: usize| (ws[k], we[k]);
        let ((s0, e0), (s1, e1)) = (w(0), w(1));
        [
            ((1.0 - s0 - e0) * p.c + s0 * p.start.0 + e0 * p.end.0, (-s1 - e1) * p.c + s1 * p.start.0 + e1 * p.end.0),
            (s0 * p.start.1 + e0 * p.end.1, s1 * p.start.1 + e1 * p.end.1),
        ]
    }

    /// The values of the cross tangent's weights `(α, β)` on piece `p` at `v − V_k = dv`.
    fn weights(&self, p: &Piece, dv: f64) -> (f64, f64) {
        let span = TAU / self.pieces.len() as f64;
        let h = self.blend * span;
        let (ws, we) = (bump(dv / h, 1.0, 0)[0], bump((span - dv) / h, 1.0, 0)[0]);
        ((1.0 - ws - we) * p.c + ws * p.start.0 + we * p.end.0, ws * p.start.1 + we * p.end.1)
    }

    /// Where the corner blends end, `(v, 3)` each: across these lines the cross derivatives
    /// are only C³ in `v` (the bump `ω` has three vanishing derivatives at its end, not
    /// four). A blend that moves nothing is left out: the data are then smooth across its
    /// end. A blend moves nothing when, at its corner, its change of the cross tangent
    /// `(a − c) S_s + b S_w + g N` is at most 1e-12 of `|c S_s|` and (order-6 data) the change
    /// `γ S_s + δ S_w + η N` of the second cross derivative at most 1e-12 of `|c S_s|² κ`,
    /// `κ` the larger of `|S_ss| / |S_s|²` and `|S_ww| / |S_w|²`. So it is at the corners
    /// of a closed smooth edge cut into pieces (as a CAD model's single closed edge is):
    /// both sides see such a corner alike, and the means equal each side's own data.
    pub fn blend_joins(&self, t: f64) -> Vec<(f64, usize)> {
        let n = self.pieces.len();
        let span = TAU / n as f64;
        let h = self.blend * span;
        let mut out = Vec::new();
        for (k, p) in self.pieces.iter().enumerate() {
            for (w, (a, b), g, q, at) in [
                (p.w0, p.start, p.start_n, p.start2, k as f64 * span + h),
                (p.w0 + p.lambda * span, p.end, p.end_n, p.end2, (k + 1) as f64 * span - h),
            ] {
                let f = second_frame(&p.surface, p.s0, w, t);
                let nn = f[1].cross(f[2]);
                let first = f[1] * (a - p.c) + f[2] * b + nn * g;
                let second = f[1] * q[0] + f[2] * q[1] + nn * q[2];
                let cross = (f[1] * p.c).norm();
                let kappa = crate::num::max_nan(f[3].norm() / f[1].dot(f[1]), f[5].norm() / f[2].dot(f[2]));
                // a blend with a non-finite frame or correction counts as moving
                let moves = |d: Vec3, base: f64| d.norm().is_nan() || base.is_nan() || d.norm() > 1e-12 * base;
                if moves(first, cross) || moves(second, cross * cross * kappa) {
                    out.push((at, 3));
                }
            }
        }
        out.sort_by(|x, y| x.0.total_cmp(&y.0));
        out.dedup_by(|x, y| x.0 == y.0);
        out
    }

    /// The neighbour's `[S, S_s, S_w, S_ss, S_sw, S_ww]` at the loop's `v` (for diagnostics).
    pub fn frame2(&self, v: f64, t: f64) -> [Vec3; 6] {
        let (k, dv) = self.locate(v);
        let p = &self.pieces[k];
        second_frame(&p.surface, p.s0, p.w0 + p.lambda * dv, t)
    }

    /// The neighbour's point, `S_s` and `S_w` at the loop's `v` (for diagnostics).
    pub fn frame(&self, v: f64, t: f64) -> (Vec3, Vec3, Vec3) {
        let (k, dv) = self.locate(v);
        let p = &self.pieces[k];
        let j = p.surface.jet(&[p.s0, p.w0 + p.lambda * dv, t], JetShape::new(&[1, 1, 0]));
        let g = |m: [usize; 3]| Vec3::new(j.0[0].coeff(m), j.0[1].coeff(m), j.0[2].coeff(m));
        (g([0, 0, 0]), g([1, 0, 0]), g([0, 1, 0]))
    }
}

impl Field for LoopData {
    fn arity(&self) -> usize {
        2
    }
    fn jet(&self, at: &[f64], shape: JetShape) -> VecJet {
        let [ov, _, _] = shape.orders();
        let t = at.get(1).copied().unwrap_or(0.0);
        let s = self.series(at[0], t, ov);
        // the fill is static: no t-dependence (its neighbours are taken at the given t)
        VecJet(std::array::from_fn(|c| {
            let coeffs: Vec<f64> = shape.multi_indices().map(|[j, l, _]| if l == 0 { s[c][j] } else { 0.0 }).collect();
            Jet::from_coeffs(shape, coeffs)
        }))
    }
    fn is_constant_in(&self, slot: usize) -> bool {
        slot == 1
    }
    /// The fast paths (the neighbours' compiled one-slot derivatives, no jets): positions
    /// to any order along `v` (`dʲ/dvʲ S(s₀, w(v)) = λʲ ∂ʲS/∂wʲ`), the cross tangent's value
    /// (`α S_s + β S_w` from one derivative along `s` and one along `w`); the rest through
    /// the jets.
    fn derivatives_in(&self, at: &[f64], slot: usize, out: &mut [Vec3]) {
        let t = at.get(1).copied().unwrap_or(0.0);
        if slot == 1 {
            out.iter_mut().enumerate().for_each(|(k, o)| *o = if k == 0 { self.eval(at) } else { Vec3::ZERO });
            return;
        }
        let (k, dv) = self.locate(at[0]);
        let p = &self.pieces[k];
        let on = [p.s0, p.w0 + p.lambda * dv, t];
        if self.order == 0 {
            p.surface.derivatives_in(&on, 1, out);
            let mut f = 1.0;
            for o in out.iter_mut().skip(1) {
                f *= p.lambda;
                *o *= f;
            }
        } else if self.order == 1 && (p.start_n != 0.0 || p.end_n != 0.0) {
            // a corner that is not G1: the normal part through the series
            crate::data::derivatives_by_jet(self, at, slot, out);
        } else if self.order == 1 && out.len() == 1 {
            let (mut along_s, mut along_w) = ([Vec3::ZERO; 2], [Vec3::ZERO; 2]);
            p.surface.derivatives_in(&on, 0, &mut along_s);
            p.surface.derivatives_in(&on, 1, &mut along_w);
            let (alpha, beta) = self.weights(p, dv);
            out[0] = along_s[1] * alpha + along_w[1] * beta;
        } else if self.order == 1 && out.len() == 2 {
            // T = α S_s + β S_w, T′ = α′ S_s + α λ S_sw + β′ S_w + β λ S_ww (one small jet
            // of the neighbour for the mixed derivative)
            let j = p.surface.jet(&on, JetShape::new(&[1, 2, 0]));
            let g = |m: [usize; 3], f: f64| Vec3::new(j.0[0].coeff(m), j.0[1].coeff(m), j.0[2].coeff(m)) * f;
            let (ss, sw, ssw, sww) = (g([1, 0, 0], 1.0), g([0, 1, 0], 1.0), g([1, 1, 0], 1.0), g([0, 2, 0], 2.0));
            let [(a, da), (b, db)] = self.weights_series(p, dv);
            out[0] = ss * a + sw * b;
            out[1] = ss * da + sw * db + (ssw * a + sww * b) * p.lambda;
        } else {
            crate::data::derivatives_by_jet(self, at, slot, out);
        }
    }
    /// The neighbour's `S_s × S_w` at the loop point (position data only: the cross tangent
    /// is not a curve on a surface).
    fn host_normal(&self, at: &[f64]) -> Option<Vec3> {
        (self.order == 0).then(|| {
            let (_, ss, sw) = self.frame(at[0], at.get(1).copied().unwrap_or(0.0));
            ss.cross(sw)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The fast paths equal the jets (to round-off: different evaluation orders).
    #[test]
    fn fast_paths_match_the_jets() {
        let f = crate::data::ExprField::parse(
            ["cos(w)*(1 + s*s)", "sin(w)*exp(s)", "s*w + 0.3*w*w"],
            &["s", "w", "t"],
            &|_| None,
        )
        .unwrap();
        let piece = |w0: f64| Piece {
            surface: std::sync::Arc::new(f.clone()),
            s0: 0.2,
            w0,
            lambda: 0.7,
            c: 1.3,
            start: (0.4, -0.2),
            end: (0.9, 0.35),
            start_n: 0.0,
            end_n: 0.0,
            start2: [0.3, -0.1, 0.2],
            end2: [-0.2, 0.4, 0.1],
        };
        // positions to three v-derivatives; the cross tangent's value alone and with one
        for (order, n) in [(0, 4), (1, 1), (1, 2)] {
            let d = LoopData { pieces: vec![piece(0.0), piece(1.0), piece(2.0)], order, blend: 0.3 };
            for v in [0.05, 0.4, 1.0, 2.2, 3.3, 6.1] {
                let mut fast = [Vec3::ZERO; 4];
                d.derivatives_in(&[v, 0.0], 0, &mut fast[..n]);
                let mut slow = [Vec3::ZERO; 4];
                crate::data::derivatives_by_jet(&d, &[v, 0.0], 0, &mut slow[..n]);
                for k in 0..n {
                    assert!(
                        (fast[k] - slow[k]).norm() < 1e-13 * (1.0 + slow[k].norm()),
                        "{order} {v} {k}: {:?} {:?}",
                        fast[k],
                        slow[k]
                    );
                }
                assert!((d.eval(&[v, 0.0]) - slow[0]).norm() < 1e-14 * (1.0 + slow[0].norm()));
            }
        }
    }

    /// The series are Taylor series: at `v + h` (same piece, same side of the bumps' ends)
    /// the truncated series from `v` predicts the value to `O(h⁷)`; and the order-2 value
    /// is `α² S_ss + 2αβ S_sw + β² S_ww + ω (γ S_s + δ S_w + η S_s × S_w)` written out.
    #[test]
    fn the_series_are_taylor_series_of_the_data() {
        let f = crate::data::ExprField::parse(
            ["cos(w)*(1 + s*s)", "sin(w)*exp(s)", "s*w + 0.3*w*w*s"],
            &["s", "w", "t"],
            &|_| None,
        )
        .unwrap();
        let piece = |w0: f64| Piece {
            surface: std::sync::Arc::new(f.clone()),
            s0: 0.2,
            w0,
            lambda: 0.7,
            c: 1.3,
            start: (0.4, -0.2),
            end: (0.9, 0.35),
            start_n: 0.15,
            end_n: -0.3,
            start2: [0.3, -0.1, 0.2],
            end2: [-0.2, 0.4, 0.1],
        };
        let span = TAU / 3.0;
        for order in [0, 1, 2] {
            let d = LoopData { pieces: vec![piece(0.0), piece(1.0), piece(2.0)], order, blend: 0.3 };
            // inside the start bump, between the bumps, inside the end bump
            for v in [0.1 * span, 0.5 * span, 0.9 * span, span + 0.12] {
                let s = d.series(v, 0.0, 6);
                let err = |h: f64, c: usize| {
                    let exact = d.series(v + h, 0.0, 0);
                    s[c].iter().rev().fold(0.0, |acc, x| acc * h + x) - exact[c][0]
                };
                for c in 0..3 {
                    // the remainder is O(h⁷): halving h divides it by ~128; a wrong k-th
                    // coefficient (k ≤ 6) would divide it by 2ᵏ ≤ 64 (1e-14: round-off)
                    let (e1, e2) = (err(0.01, c), err(0.005, c));
                    assert!(e1.abs() < 1e-10, "{order} {v} {c}: {e1}");
                    assert!(e2.abs() < e1.abs() / 90.0 + 1e-14, "{order} {v} {c}: {e1} {e2}");
                }
            }
        }
        // the order-2 value, written out (between the bumps: α = c, β = 0, no correction)
        let d = LoopData { pieces: vec![piece(0.0), piece(1.0), piece(2.0)], order: 2, blend: 0.3 };
        let v = 0.5 * span;
        let (s, w) = (0.2_f64, 0.7 * v);
        let sss = Vec3::new(2.0 * w.cos(), w.sin() * s.exp(), 0.0);
        let q = sss * (1.3 * 1.3);
        let got = d.series(v, 0.0, 0);
        for c in 0..3 {
            assert!((got[c][0] - [q.x, q.y, q.z][c]).abs() < 1e-14, "{c}: {} vs {:?}", got[c][0], q);
        }
        // at the start corner the bump is 1: α = a, β = b and the full correction
        let v = 0.0;
        let w = 0.0_f64;
        let ss = Vec3::new(w.cos() * 2.0 * s, w.sin() * s.exp(), w + 0.3 * w * w);
        let sw = Vec3::new(-w.sin() * (1.0 + s * s), w.cos() * s.exp(), s + 0.6 * w * s);
        let sss = Vec3::new(2.0 * w.cos(), w.sin() * s.exp(), 0.0);
        let ssw = Vec3::new(-w.sin() * 2.0 * s, w.cos() * s.exp(), 1.0 + 0.6 * w);
        let sww = Vec3::new(-w.cos() * (1.0 + s * s), -w.sin() * s.exp(), 0.6 * s);
        let (a, b) = (0.4, -0.2);
        let q = sss * (a * a) + ssw * (2.0 * a * b) + sww * (b * b) + ss * 0.3 + sw * -0.1 + ss.cross(sw) * 0.2;
        let got = d.series(v, 0.0, 0);
        for c in 0..3 {
            assert!((got[c][0] - [q.x, q.y, q.z][c]).abs() < 1e-14, "{c}: {} vs {:?}", got[c][0], q);
        }
    }

    #[test]
    fn the_bump_is_one_at_the_corner_zero_beyond_and_c3() {
        let b0 = bump(0.0, 1.0, 4);
        assert_eq!(b0, vec![1.0, 0.0, 0.0, 0.0, -35.0]);
        let b1 = bump(1.0 - 1e-12, 1.0, 3);
        assert!(b1.iter().all(|x| x.abs() < 1e-9), "{b1:?}");
        assert_eq!(bump(1.5, 1.0, 2), vec![0.0; 3]);
        // Taylor coefficients against the closed-form derivative at x = 0.3, slope 2:
        // p′(x) = −140x³ + 420x⁴ − 420x⁵ + 140x⁶
        let x: f64 = 0.3;
        let d1 = -140.0 * x.powi(3) + 420.0 * x.powi(4) - 420.0 * x.powi(5) + 140.0 * x.powi(6);
        let b = bump(x, 2.0, 1);
        assert!((b[1] - 2.0 * d1).abs() < 1e-14, "{} vs {}", b[1], 2.0 * d1);
    }
}
