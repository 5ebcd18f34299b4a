//! A spectral patch at scattered points, in batches: no row cache, no lock, no allocation
//! per point.
//!
//! With `θ(v)` and the patch written as in the module docs,
//!
//! ```text
//! ∂uⁱ∂θʲ X = Σ_n [A_n^{(i)}(u) ∂θʲ cos nθ + B_n^{(i)}(u) ∂θʲ sin nθ] + Σ_c ℓ_c^{(ω,i)}(u) r_c^{(j)}(θ),
//! A_n = Σ_c ℓ_c^{(n)} a_{c,n},  B_n = Σ_c ℓ_c^{(n)} b_{c,n},  r_c = g_c − F_M[g_c].
//! ```
//!
//! Each mode's six functions `(A_n, B_n)` are folded once into the mode's own basis
//! ([`Combined`]): a point costs, per mode, the basis at `u` and a `basis × 6` product,
//! instead of every cardinal function and a sum over the conditions (the exponential basis
//! goes through the cardinal functions still, in the pointwise order: its functions are
//! far from orthogonal for slow modes, and the folded sums moved by 1e-13). Exponentials
//! of the modes `c = a n` come as products of `e^{a(u−1)}` and `e^{−au}` (exact `exp`
//! every 8th mode, so the products' round-off stays ≤ 8 ulps). The boundary data `g_c`
//! are evaluated for a block of points at once: in one tape for all conditions when they
//! are expression fields (shared sub-expressions once), else
//! [`crate::data::Field::derivatives_in_many`]. A point's numbers do not depend on the
//! other points of the batch. The result is the pointwise
//! [`Surface::derivatives`](crate::patch::Surface::derivatives) reassociated: equal to
//! round-off, which the tests measure on every kind of cardinal set and every example.

use super::SpectralPatch;
use crate::Vec3;
use crate::data::FieldRef;
use crate::expr::Tape;
use crate::ode::{Combined, chebyshev_t};
use crate::taylor::Taylor;

/// Points per block: the data are evaluated for a block at once.
const BLOCK: usize = 256;

/// Highest `u`-derivative folded for values and first derivatives.
pub(super) const KMAX: usize = 1;

/// Highest `u`-derivative of the second folding, made on the first call that asks for
/// second derivatives (a local maximisation's Newton steps): the first keeps its tables
/// and its cost, and its numbers do not depend on whether seconds were ever asked for.
pub(super) const KMAX2: usize = 2;

/// Every mode's `(A_n, B_n)` and the remainder's cardinal functions, folded.
pub(super) struct Folded {
    modes: Vec<Combined>,
    /// None when the patch has no remainder (every datum a proved trigonometric polynomial).
    rem: Option<Combined>,
    /// All the conditions' data in one tape, when they are expression fields in the same
    /// variables (at most `v, t`): what the sections share (`cos v`, `sin v`) is computed
    /// once per point, not once per section.
    joint: Option<Tape>,
}

/// One tape for every field's three components, if every field is an expression field
/// over the same variables, at most two (`v`, `t`).
fn joint_tape(data: &[FieldRef]) -> Option<Tape> {
    let (_, vars) = data.first()?.expressions()?;
    if vars.len() > 2 {
        return None;
    }
    let mut exprs = Vec::with_capacity(3 * data.len());
    for d in data {
        let (comps, v) = d.expressions()?;
        if v != vars {
            return None;
        }
        exprs.extend(comps.iter());
    }
    Some(Tape::compile(&exprs))
}

