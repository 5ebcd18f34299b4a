//! Truncated power series in one variable, as the loop data and the reparametrised
//! neighbours compose them: the Cauchy product and binomial coefficients.

/// `o_l = Σ_{i ≤ l} a_i b_{l−i}` for `l < o.len()` (`a`, `b` at least that long): the
/// truncated Cauchy product, summed in increasing `i`.
pub(crate) fn mul_into(a: &[f64], b: &[f64], o: &mut [f64]) {
    for (l, x) in o.iter_mut().enumerate() {
        *x = (0..=l).map(|i| a[i] * b[l - i]).sum();
    }
}

/// The Cauchy product of two series truncated at the shorter one's length.
pub(crate) fn mul(a: &[f64], b: &[f64]) -> Vec<f64> {
    let mut o = vec![0.0; a.len().min(b.len())];
    mul_into(a, b, &mut o);
    o
}

/// Rows of Pascal's triangle held exactly (every entry below 2⁵³).
const EXACT_ROWS: usize = 50;

/// Pascal's triangle, its first [`EXACT_ROWS`] rows, made at compile time.
static PASCAL: [[f64; EXACT_ROWS]; EXACT_ROWS] = {
    let mut t = [[0.0; EXACT_ROWS]; EXACT_ROWS];
    let mut a = 0;
    while a < EXACT_ROWS {
        t[a][0] = 1.0;
        let mut b = 1;
        while b <= a {
            t[a][b] = t[a - 1][b - 1] + t[a - 1][b];
            b += 1;
        }
        a += 1;
    }
    t
};

/// `C(n, k)` (0 for `k > n`): exact up to `n = 49` (Pascal's rule on integers below
/// 2⁵³), beyond that the product `Π (n − i)/(i + 1)`, rounded.
pub(crate) fn binomial(n: usize, k: usize) -> f64 {
    if k > n {
        0.0
    } else if n < EXACT_ROWS {
        PASCAL[n][k]
    } else {
        (0..k).fold(1.0, |b, i| b * (n - i) as f64 / (i + 1) as f64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Binomials against the closed forms `C(n, 0) = C(n, n) = 1`, `C(n, 1) = n`, the
    /// row sums `2ⁿ` (exact below 2⁵³), `C(n, 2)` past the exact rows and a value by hand, `C(49, 24) = 63 205 303 218 876`;
    /// the product `(1 + x)³ (1 − x)` truncated at four terms: `1 + 2x + 0x² − 2x³`.
    #[test]
    fn binomials_and_products() {
        for n in 0..50 {
            assert_eq!(binomial(n, 0), 1.0);
            assert_eq!(binomial(n, n), 1.0);
            assert_eq!(binomial(n, n + 1), 0.0);
            if n > 0 {
                assert_eq!(binomial(n, 1), n as f64);
            }
            let sum: f64 = (0..=n).map(|k| binomial(n, k)).sum();
            assert_eq!(sum, 2f64.powi(n as i32), "row {n}");
        }
        // past the exact rows the product is rounded: a few ulps per factor
        for n in 50..60 {
            assert!((binomial(n, n) - 1.0).abs() <= 1e-13, "C({n}, {n}) = {}", binomial(n, n));
            assert!((binomial(n, 2) / (n * (n - 1) / 2) as f64 - 1.0).abs() <= 1e-15);
        }
        assert_eq!(binomial(49, 24), 63_205_303_218_876.0);
        let cube = [1.0, 3.0, 3.0, 1.0];
        assert_eq!(mul(&cube, &[1.0, -1.0, 0.0, 0.0]), vec![1.0, 2.0, 0.0, -2.0]);
        assert_eq!(mul(&cube, &[1.0, -1.0]), vec![1.0, 2.0]);
    }
}
