//! The solid blend: Hermite part + correction.

use super::{SolidError, gauss_legendre};
use crate::Vec3;
use crate::data::FieldRef;
use crate::jet::JetShape;
use crate::num::MaxNan;
use crate::patch::cubic_hermite;
use faer::Mat;
use rayon::prelude::*;
use std::f64::consts::PI;

/// `α∂u⁴ + β∂v⁴ + γ∂w⁴`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolidOperator {
    /// `α`.
    pub alpha: f64,
    /// `β`.
    pub beta: f64,
    /// `γ`.
    pub gamma: f64,
}

impl SolidOperator {
    /// Requires positive finite coefficients (the operator is then elliptic and the
    /// Galerkin systems positive definite).
    pub fn new(alpha: f64, beta: f64, gamma: f64) -> Result<Self, SolidError> {
        for (n, x) in [("alpha", alpha), ("beta", beta), ("gamma", gamma)] {
            if !(x.is_finite() && x > 0.0) {
                return Err(SolidError::Input(format!(
                    "{n} = {x}: the solid operator needs positive coefficients (it is then elliptic)"
                )));
            }
        }
        Ok(SolidOperator { alpha, beta, gamma })
    }
}

/// The correction's trial space in `w` and how it is fitted.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Trial {
    /// `sin(πw) sin(nπw)`, least squares of the residual on a Gauss grid (default).
    Complete,
    /// `sin(πw) sin(nπw)`, Galerkin projection.
    Galerkin,
    /// `sin(πw) sin(nπw)` collocated at the paper's `L·M·N` uniform interior points (a
    /// square system): for boundary surfaces whose high derivatives are singular at the
    /// edges of the parameter square, where the integrals of the other fits diverge.
    Collocation,
    /// The paper's `sin²(nπw)` with uniform collocation (singular; reported).
    Paper,
}

/// Options of a solid blend.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolidOptions {
    /// Trial space.
    pub trial: Trial,
    /// `(L, M, N)` terms in `u`, `v`, `w`.
    pub terms: (usize, usize, usize),
}

impl Default for SolidOptions {
    fn default() -> Self {
        SolidOptions { trial: Trial::Complete, terms: (6, 6, 6) }
    }
}

impl SolidOptions {
    /// The Gauss rules `(3L + 24, 3M + 24, 2N + 24)` in `u`, `v`, `w` on which the
    /// separated fits (complete and Galerkin trial spaces) integrate the residual.
    pub fn quadrature(&self) -> (usize, usize, usize) {
        let (l, m, n) = self.terms;
        (3 * l + 24, 3 * m + 24, 2 * n + 24)
    }

    /// The size of the solve's point set: the points of the Gauss grid
    /// ([`quadrature`](Self::quadrature)) for the separated fits, the `L·M·N` collocation
    /// rows otherwise. The loader caps it (`collocation`).
    pub fn points(&self) -> u128 {
        let (l, m, n) = self.terms;
        match self.trial {
            Trial::Complete | Trial::Galerkin => {
                let (a, b, c) = self.quadrature();
                a as u128 * b as u128 * c as u128
            }
            Trial::Collocation | Trial::Paper => l as u128 * m as u128 * n as u128,
        }
    }
}

/// What the solve did.
#[derive(Clone, Debug, PartialEq)]
pub struct SolidReport {
    /// `"galerkin"` or `"paper-collocation"`.
    pub method: &'static str,
    /// `(L, M, N)`.
    pub terms: (usize, usize, usize),
    /// Largest condition number of the per-(l, m) systems (or of the collocation matrix).
    pub condition_number: f64,
    /// Largest |a_lmn| (per component).
    pub max_coefficient: f64,
}

/// `d^k/dx^k sin(cx)`.
fn sin_d(c: f64, x: f64, k: usize) -> f64 {
    c.powi(k as i32) * (c * x + k as f64 * PI / 2.0).sin()
}

/// `d^k/dx^k cos(cx)`.
fn cos_d(c: f64, x: f64, k: usize) -> f64 {
    c.powi(k as i32) * (c * x + k as f64 * PI / 2.0).cos()
}

/// `ψ_n^{(k)}(w)` of the trial space.
fn psi(trial: Trial, n: usize, w: f64, k: usize) -> f64 {
    let nf = n as f64;
    match trial {
        // sin πw sin nπw = ½[cos((n−1)πw) − cos((n+1)πw)]
        Trial::Complete | Trial::Galerkin | Trial::Collocation => {
            0.5 * (cos_d((nf - 1.0) * PI, w, k) - cos_d((nf + 1.0) * PI, w, k))
        }
        // sin² nπw = ½ − ½ cos 2nπw
        Trial::Paper => (if k == 0 { 0.5 } else { 0.0 }) - 0.5 * cos_d(2.0 * nf * PI, w, k),
    }
}

