//! The surface around a mesh's hole, estimated from the vertices near its loop, and the
//! loop as a curve on it.
//!
//! A hole's loop in a mesh zigzags along the triangles' edges, so the loop itself is no
//! good as a parametrisation: the feet of nearby vertices on a zigzag jump. The collar is
//! built around a smooth curve instead and the loop is then a curve on the collar.
//!
//! 1. **Spine.** `P(w)`: a periodic cubic spline on uniform breakpoints (a quarter as many
//!    as the loop's vertices, 4 … 128) fitted by least squares to the loop's vertices at
//!    their chord-length parameters; `L` its period.
//! 2. **Parameters.** Every loop vertex and every vertex within `rings` rings of the loop
//!    gets `w` = its foot on `P` (Newton on `(P(w) − x)·P′(w) = 0`, started from the best of
//!    samples near the loop vertex it was reached from) and `s = (x − P(w))·B(w)`, its
//!    offset across the spine within the surface: `B = N × P′ / |N × P′|`, `N(w)` the
//!    least-squares spline (on the spine's breakpoints) through the unit normals of the
//!    triangles on the loop, so `s` is positive on the mesh's side. Not `±|x − P(w)|`:
//!    the spine, a smoothed loop, lies off the surface, and that distance never comes
//!    below the offset, so it folds the vertices near the spine onto each other (on the
//!    tests' torus the fit's residual at the loop was 5–23 times larger, and which loop
//!    vertex came first decided whether the collar folded).
//! 3. **Surface.** `C(s, w) = P(w) + s B(w) + Σ_{k=0}^{4} s^k D_k(w)`, `B = N × P′ /
//!    |N × P′|` the unit vector across the spine by which `s` was measured (its jet from
//!    those of `P` and `N`), `D_k` periodic cubic splines on seven times the spine's
//!    breakpoints (fewer where vertices are few), fitted by penalised least squares to
//!    what `P + s B` leaves of those vertices. `s B` a term of its own fits a plane to
//!    round-off (`D₁` had to follow `B`, which is no spline: 1.4e-4 on the tests' plane).
//!    A quartic in `s` needs five levels of vertices across the loop, the loop's and four
//!    rings (the fill's default). Against a cubic on three rings whose `D₁` followed `B`,
//!    the fills' distances to the bench's true surfaces fell from 4.8e-4 to 1.5e-4
//!    (sphere), 2.4e-3 to 1.1e-3 (torus) and 8.7e-5 to 5.2e-5 (height field); a cubic on
//!    four rings was worse than on three, and a quintic on four to six rings folded on
//!    the torus.
//!
//!    **Smoothing.** The `D_k` have about as many unknowns as there are vertices, so
//!    unpenalised they follow every vertex, and on a scan the noise: vertices moved by
//!    3e-4 (a hundredth of an edge) moved the fills by 1e-2 … 6e-2. The penalty is the
//!    third-order thin-plate energy of `Σ s^k D_k`, its weight chosen by generalised
//!    cross-validation ([`smoothing`](super::smoothing)), with a second-difference
//!    penalty of 10⁻⁶ of the mean diagonal that keeps the system determined where
//!    vertices are few. On the bench's noisy meshes the fills now lie 1.8e-3 / 7.8e-3 /
//!    2.2e-3 off (sphere, torus, height field) instead of 5.9e-2 / 4.3e-2 / 1.8e-2, with
//!    weights of 0.4 … 160. The price on clean meshes, where cross-validation still
//!    chooses weights of 5e-3 … 2e-2 on the sphere's and the height field's holes (1e-12 on
//!    the torus's): 2.4e-4 / 1.1e-3 / 1.35e-4 instead of 1.5e-4 / 1.1e-3 / 5.2e-5
//!    (BENCHMARKS.md). The residual is reported with the weight and the effective number
//!    of unknowns.
//! 4. **The loop on it.** The loop's vertices at `(s_i, w_i)`, their `w_i` increasing
//!    along the loop: where a staircase's notch steps back along the spine, its feet are
//!    moved forward by the least squares that leaves every step a fifth of its edge
//!    (`loop_parameters`), and the fit is refused if that moves one by more than three
//!    quarters of its edge. The band and the fill's boundary are laid out in these
//!    parameters; the mesh keeps the loop's own vertices.
//!
//! **Orientation.** The loop runs with the mesh on its left, so the mesh's normal is
//! `N ∝ C_w × C_s` near it; a collar whose `C_w × C_s` turns against the normals of the
//! triangles on the loop folds, and is refused.
//!
//! Derivatives are exact: `∂ᵢ_s ∂ʲ_w C` from the splines' jets and the polynomial in `s`.

use super::smoothing::{Smoothed, add_thin_plate, gcv_solve};
use super::{MeshLoop, PeriodicSpline, TriMesh};
use crate::Vec3;
use crate::data::{Field, NurbsCurve, VecJet};
use crate::jet::{Jet, JetShape};
use crate::linalg::{Envelope, LinalgError, ProfileCholesky};
use crate::num::max_nan;
use faer::Mat;
use std::cmp::Ordering;

/// `C(k, i)`.
fn binomial(k: usize, i: usize) -> f64 {
    (1..=i).map(|r| (k + 1 - r) as f64 / r as f64).product()
}

/// The `D_k` of the collar, `k < BLOCKS`: a quartic in `s` (see the module).
const BLOCKS: usize = 5;

/// `C(s, w) = P(w) + s B(w) + Σ_{k=0}^{4} s^k D_k(w)`, `L`-periodic in `w` (slots `s, w`;
/// constant in time).
#[derive(Clone, Debug)]
pub struct Collar {
    /// The spine `P`: its basis and control points.
    spine: (PeriodicSpline, Vec<Vec3>),
    /// `N`, the spline through the loop's triangles' normals, on the spine's basis: with
    /// `P′` it gives the unit vector across the spine `B = N × P′ / |N × P′|`.
    normal: Vec<Vec3>,
    /// The `D_k`: their common basis and each one's control points.
    d: (PeriodicSpline, [Vec<Vec3>; BLOCKS]),
    period: f64,
}

