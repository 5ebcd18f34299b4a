//! Time-dependent (dynamic) C1 blends (SPEC §5, paper 002).

use super::{BlendError, Solver};
use crate::Vec3;
use crate::data::FieldRef;
use crate::expr::{Expr, expand};
use crate::jet::{Jet, JetShape};
use crate::linalg::{least_squares, least_squares_min_norm};
use crate::memo::BoundedMemo;
use crate::num::MaxNan;
use crate::ode::{Cardinal, CondSpec, ExpSpace};
use crate::patch::{Condition, Surface, VDomain, cubic_hermite};
use faer::Mat;
use std::f64::consts::PI;
use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};

/// `β∂u⁴ + γ∂u²∂v² + λ∂v⁴ + ρ∂t² + η∂t`: the dynamic blend operator with its five shape
/// parameters (paper 002 eq. 3, without the force term).
///
/// On `S = G(u) F(v, t)` with `∂v²F = μF`, `∂tF = κF` it acts as
/// `[β G⁗ + γμ G″ + (λμ² + ρκ² + ηκ) G] F`: the closed form solves that ODE for every root
/// case ([`DynamicOperator::characteristic`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DynamicOperator {
    /// `β` (∂u⁴).
    pub beta: f64,
    /// `γ` (∂u²∂v²).
    pub gamma: f64,
    /// `λ` (∂v⁴).
    pub lambda: f64,
    /// `ρ` (density, ∂t²).
    pub rho: f64,
    /// `η` (damping, ∂t).
    pub eta: f64,
}

impl DynamicOperator {
    /// Checks the parameters are finite.
    pub fn new(beta: f64, gamma: f64, lambda: f64, rho: f64, eta: f64) -> Result<Self, BlendError> {
        for (n, x) in [("beta", beta), ("gamma", gamma), ("lambda", lambda), ("rho", rho), ("eta", eta)] {
            if !x.is_finite() {
                return Err(BlendError::Operator(format!("{n} = {x} is not finite")));
            }
        }
        Ok(DynamicOperator { beta, gamma, lambda, rho, eta })
    }

    /// Ascending coefficients in `s` of `β s⁴ + γμ s² + (λμ² + ρκ² + ηκ)`.
    pub fn characteristic(&self, mu: f64, kappa: f64) -> Vec<f64> {
        let c0 = self.lambda * mu * mu + self.rho * kappa * kappa + self.eta * kappa;
        vec![c0, 0.0, self.gamma * mu, 0.0, self.beta]
    }

    /// The operator applied to `G(u) F(v, t)` from `g[k] = G⁽ᵏ⁾(u)` and the partials of `F`.
    fn apply(&self, g: &[f64], f: &FDerivs) -> f64 {
        self.beta * g[4] * f.f
            + self.gamma * g[2] * f.fvv
            + g[0] * (self.lambda * f.fvvvv + self.rho * f.ftt + self.eta * f.ft)
    }
}

/// `F, ∂v²F, ∂v⁴F, ∂tF, ∂t²F` at a point.
#[derive(Clone, Copy, Debug, Default)]
struct FDerivs {
    f: f64,
    fvv: f64,
    fvvvv: f64,
    ft: f64,
    ftt: f64,
}

/// A basis function `F_j(v, t)` of the dynamic blend.
#[derive(Clone, Debug)]
pub enum DynBasis {
    /// An expression in `v` and `t` (from expansion, or given explicitly).
    Expr {
        /// Bound to the variables `v`, `t`.
        expr: Expr,
        /// Printed form.
        text: String,
    },
    /// One component of a boundary function, used whole (the fallback).
    Data {
        /// The curve (slots `(v, t)`).
        field: FieldRef,
        /// The component.
        comp: usize,
        /// Where it came from.
        label: String,
    },
}

impl DynBasis {
    /// `∂v^i ∂t^j F` for `i ≤ dv`, `j ≤ dt`, at index `i (dt + 1) + j`.
    pub fn partials(&self, v: f64, t: f64, dv: usize, dt: usize) -> Vec<f64> {
        let shape = JetShape::new(&[dv, dt]);
        let jet = match self {
            DynBasis::Expr { expr, .. } => expr.eval_jet(&[Jet::variable(shape, 0, v), Jet::variable(shape, 1, t)]),
            DynBasis::Data { field, comp, .. } => field.jet(&[v, t], shape).0[*comp].clone(),
        };
        let mut out = Vec::with_capacity((dv + 1) * (dt + 1));
        for i in 0..=dv {
            for j in 0..=dt {
                out.push(jet.derivative([i, j, 0]));
            }
        }
        out
    }

    fn eigen_derivs(&self, v: f64, t: f64) -> EigenDerivs {
        eigen_derivs(&self.partials(v, t, 2, 2))
    }

    /// A short name.
    pub fn name(&self) -> String {
        match self {
            DynBasis::Expr { text, .. } => text.clone(),
            DynBasis::Data { label, comp, .. } => format!("{label}.{}", ["x", "y", "z"][*comp]),
        }
    }

    /// `(μ, κ)` with `∂v²F = μF`, `∂tF = κF`, `∂t²F = κ²F`, when `F` is such an
    /// eigenfunction: tested at 9 × 5 points of the domain and time range from exact
    /// derivatives (relative tolerance 1e-11).
    pub fn eigenvalues(&self, domain: VDomain, times: (f64, f64)) -> Option<(f64, f64)> {
        eigen_from(eigen_points(domain, times).map(|(v, t)| self.eigen_derivs(v, t)))
    }
}

