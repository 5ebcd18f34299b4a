//! Tensor-product B-spline approximation of exact surfaces to a measured maximum deviation (for CAD exchange).
//!
//! A patch `X(u, v)` (any [`Surface`]: exact derivatives) is approximated by a clamped
//! B-spline surface `S(u, v) = Σᵢⱼ Nᵢ(u) Mⱼ(v) Pᵢⱼ` of degrees `(p, q)` (3 or more) on the
//! patch's own parameter rectangle `[0, 1] × [v₀, v₁]`:
//!
//! - **Knots where the patch is not smooth**: a line where the patch is only C0 (an N-sided
//!   fill's corners, or a kink the refinement finds) gets a knot of full multiplicity `q`;
//!   a line where it is only `Cᵏ` (where a fill's corner blends end, `k = 3`) a knot of
//!   multiplicity `q − k`. The spline space then holds the jump of the patch's
//!   `(k+1)`-th derivative, and the fit converges across the line at its full rate (a
//!   simple knot there: at `hᵏ⁺¹`, whatever the degree).
//! - **Fit**: interpolation at the Greville abscissae, separably — `X` sampled on
//!   `gᵘ × gᵛ`, then `Bᵤ C = X` per column and `Bᵥ Pᵀ = Cᵀ` per row, `B` the collocation
//!   matrices (non-singular by Schoenberg–Whitney, well conditioned at Greville points);
//!   in `u` the second and last-but-one rows are the cross derivative `X_u` at `u = 0`
//!   and `1` (clamped-end interpolation), so the edges carry the patch's tangent planes.
//!   The patch's boundary rows are interpolated at their Greville points too, so corners
//!   are exact and a periodic `v` closes (positions equal at the seam; the seam's tangent
//!   continuity is within the tolerance).
//! - **Measured maximum** (not a proved bound): the parametric deviation `|S(u, v) − X(u, v)|` bounds the distance of
//!   every point of `S` from the patch. It is sampled on a 7 × 7 grid in every knot-span
//!   cell, and from every discrete local maximum of those samples it is maximised locally
//!   (projected Newton steps on `ln|S − X|` with exact first and second derivatives of `S`
//!   and `X`, gradient steps where the model is not concave).
//!   The reported maximum is the largest value found; a bump narrower than the
//!   sample spacing can lie between the samples and be missed.
//! - **Refinement**: every knot span in `u` (and in `v`) that holds a cell above the
//!   tolerance is halved, and the fit is repeated, until the maximum is within the
//!   tolerance or the control net would exceed `max_points` per direction (an error).

mod basis;
mod curve;
mod edge;