/// The Taylor coefficients `(dʲ/dwʲ) / j!`, `j = 0 ..= nd`, of the splines with control
/// points `ctrl` on `basis` at `w` (as a jet holds them), the basis evaluated once for all
/// of them (zero above the third derivative).
fn spline_derivatives<const K: usize>(basis: &PeriodicSpline, ctrl: [&[Vec3]; K], w: f64, nd: usize) -> [Vec<Vec3>; K] {
    let (j0, b) = basis.basis(w, nd);
    let len = basis.len();
    let factorial = [1.0, 1.0, 2.0, 6.0];
    ctrl.map(|c| {
        (0..=nd)
            .map(|j| {
                b.get(j).map_or(Vec3::ZERO, |row| {
                    (0..4).fold(Vec3::ZERO, |a, r| a + c[(j0 + r) % len] * row[r]) * (1.0 / factorial[j])
                })
            })
            .collect()
    })
}

/// The Taylor coefficients in `w`, orders `0 ..= nd`, of `B = N × P′ / |N × P′|` from
/// those of `P` and `N` (orders `0 ..= nd + 1`): `c = N × P′` and `g = c·c` by Cauchy
/// products, `h = g^(−1/2)` by the power series recurrence
/// `h₀ = g₀^(−1/2)`, `hₙ = (1 / (n g₀)) Σ_{k=1}^{n} ((α + 1) k − n) g_k h_{n−k}` with
/// `α = −½`, and `B = c h`.
fn across_taylor(p: &[Vec3], n: &[Vec3], nd: usize) -> Vec<Vec3> {
    let dp: Vec<Vec3> = (0..=nd).map(|j| p[j + 1] * (j + 1) as f64).collect();
    let c: Vec<Vec3> = (0..=nd).map(|t| (0..=t).fold(Vec3::ZERO, |a, k| a + n[k].cross(dp[t - k]))).collect();
    let g: Vec<f64> = (0..=nd).map(|t| (0..=t).map(|k| c[k].dot(c[t - k])).sum()).collect();
    let mut h = vec![0.0; nd + 1];
    h[0] = 1.0 / g[0].sqrt();
    for m in 1..=nd {
        let sum: f64 = (1..=m).map(|k| (0.5 * k as f64 - m as f64) * g[k] * h[m - k]).sum();
        h[m] = sum / (m as f64 * g[0]);
    }
    (0..=nd).map(|t| (0..=t).fold(Vec3::ZERO, |a, k| a + c[k] * h[t - k])).collect()
}

impl Field for Collar {
    fn arity(&self) -> usize {
        2
    }

    fn jet(&self, at: &[f64], shape: JetShape) -> VecJet {
        let [os, ow, _] = shape.orders();
        let (s, w) = (at[0], at.get(1).copied().unwrap_or(0.0).rem_euclid(self.period));
        let [p, nrm] = spline_derivatives(&self.spine.0, [&self.spine.1, &self.normal], w, ow + 1);
        let across = across_taylor(&p, &nrm, ow);
        let dk = spline_derivatives(&self.d.0, self.d.1.each_ref().map(|c| c.as_slice()), w, ow);
        // `∂ˢⁱ sᵏ = C(k, i) sᵏ⁻ⁱ`, once for the three components
        let f: [[f64; BLOCKS]; BLOCKS] = std::array::from_fn(|i| {
            std::array::from_fn(|k| if k >= i { binomial(k, i) * s.powi((k - i) as i32) } else { 0.0 })
        });
        VecJet(std::array::from_fn(|q| {
            let mut c = vec![0.0; shape.len()];
            for i in 0..=os.min(BLOCKS - 1) {
                for j in 0..=ow {
                    let mut v: f64 = (i..BLOCKS).map(|k| f[i][k] * dk[k][j][q]).sum();
                    if i == 0 {
                        v += p[j][q] + s * across[j][q];
                    } else if i == 1 {
                        v += across[j][q];
                    }
                    c[shape.index([i, j, 0])] = v;
                }
            }
            Jet::from_coeffs(shape, c)
        }))
    }

    fn is_constant_in(&self, slot: usize) -> bool {
        slot >= 2
    }
}

/// A curve `τ ↦ (σ(τ), τ)` in the collar's domain, `σ` an `L`-periodic spline (slot `τ`;
/// components 0 and 1 are the collar's `s` and `w`).
#[derive(Clone, Debug)]
pub struct DomainLine {
    sigma: NurbsCurve,
    period: f64,
    /// The spline's basis and control values, for [`DomainLine::sigma_and_slope`].
    basis: PeriodicSpline,
    ctrl: Vec<f64>,
}

impl DomainLine {
    /// The line `(σ(τ), τ)`, `σ` with control points `ctrl` on `basis` (period `L`).
    pub fn new(basis: &PeriodicSpline, ctrl: &[f64]) -> Self {
        let pts: Vec<Vec3> = ctrl.iter().map(|&c| Vec3::new(c, 0.0, 0.0)).collect();
        let (a, b) = basis.domain();
        DomainLine { sigma: basis.curve(&pts), period: b - a, basis: basis.clone(), ctrl: ctrl.to_vec() }
    }

    /// `(σ(τ), σ′(τ))` from the periodic basis at `τ` (the same spline as the field's jet,
    /// without its general NURBS path: the disc fills ask it at every point they evaluate).
    pub fn sigma_and_slope(&self, tau: f64) -> (f64, f64) {
        let (j0, b) = self.basis.basis(tau, 1);
        let n = self.ctrl.len();
        let sum = |row: &[f64]| (0..4).fold(0.0, |a, r| a + self.ctrl[(j0 + r) % n] * row[r]);
        (sum(&b[0]), sum(&b[1]))
    }