/// `∂v^i ∂t^j F_k` (index `i (dt + 1) + j`) for every basis function at one point. Whole
/// data functions that are components of the same field share one evaluation of it.
fn partials_all(basis: &[DynBasis], v: f64, t: f64, dv: usize, dt: usize) -> Vec<Vec<f64>> {
    let shape = JetShape::new(&[dv, dt]);
    let mut fields: Vec<(*const (), crate::data::VecJet)> = Vec::new();
    let pick = |jet: &Jet| {
        let mut out = Vec::with_capacity((dv + 1) * (dt + 1));
        for i in 0..=dv {
            for j in 0..=dt {
                out.push(jet.derivative([i, j, 0]));
            }
        }
        out
    };
    basis
        .iter()
        .map(|b| match b {
            DynBasis::Expr { .. } => b.partials(v, t, dv, dt),
            DynBasis::Data { field, comp, .. } => {
                let key = Arc::as_ptr(field) as *const ();
                let k = match fields.iter().position(|(p, _)| *p == key) {
                    Some(k) => k,
                    None => {
                        fields.push((key, field.jet(&[v, t], shape)));
                        fields.len() - 1
                    }
                };
                pick(&fields[k].1.0[*comp])
            }
        })
        .collect()
}

fn fderivs(p: &[f64]) -> FDerivs {
    // index i·3 + j for dv = 4, dt = 2
    FDerivs { f: p[0], fvv: p[6], fvvvv: p[12], ft: p[1], ftt: p[2] }
}

/// `F, ∂v²F, ∂tF, ∂t²F` at a point: what the eigenfunction test reads.
#[derive(Clone, Copy, Debug)]
struct EigenDerivs {
    f: f64,
    fvv: f64,
    ft: f64,
    ftt: f64,
}

/// [`EigenDerivs`] from the partials of orders (2, 2) (index `i·3 + j`). Jets of that
/// order carry the same coefficients up to it as those of order (4, 2), from the same
/// sums (a truncated product's low coefficients do not read the high ones), at under half
/// the coefficients. At (4, 2) this test was most of `DynamicBlend::new`, 45 % of eq. 19's
/// closed-form solve and 100 × 100 mesh.
fn eigen_derivs(p: &[f64]) -> EigenDerivs {
    EigenDerivs { f: p[0], fvv: p[6], ft: p[1], ftt: p[2] }
}

/// `(μ, κ)` of every basis function that is an eigenfunction (see
/// [`DynBasis::eigenvalues`]), sharing field evaluations.
fn eigen_all(basis: &[DynBasis], domain: VDomain, times: (f64, f64)) -> Vec<Option<(f64, f64)>> {
    let pts: Vec<Vec<EigenDerivs>> = eigen_points(domain, times)
        .map(|(v, t)| partials_all(basis, v, t, 2, 2).iter().map(|p| eigen_derivs(p)).collect())
        .collect();
    (0..basis.len()).map(|j| eigen_from(pts.iter().map(|row| row[j]))).collect()
}

fn eigen_points(domain: VDomain, times: (f64, f64)) -> impl Iterator<Item = (f64, f64)> {
    (0..9).flat_map(move |i| {
        (0..5)
            .map(move |k| (domain.at((i as f64 + 0.31) / 9.2), times.0 + (times.1 - times.0) * (k as f64 + 0.17) / 4.5))
    })
}

fn eigen_from(pts: impl Iterator<Item = EigenDerivs>) -> Option<(f64, f64)> {
    let pts: Vec<EigenDerivs> = pts.collect();
    let den: f64 = pts.iter().map(|d| d.f * d.f).sum();
    if den == 0.0 || !den.is_finite() {
        return None;
    }
    let mu = pts.iter().map(|d| d.f * d.fvv).sum::<f64>() / den;
    let kappa = pts.iter().map(|d| d.f * d.ft).sum::<f64>() / den;
    let scale = pts
        .iter()
        .flat_map(|d| [d.fvv.abs(), d.ft.abs(), d.ftt.abs(), d.f.abs() * (mu.abs() + kappa.abs() + kappa * kappa)])
        .max_nan();
    let tol = 1e-11 * scale;
    pts.iter()
        .all(|d| {
            (d.fvv - mu * d.f).abs() <= tol
                && (d.ft - kappa * d.f).abs() <= tol
                && (d.ftt - kappa * kappa * d.f).abs() <= tol
        })
        .then_some((mu, kappa))
}

/// The corrected sine terms: `ζ_k(u) = sin kπu − kπ [ξ₂(u) + (−1)ᵏ ξ₄(u)]` with the cubic
/// Hermite functions `ξ₂ = u(1 − u)²`, `ξ₄ = u³ − u²`. The subtracted cubic is the Hermite
/// interpolant of `sin kπu` (value 0 at both ends, slope `kπ` at 0 and `(−1)ᵏkπ` at 1), so
/// `ζ_k(0) = ζ_k(1) = ζ_k′(0) = ζ_k′(1) = 0`. Paper 002 eq. 12 prints
/// `(−1)ᵏkπ(1 − u)u² + sin kπu`, whose slope at `u = 0` is `kπ ≠ 0`: adding it would break
/// the tangent condition at `u = 0`.
///
/// Returns `ζ_k^{(i)}(u)` for `i ≤ 4`.
///
/// ```
/// use pdeshape_core::blend::zeta;
/// for k in 1..6 {
///     let (a, b) = (zeta(k, 0.0), zeta(k, 1.0));
///     assert!(a[0].abs() < 1e-14 && a[1].abs() < 1e-13 && b[0].abs() < 1e-14 && b[1].abs() < 1e-13);
/// }
/// ```
pub fn zeta(k: usize, u: f64) -> [f64; 5] {
    let w = k as f64 * PI;
    let sg = if k.is_multiple_of(2) { 1.0 } else { -1.0 };
    let (s, c) = (w * u).sin_cos();
    // ξ₂ = u − 2u² + u³, ξ₄ = u³ − u²
    let xi2 = [u - 2.0 * u * u + u * u * u, 1.0 - 4.0 * u + 3.0 * u * u, -4.0 + 6.0 * u, 6.0, 0.0];
    let xi4 = [u * u * u - u * u, 3.0 * u * u - 2.0 * u, 6.0 * u - 2.0, 6.0, 0.0];
    let sine = [s, w * c, -w * w * s, -w * w * w * c, w * w * w * w * s];
    std::array::from_fn(|i| sine[i] - w * (xi2[i] + sg * xi4[i]))
}

