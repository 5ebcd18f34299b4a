//! Truncated Taylor series in one variable, of a length fixed at compile time.
//!
//! `Taylor<N>` holds `c[k] = f⁽ᵏ⁾(x₀)/k!` for `k = 0 … N−1`: the exact derivatives of a
//! function at one point up to order `N − 1`. It is the number type of compiled boundary
//! data ([`crate::expr::Tape`]) where only derivatives along one parameter are needed (the
//! θ-derivatives of a grid column, the normals of a mesh). Unlike [`crate::jet::Jet`] it is
//! `Copy`, never allocates, and every operation is a short loop the compiler unrolls.
//!
//! Elementary functions use the classical recurrences obtained by matching coefficients
//! in a first-order ODE the function satisfies (Griewank & Walther, "Evaluating
//! Derivatives", §13.2). With `a` the argument and `k ≥ 1`:
//!
//! | function | ODE | recurrence |
//! |---|---|---|
//! | `q = a/b` | `b q = a` | `q_k = (a_k − Σ_{j<k} q_j b_{k−j}) / b₀` |
//! | `e = exp a` | `e' = a' e` | `k e_k = Σ_{j=1}^{k} j a_j e_{k−j}` |
//! | `s, c = sin a, cos a` | `s' = a' c`, `c' = −a' s` | `k s_k = Σ j a_j c_{k−j}`, `k c_k = −Σ j a_j s_{k−j}` |
//! | `sinh`, `cosh` | `s' = a' c`, `c' = a' s` | as above with `+` |
//! | `l = ln a` | `a l' = a'` | `a₀ k l_k = k a_k − Σ_{j=1}^{k−1} j l_j a_{k−j}` |
//! | `y = aᵖ` | `a y' = p a' y` | `k a₀ y_k = Σ_{j=1}^{k} (p j − (k − j)) a_j y_{k−j}` |
//! | `r = √a` | `r² = a` | `2 r₀ r_k = a_k − Σ_{j=1}^{k−1} r_j r_{k−j}` |
//! | `atan2(y, x)` | `θ' = (x y' − y x') / (x² + y²)` | the quotient's series, integrated |
//!
//! Each is proved against closed forms in the tests below.

// The recurrences are written with the indices of the formulas above.
#![allow(clippy::needless_range_loop)]

use std::array;

/// A truncated Taylor series `Σ_{k<N} c_k (x − x₀)^k` (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Taylor<const N: usize>(pub [f64; N]);

impl<const N: usize> Taylor<N> {
    /// The constant `x`.
    pub fn constant(x: f64) -> Self {
        let mut c = [0.0; N];
        c[0] = x;
        Taylor(c)
    }

    /// The independent variable at `x0`.
    pub fn variable(x0: f64) -> Self {
        let mut c = [0.0; N];
        c[0] = x0;
        if N > 1 {
            c[1] = 1.0;
        }
        Taylor(c)
    }

    /// The value `c₀`.
    pub fn value(&self) -> f64 {
        self.0[0]
    }

    /// The `k`-th derivative `k! c_k`.
    pub fn derivative(&self, k: usize) -> f64 {
        let mut f = 1.0;
        for i in 2..=k {
            f *= i as f64;
        }
        self.0[k] * f
    }

    /// `a + b`.
    pub fn add(&self, b: &Self) -> Self {
        Taylor(array::from_fn(|k| self.0[k] + b.0[k]))
    }

    /// `a − b`.
    pub fn sub(&self, b: &Self) -> Self {
        Taylor(array::from_fn(|k| self.0[k] - b.0[k]))
    }

    /// `−a`.
    pub fn neg(&self) -> Self {
        Taylor(array::from_fn(|k| -self.0[k]))
    }

    /// `s · a` for a number `s`.
    pub fn scale(&self, s: f64) -> Self {
        Taylor(array::from_fn(|k| self.0[k] * s))
    }

    /// `a / s` for a number `s` (each coefficient divided, so the value is `a₀ / s` exactly
    /// as in `f64`).
    pub fn div_scalar(&self, s: f64) -> Self {
        Taylor(array::from_fn(|k| self.0[k] / s))
    }

    /// `a · b` (the Cauchy product).
    pub fn mul(&self, b: &Self) -> Self {
        Taylor(array::from_fn(|k| {
            let mut s = self.0[0] * b.0[k];
            for j in 1..=k {
                s += self.0[j] * b.0[k - j];
            }
            s
        }))
    }

    /// `a / b`.
    pub fn div(&self, b: &Self) -> Self {
        let mut q = [0.0; N];
        for k in 0..N {
            let mut s = self.0[k];
            for j in 0..k {
                s -= q[j] * b.0[k - j];
            }
            q[k] = s / b.0[0];
        }
        Taylor(q)
    }

    /// `exp a`.
    pub fn exp(&self) -> Self {
        let mut e = [0.0; N];
        e[0] = self.0[0].exp();
        for k in 1..N {
            let mut s = 0.0;
            for j in 1..=k {
                s += j as f64 * self.0[j] * e[k - j];
            }
            e[k] = s / k as f64;
        }
        Taylor(e)
    }

