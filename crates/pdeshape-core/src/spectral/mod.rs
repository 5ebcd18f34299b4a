//! PDE surfaces of any even order 2N (SPEC §3; papers 004 and 003).
//!
//! The patch solves `(∂u² + a²∂θ²)^N X = 0` on `[0, 1] × [0, 2π)` with `2N` conditions
//! `∂^{d_i}X/∂u^{d_i}(u_i, θ) = g_i(θ)`. With the Fourier series of the data,
//!
//! ```text
//! X̃(u, θ) = A₀(u) + Σ_{n=1}^{M} [A_n(u) cos nθ + B_n(u) sin nθ],
//! A_n(u) = Σ_i ℓ_i^{(n)}(u) a_{i,n},  B_n(u) = Σ_i ℓ_i^{(n)}(u) b_{i,n},
//! ```
//!
//! where `ℓ^{(n)}` are the cardinal functions of the condition set in `ker (D² − a²n²)^N`
//! (polynomials of degree `2N − 1` for `n = 0`), see [`crate::ode`]. `X̃` solves the PDE
//! exactly and meets the conditions up to the truncated Fourier tail
//! `r_i(θ) = g_i(θ) − F_M[g_i](θ)`. The remainder
//!
//! ```text
//! R(u, θ) = Σ_i ℓ_i^{(ω)}(u) r_i(θ),   ℓ^{(ω)} cardinal in ker (D² − ω²)^N,  ω = a (M + 1),
//! ```
//!
//! has `∂^{d_k}R/∂u^{d_k}(u_k, θ) = r_k(θ)`, so `X = X̃ + R` meets **every** condition
//! exactly at every θ (paper 004 eqs. 23/25, whose printed `r_1`, `r_{2N}` have typos).
//!
//! Open patches (`v ∈ [v₀, v₁]`) are solved on the even extension (SPEC §2): θ = π(v − v₀)/(v₁ − v₀),
//! and `a` is the shape parameter in θ.

use crate::Vec3;
use crate::data::fourier::{FourierSeries, sample_count};
use crate::data::{EvenExtension, FieldRef};
use crate::memo::BoundedMemo;
use crate::num::MaxNan;
use crate::ode::{CardinalSet, Combined, CondSpec, ExpSpace, OdeError};
use crate::patch::{Condition, Surface, VDomain};
use faer::Mat;
use rayon::prelude::*;
use std::f64::consts::PI;
use std::sync::{Arc, OnceLock};

/// The largest exponential rate (`a·M`, `ω`) a spectral patch takes.
pub const MAX_RATE: f64 = 1e6;

/// Options of the spectral solver.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpectralOptions {
    /// The shape parameter `a` (> 0): larger `a` shortens the reach of the boundary data.
    pub a: f64,
    /// Fourier modes kept, `M` (default 6).
    pub modes: usize,
    /// Remainder rate `ω` (default `a (M + 1)`).
    pub omega: Option<f64>,
}

impl Default for SpectralOptions {
    fn default() -> Self {
        SpectralOptions { a: 1.0, modes: 6, omega: None }
    }
}

/// Why a spectral patch cannot be built.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SpectralError {
    /// Bad options.
    #[error("{0}")]
    Options(String),
    /// The conditions do not determine the solution.
    #[error("mode {mode} ({what}): {source}")]
    Conditions {
        /// Fourier mode (or `ω` for the remainder).
        mode: String,
        /// Description of the condition set.
        what: String,
        /// The underlying failure.
        source: OdeError,
    },
}

/// Per-row cache: `a[k][n] = A_n^{(k)}(u)`, `b[k][n]`, `l[k][i] = ℓ_i^{(ω,k)}(u)`.
struct Row {
    a: Vec<Vec<Vec3>>,
    b: Vec<Vec<Vec3>>,
    l: Vec<Vec<f64>>,
}