/// Options of a dynamic blend.
#[derive(Clone, Debug)]
pub struct DynamicOptions {
    /// Solver choice.
    pub solver: Solver,
    /// Sine terms `K` (collocation).
    pub terms: usize,
    /// Collocation grid `(L, M)`: uniform points in `u` (ends included) and `v`.
    pub collocation: (usize, usize),
    /// Least squares jointly over all `j` instead of per `j` (the paper).
    pub joint: bool,
    /// An explicit basis `F_j(v, t)`; `None` extracts one (expansion, or whole functions).
    pub basis: Option<Vec<DynBasis>>,
    /// The time range (for eigenfunction detection and the explicit-basis fit).
    pub times: (f64, f64),
    /// Caps; the collocation solver checks its dense matrices against `limits.memory`.
    pub limits: crate::limits::Limits,
}

impl Default for DynamicOptions {
    fn default() -> Self {
        DynamicOptions {
            solver: Solver::Auto,
            terms: 5,
            collocation: (11, 11),
            joint: false,
            basis: None,
            times: (0.0, 1.0),
            limits: crate::limits::Limits::default(),
        }
    }
}

/// A dynamic C1 blend: `S(u, v, t) = Σ_j G_j(u) F_j(v, t)` with vector `G_j` meeting
/// `G_j(0) = b_j`, `G_j′(0) = b̄_j`, `G_j(1) = d_j`, `G_j′(1) = d̄_j` — the coefficients of
/// `F_j` in the four boundary functions — so that every frame meets the four C1 conditions
/// exactly.
///
/// - **closed form** (every `F_j` an eigenfunction: `∂v²F = μF`, `∂tF = κF`): `G_j` solves
///   `β G⁗ + γμ G″ + (λμ² + ρκ² + ηκ) G = 0` exactly through the ODE core (all root cases:
///   real, complex, repeated, zero), independent of `t`;
/// - **collocation** (paper 002): `G_j = ξ₁b_j + ξ₂b̄_j + ξ₃d_j + ξ₄d̄_j + Σ_k ζ_k P_jk`
///   ([`zeta`]), with `P_jk` minimising the squared PDE residual on `L × M` points at the
///   frame's time, per `j` (the paper) or jointly.
#[derive(Clone, Debug)]
pub struct DynamicBlend {
    op: DynamicOperator,
    domain: VDomain,
    basis: Vec<DynBasis>,
    /// `coef[c][j]` for the conditions c = (0,0), (0,1), (1,0), (1,1).
    coef: Vec<Vec<Vec3>>,
    eigen: Vec<Option<(f64, f64)>>,
    exact: Option<Vec<Arc<Cardinal>>>,
    opts: DynamicOptions,
    /// Frames solved so far, by the bits of `t`: every caller (mesh, animation, reports,
    /// exporters) asks [`frame`](Self::frame) and each instant is solved once. Shared by
    /// clones, which are the same blend.
    frames: Arc<BoundedMemo<u64, DynamicFrame>>,
    /// How many frames were solved (not served from `frames`).
    solves: Arc<AtomicUsize>,
}

/// What a frame's solve did.
#[derive(Clone, Debug, PartialEq)]
pub struct DynamicReport {
    /// `"exact"` or `"collocation"`.
    pub solver: &'static str,
    /// The basis functions by name.
    pub basis: Vec<String>,
    /// Whether the closed form applies.
    pub exact_available: bool,
    /// Largest condition number of the mode systems (exact) or least-squares matrices.
    pub condition_number: f64,
}

const COND_ORDER: [(f64, usize); 4] = [(0.0, 0), (0.0, 1), (1.0, 0), (1.0, 1)];

/// Splits the four boundary functions over a shared basis: expansion of expression data
/// into (constant × product) terms, whole functions otherwise.
fn extract(conds: &[&Condition]) -> (Vec<DynBasis>, Vec<Vec<Vec3>>) {
    let mut basis: Vec<DynBasis> = Vec::new();
    let mut keys: Vec<Option<String>> = Vec::new();
    let mut coef: Vec<Vec<(usize, usize, f64)>> = vec![Vec::new(); conds.len()];
    for (ci, c) in conds.iter().enumerate() {
        for comp in 0..3 {
            let expanded = c.data.expressions().and_then(|(e, vars)| {
                let vt =
                    vars.len() <= 2 && vars.first().is_none_or(|v| v == "v") && vars.get(1).is_none_or(|v| v == "t");
                if vt { expand(&e[comp]) } else { None }
            });
            // printed terms name variables by slot: #0 is v, #1 is t
            let pretty = |k: &str| k.replace("#0", "v").replace("#1", "t");
            match expanded {
                Some(terms) => {
                    for term in terms {
                        if term.coef == 0.0 {
                            continue;
                        }
                        let key = term.key();
                        let j = match keys.iter().position(|k| k.as_deref() == Some(key.as_str())) {
                            Some(j) => j,
                            None => {
                                keys.push(Some(key.clone()));
                                basis.push(DynBasis::Expr { expr: term.product(), text: pretty(&key) });
                                basis.len() - 1
                            }
                        };
                        coef[ci].push((j, comp, term.coef));
                    }
                }
                None => {
                    // identically zero components contribute nothing
                    let zero = (0..23).all(|i| {
                        let (v, t) = (0.27 * i as f64 + 0.05, 0.043 * i as f64);
                        c.data.eval(&[v, t])[comp] == 0.0
                    });
                    if zero {
                        continue;
                    }
                    keys.push(None);
                    basis.push(DynBasis::Data {
                        field: c.data.clone(),
                        comp,
                        label: format!("∂^{}S/∂u^{} at u = {}", c.order, c.order, c.u),
                    });
                    coef[ci].push((basis.len() - 1, comp, 1.0));
                }
            }
        }
    }
    let coef = coef
        .iter()
        .map(|list| {
            let mut row = vec![Vec3::ZERO; basis.len()];
            for &(j, comp, x) in list {
                row[j][comp] += x;
            }
            row
        })
        .collect();
    (basis, coef)
}