    /// `(sin a, cos a)`.
    pub fn sin_cos(&self) -> (Self, Self) {
        let (mut s, mut c) = ([0.0; N], [0.0; N]);
        (s[0], c[0]) = self.0[0].sin_cos();
        for k in 1..N {
            let (mut ss, mut cc) = (0.0, 0.0);
            for j in 1..=k {
                let ja = j as f64 * self.0[j];
                ss += ja * c[k - j];
                cc -= ja * s[k - j];
            }
            s[k] = ss / k as f64;
            c[k] = cc / k as f64;
        }
        (Taylor(s), Taylor(c))
    }

    /// `(sinh a, cosh a)`.
    pub fn sinh_cosh(&self) -> (Self, Self) {
        let (mut s, mut c) = ([0.0; N], [0.0; N]);
        (s[0], c[0]) = (self.0[0].sinh(), self.0[0].cosh());
        for k in 1..N {
            let (mut ss, mut cc) = (0.0, 0.0);
            for j in 1..=k {
                let ja = j as f64 * self.0[j];
                ss += ja * c[k - j];
                cc += ja * s[k - j];
            }
            s[k] = ss / k as f64;
            c[k] = cc / k as f64;
        }
        (Taylor(s), Taylor(c))
    }

    /// `ln a`.
    pub fn ln(&self) -> Self {
        let a0 = self.0[0];
        let mut l = [0.0; N];
        l[0] = a0.ln();
        for k in 1..N {
            let mut s = k as f64 * self.0[k];
            for j in 1..k {
                s -= j as f64 * l[j] * self.0[k - j];
            }
            l[k] = s / (k as f64 * a0);
        }
        Taylor(l)
    }

    /// `√a`.
    pub fn sqrt(&self) -> Self {
        let mut r = [0.0; N];
        r[0] = self.0[0].sqrt();
        for k in 1..N {
            let mut s = self.0[k];
            for j in 1..k {
                s -= r[j] * r[k - j];
            }
            r[k] = s / (2.0 * r[0]);
        }
        Taylor(r)
    }

    /// `aⁿ` for an integer `n` by binary powering (`n < 0` through `1/a`), so a negative
    /// or zero `a₀` is fine.
    pub fn powi(&self, n: i32) -> Self {
        if n < 0 {
            return Taylor::constant(1.0).div(self).powi(-n);
        }
        let mut result = Taylor::constant(1.0);
        let mut base = *self;
        let mut e = n as u32;
        while e > 0 {
            if e & 1 == 1 {
                result = result.mul(&base);
            }
            e >>= 1;
            if e > 0 {
                base = base.mul(&base);
            }
        }
        result
    }

    /// `aᵖ` for a real constant `p` (integer `p` with `|p| ≤ 64` through [`powi`](Self::powi),
    /// as in `f64` evaluation).
    pub fn powf(&self, p: f64) -> Self {
        if p == p.round() && p.abs() <= 64.0 {
            return self.powi(p as i32);
        }
        let a0 = self.0[0];
        let mut y = [0.0; N];
        y[0] = a0.powf(p);
        for k in 1..N {
            let mut s = 0.0;
            for j in 1..=k {
                s += (p * j as f64 - (k - j) as f64) * self.0[j] * y[k - j];
            }
            y[k] = s / (k as f64 * a0);
        }
        Taylor(y)
    }

    /// `aᵇ`: [`powf`](Self::powf) when `b` is constant, else `exp(b ln a)`.
    pub fn pow(&self, b: &Self) -> Self {
        if b.0[1..].iter().all(|&c| c == 0.0) { self.powf(b.0[0]) } else { b.mul(&self.ln()).exp() }
    }

    /// The series of `a'` (the last coefficient, which needs `c_N`, is zero).
    fn derivative_series(&self) -> Self {
        Taylor(array::from_fn(|k| if k + 1 < N { (k + 1) as f64 * self.0[k + 1] } else { 0.0 }))
    }

    /// The antiderivative with value `c0` of a series whose coefficients `0 … N−2` are
    /// those of the derivative.
    fn integrate(d: &Self, c0: f64) -> Self {
        Taylor(array::from_fn(|k| if k == 0 { c0 } else { d.0[k - 1] / k as f64 }))
    }

    /// `atan2(y, x)`, the angle of `(x, y)`.
    pub fn atan2(y: &Self, x: &Self) -> Self {
        let num = x.mul(&y.derivative_series()).sub(&y.mul(&x.derivative_series()));
        let den = x.mul(x).add(&y.mul(y));
        Taylor::integrate(&num.div(&den), y.0[0].atan2(x.0[0]))
    }

