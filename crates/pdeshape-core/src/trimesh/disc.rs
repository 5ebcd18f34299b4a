//! A mesh hole's fill as a disc fill ([`crate::fill::disc`]): `Δ³X = 0` (order 6) or
//! `Δ²X = 0` (order 4) in the unit disc, its circle mapped to the fill's boundary line on
//! the collar.
//!
//! **The map.** The boundary line `γ(w) = C(σ̄(w), w)` is projected onto the plane through
//! the loop normal to `d`, the mean of the collar's unit normals along it; a conic
//! `A x² + B xy + C y² + D x + E y = 1` is fitted to the projection by least squares, and
//! a point's angle `θ(w)` is the polar angle of its projection after the affine map that
//! takes the fitted ellipse to the unit circle (increasing with `w`). The disc's circle is
//! the line parametrised by `θ`. A loop whose projection is not an ellipse's, or whose
//! angle does not increase along it (not star-shaped about the ellipse's centre), is not
//! filled this way ([`DiscSurface::new`] returns `None`).
//!
//! **The data.** With `c` the ellipse's centre and `P` the projection onto the plane:
//! `X(1, θ) = γ`; `X_r = f G`, `G = P(γ − c) + t d` with `t` such that `G` lies in the
//! collar's tangent plane (so G1 holds); at order 6 `X_rr = f² Q + μ f G`,
//! `Q = II(G, G)/(n·d) · d`, `II` the collar's second fundamental form, so that
//! `X_rr·n = II(X_r, X_r)`: with G1 along the whole line, the fill's second fundamental form
//! then equals the collar's (its `(γ′, γ′)` and `(γ′, X_r)` entries follow from G1 along
//! the line, see [`crate::fill`]), which is G2. `f` and `μ` change neither. For a quadratic
//! height field over the plane and a loop over an ellipse these are its own radial
//! derivatives at `f = 1`, `μ = 0`, and the fill is the surface itself.
//!
//! **Which `(f, μ)`.** The fill is linear in its data, so `X = F₀ + f F₁ + f² F₂ + μ f F₃`
//! from four solves; the member of least Willmore energy `∫H² dA` of its modal part (the
//! remainder, which makes up for the data's modes above `N/2`, is left out of the
//! energy) is taken by the trimesh fills' coordinate search.

use super::collar::{Collar, DomainLine};
use crate::Vec3;
use crate::data::Field;
use crate::fill::EdgeContinuity;
use crate::fill::disc::{DiscFill, sample_angles};
use crate::jet::JetShape;
use crate::num::max_nan;
use std::f64::consts::TAU;

/// Samples of the data around the loop.
const SAMPLES: usize = 128;
/// Samples of the line for the conic fit and the monotonicity check.
const DENSE: usize = 1024;

/// The collar's geometry at the boundary line's point `w`.
struct LinePoint {
    p: Vec3,
    /// `γ′(w)`.
    dp: Vec3,
    cs: Vec3,
    cw: Vec3,
    css: Vec3,
    csw: Vec3,
    cww: Vec3,
}

impl LinePoint {
    /// `II(v, v)` of the collar against the unit normal `n`, the tangent vector `v`
    /// written as `α C_s + β C_w` by the normal equations of the tangent basis.
    fn second_form(&self, v: Vec3, n: Vec3) -> f64 {
        let (e, f, g) = (self.cs.dot(self.cs), self.cs.dot(self.cw), self.cw.dot(self.cw));
        let det = e * g - f * f;
        let (bs, bw) = (v.dot(self.cs), v.dot(self.cw));
        let (al, be) = ((g * bs - f * bw) / det, (e * bw - f * bs) / det);
        al * al * self.css.dot(n) + 2.0 * al * be * self.csw.dot(n) + be * be * self.cww.dot(n)
    }
}

/// The weights of the parts `F₀ … F₃` in the member `(f, μ)`.
fn weights(f: f64, mu: f64) -> [f64; 4] {
    [1.0, f, f * f, mu * f]
}

