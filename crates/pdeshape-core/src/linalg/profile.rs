//! Cholesky factorisation of a symmetric positive definite matrix stored by its envelope
//! (profile): row `i` keeps `A[i][f_i ..= i]`, `f_i` the column of its first non-zero.
//!
//! `A = L Lᵀ` with, for `j < i`,
//!
//! `L_ij = (A_ij − Σ_{k = max(f_i, f_j)}^{j−1} L_ik L_jk) / L_jj`,
//! `L_ii = √(A_ii − Σ_{k = f_i}^{i−1} L_ik²)`,
//!
//! so `L_ij = 0` for `j < f_i` (a sum over an empty range of an entry that is zero): the
//! factor has the matrix's envelope, and the work is `Σ_i (i − f_i)²` instead of `n³/3`
//! (George and Liu, *Computer Solution of Large Sparse Positive Definite Systems*, 1981,
//! ch. 4). A periodic spline fit's normal equations, ordered control point by control
//! point, are banded but for a few rows that wrap round: their envelope is the band and
//! those rows.
//!
//! The condition number is the 1-norm one, `κ₁ = ‖A‖₁ ‖A⁻¹‖₁`, with `‖A⁻¹‖₁` estimated
//! from a few solves ([`super::inverse_norm1_estimate_by`]: Hager's method with Higham's
//! extra vector, LAPACK's estimator): the estimate never exceeds `‖A⁻¹‖₁` and in practice
//! equals it or comes within a small factor. For a symmetric matrix `κ₂ ≤ κ₁ ≤ n κ₂`.

use super::LinalgError;
use faer::Mat;

/// `A = L Lᵀ` in envelope storage, with the estimated 1-norm condition number of `A`.
pub struct ProfileCholesky {
    /// Column of the first stored entry of each row.
    first: Vec<usize>,
    /// Row `i` of `L`, columns `first[i] ..= i`.
    rows: Vec<Vec<f64>>,
    cond: f64,
}

impl ProfileCholesky {
    /// Factorizes the symmetric `a` (its lower triangle is read; entries that are exactly
    /// zero left of a row's first non-zero are outside its envelope). Fails when `a` has a
    /// non-finite entry, is not positive definite to working precision, or its estimated
    /// 1-norm condition number exceeds `max_cond`.
    pub fn new(a: &Mat<f64>, max_cond: f64) -> Result<Self, LinalgError> {
        assert_eq!(a.nrows(), a.ncols(), "ProfileCholesky needs a square matrix");
        let n = a.nrows();
        if !(0..n).all(|i| (0..=i).all(|j| a[(i, j)].is_finite())) {
            return Err(LinalgError::NonFinite);
        }
        let first: Vec<usize> = (0..n).map(|i| (0..i).find(|&j| a[(i, j)] != 0.0).unwrap_or(i)).collect();
        let mut rows: Vec<Vec<f64>> = Vec::with_capacity(n);
        for i in 0..n {
            let fi = first[i];
            let mut row: Vec<f64> = (fi..=i).map(|j| a[(i, j)]).collect();
            for j in fi..i {
                let (fj, rj) = (first[j], &rows[j]);
                let k0 = fi.max(fj);
                let mut s = row[j - fi];
                for k in k0..j {
                    s -= row[k - fi] * rj[k - fj];
                }
                row[j - fi] = s / rj[j - fj];
            }
            let d = row[i - fi] - row[..i - fi].iter().map(|x| x * x).sum::<f64>();
            // not positive definite to working precision (or NaN from an overflow)
            if d.is_nan() || d <= 0.0 {
                return Err(LinalgError::NotPositiveDefinite { row: i });
            }
            row[i - fi] = d.sqrt();
            rows.push(row);
        }
        let mut f = ProfileCholesky { first, rows, cond: f64::NAN };
        // ‖A‖₁ of the symmetric matrix: its largest absolute column sum = row sum
        let norm1 = (0..n)
            .map(|i| (0..n).map(|j| if j <= i { a[(i, j)] } else { a[(j, i)] }.abs()).sum::<f64>())
            .fold(0.0, crate::num::max_nan);
        // A is symmetric: A⁻ᵀ = A⁻¹
        f.cond = norm1 * super::inverse_norm1_estimate_by(n, |b| f.solve(b), |b| f.solve(b));
        if f.cond.is_nan() || f.cond > max_cond {
            return Err(LinalgError::SingularEstimate { cond: f.cond });
        }
        Ok(f)
    }

    /// The order of the matrix.
    pub fn len(&self) -> usize {
        self.rows.len()
    }