/// A PDE surface of order `2N` solved by Fourier modes plus the exactness remainder.
pub struct SpectralPatch {
    domain: VDomain,
    dtheta_dv: f64,
    n: usize,
    opts: SpectralOptions,
    omega: f64,
    conds: Vec<CondSpec>,
    data: Vec<FieldRef>,
    series: Vec<FourierSeries>,
    /// The cardinal sets of modes `0 … kept`: the modes above `kept` have no data.
    cards: Vec<Arc<CardinalSet>>,
    /// The remainder's cardinal set; none when every datum is proved a trigonometric
    /// polynomial of degree ≤ M (`exact_series`: the tails and so the remainder are zero).
    rem: Option<Arc<CardinalSet>>,
    /// The modes summed: `M`, or the largest proved degree when every datum is proved a
    /// trigonometric polynomial of degree ≤ M. Mode `n` of the solution is
    /// `Σ_i ℓ_i^{(n)}(u) (a_{i,n} cos nθ + b_{i,n} sin nθ)`, identically zero when every
    /// datum's coefficients of order `n` are: such modes are neither solved nor summed.
    kept: usize,
    /// Order of the derivatives tabulated on demand (`2N` for `N ≤ 10`, else none beyond
    /// what the solve tabulated) and the cardinal functions tabulated to it: computed the
    /// first time a derivative above the solve's order is asked for (the PDE residual,
    /// high-order jets of a curve on this patch), not by every solve.
    deep_kmax: usize,
    deep: OnceLock<Option<CardSets>>,
    time: f64,
    cache: BoundedMemo<(u64, usize), Arc<Row>>,
    /// Mode 0's functions folded with its data ([`Combined::polynomial`]) when they are
    /// polynomials, on first use: the rows and the scattered points both read them, so the
    /// two paths give the same numbers, and derivatives come from series differentiated
    /// exactly (through the cardinal functions' `T_b′`, the dolphin body's `X_u` was 3e-13
    /// off near `u = 1`, where the folded series is within 5e-15 of the exact value of the
    /// stored coefficients).
    poly0: OnceLock<Option<Combined>>,
    /// The modes folded for scattered points ([`batch`]), on first use.
    folded: OnceLock<batch::Folded>,
    /// The same with second `u`-derivatives, on the first call that asks for them.
    folded2: OnceLock<batch::Folded>,
    /// Every datum is proved a trigonometric polynomial of degree ≤ M in θ
    /// ([`crate::expr::trig_degree`]) on a periodic patch, independent of `t`: its Fourier
    /// series of M modes is the datum itself (analysed from more than 2M samples, so
    /// nothing aliases), the tails `g − F_M[g]` are identically zero and so is the
    /// remainder term. Evaluation then takes the tails as zero instead of summing their
    /// round-off (which the remainder's cardinal functions amplify: 6e-14 relative in the
    /// dolphin's flukes' `X_u`), and does not evaluate the data at all.
    exact_series: bool,
    /// The same of each datum: its tails are zero and are not evaluated (the members of a
    /// fill family have most of their data zero or the pole's ring).
    exact: Vec<bool>,
}

/// The degree `d ≤ modes` of the datum `g(θ, t)` when it is proved a trigonometric
/// polynomial of degree at most `d` in θ that does not depend on `t`
/// ([`Field::trig_degree`]; the series is analysed at one time).
fn finite_series(g: &FieldRef, modes: usize) -> Option<usize> {
    g.trig_degree().filter(|&d| d <= modes)
}

/// The modes' cardinal sets and the remainder's.
type CardSets = (Vec<Arc<CardinalSet>>, Option<Arc<CardinalSet>>);

/// What a mode without data reports as its path: it is neither solved nor summed.
pub const NO_DATA: &str = "none: no data of this degree";

impl std::fmt::Debug for SpectralPatch {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SpectralPatch").field("order", &(2 * self.n)).field("opts", &self.opts).finish()
    }
}

/// Diagnostics of a solved spectral patch.
#[derive(Clone, Debug, PartialEq)]
pub struct SpectralReport {
    /// PDE order `2N`.
    pub order: usize,
    /// Modes `M`.
    pub modes: usize,
    /// Remainder rate.
    pub omega: f64,
    /// Largest condition number over the mode systems (f64 solve) or inverse size
    /// (multiple precision).
    pub max_mode_condition: f64,
    /// How the cardinal functions were computed: counts of `f64` (exponential basis or
    /// ultraspherical) and `multiprecision` modes, over the modes solved.
    pub methods: (usize, usize),
    /// The modes solved and summed, `0 … kept`: `M`, or the largest degree of the data when
    /// every datum is proved a trigonometric polynomial (the modes above it, and then the
    /// remainder, are identically zero).
    pub kept: usize,
    /// The path of every mode `0 … M` and then of the remainder (`"f64"`,
    /// `"f64-ultraspherical"`, `"multiprecision"`, or [`NO_DATA`] for a mode or remainder
    /// that is identically zero and was not solved).
    pub mode_paths: Vec<&'static str>,
    /// The ODE residual of every mode's cardinal functions (`0 … M`, then the remainder's;
    /// 0 where nothing was solved),
    /// relative to the operator's terms, computed in Chebyshev coefficients through the
    /// banded operators for every order ([`crate::ode::CardinalSet::residual`]; 0 for
    /// the exact exponential basis). The truncated part `X̃ = Σ_m U_m(u) e^{imθ}` has PDE
    /// residual `Σ_m P_m(D)U_m e^{imθ}`, so the largest mode figure bounds its relative
    /// residual.
    pub mode_residuals: Vec<f64>,
    /// Lebesgue constants of the condition set for mode 0 and mode 1 (amplification of
    /// the data between the conditions).
    pub lebesgue: (f64, Option<f64>),
}

fn describe(conds: &[CondSpec]) -> String {
    conds.iter().map(|c| format!("∂^{} at u = {}", c.order, c.u)).collect::<Vec<_>>().join(", ")
}

/// `(rate bits, n, condition positions and orders, kmax)`.
type MemoKey = (u64, usize, Vec<(u64, usize)>, usize);
static CARDINAL_MEMO: std::sync::LazyLock<BoundedMemo<MemoKey, Arc<CardinalSet>>> =
    std::sync::LazyLock::new(|| BoundedMemo::new(256));