    /// `σ(τ)`.
    pub fn sigma(&self, tau: f64) -> f64 {
        self.sigma.eval(&[tau.rem_euclid(self.period)]).x
    }
}

impl Field for DomainLine {
    fn arity(&self) -> usize {
        1
    }

    fn jet(&self, at: &[f64], shape: JetShape) -> VecJet {
        let [o, _, _] = shape.orders();
        let tau = at[0];
        let sj = self.sigma.jet(&[tau.rem_euclid(self.period)], JetShape::new(&[o]));
        let mut c0 = vec![0.0; shape.len()];
        let mut c1 = vec![0.0; shape.len()];
        for j in 0..=o {
            c0[shape.index([j, 0, 0])] = sj.0[0].coeff([j, 0, 0]);
        }
        c1[0] = tau;
        if o >= 1 {
            c1[shape.index([1, 0, 0])] = 1.0;
        }
        VecJet([Jet::from_coeffs(shape, c0), Jet::from_coeffs(shape, c1), Jet::constant(shape, 0.0)])
    }

    fn is_constant_in(&self, slot: usize) -> bool {
        slot >= 1
    }
}

/// A fitted collar with what the fit found.
#[derive(Clone, Debug)]
pub struct CollarFit {
    /// The collar.
    pub collar: Collar,
    /// The loop vertices' `(s_i, w_i)`, `w_i` increasing from `w₀` within one period.
    pub params: Vec<(f64, f64)>,
    /// The period `L`.
    pub period: f64,
    /// Vertices fitted (the loop's and those within `rings` rings of it).
    pub points: usize,

    /// Control points of each `D_k`.
    pub controls: usize,
    /// The spine's basis (fewer control points, for smooth curves along the loop).
    pub spine_basis: PeriodicSpline,
    /// The largest `s` among them.
    pub width: f64,
    /// Root mean square distance of the fitted vertices from `C̄`.
    pub rms: f64,
    /// The largest.
    pub max_residual: f64,
    /// The largest `|C(s_i, w_i) − x_i|` at the loop's vertices' parameters (the fit's
    /// residual, and the shift of the feet that `loop_parameters` moved forward).
    pub loop_residual: f64,
    /// The least-squares normal matrix's 1-norm condition number, estimated
    /// ([`ProfileCholesky`]; the 2-norm one is at most this and at least this over its order).
    pub cond: f64,
    /// The thin-plate penalty's weight that cross-validation chose, relative to the data
    /// (`λ tr(Ω) / tr(AᵀA)`, [`smoothing`](super::smoothing)).
    pub smoothing: f64,
    /// The fit's effective number of unknowns, `tr H` (at most the vertices fitted; near
    /// it, the collar follows every vertex).
    pub dof: f64,
}

/// Why a collar is not fitted.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum CollarError {
    /// Too few vertices near the loop.
    #[error("only {points} vertices lie within {rings} rings of the loop (at least {needed} are needed)")]
    TooFewPoints {
        /// Found.
        points: usize,
        /// Rings searched.
        rings: usize,
        /// Needed.
        needed: usize,
    },
    /// Two consecutive loop vertices coincide.
    #[error("loop vertices {0} and {1} coincide")]
    Coincident(u32, u32),
    /// A spline through the loop failed.
    #[error("the spline through the loop's vertices is singular")]
    Interpolation,
    /// The loop's vertices do not follow each other along the spine.
    #[error("the loop turns back on itself near vertex {0} (its feet on the smoothed loop do not increase)")]
    NotMonotone(u32),
    /// The least-squares system.
    #[error("the collar's least squares: {0}")]
    Singular(#[from] LinalgError),
    /// The collar turns against the mesh.
    #[error(
        "the surface fitted around the loop folds near vertex {vertex} (its normal turns against the mesh's by {angle:.3} rad)"
    )]
    Folds {
        /// The loop vertex.
        vertex: u32,
        /// The angle between the collar's and the triangle's normal.
        angle: f64,
    },
}

/// The vertex neighbours of every vertex of `m`.
pub fn adjacency(m: &TriMesh) -> Vec<Vec<u32>> {
    let mut adj = vec![Vec::new(); m.positions.len()];
    for &[a, b, c] in &m.triangles {
        for (x, y) in [(a, b), (b, c), (c, a)] {
            adj[x as usize].push(y);
            adj[y as usize].push(x);
        }
    }
    for l in &mut adj {
        l.sort_unstable();
        l.dedup();
    }
    adj
}

/// The normal equations of a periodic spline fit with `blocks` blocks of `m` control
/// points: `g = AᵀA`, `r = Aᵀy` (a column a coordinate), `‖y‖²`, the rows of `A`, and a
/// second-difference penalty of 10⁻⁶ of the mean diagonal in every block that keeps the
/// system determined where data are few. `rows` gives each data row's non-zero columns and
/// values and its right-hand side. Column `k m + j` (block `k`, control point `j`) is
/// unknown [`Normal::at`]`= j · blocks + k`: so ordered, a row's columns (four
/// neighbouring control points in every block) and the penalties' lie within a band of
/// `4 · blocks` but for the control points that wrap round, and the envelope Cholesky
/// ([`ProfileCholesky`]) costs `O(n · blocks²)` where the dense one costs `O(n³)`.
struct Normal {
    m: usize,
    blocks: usize,
    g: Envelope,
    r: Mat<f64>,
    yy: f64,
    rows: usize,
    base: Envelope,
}