impl DynamicBlend {
    /// Builds the blend from the four C1 conditions (`u = 0, 1`, orders 0 and 1; others
    /// are ignored).
    pub fn new(
        op: DynamicOperator,
        conditions: &[Condition],
        domain: VDomain,
        opts: &DynamicOptions,
    ) -> Result<Self, BlendError> {
        let mut used = Vec::with_capacity(4);
        for (u, order) in COND_ORDER {
            let found: Vec<&Condition> = conditions.iter().filter(|c| c.u == u && c.order == order).collect();
            match found.len() {
                1 => used.push(found[0]),
                0 => {
                    return Err(BlendError::Conditions(format!(
                        "a dynamic blend needs ∂^{order}S/∂u^{order} at u = {u}, which is missing"
                    )));
                }
                n => return Err(BlendError::Conditions(format!("{n} conditions ∂^{order}S/∂u^{order} at u = {u}"))),
            }
        }
        if let Some(c) = conditions.iter().find(|c| (c.u != 0.0 && c.u != 1.0) || c.order > 1) {
            return Err(BlendError::Conditions(format!(
                "a dynamic blend takes positions and tangents at u = 0 and 1, not ∂^{}S/∂u^{} at u = {}",
                c.order, c.order, c.u
            )));
        }
        let (basis, coef) = match &opts.basis {
            None => extract(&used),
            Some(b) => (b.clone(), project(&used, b, domain, opts.times)?),
        };
        let eigen = eigen_all(&basis, domain, opts.times);
        let exact_ok = eigen.iter().all(|e| e.is_some()) && op.beta != 0.0;
        let use_exact = match opts.solver {
            Solver::Auto => exact_ok,
            Solver::Exact if !exact_ok => {
                let why = if op.beta == 0.0 {
                    "β = 0 leaves a 2nd-order ODE in u, which cannot take four conditions".to_string()
                } else {
                    let bad: Vec<String> =
                        basis.iter().zip(&eigen).filter(|(_, e)| e.is_none()).map(|(b, _)| b.name()).collect();
                    format!("these basis functions are not eigenfunctions of ∂v² and ∂t: {}", bad.join(", "))
                };
                return Err(BlendError::Solver(format!("the closed form does not apply: {why}")));
            }
            Solver::Exact => true,
            Solver::Collocation => false,
        };
        if !use_exact && opts.terms == 0 {
            return Err(BlendError::Solver("collocation needs at least one sine term".into()));
        }
        let exact = if use_exact {
            let sp: Vec<CondSpec> = COND_ORDER.iter().map(|&(u, order)| CondSpec { u, order }).collect();
            let mut cache: Vec<((f64, f64), Arc<Cardinal>)> = Vec::new();
            let mut cards = Vec::with_capacity(basis.len());
            for (j, e) in eigen.iter().enumerate() {
                let (mu, kappa) = e.expect("checked");
                let card = match cache.iter().find(|(k, _)| *k == (mu, kappa)) {
                    Some((_, c)) => c.clone(),
                    None => {
                        let space = ExpSpace::from_polynomial(&op.characteristic(mu, kappa))
                            .map_err(|e| BlendError::Solver(format!("basis function {}: {e}", basis[j].name())))?;
                        let c = Arc::new(Cardinal::new(space, &sp).map_err(|e| {
                            BlendError::Solver(format!(
                                "basis function {} (μ = {mu}, κ = {kappa}): no unique solution: {e}",
                                basis[j].name()
                            ))
                        })?);
                        cache.push(((mu, kappa), c.clone()));
                        c
                    }
                };
                cards.push(card);
            }
            Some(cards)
        } else {
            None
        };
        Ok(DynamicBlend {
            op,
            domain,
            basis,
            coef,
            eigen,
            exact,
            opts: opts.clone(),
            frames: Arc::new(BoundedMemo::new(1024)),
            solves: Default::default(),
        })
    }

    /// The basis functions.
    pub fn basis(&self) -> &[DynBasis] {
        &self.basis
    }

    /// The operator.
    pub fn operator(&self) -> DynamicOperator {
        self.op
    }

    /// The frame at time `t` (solves the collocation problem at `t` when the collocation
    /// solver is in use), solved once per instant: later calls for the same `t` return
    /// the frame already solved.
    pub fn frame(&self, t: f64) -> Result<DynamicFrame, BlendError> {
        // bounded: a long animation or a scan of t does not grow it without end
        self.frames.get_or_try_insert_with(t.to_bits(), || {
            let f = self.solve_frame(t)?;
            self.solves.fetch_add(1, Ordering::Relaxed);
            Ok(f)
        })
    }

    /// How many frames this blend (and its clones) has solved; instants asked for again
    /// are served from the frames already solved.
    pub fn frames_solved(&self) -> usize {
        self.solves.load(Ordering::Relaxed)
    }