/// A solid blend (see the module docs).
#[derive(Clone, Debug)]
pub struct SolidBlend {
    op: SolidOperator,
    faces: [FieldRef; 4],
    opts: SolidOptions,
    /// `a[(l·M + m)·N + n]`, 0-based `l, m, n` for `l + 1, m + 1, n + 1`.
    a: Vec<Vec3>,
    report: SolidReport,
}

impl SolidBlend {
    /// Solves for the correction. `faces` are `S₁ … S₄` (slots `(u, v)`).
    pub fn new(op: SolidOperator, faces: [FieldRef; 4], opts: SolidOptions) -> Result<Self, SolidError> {
        crate::solves::record(crate::solves::SolveKind::Solid);
        let (nl, nm, nn) = opts.terms;
        if nl == 0 || nm == 0 || nn == 0 || nl * nm * nn > 40_000 {
            return Err(SolidError::Input(format!("terms ({nl}, {nm}, {nn}): each must be ≥ 1 and L·M·N ≤ 40000")));
        }
        let mut s = SolidBlend {
            op,
            faces,
            opts,
            a: vec![Vec3::ZERO; nl * nm * nn],
            report: SolidReport {
                method: "least-squares",
                terms: opts.terms,
                condition_number: 1.0,
                max_coefficient: 0.0,
            },
        };
        match opts.trial {
            Trial::Complete => s.solve_separated(false)?,
            Trial::Galerkin => s.solve_separated(true)?,
            Trial::Paper | Trial::Collocation => s.solve_collocation()?,
        }
        s.report.max_coefficient = s.a.iter().map(|x| x.max_abs()).max_nan();
        Ok(s)
    }

    /// The operator.
    pub fn operator(&self) -> SolidOperator {
        self.op
    }

    /// The options it was solved with (trial space and term counts).
    pub fn options(&self) -> SolidOptions {
        self.opts
    }

    /// What the solve did.
    pub fn report(&self) -> &SolidReport {
        &self.report
    }

    /// The coefficients `a_lmn`.
    pub fn coefficients(&self) -> &[Vec3] {
        &self.a
    }

    /// `R_i(u, v) = α∂u⁴S_i + β∂v⁴S_i`, so that `L[H] = Σ_i h_i(w) R_i(u, v)`.
    fn face_residuals(&self, u: f64, v: f64) -> [Vec3; 4] {
        std::array::from_fn(|i| {
            let ju = self.faces[i].jet(&[u, v], JetShape::new(&[4, 0]));
            let jv = self.faces[i].jet(&[u, v], JetShape::new(&[0, 4]));
            ju.derivative([4, 0, 0]) * self.op.alpha + jv.derivative([0, 4, 0]) * self.op.beta
        })
    }

