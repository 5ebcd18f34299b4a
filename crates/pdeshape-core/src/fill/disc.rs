//! A fill of the unit disc: `Δᵏ X = 0` (`k = 1, 2, 3`: orders 2, 4, 6) in the disc's own
//! Cartesian coordinates, with `X`, `X_r` (and `X_rr`) given on the unit circle.
//!
//! **Why a disc.** The strip fill ([`super::Fill`]) solves `(∂²_u + a²∂²_v)³ X = 0` on a
//! periodic strip closed in a pole; its modes are `e^{±nau}(1, u, u²)`, and no member is a
//! quadratic written in `r = 1 − u`. A smooth surface over a hole is, to second order, a
//! quadratic; `Δᵏ` annihilates every polynomial of degree below `2k` in `(x, y)`, so the
//! disc fill reproduces such a surface exactly when its data are the surface's, read over
//! the disc through an affine map (the trimesh fills parametrise a loop by the affine angle
//! of a fitted ellipse for that reason).
//!
//! **Modes.** In polar coordinates `Δ(rᵐ e^{inθ}) = (m² − n²) r^{m−2} e^{inθ}`, so with
//! `m = n + 2j`, `Δ` maps `r^{n+2j}` to `4j(n + j) r^{n+2(j−1)}` and `Δᵏ` annihilates
//! `r^{n+2j} e^{inθ}` for `j < k`: the solutions regular at the centre. They are written
//! as `rⁿ ρʲ`, `ρ = 1 − r²`, which vanish to order `j` at `r = 1`: the `i`-th radial
//! derivative of `rⁿ ρʲ` at `r = 1` is 0 for `i < j` and `j! (−2)ʲ` for `i = j`, so the
//! conditions `∂ⁱ_r X(1, θ) = Dᵢ(θ)`, `i < k`, are a lower-triangular system per mode,
//! solved by forward substitution with no pivot smaller than 2 in magnitude.
//!
//! **Data that are not a finite Fourier series.** The data's `N` equispaced samples give
//! the modes `n < N/2`; the rest (aliasing and truncation) is made up by the remainder
//! `R(r, θ) = Σᵢ φᵢ(r) (Dᵢ(θ) − ∂ⁱ_r F(1, θ))`, `F` the modal part, with
//! `φᵢ(r) = (−σ)ⁱ/i! · χ(σ)`, `σ = 1 − r`, `χ` a quintic step from 1 (with two vanishing
//! derivatives) at `σ = 0` to 0 at `σ = ½`: `∂ʲ_r φᵢ(1) = δᵢⱼ` for `j < 3`, so `X = F + R`
//! meets every condition at every `θ`, and `R` vanishes on `r ≤ ½`. A point's remainder
//! needs the data at its `θ`, which the caller gives ([`DiscFill::point`]).

use crate::Vec3;
use crate::data::fourier::FourierSeries;
use std::f64::consts::TAU;

/// A solved disc fill: per mode `n` and component, `X = Σ_j rⁿ ρʲ (a_{nj} cos nθ + b_{nj}
/// sin nθ)`, `j < k`.
#[derive(Clone, Debug)]
pub struct DiscFill {
    k: usize,
    /// Per mode: `[a_0, a_1, a_2, b_0, b_1, b_2]` (unused `j ≥ k` zero).
    modes: Vec<[Vec3; 6]>,
}

/// Why a disc fill cannot be solved.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum DiscFillError {
    /// Order not 2, 4 or 6, or the data's count does not match.
    #[error("a disc fill of order {order} needs {need} data rows, got {got}")]
    Order {
        /// The order asked for.
        order: usize,
        /// Rows needed (`order / 2`).
        need: usize,
        /// Rows given.
        got: usize,
    },
    /// Too few samples, or rows of different lengths.
    #[error("a disc fill needs an even number of at least 8 samples in every row, got {0}")]
    Samples(usize),
    /// A sample is not finite.
    #[error("datum {row} at sample {index} is not finite")]
    NotFinite {
        /// The row (radial derivative order).
        row: usize,
        /// The sample.
        index: usize,
    },
}

