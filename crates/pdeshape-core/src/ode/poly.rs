//! Roots of a characteristic polynomial, with multiplicities.
//!
//! Separating a constant-coefficient PDE over a transverse eigenfunction gives an ODE
//! `P(D) y = 0`, `P(s) = Σ_k c_k s^k` with real `c_k`. Its solution space is spanned by
//! `uʲ e^{r u}`, `j < m`, for every root `r` of multiplicity `m`, so the exact solvers need
//! the roots *and* their multiplicities:
//!
//! - exact zero roots are split off first (`c_0 = … = c_{m−1} = 0` exactly: the mode
//!   `μ = 0` of every operator in SPEC §4–5 has `P(s) = c s^{2r}`, whose basis is then the
//!   polynomials of degree `< 2r`, exactly);
//! - the remaining roots are the eigenvalues of the companion matrix (faer's Hessenberg QR),
//!   each polished by complex Newton steps on `P` while they reduce `|P|`;
//! - eigenvalues closer than [`CLUSTER_TOL`] (relative to the root scale) are candidates
//!   for one root of multiplicity = cluster size. An `m`-fold root is perturbed to
//!   `~ε^{1/m}` by any eigenvalue method; the cluster mean is much closer, and since an
//!   `m`-fold root of `P` is a *simple* root of `P^{(m−1)}`, Newton steps on `P^{(m−1)}`
//!   from the mean recover it to round-off. The candidates merge (closest first) only
//!   when `P … P^{(m−2)}` vanish at the polished mean to round-off ([`MULTIPLE_TOL`]):
//!   two *distinct* roots `δ` apart would leave `P ~ δ²` there, and merging them would put
//!   an `O(δ²)` error into the ODE (2e-8 at `δ = 1e-4`, measured). Distinct roots that
//!   close stay apart; the divided-difference basis of [`super::ExpSpace`] keeps them well
//!   conditioned. Merged clusters are reported by [`PolyRoots::merged`].
//!
//! Tested on random polynomials of degree ≤ 10 with simple and double real roots and
//! complex pairs, and on the triple roots of sixth-order operators such as
//! `(∂u² + ∂v²)³`. Roots of multiplicity ≥ 3 inside high-degree polynomials are perturbed
//! beyond the cluster tolerance by any eigenvalue method and are not promised.

use super::{OdeError, Root};
use faer::Mat;
use num_complex::Complex64;

/// Relative distance below which eigenvalues of the companion matrix are one multiple root.
pub const CLUSTER_TOL: f64 = 1e-4;

/// The roots of a real polynomial with their multiplicities.
#[derive(Clone, Debug, PartialEq)]
pub struct PolyRoots {
    /// Roots (complex ones once, with `im > 0`).
    pub roots: Vec<Root>,
    /// Largest distance between eigenvalues merged into one multiple root, relative to the
    /// root scale (0 when nothing was merged or every merge was an exact zero root).
    pub merged: f64,
}

/// `P(z)` and `P'(z)` by Horner's rule; `c` ascending.
fn horner(c: &[f64], z: Complex64) -> (Complex64, Complex64) {
    let mut p = Complex64::new(0.0, 0.0);
    let mut dp = Complex64::new(0.0, 0.0);
    for &ck in c.iter().rev() {
        dp = dp * z + p;
        p = p * z + ck;
    }
    (p, dp)
}

/// Newton steps on `P` from `z` while they reduce `|P|`.
fn newton(c: &[f64], z: &mut Complex64) {
    for _ in 0..8 {
        let (p, dp) = horner(c, *z);
        if dp.norm() == 0.0 || p.norm() == 0.0 {
            return;
        }
        let next = *z - p / dp;
        if horner(c, next).0.norm() < p.norm() {
            *z = next;
        } else {
            return;
        }
    }
}

/// The coefficients of `P^{(k)}`.
fn derivative(c: &[f64], k: usize) -> Vec<f64> {
    (k..c.len()).map(|i| c[i] * ((i - k + 1)..=i).map(|f| f as f64).product::<f64>()).collect()
}

/// Relative backward error below which a polished cluster mean is an `m`-fold root:
/// `|P^{(k)}(z)| ≤ MULTIPLE_TOL · Σ_i |c_i^{(k)}| |z|^i` for every `k < m − 1`. Merging
/// two distinct roots `δ` apart leaves `P(z) ~ δ²` (relative), which the divided-difference
/// basis of a cluster amplifies further, so only `δ ≲ 3e-7` merge; keeping roots further
/// apart costs `~ε/δ` instead: at most 4e-11 relative ODE residual over the gaps
/// 1e-2 … 1e-9 of `close_distinct_roots_keep_the_ode_exact` (measured).
const MULTIPLE_TOL: f64 = 1e-13;