/// A mesh hole's disc fill: the solved fills, the map `w ↦ θ` and what the data need.
pub struct DiscSurface {
    collar: Collar,
    line: DomainLine,
    period: f64,
    w0: f64,
    /// The plane's normal, the ellipse's centre, and the plane's axes after the affine map
    /// (`z = (a₁·(x − c), a₂·(x − c))`).
    d: Vec3,
    c: Vec3,
    a: [Vec3; 2],
    theta0: f64,
    /// `+1` or `−1`: the direction that makes `θ` increase with `w`.
    turn: f64,
    /// `F₀ … F₃` (order 4: `F₀`, `F₁`).
    parts: Vec<DiscFill>,
    /// The chosen `(f, μ)` and the fill for it.
    chosen: (f64, f64),
    fill: DiscFill,
    /// The loop's mean radius about `c`.
    radius: f64,
}

impl DiscSurface {
    /// The disc fill of the line `(σ̄(w), w)`, `w ∈ [w₀, w₀ + L)`, on `collar`, or `None`
    /// when the loop is not star-shaped about a fitted ellipse (see the module).
    pub fn new(collar: &Collar, line: &DomainLine, period: f64, w0: f64, order: usize) -> Option<Self> {
        let at = |w: f64| line_point(collar, line, w, 2);
        // the dense pass needs points and tangent planes only
        let dense: Vec<LinePoint> =
            (0..DENSE).map(|i| line_point(collar, line, w0 + period * i as f64 / DENSE as f64, 1)).collect();
        let mut d = Vec3::ZERO;
        for q in &dense {
            d += q.cw.cross(q.cs).normalized()?;
        }
        let d = d.normalized()?;
        let e1 = (if d.x.abs() < 0.9 { Vec3::new(1.0, 0.0, 0.0) } else { Vec3::new(0.0, 1.0, 0.0) })
            .cross(d)
            .normalized()?;
        let e2 = d.cross(e1);
        let mean = dense.iter().fold(Vec3::ZERO, |a, q| a + q.p) / DENSE as f64;
        let xy: Vec<(f64, f64)> = dense.iter().map(|q| ((q.p - mean).dot(e1), (q.p - mean).dot(e2))).collect();
        let scale = xy.iter().map(|&(x, y)| x.hypot(y)).fold(0.0, max_nan);
        if scale.is_nan() || scale <= 0.0 {
            return None;
        }
        // the conic A x² + B xy + C y² + D x + E y = 1 in coordinates scaled by `scale`
        let mut g = faer::Mat::<f64>::zeros(5, 5);
        let mut rhs = faer::Mat::<f64>::zeros(5, 1);
        for &(x, y) in &xy {
            let (x, y) = (x / scale, y / scale);
            let row = [x * x, x * y, y * y, x, y];
            for i in 0..5 {
                rhs[(i, 0)] += row[i];
                for j in 0..5 {
                    g[(i, j)] += row[i] * row[j];
                }
            }
        }
        use faer::linalg::solvers::Solve;
        let sol = crate::lanes::after(g.full_piv_lu().solve(&rhs));
        let [ca, cb, cc, cd, ce] = std::array::from_fn(|i| sol[(i, 0)]);
        // centre: the gradient of the quadratic vanishes
        let det = 4.0 * ca * cc - cb * cb;
        if det.is_nan() || det <= 0.0 {
            return None;
        }
        let xc = (-2.0 * cc * cd + cb * ce) / det;
        let yc = (cb * cd - 2.0 * ca * ce) / det;
        let k = 1.0 + ca * xc * xc + cb * xc * yc + cc * yc * yc;
        let (m11, m12, m22) = (ca / k, cb / (2.0 * k), cc / k);
        let positive = k > 0.0 && m11 > 0.0 && m11 * m22 - m12 * m12 > 0.0;
        if !positive {
            return None;
        }
        // M^{1/2} of the 2 × 2 symmetric positive definite M: (M + √det I)/√(tr + 2√det)
        let sd = (m11 * m22 - m12 * m12).sqrt();
        let tn = (m11 + m22 + 2.0 * sd).sqrt();
        let (h11, h12, h22) = ((m11 + sd) / tn, m12 / tn, (m22 + sd) / tn);
        let c = mean + (e1 * xc + e2 * yc) * scale;
        let a = [(e1 * h11 + e2 * h12) / scale, (e1 * h12 + e2 * h22) / scale];
        let angle = |p: Vec3| {
            let q = p - c;
            q.dot(a[1]).atan2(q.dot(a[0]))
        };
        // θ along the line, unwrapped: it must turn once, monotonically
        let mut th: Vec<f64> = Vec::with_capacity(DENSE + 1);
        for q in dense.iter().chain(std::iter::once(&line_point(collar, line, w0 + period, 1))) {
            let t = angle(q.p);
            let t = match th.last() {
                Some(&prev) => prev + (t - prev + std::f64::consts::PI).rem_euclid(TAU) - std::f64::consts::PI,
                None => t,
            };
            th.push(t);
        }
        let total = th[DENSE] - th[0];
        let once = (total.abs() - TAU).abs() < 1e-6;
        if !once {
            return None;
        }
        let turn = total.signum();
        if !th.windows(2).all(|w| turn * (w[1] - w[0]) > 0.0) {
            return None;
        }
        let theta0 = th[0];
        let radius = dense.iter().map(|q| (q.p - c - d * (q.p - c).dot(d)).norm()).sum::<f64>() / DENSE as f64;
        let mut me = DiscSurface {
            collar: collar.clone(),
            line: line.clone(),
            period,
            w0,
            d,
            c,
            a,
            theta0,
            turn,
            parts: Vec::new(),
            chosen: (1.0, 0.0),
            fill: DiscFill::new(2, &[vec![Vec3::ZERO; 8]]).ok()?,
            radius,
        };
        // the samples' w: θ(w) = 2πm/N by safeguarded Newton within the dense table's bracket
        let unwrapped: Vec<f64> = th.iter().map(|t| turn * (t - theta0)).collect();
        let mut ws = Vec::with_capacity(SAMPLES);
        for &target in &sample_angles(SAMPLES) {
            let i = unwrapped.partition_point(|&t| t <= target).clamp(1, DENSE);
            let (mut lo, mut hi) = (period * (i - 1) as f64 / DENSE as f64, period * i as f64 / DENSE as f64);
            let mut x = 0.5 * (lo + hi);
            for _ in 0..60 {
                let q = line_point(collar, line, w0 + x, 1);
                let f = me.theta_of(q.p, target) - target;
                if f.abs() < 1e-15 {
                    break;
                }
                if f > 0.0 {
                    hi = x;
                } else {
                    lo = x;
                }
                let slope = me.theta_slope(q.p, q.dp);
                let nx = x - f / slope;
                x = if nx > lo && nx < hi && slope > 0.0 { nx } else { 0.5 * (lo + hi) };
                if hi - lo < 1e-16 * period {
                    break;
                }
            }
            ws.push(w0 + x);
        }
        let k = order / 2;
        let mut rows: Vec<[Vec<Vec3>; 4]> =
            (0..k).map(|_| std::array::from_fn(|_| vec![Vec3::ZERO; SAMPLES])).collect();
        for (m, &w) in ws.iter().enumerate() {
            let (x, g, q) = me.basis_data(&at(w))?;
            rows[0][0][m] = x;
            if k >= 2 {
                rows[1][1][m] = g;
            }
            if k >= 3 {
                rows[2][2][m] = q;
                rows[2][3][m] = g;
            }
        }
        // part p has data row i = rows[i][p]
        let parts = (0..if k >= 3 { 4 } else { k })
            .map(|p| {
                let data: Vec<Vec<Vec3>> = (0..k).map(|i| rows[i][p].clone()).collect();
                DiscFill::new(order, &data)
            })
            .collect::<Result<Vec<_>, _>>()
            .ok()?;
        me.parts = parts;
        me.fill = me.combined(1.0, 0.0);
        Some(me)
    }