    /// Both fits of the complete trial space separate over `(l, m)`: with Gauss rules in `u`
    /// and `v` the sines are orthogonal (`∫ sin lπu sin l′πu = δ/2`) and `∂u⁴`, `∂v⁴` act
    /// on them as `(lπ)⁴`, `(mπ)⁴`; so the residual's component along `sin lπu sin mπv` is
    /// `(λ_lm ψ + γ ψ⁗) a_lm + r_lm(w)`, `λ_lm = α(lπ)⁴ + β(mπ)⁴`, `r_lm = 4 ∫∫ L[H] sin sin`.
    /// Least squares minimises its `L²(w)` norm on a `2N + 24`-point Gauss grid (the strong
    /// residual, oversampled); Galerkin makes it orthogonal to every `ψ_n`.
    #[allow(clippy::needless_range_loop)] // (l, m) index the coefficient tensor and tables
    fn solve_separated(&mut self, galerkin: bool) -> Result<(), SolidError> {
        let (nl, nm, nn) = self.opts.terms;
        let (qu, qv, qw) = self.opts.quadrature();
        let (xw, ww) = gauss_legendre(qw);
        let p0: Vec<Vec<f64>> = xw.iter().map(|&w| (1..=nn).map(|n| psi(Trial::Complete, n, w, 0)).collect()).collect();
        let p4: Vec<Vec<f64>> = xw.iter().map(|&w| (1..=nn).map(|n| psi(Trial::Complete, n, w, 4)).collect()).collect();
        let hs: Vec<[[f64; 5]; 4]> = xw.iter().map(|&w| cubic_hermite(w)).collect();
        // u, v: ∫∫ R_f sin lπu sin mπv
        let (xu, wu) = gauss_legendre(qu);
        let (xv, wv) = gauss_legendre(qv);
        let rf: Vec<Vec<[Vec3; 4]>> = xu
            .par_iter()
            .map(|&u| {
                crate::cancel::checkpoint();
                xv.iter().map(|&v| self.face_residuals(u, v)).collect()
            })
            .collect();
        let mut cond: f64 = 1.0;
        self.report.method = if galerkin { "galerkin" } else { "least-squares" };
        for l in 0..nl {
            crate::cancel::checkpoint();
            let su: Vec<f64> = xu.iter().map(|&u| ((l + 1) as f64 * PI * u).sin()).collect();
            for m in 0..nm {
                let sv: Vec<f64> = xv.iter().map(|&v| ((m + 1) as f64 * PI * v).sin()).collect();
                let mut r = [Vec3::ZERO; 4];
                for (iu, qu) in wu.iter().enumerate() {
                    for (iv, qv) in wv.iter().enumerate() {
                        let wgt = 4.0 * qu * qv * su[iu] * sv[iv];
                        for f in 0..4 {
                            r[f] += rf[iu][iv][f] * wgt;
                        }
                    }
                }
                let lam = self.op.alpha * ((l + 1) as f64 * PI).powi(4) + self.op.beta * ((m + 1) as f64 * PI).powi(4);
                let qw = xw.len();
                // rows: Gauss points in w (scaled by √weight); columns: ψ_n
                let g = Mat::from_fn(qw, nn, |k, n| ww[k].sqrt() * (lam * p0[k][n] + self.op.gamma * p4[k][n]));
                let rhs =
                    Mat::from_fn(qw, 3, |k, c| -ww[k].sqrt() * (0..4).map(|f| hs[k][f][0] * r[f][c]).sum::<f64>());
                let x = if galerkin {
                    // Σ_k w_k ψ_n'(w_k) [(λψ + γψ⁗) a + r](w_k) = 0
                    let t = Mat::from_fn(qw, nn, |k, n| ww[k].sqrt() * p0[k][n]);
                    let a = crate::lanes::after(t.transpose() * &g);
                    let b = crate::lanes::after(t.transpose() * &rhs);
                    let solver =
                        crate::linalg::SquareSolver::new(&a, 1e14).map_err(|e| SolidError::Solve(e.to_string()))?;
                    cond = crate::num::max_nan(cond, solver.cond());
                    solver.solve(&b)
                } else {
                    let (x, c) =
                        crate::linalg::least_squares(&g, &rhs, 1e14).map_err(|e| SolidError::Solve(e.to_string()))?;
                    cond = crate::num::max_nan(cond, c);
                    x
                };
                for n in 0..nn {
                    self.a[(l * nm + m) * nn + n] = Vec3::new(x[(n, 0)], x[(n, 1)], x[(n, 2)]);
                }
            }
        }
        self.report.condition_number = cond;
        Ok(())
    }

