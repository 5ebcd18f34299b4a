//! Certified tensor-product B-spline approximation of exact surfaces (for CAD exchange).
//!
//! A patch `X(u, v)` (any [`Surface`]: exact derivatives) is approximated by a clamped
//! B-spline surface `S(u, v) = Σᵢⱼ Nᵢ(u) Mⱼ(v) Pᵢⱼ` of degree 3 (or 5) on the patch's own
//! parameter rectangle `[0, 1] × [v₀, v₁]`:
//!
//! - **Fit**: interpolation at the Greville abscissae, separably — `X` sampled on
//!   `gᵘ × gᵛ`, then `Bᵤ C = X` per column and `Bᵥ Pᵀ = Cᵀ` per row, `B` the collocation
//!   matrices (non-singular by Schoenberg–Whitney, well conditioned at Greville points).
//!   The patch's boundary rows are interpolated at their Greville points too, so corners
//!   are exact and a periodic `v` closes (positions equal at the seam; the seam's tangent
//!   continuity is within the tolerance).
//! - **Certificate**: the parametric deviation `|S(u, v) − X(u, v)|` bounds the distance of
//!   every point of `S` from the patch. It is sampled on a 7 × 7 grid in every knot-span
//!   cell, and from every discrete local maximum of those samples it is maximised locally (projected gradient ascent with exact derivatives of `S` and `X`).
//!   The reported maximum is the largest value found.
//! - **Refinement**: every knot span in `u` (and in `v`) that holds a cell above the
//!   tolerance is halved, and the fit is repeated, until the maximum is within the
//!   tolerance or the control net would exceed `max_points` per direction (an error).

mod basis;

pub use basis::Knots;

use crate::Vec3;
use crate::patch::Surface;

/// A clamped tensor-product B-spline surface.
#[derive(Clone, Debug)]
pub struct BSplineSurface {
    /// Knots in `u`.
    pub u: Knots,
    /// Knots in `v`.
    pub v: Knots,
    /// Control points, row-major in `u`: `P[i * nv + j]`.
    pub control: Vec<Vec3>,
}

impl BSplineSurface {
    /// Control points in `u` and in `v`.
    pub fn counts(&self) -> (usize, usize) {
        (self.u.count(), self.v.count())
    }

    /// `∂^{a+b}S/∂uᵃ∂vᵇ` for `a ≤ du`, `b ≤ dv` at index `a (dv + 1) + b`.
    pub fn derivatives(&self, u: f64, v: f64, du: usize, dv: usize) -> Vec<Vec3> {
        let (su, nu) = self.u.basis(u, du);
        let (sv, nv) = self.v.basis(v, dv);
        let (p, q) = (self.u.degree, self.v.degree);
        let cols = self.v.count();
        let mut out = vec![Vec3::ZERO; (du + 1) * (dv + 1)];
        for a in 0..=du {
            for b in 0..=dv {
                let mut s = Vec3::ZERO;
                for (r, &wu) in nu[a].iter().enumerate() {
                    if wu == 0.0 {
                        continue;
                    }
                    let row = (su - p + r) * cols;
                    let mut t = Vec3::ZERO;
                    for (c, &wv) in nv[b].iter().enumerate() {
                        t += self.control[row + sv - q + c] * wv;
                    }
                    s += t * wu;
                }
                out[a * (dv + 1) + b] = s;
            }
        }
        out
    }

    /// `S(u, v)`.
    pub fn point(&self, u: f64, v: f64) -> Vec3 {
        self.derivatives(u, v, 0, 0)[0]
    }

    /// The boundary isocurve `u = 0` (`end` false) or `u = 1` as its control points (the
    /// first or last row of the net): exact, a clamped surface's edge is that curve.
    pub fn u_edge(&self, end: bool) -> Vec<Vec3> {
        let (nu, nv) = self.counts();
        let i = if end { nu - 1 } else { 0 };
        self.control[i * nv..(i + 1) * nv].to_vec()
    }