/// The `m`-fold root that the eigenvalues `members` (`m` of them) approximate, or `None`
/// when they are distinct roots. An `m`-fold root of `P` is a simple root of `P^{(m−1)}`:
/// Newton steps there from the members' mean recover it to round-off; it is accepted when
/// `P, P′, …, P^{(m−2)}` vanish there too, to [`MULTIPLE_TOL`].
fn multiple_root(q: &[f64], members: &[Complex64]) -> Option<Complex64> {
    let m = members.len();
    let mut z = members.iter().sum::<Complex64>() / m as f64;
    newton(&derivative(q, m - 1), &mut z);
    (0..m - 1)
        .all(|k| {
            let d = derivative(q, k);
            let size: f64 = d.iter().enumerate().map(|(i, c)| c.abs() * z.norm().powi(i as i32)).sum();
            horner(&d, z).0.norm() <= MULTIPLE_TOL * size
        })
        .then_some(z)
}

/// The roots of `P(s) = Σ_k c[k] s^k` with multiplicities.
///
/// ```
/// use pdeshape_core::ode::{polynomial_roots, Root};
/// // (s² − 4)² = s⁴ − 8 s² + 16: roots ±2, each double.
/// let r = polynomial_roots(&[16.0, 0.0, -8.0, 0.0, 1.0]).unwrap().roots;
/// assert_eq!(r.len(), 2);
/// assert!(r.iter().all(|r| r.mult == 2 && (r.re.abs() - 2.0).abs() < 1e-12 && r.im == 0.0));
/// ```
pub fn polynomial_roots(c: &[f64]) -> Result<PolyRoots, OdeError> {
    let bad = |why: String| OdeError::Polynomial(why);
    if let Some(k) = c.iter().position(|x| !x.is_finite()) {
        return Err(bad(format!("coefficient {k} is not finite ({})", c[k])));
    }
    let scale = c.iter().fold(0.0f64, |m, x| crate::num::max_nan(m, x.abs()));
    let Some(deg) = c.iter().rposition(|&x| x != 0.0) else {
        return Err(bad("every coefficient is zero (the operator vanishes)".into()));
    };
    if deg == 0 {
        return Err(bad("the polynomial is a nonzero constant: the ODE has no derivatives".into()));
    }
    if c[deg].abs() < 1e-13 * scale {
        return Err(bad(format!(
            "the leading coefficient {:.3e} is negligible against {scale:.3e}: the order is degenerate",
            c[deg]
        )));
    }
    let zeros = c.iter().position(|&x| x != 0.0).unwrap_or(0);
    let mut roots = Vec::new();
    if zeros > 0 {
        roots.push(Root { re: 0.0, im: 0.0, mult: zeros });
    }
    let q: Vec<f64> = c[zeros..=deg].iter().map(|x| x / c[deg]).collect();
    let n = q.len() - 1;
    let mut merged = 0.0f64;
    if n > 0 {
        // Companion matrix of the monic q: ones on the subdiagonal, −q_k in the last column.
        let comp = Mat::from_fn(n, n, |i, j| {
            if j == n - 1 {
                -q[i]
            } else if i == j + 1 {
                1.0
            } else {
                0.0
            }
        });
        let ev = comp.eigenvalues().map_err(|e| bad(format!("eigenvalue iteration failed: {e:?}")))?;
        let mut z: Vec<Complex64> = ev.iter().map(|e| Complex64::new(e.re, e.im)).collect();
        for zi in &mut z {
            newton(&q, zi);
        }
        let rscale = crate::num::max_nan(z.iter().fold(0.0f64, |m, x| crate::num::max_nan(m, x.norm())), 1e-300);
        // Agglomerative clustering: the closest two groups within the tolerance merge when
        // the merged group is a genuine multiple root ([`multiple_root`]).
        let mut groups: Vec<(Vec<Complex64>, Complex64)> = z.iter().map(|&x| (vec![x], x)).collect();
        let mut refused: Vec<(Vec<Complex64>, Vec<Complex64>)> = Vec::new();
        loop {
            let mut best: Option<(f64, usize, usize)> = None;
            for i in 0..groups.len() {
                for j in 0..i {
                    let d = (groups[i].1 - groups[j].1).norm();
                    let near = d <= CLUSTER_TOL * rscale.max(groups[i].1.norm());
                    let tried = refused.iter().any(|(a, b)| *a == groups[j].0 && *b == groups[i].0);
                    if near && !tried && best.is_none_or(|(bd, _, _)| d < bd) {
                        best = Some((d, i, j));
                    }
                }
            }
            let Some((_, i, j)) = best else { break };
            let members: Vec<Complex64> = groups[j].0.iter().chain(&groups[i].0).copied().collect();
            match multiple_root(&q, &members) {
                Some(root) => {
                    for m in &members {
                        merged = crate::num::max_nan(merged, (m - root).norm() / rscale);
                    }
                    groups[j] = (members, root);
                    groups.remove(i);
                }
                None => refused.push((groups[j].0.clone(), groups[i].0.clone())),
            }
        }
        let mut dims = 0;
        for (members, root) in groups {
            let m = members.len();
            if root.im.abs() <= CLUSTER_TOL * rscale {
                roots.push(Root { re: root.re, im: 0.0, mult: m });
                dims += m;
            } else if root.im > 0.0 {
                roots.push(Root { re: root.re, im: root.im, mult: m });
                dims += 2 * m;
            }
        }
        if dims != n {
            return Err(bad(format!(
                "the roots could not be grouped into real roots and conjugate pairs ({dims} of {n})"
            )));
        }
    }
    Ok(PolyRoots { roots, merged })
}