pub use basis::Knots;
pub use curve::{BSplineCurve3, fit_curve};
pub use edge::{EdgeTolerance, normal_curvature};

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
    /// The fitted patch is closed in `v` (its `v = v₀` and `v = v₁` boundary rows are the
    /// same curve, the seam).
    pub periodic_v: bool,
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
        let mut out = vec![Vec3::ZERO; (du + 1) * (dv + 1)];
        for a in 0..=du {
            for b in 0..=dv {
                out[a * (dv + 1) + b] = self.sum((su, &nu[a]), (sv, &nv[b]));
            }
        }
        out
    }

    /// `Σᵣ Σ_c wuᵣ wv_c P_{su−p+r, sv−q+c}`: the net weighted by `u` weights on knot span
    /// `su` and `v` weights on `sv` (the values or derivatives of the basis functions there),
    /// summed over `v` inside and `u` outside, a zero `u` weight skipped. Every evaluation
    /// of the surface sums in this one order, so its results agree to the bit.
    fn sum(&self, (su, wu): (usize, &[f64]), (sv, wv): (usize, &[f64])) -> Vec3 {
        let (p, q, cols) = (self.u.degree, self.v.degree, self.v.count());
        let mut s = Vec3::ZERO;
        for (r, &a) in wu.iter().enumerate() {
            if a == 0.0 {
                continue;
            }
            let row = (su - p + r) * cols;
            let mut t = Vec3::ZERO;
            for (c, &x) in wv.iter().enumerate() {
                t += self.control[row + sv - q + c] * x;
            }
            s += t * a;
        }
        s
    }

    /// `S(u, v)` (the bits of `derivatives(u, v, 0, 0)[0]`, without allocating).
    pub fn point(&self, u: f64, v: f64) -> Vec3 {
        let mut nu: smallvec::SmallVec<[f64; 16]> = smallvec::smallvec![0.0; self.u.degree + 1];
        let mut nv: smallvec::SmallVec<[f64; 16]> = smallvec::smallvec![0.0; self.v.degree + 1];
        let su = self.u.values_into(u, &mut nu);
        let sv = self.v.values_into(v, &mut nv);
        self.sum((su, &nu), (sv, &nv))
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
#[derive(Clone, Debug)]
pub struct FitOptions {
    /// Absolute tolerance on the parametric deviation; `None`: `relative` × the patch's
    /// bounding-box diagonal.
    pub tolerance: Option<f64>,
    /// The tolerance relative to the patch's bounding-box diagonal when `tolerance` is
    /// `None` (default 1e-6).
    pub relative: f64,
    /// Degrees in `u` and in `v` (3, or 5 and more when C2 must survive: at degree ≥ 5 the
    /// `u` edges interpolate `X_uu` too).
    pub degrees: (usize, usize),
    /// Initial spans per direction.
    pub spans: (usize, usize),
    /// The largest control net per direction.
    pub max_points: usize,
    /// Values of `v` where the patch is only C0 (an N-sided fill's corners): knots of full
    /// multiplicity there, so the spline follows the kink exactly.
    pub v_breaks: Vec<f64>,
    /// Values of `v` where the patch is only `Cᵏ` (`(v, k)`, `0 < k < q`, `q` the `v`
    /// degree; e.g. where a fill's corner blends end, `k = 3`): knots of multiplicity
    /// `q − k` there (at least 1), so that the spline space holds the jump of the patch's
    /// `(k+1)`-th derivative and the fit converges at its full rate across the line
    /// instead of at `hᵏ⁺¹`.
    pub v_joins: Vec<(f64, usize)>,
    /// Interior `v` breakpoints to start from instead of `spans.1` uniform spans (faces
    /// that meet along a `u` edge start from the union of each other's, so that they end
    /// with the same `v` knots and the same edge).
    pub v_start: Vec<f64>,
    /// Interior `u` breakpoints to start from instead of `spans.0` uniform spans (the
    /// faces of a solid, which meet along edges in either direction).
    pub u_start: Vec<f64>,
    /// Tolerances for the `u = 0` edge (gap, normal angle, normal curvature across it
    /// against the patch's own), met first by refining the `v` knots (see [`EdgeTolerance`]
    /// and the module `edge`); `None`: the edge is only as good as the surface tolerance
    /// makes it.
    pub edge: Option<EdgeTolerance>,
}

impl Default for FitOptions {
    fn default() -> Self {
        FitOptions {
            tolerance: None,
            relative: 1e-6,
            degrees: (3, 3),
            spans: (4, 8),
            max_points: 400,
            v_breaks: Vec::new(),
            v_joins: Vec::new(),
            v_start: Vec::new(),
            u_start: Vec::new(),
            edge: None,
        }
    }
}

/// What a fit achieved.
#[derive(Clone, Debug, PartialEq)]
pub struct FitReport {
    /// The tolerance aimed at (absolute).
    pub tolerance: f64,
    /// The measured maximum parametric deviation (absolute).
    pub max_deviation: f64,
    /// Where it was found.
    pub at: (f64, f64),
    /// Control points per direction.
    pub points: (usize, usize),
    /// Fit–check–refine rounds.
    pub rounds: usize,
    /// Samples and local maximisations the measurement took.
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
    /// The patch is a single point: there is no face to fit.
    #[error("the patch is a single point (its bounding box has no extent): there is no face to fit")]
    Degenerate,
    /// The tolerance is not a positive finite number (given so, or the patch's size
    /// times the relative tolerance is not).
    #[error("the tolerance {0:e} is not a positive finite number")]
    BadTolerance(f64),
    /// A collocation matrix could not be factorised.
    #[error("the interpolation system is singular: {0}")]
    Singular(String),
}

/// Solves `B X = R` for the collocation matrix `B[k][j] = N_j^{(d_k)}(x_k)` (rows of values,
/// `d_k = 0`, or of derivatives) and right-hand sides `R` (rows `k`, `m` columns of `Vec3`).
fn interpolate(k: &Knots, xs: &[(f64, usize)], rhs: &[Vec<Vec3>]) -> Result<Vec<Vec<Vec3>>, FitError> {
    let n = k.count();
    let m = rhs[0].len();
    let mut b = faer::Mat::<f64>::from_fn(n, n, |_, _| 0.0);
    for (row, &(x, order)) in xs.iter().enumerate() {
        let (span, d) = k.basis(x, order);
        for (r, &w) in d[order].iter().enumerate() {
            b[(row, span - k.degree + r)] = w;
        }
    }
    let lu = crate::lanes::after(b.partial_piv_lu());
    // P B = L U: the right-hand sides permuted (`y_i = r_{P(i)}`, row-major, 3m wide), then
    // the two substitutions over each factor row's nonzeros alone. The collocation matrix
    // is banded (p + 1 entries a row), and so nearly are its factors: n · band · 3m
    // operations instead of the dense solve's n² · 3m.
    let (l, u) = (lu.L(), lu.U());
    let (fwd, _) = lu.P().arrays();
    let w = 3 * m;
    let mut y: Vec<f64> = Vec::with_capacity(n * w);
    for &i in fwd {
        y.extend(rhs[i].iter().flat_map(|p| [p.x, p.y, p.z]));
    }
    let axpy = |y: &mut [f64], i: usize, j: usize, f: f64| {
        let (a, b) = y.split_at_mut(i.max(j) * w);
        let (dst, src) = if i < j { (&mut a[i * w..][..w], &b[..w]) } else { (&mut b[..w], &a[j * w..][..w]) };
        for (d, s) in dst.iter_mut().zip(src) {
            *d -= f * s;
        }
    };
    for i in 0..n {
        for j in 0..i {
            let f = l[(i, j)];
            if f != 0.0 {
                axpy(&mut y, i, j, f);
            }
        }
    }
    for i in (0..n).rev() {
        for j in i + 1..n {
            let f = u[(i, j)];
            if f != 0.0 {
                axpy(&mut y, i, j, f);
            }
        }
        let d = u[(i, i)];
        y[i * w..][..w].iter_mut().for_each(|x| *x /= d);
    }
    let out: Vec<Vec<Vec3>> =
        (0..n).map(|i| y[i * w..(i + 1) * w].chunks_exact(3).map(|c| Vec3::new(c[0], c[1], c[2])).collect()).collect();
    if out.iter().flatten().any(|p| !p.is_finite()) {
        return Err(FitError::Singular(format!("{n} × {n} collocation system")));
    }
    Ok(out)
}

/// Interpolates `s` at the Greville points of `(ku, kv)`.
fn fit_on(s: &dyn Surface, ku: &Knots, kv: &Knots) -> Result<BSplineSurface, FitError> {
    let (gu, gv) = (ku.greville(), kv.greville());
    let g = s.grid_values(&gu, &gv);
    let mut samples: Vec<Vec<Vec3>> = g.chunks(gv.len()).map(<[Vec3]>::to_vec).collect();
    // in u, the rows next to the ends interpolate the cross derivative X_u at u = 0 and 1
    // instead of X at their Greville points (clamped-end conditions): the face's edge
    // tangent plane is then the interpolant of the patch's, the same for every face that
    // meets it along an edge with the same v knots (see `fit_group`)
    let nu = gu.len();
    let mut rows: Vec<(f64, usize)> = gu.iter().map(|&u| (u, 0)).collect();
    if nu >= 4 {
        // degree ≥ 5: the next rows interpolate X_uu too, so that faces meeting along an
        // edge share their curvature across it as well (C2 / G2 survives the export); one
        // evaluation of the ends then gives both (`grid2`'s X_u is `grid`'s, the same
        // products)
        let second = ku.degree >= 5 && nu >= 6;
        let ends: Vec<[Vec3; 2]> = if second {
            s.grid2(&[0.0, 1.0], &gv).into_iter().map(|x| [x[1], x[3]]).collect()
        } else {
            s.grid(&[0.0, 1.0], &gv).into_iter().map(|x| [x[1], Vec3::ZERO]).collect()
        };
        let nv = gv.len();
        rows[1] = (0.0, 1);
        rows[nu - 2] = (1.0, 1);
        samples[1] = ends[..nv].iter().map(|x| x[0]).collect();
        samples[nu - 2] = ends[nv..].iter().map(|x| x[0]).collect();
        if second {
            rows[2] = (0.0, 2);
            rows[nu - 3] = (1.0, 2);
            samples[2] = ends[..nv].iter().map(|x| x[1]).collect();
            samples[nu - 3] = ends[nv..].iter().map(|x| x[1]).collect();
        }
    }
    for (i, row) in samples.iter().enumerate() {
        if let Some(j) = row.iter().position(|p| !p.is_finite()) {
            return Err(FitError::NotFinite(rows[i].0, gv[j]));
        }
    }
    // along u for every v column, then along v for every u row
    let c = interpolate(ku, &rows, &samples)?;
    let ct: Vec<Vec<Vec3>> = (0..gv.len()).map(|j| c.iter().map(|row| row[j]).collect()).collect();
    let vrows: Vec<(f64, usize)> = gv.iter().map(|&v| (v, 0)).collect();
    let pt = interpolate(kv, &vrows, &ct)?;
    let (nu, nv) = (ku.count(), kv.count());
    let control = (0..nu * nv).map(|k| pt[k % nv][k / nv]).collect();
    Ok(BSplineSurface { u: ku.clone(), v: kv.clone(), control, periodic_v: s.v_domain().periodic })
}

/// Samples per knot span and direction (the span's ends included).
const K: usize = 7;

/// `S` on the grid `us × vs` (row-major in `u`), separably: each `u` row of the net is
/// first reduced to a curve's control points, then evaluated at every `v`.
fn spline_grid(b: &BSplineSurface, us: &[f64], vs: &[f64]) -> Vec<Vec3> {
    let (p, q, nv) = (b.u.degree, b.v.degree, b.v.count());
    // the v basis of every column, q + 1 values each
    let mut vw = vec![0.0; vs.len() * (q + 1)];
    let vspan: Vec<usize> = vs.iter().zip(vw.chunks_mut(q + 1)).map(|(&v, w)| b.v.values_into(v, w)).collect();
    let mut out = Vec::with_capacity(us.len() * vs.len());
    // the row's components apart, and sums in named locals: with `Vec3` accumulators the
    // loops kept them in memory (the same sums in the same order, so the same numbers)
    let mut row = vec![[0.0f64; 3]; nv];
    let mut uw = vec![0.0; p + 1];
    for &u in us {
        let su = b.u.values_into(u, &mut uw);
        row.fill([0.0; 3]);
        for (r, &w) in uw.iter().enumerate() {
            let net = &b.control[(su - p + r) * nv..][..nv];
            for (x, c) in row.iter_mut().zip(net) {
                x[0] += c.x * w;
                x[1] += c.y * w;
                x[2] += c.z * w;
            }
        }
        // a trusted-length iterator: no capacity check per point, no zeroing first
        out.extend(vspan.iter().zip(vw.chunks_exact(q + 1)).map(|(&sv, w)| {
            let (mut x, mut y, mut z) = (0.0, 0.0, 0.0);
            for (a, &wc) in row[sv - q..=sv].iter().zip(w) {
                x += a[0] * wc;
                y += a[1] * wc;
                z += a[2] * wc;
            }
            Vec3::new(x, y, z)
        }));
    }
    out
}

/// The largest deviation in each knot-span cell (row-major in `u` spans) with its place,
/// and the number of evaluations. The deviation is sampled on a `K × K` grid per cell
/// (the exact patch evaluated as grids of many spans, so solvers share their per-column
/// work); from the discrete local maxima of the samples, largest first, it is then
/// maximised locally until no remaining peak could overtake the largest maximum found,
/// were it to gain three times as much over its sample as any ascent so far (plus 10 %). (The error of
/// a spline fit to a smooth patch is a low-degree bump per cell, sampled at sevenths of a
/// span: ascents gain a few per cent. This is where the measurement trusts the sampling (no bound is proved);
/// the tests check it against dense random points.) While some sample is above `tol` the
/// fit is refined anyway and the local search is skipped.
fn cell_deviations(s: &dyn Surface, b: &BSplineSurface, tol: f64) -> (Vec<(f64, f64, f64)>, usize) {
    let (bu, bv) = (b.u.breakpoints(), b.v.breakpoints());
    let (ncu, ncv) = (bu.len() - 1, bv.len() - 1);
    let ticks = |b: &[f64]| -> Vec<f64> {
        let mut t = Vec::with_capacity((b.len() - 1) * (K - 1) + 1);
        for w in b.windows(2) {
            for a in 0..K - 1 {
                t.push(w[0] + (w[1] - w[0]) * a as f64 / (K - 1) as f64);
            }
        }
        t.push(b[b.len() - 1]);
        t
    };
    let vs = ticks(&bv);
    let nvs = vs.len();
    // dev[i] holds the deviations of u span i on its K × nvs grid; the exact grid is
    // evaluated for many spans at once (a solver's per-column work is then shared), in
    // blocks of about 1e5 points
    let mut dev: Vec<Vec<f64>> = Vec::with_capacity(ncu);
    let per_block = (100_000 / (K * nvs)).max(1);
    for first in (0..ncu).step_by(per_block) {
        crate::cancel::checkpoint();
        let spans = first..(first + per_block).min(ncu);
        let bu = &bu;
        let us: Vec<f64> = spans
            .clone()
            .flat_map(|i| (0..K).map(move |a| bu[i] + (bu[i + 1] - bu[i]) * a as f64 / (K - 1) as f64))
            .collect();
        let exact = s.grid_values(&us, &vs);
        let spline = spline_grid(b, &us, &vs);
        let d: Vec<f64> = exact.iter().zip(&spline).map(|(x, y)| (*x - *y).scaled_norm()).collect();
        for chunk in d.chunks(K * nvs) {
            dev.push(chunk.to_vec());
        }
    }
    let mut evals = ncu * K * nvs;
    let at = |i: usize, a: usize, col: usize| (bu[i] + (bu[i + 1] - bu[i]) * a as f64 / (K - 1) as f64, vs[col]);
    let mut out = vec![(0.0_f64, 0.0, 0.0); ncu * ncv];
    let mut top = 0.0_f64;
    for i in 0..ncu {
        for j in 0..ncv {
            let mut best = (0.0_f64, bu[i], bv[j]);
            for a in 0..K {
                for c in 0..K {
                    let x = dev[i][a * nvs + j * (K - 1) + c];
                    if x.is_nan() || x > best.0 {
                        let (u, v) = at(i, a, j * (K - 1) + c);
                        best = (x, u, v);
                    }
                }
            }
            top = crate::num::max_nan(top, best.0);
            out[i * ncv + j] = best;
        }
    }
    if top.is_nan() || top > tol {
        return (out, evals); // refined anyway: the local search waits for a candidate
    }
    // discrete local maxima of the samples within a factor 2 of the largest, largest first
    let mut peaks: Vec<(f64, usize, usize, usize)> = Vec::new();
    for i in 0..ncu {
        for j in 0..ncv {
            if out[i * ncv + j].0 < 0.5 * top {
                continue;
            }
            let d = |a: usize, c: usize| dev[i][a * nvs + j * (K - 1) + c];
            for a in 0..K {
                for c in 0..K {
                    let x = d(a, c);
                    let peak = x >= 0.5 * top
                        && (a.saturating_sub(1)..(a + 2).min(K))
                            .all(|a2| (c.saturating_sub(1)..(c + 2).min(K)).all(|c2| d(a2, c2) <= x));
                    if peak {
                        peaks.push((x, i, j, a * nvs + j * (K - 1) + c));
                    }
                }
            }
        }
    }
    peaks.sort_by(|x, y| y.0.total_cmp(&x.0));
    // ascend from each until no remaining peak could overtake the best: three times the
    // largest relative gain (ascended / sampled − 1) seen so far plus 10 %, applied to a
    // peak's sample, stays below the best found (at least 64 ascents)
    let (mut best, mut gain) = (top, 1.0_f64);
    for (k, &(x, i, j, idx)) in peaks.iter().enumerate() {
        if k >= 64 && x * (1.0 + 3.0 * (gain - 1.0) + 0.1) < best {
            break;
        }
        let (a, col) = (idx / nvs, idx % nvs);
        let (u, v) = at(i, a, col);
        let (m, u, v, n) = local_max(s, b, u, v, (bu[i], bu[i + 1]), (bv[j], bv[j + 1]));
        evals += n;
        if m.is_nan() {
            out[i * ncv + j] = (m, u, v);
            return (out, evals);
        }
        gain = gain.max(m / x);
        best = best.max(m);
        let cell = &mut out[i * ncv + j];
        if m > cell.0 {
            *cell = (m, u, v);
        }
    }
    (out, evals)
}

/// Local maximisation of `|S − X|` within a cell from `(u, v)`, with exact first and second
/// derivatives of `S` and `X`: Newton's method on `ψ = ln|e| = ½ ln 2φ`, `φ = ½|e|²`,
/// `e = S − X`,
///
/// `∇φ = (e·e_u, e·e_v)`, `∇²φ = [e_u·e_u + e·e_uu, e_u·e_v + e·e_uv; ·, e_v·e_v + e·e_vv]`,
/// `∇ψ = ∇φ / 2φ`, `∇²ψ = ∇²φ / 2φ − ∇φ ∇φᵀ / 2φ²`,
///
/// with the step `δ = −(∇²ψ)⁻¹∇ψ` where `∇²ψ` is negative definite (a wider region than
/// where `∇²φ` is; a Gaussian bump's `ψ` is quadratic: one step), projected on the cell: a
/// coordinate at a side of the cell whose gradient points out of it is held there and the
/// other one takes the one-dimensional step. `t δ` grows `ψ`, that is `|e|` relative to
/// itself, by `P t (2 − t)` in the quadratic model, `P = ½ ∇ψ·δ`. The maximisation stops
/// where `|e|` would grow (or grew) by less than 5e-10 of itself or than its round-off,
/// `16 ε |X| / |e|` (a deviation of 1e-10 on a patch of size 1 is known to ~1e-5 of
/// itself only). A full step that does not grow `|e|` is halved, at most three times;
/// where `∇²ψ` is not negative definite, or the halved steps fail too (the model is wrong
/// there: a kink at the cell's side), a gradient step is taken instead, halved until `|e|`
/// grows. Everything is divided by `|e|` first (a scaled norm), so a patch at 1e-160 or
/// 1e160 is measured as one at 1 (no square underflows or overflows). Returns the
/// maximum, its place and the evaluations made.
fn local_max(
    s: &dyn Surface,
    b: &BSplineSurface,
    u0: f64,
    v0: f64,
    ru: (f64, f64),
    rv: (f64, f64),
) -> (f64, f64, f64, usize) {
    // e and its derivatives [e, e_u, e_v, e_uu, e_uv, e_vv] at (u, v), and |X|: the patch
    // through its scattered-point evaluation (batches of one point: no row of cardinal
    // functions computed and cached for a `u` that the maximisation never visits again)
    let jet = |u: f64, v: f64| {
        let mut x = [[Vec3::ZERO; 6]];
        s.seconds_at(&[[u, v]], &mut x);
        // `ds` by index a·3 + b of ∂ᵃ_u ∂ᵇ_v
        let ds = b.derivatives(u, v, 2, 2);
        let x = x[0];
        let e = [ds[0] - x[0], ds[3] - x[1], ds[1] - x[2], ds[6] - x[3], ds[4] - x[4], ds[2] - x[5]];
        (e, x[0].scaled_norm())
    };
    let point = |u: f64, v: f64| {
        let mut x = [Vec3::ZERO];
        s.points_at(&[[u, v]], &mut x);
        (b.point(u, v) - x[0]).scaled_norm()
    };
    // the relative growth below which |e| is taken as converged
    let floor = |f: f64, x: f64| crate::num::max_nan(5e-10, 16.0 * f64::EPSILON * (x / f));
    let (wu, wv) = (ru.1 - ru.0, rv.1 - rv.0);
    let (mut u, mut v) = (u0, v0);
    let (mut e, mut xn) = jet(u, v);
    let mut evals = 1;
    let mut fv = e[0].scaled_norm();
    let mut step = 0.25 * wu.max(wv);
    for _ in 0..30 {
        let n = fv;
        if !(n > 0.0 && n.is_finite()) {
            break;
        }
        let tol = floor(fv, xn);
        let d = e.map(|x| x / n);
        let g = [d[0].dot(d[1]), d[0].dot(d[2])];
        // the Hessian of ψ (with |d| = 1): ∇²φ − 2 ∇φ ∇φᵀ
        let h = [
            d[1].dot(d[1]) + d[0].dot(d[3]) - 2.0 * g[0] * g[0],
            d[1].dot(d[2]) + d[0].dot(d[4]) - 2.0 * g[0] * g[1],
            d[2].dot(d[2]) + d[0].dot(d[5]) - 2.0 * g[1] * g[1],
        ];
        // the coordinates held at a side of the cell (the gradient pointing out of it)
        let held = |x: f64, (lo, hi): (f64, f64), gx: f64| (x <= lo && gx < 0.0) || (x >= hi && gx > 0.0);
        let newton = match (held(u, ru, g[0]), held(v, rv, g[1])) {
            (true, true) => Some([0.0, 0.0]),
            (false, false) => {
                let det = h[0] * h[2] - h[1] * h[1];
                (h[0] < 0.0 && det > 0.0)
                    .then(|| [-(h[2] * g[0] - h[1] * g[1]) / det, -(h[0] * g[1] - h[1] * g[0]) / det])
            }
            (false, true) => (h[0] < 0.0).then(|| [-g[0] / h[0], 0.0]),
            (true, false) => (h[2] < 0.0).then(|| [0.0, -g[1] / h[2]]),
        };
        // the next point and whether |e| grew there by more than `tol` of itself
        let mut next: Option<(f64, f64, bool)> = None;
        if let Some(dx) = newton.filter(|dx| dx.iter().all(|x| x.is_finite())) {
            // P: the growth of ψ the full step promises (∇ψ = g: the scaled quantities are
            // already divided by |e|)
            let p = 0.5 * (g[0] * dx[0] + g[1] * dx[1]);
            if p.partial_cmp(&tol) != Some(std::cmp::Ordering::Greater) {
                break; // converged (or a corner of the cell that the gradient leaves)
            }
            let (nu, nv) = ((u + dx[0]).clamp(ru.0, ru.1), (v + dx[1]).clamp(rv.0, rv.1));
            let (en, xnew) = jet(nu, nv);
            evals += 1;
            let fnew = en[0].scaled_norm();
            if fnew > fv {
                let moved = fnew - fv > tol * fnew;
                (u, v, e, xn, fv) = (nu, nv, en, xnew, fnew);
                if !moved {
                    break;
                }
                continue;
            }
            let mut t = 0.5;
            while p * t * (2.0 - t) > tol {
                if t < 0.1 {
                    break;
                }
                let (nu, nv) = ((u + t * dx[0]).clamp(ru.0, ru.1), (v + t * dx[1]).clamp(rv.0, rv.1));
                let fnew = point(nu, nv);
                evals += 1;
                if fnew > fv {
                    next = Some((nu, nv, fnew - fv > tol * fnew));
                    break;
                }
                t *= 0.5;
            }
            if next.is_none() && p * t * (2.0 - t) <= tol {
                break; // what is left to gain is below the stopping rule
            }
        }
        if next.is_none() {
            // a gradient step: only the gradient's direction is used, scaled to its
            // largest component so that its square neither underflows nor overflows
            let m = crate::num::max_nan(g[0].abs(), g[1].abs());
            if !(m > 0.0 && m.is_finite()) {
                break;
            }
            let (gu, gv) = (g[0] / m, g[1] / m);
            let gn = (gu * gu * wu * wu + gv * gv * wv * wv).sqrt();
            if gn.is_nan() || gn == 0.0 {
                break;
            }
            while step > 1e-6 * wu {
                let nu = (u + step * gu * wu * wu / gn).clamp(ru.0, ru.1);
                let nv = (v + step * gv * wv * wv / gn).clamp(rv.0, rv.1);
                let fnew = point(nu, nv);
                evals += 1;
                if fnew > fv {
                    next = Some((nu, nv, fnew - fv > tol * fnew));
                    step *= 1.5;
                    break;
                }
                step *= 0.5;
            }
        }
        let Some((nu, nv, moved)) = next else { break };
        (u, v) = (nu, nv);
        (e, xn) = jet(u, v);
        evals += 1;
        fv = e[0].scaled_norm();
        if !moved {
            break;
        }
    }
    (fv, u, v, evals)
}

/// Knots of degree `p` on `[a, b]` with the distinct interior breakpoints `interior`;
/// those in `c0` (C0 lines of the patch) get multiplicity `p`.
fn knots_with_breaks(p: usize, a: f64, b: f64, interior: &[f64], c0: &[f64], joins: &[(f64, usize)]) -> Knots {
    let mut k = Vec::with_capacity(interior.len() + c0.len() * p);
    for &x in interior {
        let m =
            if c0.contains(&x) { p } else { joins.iter().find(|j| j.0 == x).map_or(1, |j| join_multiplicity(p, j.1)) };
        k.extend(std::iter::repeat_n(x, m));
    }
    Knots::clamped(p, a, b, &k)
}

/// The multiplicity of a knot of degree `p` where the patch is `Cᵏ`: `p − k`, at least 1.
fn join_multiplicity(p: usize, k: usize) -> usize {
    p.saturating_sub(k).max(1)
}

/// Control points of degree `p` on `interior` distinct breakpoints, of which `c0` are of
/// full multiplicity and `joins` (not also in `c0`) of [`join_multiplicity`].
fn control_count(p: usize, interior: usize, c0: &[f64], joins: &[(f64, usize)]) -> usize {
    let extra: usize = joins.iter().filter(|j| !c0.contains(&j.0)).map(|j| join_multiplicity(p, j.1) - 1).sum();
    interior + c0.len() * (p - 1) + extra + p + 1
}

/// The spline's top derivatives, `∂ᵖS/∂uᵖ` and `∂^qS/∂v^q`, which are constant across a
/// span in their direction: the weights of the basis functions' top derivative are
/// computed once per breakpoint span and direction (a round's refinement asks for them
/// from every cell above the tolerance), and summed with the other direction's values at
/// the asked parameter as [`BSplineSurface::derivatives`] sums them.
struct TopDerivatives<'a> {
    b: &'a BSplineSurface,
    /// Per direction and breakpoint span.
    weights: [Vec<Option<SpanWeights>>; 2],
}