    /// The boundary isocurve `v = v₀` (`end` false) or `v = v₁` as control points.
    pub fn v_edge(&self, end: bool) -> Vec<Vec3> {
        let (nu, nv) = self.counts();
        let j = if end { nv - 1 } else { 0 };
        (0..nu).map(|i| self.control[i * nv + j]).collect()
    }
}

/// Options of a fit.
#[derive(Clone, Copy, Debug)]
pub struct FitOptions {
    /// Absolute tolerance on the parametric deviation; `None`: 1e-6 × the patch's
    /// bounding-box diagonal.
    pub tolerance: Option<f64>,
    /// Degree in both directions (3, or 5 when C2 must survive).
    pub degree: usize,
    /// Initial spans per direction.
    pub spans: (usize, usize),
    /// The largest control net per direction.
    pub max_points: usize,
}

impl Default for FitOptions {
    fn default() -> Self {
        FitOptions { tolerance: None, degree: 3, spans: (4, 8), max_points: 400 }
    }
}

/// What a fit achieved.
#[derive(Clone, Debug, PartialEq)]
pub struct FitReport {
    /// The tolerance aimed at (absolute).
    pub tolerance: f64,
    /// The certified maximum parametric deviation (absolute).
    pub max_deviation: f64,
    /// Where it was found.
    pub at: (f64, f64),
    /// Control points per direction.
    pub points: (usize, usize),
    /// Fit–check–refine rounds.
    pub rounds: usize,
    /// Samples and local maximisations the certificate took.
    pub samples: usize,
}

/// Why a fit failed.
#[derive(Debug, thiserror::Error)]
pub enum FitError {
    /// The patch is not finite at a sample.
    #[error("the patch is not finite at (u, v) = ({0}, {1})")]
    NotFinite(f64, f64),
    /// The tolerance was not reached within the control-point cap.
    #[error(
        "the tolerance {tolerance:.3e} was not reached with at most {cap} control points per direction (deviation {deviation:.3e} at (u, v) = ({u:.4}, {v:.4}))"
    )]
    Tolerance {
        /// Aimed at.
        tolerance: f64,
        /// Reached.
        deviation: f64,
        /// Where.
        u: f64,
        /// Where.
        v: f64,
        /// The cap.
        cap: usize,
    },
    /// A collocation matrix could not be factorised.
    #[error("the interpolation system is singular: {0}")]
    Singular(String),
}

/// Solves `B X = R` for the collocation matrix `B[k][j] = N_j(x_k)` and right-hand sides
/// `R` (rows `k`, `m` columns of `Vec3`).
fn interpolate(k: &Knots, xs: &[f64], rhs: &[Vec<Vec3>]) -> Result<Vec<Vec<Vec3>>, FitError> {
    let n = k.count();
    let m = rhs[0].len();
    let b = faer::Mat::<f64>::from_fn(n, n, |_, _| 0.0);
    let mut b = b;
    for (row, &x) in xs.iter().enumerate() {
        let (span, d) = k.basis(x, 0);
        for (r, &w) in d[0].iter().enumerate() {
            b[(row, span - k.degree + r)] = w;
        }
    }
    let lu = b.partial_piv_lu();
    let r = faer::Mat::<f64>::from_fn(n, 3 * m, |row, c| {
        let p = rhs[row][c / 3];
        [p.x, p.y, p.z][c % 3]
    });
    use faer::linalg::solvers::Solve;
    let x = lu.solve(&r);
    let out: Vec<Vec<Vec3>> = (0..n)
        .map(|i| (0..m).map(|c| Vec3::new(x[(i, 3 * c)], x[(i, 3 * c + 1)], x[(i, 3 * c + 2)])).collect())
        .collect();
    if out.iter().flatten().any(|p| !p.is_finite()) {
        return Err(FitError::Singular(format!("{n} × {n} collocation system")));
    }
    Ok(out)
}