/// Cardinal functions of `ExpSpace::symmetric(rate, n)` for the condition set, memoised
/// process-wide: they depend only on the operator and the condition positions, not on the
/// data, so re-solving with new boundary curves (a designer dragging a curve or a section
/// parameter) reuses them. Bounded: the memo is emptied when it holds 256 sets.
fn cardinal_set(rate: f64, n: usize, specs: &[CondSpec], kmax: usize) -> Result<Arc<CardinalSet>, OdeError> {
    let key: MemoKey = (rate.to_bits(), n, specs.iter().map(|c| (c.u.to_bits(), c.order)).collect(), kmax);
    CARDINAL_MEMO
        .get_or_try_insert_with(key, || Ok(Arc::new(CardinalSet::new(ExpSpace::symmetric(rate, n), specs, kmax)?)))
}

/// Empties the process-wide memo of cardinal functions, so that the next solves compute
/// them anew (benchmarks of cold solves use it; results do not change).
pub fn clear_cardinal_memo() {
    CARDINAL_MEMO.clear()
}

impl SpectralPatch {
    /// Solves the patch for `conds` (data slots `(v, t)`) over `domain` at time `t`.
    pub fn new(conds: &[Condition], domain: VDomain, opts: SpectralOptions) -> Result<Self, SpectralError> {
        crate::solves::record(crate::solves::SolveKind::Spectral);
        // one entry into the thread pool for the analysis and the cardinal sets (see
        // `grid_products`)
        rayon::scope(|_| Self::new_in_pool(conds, domain, opts))
    }

    fn new_in_pool(conds: &[Condition], domain: VDomain, opts: SpectralOptions) -> Result<Self, SpectralError> {
        if conds.len() < 2 || !conds.len().is_multiple_of(2) {
            return Err(SpectralError::Options(format!(
                "a PDE of order 2N needs 2N conditions (an even number ≥ 2); got {}",
                conds.len()
            )));
        }
        if !(opts.a.is_finite() && opts.a > 0.0) {
            return Err(SpectralError::Options(format!("the shape parameter a = {} must be positive", opts.a)));
        }
        let n = conds.len() / 2;
        let omega = opts.omega.unwrap_or(opts.a * (opts.modes + 1) as f64);
        if !(omega.is_finite() && omega > 0.0) {
            return Err(SpectralError::Options(match opts.omega {
                Some(w) => format!("the remainder rate ω = {w} must be positive and finite"),
                None => format!(
                    "the remainder rate ω = a·(M + 1) = {} · {} overflows; lower the shape parameter a",
                    opts.a,
                    opts.modes + 1
                ),
            }));
        }
        // a rate r puts the data's reach at 1/r of the domain: past 1e6 the whole patch is
        // a boundary layer thinner than any mesh or fit resolves (and a·M overflows the
        // exponentials long before it is infinite)
        let top = (opts.a * opts.modes as f64).max(omega);
        if top > MAX_RATE {
            return Err(SpectralError::Options(format!(
                "the exponential rate {top:e} (a·M = {:e}, ω = {omega:e}) is above {MAX_RATE:e}: the boundary data would reach less than 1e-6 of the domain; lower a or ω",
                opts.a * opts.modes as f64
            )));
        }
        let specs: Vec<CondSpec> = conds.iter().map(|c| CondSpec { u: c.u, order: c.order }).collect();
        let dmax = specs.iter().map(|c| c.order).max().unwrap_or(0);
        // Tabulate what evaluation needs (normals, curvature, conditions); the 2N-th
        // derivatives for the PDE residual, where affordable, only when asked for.
        let kmax = dmax.max(2);
        let (data, dtheta_dv): (Vec<FieldRef>, f64) = if domain.periodic {
            (conds.iter().map(|c| c.data.clone()).collect(), 1.0)
        } else {
            (
                conds
                    .iter()
                    .map(|c| Arc::new(EvenExtension::new(c.data.clone(), domain.start, domain.end)) as FieldRef)
                    .collect(),
                PI / (domain.end - domain.start),
            )
        };
        let samples = sample_count(opts.modes);
        let degrees: Vec<Option<usize>> =
            data.iter().map(|d| finite_series(d, opts.modes).filter(|_| domain.periodic)).collect();
        let exact_series = degrees.iter().all(Option::is_some);
        let kept = if exact_series { degrees.iter().flatten().copied().max().unwrap_or(0) } else { opts.modes };
        let series: Vec<FourierSeries> = data
            .par_iter()
            .zip(&degrees)
            .map(|(g, d)| {
                let mut s = FourierSeries::analyse(|th| g.eval(&[th, 0.0]), opts.modes, samples);
                // a proved degree d: the coefficients above d are zero, not their round-off
                if let Some(d) = *d {
                    for n in d + 1..s.a.len() {
                        (s.a[n], s.b[n]) = (Vec3::ZERO, Vec3::ZERO);
                    }
                }
                s
            })
            .collect();
        let what = describe(&specs);
        let cards: Vec<Arc<CardinalSet>> = (0..=kept)
            .into_par_iter()
            .map(|m| {
                crate::cancel::checkpoint();
                cardinal_set(opts.a * m as f64, n, &specs, kmax).map_err(|source| SpectralError::Conditions {
                    mode: m.to_string(),
                    what: what.clone(),
                    source,
                })
            })
            .collect::<Result<_, _>>()?;
        let rem = if exact_series {
            None
        } else {
            Some(cardinal_set(omega, n, &specs, kmax).map_err(|source| SpectralError::Conditions {
                mode: format!("ω = {omega}"),
                what,
                source,
            })?)
        };
        Ok(SpectralPatch {
            domain,
            dtheta_dv,
            n,
            opts,
            omega,
            conds: specs,
            series,
            cards,
            rem,
            kept,
            deep_kmax: if n <= 10 { 2 * n } else { 0 },
            deep: OnceLock::new(),
            time: 0.0,
            cache: BoundedMemo::new(4096),
            poly0: OnceLock::new(),
            folded: OnceLock::new(),
            folded2: OnceLock::new(),
            exact: degrees.iter().map(Option::is_some).collect(),
            exact_series,
            data,
        })
    }