    #[allow(clippy::needless_range_loop)] // (l, m) index the grid row l·M + m and the tables
    fn solve_frame(&self, t: f64) -> Result<DynamicFrame, BlendError> {
        crate::solves::record(crate::solves::SolveKind::DynamicFrame);
        let nj = self.basis.len();
        let w = |j: usize| -> [Vec3; 4] { std::array::from_fn(|c| self.coef[c][j]) };
        if let Some(cards) = &self.exact {
            let profiles = (0..nj).map(|j| Profile::Exact { card: cards[j].clone(), w: w(j) }).collect();
            let cond = cards.iter().map(|c| c.condition_number()).max_nan();
            return Ok(self.make_frame(t, profiles, "exact", cond));
        }
        let k = self.opts.terms;
        let (nl, nm) = self.opts.collocation;
        if nl < 2 || nm < 1 {
            return Err(BlendError::Solver(format!("collocation grid {nl} × {nm} is too small")));
        }
        let us: Vec<f64> = (0..nl).map(|l| l as f64 / (nl - 1) as f64).collect();
        let vs: Vec<f64> = (0..nm)
            .map(|m| {
                if self.domain.periodic {
                    self.domain.at(m as f64 / nm as f64)
                } else {
                    self.domain.at(m as f64 / (nm - 1).max(1) as f64)
                }
            })
            .collect();
        let fd: Vec<Vec<FDerivs>> =
            vs.iter().map(|&v| partials_all(&self.basis, v, t, 4, 2).iter().map(|p| fderivs(p)).collect()).collect();
        let z: Vec<Vec<[f64; 5]>> = us.iter().map(|&u| (1..=k).map(|kk| zeta(kk, u)).collect()).collect();
        let h: Vec<[[f64; 5]; 4]> = us.iter().map(|&u| cubic_hermite(u)).collect();
        // Hermite part of G_j at u_l (derivatives 0..4), per component
        let hpart = |l: usize, j: usize| -> [Vec3; 5] {
            let ww = w(j);
            std::array::from_fn(|i| (0..4).fold(Vec3::ZERO, |acc, c| acc + ww[c] * h[l][c][i]))
        };
        let rows = nl * nm;
        let mut cond: f64 = 0.0;
        let mut p = vec![vec![Vec3::ZERO; k]; nj];
        let groups: Vec<Vec<usize>> =
            if self.opts.joint { vec![(0..nj).collect()] } else { (0..nj).map(|j| vec![j]).collect() };
        for group in groups {
            let cols = group.len() * k;
            self.opts.limits.check_bytes(
                super::solve::least_squares_bytes(rows, cols, 3),
                &format!("the collocation system ({rows} rows × {cols} unknowns)"),
            )?;
            let mut a = Mat::<f64>::zeros(rows, cols);
            let mut b = Mat::<f64>::zeros(rows, 3);
            for l in 0..nl {
                crate::cancel::checkpoint();
                for m in 0..nm {
                    let row = l * nm + m;
                    for (gi, &j) in group.iter().enumerate() {
                        let f = &fd[m][j];
                        for kk in 0..k {
                            a[(row, gi * k + kk)] = self.op.apply(&z[l][kk], f);
                        }
                        let hp = hpart(l, j);
                        for comp in 0..3 {
                            let g: [f64; 5] = std::array::from_fn(|i| hp[i][comp]);
                            b[(row, comp)] -= self.op.apply(&g, f);
                        }
                    }
                }
            }
            if a.norm_max() == 0.0 {
                continue; // F ≡ 0 on the grid: nothing to fit
            }
            let x = if self.opts.joint {
                // At one instant several F_j may coincide up to a factor (e^t sin v and
                // e^−t sin v): every least-squares solution then gives the same surface, and
                // the minimum-norm one is taken.
                let (x, rank) = least_squares_min_norm(&a, &b, 1e-12).map_err(|e| {
                    BlendError::Solver(format!("the joint collocation fit ({rows} × {cols}) at t = {t} failed: {e}"))
                })?;
                cond = cond.max(if rank < cols {
                    f64::INFINITY
                } else {
                    crate::linalg::condition_number(&a).unwrap_or(f64::NAN)
                });
                x
            } else {
                let (x, c) = least_squares(&a, &b, 1e17).map_err(|e| {
                    BlendError::Solver(format!(
                        "the collocation matrix ({rows} × {cols}) at t = {t} is singular ({e}): use fewer sine terms or more points"
                    ))
                })?;
                cond = crate::num::max_nan(cond, c);
                x
            };
            for (gi, &j) in group.iter().enumerate() {
                for kk in 0..k {
                    p[j][kk] = Vec3::new(x[(gi * k + kk, 0)], x[(gi * k + kk, 1)], x[(gi * k + kk, 2)]);
                }
            }
        }
        let profiles = (0..nj).map(|j| Profile::Poly { w: w(j), p: p[j].clone() }).collect();
        Ok(self.make_frame(t, profiles, "collocation", cond))
    }

    fn make_frame(&self, t: f64, profiles: Vec<Profile>, solver: &'static str, cond: f64) -> DynamicFrame {
        DynamicFrame {
            t,
            domain: self.domain,
            op: self.op,
            basis: self.basis.clone(),
            profiles,
            report: DynamicReport {
                solver,
                basis: self.basis.iter().map(|b| b.name()).collect(),
                exact_available: self.eigen.iter().all(|e| e.is_some()) && self.op.beta != 0.0,
                condition_number: cond,
            },
        }
    }
}