/// A knot span's index and its basis functions' weights.
type SpanWeights = (usize, Vec<f64>);

impl<'a> TopDerivatives<'a> {
    fn new(b: &'a BSplineSurface, bk: &[Vec<f64>; 2]) -> Self {
        TopDerivatives { b, weights: [vec![None; bk[0].len() - 1], vec![None; bk[1].len() - 1]] }
    }

    /// The other direction's basis values at `w` (for [`Self::at`]).
    fn other(&self, dir: usize, w: f64) -> SpanWeights {
        let (span, mut d) = if dir == 0 { self.b.v.basis(w, 0) } else { self.b.u.basis(w, 0) };
        (span, d.swap_remove(0))
    }

    /// `∂ᵖS/∂uᵖ` (`dir` 0) on breakpoint span `k` (through its point `mid`) at `v = w`, or
    /// `∂^qS/∂v^q` on span `k` at `u = w`, with `(so, wo)` [`Self::other`] at `w`.
    fn at(&mut self, dir: usize, k: usize, mid: f64, (so, wo): (usize, &[f64])) -> Vec3 {
        let b = self.b;
        let top_knots = if dir == 0 { &b.u } else { &b.v };
        let (st, top) = self.weights[dir][k].get_or_insert_with(|| {
            let (span, mut d) = top_knots.basis(mid, top_knots.degree);
            (span, d.pop().expect("the top order"))
        });
        let (st, top) = (*st, &top[..]);
        if dir == 0 { b.sum((st, top), (so, wo)) } else { b.sum((so, wo), (st, top)) }
    }
}