    /// PDE order `2N`.
    pub fn order(&self) -> usize {
        2 * self.n
    }

    /// The options it was solved with.
    pub fn options(&self) -> SpectralOptions {
        self.opts
    }

    /// The remainder rate `ω` in force.
    pub fn omega(&self) -> f64 {
        self.omega
    }

    /// Diagnostics.
    pub fn report(&self) -> SpectralReport {
        let max_mode_condition = self.cards.iter().map(|c| c.condition_number()).max_nan();
        let mp = self.cards.iter().filter(|c| matches!(c.as_ref(), CardinalSet::Tabulated(_))).count();
        SpectralReport {
            order: 2 * self.n,
            modes: self.opts.modes,
            omega: self.omega,
            max_mode_condition,
            methods: (self.cards.len() - mp, mp),
            kept: self.kept,
            mode_paths: self.sets_or_none().map(|c| c.map_or(NO_DATA, |c| c.method())).collect(),
            mode_residuals: self.sets_or_none().map(|c| c.map_or(0.0, |c| c.residual())).collect(),
            lebesgue: (self.cards[0].lebesgue(400), self.cards.get(1).map(|c| c.lebesgue(400))),
        }
    }

    /// The cardinal set of every mode `0 … M` and of the remainder, none where there are
    /// no data.
    fn sets_or_none(&self) -> impl Iterator<Item = Option<&Arc<CardinalSet>>> {
        (0..=self.opts.modes).map(|m| self.cards.get(m)).chain([self.rem.as_ref()])
    }

    /// Drops the per-row cache (rows are recomputed on the next evaluation).
    pub fn clear_row_cache(&self) {
        self.cache.clear();
    }

    fn theta(&self, v: f64) -> f64 {
        if self.domain.periodic { v } else { (v - self.domain.start) * self.dtheta_dv }
    }

    /// Cardinal sets that hold derivatives up to `k` if any do: the solve's, or the ones
    /// tabulated to `deep_kmax` on demand.
    fn sets(&self, k: usize) -> (&[Arc<CardinalSet>], Option<&Arc<CardinalSet>>) {
        let fast = self.cards.iter().chain(&self.rem).all(|c| c.kmax() >= k);
        if fast || k > self.deep_kmax {
            return (&self.cards, self.rem.as_ref());
        }
        let deep = self.deep.get_or_init(|| {
            let (n, a, kk) = (self.n, self.opts.a, self.deep_kmax);
            let cards: Option<Vec<_>> =
                (0..=self.kept).into_par_iter().map(|m| cardinal_set(a * m as f64, n, &self.conds, kk).ok()).collect();
            let rem = match self.rem {
                Some(_) => Some(cardinal_set(self.omega, n, &self.conds, kk).ok()?),
                None => None,
            };
            Some((cards?, rem))
        });
        match deep {
            Some((c, r)) => (c, r.as_ref()),
            None => (&self.cards, self.rem.as_ref()),
        }
    }

    /// The remainder's cardinal functions at `u` (derivatives to `k`), zeros without a
    /// remainder.
    fn rem_row(&self, rem: Option<&Arc<CardinalSet>>, u: f64, k: usize) -> Vec<Vec<f64>> {
        rem.map_or_else(|| vec![vec![0.0; self.conds.len()]; k + 1], |r| r.eval(u, k))
    }

    /// Mode `m`'s weights for [`Combined`]: per condition, the data's cosine and sine
    /// coefficients of order `m`, three components each.
    fn mode_weights(&self, m: usize) -> Vec<f64> {
        self.series
            .iter()
            .flat_map(|s| {
                let (a, b) = (s.a[m], s.b[m]);
                [a.x, a.y, a.z, b.x, b.y, b.z]
            })
            .collect()
    }

    /// Mode 0 folded, when its functions are polynomials.
    fn poly0(&self) -> Option<&Combined> {
        self.poly0.get_or_init(|| Combined::polynomial(&self.cards[0], self.mode_weights(0), 6)).as_ref()
    }