/// `P(s) = Σ_k c_k s^k` from roots with multiplicities (monic), ascending coefficients.
pub fn polynomial_from_roots(roots: &[Root]) -> Vec<f64> {
    let mut p = vec![1.0];
    let mul = |p: &mut Vec<f64>, f: &[f64]| {
        let mut out = vec![0.0; p.len() + f.len() - 1];
        for (i, a) in p.iter().enumerate() {
            for (j, b) in f.iter().enumerate() {
                out[i + j] += a * b;
            }
        }
        *p = out;
    };
    for r in roots {
        let f: Vec<f64> = if r.im > 0.0 { vec![r.re * r.re + r.im * r.im, -2.0 * r.re, 1.0] } else { vec![-r.re, 1.0] };
        for _ in 0..r.mult {
            mul(&mut p, &f);
        }
    }
    p
}

#[cfg(test)]
mod tests {
    use super::super::ExpSpace;
    use super::*;
    use proptest::prelude::*;

    /// `max_b |Σ_k c_k φ_b^{(k)}(u)| / Σ_k |c_k φ_b^{(k)}(u)|` over a few u.
    #[allow(clippy::needless_range_loop)] // d is indexed [order][basis]
    fn ode_residual(c: &[f64], space: &ExpSpace) -> f64 {
        let mut worst: f64 = 0.0;
        for u in [0.0, 0.21, 0.5, 0.77, 1.0] {
            let d = space.derivatives(u, c.len() - 1);
            for b in 0..space.dim() {
                let acc: f64 = c.iter().enumerate().map(|(k, ck)| ck * d[k][b]).sum();
                let size: f64 = c.iter().enumerate().map(|(k, ck)| (ck * d[k][b]).abs()).sum();
                worst = crate::num::max_nan(worst, acc.abs() / size.max(1e-300));
            }
        }
        worst
    }

    #[test]
    fn biharmonic_modes_have_double_roots() {
        // a s⁴ + b μ s² + c μ², μ = −n²: (∂u² + ∂v²)² has a = c = 1, b = 2 → s = ±n double.
        for n in [1.0f64, 3.0, 17.0] {
            let mu = -n * n;
            let r = polynomial_roots(&[mu * mu, 0.0, 2.0 * mu, 0.0, 1.0]).unwrap();
            assert_eq!(r.roots.len(), 2, "{r:?}");
            for root in &r.roots {
                assert_eq!((root.mult, root.im), (2, 0.0));
                assert!((root.re.abs() - n).abs() < 1e-12 * n);
            }
        }
        // (∂u² + ∂v²)³: triple roots ±n.
        let n: f64 = 5.0;
        let s2 = n * n;
        let c = [-s2 * s2 * s2, 0.0, 3.0 * s2 * s2, 0.0, -3.0 * s2, 0.0, 1.0];
        let r = polynomial_roots(&c).unwrap();
        assert_eq!(r.roots.iter().map(|r| r.mult).collect::<Vec<_>>(), vec![3, 3], "{r:?}");
        let space = ExpSpace::from_roots(r.roots);
        assert!(ode_residual(&c, &space) < 1e-12);
        // (s² + 25)³: the conjugate pair ±5i, triple.
        let c = [125.0 * 125.0, 0.0, 3.0 * 625.0, 0.0, 75.0, 0.0, 1.0];
        let r = polynomial_roots(&c).unwrap();
        assert_eq!(r.roots.len(), 1);
        assert_eq!(r.roots[0].mult, 3);
        assert!(r.roots[0].re.abs() < 1e-12 && (r.roots[0].im - 5.0).abs() < 1e-12, "{r:?}");
        assert!(ode_residual(&c, &ExpSpace::from_roots(r.roots)) < 1e-12);
    }

