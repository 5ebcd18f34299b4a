//! Cardinal functions computed in multiple precision and tabulated as f64 Chebyshev
//! series (SPEC §3 "Conditioning").
//!
//! For large orders no global basis of `ker (D² − c²)^N` is usable in f64 (condition
//! numbers up to 1e69 for N = 20), while the cardinal functions themselves are bounded.
//! So the condition matrix is built and inverted with `astro-float` at a precision chosen
//! from the size of the inverse, the cardinal functions and their derivatives are
//! evaluated at Chebyshev nodes of a few subintervals of `[0, 1]`, rounded to f64, and
//! turned into Chebyshev series; everything after that is f64 (Clenshaw summation).

use super::{CondSpec, ExpSpace, OdeError};
use crate::num::MaxNan;
use astro_float::{BigFloat, Consts, RoundingMode, Sign};

const RM: RoundingMode = RoundingMode::ToEven;

fn to_f64(x: &BigFloat) -> f64 {
    if x.is_zero() {
        return 0.0;
    }
    match x.as_raw_parts() {
        Some((words, _, sign, exp, _)) => {
            let top = *words.last().unwrap_or(&0) as f64;
            let next = if words.len() > 1 { words[words.len() - 2] as f64 } else { 0.0 };
            let m = top / 18446744073709551616.0 + next / 18446744073709551616.0 / 18446744073709551616.0;
            let v = m * 2f64.powi(exp);
            if sign == Sign::Neg { -v } else { v }
        }
        None => f64::NAN,
    }
}

fn bf(x: f64, p: usize) -> BigFloat {
    BigFloat::from_f64(x, p)
}

/// `[1, x, x², …]` (`count` entries) by repeated multiplication (exact signs).
fn powers(x: &BigFloat, count: usize, p: usize) -> Vec<BigFloat> {
    let mut out = Vec::with_capacity(count);
    let mut acc = bf(1.0, p);
    for _ in 0..count {
        out.push(acc.clone());
        acc = acc.mul(x, p, RM);
    }
    out
}

/// Basis derivative table of an all-real-roots space in multiple precision:
/// `out[j][b] = φ_b^{(j)}(u)`, with `u` given exactly as the f64 it is.
fn mp_derivatives(space: &ExpSpace, u: f64, kmax: usize, p: usize, cc: &mut Consts) -> Vec<Vec<BigFloat>> {
    let mut out: Vec<Vec<BigFloat>> = vec![Vec::with_capacity(space.dim()); kmax + 1];
    for r in space.roots() {
        debug_assert!(r.im == 0.0, "multiple precision supports real roots");
        if r.re == 0.0 {
            // Chebyshev polynomials T_k(x), x = 2u − 1, derivatives by recurrence.
            let m = r.mult;
            let x = bf(2.0, p).mul(&bf(u, p), p, RM).sub(&bf(1.0, p), p, RM);
            let mut t: Vec<Vec<BigFloat>> = vec![Vec::with_capacity(m); kmax + 1];
            for j in 0..=kmax {
                for k in 0..m {
                    let v = match (k, j) {
                        (0, 0) => bf(1.0, p),
                        (0, _) => bf(0.0, p),
                        (1, 0) => x.clone(),
                        (1, 1) => bf(1.0, p),
                        (1, _) => bf(0.0, p),
                        _ => {
                            let a = bf(2.0, p).mul(&x, p, RM).mul(&t[j][k - 1], p, RM);
                            let b = if j > 0 { bf(2.0 * j as f64, p).mul(&t[j - 1][k - 1], p, RM) } else { bf(0.0, p) };
                            a.add(&b, p, RM).sub(&t[j][k - 2], p, RM)
                        }
                    };
                    t[j].push(v);
                }
            }
            for (j, row) in out.iter_mut().enumerate() {
                let s = bf(2f64.powi(j as i32), p);
                row.extend(t[j].iter().map(|v| v.mul(&s, p, RM)));
            }
            continue;
        }
        let anchor = if r.re > 0.0 { 1.0 } else { 0.0 };
        // w = u − anchor in multiple precision: in f64 it would round, and every basis
        // function must be evaluated at exactly the same u.
        let w = bf(u, p).sub(&bf(anchor, p), p, RM);
        let c = bf(r.re, p);
        let e = c.mul(&w, p, RM).exp(p, RM, cc);
        // powers of c and w
        let cp = powers(&c, kmax + 1, p);
        let wp = powers(&w, r.mult, p);
        for k in 0..r.mult {
            for (j, row) in out.iter_mut().enumerate() {
                let mut s = bf(0.0, p);
                let mut fall = 1.0f64;
                let mut bin = 1.0f64;
                for i in 0..=j.min(k) {
                    if i > 0 {
                        fall *= (k - i + 1) as f64;
                        bin *= (j - i + 1) as f64 / i as f64;
                    }
                    let term = bf(bin * fall, p).mul(&wp[k - i], p, RM).mul(&cp[j - i], p, RM);
                    s = s.add(&term, p, RM);
                }
                row.push(s.mul(&e, p, RM));
            }
        }
    }
    out
}