    /// Every mode's cardinal functions at `u` (derivatives to `k`), mode 0's left empty when
    /// `skip0` (it is folded).
    fn mode_rows(cards: &[Arc<CardinalSet>], u: f64, k: usize, skip0: bool) -> Vec<Vec<Vec<f64>>> {
        cards.iter().enumerate().map(|(m, card)| if m == 0 && skip0 { Vec::new() } else { card.eval(u, k) }).collect()
    }

    fn row(&self, u: f64, k: usize) -> Arc<Row> {
        let key = (u.to_bits(), k);
        if let Some(r) = self.cache.get(&key) {
            return r;
        }
        let (cards, rem) = self.sets(k);
        let modes = Self::mode_rows(cards, u, k, self.poly0().is_some());
        let row = Arc::new(self.row_from(u, &modes, self.rem_row(rem, u, k), k));
        self.cache.insert(key, row.clone());
        row
    }

    /// The row at `u` from each mode's cardinal functions `modes[mode][kk][i] = ℓ_i^{(kk)}(u)`
    /// (modes `0 … kept` are read; mode 0 from [`poly0`](Self::poly0) when it is folded) and
    /// the remainder's `l`: the modes folded with the data's Fourier coefficients.
    fn row_from(&self, u: f64, modes: &[Vec<Vec<f64>>], l: Vec<Vec<f64>>, k: usize) -> Row {
        let m = self.kept;
        let mut a = vec![vec![Vec3::ZERO; m + 1]; k + 1];
        let mut b = vec![vec![Vec3::ZERO; m + 1]; k + 1];
        for (mode, lm) in modes.iter().take(m + 1).enumerate() {
            for (kk, lk) in lm.iter().enumerate() {
                for (i, s) in self.series.iter().enumerate() {
                    a[kk][mode] += s.a[mode] * lk[i];
                    b[kk][mode] += s.b[mode] * lk[i];
                }
            }
        }
        if let Some(p0) = self.poly0() {
            let mut scratch = vec![0.0; p0.scratch_len()];
            let mut out = vec![0.0; (k + 1) * 6];
            p0.eval(u, k, None, &[], &mut scratch, &mut out);
            for (kk, r) in out.chunks_exact(6).enumerate() {
                a[kk][0] = Vec3::new(r[0], r[1], r[2]);
                b[kk][0] = Vec3::new(r[3], r[4], r[5]);
            }
        }
        Row { a, b, l }
    }

    /// Fills the row caches of `patches` at every `u` of `us` (derivatives to `k`) from one
    /// evaluation of the cardinal functions a `u`. Patches solved for the same conditions'
    /// places and orders, `a`, `M` and `ω` share their cardinal sets (process-wide) and differ
    /// in their data alone — the members of a fill family (those whose data are all proved
    /// trigonometric polynomials have fewer modes and no remainder: the first of the
    /// others'). A patch whose sets are not the reference's (the one with the most) is left
    /// to compute its own rows. The rows are those [`row`](Self::row) computes, bit for bit
    /// (the same sums in the same order).
    pub fn share_rows(patches: &[&SpectralPatch], us: &[f64], k: usize) {
        let Some(reference) = patches.iter().copied().max_by_key(|p| (p.rem.is_some(), p.kept)) else { return };
        let (cards, rem) = reference.sets(k);
        let same = |p: &SpectralPatch| {
            let (c, r) = p.sets(k);
            let rem_shared = match (r, rem) {
                (Some(r), Some(rem)) => Arc::ptr_eq(r, rem),
                (r, _) => r.is_none(),
            };
            rem_shared && c.len() <= cards.len() && c.iter().zip(cards).all(|(x, y)| Arc::ptr_eq(x, y))
        };
        let sharing: Vec<&SpectralPatch> = patches.iter().copied().filter(|p| same(p)).collect();
        // mode 0's set is shared, so it is folded in all of them or in none
        let skip0 = sharing.iter().all(|p| p.poly0().is_some());
        for &u in us {
            let key = (u.to_bits(), k);
            if sharing.iter().all(|p| p.cache.get(&key).is_some()) {
                continue;
            }
            let modes = SpectralPatch::mode_rows(cards, u, k, skip0);
            let l = reference.rem_row(rem, u, k);
            for p in &sharing {
                let l = if p.rem.is_some() { l.clone() } else { p.rem_row(None, u, k) };
                p.cache.insert(key, Arc::new(p.row_from(u, &modes, l, k)));
            }
        }
    }

    /// `(cos nθ, sin nθ)` for `n = 0 … kept` (`M` whenever a datum's tails are summed).
    fn trig(&self, theta: f64) -> Vec<(f64, f64)> {
        (0..=self.kept).map(|n| (n as f64 * theta).sin_cos()).map(|(s, c)| (c, s)).collect()
    }

    /// `r_i^{(j)}(θ)` for every condition, `j = 0 … jmax` (θ-derivatives); none at all when
    /// every datum's tails are zero (`exact_series`).
    fn tails(&self, theta: f64, jmax: usize) -> Vec<Vec<Vec3>> {
        self.tails_with(theta, &self.trig(theta), jmax)
    }

