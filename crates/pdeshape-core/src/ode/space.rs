//! The solution space of `P(D) y = 0` with a bounded, well-conditioned basis.

use crate::num::MaxNan;
use num_complex::Complex64;

/// A root of the characteristic polynomial with its multiplicity. Complex roots are given
/// once, with `im > 0`; their conjugate is implied.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Root {
    /// Real part.
    pub re: f64,
    /// Imaginary part (≥ 0; > 0 means a conjugate pair).
    pub im: f64,
    /// Multiplicity.
    pub mult: usize,
}

/// `K = ker P(D)`, the solutions of a constant-coefficient ODE, with a bounded real basis.
///
/// ```
/// use pdeshape_core::ode::ExpSpace;
/// // (D² − 4)² : roots ±2, each double: basis (u−1)e^{2(u−1)}… of dimension 4.
/// let k = ExpSpace::symmetric(2.0, 2);
/// assert_eq!(k.dim(), 4);
/// let d = k.derivatives(0.3, 1);
/// assert_eq!(d.len(), 2);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct ExpSpace {
    roots: Vec<Root>,
    dim: usize,
    /// Distinct non-zero roots closer than [`CLUSTER_GAP`] to each other, by index into
    /// `roots`: their basis is the divided differences of [`cluster_derivatives`].
    clusters: Vec<Vec<usize>>,
}

/// Distinct roots closer than this (absolute, on `u ∈ [0, 1]`) share a divided-difference
/// basis. `e^{r₁u}` and `e^{r₂u}` differ by about `|r₁ − r₂|` on `[0, 1]`, so as separate
/// basis functions they make the condition matrix ill-conditioned like `1/|r₁ − r₂|`
/// (per pair; a cluster of `m` close roots like its power `m − 1`).
pub const CLUSTER_GAP: f64 = 0.5;

/// Groups the distinct non-zero roots into clusters by single linkage at
/// [`CLUSTER_GAP`]; real roots and complex roots (`im > 0`) are grouped separately.
fn clusters(roots: &[Root]) -> Vec<Vec<usize>> {
    let z = |i: usize| Complex64::new(roots[i].re, roots[i].im);
    let mut out: Vec<Vec<usize>> = Vec::new();
    for i in 0..roots.len() {
        if roots[i].re == 0.0 && roots[i].im == 0.0 {
            continue;
        }
        let near = |c: &Vec<usize>| {
            c.iter().any(|&j| (roots[j].im > 0.0) == (roots[i].im > 0.0) && (z(j) - z(i)).norm() < CLUSTER_GAP)
        };
        let mut merged = vec![i];
        let mut kept = Vec::with_capacity(out.len());
        for c in out {
            if near(&c) { merged.extend(c) } else { kept.push(c) }
        }
        merged.sort_unstable();
        kept.push(merged);
        out = kept;
    }
    out.sort_unstable();
    out
}

/// `out[j][k] = d^j/du^j φ_k(u)` for the divided-difference basis of a cluster of roots
/// `z_0 … z_{m−1}` (repeated by multiplicity), `w = u − anchor`:
///
/// `φ_k(u) = e[z_0, …, z_k]`, the divided difference over the roots of `z ↦ e^{z w}`.
///
/// It lies in the span of the cluster's `e^{z_i w}` (and `wᵏ e^{z w}` for repeated
/// roots), and it stays well conditioned as the roots coalesce: for equal roots it is
/// `wᵏ e^{z w}/k!`. With the centre `c` and offsets `δ_i = z_i − c`,
/// `(c + δ)ʲ e^{(c+δ)w} = e^{cw} Σ_n A_{j,n} δⁿ`, `A_{j,n} = Σ_{i ≤ min(j,n)} C(j,i) c^{j−i} w^{n−i}/(n−i)!`,
/// and the divided difference of `δⁿ` over `δ_0 … δ_k` is the complete homogeneous
/// symmetric polynomial `h_{n−k}(δ_0, …, δ_k)`, so
/// `φ_k^{(j)} = e^{cw} Σ_{n ≥ k} A_{j,n} h_{n−k}(δ_0, …, δ_k)`, summed until the terms
/// `Rᵗ/t!` (`R = max |δ_i|`, `|w| ≤ 1`) fall below round-off.
fn cluster_derivatives(c: Complex64, delta: &[Complex64], w: f64, kmax: usize) -> Vec<Vec<Complex64>> {
    let zero = Complex64::new(0.0, 0.0);
    let m = delta.len();
    let radius = delta.iter().map(|d| d.norm()).max_nan() * w.abs().max(1e-300);
    let mut tail = 1usize;
    let mut term = radius;
    while term > 1e-18 && tail < 400 {
        tail += 1;
        term *= radius / tail as f64;
    }
    let nmax = m + kmax + tail;
    // h[k][p] = h_p(δ_0 … δ_k) = h_p(δ_0 … δ_{k−1}) + δ_k h_{p−1}(δ_0 … δ_k)
    let mut h = vec![vec![zero; nmax + 1]; m];
    for k in 0..m {
        for p in 0..=nmax {
            let before = if k > 0 {
                h[k - 1][p]
            } else if p == 0 {
                Complex64::new(1.0, 0.0)
            } else {
                zero
            };
            h[k][p] = before + if p > 0 { delta[k] * h[k][p - 1] } else { zero };
        }
    }
    // wp[l] = w^l / l!
    let mut wp = vec![1.0; nmax + 1];
    for l in 1..=nmax {
        wp[l] = wp[l - 1] * w / l as f64;
    }
    let e = (c * w).exp();
    (0..=kmax)
        .map(|j| {
            let a: Vec<Complex64> = (0..=nmax)
                .map(|n| (0..=j.min(n)).map(|i| c.powu((j - i) as u32) * (binom(j, i) * wp[n - i])).sum())
                .collect();
            (0..m).map(|k| e * (k..=nmax).map(|n| a[n] * h[k][n - k]).sum::<Complex64>()).collect()
        })
        .collect()
}

