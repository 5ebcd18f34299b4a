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

/// A symmetric matrix by its envelope: row `i` holds `A[i][f_i ..= i]`, every entry left
/// of `f_i` zero.
#[derive(Clone, Debug, PartialEq)]
pub struct Envelope {
    /// `f_i`, the column of row `i`'s first stored entry.
    pub first: Vec<usize>,
    /// Row `i`, columns `first[i] ..= i`.
    pub rows: Vec<Vec<f64>>,
}

impl Envelope {
    /// The envelope of the lower triangle of `a` (`f_i` its first non-zero column).
    pub fn from_dense(a: &Mat<f64>) -> Self {
        let n = a.nrows();
        let first: Vec<usize> = (0..n).map(|i| (0..i).find(|&j| a[(i, j)] != 0.0).unwrap_or(i)).collect();
        Self::from_dense_in(a, first)
    }

    /// `a`'s lower triangle inside the envelope `first` (entries left of it not read).
    pub fn from_dense_in(a: &Mat<f64>, first: Vec<usize>) -> Self {
        let rows = first.iter().enumerate().map(|(i, &f)| (f..=i).map(|j| a[(i, j)]).collect()).collect();
        Envelope { first, rows }
    }

    /// The zero matrix with envelope `first` (`first[i] ≤ i`).
    pub fn zeros(first: Vec<usize>) -> Self {
        let rows = first.iter().enumerate().map(|(i, &f)| vec![0.0; i + 1 - f]).collect();
        Envelope { first, rows }
    }

    /// `A_ij += v` for `j ≤ i` (the lower triangle; `A_ji` is the same entry). Panics
    /// outside the envelope.
    pub fn add_lower(&mut self, i: usize, j: usize, v: f64) {
        assert!(j <= i && j >= self.first[i], "({i}, {j}) outside the envelope");
        self.rows[i][j - self.first[i]] += v;
    }

    /// The order.
    pub fn len(&self) -> usize {
        self.rows.len()
    }

    /// Whether the order is zero.
    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }

    /// `A_ij` (zero outside the envelope).
    pub fn get(&self, i: usize, j: usize) -> f64 {
        let (r, c) = if i >= j { (i, j) } else { (j, i) };
        if c < self.first[r] { 0.0 } else { self.rows[r][c - self.first[r]] }
    }

    /// `Σ_t c_t A_t` of matrices with this envelope (`self` gives the envelope).
    pub fn combination(&self, terms: &[(f64, &Envelope)]) -> Envelope {
        let rows = (0..self.len())
            .map(|i| {
                let mut r = vec![0.0; self.rows[i].len()];
                for &(c, t) in terms {
                    assert_eq!(t.first[i], self.first[i], "one envelope");
                    r.iter_mut().zip(&t.rows[i]).for_each(|(x, y)| *x += c * y);
                }
                r
            })
            .collect();
        Envelope { first: self.first.clone(), rows }
    }

    /// `A x`.
    pub fn mul(&self, x: &[f64]) -> Vec<f64> {
        let mut y = vec![0.0; self.len()];
        for (i, r) in self.rows.iter().enumerate() {
            let fi = self.first[i];
            for (c, &a) in r.iter().enumerate() {
                let j = fi + c;
                y[i] += a * x[j];
                if j != i {
                    y[j] += a * x[i];
                }
            }
        }
        y
    }

    /// `‖A‖₁`, the largest absolute column sum (= row sum).
    pub fn norm1(&self) -> f64 {
        let mut sums = vec![0.0; self.len()];
        for (i, r) in self.rows.iter().enumerate() {
            let fi = self.first[i];
            for (c, &a) in r.iter().enumerate() {
                let j = fi + c;
                sums[i] += a.abs();
                if j != i {
                    sums[j] += a.abs();
                }
            }
        }
        sums.into_iter().fold(0.0, crate::num::max_nan)
    }
}

impl ProfileCholesky {
    /// Factorizes the symmetric `a` (its lower triangle is read; entries that are exactly
    /// zero left of a row's first non-zero are outside its envelope). Fails when `a` has a
    /// non-finite entry, is not positive definite to working precision, or its estimated
    /// 1-norm condition number exceeds `max_cond`.
    pub fn new(a: &Mat<f64>, max_cond: f64) -> Result<Self, LinalgError> {
        assert_eq!(a.nrows(), a.ncols(), "ProfileCholesky needs a square matrix");
        Self::from_envelope(&Envelope::from_dense(a), max_cond)
    }

