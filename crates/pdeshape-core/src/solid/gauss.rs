//! Gauss–Legendre quadrature on `[0, 1]`.

/// Nodes and weights of the `n`-point Gauss–Legendre rule on `[0, 1]` (exact for
/// polynomials of degree `2n − 1`), by Newton's method on `P_n` from Chebyshev guesses.
///
/// ```
/// use pdeshape_core::solid::gauss_legendre;
/// let (x, w) = gauss_legendre(5);
/// let int: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(9)).sum();
/// assert!((int - 0.1).abs() < 1e-15);
/// ```
pub fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut x = Vec::with_capacity(n);
    let mut w = Vec::with_capacity(n);
    for i in 0..n {
        let mut z = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            // P_n(z) and P_n'(z) by the three-term recurrence
            let (mut p0, mut p1) = (1.0, z);
            for k in 2..=n {
                let kf = k as f64;
                let p2 = ((2.0 * kf - 1.0) * z * p1 - (kf - 1.0) * p0) / kf;
                p0 = p1;
                p1 = p2;
            }
            let p = if n == 0 { 1.0 } else { p1 };
            let pm = if n == 0 { 0.0 } else { p0 };
            dp = n as f64 * (z * p - pm) / (z * z - 1.0);
            let dz = p / dp;
            z -= dz;
            if dz.abs() < 1e-16 {
                break;
            }
        }
        x.push((1.0 - z) / 2.0);
        w.push(1.0 / ((1.0 - z * z) * dp * dp));
    }
    (x, w)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rules_integrate_polynomials_exactly() {
        for n in [1, 2, 7, 20, 64] {
            let (x, w) = gauss_legendre(n);
            assert!((w.iter().sum::<f64>() - 1.0).abs() < 1e-14);
            let d = 2 * n - 1;
            let int: f64 = x.iter().zip(&w).map(|(x, w)| w * x.powi(d as i32)).sum();
            assert!((int - 1.0 / (d + 1) as f64).abs() < 1e-14, "n {n}");
        }
    }
}