impl Normal {
    fn new(m: usize, blocks: usize, rows: impl Iterator<Item = (Vec<(usize, f64)>, Vec3)>) -> Self {
        let nc = m * blocks;
        let at = |c: usize| (c % m) * blocks + c / m;
        // control point j meets j − 3 … j + 3 (mod m) in every block: row j · blocks + k's
        // first entry is control j − 3's, or control 0's where j + 3 wraps round
        let first = (0..nc)
            .map(|u| {
                let j = u / blocks;
                if j + 3 >= m { 0 } else { j.saturating_sub(3) * blocks }
            })
            .collect::<Vec<_>>();
        let mut g = Envelope::zeros(first.clone());
        let mut r = Mat::<f64>::zeros(nc, 3);
        let (mut yy, mut count) = (0.0, 0);
        for (cols, d) in rows {
            for &(ca, va) in &cols {
                for &(cb, vb) in &cols {
                    if at(cb) <= at(ca) {
                        g.add_lower(at(ca), at(cb), va * vb);
                    }
                }
                for c in 0..3 {
                    r[(at(ca), c)] += va * d[c];
                }
            }
            yy += d.dot(d);
            count += 1;
        }
        let lambda = 1e-6 * (0..nc).map(|i| g.get(i, i)).sum::<f64>() / nc as f64;
        let mut base = Envelope::zeros(first);
        for k in 0..blocks {
            for j in 0..m {
                let idx = [(j + m - 1) % m, j, (j + 1) % m].map(|i| at(k * m + i));
                let coef = [1.0, -2.0, 1.0];
                for a in 0..3 {
                    for b in 0..3 {
                        if idx[b] <= idx[a] {
                            base.add_lower(idx[a], idx[b], lambda * coef[a] * coef[b]);
                        }
                    }
                }
            }
        }
        Normal { m, blocks, g, r, yy, rows: count, base }
    }

    /// The unknown of column `c`.
    fn at(&self, c: usize) -> usize {
        (c % self.m) * self.blocks + c / self.m
    }

    /// The solution by columns, from one in the unknowns' order.
    fn by_columns(&self, x: &Mat<f64>) -> Mat<f64> {
        Mat::from_fn(self.m * self.blocks, 3, |c, k| x[(self.at(c), k)])
    }

    /// Solves `(AᵀA + base) X = Aᵀy`.
    fn solve(&self) -> Result<Mat<f64>, LinalgError> {
        let a = self.g.combination(&[(1.0, &self.g), (1.0, &self.base)]);
        // symmetric positive definite where the fit is determined
        let x = ProfileCholesky::from_envelope(&a, 1e13)?.solve(&self.r);
        Ok(self.by_columns(&x))
    }

    /// Solves with the thin-plate penalty of `R = Σ_k β^k D̃_k(w)` (`D̃_k` on `basis`,
    /// `β = s / width`) added, its weight chosen by generalised cross-validation
    /// ([`smoothing`](super::smoothing)).
    fn solve_smoothed(&self, basis: &PeriodicSpline, width: f64) -> Result<(Mat<f64>, Smoothed), LinalgError> {
        let mut omega = Envelope::zeros(self.g.first.clone());
        add_thin_plate(&mut omega, basis, self.blocks, width, 1.0, |c| self.at(c));
        let fit = gcv_solve(&self.g, &omega, &self.base, &self.r, self.yy, self.rows)?;
        Ok((self.by_columns(&fit.x), fit))
    }
}

fn column(sol: &Mat<f64>, range: std::ops::Range<usize>, scale: f64) -> Vec<Vec3> {
    range.map(|i| Vec3::new(sol[(i, 0)], sol[(i, 1)], sol[(i, 2)]) * scale).collect()
}