/// One direction's refinement weight for span `i` of `bk` (through the other parameter
/// `w`): `hᵖ` times the largest jump of the spline's `p`-th derivative across the span's
/// interior knots that are not C0 lines. The jump is `≈ h |∂ᵖ⁺¹X|`, so this estimates that
/// direction's interpolation error `O(hᵖ⁺¹ |∂ᵖ⁺¹X|)` from the fit itself. Infinite when no
/// such knot exists (a single span must be split to learn anything).
fn direction_weight(tops: &mut TopDerivatives, dir: usize, bk: &[f64], c0: &[f64], i: usize, w: f64) -> f64 {
    let (so, wo) = tops.other(dir, w);
    let mut d = |k: usize| tops.at(dir, k, 0.5 * (bk[k] + bk[k + 1]), (so, &wo));
    let here = d(i);
    let mut jump = f64::NEG_INFINITY;
    if i > 0 && !c0.contains(&bk[i]) {
        jump = crate::num::max_nan(jump, (here - d(i - 1)).norm());
    }
    if i + 2 < bk.len() && !c0.contains(&bk[i + 1]) {
        jump = crate::num::max_nan(jump, (d(i + 1) - here).norm());
    }
    if jump == f64::NEG_INFINITY {
        return f64::INFINITY;
    }
    let p = if dir == 0 { tops.b.u.degree } else { tops.b.v.degree };
    jump * (bk[i + 1] - bk[i]).powi(p as i32)
}

