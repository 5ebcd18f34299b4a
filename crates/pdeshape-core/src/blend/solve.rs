//! The static blend: exact separable solver and collocation least squares.

use super::basis::{BasisFn, Decomposition, decompose};
use super::{BlendError, Operator, bubbles};
use crate::Vec3;
use crate::linalg::least_squares;
use crate::ode::{Cardinal, CondSpec, ExpSpace};
use crate::patch::{Condition, Surface, VDomain};
use faer::Mat;
use rayon::prelude::*;
use std::sync::Arc;

/// Which solver a static blend uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Solver {
    /// The exact separable solver when every basis function is an eigenfunction of `∂v²`,
    /// collocation otherwise.
    Auto,
    /// The exact separable solver (an error when it does not apply).
    Exact,
    /// The paper's collocation least squares.
    Collocation,
}

impl Solver {
    /// `"auto"`, `"exact"`, `"collocation"`.
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "auto" => Some(Solver::Auto),
            "exact" => Some(Solver::Exact),
            "collocation" => Some(Solver::Collocation),
            _ => None,
        }
    }
}

/// Options of [`StaticBlend::new`].
#[derive(Clone, Debug)]
pub struct BlendOptions {
    /// Solver choice.
    pub solver: Solver,
    /// Number `B` of bubble functions per basis function (collocation).
    pub bubbles: usize,
    /// Collocation grid `(L, Q)`: interior `u` points and `v` points; `None` picks
    /// `L = 2B + 2r`, `Q = max(24, 4J + 8)` (oversampled).
    pub collocation: Option<(usize, usize)>,
    /// An explicit boundary basis, or `None` to extract one automatically.
    pub basis: Option<Vec<BasisFn>>,
    /// Caps; the solver checks the memory of its dense matrices against `limits.memory`
    /// before allocating them.
    pub limits: crate::limits::Limits,
}

/// Bytes of the dense least-squares solve of an `rows × cols` system: the matrix, the
/// copy the singular values (condition number) work on, the pivoted QR's copy, and the
/// right-hand sides and residuals (`rhs` columns each).
pub fn least_squares_bytes(rows: usize, cols: usize, rhs: usize) -> u128 {
    8 * rows as u128 * (3 * cols as u128 + 2 * rhs as u128)
}

impl Default for BlendOptions {
    fn default() -> Self {
        BlendOptions {
            solver: Solver::Auto,
            bubbles: 8,
            collocation: None,
            basis: None,
            limits: crate::limits::Limits::default(),
        }
    }
}

/// How one `U_j(u)` is represented.
#[derive(Clone, Debug)]
enum Profile {
    /// `U = Σ_c ℓ_c(u) w_c` with the cardinal functions of the mode's ODE.
    Exact { card: Arc<Cardinal>, w: Vec<f64> },
    /// `U = Σ_c h_c(u) w_c + Σ_m p_m β_m(u)` (Hermite part + bubbles).
    Poly { herm: Arc<Cardinal>, w: Vec<f64>, p: Vec<f64>, r: usize },
}