/// Fits the collar of loop `lp` of `m` to the vertices within `rings` rings of it
/// (`adj` from [`adjacency`]).
pub fn fit_collar(m: &TriMesh, adj: &[Vec<u32>], lp: &MeshLoop, rings: usize) -> Result<CollarFit, CollarError> {
    let n = lp.vertices.len();
    let x: Vec<Vec3> = lp.vertices.iter().map(|&i| m.positions[i as usize]).collect();
    let mut chord = Vec::with_capacity(n);
    let mut acc = 0.0;
    for i in 0..n {
        chord.push(acc);
        let d = (x[(i + 1) % n] - x[i]).norm();
        if d == 0.0 {
            return Err(CollarError::Coincident(lp.vertices[i], lp.vertices[(i + 1) % n]));
        }
        acc += d;
    }
    let period = acc;
    let uniform = |c: usize| {
        PeriodicSpline::new((0..c).map(|j| period * j as f64 / c as f64).collect(), period)
            .expect("uniform breakpoints")
    };
    let spine_controls = (n / 6).clamp(6, 64);
    let us = uniform(spine_controls);
    // 1. the spine
    let spine_ctrl = fit_curve(&us, chord.iter().copied().zip(x.iter().copied()))?;
    let spine = us.curve(&spine_ctrl);
    // the vertices within `rings` rings, each with the loop vertex it was reached from
    let mut origin: Vec<Option<usize>> = vec![None; m.positions.len()];
    let mut front: Vec<u32> = lp.vertices.clone();
    let mut pts: Vec<(u32, usize)> = Vec::new();
    for (k, &v) in lp.vertices.iter().enumerate() {
        origin[v as usize] = Some(k);
        pts.push((v, k));
    }
    for _ in 1..=rings {
        let mut next = Vec::new();
        for &v in &front {
            let k = origin[v as usize].expect("a front vertex has an origin");
            for &w in &adj[v as usize] {
                if origin[w as usize].is_none() {
                    origin[w as usize] = Some(k);
                    next.push(w);
                    pts.push((w, k));
                }
            }
        }
        front = next;
    }
    // the D_k's breakpoints: seven a spine's span where the vertices outnumber the
    // unknowns (5 a breakpoint), at least three. Fewer lose the loop's staircase of
    // vertices at `s ≈ 0`, and the fill's boundary with them: the bench's torus and height
    // field 1.1e-3 and 5.2e-5 off with seven, 6.2e-3 and 5.5e-4 with three, 8.8e-3 and
    // 1.4e-3 with two (before the smoothing); over all 54 starts of `collar_does_not_
    // depend_on_the_loops_first_vertex` 1.05e-3 … 1.62e-3 with seven. So many unknowns
    // would follow a mesh's noise: the smoothing's weight holds them back (see the module)
    let needed = BLOCKS * 3 * spine_controls;
    if pts.len() < needed {
        return Err(CollarError::TooFewPoints { points: pts.len(), rings, needed });
    }
    let controls = (7 * spine_controls).min(pts.len() / BLOCKS);
    let ub = uniform(controls);
    // 2. parameters: feet on the spine and signed distances
    let on_loop = triangles_on_loop(m, lp);
    let normal_ctrl = normal_along(m, &on_loop, &chord, period, &us)?;
    let normal = us.curve(&normal_ctrl);
    // the spine sampled once, for every vertex's foot
    let samples = SpineSamples::new(&spine, &chord, period);
    let feet: Vec<(f64, f64, Vec3)> = pts
        .iter()
        .map(|&(v, k)| {
            let xv = m.positions[v as usize];
            let w = foot(&spine, &samples, k, 3 + 2 * rings, xv);
            let j = spine.jet(&[w], JetShape::new(&[1]));
            let (pw, t) = (j.derivative([0, 0, 0]), j.derivative([1, 0, 0]));
            let d = xv - pw;
            let side = normal.eval(&[w]).cross(t);
            let across = side * (1.0 / side.norm());
            let s = d.dot(across);
            // the collar's `s B(w)` taken out: the `D_k` fit what is left
            (w, s, d - across * s)
        })
        .collect();
    let width = feet.iter().fold(0.0, |a: f64, f| max_nan(a, f.1));
    if width.partial_cmp(&0.0) != Some(Ordering::Greater) {
        return Err(CollarError::TooFewPoints { points: 0, rings, needed });
    }
    // 3. the surface, in β = s / width for D̃_k = width^k D_k
    let rows = feet.iter().map(|&(w, s, d)| {
        let (j0, bas) = ub.basis(w, 0);
        let beta = s / width;
        let cols = (0..BLOCKS)
            .flat_map(|k| (0..4).map(move |t| (k, t)))
            .map(|(k, t)| (k * controls + (j0 + t) % controls, beta.powi(k as i32) * bas[0][t]))
            .collect();
        (cols, d)
    });
    let (sol, smoothed) = Normal::new(controls, BLOCKS, rows).solve_smoothed(&ub, width)?;
    let d: [Vec<Vec3>; BLOCKS] =
        std::array::from_fn(|k| column(&sol, k * controls..(k + 1) * controls, width.powi(-(k as i32))));
    let collar = Collar { spine: (us.clone(), spine_ctrl), normal: normal_ctrl, d: (ub, d), period };
    let mut sq = 0.0;
    let mut max_residual: f64 = 0.0;
    for (&(v, _), &(w, s, _)) in pts.iter().zip(&feet) {
        let e = (m.positions[v as usize] - collar.eval(&[s, w])).norm();
        sq += e * e;
        max_residual = max_nan(max_residual, e);
    }
    // 4. the loop on it: w_i increasing from w₀ within one period
    let feet_w: Vec<f64> = feet[..n].iter().map(|f| f.0).collect();
    let ws = loop_parameters(&feet_w, &x, period).map_err(|i| CollarError::NotMonotone(lp.vertices[i]))?;
    let params: Vec<(f64, f64)> = feet[..n].iter().zip(ws).map(|(f, w)| (f.1, w)).collect();
    let loop_residual =
        (0..n).fold(0.0, |a: f64, i| max_nan(a, (collar.eval(&[params[i].0, params[i].1]) - x[i]).norm()));
    check_orientation(m, lp, &collar, &params, period, width, &on_loop)?;
    Ok(CollarFit {
        collar,
        params,
        period,
        points: pts.len(),
        controls,
        spine_basis: us,
        width,
        rms: (sq / feet.len() as f64).sqrt(),
        max_residual,
        loop_residual,
        cond: smoothed.cond,
        smoothing: smoothed.weight,
        dof: smoothed.dof,
    })
}

/// The loop's vertices' `w_i`, increasing from `w₀` within one period: their feet `feet`
/// on the spine (in `[0, L)`), unwrapped along the loop, where a staircase's step turns
/// back against the spine moved forward by the least squares that leaves each step at
/// least `0.2` of its edge's length (pool-adjacent-violators on `w_i − Σ_{j<i} g_j`,
/// started after the loop's longest step). A vertex moved by more than `0.75` of its
/// longer edge, or feet that wind round the spine other than once, give its index.
fn loop_parameters(feet: &[f64], x: &[Vec3], period: f64) -> Result<Vec<f64>, usize> {
    let n = feet.len();
    let step = |i: usize| (feet[(i + 1) % n] - feet[i] + 0.5 * period).rem_euclid(period) - 0.5 * period;
    let steps: Vec<f64> = (0..n).map(step).collect();
    let worst = (0..n).min_by(|&a, &b| steps[a].total_cmp(&steps[b])).unwrap_or(0);
    let total: f64 = steps.iter().sum();
    if (total - period).abs().partial_cmp(&(0.5 * period)) != Some(Ordering::Less) {
        return Err((worst + 1) % n);
    }
    let edge = |i: usize| (x[(i + 1) % n] - x[i % n]).norm();
    // the linear sequence starts after the longest step, far from any violation
    let c = (0..n).max_by(|&a, &b| steps[a].total_cmp(&steps[b])).map_or(0, |i| (i + 1) % n);
    let mut w = Vec::with_capacity(n);
    let mut gap_sum = Vec::with_capacity(n);
    let (mut acc, mut g) = (feet[c], 0.0);
    for k in 0..n {
        w.push(acc);
        gap_sum.push(g);
        acc += steps[(c + k) % n];
        g += 0.2 * edge(c + k);
    }
    // pool adjacent violators on z_k = w_k − G_k: blocks of (sum, count)
    let mut blocks: Vec<(f64, usize)> = Vec::with_capacity(n);
    for k in 0..n {
        blocks.push((w[k] - gap_sum[k], 1));
        while blocks.len() > 1 {
            let (b, a) = (blocks[blocks.len() - 1], blocks[blocks.len() - 2]);
            if a.0 / a.1 as f64 <= b.0 / b.1 as f64 {
                break;
            }
            blocks.pop();
            let last = blocks.len() - 1;
            blocks[last] = (a.0 + b.0, a.1 + b.1);
        }
    }
    let mut out = vec![0.0; n];
    let mut k = 0;
    for (sum, count) in blocks {
        for _ in 0..count {
            let moved = sum / count as f64 + gap_sum[k];
            let i = (c + k) % n;
            let reach = 0.75 * edge(i).max(edge(i + n - 1));
            if (moved - w[k]).abs().partial_cmp(&reach).is_none_or(|o| o == Ordering::Greater) {
                return Err(i);
            }
            out[i] = moved;
            k += 1;
        }
    }
    // the step closing the loop keeps its room too
    let last = (c + n - 1) % n;
    if (out[c] + period - out[last]).partial_cmp(&(0.2 * edge(last))).is_none_or(|o| o == Ordering::Less) {
        return Err(c);
    }
    // from w₀ in [0, L)
    let shift = period * out[0].div_euclid(period);
    let first = out[0] - shift;
    for w in &mut out {
        *w -= shift;
        if *w < first {
            *w += period;
        }
    }
    Ok(out)
}