/// Gauss–Jordan inverse with partial pivoting in multiple precision.
fn mp_inverse(a: Vec<Vec<BigFloat>>, p: usize) -> Option<Vec<Vec<BigFloat>>> {
    let n = a.len();
    let mut m: Vec<Vec<BigFloat>> = a
        .into_iter()
        .enumerate()
        .map(|(i, mut row)| {
            row.extend((0..n).map(|j| bf(if i == j { 1.0 } else { 0.0 }, p)));
            row
        })
        .collect();
    for col in 0..n {
        crate::cancel::checkpoint();
        let piv = (col..n)
            .max_by(|&x, &y| m[x][col].abs_cmp(&m[y][col]).map(|s| s.cmp(&0)).unwrap_or(std::cmp::Ordering::Equal))?;
        if m[piv][col].is_zero() {
            return None;
        }
        m.swap(col, piv);
        let inv = bf(1.0, p).div(&m[col][col], p, RM);
        for x in m[col].iter_mut() {
            *x = x.mul(&inv, p, RM);
        }
        let pivot_row = m[col].clone();
        for (r, row) in m.iter_mut().enumerate() {
            if r != col && !row[col].is_zero() {
                let f = row[col].clone();
                for (x, q) in row.iter_mut().zip(&pivot_row) {
                    *x = x.sub(&f.mul(q, p, RM), p, RM);
                }
            }
        }
    }
    Some(m.into_iter().map(|row| row[n..].to_vec()).collect())
}

/// The cardinal functions of a condition set as f64 Chebyshev series on subintervals.
#[derive(Clone, Debug)]
pub struct ChebCardinal {
    breaks: Vec<f64>,
    /// `coef[piece][k][i]`: Chebyshev coefficients of `ℓ_i^{(k)}` on the piece.
    coef: Vec<Vec<Vec<Vec<f64>>>>,
    kmax: usize,
    dim: usize,
    bits: usize,
    max_inverse: f64,
    /// Exact (multiple-precision, then rounded) values at the condition points, where the
    /// cardinal property must hold to round-off for every tabulated derivative order: a
    /// Chebyshev series of a high derivative is only accurate relative to its maximum.
    at_conditions: Vec<(f64, Vec<Vec<f64>>)>,
    /// The worst relative ODE residual of the pieces' series
    /// ([`super::ultraspherical::relative_residual`]).
    residual: f64,
}