    #[test]
    fn zero_roots_are_exact() {
        let r = polynomial_roots(&[0.0, 0.0, 0.0, 0.0, 2.5]).unwrap();
        assert_eq!(r.roots, vec![Root { re: 0.0, im: 0.0, mult: 4 }]);
        let r = polynomial_roots(&[0.0, 0.0, -9.0, 0.0, 1.0]).unwrap();
        assert_eq!(r.roots[0], Root { re: 0.0, im: 0.0, mult: 2 });
        assert_eq!(r.roots.len(), 3);
    }

    #[test]
    fn degenerate_polynomials_are_rejected() {
        for c in [&[0.0, 0.0][..], &[3.0], &[1.0, f64::NAN, 1.0], &[1.0, 2.0, 1e-20]] {
            let e = polynomial_roots(c).unwrap_err();
            assert!(matches!(e, OdeError::Polynomial(_)), "{c:?}: {e}");
        }
    }

    /// Two distinct roots `δ` apart (relative), beside others: whether they are merged into
    /// one double root or kept apart, every basis function solves the ODE to round-off.
    /// Merging distinct roots costs `O(δ²)`, keeping them costs `O(ε/δ)` (the divided
    /// differences amplify the roots' round-off). The worst measured is 4e-11 (δ = 1e-6,
    /// kept apart); the bound is the blend tests' 1e-10. Merging at `δ = 1e-4`, as a
    /// fixed tolerance did, gave 2e-8.
    #[test]
    fn close_distinct_roots_keep_the_ode_exact() {
        for delta in [1e-2, 2.2e-4, 1e-4, 5e-5, 1e-5, 5e-6, 2e-6, 1e-6, 7e-7, 5e-7, 3e-7, 2e-7, 1e-7, 1e-9, 0.0] {
            for (a, b) in [(1.0219, 1.0858), (0.3, 2.0), (-1.5, 4.0)] {
                let z = b * (1.0 + delta);
                let roots = [a, -a, b, -b, z, -z].map(|re| Root { re, im: 0.0, mult: 1 });
                let c = polynomial_from_roots(&roots);
                let found = polynomial_roots(&c).unwrap();
                let res = ode_residual(&c, &ExpSpace::from_roots(found.roots.clone()));
                assert!(res < 1e-10, "δ = {delta:e}, roots ±{a}, ±{b}, ±{z}: ODE residual {res:e}");
            }
        }
    }

    fn arb_roots() -> impl Strategy<Value = Vec<Root>> {
        // Separated real roots and complex pairs, simple or double.
        prop::collection::vec((-6i32..=6, 0i32..=4, 1usize..=2), 1..=4).prop_map(|v| {
            let mut seen = std::collections::HashSet::new();
            v.into_iter()
                .filter(|(re, im, _)| seen.insert((*re, *im)))
                .map(|(re, im, mult)| Root { re: re as f64 * 1.5 + 0.25, im: im as f64 * 1.25, mult })
                .collect()
        })
    }

    proptest! {
        /// Random roots with multiplicities: expanded, found again with the same
        /// multiplicities, and every basis function solves the ODE to round-off.
        #[test]
        fn roots_and_multiplicities_are_recovered(roots in arb_roots()) {
            let c = polynomial_from_roots(&roots);
            prop_assume!(c.len() <= 11);
            let found = polynomial_roots(&c).unwrap();
            let mut want: Vec<(i64, i64, usize)> =
                roots.iter().map(|r| ((r.re * 1e6).round() as i64, (r.im * 1e6).round() as i64, r.mult)).collect();
            let mut got: Vec<(i64, i64, usize)> =
                found.roots.iter().map(|r| ((r.re * 1e6).round() as i64, (r.im * 1e6).round() as i64, r.mult)).collect();
            want.sort_unstable();
            got.sort_unstable();
            prop_assert_eq!(&got, &want);
            let space = ExpSpace::from_roots(found.roots);
            prop_assert_eq!(space.dim(), c.len() - 1);
            let res = ode_residual(&c, &space);
            prop_assert!(res < 1e-9, "ODE residual {}", res);
        }
    }
}