/// `g[(c·blk + k)·nj + j] = ∂θʲ g_c` at the block's points `at` (`θ, t` pairs) from the
/// joint tape, in Taylor series of length `N = nj`.
fn joint_taylor<const N: usize>(tape: &Tape, at: &[f64], blk: usize, g: &mut [Vec3]) {
    let mut regs = Vec::new();
    for (k, p) in at.chunks_exact(2).enumerate() {
        let vars = [Taylor::<N>::variable(p[0]), Taylor::constant(p[1])];
        let o = tape.eval(&vars, &Taylor::constant(0.0), &mut regs);
        for c in 0..g.len() / (blk * N) {
            let (x, y, z) = (&o[3 * c], &o[3 * c + 1], &o[3 * c + 2]);
            for j in 0..N {
                g[(c * blk + k) * N + j] = Vec3::new(x.derivative(j), y.derivative(j), z.derivative(j));
            }
        }
    }
}

impl Folded {
    pub(super) fn new(p: &SpectralPatch, kmax: usize) -> Folded {
        let nc = p.conds.len();
        // mode 0, when polynomial, is the rows' own folding (every order already folded)
        let modes = p
            .cards
            .iter()
            .enumerate()
            .map(|(m, card)| match p.poly0() {
                Some(c) if m == 0 => c.clone(),
                _ => Combined::new(card, p.mode_weights(m), 6, kmax),
            })
            .collect();
        let eye: Vec<f64> = (0..nc * nc).map(|k| f64::from(k / nc == k % nc)).collect();
        let rem = p.rem.as_ref().map(|r| Combined::new(r, eye, nc, kmax));
        Folded { modes, rem, joint: joint_tape(&p.data) }
    }
}

/// `(cos, sin)(φ + jπ/2)` from `(cos φ, sin φ)`: a quarter turn per order.
#[inline]
pub(super) fn turn((c, s): (f64, f64), j: usize) -> (f64, f64) {
    match j % 4 {
        0 => (c, s),
        1 => (-s, c),
        2 => (-c, -s),
        _ => (s, -c),
    }
}

/// `nʲ` (exact for the small `j` asked for here).
#[inline]
fn npow(n: usize, j: usize) -> f64 {
    match j {
        0 => 1.0,
        1 => n as f64,
        _ => (n as f64).powi(j as i32),
    }
}

impl SpectralPatch {
    /// The folding for `u`-derivatives up to `imax` (at most [`KMAX2`]).
    fn folded(&self, imax: usize) -> &Folded {
        if imax <= KMAX {
            self.folded.get_or_init(|| Folded::new(self, KMAX))
        } else {
            self.folded2.get_or_init(|| Folded::new(self, KMAX2))
        }
    }