    /// [`tails`](Self::tails) with `cs = trig(θ)` given.
    fn tails_with(&self, theta: f64, cs: &[(f64, f64)], jmax: usize) -> Vec<Vec<Vec3>> {
        if self.exact_series {
            return Vec::new();
        }
        let data: Vec<Option<Vec<Vec3>>> = self
            .data
            .iter()
            .zip(&self.exact)
            .map(|(g, &exact)| {
                (!exact).then(|| {
                    let mut d = vec![Vec3::ZERO; jmax + 1];
                    g.derivatives_in(&[theta, self.time], 0, &mut d);
                    d
                })
            })
            .collect();
        self.tails_from(cs, jmax, |c| data[c].as_deref())
    }

    /// The tails `r_c^{(j)} = g_c^{(j)} − (series of g_c)^{(j)}` at a `θ` with
    /// `cs = trig(θ)`, from each datum's derivatives `data(c)` there (`j = 0 … jmax`);
    /// `None` for a datum proved a finite series, whose tails are zero.
    fn tails_from<'a>(
        &self,
        cs: &[(f64, f64)],
        jmax: usize,
        data: impl Fn(usize) -> Option<&'a [Vec3]>,
    ) -> Vec<Vec<Vec3>> {
        self.series
            .iter()
            .enumerate()
            .map(|(c, s)| match data(c) {
                None => vec![Vec3::ZERO; jmax + 1],
                Some(d) => {
                    let series = s.derivatives_from(cs, jmax);
                    d.iter().zip(&series).map(|(&x, &f)| x - f).collect()
                }
            })
            .collect()
    }

    /// `∂^{i+j}X/∂uⁱ∂θʲ` at one point, from a cached row and the tails at θ.
    fn combine(&self, row: &Row, tails: &[Vec<Vec3>], theta: f64, i: usize, j: usize) -> Vec3 {
        let mut s = Vec3::ZERO;
        for n in 0..=self.kept {
            let nf = n as f64;
            if n == 0 {
                if j == 0 {
                    s += row.a[i][0];
                }
                continue;
            }
            let ph = nf * theta + j as f64 * PI / 2.0;
            let f = nf.powi(j as i32);
            let (sn, cs) = ph.sin_cos();
            s += (row.a[i][n] * cs + row.b[i][n] * sn) * f;
        }
        for (c, t) in tails.iter().enumerate() {
            s += t[j] * row.l[i][c];
        }
        s
    }

    /// The remainder term `R(u, v) = Σ_i ℓ_i^{(ω)}(u) r_i(θ)`: the part of the patch that is
    /// not an exact Fourier solution of the PDE. It tends to zero with `M` for continuous
    /// data (uniformly, as the Fourier tails `r_i` do).
    pub fn remainder(&self, u: f64, v: f64) -> Vec3 {
        let Some(rem) = &self.rem else { return Vec3::ZERO };
        let theta = self.theta(v);
        let l = rem.eval(u, 0);
        self.tails(theta, 0).iter().zip(&l[0]).map(|(t, w)| t[0] * *w).sum()
    }

    /// The PDE residual `(∂u² + a²∂θ²)^N` at `(u, v)` of the truncated solution `X̃`, of the
    /// remainder `R` and of the whole `X` (norms of the vector residuals). The truncated
    /// part needs the `2N`-th derivatives of every mode's cardinal functions, which are
    /// tabulated only for `N ≤ 10`; above that the parts are `None` (not computed, not assumed).
    pub fn residual(&self, u: f64, v: f64) -> Residual {
        let n = self.n;
        let k = 2 * n;
        let theta = self.theta(v);
        let binom = |n: usize, k: usize| (0..k).fold(1.0, |acc, i| acc * (n - i) as f64 / (i + 1) as f64);
        let a2 = self.opts.a * self.opts.a;
        let (cards, rem_set) = self.sets(k);
        let trunc = cards.iter().all(|c| c.kmax() >= k).then(|| {
            let row = self.row(u, k);
            let zero_tails: Vec<Vec<Vec3>> = vec![vec![Vec3::ZERO; k + 1]; self.conds.len()];
            let mut r = Vec3::ZERO;
            for q in 0..=n {
                let w = binom(n, q) * a2.powi((n - q) as i32);
                r += self.combine(&row, &zero_tails, theta, 2 * q, 2 * (n - q)) * w;
            }
            r
        });
        // no remainder (every datum a proved trigonometric polynomial): R ≡ 0
        let rem = rem_set.map_or(Some(Vec3::ZERO), |rem_set| {
            (rem_set.kmax() >= k).then(|| {
                let l = rem_set.eval(u, k);
                let tails = self.tails(theta, k);
                let mut rem = Vec3::ZERO;
                for q in 0..=n {
                    let w = binom(n, q) * a2.powi((n - q) as i32);
                    for (c, t) in tails.iter().enumerate() {
                        rem += t[2 * (n - q)] * (l[2 * q][c] * w);
                    }
                }
                rem
            })
        });
        Residual {
            truncated: trunc.map(|t| t.norm()),
            remainder: rem.map(|r| r.norm()),
            whole: trunc.zip(rem).map(|(t, r)| (t + r).norm()),
        }
    }
}