    /// `|a|`, differentiated on the side of the sign of `a₀`.
    pub fn abs(&self) -> Self {
        if self.0[0] < 0.0 { self.neg() } else { *self }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Derivatives of `f` at `x` against closed forms `d[k]`, relative to their size.
    fn close<const N: usize>(t: Taylor<N>, d: &[f64], tol: f64) {
        for (k, want) in d.iter().enumerate() {
            let got = t.derivative(k);
            assert!((got - want).abs() <= tol * want.abs().max(1.0), "order {k}: {got} vs {want}");
        }
    }

    // Tolerances: a handful of rounded operations per coefficient, each ≤ 2⁻⁵³ relative, on
    // values of order one; 1e-14 leaves a factor of ~50.
    const TOL: f64 = 1e-14;

    #[test]
    fn elementary_functions_match_closed_form_derivatives() {
        let x0 = 0.7;
        let x = Taylor::<5>::variable(x0);
        // exp(2x): 2ᵏ e^{2x}
        let e = (2.0 * x0).exp();
        close(x.scale(2.0).exp(), &[e, 2.0 * e, 4.0 * e, 8.0 * e, 16.0 * e], TOL);
        // sin(3x), cos(3x)
        let (s, c) = (3.0 * x0).sin_cos();
        let (ts, tc) = x.scale(3.0).sin_cos();
        close(ts, &[s, 3.0 * c, -9.0 * s, -27.0 * c, 81.0 * s], TOL);
        close(tc, &[c, -3.0 * s, -9.0 * c, 27.0 * s, 81.0 * c], TOL);
        // sinh, cosh
        let (sh, ch) = x.sinh_cosh();
        let (s, c) = (x0.sinh(), x0.cosh());
        close(sh, &[s, c, s, c, s], TOL);
        close(ch, &[c, s, c, s, c], TOL);
        // ln x: (-1)^{k-1} (k-1)! / x^k
        close(x.ln(), &[x0.ln(), 1.0 / x0, -1.0 / x0.powi(2), 2.0 / x0.powi(3), -6.0 / x0.powi(4)], TOL);
        // √x
        let r = x0.sqrt();
        close(x.sqrt(), &[r, 0.5 / r, -0.25 / (r * x0), 0.375 / (r * x0 * x0), -0.9375 / (r * x0.powi(3))], TOL);
        // x^2.5
        let p = 2.5;
        let d: Vec<f64> =
            (0..5).map(|k| (0..k).map(|i| p - i as f64).product::<f64>() * x0.powf(p - k as f64)).collect();
        close(x.powf(p), &d, TOL);
        // x^-3 by powi
        let d: Vec<f64> = (0..5).map(|k| (0..k).map(|i| -3.0 - i as f64).product::<f64>() * x0.powi(-3 - k)).collect();
        close(x.powf(-3.0), &d, TOL);
        // 1/(1+x) by division
        let q = Taylor::constant(1.0).div(&x.add(&Taylor::constant(1.0)));
        let d: Vec<f64> =
            (0..5).map(|k| (1..=k).map(|i| -(i as f64)).product::<f64>() / (1.0 + x0).powi(k + 1)).collect();
        close(q, &d, TOL);
    }

    #[test]
    fn atan2_matches_the_derivatives_of_atan() {
        // atan2(x, 1) = atan x: derivatives 1/(1+x²), −2x/(1+x²)², (6x² − 2)/(1+x²)³
        let x0 = 0.4;
        let x = Taylor::<4>::variable(x0);
        let w = 1.0 + x0 * x0;
        let t = Taylor::atan2(&x, &Taylor::constant(1.0));
        close(t, &[x0.atan(), 1.0 / w, -2.0 * x0 / (w * w), (6.0 * x0 * x0 - 2.0) / w.powi(3)], TOL);
        // the angle of the unit circle point (cos x, sin x) is x in every quadrant
        for x0 in [0.3, 2.0, -2.5] {
            let x = Taylor::<4>::variable(x0);
            let (s, c) = x.sin_cos();
            close(Taylor::atan2(&s, &c), &[x0, 1.0, 0.0, 0.0], TOL);
        }
    }

    #[test]
    fn pow_with_variable_exponent_is_exp_of_b_ln_a() {
        // x^x: derivative x^x (ln x + 1), second x^x ((ln x + 1)² + 1/x)
        let x0 = 1.3;
        let x = Taylor::<3>::variable(x0);
        let y = x0.powf(x0);
        let l = x0.ln() + 1.0;
        close(x.pow(&x), &[y, y * l, y * (l * l + 1.0 / x0)], TOL);
    }

    #[test]
    fn non_finite_values_propagate() {
        let x = Taylor::<3>::variable(-1.0);
        // ln of a negative number: the value is NaN (its derivatives, those of ln|x|, are
        // finite, as in the jet arithmetic); every coefficient of √ depends on √a₀.
        assert!(x.ln().value().is_nan());
        assert!(x.sqrt().0.iter().all(|c| c.is_nan()));
        let z = Taylor::<3>::variable(0.0);
        assert!(Taylor::constant(1.0).div(&z).0.iter().all(|c| !c.is_finite()));
    }
}