/// `N(w)`: a smooth normal along the spine, the least-squares periodic spline on `basis`
/// through the unit normals of the triangles on the loop's edges at their midpoints' chord
/// parameters. The loop's own triangles tilt back and forth where it zigzags; their fit
/// does not, so `s` measured across `N × P′` is smooth in the vertex.
fn normal_along(
    m: &TriMesh,
    on_loop: &[usize],
    chord: &[f64],
    period: f64,
    basis: &PeriodicSpline,
) -> Result<Vec<Vec3>, LinalgError> {
    let n = chord.len();
    let data = (0..n).filter_map(|i| {
        let next = if i + 1 == n { period } else { chord[i + 1] };
        Some((0.5 * (chord[i] + next), m.face_normal(on_loop[i]).normalized()?))
    });
    fit_curve(basis, data)
}

/// The control points of the periodic cubic spline on `basis` fitted to `data` (parameter,
/// point) by penalised least squares ([`Normal`]).
fn fit_curve(basis: &PeriodicSpline, data: impl Iterator<Item = (f64, Vec3)>) -> Result<Vec<Vec3>, LinalgError> {
    let c = basis.len();
    let rows = data.map(|(t, p)| {
        let (j0, b) = basis.basis(t, 0);
        ((0..4).map(|r| ((j0 + r) % c, b[0][r])).collect(), p)
    });
    let sol = Normal::new(c, 1, rows).solve()?;
    Ok(column(&sol, 0..c, 1.0))
}

/// The spine `p` sampled at [`SpineSamples::PER_EDGE`] points a loop edge, evenly in each
/// edge's chord interval: where every foot search starts.
struct SpineSamples {
    period: f64,
    /// `(w, p(w))` for `w` in `[0, period)`, increasing.
    samples: Vec<(f64, Vec3)>,
}

impl SpineSamples {
    const PER_EDGE: usize = 8;

    fn new(p: &NurbsCurve, chord: &[f64], period: f64) -> Self {
        let n = chord.len();
        let samples = (0..n)
            .flat_map(|e| {
                let (a, b) = (chord[e], if e + 1 < n { chord[e + 1] } else { chord[0] + period });
                (0..Self::PER_EDGE).map(move |i| a + (b - a) * i as f64 / Self::PER_EDGE as f64)
            })
            .map(|w| (w, p.eval(&[w.rem_euclid(period)])))
            .collect();
        SpineSamples { period, samples }
    }

    /// The samples within `reach` loop edges of loop vertex `k` (at most half the loop each
    /// way), their `w` unwrapped to increase through `chord[k]`: the window's ends `lo`,
    /// `hi` and its samples.
    fn window(&self, k: usize, reach: usize) -> (f64, f64, impl Iterator<Item = (f64, Vec3)> + '_) {
        let n = self.samples.len() / Self::PER_EDGE;
        let reach = reach.min(n / 2) as isize;
        let count = self.samples.len() as isize;
        let at = move |j: isize| -> (f64, Vec3) {
            let (w, pw) = self.samples[j.rem_euclid(count) as usize];
            (w + self.period * j.div_euclid(count) as f64, pw)
        };
        let per = Self::PER_EDGE as isize;
        let (first, last) = ((k as isize - reach) * per, (k as isize + reach) * per);
        (at(first).0, at(last).0, (first..=last).map(at))
    }
}

/// The foot of `x` on the spine `p`: the nearest of the samples within `reach` loop edges of
/// loop vertex `k`, refined by Newton within them.
fn foot(p: &NurbsCurve, samples: &SpineSamples, k: usize, reach: usize, x: Vec3) -> f64 {
    let period = samples.period;
    let (lo, hi, window) = samples.window(k, reach);
    let wrap = |w: f64| w.rem_euclid(period);
    let mut best = (f64::INFINITY, lo);
    for (w, pw) in window {
        let d = (pw - x).norm();
        if d < best.0 {
            best = (d, w);
        }
    }
    let mut w = best.1;
    let shape = JetShape::new(&[2]);
    for _ in 0..20 {
        let j = p.jet(&[wrap(w)], shape);
        let (c, c1, c2) = (j.derivative([0, 0, 0]), j.derivative([1, 0, 0]), j.derivative([2, 0, 0]));
        let f = (c - x).dot(c1);
        let df = c1.dot(c1) + (c - x).dot(c2);
        if df.partial_cmp(&0.0) != Some(Ordering::Greater) {
            break;
        }
        let step = (f / df).clamp(-(hi - lo) / 8.0, (hi - lo) / 8.0);
        w = (w - step).clamp(lo, hi);
        if step.abs() <= 1e-15 * period {
            break;
        }
    }
    wrap(w)
}