impl Profile {
    /// `U^{(i)}(u)`, `i ≤ kmax`.
    fn eval(&self, u: f64, kmax: usize) -> Vec<f64> {
        match self {
            Profile::Exact { card, w } => card.eval(u, kmax).iter().map(|row| dot(row, w)).collect(),
            Profile::Poly { herm, w, p, r } => {
                let h = herm.eval(u, kmax);
                let b = bubbles(*r, p.len(), u, kmax);
                (0..=kmax).map(|i| dot(&h[i], w) + b.iter().zip(p).map(|(bm, pm)| bm[i] * pm).sum::<f64>()).collect()
            }
        }
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// One component: `X_t(u, v) = Σ_j U_j(u) g_j(v)`.
#[derive(Clone, Debug)]
struct Component {
    basis: Vec<BasisFn>,
    profiles: Vec<Profile>,
}

/// What a solve did, per component.
#[derive(Clone, Debug, PartialEq)]
pub struct ComponentReport {
    /// Operator order `2r`.
    pub order: usize,
    /// `"exact"` or `"collocation"`.
    pub solver: &'static str,
    /// The basis functions `g_j` by name.
    pub basis: Vec<String>,
    /// Whether the exact separable solver applies (every `g_j` an eigenfunction).
    pub exact_available: bool,
    /// Largest condition number of the mode systems (exact) or of the collocation matrix.
    pub condition_number: f64,
    /// RMS of the PDE residual at the collocation points (collocation only).
    pub collocation_rms: Option<f64>,
    /// Collocation grid `(L, Q)` and bubble count (collocation only).
    pub collocation: Option<(usize, usize, usize)>,
    /// Whether the operator is elliptic.
    pub elliptic: bool,
}

/// A static blend (SPEC §4): per component `t` the operator `L_t` of order `2r_t`
/// ([`Operator`]) with the conditions `∂ᵏX_t/∂uᵏ` at `u = 0` and `u = 1` for `k < r_t`.
///
/// The boundary data of each component are decomposed over basis functions `g_j(v)`
/// ([`decompose`]) and `X_t = Σ_j U_j(u) g_j(v)`:
///
/// - **exact separable solver**: when every `g_j″ = μ_j g_j`, `L_t(U_j g_j) = P_{μ_j}(D)U_j · g_j`,
///   so each `U_j` solves the ODE `P_{μ_j}(D) U = 0` with the `2r` end conditions of its
///   coefficients — solved by the cardinal functions of `ker P_{μ_j}(D)` (bounded basis,
///   any roots, [`crate::ode`]). The result satisfies the PDE and every condition to
///   round-off.
/// - **collocation** (paper 001): `U_j = H_j + Σ_m p_jm β_m`, `H_j` the degree-`(2r − 1)`
///   Hermite interpolant of the coefficients, `β_m` the [`bubbles`]; the `p_jm` of all `j`
///   jointly minimise the squared residual of `L_t X_t` on an `L × Q` grid (interior
///   Chebyshev points in `u`, equispaced or Chebyshev in `v`) by column-pivoted QR.
///   Conditions hold exactly by construction; the PDE only approximately.
#[derive(Clone, Debug)]
pub struct StaticBlend {
    domain: VDomain,
    ops: [Operator; 3],
    comps: [Component; 3],
    reports: [ComponentReport; 3],
}

/// Condition indices used by a component of half order `r`: `(u = 0, k)`, `k < r`, then
/// `(u = 1, k)`.
fn used_conditions<'a>(conds: &'a [Condition], r: usize, axis: &str) -> Result<Vec<&'a Condition>, BlendError> {
    let mut out = Vec::with_capacity(2 * r);
    for end in [0.0, 1.0] {
        for k in 0..r {
            let found: Vec<&Condition> = conds.iter().filter(|c| c.u == end && c.order == k).collect();
            match found.len() {
                1 => out.push(found[0]),
                0 => {
                    return Err(BlendError::Conditions(format!(
                        "component {axis} has order {}: it needs ∂^{k}X/∂u^{k} at u = {end}, which is missing",
                        2 * r
                    )));
                }
                _ => {
                    return Err(BlendError::Conditions(format!(
                        "{} conditions ∂^{k}X/∂u^{k} at u = {end}: give one",
                        found.len()
                    )));
                }
            }
        }
    }
    Ok(out)
}

fn specs(r: usize) -> Vec<CondSpec> {
    [0.0, 1.0].iter().flat_map(|&u| (0..r).map(move |order| CondSpec { u, order })).collect()
}