/// Binomial coefficient as f64.
fn binom(n: usize, k: usize) -> f64 {
    (0..k).fold(1.0, |acc, i| acc * (n - i) as f64 / (i + 1) as f64)
}

impl ExpSpace {
    /// The space of the given roots.
    pub fn from_roots(roots: Vec<Root>) -> Self {
        let dim = roots.iter().map(|r| if r.im > 0.0 { 2 * r.mult } else { r.mult }).sum();
        let clusters = clusters(&roots);
        ExpSpace { roots, dim, clusters }
    }

    /// `ker P(D)` for `P(s) = Σ_k c[k] s^k` (real coefficients, any roots): see
    /// [`polynomial_roots`](super::polynomial_roots).
    ///
    /// ```
    /// use pdeshape_core::ode::ExpSpace;
    /// // y⁗ + 2y″ + y = 0: roots ±i, each double.
    /// let k = ExpSpace::from_polynomial(&[1.0, 0.0, 2.0, 0.0, 1.0]).unwrap();
    /// assert_eq!(k.dim(), 4);
    /// assert_eq!(k.roots()[0].mult, 2);
    /// ```
    pub fn from_polynomial(c: &[f64]) -> Result<Self, super::OdeError> {
        Ok(Self::from_roots(super::polynomial_roots(c)?.roots))
    }

    /// `ker (D² − c²)^N`: roots `±c` of multiplicity `N` (polynomials of degree `2N − 1`
    /// when `c = 0`). This is mode `n` of `(∂u² + a²∂v²)^N` with `c = a n`.
    pub fn symmetric(c: f64, n: usize) -> Self {
        let c = c.abs();
        if c == 0.0 {
            Self::from_roots(vec![Root { re: 0.0, im: 0.0, mult: 2 * n }])
        } else {
            Self::from_roots(vec![Root { re: c, im: 0.0, mult: n }, Root { re: -c, im: 0.0, mult: n }])
        }
    }

    /// The dimension (the order of the ODE).
    pub fn dim(&self) -> usize {
        self.dim
    }

    /// The roots.
    pub fn roots(&self) -> &[Root] {
        &self.roots
    }

    /// True when some distinct roots share a divided-difference basis.
    pub fn clustered(&self) -> bool {
        self.clusters.iter().any(|c| c.len() > 1)
    }