    /// `θ` of the point `p`, unwrapped to within `π` of `near`.
    fn theta_of(&self, p: Vec3, near: f64) -> f64 {
        let q = p - self.c;
        let t = self.turn * (q.dot(self.a[1]).atan2(q.dot(self.a[0])) - self.theta0);
        near + (t - near + std::f64::consts::PI).rem_euclid(TAU) - std::f64::consts::PI
    }

    /// `dθ/dw` at the point `p` of derivative `dp`.
    fn theta_slope(&self, p: Vec3, dp: Vec3) -> f64 {
        let q = p - self.c;
        let (x, y) = (q.dot(self.a[0]), q.dot(self.a[1]));
        let (dx, dy) = (dp.dot(self.a[0]), dp.dot(self.a[1]));
        self.turn * (x * dy - y * dx) / (x * x + y * y)
    }

    /// `(γ, G, Q)` at a line point (see the module), or `None` where the collar is
    /// degenerate.
    fn basis_data(&self, q: &LinePoint) -> Option<(Vec3, Vec3, Vec3)> {
        let n = q.cw.cross(q.cs).normalized()?;
        let rel = q.p - self.c;
        let proj = rel - self.d * rel.dot(self.d);
        let nd = n.dot(self.d);
        let g = proj - self.d * (proj.dot(n) / nd);
        let ii = q.second_form(g, n);
        let out = (q.p, g, self.d * (ii / nd));
        (out.0.is_finite() && out.1.is_finite() && out.2.is_finite()).then_some(out)
    }