/// PDE residual norms at a point (see [`SpectralPatch::residual`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Residual {
    /// Of the truncated Fourier solution (zero up to round-off by construction).
    pub truncated: Option<f64>,
    /// Of the remainder term.
    pub remainder: Option<f64>,
    /// Of the whole patch.
    pub whole: Option<f64>,
}

impl Surface for SpectralPatch {
    fn v_domain(&self) -> VDomain {
        self.domain
    }

    fn derivatives(&self, u: f64, v: f64, du: usize, dv: usize) -> Vec<Vec3> {
        let theta = self.theta(v);
        let row = self.row(u, du);
        let tails = self.tails(theta, dv);
        let mut out = Vec::with_capacity((du + 1) * (dv + 1));
        for i in 0..=du {
            for j in 0..=dv {
                out.push(self.combine(&row, &tails, theta, i, j) * self.dtheta_dv.powi(j as i32));
            }
        }
        out
    }

    fn points_at(&self, uv: &[[f64; 2]], out: &mut [Vec3]) {
        let mut o = vec![[Vec3::ZERO]; uv.len()];
        self.scattered(uv, [(0, 0)], &mut o);
        for (d, s) in out.iter_mut().zip(o) {
            *d = s[0];
        }
    }

    fn firsts_at(&self, uv: &[[f64; 2]], out: &mut [[Vec3; 3]]) {
        self.scattered(uv, [(0, 0), (1, 0), (0, 1)], out);
    }

    fn seconds_at(&self, uv: &[[f64; 2]], out: &mut [[Vec3; 6]]) {
        self.scattered(uv, [(0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2)], out);
    }

    fn grid(&self, us: &[f64], vs: &[f64]) -> Vec<[Vec3; 4]> {
        self.grid_products(us, vs, [(0, 0), (1, 0), (0, 1), (1, 1)])
    }

    fn grid_values(&self, us: &[f64], vs: &[f64]) -> Vec<Vec3> {
        self.grid_products(us, vs, [(0, 0)]).into_iter().map(|[x]| x).collect()
    }

    fn grid2(&self, us: &[f64], vs: &[f64]) -> Vec<[Vec3; 6]> {
        self.grid_products(us, vs, [(0, 0), (1, 0), (0, 1), (2, 0), (1, 1), (0, 2)])
    }
}

/// Per-column data of the grid evaluations: `(cos nθ, sin nθ)` and the boundary tails with
/// their θ-derivatives.
struct GridColumn {
    cs: Vec<(f64, f64)>,
    tails: Vec<Vec<Vec3>>,
}

impl SpectralPatch {
    /// `∂^{i+j}X/∂uⁱ∂vʲ` for each `(i, j)` of `orders` on the grid `us × vs` (row-major in
    /// `u`), as dense matrix products. Per component `x`,
    ///
    /// `∂uⁱ∂θʲ X_x = Rᵢ · Qⱼ`, `Rᵢ = [a⁽ⁱ⁾₀ₓ(u) | a⁽ⁱ⁾ₙₓ(u) | b⁽ⁱ⁾ₙₓ(u) | ℓ⁽ⁱ⁾_c(u)]` (a row per `u`),
    /// `Qⱼ = [δⱼ₀ ; ∂θʲ cos nθ ; ∂θʲ sin nθ ; r⁽ʲ⁾_{c,x}(θ)]` (a column per `v`),
    ///
    /// with `n = 1 … kept` and `c` the conditions whose data are not proved trigonometric
    /// polynomials (the remainder's cardinal functions times the Fourier tails). The mode functions are computed once per `u`, the data once per `v`;
    /// the products run in faer's GEMM, one per order and component, in parallel.
    fn grid_products<const D: usize>(&self, us: &[f64], vs: &[f64], orders: [(usize, usize); D]) -> Vec<[Vec3; D]> {
        // One entry into the thread pool for the whole grid: called from outside the pool,
        // each parallel step below would otherwise be a separate hand-over to the workers
        // (a wake-up each, measurable on 100 × 100 grids).
        rayon::scope(|_| self.grid_products_in_pool(us, vs, orders))
    }