    /// Factorizes the symmetric matrix stored by its envelope (see [`Self::new`]).
    pub fn from_envelope(a: &Envelope, max_cond: f64) -> Result<Self, LinalgError> {
        Self::factor(a)?.with_cond(a, max_cond)
    }

    /// This factorisation of `a` (from [`Self::factor`]) with `a`'s condition number
    /// estimated; fails as [`Self::new`] does when it exceeds `max_cond`.
    pub fn with_cond(mut self, a: &Envelope, max_cond: f64) -> Result<Self, LinalgError> {
        let norm1 = a.norm1();
        // A is symmetric: A⁻ᵀ = A⁻¹
        let f = &self;
        let cond = norm1 * super::inverse_norm1_estimate_by(a.len(), |b| f.solve(b), |b| f.solve(b));
        if cond.is_nan() || cond > max_cond {
            return Err(LinalgError::SingularEstimate { cond });
        }
        self.cond = cond;
        Ok(self)
    }

    /// The factorisation alone, its condition number not estimated ([`Self::cond`] is
    /// NaN): for searches that factor many matrices and keep one. Fails as
    /// [`Self::new`] does but for the condition number.
    pub fn factor(a: &Envelope) -> Result<Self, LinalgError> {
        let n = a.len();
        if !a.rows.iter().all(|r| r.iter().all(|x| x.is_finite())) {
            return Err(LinalgError::NonFinite);
        }
        let first = a.first.clone();
        let mut rows: Vec<Vec<f64>> = Vec::with_capacity(n);
        for i in 0..n {
            let fi = first[i];
            let mut row: Vec<f64> = a.rows[i].clone();
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
        Ok(ProfileCholesky { first, rows, cond: f64::NAN })
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

    /// The entries of `A⁻¹` inside the envelope: row `i`, columns `f_i ..= i`, stored as
    /// `L`'s rows are. From `Lᵀ Z = L⁻¹` with `Z = A⁻¹` and `(L⁻¹)_ji = δ_ij / L_jj` for
    /// `i ≥ j` (`L⁻¹` is lower triangular):
    ///
    /// `Z_ij = (δ_ij / L_jj − Σ_{k > j} L_kj Z_ki) / L_jj`,
    ///
    /// the sum over the rows `k` of `L`'s column `j`. Taken column by column from the last,
    /// and in a column from the bottom row up, every `Z_ki` it needs is already known and
    /// lies inside the envelope (`f_k ≤ j` and `f_i ≤ j` with `k, i ≥ j`): the envelope is
    /// closed under the recurrence (Takahashi, Fagan and Chin, 1973; Erisman and Tinney,
    /// *Comm. ACM* 18, 1975). The work is `Σ_j c_j²`, `c_j` the length of column `j`, the
    /// factorisation's order of work, where the whole inverse costs `n³`.
    pub fn inverse_in_envelope(&self) -> Vec<Vec<f64>> {
        let n = self.len();
        let mut cols: Vec<Vec<(usize, f64)>> = vec![Vec::new(); n];
        for (k, (&fk, r)) in self.first.iter().zip(&self.rows).enumerate() {
            for j in fk..k {
                cols[j].push((k, r[j - fk]));
            }
        }
        let mut z: Vec<Vec<f64>> = self.rows.iter().map(|r| vec![0.0; r.len()]).collect();
        let first = &self.first;
        for j in (0..n).rev() {
            let ljj = self.rows[j][j - first[j]];
            let col = &cols[j];
            // the rows below j in column j, then j itself: each needs only Z's entries in
            // later columns and, for i = j, the ones just found below it. Column j's rows
            // increase, so for i = col[p] the rows k = col[..=p] are at most i (Z_ik in row
            // i) and col[p+1..] above it (Z_ki in row k)
            for p in (0..col.len()).rev() {
                let i = col[p].0;
                let (zi, fi) = (&z[i], first[i]);
                let mut s: f64 = col[..=p].iter().map(|&(k, lkj)| lkj * zi[k - fi]).sum();
                s += col[p + 1..].iter().map(|&(k, lkj)| lkj * z[k][i - first[k]]).sum::<f64>();
                z[i][j - fi] = -s / ljj;
            }
            let s: f64 = col.iter().map(|&(k, lkj)| lkj * z[k][j - first[k]]).sum();
            z[j][j - first[j]] = (1.0 / ljj - s) / ljj;
        }
        z
    }

    /// `tr(A⁻¹ B)` for a symmetric `B` inside `A`'s envelope: `Σ_i Z_ii B_ii + 2
    /// Σ_{f_i ≤ j < i} Z_ij B_ij` with `Z` from [`Self::inverse_in_envelope`].
    pub fn trace_of_inverse_times(&self, b: &Envelope) -> f64 {
        assert!(b.first.iter().zip(&self.first).all(|(fb, fa)| fb >= fa), "B inside A's envelope");
        let z = self.inverse_in_envelope();
        let mut t = 0.0;
        for (i, zi) in z.iter().enumerate() {
            let fi = self.first[i];
            for (c, &zij) in zi.iter().enumerate() {
                let j = fi + c;
                t += if j == i { zij * b.get(i, i) } else { 2.0 * zij * b.get(i, j) };
            }
        }
        t
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

    /// The envelope of the inverse against a closed form: the second-difference matrix
    /// `tridiag(−1, 2, −1)` of order `n` has `(A⁻¹)_ij = i (n + 1 − j) / (n + 1)` for
    /// `1 ≤ i ≤ j ≤ n`; and against faer's dense inverse on periodic normal matrices, whose
    /// wrap-round rows make the envelope more than a band. `tr(A⁻¹ A) = n` and `tr(A⁻¹ B)`
    /// against the dense product.
    #[test]
    fn inverse_in_envelope_matches_closed_form_and_dense() {
        let n = 30;
        let lap = Mat::<f64>::from_fn(n, n, |i, j| match i.abs_diff(j) {
            0 => 2.0,
            1 => -1.0,
            _ => 0.0,
        });
        let f = ProfileCholesky::new(&lap, 1e15).unwrap();
        let z = f.inverse_in_envelope();
        let mut worst: f64 = 0.0;
        for (i, zi) in z.iter().enumerate() {
            for (c, &zij) in zi.iter().enumerate() {
                let j = f.first[i] + c;
                let (lo, hi) = (j.min(i) + 1, j.max(i) + 1);
                let want = (lo * (n + 1 - hi)) as f64 / (n + 1) as f64;
                worst = crate::num::max_nan(worst, (zij - want).abs() / want);
            }
        }
        // the matrix's condition number is ~4 (n+1)²/π² ≈ 390: errors of a few hundred ε
        assert!(worst < 1e-13, "tridiagonal: relative error {worst:e}");
        for (seed, (n, band, delta)) in [(40, 4, 1e-3), (97, 6, 1e-6), (7, 3, 0.5)].into_iter().enumerate() {
            let a = periodic_normal(n, band, delta, seed as u64 + 11);
            let f = ProfileCholesky::new(&a, 1e15).unwrap();
            let dense = faer::linalg::solvers::Llt::new(a.as_ref(), faer::Side::Lower).unwrap();
            let inv = faer::linalg::solvers::DenseSolveCore::inverse(&dense);
            let scale = (0..n).map(|i| inv[(i, i)].abs()).fold(0.0, crate::num::max_nan);
            let z = f.inverse_in_envelope();
            let mut err: f64 = 0.0;
            for (i, zi) in z.iter().enumerate() {
                for (c, &zij) in zi.iter().enumerate() {
                    err = crate::num::max_nan(err, (zij - inv[(i, f.first[i] + c)]).abs());
                }
            }
            // two backward-stable inverses differ by ~n ε κ of the largest entry
            assert!(err <= 1e-15 * n as f64 * f.cond() * scale, "n {n}: error {err:e}, κ₁ {:e}", f.cond());
            // symmetric, with `a`'s pattern
            let b = Mat::<f64>::from_fn(n, n, |i, j| a[(i, j)] * (1.5 + ((i + j) as f64).sin()));
            let want: f64 = (0..n).map(|i| (0..n).map(|k| inv[(i, k)] * b[(k, i)]).sum::<f64>()).sum();
            let got = f.trace_of_inverse_times(&Envelope::from_dense(&b));
            assert!((got - want).abs() <= 1e-15 * n as f64 * f.cond() * want.abs(), "n {n}: {got} against {want}");
            let own = f.trace_of_inverse_times(&Envelope::from_dense(&a));
            assert!((own - n as f64).abs() <= 1e-15 * n as f64 * f.cond(), "n {n}: tr(A⁻¹A) = {own}");
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