    #[allow(clippy::needless_range_loop)] // (l, m, n) index the coefficient tensor
    fn solve_collocation(&mut self) -> Result<(), SolidError> {
        let trial = self.opts.trial;
        let (nl, nm, nn) = self.opts.terms;
        let k = nl * nm * nn;
        if k > 4096 {
            return Err(SolidError::Input(format!("collocation with L·M·N = {k} > 4096 is too large")));
        }
        let pts = |n: usize| -> Vec<f64> { (1..=n).map(|i| i as f64 / (n + 1) as f64).collect() };
        let (pu, pv, pw) = (pts(nl), pts(nm), pts(nn));
        let mut a = Mat::<f64>::zeros(k, k);
        let mut b = Mat::<f64>::zeros(k, 3);
        let mut row = 0;
        for &u in &pu {
            crate::cancel::checkpoint();
            for &v in &pv {
                let rf = self.face_residuals(u, v);
                for &w in &pw {
                    let h = cubic_hermite(w);
                    let lh = (0..4).fold(Vec3::ZERO, |acc, f| acc + rf[f] * h[f][0]);
                    for c in 0..3 {
                        b[(row, c)] = -lh[c];
                    }
                    for l in 0..nl {
                        let lf = (l + 1) as f64 * PI;
                        for m in 0..nm {
                            let mf = (m + 1) as f64 * PI;
                            for n in 0..nn {
                                let s = (lf * u).sin() * (mf * v).sin();
                                a[(row, (l * nm + m) * nn + n)] = s
                                    * ((self.op.alpha * lf.powi(4) + self.op.beta * mf.powi(4))
                                        * psi(trial, n + 1, w, 0)
                                        + self.op.gamma * psi(trial, n + 1, w, 4));
                            }
                        }
                    }
                    row += 1;
                }
            }
        }
        let cond = crate::linalg::condition_number(&a).map_err(|e| SolidError::Solve(e.to_string()))?;
        self.report.method = if trial == Trial::Paper { "paper-collocation" } else { "collocation" };
        self.report.condition_number = cond;
        if cond.is_nan() || cond > 1e12 {
            return Err(if trial == Trial::Paper {
                SolidError::PaperSingular { cond }
            } else {
                SolidError::Solve(format!("the collocation system is singular (condition number {cond:.2e})"))
            });
        }
        let solver = crate::linalg::SquareSolver::new(&a, 1e12).map_err(|e| SolidError::Solve(e.to_string()))?;
        let x = solver.solve(&b);
        for i in 0..k {
            self.a[i] = Vec3::new(x[(i, 0)], x[(i, 1)], x[(i, 2)]);
        }
        Ok(())
    }

    #[allow(clippy::needless_range_loop)] // (l, m, n) index the coefficient tensor
    /// `∂^{a+b+c} x / ∂uᵃ∂vᵇ∂wᶜ` for every `(a, b, c) ≤ (du, dv, dw)` at index
    /// `(a (dv + 1) + b)(dw + 1) + c`.
    pub fn derivatives(&self, u: f64, v: f64, w: f64, du: usize, dv: usize, dw: usize) -> Vec<Vec3> {
        let (nl, nm, nn) = self.opts.terms;
        let idx = |a: usize, b: usize, c: usize| (a * (dv + 1) + b) * (dw + 1) + c;
        let mut out = vec![Vec3::ZERO; (du + 1) * (dv + 1) * (dw + 1)];
        let h = cubic_hermite(w);
        for (f, face) in self.faces.iter().enumerate() {
            let j = face.jet(&[u, v], JetShape::new(&[du, dv]));
            for a in 0..=du {
                for b in 0..=dv {
                    let s = j.derivative([a, b, 0]);
                    for c in 0..=dw {
                        out[idx(a, b, c)] += s * if c <= 4 { h[f][c] } else { 0.0 };
                    }
                }
            }
        }
        let su: Vec<Vec<f64>> = (0..nl).map(|l| (0..=du).map(|k| sin_d((l + 1) as f64 * PI, u, k)).collect()).collect();
        let sv: Vec<Vec<f64>> = (0..nm).map(|m| (0..=dv).map(|k| sin_d((m + 1) as f64 * PI, v, k)).collect()).collect();
        let pw: Vec<Vec<f64>> =
            (0..nn).map(|n| (0..=dw).map(|k| psi(self.opts.trial, n + 1, w, k)).collect()).collect();
        for l in 0..nl {
            for m in 0..nm {
                for n in 0..nn {
                    let coef = self.a[(l * nm + m) * nn + n];
                    if coef == Vec3::ZERO {
                        continue;
                    }
                    for a in 0..=du {
                        for b in 0..=dv {
                            let ab = su[l][a] * sv[m][b];
                            for c in 0..=dw {
                                out[idx(a, b, c)] += coef * (ab * pw[n][c]);
                            }
                        }
                    }
                }
            }
        }
        out
    }

    /// `x(u, v, w)`.
    pub fn point(&self, u: f64, v: f64, w: f64) -> Vec3 {
        self.derivatives(u, v, w, 0, 0, 0)[0]
    }

    /// The Jacobian columns `[x_u, x_v, x_w]`.
    pub fn jacobian(&self, u: f64, v: f64, w: f64) -> [Vec3; 3] {
        let d = self.derivatives(u, v, w, 1, 1, 1);
        [d[4], d[2], d[1]]
    }

    /// The PDE residual `(α∂u⁴ + β∂v⁴ + γ∂w⁴) x`.
    pub fn residual(&self, u: f64, v: f64, w: f64) -> Vec3 {
        let du = self.derivatives(u, v, w, 4, 0, 0)[4];
        let dv = self.derivatives(u, v, w, 0, 4, 0)[4];
        let dw = self.derivatives(u, v, w, 0, 0, 4)[4];
        du * self.op.alpha + dv * self.op.beta + dw * self.op.gamma
    }