    /// The fill of data `(γ, f G, f² Q + μ f G)`.
    fn combined(&self, f: f64, mu: f64) -> DiscFill {
        let w = weights(f, mu);
        let parts: Vec<(f64, &DiscFill)> = self.parts.iter().enumerate().map(|(p, d)| (w[p], d)).collect();
        DiscFill::combine(&parts)
    }

    /// The modal derivatives `[X, X_r, X_θ, X_rr, X_rθ, X_θθ]` of each part on `rs × θs`.
    pub fn part_grids(&self, rs: &[f64], thetas: &[f64]) -> Vec<Vec<[Vec3; 6]>> {
        self.parts.iter().map(|p| p.modal_grid(rs, thetas)).collect()
    }

    /// The grid of the member `(f, μ)` from the parts' grids.
    pub fn member_grid(grids: &[Vec<[Vec3; 6]>], f: f64, mu: f64) -> Vec<[Vec3; 6]> {
        let w = weights(f, mu);
        (0..grids[0].len())
            .map(|i| {
                let mut o = [Vec3::ZERO; 6];
                for (p, g) in grids.iter().enumerate() {
                    for q in 0..6 {
                        o[q] += g[i][q] * w[p];
                    }
                }
                o
            })
            .collect()
    }

    /// Takes the member `(f, μ)`.
    pub fn choose(&mut self, f: f64, mu: f64) {
        self.chosen = (f, mu);
        self.fill = self.combined(f, mu);
    }

    /// The exact data `[X, X_r, X_rr]` of the chosen member at `w`, and `θ(w)`.
    fn data_at(&self, w: f64) -> ([Vec3; 3], f64) {
        let q = line_point(&self.collar, &self.line, w, 2);
        let (f, mu) = self.chosen;
        let (x, g, qq) = self.basis_data(&q).unwrap_or((q.p, Vec3::ZERO, Vec3::ZERO));
        let t = self.theta_of(q.p, std::f64::consts::PI);
        ([x, g * f, qq * (f * f) + g * (mu * f)], t)
    }

    /// The fill at the strip chart's `(u, v)`: `r = 1 − u`, `w = w₀ + L v/2π`, on the grid
    /// `us × vs` (point `(i, j)` at `i · vs.len() + j`), the remainder included.
    pub fn values(&self, us: &[f64], vs: &[f64]) -> Vec<Vec3> {
        // the data enter only through the remainder, on r > ½
        let (data, thetas): (Vec<[Vec3; 3]>, Vec<f64>) = if us.iter().any(|&u| 1.0 - u > 0.5) {
            vs.iter().map(|&v| self.data_at(self.w0 + self.period * v / TAU)).unzip()
        } else {
            vs.iter()
                .map(|&v| {
                    let q = line_point(&self.collar, &self.line, self.w0 + self.period * v / TAU, 0);
                    ([Vec3::ZERO; 3], self.theta_of(q.p, std::f64::consts::PI))
                })
                .unzip()
        };
        let rs: Vec<f64> = us.iter().map(|u| 1.0 - u).collect();
        self.fill.grid(&rs, &thetas, &data).into_iter().map(|p| p[0]).collect()
    }