/// A C0 line of `s` across direction `dir` inside `(a, b)`, on the line through the other
/// parameter `w`: bisection keeping the half over which the exact first derivative
/// changes more. A kink keeps its jump down to the last representable interval; a smooth
/// patch's change there is ~1e-16 of its second derivative (and after three halvings
/// already ~1/8 of the first: the search stops there). Returns the place.
fn find_kink(s: &dyn Surface, dir: usize, w: f64, a: f64, b: f64) -> Option<f64> {
    let d = |x: f64| if dir == 0 { s.derivatives(x, w, 1, 0)[1] } else { s.derivatives(w, x, 0, 1)[1] };
    let (mut a, mut b) = (a, b);
    let (mut da, mut db) = (d(a), d(b));
    let first = (db - da).norm();
    for step in 0..80 {
        // a smooth patch's change has shrunk ~8-fold after three halvings, a kink's not
        if step == 3 && (db - da).norm() < 0.5 * first {
            return None;
        }
        let m = 0.5 * (a + b);
        if m <= a || m >= b {
            break;
        }
        let dm = d(m);
        if (dm - da).norm() >= (db - dm).norm() {
            (b, db) = (m, dm);
        } else {
            (a, da) = (m, dm);
        }
    }
    let jump = (db - da).norm();
    let scale = da.norm() + db.norm();
    (jump.is_finite() && jump > 1e-6 * scale).then_some(0.5 * (a + b))
}