/// Coefficients of the four boundary functions over an explicit basis, by least squares
/// on 31 × 7 points of `(v, t)`; data outside the span are an error.
fn project(
    conds: &[&Condition],
    basis: &[DynBasis],
    domain: VDomain,
    times: (f64, f64),
) -> Result<Vec<Vec<Vec3>>, BlendError> {
    let pts: Vec<(f64, f64)> = (0..31)
        .flat_map(|i| {
            (0..7).map(move |k| (domain.at((i as f64 + 0.37) / 31.4), times.0 + (times.1 - times.0) * k as f64 / 6.0))
        })
        .collect();
    let g = Mat::from_fn(pts.len(), basis.len(), |r, j| basis[j].partials(pts[r].0, pts[r].1, 0, 0)[0]);
    let mut out = Vec::new();
    for c in conds {
        let f = Mat::from_fn(pts.len(), 3, |r, comp| c.data.eval(&[pts[r].0, pts[r].1])[comp]);
        let (x, _) = least_squares(&g, &f, 1e12)
            .map_err(|e| BlendError::Basis(format!("the explicit basis functions are not independent ({e})")))?;
        let fit = crate::lanes::after(&g * &x);
        let size = f.norm_max();
        let err = (&fit - &f).norm_max();
        if err > 1e-10 * size.max(1e-300) && err > 1e-14 {
            return Err(BlendError::Basis(format!(
                "∂^{}S/∂u^{} at u = {} is not in the span of the basis (max residual {err:.3e})",
                c.order, c.order, c.u
            )));
        }
        out.push((0..basis.len()).map(|j| Vec3::new(x[(j, 0)], x[(j, 1)], x[(j, 2)])).collect());
    }
    Ok(out)
}

#[derive(Clone, Debug)]
enum Profile {
    Exact { card: Arc<Cardinal>, w: [Vec3; 4] },
    Poly { w: [Vec3; 4], p: Vec<Vec3> },
}

impl Profile {
    fn eval(&self, u: f64, kmax: usize) -> Vec<Vec3> {
        match self {
            Profile::Exact { card, w } => {
                card.eval(u, kmax).iter().map(|row| (0..4).fold(Vec3::ZERO, |a, c| a + w[c] * row[c])).collect()
            }
            Profile::Poly { w, p } => {
                assert!(kmax <= 4, "collocation profiles are evaluated up to the 4th derivative");
                let h = cubic_hermite(u);
                let z: Vec<[f64; 5]> = (1..=p.len()).map(|k| zeta(k, u)).collect();
                (0..=kmax)
                    .map(|i| {
                        (0..4).fold(Vec3::ZERO, |a, c| a + w[c] * h[c][i])
                            + p.iter().zip(&z).fold(Vec3::ZERO, |a, (pk, zk)| a + *pk * zk[i])
                    })
                    .collect()
            }
        }
    }
}

/// The dynamic blend at one instant: a patch with exact derivatives.
#[derive(Clone, Debug)]
pub struct DynamicFrame {
    t: f64,
    domain: VDomain,
    op: DynamicOperator,
    basis: Vec<DynBasis>,
    profiles: Vec<Profile>,
    report: DynamicReport,
}

impl DynamicFrame {
    /// The time.
    pub fn time(&self) -> f64 {
        self.t
    }

    /// What the solve did.
    pub fn report(&self) -> &DynamicReport {
        &self.report
    }

    /// `G_j^{(i)}(u)` for `i ≤ kmax` (≤ 4 for collocation frames).
    pub fn profile(&self, j: usize, u: f64, kmax: usize) -> Vec<Vec3> {
        self.profiles[j].eval(u, kmax)
    }

    /// The PDE residual `(β∂u⁴ + γ∂u²∂v² + λ∂v⁴ + ρ∂t² + η∂t) S` at `(u, v)`, with the
    /// frame's `G_j` held fixed in time (exact for the closed form, where `G_j` does not
    /// depend on `t`).
    pub fn residual(&self, u: f64, v: f64) -> Vec3 {
        let mut r = Vec3::ZERO;
        let all = partials_all(&self.basis, v, self.t, 4, 2);
        for (p, prof) in all.iter().zip(&self.profiles) {
            let g = prof.eval(u, 4);
            let d = fderivs(p);
            for comp in 0..3 {
                let gc: [f64; 5] = std::array::from_fn(|i| g[i][comp]);
                r[comp] += self.op.apply(&gc, &d);
            }
        }
        r
    }
}

impl Surface for DynamicFrame {
    fn v_domain(&self) -> VDomain {
        self.domain
    }

    fn derivatives(&self, u: f64, v: f64, du: usize, dv: usize) -> Vec<Vec3> {
        let mut out = vec![Vec3::ZERO; (du + 1) * (dv + 1)];
        let all = partials_all(&self.basis, v, self.t, dv, 0);
        for (fv, prof) in all.iter().zip(&self.profiles) {
            let g = prof.eval(u, du);
            for i in 0..=du {
                for j in 0..=dv {
                    out[i * (dv + 1) + j] += g[i] * fv[j];
                }
            }
        }
        out
    }