    /// The centre, `u = 1`.
    pub fn pole(&self) -> Vec3 {
        self.fill.centre()
    }

    /// Grid points (`r ∈ [0.02, 1]`, `θ`) whose modal normal `X_r × X_θ` vanishes, is not
    /// finite, or turns against a neighbour's (cosine ≤ 0), as the strip fill's `folds`.
    pub fn folds(&self, nr: usize, nt: usize) -> usize {
        let rs: Vec<f64> = (0..nr).map(|i| 0.02 + 0.98 * i as f64 / (nr - 1) as f64).collect();
        let ts: Vec<f64> = (0..nt).map(|j| TAU * (j as f64 + 0.5) / nt as f64).collect();
        let g = self.fill.modal_grid(&rs, &ts);
        let normals: Vec<Vec3> = g.iter().map(|d| d[1].cross(d[2])).collect();
        crate::fill::count_turns(&normals, nr, nt, 0.0)
    }

    /// The fill against the collar along the boundary line at `n` points of `w`: the gap
    /// `|X(1, θ(w)) − γ(w)|`, the angle between the normals `γ′ × X_r` and the collar's, and
    /// the difference of the normal curvatures (small at order 6; at order 4, how far from
    /// G2 the fill is), `(X_rr·n − II(X_r, X_r))/(X_r·e)²`
    /// with `e` the unit tangent across `γ′` — the only entry of the two second fundamental
    /// forms that G1 along the line leaves free (see the module) — times the loop's mean
    /// radius. `X`, `X_r`, `X_rr` are the fill's own (modal part and remainder); along `r = 1`
    /// the fill is the line (the gap says how nearly), so its tangent there is `γ′`.
    pub fn continuity(&self, n: usize) -> EdgeContinuity {
        let (mut g1, mut gap, mut g2) = (0.0f64, 0.0f64, 0.0f64);
        let ws: Vec<f64> = (0..n).map(|i| self.w0 + self.period * (i as f64 + 0.5) / n as f64).collect();
        let (data, thetas): (Vec<[Vec3; 3]>, Vec<f64>) = ws.iter().map(|&w| self.data_at(w)).unzip();
        // the fill at r = 1 at every sample in one grid evaluation
        let fill = self.fill.grid(&[1.0], &thetas, &data);
        for (&w, x) in ws.iter().zip(&fill) {
            let q = line_point(&self.collar, &self.line, w, 2);
            gap = max_nan(gap, (x[0] - q.p).norm() / self.radius);
            let nc = q.cw.cross(q.cs);
            let nf = q.dp.cross(x[1]);
            // the fill's normal runs with the collar's or against it, whichever the
            // parametrisation gives; the angle between the normal lines
            let ang = nf.cross(nc).norm().atan2(nf.dot(nc).abs());
            g1 = max_nan(g1, ang);
            let nu = nc.normalized().unwrap_or(Vec3::new(f64::NAN, f64::NAN, f64::NAN));
            let ii = q.second_form(x[1], nu);
            let tu = q.dp.normalized().unwrap_or(Vec3::ZERO);
            let across = nu.cross(tu);
            let xe = x[1].dot(across);
            g2 = max_nan(g2, ((x[2].dot(nu) - ii) / (xe * xe)).abs() * self.radius);
        }
        EdgeContinuity { g1, gap, g2, samples: n }
    }
}

/// The collar's geometry at the line's point `w`, its derivatives up to order `nd` (1 or 2;
/// the second ones are zero for 1).
fn line_point(collar: &Collar, line: &DomainLine, w: f64, nd: usize) -> LinePoint {
    let (s, ds) = line.sigma_and_slope(w);
    let j = collar.jet(&[s, w], JetShape::new(&[nd, nd]));
    let dv = |i: usize, k: usize| if i.max(k) <= nd { j.derivative([i, k, 0]) } else { Vec3::ZERO };
    let (cs, cw) = (dv(1, 0), dv(0, 1));
    LinePoint { p: j.value(), dp: cs * ds + cw, cs, cw, css: dv(2, 0), csw: dv(1, 1), cww: dv(0, 2) }
}