/// One parameter direction of a fit: its interval, distinct interior breakpoints, the C0
/// lines among them, and the spans already searched for a kink.
struct Axis {
    lo: f64,
    hi: f64,
    interior: Vec<f64>,
    c0: Vec<f64>,
    /// Lines where the patch is `Cᵏ` only (`(place, k)`, among `interior`).
    joins: Vec<(f64, usize)>,
    searched: Vec<(f64, f64)>,
    first_span: f64,
}

impl Axis {
    fn new(lo: f64, hi: f64, spans: usize, c0: &[f64], joins: &[(f64, usize)]) -> Axis {
        let even =
            |a: f64, b: f64, n: usize| -> Vec<f64> { (1..n).map(|i| a + (b - a) * i as f64 / n as f64).collect() };
        let c0: Vec<f64> = c0.iter().copied().filter(|&x| x > lo && x < hi).collect();
        let mut cuts = vec![lo];
        cuts.extend(&c0);
        cuts.push(hi);
        let per = spans.max(1).div_ceil(cuts.len() - 1).max(1);
        let mut interior = Vec::new();
        for (k, w) in cuts.windows(2).enumerate() {
            if k > 0 {
                interior.push(w[0]);
            }
            interior.extend(even(w[0], w[1], per));
        }
        let joins: Vec<(f64, usize)> =
            joins.iter().copied().filter(|&(x, _)| x > lo && x < hi && !c0.contains(&x)).collect();
        interior.extend(joins.iter().map(|j| j.0));
        interior.sort_by(f64::total_cmp);
        interior.dedup();
        Axis { lo, hi, interior, c0, joins, searched: Vec::new(), first_span: (hi - lo) / (spans.max(1) as f64) }
    }