    fn grid(&self, us: &[f64], vs: &[f64]) -> Vec<[Vec3; 4]> {
        use rayon::prelude::*;
        let cols: Vec<Vec<Vec<f64>>> = vs.par_iter().map(|&v| partials_all(&self.basis, v, self.t, 1, 0)).collect();
        us.par_iter()
            .flat_map_iter(|&u| {
                crate::cancel::checkpoint();
                let row: Vec<Vec<Vec3>> = self.profiles.iter().map(|p| p.eval(u, 1)).collect();
                cols.iter()
                    .map(|col| {
                        let mut o = [Vec3::ZERO; 4];
                        for (g, f) in row.iter().zip(col) {
                            o[0] += g[0] * f[0];
                            o[1] += g[1] * f[0];
                            o[2] += g[0] * f[1];
                            o[3] += g[1] * f[1];
                        }
                        o
                    })
                    .collect::<Vec<_>>()
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::ExprField;
    use crate::patch::check_conditions;

    fn cond(u: f64, order: usize, e: [&str; 3]) -> Condition {
        Condition { u, order, data: Arc::new(ExprField::parse(e, &["v", "t"], &|_| None).unwrap()) }
    }

    /// Paper 002 eq. 19 with its constants.
    fn eq19() -> Vec<Condition> {
        vec![
            cond(0.0, 0, ["1.6*exp(t)*sin(v)", "1*exp(-t)*cos(v)", "2"]),
            cond(0.0, 1, ["0", "0", "-3"]),
            cond(1.0, 0, ["0.8*exp(-t)*sin(v)", "0.6*exp(t)*cos(v)", "0"]),
            cond(1.0, 1, ["0", "0", "-3"]),
        ]
    }

    fn op19() -> DynamicOperator {
        DynamicOperator::new(1.0, 12.1, 1.0, 1.0, 1.0).unwrap()
    }

    #[test]
    fn corrected_sine_terms_meet_all_four_conditions_and_the_papers_do_not() {
        for k in 1..=20 {
            let (a, b) = (zeta(k, 0.0), zeta(k, 1.0));
            for x in [a[0], a[1], b[0], b[1]] {
                assert!(x.abs() < 1e-12 * k as f64, "k {k}: {a:?} {b:?}");
            }
            // the table's derivatives, against identities derived by hand: ζ_k minus sin kπu
            // is a cubic, so ζ⁗ = (kπ)⁴ sin kπu and ζ‴ = −(kπ)³ cos kπu − 6kπ(1 + (−1)ᵏ)
            let w = k as f64 * PI;
            let sg = if k % 2 == 0 { 1.0 } else { -1.0 };
            for u in [0.1, 0.3, 0.77] {
                let z = zeta(k, u);
                assert!((z[4] - w.powi(4) * (w * u).sin()).abs() <= 1e-12 * w.powi(4), "k {k} u {u}");
                let d3 = -w.powi(3) * (w * u).cos() - 6.0 * w * (1.0 + sg);
                assert!((z[3] - d3).abs() <= 1e-12 * w.powi(3), "k {k} u {u}");
            }
            // eq. 12 as printed, ζ = (−1)ᵏkπ(1 − u)u² + sin kπu, with its exact slope
            // (−1)ᵏkπ(2u − 3u²) + kπ cos kπu: kπ at u = 0, where the corrected ζ_k has 0
            let paper_slope = |u: f64| sg * w * (2.0 * u - 3.0 * u * u) + w * (w * u).cos();
            assert!((paper_slope(0.0) - w).abs() < 1e-12 * w);
            assert!(zeta(k, 0.0)[1].abs() < 1e-12 * w, "k {k}: the corrected slope at 0");
        }
    }

    /// The eigenfunction test reads `F, F_vv, F_t, F_tt` from jets of order (2, 2); those of
    /// order (4, 2) (the collocation's) give the same numbers bit for bit, for expression
    /// terms and for whole data components.
    #[test]
    fn eigen_test_jets_of_order_two_match_those_of_order_four() {
        let mut conds = eq19();
        // a field that is no expression: its components are data basis functions
        let data = crate::data::FnField::new(2, |p: &[Jet]| {
            let (v, t) = (&p[0], &p[1]);
            let y = t.neg().exp().mul(&v.cos()).mul(&v.cos().add_scalar(2.0).sqrt());
            [t.exp().mul(&v.sin()).scale(1.6), y, Jet::constant(v.shape(), 2.0)]
        });
        conds[2] = Condition { u: 1.0, order: 0, data: Arc::new(data) };
        let (basis, _) = extract(&conds.iter().collect::<Vec<_>>());
        assert!(basis.iter().any(|b| matches!(b, DynBasis::Data { .. })), "a data component is tested");
        assert!(basis.iter().any(|b| matches!(b, DynBasis::Expr { .. })), "an expression term is tested");
        for (v, t) in eigen_points(VDomain::PERIODIC, (-0.4, 0.9)) {
            let low = partials_all(&basis, v, t, 2, 2);
            let high = partials_all(&basis, v, t, 4, 2);
            for (l, h) in low.iter().zip(&high) {
                let (a, b) = (eigen_derivs(l), fderivs(h));
                let bits = |x: [f64; 4]| x.map(f64::to_bits);
                assert_eq!(bits([a.f, a.fvv, a.ft, a.ftt]), bits([b.f, b.fvv, b.ft, b.ftt]), "at ({v}, {t})");
            }
        }
    }

    #[test]
    fn closed_form_of_eq19_is_exact_at_every_frame() {
        let conds = eq19();
        let b = DynamicBlend::new(op19(), &conds, VDomain::PERIODIC, &DynamicOptions::default()).unwrap();
        // F: e^t sin v, e^−t cos v, 1, e^−t sin v, e^t cos v (expansion of the data)
        assert_eq!(b.basis().len(), 5, "{:?}", b.basis().iter().map(|f| f.name()).collect::<Vec<_>>());
        for i in 0..=10 {
            let t = 0.03 * i as f64;
            let f = b.frame(t).unwrap();
            assert_eq!(f.report().solver, "exact");
            let rep = check_conditions(&f, &conds, t, 1000);
            assert!(rep.max_rel < 1e-12, "t {t}: {rep:?}");
            for (u, v) in [(0.2, 0.4), (0.5, 2.0), (0.77, 4.4)] {
                let r = f.residual(u, v);
                assert!(r.norm() < 1e-10, "PDE residual {r:?} at t {t}");
            }
        }
    }

    /// SPEC §5 "What to expect": G_1 (the x profile of e^t sin v, amplitude 1.6) by per-j
    /// least squares against the closed form.
    #[test]
    fn collocation_error_of_g1_matches_the_independent_figures() {
        let conds = eq19();
        let exact = DynamicBlend::new(op19(), &conds, VDomain::PERIODIC, &DynamicOptions::default()).unwrap();
        let fe = exact.frame(0.0).unwrap();
        let names: Vec<String> = exact.basis().iter().map(|f| f.name()).collect();
        let j1 =
            names.iter().position(|n| n == "exp(t)*sin(v)").unwrap_or_else(|| panic!("F_1 = e^t sin v in {names:?}"));
        let err = |k: usize, l: usize| {
            let o =
                DynamicOptions { solver: Solver::Collocation, terms: k, collocation: (l, 11), ..Default::default() };
            let f = DynamicBlend::new(op19(), &conds, VDomain::PERIODIC, &o).unwrap().frame(0.0).unwrap();
            assert!(check_conditions(&f, &conds, 0.0, 1000).max_rel < 1e-12);
            (0..=1000)
                .map(|i| i as f64 / 1000.0)
                .map(|u| (f.profile(j1, u, 0)[0].x - fe.profile(j1, u, 0)[0].x).abs())
                .max_nan()
        };
        let close = |got: f64, want: f64| (got / want - 1.0).abs() < 0.15;
        for (k, l, want) in [(5, 11, 4.4e-3), (7, 11, 4.5e-3), (10, 11, 0.19), (5, 41, 1.9e-3), (10, 41, 1.5e-3)] {
            let e = err(k, l);
            println!("G_1 max error, K = {k}, L = {l}: {e:.3e} (SPEC: {want:.1e})");
            assert!(close(e, want), "K = {k}, L = {l}: {e:.3e} (expected about {want:.1e})");
        }
    }

    #[test]
    fn every_root_case_of_the_closed_form() {
        // γ² − 4β(λμ² + ρκ² + ηκ) > 0, = 0, < 0 for mode μ = −1, κ = 1
        for (beta, gamma, lambda) in [(1.0, 12.1, 1.0), (1.0, 2.0, -1.0), (1.0, 1.0, 1.0), (-0.5, 3.0, 2.0)] {
            let op = DynamicOperator::new(beta, gamma, lambda, 1.0, 1.0).unwrap();
            let conds = eq19();
            let b = DynamicBlend::new(op, &conds, VDomain::PERIODIC, &DynamicOptions::default()).unwrap();
            let f = b.frame(0.1).unwrap();
            assert!(check_conditions(&f, &conds, 0.1, 200).max_rel < 1e-11, "{op:?}");
            let r = f.residual(0.4, 1.1);
            assert!(r.norm() < 1e-9, "{op:?}: {r:?}");
        }
    }

    #[test]
    fn beta_zero_needs_collocation_and_joint_fit_meets_conditions() {
        let op = DynamicOperator::new(0.0, 10.0, 0.01, 0.01, -5.0).unwrap();
        let conds = eq19();
        let o = DynamicOptions { solver: Solver::Exact, ..Default::default() };
        let e = DynamicBlend::new(op, &conds, VDomain::PERIODIC, &o).unwrap_err();
        assert!(e.to_string().contains("β = 0"), "{e}");
        for joint in [false, true] {
            let o = DynamicOptions { joint, ..Default::default() };
            let b = DynamicBlend::new(op, &conds, VDomain::PERIODIC, &o).unwrap();
            let f = b.frame(0.2).unwrap();
            assert_eq!(f.report().solver, "collocation");
            assert!(check_conditions(&f, &conds, 0.2, 1000).max_rel < 1e-12);
        }
    }

    #[test]
    fn expansion_finds_the_papers_sixteen_functions_for_eqs_29_30() {
        let (a1, a2, a3, a4, a5) = ("0.3", "0.2", "2", "0.25", "3");
        let e = |s: &str| s.replace("a1", a1).replace("a2", a2).replace("a3", a3).replace("a4", a4).replace("a5", a5);
        let c0 = [
            e("(1 - t)*(0.5*sinh(a1*v + a2) + 0.2*sin(a3*v)) + 1.2*t*cos(-v)"),
            e("(1 - t)*(0.4*cosh(a4*v) + 0.2*cos(a3*v)) + 1.1*t*sin(-v)"),
            e("(1 - t)*(2 + 1.1) + 3*t"),
        ];
        let c1 = [
            e("0.8*(1 - t)*1.5*sin(a5*v) + 1.3*t*cos(-v)"),
            e("0.8*(1 - t)*1.5*cos(a5*v) + 1.4*t*sin(-v)"),
            "(1 - t)*0.5 + 0.2*t".to_string(),
        ];
        let t1 = [e("(1 - t)*1.5*sin(a5*v)"), e("(1 - t)*1.5*cos(a5*v)"), "-0.7*t".to_string()];
        let conds = vec![
            cond(0.0, 0, [&c0[0], &c0[1], &c0[2]]),
            cond(0.0, 1, ["0", "0", "-(1 - t)*1.1"]),
            cond(1.0, 0, [&c1[0], &c1[1], &c1[2]]),
            cond(1.0, 1, [&t1[0], &t1[1], &t1[2]]),
        ];
        let dom = VDomain::open(0.0, 2.0 * PI);
        let b = DynamicBlend::new(op19(), &conds, dom, &DynamicOptions::default()).unwrap();
        let names: Vec<String> = b.basis().iter().map(|f| f.name()).collect();
        assert_eq!(names.len(), 16, "{names:?}");
        let f = b.frame(0.5).unwrap();
        assert_eq!(f.report().solver, "collocation", "sinh(a1 v + a2) is no eigenfunction in t·… combinations");
        assert!(check_conditions(&f, &conds, 0.5, 1000).max_rel < 1e-12);
    }
}