#[allow(clippy::too_many_arguments)]
fn check_orientation(
    m: &TriMesh,
    lp: &MeshLoop,
    collar: &Collar,
    params: &[(f64, f64)],
    period: f64,
    width: f64,
    on_loop: &[usize],
) -> Result<(), CollarError> {
    let n = lp.vertices.len();
    let shape = JetShape::new(&[1, 1]);
    for i in 0..n {
        let w1 = if i + 1 == n { params[0].1 + period } else { params[i + 1].1 };
        let wm = 0.5 * (params[i].1 + w1);
        let tn = m.face_normal(on_loop[i]);
        let s0 = 0.5 * (params[i].0 + params[(i + 1) % n].0);
        for s in [s0, 0.5 * width, width] {
            let j = collar.jet(&[s, wm], shape);
            let cn = j.derivative([0, 1, 0]).cross(j.derivative([1, 0, 0]));
            let cosang = cn.dot(tn) / (cn.norm() * tn.norm());
            if cosang.partial_cmp(&0.0) != Some(Ordering::Greater) {
                return Err(CollarError::Folds { vertex: lp.vertices[i], angle: cosang.clamp(-1.0, 1.0).acos() });
            }
        }
    }
    Ok(())
}

/// For each loop edge `(v_i, v_{i+1})`, the triangle that runs it.
pub(super) fn triangles_on_loop(m: &TriMesh, lp: &MeshLoop) -> Vec<usize> {
    let n = lp.vertices.len();
    let mut want: std::collections::HashMap<(u32, u32), usize> =
        (0..n).map(|i| ((lp.vertices[i], lp.vertices[(i + 1) % n]), i)).collect();
    // only a triangle with a loop vertex can run a loop edge: the hash asked for those alone
    let mut on = vec![false; m.positions.len()];
    for &v in &lp.vertices {
        on[v as usize] = true;
    }
    let mut out = vec![usize::MAX; n];
    for (t, &[a, b, c]) in m.triangles.iter().enumerate() {
        if !(on[a as usize] || on[b as usize] || on[c as usize]) {
            continue;
        }
        for e in [(a, b), (b, c), (c, a)] {
            if let Some(i) = want.remove(&e) {
                out[i] = t;
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Eight loop vertices on a regular octagon of edge 1 (gaps 0.2), period 8, feet
    /// `(0, 1, 2, 1.9, 4, 5, 6, 7)`: the fourth 0.1 behind the third. Worked by hand: the
    /// sequence starts after the longest step (2.1, into vertex 4), so w = (4, …, 10, 9.9)
    /// for vertices 4, …, 3; less the gaps (0, 0.2, …, 1.4) the last two are 8.8 and 8.5,
    /// pooled at 8.65 they give back 9.85 and 10.05: vertices 2 and 3 move to 1.85 and
    /// 2.05, each by 0.15, the least squares that leaves their step 0.2.
    #[test]
    fn loop_parameters_by_hand() {
        let r = 0.5 / (std::f64::consts::PI / 8.0).sin();
        let x: Vec<Vec3> = (0..8)
            .map(|k| {
                let a = std::f64::consts::TAU * k as f64 / 8.0;
                Vec3::new(r * a.cos(), r * a.sin(), 0.0)
            })
            .collect();
        let w = loop_parameters(&[0.0, 1.0, 2.0, 1.9, 4.0, 5.0, 6.0, 7.0], &x, 8.0).unwrap();
        let want = [0.0, 1.0, 1.85, 2.05, 4.0, 5.0, 6.0, 7.0];
        for (a, b) in w.iter().zip(want) {
            // sums of a few numbers of size 10: round-off
            assert!((a - b).abs() < 1e-13, "{w:?}");
        }
        // the fourth foot 1.4 behind: pooled with the third at 8.0 (less the gaps) it
        // moves vertex 2 by 0.8, more than 0.75 of its edges, and is refused by name
        assert_eq!(loop_parameters(&[0.0, 1.0, 2.0, 0.6, 4.0, 5.0, 6.0, 7.0], &x, 8.0), Err(2));
        // feet that wind round three times, or not at all
        assert!(loop_parameters(&[0.0, 3.0, 6.0, 1.0, 4.0, 7.0, 2.0, 5.0], &x, 8.0).is_err());
        assert!(loop_parameters(&[0.0, 1.0, 0.0, 1.0, 0.0, 1.0, 0.0, 1.0], &x, 8.0).is_err());
        // NaN feet are refused, not ordered
        assert!(loop_parameters(&[0.0, f64::NAN, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0], &x, 8.0).is_err());
    }

    /// The line's `σ`, `σ′` from the periodic basis against its NURBS jet at 50 pseudo-random
    /// `τ`, wrapped ones included.
    #[test]
    fn line_slope_matches_its_jet() {
        let period = 2.0;
        let b = PeriodicSpline::new((0..9).map(|j| period * (j as f64 + 0.1 * (j % 3) as f64) / 9.0).collect(), period)
            .unwrap();
        let ctrl: Vec<f64> = (0..9).map(|j| (j as f64 * 1.3).sin()).collect();
        let line = DomainLine::new(&b, &ctrl);
        for q in 0..50 {
            let tau = -3.0 + 0.1337 * q as f64;
            let j = line.jet(&[tau], JetShape::new(&[1]));
            let (s, ds) = line.sigma_and_slope(tau);
            // control values of size 1, cubic basis: round-off ~1e-15 (both sum four terms)
            assert!((s - j.value().x).abs() < 1e-14, "{tau}: {s} {}", j.value().x);
            assert!((ds - j.derivative([1, 0, 0]).x).abs() < 1e-13, "{tau}: {ds} {}", j.derivative([1, 0, 0]).x);
        }
    }

    /// Pseudo-random numbers in `[−½, ½)` (xorshift64 from `seed`): the tests' fixed draws.
    fn uniform_in_half(mut seed: u64) -> impl FnMut() -> f64 {
        move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        }
    }

    /// The collar's jet (the bases evaluated once, `spline_derivatives`) against the same
    /// splines as `NurbsCurve`s (the B-spline module's own jets): `Σ s^k D_k` expanded by
    /// hand at 50 pseudo-random `(s, w)`, every Taylor coefficient up to order (4, 5).
    #[test]
    fn jet_matches_the_nurbs_curves() {
        let period = 2.0;
        let (us, ub) = (
            PeriodicSpline::new((0..6).map(|j| period * j as f64 / 6.0).collect(), period).unwrap(),
            PeriodicSpline::new((0..15).map(|j| period * j as f64 / 15.0).collect(), period).unwrap(),
        );
        let mut rnd = uniform_in_half(0x2545_f491_4f6c_dd1d);
        let mut pts = |n: usize| -> Vec<Vec3> { (0..n).map(|_| Vec3::new(rnd(), rnd(), rnd())).collect() };
        let spine = pts(6);
        let d: [Vec<Vec3>; BLOCKS] = std::array::from_fn(|_| pts(15));
        let normal = pts(6);
        let collar =
            Collar { spine: (us.clone(), spine.clone()), normal: normal.clone(), d: (ub.clone(), d.clone()), period };
        let curves: Vec<NurbsCurve> = d.iter().map(|c| ub.curve(c)).chain([us.curve(&spine)]).collect();
        let shape = JetShape::new(&[4, 5]);
        for _ in 0..50 {
            let (s, w) = (0.6 * rnd(), 3.0 * rnd());
            let got = collar.jet(&[s, w], shape);
            let cj: Vec<VecJet> = curves.iter().map(|c| c.jet(&[w.rem_euclid(period)], JetShape::new(&[5]))).collect();
            // `s B(w)`: `B`'s coefficients from the spine's and the normal's own jets
            // (`across_taylor` itself is checked by `across_is_the_unit_normal`)
            let taylor = |c: &NurbsCurve| -> Vec<Vec3> {
                let v = c.jet(&[w.rem_euclid(period)], JetShape::new(&[6]));
                (0..=6)
                    .map(|t| Vec3::new(v.0[0].coeff([t, 0, 0]), v.0[1].coeff([t, 0, 0]), v.0[2].coeff([t, 0, 0])))
                    .collect()
            };
            let b = across_taylor(&taylor(&us.curve(&spine)), &taylor(&us.curve(&normal)), 5);
            let across = |j: usize, q: usize| b[j][q];
            for i in 0..=4 {
                for j in 0..=5 {
                    for q in 0..3 {
                        // d^i/ds^i of s^k over i!: C(k, i) s^(k−i)
                        let binom = [
                            [1.0, 0.0, 0.0, 0.0, 0.0],
                            [1.0, 1.0, 0.0, 0.0, 0.0],
                            [1.0, 2.0, 1.0, 0.0, 0.0],
                            [1.0, 3.0, 3.0, 1.0, 0.0],
                            [1.0, 4.0, 6.0, 4.0, 1.0],
                        ];
                        let mut want: f64 =
                            (i..5).map(|k| binom[k][i] * s.powi((k - i) as i32) * cj[k].0[q].coeff([j, 0, 0])).sum();
                        if i == 0 {
                            want += cj[5].0[q].coeff([j, 0, 0]) + s * across(j, q);
                        } else if i == 1 {
                            want += across(j, q);
                        }
                        let have = got.0[q].coeff([i, j, 0]);
                        // coefficients of size ≤ 10³ (derivatives over breakpoint gaps of 0.13)
                        // summed a few at a time: round-off
                        assert!(
                            (have - want).abs() <= 1e-12 * (1.0 + want.abs()),
                            "({i}, {j}) q {q}: {have} vs {want}"
                        );
                    }
                }
            }
        }
    }

    /// `across_taylor`'s coefficients are those of the unit vector along `N × P′`: as jets,
    /// `B·B = 1`, `B·N = 0` and `B·P′ = 0` in every coefficient up to order 5 (three
    /// conditions that leave only `±(N × P′)/|N × P′|`), and `B·(N × P′) > 0`; at 50
    /// pseudo-random points of random cubic splines.
    #[test]
    fn across_is_the_unit_normal() {
        let period = 2.0;
        let us = PeriodicSpline::new((0..6).map(|j| period * j as f64 / 6.0).collect(), period).unwrap();
        let mut rnd = uniform_in_half(0x9e37_79b9_7f4a_7c15);
        let mut pts = |n: usize| -> Vec<Vec3> { (0..n).map(|_| Vec3::new(rnd(), rnd(), rnd())).collect() };
        let (spine, normal) = (pts(6), pts(6));
        let nd = 5;
        for _ in 0..50 {
            let w = period * (rnd() + 0.5);
            let [p, n] = spline_derivatives(&us, [&spine, &normal], w, nd + 1);
            let b = across_taylor(&p, &n, nd);
            let dp: Vec<Vec3> = (0..=nd).map(|j| p[j + 1] * (j + 1) as f64).collect();
            // the Taylor coefficient `t` of the dot product of two vector jets, and the sum of
            // its terms' sizes: the round-off it can carry
            let dot = |a: &[Vec3], c: &[Vec3], t: usize| {
                (0..=t).fold((0.0, 0.0), |(v, m), k| (v + a[k].dot(c[t - k]), m + a[k].norm() * c[t - k].norm()))
            };
            for t in 0..=nd {
                let (bb, m) = dot(&b, &b, t);
                let unit = (bb - if t == 0 { 1.0 } else { 0.0 }, m);
                for (what, (v, m)) in [("B·B − 1", unit), ("B·N", dot(&b, &n, t)), ("B·P′", dot(&b, &dp, t))] {
                    // a few dozen products and the jets' own sums: 1e-14 of the terms
                    assert!(v.abs() <= 1e-14 * max_nan(m, 1.0), "{what} order {t}: {v:e} (terms {m:e})");
                }
            }
            assert!(b[0].dot(n[0].cross(dp[0])) > 0.0);
        }
    }
}
