//! Closed forms of boundary-value problems `Σ c_k G^{(k)} = 0` on [0, 1] with Hermite
//! conditions, written out by hand for the tests (independent of the project's ODE core):
//! the caller gives a real basis of the kernel (from the characteristic roots it derived)
//! as functions returning their derivatives, and `fit` solves the small square system by
//! Gaussian elimination with partial pivoting.
#![allow(dead_code)]

/// A kernel function: `f(u)` → `[f, f′, f″, …]` (at least as many entries as conditions).
pub type Basis = Box<dyn Fn(f64) -> Vec<f64>>;

/// `e^{a u}` with derivatives up to order 5.
pub fn exp(a: f64) -> Basis {
    Box::new(move |u| (0..6).map(|k| a.powi(k) * (a * u).exp()).collect())
}

/// `e^{a u} cos(b u)` (`sin = false`) or `e^{a u} sin(b u)` with derivatives up to 5: the
/// real and imaginary parts of `e^{(a + ib) u}`, whose k-th derivative is
/// `(a + ib)^k e^{(a + ib) u}`.
pub fn exp_trig(a: f64, b: f64, sin: bool) -> Basis {
    Box::new(move |u| {
        let (mut pr, mut pi) = (1.0, 0.0); // (a + ib)^k
        let (er, ei) = ((a * u).exp() * (b * u).cos(), (a * u).exp() * (b * u).sin());
        (0..6)
            .map(|_| {
                let (vr, vi) = (pr * er - pi * ei, pr * ei + pi * er);
                let next = (pr * a - pi * b, pr * b + pi * a);
                pr = next.0;
                pi = next.1;
                if sin { vi } else { vr }
            })
            .collect()
    })
}

/// `u^n` with derivatives up to order 5.
pub fn power(n: i32) -> Basis {
    Box::new(move |u| {
        (0..6)
            .map(|k| {
                if k > n {
                    return 0.0;
                }
                let c: f64 = (0..k).map(|j| (n - j) as f64).product();
                c * u.powi(n - k)
            })
            .collect()
    })
}

/// The combination of `basis` meeting `G^{(d)}(0) = at0[d]` and `G^{(d)}(1) = at1[d]` for
/// `d < at0.len()`; returns the coefficients.
pub fn fit(basis: &[Basis], at0: &[f64], at1: &[f64]) -> Vec<f64> {
    let r = at0.len();
    assert_eq!(basis.len(), 2 * r);
    let n = 2 * r;
    let (b0, b1): (Vec<Vec<f64>>, Vec<Vec<f64>>) =
        (basis.iter().map(|f| f(0.0)).collect(), basis.iter().map(|f| f(1.0)).collect());
    let mut a: Vec<Vec<f64>> = (0..n)
        .map(|row| {
            let (vals, d, rhs) = if row < r { (&b0, row, at0[row]) } else { (&b1, row - r, at1[row - r]) };
            let mut line: Vec<f64> = vals.iter().map(|v| v[d]).collect();
            line.push(rhs);
            line
        })
        .collect();
    for c in 0..n {
        let p = (c..n).max_by(|&i, &j| a[i][c].abs().total_cmp(&a[j][c].abs())).unwrap();
        a.swap(c, p);
        assert!(a[c][c].abs() > 1e-12, "singular Hermite system");
        let pivot = a[c].clone();
        for (i, row) in a.iter_mut().enumerate() {
            if i != c {
                let f = row[c] / pivot[c];
                for (x, p) in row.iter_mut().zip(&pivot).skip(c) {
                    *x -= f * p;
                }
            }
        }
    }
    (0..n).map(|i| a[i][n] / a[i][i]).collect()
}

/// `Σ coef_i basis_i^{(d)}(u)`.
pub fn eval(basis: &[Basis], coef: &[f64], u: f64, d: usize) -> f64 {
    basis.iter().zip(coef).map(|(f, c)| c * f(u)[d]).sum()
}
