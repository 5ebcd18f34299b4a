//! Dense linear algebra on top of `faer`: pivoted factorizations that report their
//! condition numbers.

use crate::num::MaxNan;
use faer::Mat;
use faer::Side;
use faer::linalg::solvers::{FullPivLu, Llt, Solve};

/// A failed factorization.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum LinalgError {
    /// The matrix is singular to working precision.
    #[error("the system is singular (2-norm condition number {cond:.3e})")]
    Singular {
        /// The estimated condition number (∞ when a singular value is exactly zero).
        cond: f64,
    },
    /// The matrix has non-finite entries.
    #[error("the system has non-finite entries")]
    NonFinite,
    /// The singular value decomposition did not converge.
    #[error("the singular value decomposition did not converge")]
    NoConvergence,
    /// The matrix is singular to working precision by its estimated 1-norm condition
    /// number ([`ProfileCholesky`]).
    #[error("the system is singular (1-norm condition number estimated at {cond:.3e})")]
    SingularEstimate {
        /// The estimate.
        cond: f64,
    },
    /// A Cholesky factorisation met a pivot that is not positive.
    #[error("the system is not positive definite to working precision (row {row})")]
    NotPositiveDefinite {
        /// The row where the pivot was not positive.
        row: usize,
    },
}

mod profile;
pub use profile::{Envelope, ProfileCholesky};

/// The 2-norm condition number `σ_max / σ_min` of a matrix (∞ for a rank-deficient one).
pub fn condition_number(a: &Mat<f64>) -> Result<f64, LinalgError> {
    if a.nrows() == 0 || a.ncols() == 0 {
        return Ok(1.0);
    }
    if !(0..a.nrows()).all(|i| (0..a.ncols()).all(|j| a[(i, j)].is_finite())) {
        return Err(LinalgError::NonFinite);
    }
    let s = crate::lanes::after(a.singular_values()).map_err(|_| LinalgError::NoConvergence)?;
    let max = s.iter().cloned().max_nan();
    let min = s.iter().cloned().fold(f64::INFINITY, f64::min);
    Ok(if min > 0.0 { max / min } else { f64::INFINITY })
}

/// A square system factorized by LU with full pivoting, with its condition number.
pub struct SquareSolver {
    lu: FullPivLu<f64>,
    cond: f64,
}

impl SquareSolver {
    /// Factorizes `a`; fails when the condition number exceeds `max_cond`.
    pub fn new(a: &Mat<f64>, max_cond: f64) -> Result<Self, LinalgError> {
        assert_eq!(a.nrows(), a.ncols(), "SquareSolver needs a square matrix");
        let cond = condition_number(a)?;
        if cond.is_nan() || cond > max_cond {
            return Err(LinalgError::Singular { cond });
        }
        Ok(SquareSolver { lu: crate::lanes::after(a.full_piv_lu()), cond })
    }

    /// The 2-norm condition number of the factorized matrix.
    pub fn cond(&self) -> f64 {
        self.cond
    }

    /// Solves `A X = B` for every column of `B`.
    pub fn solve(&self, b: &Mat<f64>) -> Mat<f64> {
        crate::lanes::after(self.lu.solve(b))
    }
}

/// A symmetric positive definite system (normal equations, penalised fits) factorized by
/// Cholesky, with its condition number.
///
/// A symmetric positive definite `A` has its eigenvalues for singular values, so its 2-norm
/// condition number is `λ_max / λ_min` from the symmetric eigenvalue problem (one
/// tridiagonal reduction), the same number [`condition_number`] finds by an SVD at several
/// times the cost. A matrix with an eigenvalue `≤ 0` (indefinite, or semidefinite to
/// working precision) is refused as singular.
pub struct SpdSolver {
    llt: Llt<f64>,
    cond: f64,
}

impl SpdSolver {
    /// Factorizes the symmetric `a` (its lower triangle is read); fails when `a` is not
    /// positive definite or its condition number exceeds `max_cond`.
    pub fn new(a: &Mat<f64>, max_cond: f64) -> Result<Self, LinalgError> {
        assert_eq!(a.nrows(), a.ncols(), "SpdSolver needs a square matrix");
        let n = a.nrows();
        if !(0..n).all(|j| (j..n).all(|i| a[(i, j)].is_finite())) {
            return Err(LinalgError::NonFinite);
        }
        // nondecreasing
        let ev =
            crate::lanes::after(a.self_adjoint_eigenvalues(Side::Lower)).map_err(|_| LinalgError::NoConvergence)?;
        let cond = match (ev.first(), ev.last()) {
            (Some(&min), Some(&max)) if min > 0.0 => max / min,
            (Some(_), Some(_)) => f64::INFINITY,
            _ => 1.0,
        };
        if cond.is_nan() || cond > max_cond {
            return Err(LinalgError::Singular { cond });
        }
        let llt = crate::lanes::after(a.llt(Side::Lower)).map_err(|_| LinalgError::Singular { cond: f64::INFINITY })?;
        Ok(SpdSolver { llt, cond })
    }