    /// `out[p][d] = ∂^{i+j}X/∂uⁱ∂vʲ (uv[p])` for `(i, j) = orders[d]`, `i ≤ 1`, on the
    /// calling thread.
    pub(super) fn scattered<const D: usize>(
        &self,
        uv: &[[f64; 2]],
        orders: [(usize, usize); D],
        out: &mut [[Vec3; D]],
    ) {
        assert_eq!(uv.len(), out.len(), "one output per point");
        let imax = orders.iter().map(|o| o.0).max().unwrap_or(0);
        let jmax = orders.iter().map(|o| o.1).max().unwrap_or(0);
        assert!(imax <= KMAX2, "u-derivatives up to {KMAX2} at scattered points");
        let f = self.folded(imax);
        let (m, nc, nj) = (self.kept, self.conds.len(), jmax + 1);
        let a = self.opts.a;
        let scratch_len = f.modes.iter().chain(&f.rem).map(Combined::scratch_len).max().unwrap_or(0);
        let mut scratch = vec![0.0; scratch_len];
        // T_m(2u − 1) once per point for every Chebyshev combination
        let rem_terms = f.rem.as_ref().map_or(0, Combined::chebyshev_terms);
        let terms = f.modes.iter().map(Combined::chebyshev_terms).chain([rem_terms]).max().unwrap_or(0);
        let mut cheb = vec![0.0; if terms > 0 { terms.max(2) } else { 0 }];
        let mut fold = vec![0.0; (imax + 1) * 6];
        let mut lrem = vec![0.0; (imax + 1) * nc];
        let mut cs = vec![(1.0, 0.0); m + 1];
        let mut tails = vec![Vec3::ZERO; nc * nj];
        // the block's length: a call for a few points (a local ascent's steps) allocates
        // for those alone
        let blk = BLOCK.min(uv.len()).max(1);
        let mut at = Vec::with_capacity(2 * blk);
        // the data of a block (none when the series are exact: nothing reads them)
        let mut g = vec![Vec3::ZERO; if self.exact_series { 0 } else { nc * blk * nj }];
        let scale: [f64; 4] = std::array::from_fn(|j| self.dtheta_dv.powi(j as i32));
        for (pts, dst) in uv.chunks(blk).zip(out.chunks_mut(blk)) {
            crate::cancel::checkpoint();
            let b = pts.len();
            at.clear();
            at.extend(pts.iter().flat_map(|p| [self.theta(p[1]), self.time]));
            match (&f.joint, nj) {
                _ if self.exact_series => {}
                (Some(tape), 1) => {
                    let mut regs = Vec::new();
                    for (k, p) in at.chunks_exact(2).enumerate() {
                        let o = tape.eval(p, &0.0, &mut regs);
                        for c in 0..nc {
                            g[c * blk + k] = Vec3::new(o[3 * c], o[3 * c + 1], o[3 * c + 2]);
                        }
                    }
                }
                (Some(tape), 2) => joint_taylor::<2>(tape, &at, blk, &mut g),
                (Some(tape), 3) => joint_taylor::<3>(tape, &at, blk, &mut g),
                _ => {
                    for (c, data) in self.data.iter().enumerate() {
                        data.derivatives_in_many(&at, 2, 0, nj, &mut g[c * blk * nj..][..b * nj]);
                    }
                }
            }
            for (k, (p, o)) in pts.iter().zip(dst.iter_mut()).enumerate() {
                let (u, th) = (p[0], at[2 * k]);
                if !cheb.is_empty() {
                    chebyshev_t(2.0 * u - 1.0, &mut cheb);
                }
                // cos nθ, sin nθ by `sin_cos` for each mode, as the pointwise path: rotations
                // (one `sin_cos`, products after) moved the dolphin's flukes' X_u by 1.6e-14
                // relative (~7 ulps in cos 7θ, amplified by cancelling modes)
                for (n, x) in cs.iter_mut().enumerate().skip(1) {
                    let (s, c) = (n as f64 * th).sin_cos();
                    *x = (c, s);
                }
                let mut acc = [Vec3::ZERO; D];
                // the modes; exponentials of c = a n as products (exact every 8th mode)
                let mut unit: Option<(f64, f64)> = None;
                let mut prev: Option<(f64, f64)> = None;
                for (n, mode) in f.modes.iter().enumerate() {
                    let exps = match mode.rate() {
                        Some(c) if c == a * n as f64 => {
                            let e = match prev {
                                Some((p1, p2)) if n % 8 != 0 => {
                                    let (e1, e2) = *unit.get_or_insert_with(|| ((a * (u - 1.0)).exp(), (-a * u).exp()));
                                    (p1 * e1, p2 * e2)
                                }
                                _ => ((c * (u - 1.0)).exp(), (-c * u).exp()),
                            };
                            prev = Some(e);
                            Some(e)
                        }
                        _ => {
                            prev = None;
                            None
                        }
                    };
                    mode.eval(u, imax, exps, &cheb, &mut scratch, &mut fold);
                    for (d, &(i, j)) in orders.iter().enumerate() {
                        let r = &fold[i * 6..i * 6 + 6];
                        let (av, bv) = (Vec3::new(r[0], r[1], r[2]), Vec3::new(r[3], r[4], r[5]));
                        if n == 0 {
                            if j == 0 {
                                acc[d] += av;
                            }
                            continue;
                        }
                        let (c, s) = turn(cs[n], j);
                        acc[d] += (av * c + bv * s) * npow(n, j);
                    }
                }
                let Some(rem) = &f.rem else {
                    for (d, &(_, j)) in orders.iter().enumerate() {
                        o[d] = acc[d] * if j < 4 { scale[j] } else { self.dtheta_dv.powi(j as i32) };
                    }
                    continue;
                };
                // the Fourier tails of the data, r_c^{(j)} = g_c^{(j)} − F_M[g_c]^{(j)}; zero for
                // a datum proved a trigonometric polynomial, as in the pointwise path
                for (c, s) in self.series.iter().enumerate() {
                    if self.exact[c] {
                        tails[c * nj..(c + 1) * nj].fill(Vec3::ZERO);
                        continue;
                    }
                    for j in 0..nj {
                        let mut sum = if j == 0 { s.a[0] } else { Vec3::ZERO };
                        for (n, ((a, b), &t)) in s.a.iter().zip(&s.b).zip(&cs).enumerate().skip(1) {
                            let (cj, sj) = turn(t, j);
                            sum += (*a * cj + *b * sj) * npow(n, j);
                        }
                        tails[c * nj + j] = g[(c * blk + k) * nj + j] - sum;
                    }
                }
                rem.eval(u, imax, None, &cheb, &mut scratch, &mut lrem);
                for (d, &(i, j)) in orders.iter().enumerate() {
                    let l = &lrem[i * nc..(i + 1) * nc];
                    let mut r = Vec3::ZERO;
                    for (c, &w) in l.iter().enumerate() {
                        r += tails[c * nj + j] * w;
                    }
                    o[d] = (acc[d] + r) * if j < 4 { scale[j] } else { self.dtheta_dv.powi(j as i32) };
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use crate::Vec3;
    use crate::data::{ExprField, FieldRef};
    use crate::num::max_nan;
    use crate::patch::{Condition, Surface, VDomain};
    use crate::spectral::{SpectralOptions, SpectralPatch};
    use std::sync::Arc;

    /// A section curve `k` of a patch: data with every Fourier mode (analytic, not a
    /// finite series), so the remainder is not zero.
    fn curve(k: usize, order: usize) -> FieldRef {
        let s = k as f64 * 0.37;
        let f = |x: &str| x.replace('S', &format!("{s}")).replace('D', &format!("{}", order as f64 + 1.0));
        Arc::new(
            ExprField::parse(
                [
                    &f("(2 + S) * cos(v) * exp(0.3 * sin(v + S)) / D"),
                    &f("(2 - S / 3) * sin(v) + 0.2 * cos(3 * v + S) / D"),
                    &f("S + 0.1 * sin(2 * v) * cos(v) / D"),
                ],
                &["v", "t"],
                &|_| None,
            )
            .expect("parses"),
        )
    }

    /// `2N` conditions: position and derivatives up to `N − 1` at both ends, or
    /// positions at `2N` Chebyshev points.
    fn patch(n: usize, chebyshev: bool, a: f64, modes: usize, domain: VDomain) -> SpectralPatch {
        let conds: Vec<Condition> = if chebyshev {
            (0..2 * n)
                .map(|k| {
                    let u = 0.5 - 0.5 * (std::f64::consts::PI * k as f64 / (2 * n - 1) as f64).cos();
                    Condition { u, order: 0, data: curve(k, 0) }
                })
                .collect()
        } else {
            (0..n)
                .flat_map(|d| [(0.0, d), (1.0, d)])
                .enumerate()
                .map(|(k, (u, order))| Condition { u, order, data: curve(k, order) })
                .collect()
        };
        SpectralPatch::new(&conds, domain, SpectralOptions { a, modes, omega: None }).expect("solves")
    }

    /// Largest `|batched − pointwise|` over the points relative to the largest
    /// `|pointwise|`, for the value, `X_u`, `X_v` (from `firsts_at`) and `X_uu`, `X_uv`,
    /// `X_vv` (from `seconds_at`, whose value and first derivatives count too).
    fn agreement(p: &SpectralPatch, uv: &[[f64; 2]]) -> [f64; 6] {
        let mut vals = vec![Vec3::ZERO; uv.len()];
        p.points_at(uv, &mut vals);
        let mut firsts = vec![[Vec3::ZERO; 3]; uv.len()];
        p.firsts_at(uv, &mut firsts);
        let mut seconds = vec![[Vec3::ZERO; 6]; uv.len()];
        p.seconds_at(uv, &mut seconds);
        let mut err = [0.0; 6];
        let mut size = [0.0; 6];
        for (k, q) in uv.iter().enumerate() {
            // index i·3 + j of ∂ⁱ_u ∂ʲ_v
            let d = p.derivatives(q[0], q[1], 2, 2);
            let want = [d[0], d[3], d[1], d[6], d[4], d[2]];
            // the values alone and with derivatives: the same sums
            err[0] = max_nan(err[0], (vals[k] - firsts[k][0]).norm());
            for c in 0..6 {
                if c < 3 {
                    err[c] = max_nan(err[c], (firsts[k][c] - want[c]).norm());
                }
                err[c] = max_nan(err[c], (seconds[k][c] - want[c]).norm());
                size[c] = max_nan(size[c], want[c].norm());
            }
        }
        std::array::from_fn(|c| err[c] / size[c])
    }

    /// Pseudo-random points (a fixed LCG), plus every condition's `u` and the domain's ends.
    fn points(n: usize, dom: VDomain, conds_u: &[f64]) -> Vec<[f64; 2]> {
        let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
        let mut next = || {
            x = x.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (x >> 11) as f64 / (1u64 << 53) as f64
        };
        let mut uv: Vec<[f64; 2]> = (0..n).map(|_| [next(), dom.at(next())]).collect();
        for (k, &u) in conds_u.iter().chain(&[0.0, 1.0]).enumerate() {
            uv.push([u, dom.at(k as f64 / 7.0)]);
        }
        uv
    }

    /// Batched and pointwise evaluation agree to round-off at 10⁴ random points, for each
    /// way the cardinal functions are held (exponential basis, polynomials, Chebyshev
    /// series, divided differences of clustered roots, multiple-precision tables), on
    /// closed and open patches, at the condition points too (where the Chebyshev forms
    /// answer from stored rows).
    #[test]
    fn batched_points_equal_pointwise_ones() {
        let cases = [
            ("order 4, ends", patch(2, false, 1.3, 6, VDomain::PERIODIC)),
            ("order 4, a = 0.2 (clustered roots)", patch(2, false, 0.2, 6, VDomain::PERIODIC)),
            ("order 6, ends, 20 modes", patch(3, false, 0.9, 20, VDomain::PERIODIC)),
            ("order 4, open", patch(2, false, 1.1, 8, VDomain::open(-1.0, 2.5))),
            ("order 16, Chebyshev points", patch(8, true, 1.0, 6, VDomain::PERIODIC)),
            ("order 8, derivatives at the ends", patch(4, false, 0.7, 6, VDomain::PERIODIC)),
        ];
        let mut paths = std::collections::BTreeSet::new();
        for (name, p) in &cases {
            let report = p.report();
            paths.extend(report.mode_paths.iter().copied());
            let us: Vec<f64> = p.conds.iter().map(|c| c.u).collect();
            let e = agreement(p, &points(10_000, p.v_domain(), &us));
            for (what, e) in ["value", "X_u", "X_v", "X_uu", "X_uv", "X_vv"].iter().zip(e) {
                // the same products summed in another order (the modes' exponentials as
                // products, cos nθ by rotations): a few ulps; 2.6e-15 seen at most
                assert!(e <= 1e-14, "{name}: {what} differs by {e:e} (relative)");
            }
        }
        let all = ["f64", "f64-ultraspherical", "multiprecision"];
        assert!(all.iter().all(|p| paths.contains(p)), "paths covered: {paths:?}");
    }
}