impl ChebCardinal {
    /// Computes the cardinal functions of `conds` in `space` (real roots only) and their
    /// derivatives up to `kmax`.
    pub fn new(space: &ExpSpace, conds: &[CondSpec], kmax: usize) -> Result<Self, OdeError> {
        let n = space.dim();
        let c = space.roots().iter().map(|r| r.re.abs()).max_nan();
        let dmax = conds.iter().map(|c| c.order).max().unwrap_or(0);
        let mut cc = Consts::new().map_err(|e| OdeError::Singular { cond: f64::NAN, detail: format!(": {e:?}") })?;
        let mut bits = 256usize;
        loop {
            let rows: Vec<Vec<BigFloat>> =
                conds.iter().map(|cd| mp_derivatives(space, cd.u, dmax, bits, &mut cc).swap_remove(cd.order)).collect();
            let Some(inv) = mp_inverse(rows, bits) else {
                return Err(OdeError::Singular { cond: f64::INFINITY, detail: String::new() });
            };
            let max_inv = inv.iter().flatten().map(|x| to_f64(x).abs()).max_nan();
            let need = (max_inv.max(1.0).log2().ceil() as usize) + 80;
            if !max_inv.is_finite() || max_inv > 1e300 {
                return Err(OdeError::Singular { cond: max_inv, detail: String::new() });
            }
            if need > bits {
                bits = need.next_multiple_of(64);
                continue;
            }
            // Pieces: boundary layers e^{±c(u−·)} want c·h ≤ 24; polynomial-like content
            // of degree 2N − 1 is resolved by D = n + 30 nodes per piece.
            let pieces = ((c / 24.0).ceil() as usize).max(1);
            let deg = n + 30;
            let breaks: Vec<f64> = (0..=pieces).map(|i| i as f64 / pieces as f64).collect();
            let mut coef = Vec::with_capacity(pieces);
            for pc in 0..pieces {
                let (a, b) = (breaks[pc], breaks[pc + 1]);
                // Chebyshev points of the first kind on [a, b]
                let nodes: Vec<f64> = (0..=deg)
                    .map(|j| {
                        let t = (std::f64::consts::PI * (j as f64 + 0.5) / (deg + 1) as f64).cos();
                        0.5 * (a + b) + 0.5 * (b - a) * t
                    })
                    .collect();
                // vals[k][i][j] = ℓ_i^{(k)}(node_j)
                let mut vals = vec![vec![vec![0.0; deg + 1]; n]; kmax + 1];
                for (j, &x) in nodes.iter().enumerate() {
                    crate::cancel::checkpoint();
                    let d = mp_derivatives(space, x, kmax, bits, &mut cc);
                    for (k, row) in d.iter().enumerate() {
                        for i in 0..n {
                            let mut s = bf(0.0, bits);
                            for (bidx, phi) in row.iter().enumerate() {
                                s = s.add(&phi.mul(&inv[bidx][i], bits, RM), bits, RM);
                            }
                            vals[k][i][j] = to_f64(&s);
                        }
                    }
                }
                // Chebyshev coefficients by the discrete cosine transform at first-kind nodes.
                let m = deg + 1;
                let piece: Vec<Vec<Vec<f64>>> = vals
                    .iter()
                    .map(|per_i| {
                        per_i
                            .iter()
                            .map(|f| {
                                (0..m)
                                    .map(|q| {
                                        let s: f64 = (0..m)
                                            .map(|j| {
                                                f[j] * (std::f64::consts::PI * q as f64 * (j as f64 + 0.5) / m as f64)
                                                    .cos()
                                            })
                                            .sum();
                                        s * if q == 0 { 1.0 } else { 2.0 } / m as f64
                                    })
                                    .collect()
                            })
                            .collect()
                    })
                    .collect();
                coef.push(piece);
            }
            let mut at_conditions: Vec<(f64, Vec<Vec<f64>>)> = Vec::new();
            for cd in conds {
                if at_conditions.iter().any(|(u, _)| *u == cd.u) {
                    continue;
                }
                let d = mp_derivatives(space, cd.u, kmax, bits, &mut cc);
                let vals = d
                    .iter()
                    .map(|row| {
                        (0..n)
                            .map(|i| {
                                let mut s = bf(0.0, bits);
                                for (bidx, phi) in row.iter().enumerate() {
                                    s = s.add(&phi.mul(&inv[bidx][i], bits, RM), bits, RM);
                                }
                                to_f64(&s)
                            })
                            .collect()
                    })
                    .collect();
                at_conditions.push((cd.u, vals));
            }
            let p = super::polynomial_from_roots(space.roots());
            let mut residual = 0.0_f64;
            for (pc, piece) in coef.iter().enumerate() {
                let h = breaks[pc + 1] - breaks[pc];
                let Some(first) = piece[0].first() else { continue };
                let r = super::ultraspherical::operator_rows(&p, first.len(), h);
                for c in &piece[0] {
                    residual = crate::num::max_nan(residual, super::ultraspherical::residual_of(&r, c));
                }
            }
            return Ok(ChebCardinal {
                breaks,
                coef,
                kmax,
                dim: n,
                bits,
                max_inverse: max_inv,
                at_conditions,
                residual,
            });
        }
    }