/// `∂ⁱ_r (rⁿ ρʲ)` at `r = 1` (`ρ = 1 − r²`): `Σ_l C(j, l) (−1)ˡ (n + 2l)ᵢ` with the falling
/// factorial `(m)ᵢ = m (m − 1) … (m − i + 1)`; integers of at most ~10⁷ here, exact in
/// `f64`.
fn radial_at_one(n: usize, j: usize, i: usize) -> f64 {
    let binom = [[1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [1.0, 2.0, 1.0]];
    (0..=j)
        .map(|l| {
            let m = (n + 2 * l) as f64;
            let falling: f64 = (0..i).map(|q| m - q as f64).product();
            binom[j][l] * if l % 2 == 0 { 1.0 } else { -1.0 } * falling
        })
        .sum()
}

/// `(q, q′, q″)` of `q(r) = rⁿ Σ_j c_j ρʲ` in `r` (`ρ = 1 − r²`), `c` of length ≤ 3. Terms
/// whose power of `r` would be negative carry a zero factor and are left out (no `0 · ∞`
/// at the centre).
fn radial(n: usize, c: &[f64; 3], r: f64) -> [f64; 3] {
    let rho = 1.0 - r * r;
    let p = c[0] + rho * (c[1] + rho * c[2]);
    let dp = c[1] + 2.0 * rho * c[2]; // dp/dρ
    let ddp = 2.0 * c[2];
    let (p1, p2) = (-2.0 * r * dp, 4.0 * r * r * ddp - 2.0 * dp); // d/dr, d²/dr²
    let nf = n as f64;
    let rn = r.powi(n as i32);
    let rn1 = if n >= 1 { r.powi(n as i32 - 1) } else { 0.0 };
    let rn2 = if n >= 2 { r.powi(n as i32 - 2) } else { 0.0 };
    [rn * p, nf * rn1 * p + rn * p1, nf * (nf - 1.0) * rn2 * p + 2.0 * nf * rn1 * p1 + rn * p2]
}

/// [`radial`] for each component of vector coefficients: `[X, X_r, X_rr]`.
fn radial_vec(n: usize, c: [Vec3; 3], r: f64) -> [Vec3; 3] {
    let [x, y, z] = [c.map(|v| v.x), c.map(|v| v.y), c.map(|v| v.z)].map(|cq| radial(n, &cq, r));
    std::array::from_fn(|d| Vec3::new(x[d], y[d], z[d]))
}

/// The remainder's profiles: `[φᵢ, φᵢ′, φᵢ″]` in `r` for `i = 0, 1, 2` (see the module).
fn profiles(r: f64) -> [[f64; 3]; 3] {
    let sig = 1.0 - r;
    const S1: f64 = 0.5;
    let t = sig / S1;
    // χ(σ) = 1 − (10t³ − 15t⁴ + 6t⁵) on [0, S1], 0 beyond; its σ-derivatives
    let (chi, dchi, ddchi) = if t >= 1.0 {
        (0.0, 0.0, 0.0)
    } else {
        let t2 = t * t;
        (
            1.0 - t2 * t * (10.0 - 15.0 * t + 6.0 * t2),
            -30.0 * t2 * (1.0 - t) * (1.0 - t) / S1,
            -60.0 * t * (1.0 - t) * (1.0 - 2.0 * t) / (S1 * S1),
        )
    };
    // g_i(σ) = (−σ)^i / i! and its σ-derivatives
    let g = [[1.0, 0.0, 0.0], [-sig, -1.0, 0.0], [0.5 * sig * sig, sig, 1.0]];
    // φ = g χ; d/dr = −d/dσ, d²/dr² = d²/dσ²
    g.map(|[g0, g1, g2]| [g0 * chi, -(g1 * chi + g0 * dchi), g2 * chi + 2.0 * g1 * dchi + g0 * ddchi])
}

impl DiscFill {
    /// Solves the fill of order `order` (2, 4, 6) from `data[i]`, `i < order/2`: the `i`-th
    /// radial derivative `∂ⁱ_r X(1, θ_m)` at `θ_m = 2πm/N`, `N` the rows' common (even)
    /// length. Modes `n < N/2` are kept.
    pub fn new(order: usize, data: &[Vec<Vec3>]) -> Result<Self, DiscFillError> {
        let k = order / 2;
        if !matches!(order, 2 | 4 | 6) || data.len() != k {
            return Err(DiscFillError::Order { order, need: k.clamp(1, 3), got: data.len() });
        }
        let ns = data[0].len();
        if ns < 8 || ns % 2 == 1 || data.iter().any(|d| d.len() != ns) {
            return Err(DiscFillError::Samples(ns));
        }
        for (row, d) in data.iter().enumerate() {
            if let Some(index) = d.iter().position(|p| !p.is_finite()) {
                return Err(DiscFillError::NotFinite { row, index });
            }
        }
        let nm = ns / 2 - 1;
        let series: Vec<FourierSeries> = data.iter().map(|d| FourierSeries::from_samples(d, nm)).collect();
        let modes = (0..=nm)
            .map(|n| {
                let mut m = [Vec3::ZERO; 6];
                for (off, sine) in [(0, false), (3, true)] {
                    // forward substitution: Σ_{j ≤ i} M[i][j] c_j = D_i
                    for i in 0..k {
                        let mut rhs = if sine { series[i].b[n] } else { series[i].a[n] };
                        for j in 0..i {
                            rhs -= m[off + j] * radial_at_one(n, j, i);
                        }
                        m[off + i] = rhs / radial_at_one(n, i, i);
                    }
                }
                m
            })
            .collect();
        Ok(DiscFill { k, modes })
    }

    /// The order of the PDE (2, 4 or 6).
    pub fn order(&self) -> usize {
        2 * self.k
    }

    /// The largest mode kept.
    pub fn modes(&self) -> usize {
        self.modes.len() - 1
    }

    /// The modal part `F` and its derivatives at `(r, θ)`: `[F, F_r, F_θ, F_rr, F_rθ,
    /// F_θθ]`, exactly (no remainder).
    pub fn modal(&self, r: f64, theta: f64) -> [Vec3; 6] {
        self.modal_grid(&[r], &[theta])[0]
    }

    /// The modal part and its derivatives on the grid `rs × thetas` (point `(i, j)` at
    /// `i · thetas.len() + j`), as [`modal`](Self::modal) at each point: the radial factors
    /// once a radius and `cos nθ`, `sin nθ` once an angle.
    pub fn modal_grid(&self, rs: &[f64], thetas: &[f64]) -> Vec<[Vec3; 6]> {
        let nm = self.modes.len();
        // cos nθ, sin nθ for every angle, by the angle-addition recurrence
        let mut trig = vec![(0.0, 0.0); nm * thetas.len()];
        for (j, &t) in thetas.iter().enumerate() {
            let (s1, c1) = t.sin_cos();
            let (mut s, mut c) = (0.0, 1.0);
            for n in 0..nm {
                trig[j * nm + n] = (c, s);
                (s, c) = (s * c1 + c * s1, c * c1 - s * s1);
            }
        }
        let mut out = Vec::with_capacity(rs.len() * thetas.len());
        let mut table = vec![([Vec3::ZERO; 3], [Vec3::ZERO; 3]); nm];
        for &r in rs {
            for (n, (m, row)) in self.modes.iter().zip(table.iter_mut()).enumerate() {
                *row = (radial_vec(n, [m[0], m[1], m[2]], r), radial_vec(n, [m[3], m[4], m[5]], r));
            }
            for j in 0..thetas.len() {
                let mut o = [Vec3::ZERO; 6];
                for (n, (rc, rs)) in table.iter().enumerate() {
                    let (c, s) = trig[j * nm + n];
                    let nf = n as f64;
                    let x = rc[0] * c + rs[0] * s;
                    o[0] += x;
                    o[1] += rc[1] * c + rs[1] * s;
                    o[2] += (rs[0] * c - rc[0] * s) * nf;
                    o[3] += rc[2] * c + rs[2] * s;
                    o[4] += (rs[1] * c - rc[1] * s) * nf;
                    o[5] += x * (-nf * nf);
                }
                out.push(o);
            }
        }
        out
    }

    /// [`point`](Self::point) on the grid `rs × thetas`: `data[j]` holds the exact
    /// `∂ⁱ_r X(1, θ_j)` (`order/2` of them).
    pub fn grid(&self, rs: &[f64], thetas: &[f64], data: &[[Vec3; 3]]) -> Vec<[Vec3; 3]> {
        let at_one = self.modal_grid(&[1.0], thetas);
        // the circle alone (the continuity check): its modal part is `at_one`
        let g = if rs == [1.0] { at_one.clone() } else { self.modal_grid(rs, thetas) };
        let nt = thetas.len();
        g.iter()
            .enumerate()
            .map(|(p, f)| {
                let (r, j) = (rs[p / nt], p % nt);
                let mut out = [f[0], f[1], f[3]];
                if r > 0.5 {
                    self.add_remainder(&mut out, r, &at_one[j], &data[j]);
                }
                out
            })
            .collect()
    }

    /// The fill at `(r, θ)` with its first two radial derivatives, `[X, X_r, X_rr]`:
    /// the modal part plus the remainder made from `data`, the exact `∂ⁱ_r X(1, θ)` at this
    /// `θ` (`order/2` of them; ignored, and may be empty, for `r ≤ ½`, outside the
    /// remainder's support).
    pub fn point(&self, r: f64, theta: f64, data: &[Vec3]) -> [Vec3; 3] {
        let f = self.modal(r, theta);
        let mut out = [f[0], f[1], f[3]];
        if r > 0.5 {
            self.add_remainder(&mut out, r, &self.modal(1.0, theta), data);
        }
        out
    }

    /// Adds the remainder at radius `r` to `out` (`[X, X_r, X_rr]`): `at_one` the modal part
    /// at `r = 1` and the same `θ`, `data` the exact `∂ⁱ_r X(1, θ)`.
    fn add_remainder(&self, out: &mut [Vec3; 3], r: f64, at_one: &[Vec3; 6], data: &[Vec3]) {
        let modal_data = [at_one[0], at_one[1], at_one[3]];
        let phi = profiles(r);
        for i in 0..self.k {
            let e = data[i] - modal_data[i];
            for (d, o) in out.iter_mut().enumerate() {
                *o += e * phi[i][d];
            }
        }
    }

    /// The centre `X(0, ·)`.
    pub fn centre(&self) -> Vec3 {
        self.modes[0][0] + self.modes[0][1] + self.modes[0][2]
    }

    /// The fill whose data are `Σ wᵢ · (fill i's data)`: the solve is linear in the data.
    /// All fills must have the same order and mode count.
    pub fn combine(parts: &[(f64, &DiscFill)]) -> DiscFill {
        let first = parts[0].1;
        let mut modes = vec![[Vec3::ZERO; 6]; first.modes.len()];
        for &(w, f) in parts {
            for (m, fm) in modes.iter_mut().zip(&f.modes) {
                for q in 0..6 {
                    m[q] += fm[q] * w;
                }
            }
        }
        DiscFill { k: first.k, modes }
    }
}

/// The angles `2πm/N`, `m < N`.
pub fn sample_angles(n: usize) -> Vec<f64> {
    (0..n).map(|m| TAU * m as f64 / n as f64).collect()
}

#[cfg(test)]
#[allow(clippy::needless_range_loop)] // closed forms indexed by derivative order
mod tests {
    use super::*;

    /// A polynomial `p(x, y)` of degree ≤ 5 (vector valued) and its radial derivatives on
    /// the unit circle, `x = r cos θ`, `y = r sin θ`.
    fn quintic(r: f64, t: f64) -> [Vec3; 3] {
        // p = (x²y − 0.3 y⁵ + x, 1 + x y³ − 2 x⁴ y, x² − y² + 0.5 x y + 0.2 x³ y²): each
        // monomial xᵃyᵇ = r^{a+b} cosᵃ sinᵇ, so ∂ⁱ_r of it is (a+b)_i r^{a+b−i} cosᵃ sinᵇ
        let (s, c) = t.sin_cos();
        let terms: [(f64, usize, usize, usize); 9] = [
            (1.0, 2, 1, 0),
            (-0.3, 0, 5, 0),
            (1.0, 1, 0, 0),
            (1.0, 0, 0, 1),
            (1.0, 1, 3, 1),
            (-2.0, 4, 1, 1),
            (1.0, 2, 0, 2),
            (-1.0, 0, 2, 2),
            (0.5, 1, 1, 2),
        ];
        let mut out = [Vec3::ZERO; 3];
        let mut add = |coef: f64, a: usize, b: usize, comp: usize| {
            let d = (a + b) as f64;
            let ang = c.powi(a as i32) * s.powi(b as i32);
            for i in 0..3 {
                let falling: f64 = (0..i).map(|q| d - q as f64).product();
                let pw = if (a + b) >= i { r.powi((a + b - i) as i32) } else { 0.0 };
                out[i][comp] += coef * falling * pw * ang;
            }
        };
        for (coef, a, b, comp) in terms {
            add(coef, a, b, comp);
        }
        add(0.2, 3, 2, 2);
        out
    }

    /// Order 6 reproduces every polynomial of degree ≤ 5 in the disc's coordinates (`Δ³`
    /// annihilates them; the regular solution is unique), from 64 samples, at scattered
    /// points inside, the radial derivatives included: an independent closed form.
    #[test]
    fn order_six_reproduces_quintics() {
        let th = sample_angles(64);
        let data: Vec<Vec<Vec3>> = (0..3).map(|i| th.iter().map(|&t| quintic(1.0, t)[i]).collect()).collect();
        let fill = DiscFill::new(6, &data).unwrap();
        let mut worst = 0.0f64;
        for q in 0..200 {
            let r = ((q * 37 % 200) as f64 + 0.5) / 200.0;
            let t = 0.7 + q as f64 * 0.113;
            let want = quintic(r, t);
            let got = fill.point(r, t, &quintic(1.0, t));
            for i in 0..3 {
                worst = crate::num::max_nan(worst, (got[i] - want[i]).norm());
            }
        }
        // coefficients of size ~1–40 (the second derivative of x⁴y), 64-point FFTs: round-off
        // ~1e-14 seen 2.8e-14
        assert!(worst < 2e-13, "{worst:e}");
        // the centre is p(0, 0) = (0, 1, 0)
        assert!((fill.centre() - Vec3::new(0.0, 1.0, 0.0)).norm() < 1e-14, "{:?}", fill.centre());
    }

    /// A quintic is not reproduced at order 4 (`Δ²x²y³ ≠ 0`), a cubic is.
    #[test]
    fn order_four_reproduces_cubics_only() {
        let cubic = |r: f64, t: f64| {
            let (s, c) = t.sin_cos();
            // (x³ − 3xy², x²y + y, 2 x y): ∂_r of a degree-d form is d r^{d−1} × its angle part
            let cub = Vec3::new(c.powi(3) - 3.0 * c * s * s, c * c * s, 0.0);
            let quad = Vec3::new(0.0, 0.0, 2.0 * c * s);
            let lin = Vec3::new(0.0, s, 0.0);
            [
                cub * r.powi(3) + quad * r * r + lin * r,
                cub * 3.0 * r * r + quad * 2.0 * r + lin,
                cub * 6.0 * r + quad * 2.0,
            ]
        };
        let th = sample_angles(32);
        let data: Vec<Vec<Vec3>> = (0..2).map(|i| th.iter().map(|&t| cubic(1.0, t)[i]).collect()).collect();
        let fill = DiscFill::new(4, &data).unwrap();
        let err = (0..50)
            .map(|q| {
                let (r, t) = (q as f64 / 50.0, q as f64 * 0.41);
                (fill.point(r, t, &cubic(1.0, t)[..2])[0] - cubic(r, t)[0]).norm()
            })
            .fold(0.0, crate::num::max_nan);
        assert!(err < 1e-14, "{err:e}");
        let th = sample_angles(64);
        let data: Vec<Vec<Vec3>> = (0..2).map(|i| th.iter().map(|&t| quintic(1.0, t)[i]).collect()).collect();
        let fill = DiscFill::new(4, &data).unwrap();
        let off = (fill.point(0.5, 0.3, &[])[0] - quintic(0.5, 0.3)[0]).norm();
        assert!(off > 1e-3, "{off:e}");
    }

    /// Data that are no finite Fourier series (`1/(2 − cos θ)` and friends): the fill meets
    /// `X`, `X_r`, `X_rr` at the circle to round-off at scattered `θ` through the remainder,
    /// which the modal part alone misses by the truncation (> 1e-6 with 16 samples).
    #[test]
    fn remainder_meets_the_data_between_samples() {
        let d = |t: f64| {
            let e = 1.0 / (2.0 - t.cos());
            [
                Vec3::new(e, t.sin() * e, 0.1 * t.cos()),
                Vec3::new(t.cos() * e * e, -0.3, e.sqrt()),
                Vec3::new(0.2, e * t.sin(), -e),
            ]
        };
        let th = sample_angles(16);
        let data: Vec<Vec<Vec3>> = (0..3).map(|i| th.iter().map(|&t| d(t)[i]).collect()).collect();
        let fill = DiscFill::new(6, &data).unwrap();
        let (mut exact, mut modal) = (0.0f64, 0.0f64);
        for q in 0..100 {
            let t = 0.05 + q as f64 * 0.0617;
            let want = d(t);
            let got = fill.point(1.0, t, &want);
            let m = fill.modal(1.0, t);
            for (i, mi) in [0, 1, 3].into_iter().enumerate() {
                exact = crate::num::max_nan(exact, (got[i] - want[i]).norm());
                modal = crate::num::max_nan(modal, (m[mi] - want[i]).norm());
            }
        }
        // data of size ~1, a modal part of 7 modes: round-off ~1e-15 (seen 4.4e-16)
        assert!(exact < 1e-14, "{exact:e}");
        assert!(modal > 1e-6, "{modal:e}");
        // and the remainder is gone at r ≤ ½
        let inner = fill.point(0.5, 1.0, &d(1.0))[0] - fill.modal(0.5, 1.0)[0];
        assert_eq!(inner, Vec3::ZERO);
    }

    /// The profiles' derivatives at `r = 1` are the identity, and their values and
    /// derivatives vanish at `r = ½` from inside (C2 with zero).
    #[test]
    fn profiles_are_cardinal_at_the_circle() {
        let p = profiles(1.0);
        for i in 0..3 {
            for j in 0..3 {
                assert_eq!(p[i][j], if i == j { 1.0 } else { 0.0 }, "φ_{i}^({j})");
            }
        }
        let q = profiles(0.5 + 1e-12);
        assert!(q.iter().flatten().all(|v| v.abs() < 1e-9), "{q:?}");
    }

    /// The grid paths give [`DiscFill::modal`]'s and [`DiscFill::point`]'s numbers (sums
    /// in the same order: bit for bit).
    #[test]
    fn grids_agree_with_points() {
        let th = sample_angles(32);
        let d = |t: f64| {
            [
                Vec3::new(t.cos(), (2.0 * t).sin(), 1.0 / (3.0 + t.sin())),
                Vec3::new(0.1, t.cos(), 0.0),
                Vec3::new(0.0, 0.0, t.sin()),
            ]
        };
        let data: Vec<Vec<Vec3>> = (0..3).map(|i| th.iter().map(|&t| d(t)[i]).collect()).collect();
        let fill = DiscFill::new(6, &data).unwrap();
        let (rs, ts) = ([0.0, 0.3, 0.7, 1.0], [0.1, 2.0, 4.5]);
        let dat: Vec<[Vec3; 3]> = ts.iter().map(|&t| d(t)).collect();
        let (m, g) = (fill.modal_grid(&rs, &ts), fill.grid(&rs, &ts, &dat));
        for (i, &r) in rs.iter().enumerate() {
            for (j, &t) in ts.iter().enumerate() {
                assert_eq!(m[i * 3 + j], fill.modal(r, t));
                assert_eq!(g[i * 3 + j], fill.point(r, t, &d(t)));
            }
        }
    }

    /// `∂ⁱ_r(rⁿρʲ)` at 1 against the closed forms: `(n, n, n(n−1))` for `j = 0`, `(0, −2,
    /// −4n − 2)` for `j = 1`, `(0, 0, 8)` for `j = 2`.
    #[test]
    fn triangular_matrix() {
        for n in [0usize, 1, 5, 200] {
            let nf = n as f64;
            assert_eq!([0, 1, 2].map(|i| radial_at_one(n, 0, i)), [1.0, nf, nf * (nf - 1.0)]);
            assert_eq!([0, 1, 2].map(|i| radial_at_one(n, 1, i)), [0.0, -2.0, -4.0 * nf - 2.0]);
            assert_eq!([0, 1, 2].map(|i| radial_at_one(n, 2, i)), [0.0, 0.0, 8.0]);
        }
    }
}