    /// The 2-norm condition number of the factorized matrix.
    pub fn cond(&self) -> f64 {
        self.cond
    }

    /// Solves `A X = B` for every column of `B`.
    pub fn solve(&self, b: &Mat<f64>) -> Mat<f64> {
        crate::lanes::after(self.llt.solve(b))
    }
}

/// Solves the least-squares problem `min ‖A x − b‖₂` for every column of `b` by QR with
/// column pivoting; returns the solution and the condition number of `A`.
///
/// For a tall `A` (more rows than columns) the condition number is that of the square
/// factor: `A P = Q R` with `Q`'s columns orthonormal has the singular values of `R`, and
/// the SVD of `R` costs `n³` where that of `A` costs `m n²` and a workspace of `A`'s size.
pub fn least_squares(a: &Mat<f64>, b: &Mat<f64>, max_cond: f64) -> Result<(Mat<f64>, f64), LinalgError> {
    use faer::linalg::solvers::SolveLstsq;
    if a.nrows() <= a.ncols() || a.ncols() == 0 {
        let cond = condition_number(a)?;
        if cond.is_nan() || cond > max_cond {
            return Err(LinalgError::Singular { cond });
        }
        return Ok((crate::lanes::after(a.col_piv_qr().solve_lstsq(b)), cond));
    }
    if !(0..a.ncols()).all(|j| (0..a.nrows()).all(|i| a[(i, j)].is_finite())) {
        return Err(LinalgError::NonFinite);
    }
    let qr = crate::lanes::after(a.col_piv_qr());
    let cond = condition_number(&qr.thin_R().to_owned())?;
    if cond.is_nan() || cond > max_cond {
        return Err(LinalgError::Singular { cond });
    }
    Ok((crate::lanes::after(qr.solve_lstsq(b)), cond))
}

/// Minimum-norm least squares `min ‖A x − B‖` by the thin SVD, dropping singular values
/// below `rcond · σ_max`: the right answer when `A` is rank deficient but every solution
/// gives the same fit (e.g. basis functions that coincide at one instant). Returns the
/// solution and the numerical rank.
pub fn least_squares_min_norm(a: &Mat<f64>, b: &Mat<f64>, rcond: f64) -> Result<(Mat<f64>, usize), LinalgError> {
    if !(0..a.nrows()).all(|i| (0..a.ncols()).all(|j| a[(i, j)].is_finite())) {
        return Err(LinalgError::NonFinite);
    }
    let svd = crate::lanes::after(a.thin_svd()).map_err(|_| LinalgError::NoConvergence)?;
    let (u, s, v) = (svd.U(), svd.S().column_vector(), svd.V());
    let smax = (0..s.nrows()).map(|i| s[i]).max_nan();
    let mut utb = crate::lanes::after(u.transpose() * b);
    let mut rank = 0;
    for i in 0..s.nrows() {
        let keep = s[i] > rcond * smax && s[i] > 0.0;
        rank += usize::from(keep);
        for c in 0..b.ncols() {
            utb[(i, c)] = if keep { utb[(i, c)] / s[i] } else { 0.0 };
        }
    }
    Ok((crate::lanes::after(v * utb), rank))
}

/// An estimate of `‖A⁻¹‖₁` from a factorization of `A` (`n × n`), by Hager's method with
/// Higham's refinements (the estimator of LAPACK's `xGECON`): a few solves with `A` and
/// `Aᵀ` instead of the `n` solves of the inverse. The estimate is a lower bound, exact for
/// many matrices and rarely below a third of the true value (Higham, "Accuracy and
/// Stability of Numerical Algorithms", §15.3). NaN in, NaN out.
pub fn inverse_norm1_estimate(lu: &impl Solve<f64>, n: usize) -> f64 {
    inverse_norm1_estimate_by(n, |b| crate::lanes::after(lu.solve(b)), |b| crate::lanes::after(lu.solve_transpose(b)))
}