/// Interpolates `s` at the Greville points of `(ku, kv)`.
fn fit_on(s: &dyn Surface, ku: &Knots, kv: &Knots) -> Result<BSplineSurface, FitError> {
    let (gu, gv) = (ku.greville(), kv.greville());
    let samples: Vec<Vec<Vec3>> = gu.iter().map(|&u| gv.iter().map(|&v| s.point(u, v)).collect()).collect();
    for (i, row) in samples.iter().enumerate() {
        if let Some(j) = row.iter().position(|p| !p.is_finite()) {
            return Err(FitError::NotFinite(gu[i], gv[j]));
        }
    }
    // along u for every v column, then along v for every u row
    let c = interpolate(ku, &gu, &samples)?;
    let ct: Vec<Vec<Vec3>> = (0..gv.len()).map(|j| c.iter().map(|row| row[j]).collect()).collect();
    let pt = interpolate(kv, &gv, &ct)?;
    let (nu, nv) = (ku.count(), kv.count());
    let control = (0..nu * nv).map(|k| pt[k % nv][k / nv]).collect();
    Ok(BSplineSurface { u: ku.clone(), v: kv.clone(), control })
}

/// The largest deviation in each knot-span cell (row-major in `u` spans), its place, and
/// the number of evaluations.
fn cell_deviations(s: &dyn Surface, b: &BSplineSurface) -> (Vec<(f64, f64, f64)>, usize) {
    let (bu, bv) = (b.u.breakpoints(), b.v.breakpoints());
    const K: usize = 7;
    let mut evals = 0;
    let mut out = Vec::with_capacity((bu.len() - 1) * (bv.len() - 1));
    let mut d = [[0.0_f64; K]; K];
    for i in 0..bu.len() - 1 {
        for j in 0..bv.len() - 1 {
            let at = |a: usize, c: usize| {
                (
                    bu[i] + (bu[i + 1] - bu[i]) * a as f64 / (K - 1) as f64,
                    bv[j] + (bv[j + 1] - bv[j]) * c as f64 / (K - 1) as f64,
                )
            };
            let mut best = (0.0_f64, bu[i], bv[j]);
            for (a, row) in d.iter_mut().enumerate() {
                for (c, x) in row.iter_mut().enumerate() {
                    let (u, v) = at(a, c);
                    *x = (b.point(u, v) - s.point(u, v)).norm();
                    evals += 1;
                    if x.is_nan() || *x > best.0 {
                        best = (*x, u, v);
                    }
                }
            }
            if best.0.is_nan() {
                out.push(best);
                continue;
            }
            // the error may have several bumps in a cell (and a maximum along its edge
            // need not be the interior one): ascend from every discrete local maximum
            for a in 0..K {
                for c in 0..K {
                    let peak = (a.saturating_sub(1)..(a + 2).min(K))
                        .all(|a2| (c.saturating_sub(1)..(c + 2).min(K)).all(|c2| d[a2][c2] <= d[a][c]));
                    if !peak {
                        continue;
                    }
                    let (u, v) = at(a, c);
                    let (m, u, v, n) = local_max(s, b, u, v, (bu[i], bu[i + 1]), (bv[j], bv[j + 1]));
                    evals += n;
                    if m.is_nan() || m > best.0 {
                        best = (m, u, v);
                    }
                }
            }
            out.push(best);
        }
    }
    (out, evals)
}