    /// Positions on the grid `us × vs × ws` (index `(i·|vs| + j)·|ws| + k`), by tensor
    /// contraction: faces once per `(u, v)`, the correction as `Σ_n C_n(u, v) ψ_n(w)`.
    pub fn grid(&self, us: &[f64], vs: &[f64], ws: &[f64]) -> Vec<Vec3> {
        let (nl, nm, nn) = self.opts.terms;
        let hs: Vec<[[f64; 5]; 4]> = ws.iter().map(|&w| cubic_hermite(w)).collect();
        let ps: Vec<Vec<f64>> = ws.iter().map(|&w| (1..=nn).map(|n| psi(self.opts.trial, n, w, 0)).collect()).collect();
        let sv: Vec<Vec<f64>> = vs.iter().map(|&v| (1..=nm).map(|m| (m as f64 * PI * v).sin()).collect()).collect();
        us.par_iter()
            .flat_map_iter(|&u| {
                crate::cancel::checkpoint();
                let su: Vec<f64> = (1..=nl).map(|l| (l as f64 * PI * u).sin()).collect();
                let mut out = Vec::with_capacity(vs.len() * ws.len());
                for (j, &v) in vs.iter().enumerate() {
                    let f: [Vec3; 4] = std::array::from_fn(|i| self.faces[i].eval(&[u, v]));
                    let mut cn = vec![Vec3::ZERO; nn];
                    for (l, sl) in su.iter().enumerate() {
                        for (m, sm) in sv[j].iter().enumerate() {
                            let s = sl * sm;
                            for (n, c) in cn.iter_mut().enumerate() {
                                *c += self.a[(l * nm + m) * nn + n] * s;
                            }
                        }
                    }
                    for (k, h) in hs.iter().enumerate() {
                        let mut x = (0..4).fold(Vec3::ZERO, |acc, i| acc + f[i] * h[i][0]);
                        for (n, c) in cn.iter().enumerate() {
                            x += *c * ps[k][n];
                        }
                        out.push(x);
                    }
                }
                out
            })
            .collect()
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use crate::data::ExprField;
    use std::sync::Arc;

    pub(crate) fn faces(e: [[&str; 3]; 4]) -> [FieldRef; 4] {
        e.map(|c| Arc::new(ExprField::parse(c, &["u", "v"], &|_| None).unwrap()) as FieldRef)
    }

    pub(crate) fn cubes() -> [FieldRef; 4] {
        faces([
            ["1 - 2*u", "1 - 2*v", "4"],
            ["-0.01*(1 - 2*u)", "-0.01*(1 - 2*v)", "-2"],
            ["1.5*(1 - 2*u)", "2*(1 - 2*v)", "2"],
            ["-0.015*(1 - 2*u)", "-0.02*(1 - 2*v)", "-2"],
        ])
    }

    pub(crate) fn cylinders() -> [FieldRef; 4] {
        faces([
            ["2*u*sin(2*pi*v)", "3*u*cos(2*pi*v)", "3"],
            ["-0.2*u*sin(2*pi*v)", "-0.3*u*cos(2*pi*v)", "-2"],
            ["u*sin(2*pi*v)", "u*cos(2*pi*v)", "1"],
            ["-0.1*u*sin(2*pi*v)", "-0.1*u*cos(2*pi*v)", "-2"],
        ])
    }

    #[test]
    fn two_cubes_are_the_hermite_part_exactly() {
        let op = SolidOperator::new(1.0, 1.0, 1.0).unwrap();
        let s = SolidBlend::new(op, cubes(), SolidOptions::default()).unwrap();
        assert!(s.report().max_coefficient < 1e-13, "{:?}", s.report());
        // volume: ∫∫∫ |det J| = ∫ 4 f(w) g(w) · 2 dw with f, g the x and y profiles
        let f = |w: f64| 1.0 - 0.01 * w + 1.535 * w * w - 1.025 * w * w * w;
        let g = |w: f64| 1.0 - 0.01 * w + 3.04 * w * w - 2.03 * w * w * w;
        let (xw, ww) = crate::solid::gauss_legendre(8);
        let exact: f64 = xw.iter().zip(&ww).map(|(&w, &q)| q * 8.0 * f(w) * g(w)).sum();
        let mp = s.mass_properties(8);
        assert!((mp.volume - exact).abs() < 1e-10 * exact, "{} vs {exact}", mp.volume);
        assert!(mp.centroid.x.abs() < 1e-12 && mp.centroid.y.abs() < 1e-12 && !mp.folds());
        for (u, v, w) in [(0.1, 0.7, 0.3), (0.5, 0.5, 0.5), (0.9, 0.2, 0.8)] {
            let x = s.point(u, v, w);
            let want = Vec3::new(
                (1.0 - 0.01 * w + 1.535 * w * w - 1.025 * w * w * w) * (1.0 - 2.0 * u),
                (1.0 - 0.01 * w + 3.04 * w * w - 2.03 * w * w * w) * (1.0 - 2.0 * v),
                4.0 - 2.0 * w,
            );
            assert!((x - want).norm() < 1e-12, "{x:?} vs {want:?}");
            assert!(s.residual(u, v, w).norm() < 1e-12);
        }
    }

    #[test]
    fn boundary_conditions_hold_exactly() {
        let op = SolidOperator::new(1.0, 1.0, 1.0).unwrap();
        let f = cylinders();
        let s = SolidBlend::new(op, f.clone(), SolidOptions { terms: (5, 5, 5), ..Default::default() }).unwrap();
        assert!(s.report().max_coefficient > 1e-3, "the cylinder blend needs a correction");
        let mut worst: f64 = 0.0;
        for i in 0..50 {
            for j in 0..50 {
                let (u, v) = (i as f64 / 49.0, j as f64 / 49.0);
                for (w, k, face) in [(0.0, 0, 0), (0.0, 1, 1), (1.0, 0, 2), (1.0, 1, 3)] {
                    let d = s.derivatives(u, v, w, 0, 0, 1)[k];
                    worst = crate::num::max_nan(worst, (d - f[face].eval(&[u, v])).norm());
                }
            }
        }
        assert!(worst < 1e-12, "{worst}");
        // grid evaluation equals pointwise evaluation
        let (us, vs, ws) = ([0.1, 0.6], [0.3, 0.9], [0.0, 0.4, 1.0]);
        let g = s.grid(&us, &vs, &ws);
        // index (i·|vs| + j)·|ws| + k with (i, j, k) = (1, 0, 1)
        assert!((g[2 * 3 + 1] - s.point(0.6, 0.3, 0.4)).norm() < 1e-13);
    }

    #[test]
    fn the_papers_trial_space_is_reported_singular() {
        let op = SolidOperator::new(1.0, 1.0, 1.0).unwrap();
        for n in [2, 3, 4] {
            let e =
                SolidBlend::new(op, cylinders(), SolidOptions { trial: Trial::Paper, terms: (n, n, n) }).unwrap_err();
            match e {
                SolidError::PaperSingular { cond } => assert!(cond > 1e12, "{cond}"),
                e => panic!("{e}"),
            }
        }
        assert!(SolidOperator::new(0.0, 1.0, 1.0).is_err());
    }

    #[test]
    fn the_complete_trial_space_converges_on_the_cylinders() {
        let op = SolidOperator::new(1.0, 1.0, 1.0).unwrap();
        let pts: Vec<(f64, f64, f64)> = (0..200)
            .map(|i| ((i as f64 * 0.618).fract(), (i as f64 * 0.414).fract(), (i as f64 * 0.732).fract()))
            .collect();
        let sol = |n: usize| {
            SolidBlend::new(op, cylinders(), SolidOptions { terms: (n, n, n), ..Default::default() }).unwrap()
        };
        let eval = |s: &SolidBlend| pts.iter().map(|&(u, v, w)| s.point(u, v, w)).collect::<Vec<_>>();
        let runs: Vec<Vec<Vec3>> = [3, 6, 9, 12].iter().map(|&n| eval(&sol(n))).collect();
        let changes: Vec<f64> =
            runs.windows(2).map(|w| w[0].iter().zip(&w[1]).map(|(a, b)| (*a - *b).norm()).max_nan()).collect();
        assert!(changes[0] > changes[1] && changes[1] > changes[2], "{changes:?}");
        assert!(changes[0] < 0.12 && changes[1] < 0.01 && changes[2] < 0.002, "{changes:?}");
        // the least-squares solid does not fold; Galerkin converges to a different, folding one
        assert!(sol(6).mass_properties(10).min_jacobian > 0.0);
        let g = SolidBlend::new(op, cylinders(), SolidOptions { trial: Trial::Galerkin, terms: (6, 6, 6) }).unwrap();
        assert!(g.mass_properties(10).folds());
    }
}