impl StaticBlend {
    /// Solves the blend. `conditions` must hold, at `u = 0` and at `u = 1`, one condition of
    /// every order below the largest `r_t`; conditions of higher order are ignored by the
    /// solve (they serve the continuity diagnostics).
    pub fn new(
        ops: [Operator; 3],
        conditions: &[Condition],
        domain: VDomain,
        opts: &BlendOptions,
    ) -> Result<Self, BlendError> {
        crate::solves::record(crate::solves::SolveKind::StaticBlend);
        if let Some(c) = conditions.iter().find(|c| c.u != 0.0 && c.u != 1.0) {
            return Err(BlendError::Conditions(format!(
                "a static blend takes its conditions at u = 0 and u = 1, not at u = {}",
                c.u
            )));
        }
        let mut comps = Vec::with_capacity(3);
        let mut reports = Vec::with_capacity(3);
        for (t, op) in ops.iter().enumerate() {
            let axis = ["x", "y", "z"][t];
            let r = op.half_order();
            let used = used_conditions(conditions, r, axis)?;
            let dec = decompose(&used, t, domain, opts.basis.as_deref())?;
            let exact_ok = dec.mu.iter().all(|m| m.is_some());
            let use_exact = match opts.solver {
                Solver::Auto => exact_ok,
                Solver::Exact if !exact_ok => {
                    let bad: Vec<String> =
                        dec.basis.iter().zip(&dec.mu).filter(|(_, m)| m.is_none()).map(|(b, _)| b.name()).collect();
                    return Err(BlendError::Solver(format!(
                        "the exact solver needs eigenfunctions of ∂v² as basis functions; component {axis} has {}",
                        bad.join(", ")
                    )));
                }
                Solver::Exact => true,
                Solver::Collocation => false,
            };
            let (comp, rep) = if use_exact {
                solve_exact(op, &dec, r, axis)?
            } else {
                solve_collocation(op, &dec, r, domain, opts, axis)?
            };
            reports.push(ComponentReport { exact_available: exact_ok, elliptic: op.is_elliptic(), ..rep });
            comps.push(comp);
        }
        Ok(StaticBlend {
            domain,
            ops: ops.clone(),
            comps: comps.try_into().expect("three components"),
            reports: reports.try_into().expect("three components"),
        })
    }

    /// What each component's solve did.
    pub fn reports(&self) -> &[ComponentReport; 3] {
        &self.reports
    }

    /// The operators.
    pub fn operators(&self) -> &[Operator; 3] {
        &self.ops
    }

    /// `L_t X_t` at `(u, v)` for each component, from exact derivatives.
    pub fn residual(&self, u: f64, v: f64) -> Vec3 {
        let mut out = Vec3::ZERO;
        for (t, (comp, op)) in self.comps.iter().zip(&self.ops).enumerate() {
            let k = 2 * op.half_order();
            let mut d = vec![0.0; (k + 1) * (k + 1)];
            for (g, prof) in comp.basis.iter().zip(&comp.profiles) {
                let uu = prof.eval(u, k);
                let gg = g.derivatives(v, k);
                for i in 0..=k {
                    for j in 0..=k {
                        d[i * (k + 1) + j] += uu[i] * gg[j];
                    }
                }
            }
            out[t] = op.apply(|i, j| d[i * (k + 1) + j]);
        }
        out
    }
}

fn solve_exact(
    op: &Operator,
    dec: &Decomposition,
    r: usize,
    axis: &str,
) -> Result<(Component, ComponentReport), BlendError> {
    let sp = specs(r);
    let mut cache: Vec<(f64, Arc<Cardinal>)> = Vec::new();
    let mut profiles = Vec::with_capacity(dec.basis.len());
    let mut cond: f64 = 0.0;
    for (j, mu) in dec.mu.iter().enumerate() {
        let mu = mu.expect("checked by the caller");
        let card = match cache.iter().find(|(m, _)| *m == mu) {
            Some((_, c)) => c.clone(),
            None => {
                let space = ExpSpace::from_polynomial(&op.characteristic(mu)).map_err(|e| {
                    BlendError::Solver(format!("component {axis}, basis function {}: {e}", dec.basis[j].name()))
                })?;
                let c = Arc::new(Cardinal::new(space, &sp).map_err(|e| {
                    BlendError::Solver(format!(
                        "component {axis}, basis function {} (μ = {mu}): the mode system has no unique solution: {e}",
                        dec.basis[j].name()
                    ))
                })?);
                cache.push((mu, c.clone()));
                c
            }
        };
        cond = crate::num::max_nan(cond, card.condition_number());
        profiles.push(Profile::Exact { card, w: dec.coef.iter().map(|c| c[j]).collect() });
    }
    let rep = ComponentReport {
        order: 2 * r,
        solver: "exact",
        basis: dec.basis.iter().map(|b| b.name()).collect(),
        exact_available: true,
        condition_number: cond,
        collocation_rms: None,
        collocation: None,
        elliptic: true,
    };
    Ok((Component { basis: dec.basis.clone(), profiles }, rep))
}