/// [`inverse_norm1_estimate`] with the solves with `A` and `Aᵀ` given (a factorization
/// that is not one of faer's).
pub fn inverse_norm1_estimate_by(
    n: usize,
    solve: impl Fn(&Mat<f64>) -> Mat<f64>,
    solve_transpose: impl Fn(&Mat<f64>) -> Mat<f64>,
) -> f64 {
    if n == 0 {
        return 0.0;
    }
    let norm1 = |v: &Mat<f64>| (0..n).map(|i| v[(i, 0)].abs()).sum::<f64>();
    let mut x = Mat::<f64>::from_fn(n, 1, |_, _| 1.0 / n as f64);
    let mut est = f64::NAN;
    let mut last_j = usize::MAX;
    for iter in 0..5 {
        let y = solve(&x);
        let ny = norm1(&y);
        if !ny.is_finite() {
            return ny;
        }
        if iter > 0 && ny <= est {
            break;
        }
        est = ny;
        let xi = Mat::<f64>::from_fn(n, 1, |i, _| if y[(i, 0)] >= 0.0 { 1.0 } else { -1.0 });
        let z = solve_transpose(&xi);
        let (mut j, mut zj) = (0, f64::NEG_INFINITY);
        for i in 0..n {
            if z[(i, 0)].abs() > zj {
                (j, zj) = (i, z[(i, 0)].abs());
            }
        }
        let ztx: f64 = (0..n).map(|i| z[(i, 0)] * x[(i, 0)]).sum();
        if iter > 0 && (zj <= ztx || j == last_j) {
            break;
        }
        last_j = j;
        x = Mat::<f64>::zeros(n, 1);
        x[(j, 0)] = 1.0;
    }
    // Higham's extra vector guards against the cases Hager's iteration misses
    let alt = Mat::<f64>::from_fn(n, 1, |i, _| {
        let s = if i % 2 == 0 { 1.0 } else { -1.0 };
        s * (1.0 + i as f64 / (n.max(2) - 1) as f64)
    });
    let extra = 2.0 * norm1(&solve(&alt)) / (3.0 * n as f64);
    crate::num::max_nan(est, extra)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_and_reports_conditioning() {
        let a = Mat::from_fn(3, 3, |i, j| if i == j { 2.0 } else { 0.5 });
        let b = Mat::from_fn(3, 1, |i, _| i as f64);
        let s = SquareSolver::new(&a, 1e12).unwrap();
        let x = s.solve(&b);
        let r = &a * &x - &b;
        assert!(r.norm_max() < 1e-14);
        assert!((s.cond() - 3.0 / 1.5).abs() < 1e-12);
        let sing = Mat::from_fn(2, 2, |_, _| 1.0);
        assert!(matches!(SquareSolver::new(&sing, 1e12), Err(LinalgError::Singular { .. })));
        // rank-deficient least squares: two equal columns share the fit equally
        let a = Mat::from_fn(3, 2, |i, _| (i + 1) as f64);
        let b = Mat::from_fn(3, 1, |i, _| 2.0 * (i + 1) as f64);
        let (x, rank) = least_squares_min_norm(&a, &b, 1e-12).unwrap();
        assert_eq!(rank, 1);
        assert!((x[(0, 0)] - 1.0).abs() < 1e-14 && (x[(1, 0)] - 1.0).abs() < 1e-14);
    }

    #[test]
    fn spd_solver_condition_by_hand_and_refusals() {
        // [[2, 1], [1, 2]] has eigenvalues 3 and 1 (by hand): condition number 3
        let a = Mat::from_fn(2, 2, |i, j| if i == j { 2.0 } else { 1.0 });
        let s = SpdSolver::new(&a, 1e12).unwrap();
        // round-off of a 2 × 2 symmetric eigenvalue problem
        assert!((s.cond() - 3.0).abs() < 1e-14, "{}", s.cond());
        // A (1, 1)ᵀ = (3, 3)ᵀ
        let x = s.solve(&Mat::from_fn(2, 1, |_, _| 3.0));
        assert!((x[(0, 0)] - 1.0).abs() < 1e-15 && (x[(1, 0)] - 1.0).abs() < 1e-15, "{x:?}");
        // indefinite (eigenvalues 3, −1) and singular (2, 0): refused, not factorized
        let indefinite = Mat::from_fn(2, 2, |i, j| if i == j { 1.0 } else { 2.0 });
        assert!(
            matches!(SpdSolver::new(&indefinite, 1e12), Err(LinalgError::Singular { cond }) if cond == f64::INFINITY)
        );
        let singular = Mat::from_fn(2, 2, |_, _| 1.0);
        assert!(matches!(SpdSolver::new(&singular, 1e12), Err(LinalgError::Singular { .. })));
        let mut nan = a.clone();
        nan[(1, 0)] = f64::NAN;
        assert!(matches!(SpdSolver::new(&nan, 1e12), Err(LinalgError::NonFinite)));
    }

    #[test]
    fn spd_solver_agrees_with_the_svd_and_lu() {
        // Gram matrices BᵀB + I of a fixed pseudo-random B, 40 × 40: the eigenvalue
        // condition number against the SVD's, the Cholesky solution against full-pivot LU
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        let mut rnd = || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        for scale in [1e-3, 1.0, 1e3] {
            let b = Mat::from_fn(60, 40, |_, _| rnd());
            let g = b.transpose() * &b * scale + Mat::<f64>::identity(40, 40);
            let spd = SpdSolver::new(&g, 1e13).unwrap();
            let lu = SquareSolver::new(&g, 1e13).unwrap();
            // both are backward stable: relative differences of a few ulps times cond
            let tol = 64.0 * f64::EPSILON * lu.cond();
            assert!((spd.cond() - lu.cond()).abs() <= tol * lu.cond(), "{} {}", spd.cond(), lu.cond());
            let rhs = Mat::from_fn(40, 3, |_, _| rnd());
            let (x, y) = (spd.solve(&rhs), lu.solve(&rhs));
            assert!((&x - &y).norm_max() <= tol * y.norm_max(), "{}", (&x - &y).norm_max());
        }
    }

    #[test]
    fn least_squares_fits_a_line() {
        let a = Mat::from_fn(5, 2, |i, j| if j == 0 { 1.0 } else { i as f64 });
        let b = Mat::from_fn(5, 1, |i, _| 2.0 + 3.0 * i as f64);
        let (x, cond) = least_squares(&a, &b, 1e12).unwrap();
        assert!((x[(0, 0)] - 2.0).abs() < 1e-12 && (x[(1, 0)] - 3.0).abs() < 1e-12);
        // AᵀA = [[5, 10], [10, 30]] has eigenvalues (35 ± √1025)/2; cond(A) is the root of
        // their ratio (by hand, not from the code's SVD)
        let by_hand = ((35.0 + 1025f64.sqrt()) / (35.0 - 1025f64.sqrt())).sqrt();
        assert!((cond - by_hand).abs() < 1e-13 * by_hand, "{cond} against {by_hand}");
        // a NaN entry is refused, not solved around
        let mut bad = a.clone();
        bad[(3, 1)] = f64::NAN;
        assert!(matches!(least_squares(&bad, &b, 1e12), Err(LinalgError::NonFinite)));
    }

    /// The tall path's condition number (from `R`) is the matrix's (from its SVD), on random
    /// matrices of growing conditioning, and a rank-deficient one is refused.
    #[test]
    fn tall_least_squares_reports_the_matrix_condition() {
        let mut seed = 99u64;
        let mut rnd = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        for grade in [1.0f64, 1e3, 1e6] {
            let a = Mat::from_fn(200, 6, |_, j| rnd() * grade.powf(-(j as f64) / 5.0));
            let b = Mat::from_fn(200, 2, |_, _| rnd());
            let (_, cond) = least_squares(&a, &b, 1e12).unwrap();
            let svd = condition_number(&a).unwrap();
            // both backward stable: agreement to ~cond × 1e-16 relative
            assert!((cond - svd).abs() <= 1e-13 * grade * svd, "{cond} against {svd}");
        }
        let rank5 = Mat::from_fn(50, 6, |i, j| if j == 5 { 0.0 } else { ((i * (j + 1)) as f64).sin() });
        assert!(matches!(least_squares(&rank5, &Mat::zeros(50, 1), 1e12), Err(LinalgError::Singular { .. })));
    }

    /// The estimate against the exact ‖A⁻¹‖₁ (from the inverse): never above it, and within
    /// a factor of 3 on random and graded matrices; exact on a diagonal one.
    #[test]
    fn inverse_norm_estimate_is_a_close_lower_bound() {
        let mut seed = 12345u64;
        let mut rnd = || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        for (n, grade) in [(5, 1.0f64), (40, 1.0), (110, 1.0), (60, 1e3), (30, 1e8)] {
            let a = Mat::<f64>::from_fn(n, n, |i, j| {
                let g = grade.powf(i as f64 / n as f64);
                g * (rnd() + if i == j { 2.0 } else { 0.0 })
            });
            let lu = a.partial_piv_lu();
            let inv = lu.solve(&Mat::<f64>::identity(n, n));
            let exact = (0..n).map(|c| (0..n).map(|r| inv[(r, c)].abs()).sum::<f64>()).fold(0.0, crate::num::max_nan);
            let est = inverse_norm1_estimate(&lu, n);
            assert!(est <= exact * (1.0 + 1e-12) && est >= exact / 3.0, "n = {n}, grade {grade}: {est:e} vs {exact:e}");
        }
        let d = Mat::<f64>::from_fn(4, 4, |i, j| if i == j { [2.0, 0.5, 4.0, 1e-3][i] } else { 0.0 });
        let est = inverse_norm1_estimate(&d.partial_piv_lu(), 4);
        assert!((est - 1e3).abs() <= 1e-9, "{est}");
    }
}