    /// `out[j][b] = φ_b^{(j)}(u)` for `j = 0 … kmax` and every basis function `b`.
    pub fn derivatives(&self, u: f64, kmax: usize) -> Vec<Vec<f64>> {
        let mut out = vec![Vec::with_capacity(self.dim); kmax + 1];
        for cluster in self.clusters.iter().filter(|c| c.len() > 1) {
            let z: Vec<Complex64> = cluster
                .iter()
                .flat_map(|&i| {
                    std::iter::repeat_n(Complex64::new(self.roots[i].re, self.roots[i].im), self.roots[i].mult)
                })
                .collect();
            let c = z.iter().sum::<Complex64>() / z.len() as f64;
            let delta: Vec<Complex64> = z.iter().map(|zi| zi - c).collect();
            let w = u - if c.re > 0.0 { 1.0 } else { 0.0 };
            let complex = self.roots[cluster[0]].im > 0.0;
            for (row, d) in out.iter_mut().zip(cluster_derivatives(c, &delta, w, kmax)) {
                for v in d {
                    row.push(v.re);
                    if complex {
                        row.push(v.im);
                    }
                }
            }
        }
        let alone = |i: usize| self.clusters.iter().all(|c| c.len() == 1 || !c.contains(&i));
        for r in self.roots.iter().enumerate().filter(|(i, _)| alone(*i)).map(|(_, r)| r) {
            if r.re == 0.0 && r.im == 0.0 {
                // Polynomials of degree < mult: Chebyshev T_k(x), x = 2u − 1, with
                // derivatives by the recurrence of the derivative tables.
                let m = r.mult;
                let x = 2.0 * u - 1.0;
                // t[j][k] = d^j/dx^j T_k(x)
                let mut t = vec![vec![0.0; m.max(1)]; kmax + 1];
                for j in 0..=kmax {
                    for k in 0..m {
                        t[j][k] = match (k, j) {
                            (0, 0) => 1.0,
                            (0, _) => 0.0,
                            (1, 0) => x,
                            (1, 1) => 1.0,
                            (1, _) => 0.0,
                            // T_{k}^{(j)} = 2x T_{k-1}^{(j)} + 2j T_{k-1}^{(j-1)} − T_{k-2}^{(j)}
                            _ => {
                                2.0 * x * t[j][k - 1] + if j > 0 { 2.0 * j as f64 * t[j - 1][k - 1] } else { 0.0 }
                                    - t[j][k - 2]
                            }
                        };
                    }
                }
                for (j, row) in out.iter_mut().enumerate() {
                    let scale = 2f64.powi(j as i32); // d/du = 2 d/dx
                    row.extend(t[j].iter().take(m).map(|v| v * scale));
                }
                continue;
            }
            let anchor = if r.re > 0.0 { 1.0 } else { 0.0 };
            let w = u - anchor;
            let rc = Complex64::new(r.re, r.im);
            let e = (rc * w).exp();
            for k in 0..r.mult {
                for (j, row) in out.iter_mut().enumerate() {
                    // d^j/du^j [w^k e^{rw}] = Σ_i C(j,i) k!/(k−i)! w^{k−i} r^{j−i} e^{rw}
                    let mut s = Complex64::new(0.0, 0.0);
                    let mut fall = 1.0;
                    for i in 0..=j.min(k) {
                        if i > 0 {
                            fall *= (k - i + 1) as f64;
                        }
                        s += rc.powu((j - i) as u32) * (binom(j, i) * fall * w.powi((k - i) as i32));
                    }
                    let v = s * e;
                    row.push(v.re);
                    if r.im > 0.0 {
                        row.push(v.im);
                    }
                }
            }
        }
        out
    }
}

#[cfg(test)]
#[allow(clippy::needless_range_loop)] // derivative tables are indexed [order][basis]
mod tests {
    use super::*;
    use crate::ode::{Cardinal, CondSpec};

    /// Each basis function solves the ODE: for (D² − c²)^N, apply the operator through
    /// the derivative table and check the result vanishes.
    #[test]
    fn basis_functions_solve_the_ode() {
        for (c, n) in [(0.0, 3), (1.5, 2), (7.0, 3), (30.0, 2)] {
            let k = ExpSpace::symmetric(c, n);
            let d = k.derivatives(0.37, 2 * n);
            // coefficients of (s² − c²)^N in s: Σ_j C(N,j) (−c²)^{N−j} s^{2j}
            for b in 0..k.dim() {
                let mut acc = 0.0;
                let mut scale: f64 = 0.0;
                for j in 0..=n {
                    let coef = binom(n, j) * (-c * c).powi((n - j) as i32);
                    acc += coef * d[2 * j][b];
                    scale = scale.max((coef * d[2 * j][b]).abs());
                }
                assert!(acc.abs() <= 1e-12 * scale.max(1.0), "c {c} N {n} basis {b}: residual {acc}");
            }
        }
        // complex roots: e^{(α ± iβ)u} solve D² − 2αD + α² + β² = 0
        let k = ExpSpace::from_roots(vec![Root { re: -0.5, im: 2.0, mult: 1 }]);
        let d = k.derivatives(0.8, 2);
        for b in 0..2 {
            let r = d[2][b] + 1.0 * d[1][b] + (0.25 + 4.0) * d[0][b];
            assert!(r.abs() < 1e-13);
        }
    }