fn solve_collocation(
    op: &Operator,
    dec: &Decomposition,
    r: usize,
    domain: VDomain,
    opts: &BlendOptions,
    axis: &str,
) -> Result<(Component, ComponentReport), BlendError> {
    let herm = Arc::new(
        Cardinal::new(ExpSpace::symmetric(0.0, r), &specs(r))
            .map_err(|e| BlendError::Solver(format!("Hermite interpolation of order {}: {e}", 2 * r)))?,
    );
    let nb = opts.bubbles;
    let nj = dec.basis.len();
    let (nl, nq) = opts.collocation.unwrap_or((2 * nb + 2 * r, (4 * nj + 8).max(24)));
    if nb == 0 || nl == 0 || nq == 0 {
        return Err(BlendError::Solver("collocation needs at least one bubble and one point in u and v".into()));
    }
    let k = 2 * r;
    let us: Vec<f64> =
        (0..nl).map(|l| (1.0 - ((2 * l + 1) as f64 * std::f64::consts::PI / (2 * nl) as f64).cos()) / 2.0).collect();
    let vs: Vec<f64> = (0..nq)
        .map(|q| {
            if domain.periodic {
                domain.at(q as f64 / nq as f64)
            } else {
                domain.at((1.0 - ((2 * q + 1) as f64 * std::f64::consts::PI / (2 * nq) as f64).cos()) / 2.0)
            }
        })
        .collect();
    let weights: Vec<Vec<f64>> = (0..nj).map(|j| dec.coef.iter().map(|c| c[j]).collect()).collect();
    let gd: Vec<Vec<Vec<f64>>> = vs.iter().map(|&v| dec.basis.iter().map(|g| g.derivatives(v, k)).collect()).collect();
    // per u: (Hermite cardinal derivatives, bubble derivatives), each [function][order]
    type Table = Vec<Vec<f64>>;
    let ud: Vec<(Table, Table)> = us.iter().map(|&u| (herm.eval(u, k), bubbles(r, nb, u, k))).collect();
    let coef = op.coefficients();
    let rows = nl * nq;
    opts.limits.check_bytes(
        least_squares_bytes(rows, nj * nb, 1),
        &format!(
            "component {axis}: the collocation system ({rows} rows × {} unknowns, {nj} basis functions × {nb} bubbles)",
            nj * nb
        ),
    )?;
    let mut a = Mat::<f64>::zeros(rows, nj * nb);
    let mut b = Mat::<f64>::zeros(rows, 1);
    for (l, (h, bub)) in ud.iter().enumerate() {
        crate::cancel::checkpoint();
        for (q, g) in gd.iter().enumerate() {
            let row = l * nq + q;
            let mut known = 0.0;
            for j in 0..nj {
                for (i, c) in coef.iter().enumerate() {
                    let (du, dv) = (2 * (r - i), 2 * i);
                    let gj = c * g[j][dv];
                    if gj == 0.0 {
                        continue;
                    }
                    known += gj * dot(&h[du], &weights[j]);
                    for (m, bm) in bub.iter().enumerate() {
                        a[(row, j * nb + m)] += gj * bm[du];
                    }
                }
            }
            b[(row, 0)] = -known;
        }
    }
    let (x, cond) = least_squares(&a, &b, 1e14).map_err(|e| {
        BlendError::Solver(format!(
            "component {axis}: the collocation matrix ({rows} × {}) is singular ({e}); use fewer bubbles or more points",
            nj * nb
        ))
    })?;
    let res = crate::lanes::after(&a * &x - &b);
    let rms = (res.squared_norm_l2() / rows as f64).sqrt();
    let profiles = (0..nj)
        .map(|j| Profile::Poly {
            herm: herm.clone(),
            w: weights[j].clone(),
            p: (0..nb).map(|m| x[(j * nb + m, 0)]).collect(),
            r,
        })
        .collect();
    let rep = ComponentReport {
        order: 2 * r,
        solver: "collocation",
        basis: dec.basis.iter().map(|b| b.name()).collect(),
        exact_available: false,
        condition_number: cond,
        collocation_rms: Some(rms),
        collocation: Some((nl, nq, nb)),
        elliptic: true,
    };
    Ok((Component { basis: dec.basis.clone(), profiles }, rep))
}