    /// Whether the matrix is empty.
    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }

    /// The estimated 1-norm condition number `‖A‖₁ ‖A⁻¹‖₁` (see the module's documentation).
    pub fn cond(&self) -> f64 {
        self.cond
    }

    /// Overwrites `x` (`b` on entry) with `A⁻¹ b`: `L y = b` forward, `Lᵀ x = y` backward.
    pub fn solve_in_place(&self, x: &mut [f64]) {
        let n = self.len();
        assert_eq!(x.len(), n, "a right-hand side of the matrix's order");
        for i in 0..n {
            let (fi, r) = (self.first[i], &self.rows[i]);
            let mut s = x[i];
            for k in fi..i {
                s -= r[k - fi] * x[k];
            }
            x[i] = s / r[i - fi];
        }
        for i in (0..n).rev() {
            let (fi, r) = (self.first[i], &self.rows[i]);
            x[i] /= r[i - fi];
            let xi = x[i];
            for k in fi..i {
                x[k] -= r[k - fi] * xi;
            }
        }
    }

    /// Solves `A X = B` for every column of `B`.
    pub fn solve(&self, b: &Mat<f64>) -> Mat<f64> {
        let mut out = b.to_owned();
        let mut col = vec![0.0; self.len()];
        for c in 0..b.ncols() {
            col.iter_mut().enumerate().for_each(|(i, x)| *x = b[(i, c)]);
            self.solve_in_place(&mut col);
            col.iter().enumerate().for_each(|(i, &x)| out[(i, c)] = x);
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A reproducible generator (SplitMix64) for the test matrices.
    fn rng(mut s: u64) -> impl FnMut() -> f64 {
        move || {
            s = s.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = s;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            ((z ^ (z >> 31)) >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    /// `Bᵀ B + δ I` with `B` of rows supported on `band` consecutive columns that wrap
    /// round (a periodic fit's normal equations), in random order of magnitude.
    fn periodic_normal(n: usize, band: usize, delta: f64, seed: u64) -> Mat<f64> {
        let mut r = rng(seed);
        let mut g = Mat::<f64>::zeros(n, n);
        for _ in 0..3 * n {
            let j0 = (r() * n as f64) as usize % n;
            let vals: Vec<(usize, f64)> = (0..band).map(|p| ((j0 + p) % n, r() - 0.5)).collect();
            for &(a, va) in &vals {
                for &(b, vb) in &vals {
                    g[(a, b)] += va * vb;
                }
            }
        }
        for i in 0..n {
            g[(i, i)] += delta;
        }
        g
    }

    /// Against faer's dense Cholesky and inverse: the solution to round-off times the
    /// condition number, the envelope as the matrix's, the estimate of `κ₁` never above
    /// the exact one (from the dense inverse) and here within a factor 3 of it.
    #[test]
    fn profile_cholesky_solves_as_dense_and_estimates_kappa1() {
        for (seed, (n, band, delta)) in
            [(40, 4, 1e-3), (97, 6, 1e-6), (160, 16, 1e-2), (7, 3, 0.5)].into_iter().enumerate()
        {
            let a = periodic_normal(n, band, delta, seed as u64 + 1);
            let f = ProfileCholesky::new(&a, 1e15).unwrap();
            // the wrap-round rows are long, the others within the band
            let stored: usize = f.rows.iter().map(|r| r.len()).sum();
            assert!(stored < n * n / 2 + n, "n {n}: {stored} entries stored");
            let mut r = rng(100 + seed as u64);
            let b = Mat::<f64>::from_fn(n, 3, |_, _| r() - 0.5);
            let x = f.solve(&b);
            let dense = faer::linalg::solvers::Llt::new(a.as_ref(), faer::Side::Lower).unwrap();
            let inv = faer::linalg::solvers::DenseSolveCore::inverse(&dense);
            let kappa1 = {
                let col = |m: &Mat<f64>| {
                    (0..n).map(|j| (0..n).map(|i| m[(i, j)].abs()).sum::<f64>()).fold(0.0, crate::num::max_nan)
                };
                col(&a) * col(&inv)
            };
            let want = &inv * &b;
            let scale = (0..3)
                .flat_map(|c| (0..n).map(move |i| (i, c)))
                .map(|(i, c)| want[(i, c)].abs())
                .fold(0.0, crate::num::max_nan);
            let err = (0..3)
                .flat_map(|c| (0..n).map(move |i| (i, c)))
                .map(|(i, c)| (x[(i, c)] - want[(i, c)]).abs())
                .fold(0.0, crate::num::max_nan);
            // two backward-stable solves differ by at most ~n ε κ relative
            assert!(err <= 1e-15 * n as f64 * kappa1 * scale, "n {n}: error {err:e}, κ₁ {kappa1:e}");
            assert!(f.cond() <= kappa1 * (1.0 + 1e-9), "n {n}: estimate {:e} above κ₁ {kappa1:e}", f.cond());
            assert!(f.cond() >= kappa1 / 3.0, "n {n}: estimate {:e}, κ₁ {kappa1:e}", f.cond());
        }
    }

    /// A matrix that is not positive definite names the row; a non-finite entry, a
    /// condition number over the cap are refused.
    #[test]
    fn profile_cholesky_refuses_what_it_cannot_factor() {
        let m = |rows: &[[f64; 3]]| Mat::<f64>::from_fn(3, 3, |i, j| rows[i][j]);
        let indefinite = m(&[[1.0, 2.0, 0.0], [2.0, 1.0, 0.0], [0.0, 0.0, 1.0]]);
        assert!(matches!(ProfileCholesky::new(&indefinite, 1e15), Err(LinalgError::NotPositiveDefinite { row: 1 })));
        let nan = m(&[[1.0, 0.0, 0.0], [f64::NAN, 1.0, 0.0], [0.0, 0.0, 1.0]]);
        assert!(matches!(ProfileCholesky::new(&nan, 1e15), Err(LinalgError::NonFinite)));
        let ill = m(&[[1.0, 0.0, 0.0], [0.0, 1e-12, 0.0], [0.0, 0.0, 1.0]]);
        match ProfileCholesky::new(&ill, 1e10) {
            // diagonal: κ₁ = 1e12 exactly, and the estimate finds it
            Err(LinalgError::SingularEstimate { cond }) => assert!((cond / 1e12 - 1.0).abs() < 1e-12, "{cond:e}"),
            other => panic!("{:?}", other.map(|f| f.cond())),
        }
    }
}