    /// Applies `P(D)` (roots with multiplicities, complex pairs expanded) to every basis
    /// function through the derivative table; returns the largest residual relative to
    /// the largest term.
    fn residual(k: &ExpSpace, u: f64) -> f64 {
        let p = crate::ode::polynomial_from_roots(k.roots());
        let d = k.derivatives(u, p.len() - 1);
        (0..k.dim())
            .map(|b| {
                let acc: f64 = p.iter().enumerate().map(|(j, c)| c * d[j][b]).sum();
                let scale = p.iter().enumerate().map(|(j, c)| (c * d[j][b]).abs()).fold(1e-300, f64::max);
                acc.abs() / scale
            })
            .max_nan()
    }

    fn cond(k: ExpSpace) -> f64 {
        let sp: Vec<CondSpec> =
            [0.0, 1.0].iter().flat_map(|&u| (0..k.dim() / 2).map(move |order| CondSpec { u, order })).collect();
        Cardinal::new(k, &sp).unwrap().condition_number()
    }

    /// Close distinct roots share a divided-difference basis: it solves the ODE, and the
    /// condition matrix stays bounded as the roots coalesce (separate exponentials give
    /// `~1/δ` per pair; this was a failing random blend: three elliptic factors whose mode
    /// roots were 0.810, 0.838 and 0.839).
    #[test]
    fn close_roots_get_a_well_conditioned_basis() {
        let real = |v: &[f64]| v.iter().map(|&re| Root { re, im: 0.0, mult: 1 }).collect::<Vec<_>>();
        let blend = real(&[0.8098, 0.8380, 0.8395, -0.8098, -0.8380, -0.8395]);
        let k = ExpSpace::from_roots(blend);
        assert_eq!(k.clusters, vec![vec![0, 1, 2], vec![3, 4, 5]]);
        for u in [0.0, 0.3, 1.0] {
            assert!(residual(&k, u) < 1e-13, "u {u}: {}", residual(&k, u));
        }
        // as well conditioned as the space of the triple roots ±0.83 they are close to
        let (near, triple) = (cond(k), cond(ExpSpace::symmetric(0.83, 3)));
        assert!(near < 1.2 * triple, "{near} vs {triple}");
        let mut last = 0.0;
        for delta in [1e-1, 1e-3, 1e-6, 1e-9] {
            let k = ExpSpace::from_roots(real(&[2.0, 2.0 + delta, -2.0 - delta, -2.0]));
            assert!(residual(&k, 0.4) < 1e-12);
            let c = cond(k);
            assert!(c < 200.0 && (last == 0.0 || (c - last).abs() < 0.1 * last), "δ {delta}: cond {c}");
            last = c;
        }
        // coalesced: the divided differences tend to wᵏ e^{zw}/k!, the double root's basis
        let near = ExpSpace::from_roots(real(&[-1.5, -1.5 + 1e-9])).derivatives(0.7, 2);
        let double = ExpSpace::from_roots(vec![Root { re: -1.5, im: 0.0, mult: 2 }]).derivatives(0.7, 2);
        for j in 0..3 {
            assert!((near[j][0] - double[j][0]).abs() < 1e-8 && (near[j][1] - double[j][1]).abs() < 1e-8);
        }
        // complex pairs close to each other, a root of multiplicity two inside a cluster
        let k = ExpSpace::from_roots(vec![
            Root { re: 0.3, im: 2.0, mult: 1 },
            Root { re: 0.3, im: 2.01, mult: 1 },
            Root { re: -0.7, im: 0.0, mult: 2 },
            Root { re: -0.6, im: 0.0, mult: 1 },
            Root { re: 5.0, im: 0.0, mult: 1 },
        ]);
        assert_eq!(k.clusters, vec![vec![0, 1], vec![2, 3], vec![4]]);
        assert_eq!(k.derivatives(0.2, 0)[0].len(), 8);
        for u in [0.0, 0.55, 1.0] {
            assert!(residual(&k, u) < 1e-12, "u {u}: {}", residual(&k, u));
        }
        let coalesced = ExpSpace::from_roots(vec![
            Root { re: 0.3, im: 2.0, mult: 2 },
            Root { re: -0.7, im: 0.0, mult: 3 },
            Root { re: 5.0, im: 0.0, mult: 1 },
        ]);
        let (near, limit) = (cond(k), cond(coalesced));
        assert!(near < 2.0 * limit, "{near} vs {limit}");
    }
}