impl Surface for StaticBlend {
    fn v_domain(&self) -> VDomain {
        self.domain
    }

    fn derivatives(&self, u: f64, v: f64, du: usize, dv: usize) -> Vec<Vec3> {
        let mut out = vec![Vec3::ZERO; (du + 1) * (dv + 1)];
        for (t, comp) in self.comps.iter().enumerate() {
            for (g, prof) in comp.basis.iter().zip(&comp.profiles) {
                let uu = prof.eval(u, du);
                let gg = g.derivatives(v, dv);
                for i in 0..=du {
                    for j in 0..=dv {
                        out[i * (dv + 1) + j][t] += uu[i] * gg[j];
                    }
                }
            }
        }
        out
    }

    fn grid(&self, us: &[f64], vs: &[f64]) -> Vec<[Vec3; 4]> {
        // Per column g_j, g_j′; per row U_j, U_j′; then a dense sum per point.
        let cols: Vec<[Vec<Vec<f64>>; 3]> = vs
            .par_iter()
            .map(|&v| std::array::from_fn(|t| self.comps[t].basis.iter().map(|g| g.derivatives(v, 1)).collect()))
            .collect();
        us.par_iter()
            .flat_map_iter(|&u| {
                crate::cancel::checkpoint();
                let row: [Vec<Vec<f64>>; 3] =
                    std::array::from_fn(|t| self.comps[t].profiles.iter().map(|p| p.eval(u, 1)).collect());
                cols.iter()
                    .map(|col| {
                        let mut o = [Vec3::ZERO; 4];
                        for t in 0..3 {
                            for (uu, gg) in row[t].iter().zip(&col[t]) {
                                o[0][t] += uu[0] * gg[0];
                                o[1][t] += uu[1] * gg[0];
                                o[2][t] += uu[0] * gg[1];
                                o[3][t] += uu[1] * gg[1];
                            }
                        }
                        o
                    })
                    .collect::<Vec<_>>()
            })
            .collect()
    }

    fn grid2(&self, us: &[f64], vs: &[f64]) -> Vec<[Vec3; 6]> {
        // as `grid`, with second derivatives: the same sums in the same order as
        // `derivatives(u, v, 2, 2)`, so the values are the pointwise ones bit for bit
        let cols: Vec<[Vec<Vec<f64>>; 3]> = vs
            .par_iter()
            .map(|&v| std::array::from_fn(|t| self.comps[t].basis.iter().map(|g| g.derivatives(v, 2)).collect()))
            .collect();
        const IJ: [(usize, usize); 6] = [(0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2)];
        us.par_iter()
            .flat_map_iter(|&u| {
                crate::cancel::checkpoint();
                let row: [Vec<Vec<f64>>; 3] =
                    std::array::from_fn(|t| self.comps[t].profiles.iter().map(|p| p.eval(u, 2)).collect());
                cols.iter()
                    .map(|col| {
                        let mut o = [Vec3::ZERO; 6];
                        for t in 0..3 {
                            for (uu, gg) in row[t].iter().zip(&col[t]) {
                                for (k, &(i, j)) in IJ.iter().enumerate() {
                                    o[k][t] += uu[i] * gg[j];
                                }
                            }
                        }
                        o
                    })
                    .collect::<Vec<_>>()
            })
            .collect()
    }
}