    fn knots(&self, p: usize) -> Knots {
        knots_with_breaks(p, self.lo, self.hi, &self.interior, &self.c0, &self.joins)
    }

    /// The lines across which the patch's `p`-th derivative may jump: C0 lines and joins.
    fn rough(&self) -> Vec<f64> {
        self.c0.iter().copied().chain(self.joins.iter().map(|j| j.0)).collect()
    }

    /// Adds a C0 line at `x` (snapped to an existing breakpoint within 1e-12 of the span).
    fn add_c0(&mut self, x: f64) {
        let eps = 1e-12 * (self.hi - self.lo);
        if x - self.lo <= eps || self.hi - x <= eps {
            return; // the patch's own edge (a corner at the seam of a closed patch)
        }
        if let Some(&y) = self.interior.iter().find(|&&y| (y - x).abs() <= eps) {
            if !self.c0.contains(&y) {
                self.c0.push(y);
            }
            return;
        }
        let at = self.interior.partition_point(|&y| y < x);
        self.interior.insert(at, x);
        self.c0.push(x);
    }

    /// Control points with `interior` as breakpoints.
    fn count(&self, interior: &[f64], p: usize) -> usize {
        control_count(p, interior.len(), &self.c0, &self.joins)
    }
}

/// Halves the marked spans of the breakpoints `b` (ends included); returns the interior.
fn refine(b: &[f64], split: &[bool]) -> Vec<f64> {
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
}