    fn grid_products_in_pool<const D: usize>(
        &self,
        us: &[f64],
        vs: &[f64],
        orders: [(usize, usize); D],
    ) -> Vec<[Vec3; D]> {
        let (nu, nv) = (us.len(), vs.len());
        let mut out = vec![[Vec3::ZERO; D]; nu * nv];
        if nu == 0 || nv == 0 {
            return out;
        }
        let imax = orders.iter().map(|o| o.0).max().unwrap_or(0);
        let jmax = orders.iter().map(|o| o.1).max().unwrap_or(0);
        let cols = self.grid_columns(vs, jmax);
        let rows: Vec<Arc<Row>> = us
            .par_iter()
            .map(|&u| {
                crate::cancel::checkpoint();
                self.row(u, imax)
            })
            .collect();
        // the modes with data, and a tail column for each datum not proved a trigonometric
        // polynomial (the others' tails are zero)
        let m = self.kept;
        let tailc: Vec<usize> = (0..self.conds.len()).filter(|&c| !self.exact[c]).collect();
        let width = 1 + 2 * m + tailc.len();
        // R and Q written row by row and column by column (each row's and column's data
        // read once; the same numbers as entry by entry)
        let r_mat = |i: usize, x: usize| {
            let mut r = Mat::<f64>::zeros(nu, width);
            for (ui, row) in rows.iter().enumerate() {
                let (a, b, l) = (&row.a[i], &row.b[i], &row.l[i]);
                r[(ui, 0)] = a[0][x];
                for n in 1..=m {
                    r[(ui, n)] = a[n][x];
                    r[(ui, m + n)] = b[n][x];
                }
                for (k, &c) in tailc.iter().enumerate() {
                    r[(ui, 2 * m + 1 + k)] = l[c];
                }
            }
            r
        };
        let q_mat = |j: usize, x: usize| {
            let k = self.dtheta_dv.powi(j as i32);
            let mut q = Mat::<f64>::zeros(width, nv);
            for (vi, col) in cols.iter().enumerate() {
                let dst = q.col_as_slice_mut(vi);
                dst[0] = k * f64::from(j == 0);
                for n in 1..=m {
                    // ∂θʲ (cos nθ, sin nθ) = nʲ (cos, sin)(nθ + jπ/2): a quarter turn per order
                    let (c, s) = batch::turn(col.cs[n], j);
                    let nj = (n as f64).powi(j as i32);
                    dst[n] = k * (nj * c);
                    dst[m + n] = k * (nj * s);
                }
                for (t, &c) in tailc.iter().enumerate() {
                    dst[2 * m + 1 + t] = k * col.tails[c][j][x];
                }
            }
            q
        };
        // R and Q once per order and component; the products transposed (`Pᵀ = Qᵀ Rᵀ`, a
        // column per `u`) so that each grid row is read as a contiguous column.
        let rs: Vec<Mat<f64>> = (0..(imax + 1) * 3).into_par_iter().map(|t| r_mat(t / 3, t % 3)).collect();
        let qs: Vec<Mat<f64>> = (0..(jmax + 1) * 3).into_par_iter().map(|t| q_mat(t / 3, t % 3)).collect();
        let products: Vec<Mat<f64>> = (0..D * 3)
            .into_par_iter()
            .map(|t| {
                crate::cancel::checkpoint();
                let (d, x) = (t / 3, t % 3);
                let (i, j) = orders[d];
                let (r, q) = (&rs[i * 3 + x], &qs[j * 3 + x]);
                let mut pt = Mat::<f64>::zeros(nv, nu);
                faer::linalg::matmul::matmul(
                    pt.as_mut(),
                    faer::Accum::Replace,
                    q.transpose(),
                    r.transpose(),
                    1.0,
                    faer::Par::Seq,
                );
                crate::lanes::clear_upper();
                pt
            })
            .collect();
        out.par_chunks_mut(nv).enumerate().for_each(|(ui, dst)| {
            for (t, pt) in products.iter().enumerate() {
                let (d, x) = (t / 3, t % 3);
                for (o, &v) in dst.iter_mut().zip(pt.col_as_slice(ui)) {
                    o[d][x] = v;
                }
            }
        });
        out
    }

    /// The columns' `(cos nθ, sin nθ)` and tails ([`tails_with`](Self::tails_with)'s
    /// numbers), each unproved datum evaluated at all the columns' `θ` in blocks of
    /// [`DATA_BLOCK`] through `Field::derivatives_in_many` (data carried on another patch —
    /// a fin's root curve on the body — evaluate that patch in a batch there).
    fn grid_columns(&self, vs: &[f64], jmax: usize) -> Vec<GridColumn> {
        let ths: Vec<f64> = vs.iter().map(|&v| self.theta(v)).collect();
        let k = jmax + 1;
        let at: Vec<f64> = ths.iter().flat_map(|&th| [th, self.time]).collect();
        let data: Vec<Option<Vec<Vec3>>> = if self.exact_series {
            Vec::new()
        } else {
            self.data
                .iter()
                .zip(&self.exact)
                .map(|(g, &exact)| {
                    (!exact).then(|| {
                        let mut d = vec![Vec3::ZERO; ths.len() * k];
                        at.par_chunks(2 * DATA_BLOCK)
                            .zip(d.par_chunks_mut(k * DATA_BLOCK))
                            .for_each(|(a, o)| g.derivatives_in_many(a, 2, 0, k, o));
                        d
                    })
                })
                .collect()
        };
        ths.par_iter()
            .enumerate()
            .map(|(c, &th)| {
                let cs = self.trig(th);
                let tails = if self.exact_series {
                    Vec::new()
                } else {
                    self.tails_from(&cs, jmax, |i| data[i].as_ref().map(|d| &d[c * k..(c + 1) * k]))
                };
                GridColumn { cs, tails }
            })
            .collect()
    }
}

/// Grid columns whose data one `Field::derivatives_in_many` call evaluates.
const DATA_BLOCK: usize = 64;

mod batch;
#[cfg(test)]
mod tests;