    /// `out[k][i] = ℓ_i^{(k)}(u)`, `k ≤ kmax` (at most the tabulated order).
    pub fn eval(&self, u: f64, kmax: usize) -> Vec<Vec<f64>> {
        assert!(kmax <= self.kmax, "derivative order {kmax} not tabulated (max {})", self.kmax);
        if let Some((_, rows)) = self.at_conditions.iter().find(|(c, _)| *c == u) {
            return rows[..=kmax].to_vec();
        }
        let pieces = self.breaks.len() - 1;
        let pc = ((u * pieces as f64).floor().max(0.0) as usize).min(pieces - 1);
        let (a, b) = (self.breaks[pc], self.breaks[pc + 1]);
        let t = (2.0 * u - a - b) / (b - a);
        (0..=kmax)
            .map(|k| {
                (0..self.dim)
                    .map(|i| {
                        let c = &self.coef[pc][k][i];
                        // Clenshaw
                        let (mut b1, mut b2) = (0.0, 0.0);
                        for &cj in c.iter().skip(1).rev() {
                            let b0 = 2.0 * t * b1 - b2 + cj;
                            b2 = b1;
                            b1 = b0;
                        }
                        t * b1 - b2 + c[0]
                    })
                    .collect()
            })
            .collect()
    }

    /// The ODE residual of the cardinal functions, relative, in Chebyshev coefficients (the
    /// worst function and piece).
    pub fn residual(&self) -> f64 {
        self.residual
    }

    /// Working precision of the solve, bits.
    pub fn bits(&self) -> usize {
        self.bits
    }

    /// Largest entry of the inverse condition matrix (a proxy of its conditioning).
    pub fn max_inverse(&self) -> f64 {
        self.max_inverse
    }

    /// Highest tabulated derivative order.
    pub fn kmax(&self) -> usize {
        self.kmax
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn to_f64_round_trips() {
        for x in [1.0, -3.5, 1e-300, 123456.789, 2f64.powi(-1074 + 60), -7.25e200] {
            assert_eq!(to_f64(&bf(x, 256)), x);
        }
    }

    /// N = 20 (order 40) at Chebyshev positions, the Klein bottle's condition set: the
    /// cardinal property holds to round-off where f64 in any global basis fails.
    #[test]
    fn order_forty_cardinal_functions_are_exact() {
        let n = 20;
        let conds: Vec<CondSpec> = (0..2 * n)
            .map(|i| CondSpec {
                u: (1.0 - (std::f64::consts::PI * i as f64 / (2 * n - 1) as f64).cos()) / 2.0,
                order: 0,
            })
            .collect();
        for c in [1.0, 7.0] {
            let l = ChebCardinal::new(&ExpSpace::symmetric(c, n), &conds, 1).unwrap();
            let mut err: f64 = 0.0;
            for (k, cd) in conds.iter().enumerate() {
                let v = l.eval(cd.u, 0);
                for (i, x) in v[0].iter().enumerate() {
                    err = crate::num::max_nan(err, (x - if i == k { 1.0 } else { 0.0 }).abs());
                }
            }
            assert!(err < 1e-12, "c = {c}: cardinal error {err:e} at {} bits", l.bits());
        }
    }
}