/// Fits `s` on its parameter rectangle (`u ∈ [0, 1]`, `v` its domain) to the tolerance.
///
/// Each round fits, measures the deviation, and then for every cell above the tolerance: searches its
/// spans for a C0 line of the patch once they are half the first spans or less
/// ([`find_kink`]; a found line gets a knot of full multiplicity), and halves the spans in
/// the directions whose error estimate ([`direction_weight`]) is at least a quarter of
/// the larger.
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
            let size = (hi - lo).scaled_norm();
            if size == 0.0 {
                return Err(FitError::Degenerate);
            }
            o.relative * size
        }
    };
    if !(tol.is_finite() && tol > 0.0) {
        return Err(FitError::BadTolerance(tol));
    }
    let (p, q) = o.degrees;
    let mut axes =
        [Axis::new(0.0, 1.0, o.spans.0, &[], &[]), Axis::new(dom.start, dom.end, o.spans.1, &o.v_breaks, &o.v_joins)];
    for (ax, start) in axes.iter_mut().zip([&o.u_start, &o.v_start]) {
        if start.is_empty() {
            continue;
        }
        let mut iv: Vec<f64> = start.iter().copied().filter(|&x| x > ax.lo && x < ax.hi).collect();
        iv.extend(&ax.c0);
        iv.extend(ax.joins.iter().map(|j| j.0));
        iv.sort_by(f64::total_cmp);
        iv.dedup();
        ax.interior = iv;
    }
    if let Some(t) = &o.edge {
        let ax = &mut axes[1];
        ax.interior =
            edge::edge_breakpoints(s, q, (ax.lo, ax.hi), ax.interior.clone(), (&ax.c0, &ax.joins), t, o.max_points)?;
    }
    let mut samples = 0;
    for round in 1.. {
        let (ku, kv) = (axes[0].knots(p), axes[1].knots(q));
        let b = fit_on(s, &ku, &kv)?;
        let (cells, n) = cell_deviations(s, &b, tol);
        samples += n;
        let bk = [ku.breakpoints(), kv.breakpoints()];
        let ncv = bk[1].len() - 1;
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
        let mut split = [vec![false; bk[0].len() - 1], vec![false; ncv]];
        let mut tops = TopDerivatives::new(&b, &bk);
        for (k, c) in cells.iter().enumerate() {
            if c.0 <= tol {
                continue;
            }
            let ij = [k / ncv, k % ncv];
            let at = [c.1, c.2];
            for dir in 0..2 {
                let (lo, hi) = (bk[dir][ij[dir]], bk[dir][ij[dir] + 1]);
                let ax = &mut axes[dir];
                if hi - lo <= ax.first_span / 2.0 && !ax.searched.contains(&(lo, hi)) {
                    ax.searched.push((lo, hi));
                    if let Some(x) = find_kink(s, dir, at[1 - dir], lo, hi) {
                        ax.add_c0(x);
                    }
                }
            }
            let wu = direction_weight(&mut tops, 0, &bk[0], &axes[0].rough(), ij[0], c.2);
            let wv = direction_weight(&mut tops, 1, &bk[1], &axes[1].rough(), ij[1], c.1);
            let m = crate::num::max_nan(wu, wv);
            let (a, bb) = if m.is_nan() { (true, true) } else { (wu >= 0.25 * m, wv >= 0.25 * m) };
            // halved (more pieces at once, from the h^(p+1) rate, measured slower: the
            // estimate overshoots while kinks are still being found)
            split[0][ij[0]] |= a;
            split[1][ij[1]] |= bb;
        }
        let next: Vec<Vec<f64>> = (0..2)
            .map(|d| {
                // breakpoints of the axis as it now stands (kinks included), halved where marked
                let mut b = vec![axes[d].lo];
                b.extend(&axes[d].interior);
                b.push(axes[d].hi);
                let marks: Vec<bool> = b
                    .windows(2)
                    .map(|w| (0..bk[d].len() - 1).any(|i| split[d][i] && bk[d][i] <= w[0] && w[1] <= bk[d][i + 1]))
                    .collect();
                refine(&b, &marks)
            })
            .collect();
        if axes[0].count(&next[0], p) > o.max_points || axes[1].count(&next[1], q) > o.max_points {
            return Err(FitError::Tolerance {
                tolerance: tol,
                deviation: worst.0,
                u: worst.1,
                v: worst.2,
                cap: o.max_points,
            });
        }
        for (ax, n) in axes.iter_mut().zip(next) {
            ax.interior = n;
        }
    }
    unreachable!("the loop returns")
}

#[cfg(test)]
mod tests;