/// Projected gradient ascent of `|S − X|²` within a cell from `(u, v)`, with exact
/// derivatives; step halved until the value grows.
fn local_max(
    s: &dyn Surface,
    b: &BSplineSurface,
    u0: f64,
    v0: f64,
    ru: (f64, f64),
    rv: (f64, f64),
) -> (f64, f64, f64, usize) {
    let f = |u: f64, v: f64| {
        let e = b.point(u, v) - s.point(u, v);
        e.dot(e)
    };
    let (mut u, mut v) = (u0, v0);
    let mut fv = f(u, v);
    let mut step = 0.25 * (ru.1 - ru.0).max(rv.1 - rv.0);
    let mut evals = 1;
    for _ in 0..30 {
        let (ds, dx) = (b.derivatives(u, v, 1, 1), s.derivatives(u, v, 1, 1));
        let e = ds[0] - dx[0];
        // index a·2 + b: [S, S_v, S_u, S_uv]
        let (gu, gv) = (2.0 * e.dot(ds[2] - dx[2]), 2.0 * e.dot(ds[1] - dx[1]));
        let g = (gu * gu * (ru.1 - ru.0).powi(2) + gv * gv * (rv.1 - rv.0).powi(2)).sqrt();
        if g.is_nan() || g == 0.0 {
            break;
        }
        let mut moved = false;
        while step > 1e-6 * (ru.1 - ru.0) {
            let nu = (u + step * gu * (ru.1 - ru.0).powi(2) / g).clamp(ru.0, ru.1);
            let nv = (v + step * gv * (rv.1 - rv.0).powi(2) / g).clamp(rv.0, rv.1);
            let fnew = f(nu, nv);
            evals += 1;
            if fnew > fv {
                (u, v, fv) = (nu, nv, fnew);
                moved = true;
                step *= 1.5;
                break;
            }
            step *= 0.5;
        }
        if !moved {
            break;
        }
    }
    (fv.sqrt(), u, v, evals)
}

/// Fits `s` on its parameter rectangle (`u ∈ [0, 1]`, `v` its domain) to the tolerance.
pub fn fit_surface(s: &dyn Surface, o: &FitOptions) -> Result<(BSplineSurface, FitReport), FitError> {
    let dom = s.v_domain();
    let tol = match o.tolerance {
        Some(t) => t,
        None => {
            let mut lo = Vec3::new(f64::INFINITY, f64::INFINITY, f64::INFINITY);
            let mut hi = lo * -1.0;
            for i in 0..=16 {
                for j in 0..=32 {
                    let p = s.point(i as f64 / 16.0, dom.at(j as f64 / 32.0));
                    (lo, hi) = (lo.min(p), hi.max(p));
                }
            }
            1e-6 * (hi - lo).norm()
        }
    };
    let (p, (su, sv)) = (o.degree, o.spans);
    let mut ku = Knots::uniform(p, 0.0, 1.0, su.max(1));
    let mut kv = Knots::uniform(p, dom.start, dom.end, sv.max(1));
    let mut samples = 0;
    for round in 1.. {
        let b = fit_on(s, &ku, &kv)?;
        let (cells, n) = cell_deviations(s, &b);
        samples += n;
        let (bu, bv) = (ku.breakpoints(), kv.breakpoints());
        let ncv = bv.len() - 1;
        let worst = cells.iter().fold((0.0_f64, 0.0, 0.0), |w, c| if c.0.is_nan() || c.0 > w.0 { *c } else { w });
        if worst.0.is_nan() {
            return Err(FitError::NotFinite(worst.1, worst.2));
        }
        if worst.0 <= tol {
            let report = FitReport {
                tolerance: tol,
                max_deviation: worst.0,
                at: (worst.1, worst.2),
                points: b.counts(),
                rounds: round,
                samples,
            };
            return Ok((b, report));
        }
        let mut split_u = vec![false; bu.len() - 1];
        let mut split_v = vec![false; ncv];
        for (k, c) in cells.iter().enumerate() {
            if c.0 > tol {
                split_u[k / ncv] = true;
                split_v[k % ncv] = true;
            }
        }
        let refine = |b: &[f64], split: &[bool]| -> Vec<f64> {
            let mut out = Vec::new();
            for i in 0..b.len() - 1 {
                if i > 0 {
                    out.push(b[i]);
                }
                if split[i] {
                    out.push(0.5 * (b[i] + b[i + 1]));
                }
            }
            out
        };
        let (iu, iv) = (refine(&bu, &split_u), refine(&bv, &split_v));
        if iu.len() + p + 1 > o.max_points || iv.len() + p + 1 > o.max_points {
            return Err(FitError::Tolerance {
                tolerance: tol,
                deviation: worst.0,
                u: worst.1,
                v: worst.2,
                cap: o.max_points,
            });
        }
        ku = Knots::clamped(p, 0.0, 1.0, &iu);
        kv = Knots::clamped(p, dom.start, dom.end, &iv);
    }
    unreachable!("the loop returns")
}

#[cfg(test)]
mod tests;
