//! Truncated multivariate Taylor series ("jets") for exact derivatives.
//!
//! A [`Jet`] in up to three variables `x = (x₀, x₁, x₂)` stores the Taylor coefficients
//!
//! ```text
//! c[i,j,k] = ∂^{i+j+k} f / ∂x₀^i ∂x₁^j ∂x₂^k (a) / (i! j! k!),   i ≤ o₀, j ≤ o₁, k ≤ o₂
//! ```
//!
//! of a function at a point `a`. Sums are coefficientwise; products are truncated Cauchy
//! products; an analytic function `f` of a jet `x` with value `x₀` is the finite sum
//! `f(x) = Σ_{k≤K} f⁽ᵏ⁾(x₀)/k! · hᵏ`, `h = x − x₀`, exact because `h` is nilpotent of index
//! `K + 1` (`K = o₀ + o₁ + o₂`). Every derivative obtained this way is exact to round-off:
//! this is forward-mode automatic differentiation of arbitrary order, chosen over symbolic
//! differentiation because the size of a symbolic sixth derivative grows combinatorially
//! while a jet costs a fixed `O(len²)` per operation.
//!
//! ```
//! use pdeshape_core::jet::{Jet, JetShape};
//! // d⁶/dx⁶ sin(2x) at x = 0.3 is −64 sin(0.6).
//! let shape = JetShape::new(&[6]);
//! let x = Jet::variable(shape, 0, 0.3);
//! let f = x.scale(2.0).sin();
//! assert!((f.derivative([6, 0, 0]) + 64.0 * 0.6f64.sin()).abs() < 1e-12);
//! ```

/// Maximum number of independent variables of a [`Jet`].
pub const MAX_VARS: usize = 3;

/// The truncation orders of a jet: `orders[k]` is the highest derivative kept in variable `k`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct JetShape {
    orders: [usize; MAX_VARS],
}

impl JetShape {
    /// A shape keeping derivatives up to `orders[k]` in variable `k` (at most three variables;
    /// missing variables get order 0).
    pub fn new(orders: &[usize]) -> Self {
        assert!(orders.len() <= MAX_VARS, "a jet has at most {MAX_VARS} variables");
        let mut o = [0; MAX_VARS];
        o[..orders.len()].copy_from_slice(orders);
        JetShape { orders: o }
    }

    /// The shape of a plain value (no derivatives).
    pub const fn scalar() -> Self {
        JetShape { orders: [0; MAX_VARS] }
    }

    /// Per-variable truncation orders.
    pub fn orders(&self) -> [usize; MAX_VARS] {
        self.orders
    }

    /// Number of stored coefficients.
    pub fn len(&self) -> usize {
        self.orders.iter().map(|o| o + 1).product()
    }

    /// Always false: a jet stores at least its value.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// The highest total degree `o₀ + o₁ + o₂` of a stored monomial.
    pub fn total_order(&self) -> usize {
        self.orders.iter().sum()
    }

    /// Flat index of multi-index `[i, j, k]`.
    #[inline]
    pub fn index(&self, m: [usize; MAX_VARS]) -> usize {
        (m[0] * (self.orders[1] + 1) + m[1]) * (self.orders[2] + 1) + m[2]
    }

    /// True when `m` lies inside the shape.
    #[inline]
    pub fn contains(&self, m: [usize; MAX_VARS]) -> bool {
        m.iter().zip(self.orders.iter()).all(|(a, o)| a <= o)
    }

    /// All multi-indices of the shape in storage order.
    pub fn multi_indices(&self) -> impl Iterator<Item = [usize; MAX_VARS]> + '_ {
        let [a, b, c] = self.orders;
        (0..=a).flat_map(move |i| (0..=b).flat_map(move |j| (0..=c).map(move |k| [i, j, k])))
    }
}

/// A truncated Taylor series in up to three variables (see the module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct Jet {
    shape: JetShape,
    c: Coeffs,
}

/// Coefficient storage: inline up to 16 coefficients (every shape up to `[3, 3, 0]` or
/// `[4, 2, 0]`), so the jets of surface evaluation do not allocate.
type Coeffs = smallvec::SmallVec<[f64; 16]>;

fn factorial(n: usize) -> f64 {
    (1..=n).map(|k| k as f64).product()
}

impl Jet {
    /// A constant function with value `v`.
    pub fn constant(shape: JetShape, v: f64) -> Self {
        let mut c: Coeffs = smallvec::smallvec![0.0; shape.len()];
        c[0] = v;
        Jet { shape, c }
    }

    /// The independent variable `var` at the point `x0`.
    pub fn variable(shape: JetShape, var: usize, x0: f64) -> Self {
        let mut j = Jet::constant(shape, x0);
        if shape.orders[var] >= 1 {
            let mut m = [0; MAX_VARS];
            m[var] = 1;
            let idx = shape.index(m);
            j.c[idx] = 1.0;
        }
        j
    }

    /// A jet from raw Taylor coefficients in storage order.
    pub fn from_coeffs(shape: JetShape, c: Vec<f64>) -> Self {
        assert_eq!(c.len(), shape.len());
        Jet { shape, c: Coeffs::from_vec(c) }
    }

    /// A jet from raw Taylor coefficients in storage order, copied from a slice (inline up
    /// to 16 coefficients: no allocation).
    pub fn from_slice(shape: JetShape, c: &[f64]) -> Self {
        assert_eq!(c.len(), shape.len());
        Jet { shape, c: Coeffs::from_slice(c) }
    }

    /// `s c` for raw Taylor coefficients `c` in storage order: the jet
    /// `Jet::from_slice(shape, c).scale(s)` without the intermediate copy (the same
    /// products, the same bits).
    pub fn from_scaled_slice(shape: JetShape, c: &[f64], s: f64) -> Self {
        assert_eq!(c.len(), shape.len());
        // copied whole, then scaled in place (collecting from an iterator pushes one by one)
        let mut c = Coeffs::from_slice(c);
        for a in c.iter_mut() {
            *a *= s;
        }
        Jet { shape, c }
    }

    /// The shape of this jet.
    pub fn shape(&self) -> JetShape {
        self.shape
    }

    /// The function value.
    #[inline]
    pub fn value(&self) -> f64 {
        self.c[0]
    }

    /// The Taylor coefficients in storage order.
    pub fn coeffs(&self) -> &[f64] {
        &self.c
    }

    /// The Taylor coefficient of multi-index `m` (zero outside the shape).
    pub fn coeff(&self, m: [usize; MAX_VARS]) -> f64 {
        if self.shape.contains(m) { self.c[self.shape.index(m)] } else { 0.0 }
    }

    /// The partial derivative `∂^{i+j+k} f/∂x₀^i ∂x₁^j ∂x₂^k`, exact; zero outside the shape
    /// is *not* implied, so asking for one is a logic error and panics.
    pub fn derivative(&self, m: [usize; MAX_VARS]) -> f64 {
        assert!(self.shape.contains(m), "derivative {m:?} outside jet shape {:?}", self.shape);
        self.c[self.shape.index(m)] * m.iter().map(|&k| factorial(k)).product::<f64>()
    }

    /// True when every coefficient but the value is zero.
    pub fn is_constant(&self) -> bool {
        self.c[1..].iter().all(|&x| x == 0.0)
    }

    /// True when every coefficient is finite.
    pub fn is_finite(&self) -> bool {
        self.c.iter().all(|x| x.is_finite())
    }

    fn zip(&self, o: &Jet, f: impl Fn(f64, f64) -> f64) -> Jet {
        assert_eq!(self.shape, o.shape, "jets of different shapes");
        Jet { shape: self.shape, c: self.c.iter().zip(&o.c).map(|(a, b)| f(*a, *b)).collect() }
    }

    /// `a + b`.
    pub fn add(&self, o: &Jet) -> Jet {
        self.zip(o, |a, b| a + b)
    }

    /// `a − b`.
    pub fn sub(&self, o: &Jet) -> Jet {
        self.zip(o, |a, b| a - b)
    }

    /// `−a`.
    pub fn neg(&self) -> Jet {
        self.scale(-1.0)
    }

    /// `s·a` for a number `s`.
    pub fn scale(&self, s: f64) -> Jet {
        Jet { shape: self.shape, c: self.c.iter().map(|a| a * s).collect() }
    }

    /// `a + s` for a number `s`.
    pub fn add_scalar(&self, s: f64) -> Jet {
        let mut r = self.clone();
        r.c[0] += s;
        r
    }

    /// The truncated product `a·b`.
    pub fn mul(&self, o: &Jet) -> Jet {
        assert_eq!(self.shape, o.shape, "jets of different shapes");
        if self.is_constant() {
            return o.scale(self.c[0]);
        }
        if o.is_constant() {
            return self.scale(o.c[0]);
        }
        let [oa, ob, oc] = self.shape.orders;
        let mut out: Coeffs = smallvec::smallvec![0.0; self.c.len()];
        if oc == 0 {
            // two variables: the loops below with the inner pair over contiguous rows (the
            // same products summed in the same order)
            let s = ob + 1;
            for i1 in 0..=oa {
                for j1 in 0..=ob {
                    let x = self.c[i1 * s + j1];
                    if x == 0.0 {
                        continue;
                    }
                    for i2 in 0..=oa - i1 {
                        let dst = &mut out[(i1 + i2) * s + j1..(i1 + i2 + 1) * s];
                        for (a, b) in dst.iter_mut().zip(&o.c[i2 * s..i2 * s + s - j1]) {
                            *a += x * b;
                        }
                    }
                }
            }
            return Jet { shape: self.shape, c: out };
        }
        for i1 in 0..=oa {
            for j1 in 0..=ob {
                for k1 in 0..=oc {
                    let x = self.c[self.shape.index([i1, j1, k1])];
                    if x == 0.0 {
                        continue;
                    }
                    for i2 in 0..=oa - i1 {
                        for j2 in 0..=ob - j1 {
                            let base = self.shape.index([i1 + i2, j1 + j2, k1]);
                            let obase = self.shape.index([i2, j2, 0]);
                            for k2 in 0..=oc - k1 {
                                out[base + k2] += x * o.c[obase + k2];
                            }
                        }
                    }
                }
            }
        }
        Jet { shape: self.shape, c: out }
    }

    /// `f(a)` for an analytic `f` given by `taylor[k] = f⁽ᵏ⁾(a₀)/k!`, `k = 0 … K`
    /// (`K` = total order; extra entries are ignored, missing ones are zero).
    pub fn compose(&self, taylor: &[f64]) -> Jet {
        let k_max = self.shape.total_order().min(taylor.len().saturating_sub(1));
        let mut h = self.clone();
        h.c[0] = 0.0;
        let mut r = Jet::constant(self.shape, taylor[k_max]);
        for k in (0..k_max).rev() {
            r = r.mul(&h);
            r.c[0] += taylor[k];
        }
        r
    }

    fn k_max(&self) -> usize {
        self.shape.total_order()
    }

    /// `eᵃ`.
    pub fn exp(&self) -> Jet {
        let e = self.value().exp();
        let t: Vec<f64> = (0..=self.k_max()).map(|k| e / factorial(k)).collect();
        self.compose(&t)
    }

    /// `sin a`.
    pub fn sin(&self) -> Jet {
        let (s, c) = self.value().sin_cos();
        let cyc = [s, c, -s, -c];
        let t: Vec<f64> = (0..=self.k_max()).map(|k| cyc[k % 4] / factorial(k)).collect();
        self.compose(&t)
    }

    /// `cos a`.
    pub fn cos(&self) -> Jet {
        let (s, c) = self.value().sin_cos();
        let cyc = [c, -s, -c, s];
        let t: Vec<f64> = (0..=self.k_max()).map(|k| cyc[k % 4] / factorial(k)).collect();
        self.compose(&t)
    }

    /// `sinh a`.
    pub fn sinh(&self) -> Jet {
        let (s, c) = (self.value().sinh(), self.value().cosh());
        let t: Vec<f64> = (0..=self.k_max()).map(|k| if k % 2 == 0 { s } else { c } / factorial(k)).collect();
        self.compose(&t)
    }

    /// `cosh a`.
    pub fn cosh(&self) -> Jet {
        let (s, c) = (self.value().sinh(), self.value().cosh());
        let t: Vec<f64> = (0..=self.k_max()).map(|k| if k % 2 == 0 { c } else { s } / factorial(k)).collect();
        self.compose(&t)
    }

    /// `1/a`: Taylor coefficients `(−1)ᵏ / a₀^{k+1}`.
    pub fn recip(&self) -> Jet {
        let a = self.value();
        let t: Vec<f64> =
            (0..=self.k_max()).map(|k| if k % 2 == 0 { 1.0 } else { -1.0 } / a.powi(k as i32 + 1)).collect();
        self.compose(&t)
    }

    /// `a / b`.
    pub fn div(&self, o: &Jet) -> Jet {
        if o.is_constant() {
            return self.scale(1.0 / o.value());
        }
        self.mul(&o.recip())
    }

    /// `ln a`: Taylor coefficients `ln a₀`, then `(−1)^{k−1}/(k a₀ᵏ)`.
    pub fn ln(&self) -> Jet {
        let a = self.value();
        let t: Vec<f64> = (0..=self.k_max())
            .map(|k| {
                if k == 0 {
                    a.ln()
                } else {
                    let s = if k % 2 == 1 { 1.0 } else { -1.0 };
                    s / (k as f64 * a.powi(k as i32))
                }
            })
            .collect();
        self.compose(&t)
    }

    /// `aᵖ` for a real constant `p`: Taylor coefficients `C(p, k) a₀^{p−k}` (generalised
    /// binomial). Integer `p` is computed by repeated multiplication, so negative `a₀` works.
    pub fn powf(&self, p: f64) -> Jet {
        if p == p.round() && p.abs() <= 64.0 {
            return self.powi(p as i32);
        }
        let a = self.value();
        let mut binom = 1.0;
        let t: Vec<f64> = (0..=self.k_max())
            .map(|k| {
                if k > 0 {
                    binom *= (p - (k as f64 - 1.0)) / k as f64;
                }
                binom * a.powf(p - k as f64)
            })
            .collect();
        self.compose(&t)
    }

    /// `aⁿ` for an integer `n` (binary powering; `n < 0` through `1/a`).
    pub fn powi(&self, n: i32) -> Jet {
        if n < 0 {
            return self.recip().powi(-n);
        }
        let mut result = Jet::constant(self.shape, 1.0);
        let mut base = self.clone();
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

    /// `aᵇ` for jets: `powf` when `b` is constant, else `exp(b ln a)`.
    pub fn pow(&self, b: &Jet) -> Jet {
        if b.is_constant() { self.powf(b.value()) } else { b.mul(&self.ln()).exp() }
    }

    /// `√a`.
    pub fn sqrt(&self) -> Jet {
        self.powf(0.5)
    }

    /// `tan a = sin a / cos a`.
    pub fn tan(&self) -> Jet {
        self.sin().div(&self.cos())
    }

    /// `tanh a = sinh a / cosh a`.
    pub fn tanh(&self) -> Jet {
        self.sinh().div(&self.cosh())
    }

    /// `|a|`, differentiated on the side of the sign of `a₀`.
    pub fn abs(&self) -> Jet {
        if self.value() < 0.0 { self.neg() } else { self.clone() }
    }

    /// The argument of `(x, y)`: `atan2(y, x)`.
    ///
    /// With `θ₀ = atan2(y₀, x₀)`, `atan2(y, x) = θ₀ + atan(w)` where
    /// `w = (x₀y − y₀x)/(x₀x + y₀y)` has zero value, so the odd series
    /// `atan w = w − w³/3 + w⁵/5 − …` is exact after `K` terms.
    pub fn atan2(y: &Jet, x: &Jet) -> Jet {
        let (x0, y0) = (x.value(), y.value());
        let theta0 = y0.atan2(x0);
        if y.is_constant() && x.is_constant() {
            return Jet::constant(y.shape, theta0);
        }
        let num = y.scale(x0).sub(&x.scale(y0));
        let den = x.scale(x0).add(&y.scale(y0));
        let mut w = num.div(&den);
        w.c[0] = 0.0;
        let t: Vec<f64> = (0..=y.k_max())
            .map(|k| {
                if k % 2 == 0 {
                    0.0
                } else {
                    let s = if (k / 2) % 2 == 0 { 1.0 } else { -1.0 };
                    s / k as f64
                }
            })
            .collect();
        w.compose(&t).add_scalar(theta0)
    }

    /// `min(a, b)`, choosing the branch by value (ties: `a`).
    pub fn min(&self, o: &Jet) -> Jet {
        if o.value() < self.value() { o.clone() } else { self.clone() }
    }

    /// `max(a, b)`, choosing the branch by value (ties: `a`).
    pub fn max(&self, o: &Jet) -> Jet {
        if o.value() > self.value() { o.clone() } else { self.clone() }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol * (1.0 + b.abs())
    }

    #[test]
    fn univariate_derivatives_of_elementary_functions() {
        let s = JetShape::new(&[6]);
        let x0 = 0.7;
        let x = Jet::variable(s, 0, x0);
        // exp(2x): 2^k e^{2x}
        let f = x.scale(2.0).exp();
        for k in 0..=6 {
            assert!(close(f.derivative([k, 0, 0]), 2f64.powi(k as i32) * (2.0 * x0).exp(), 1e-13));
        }
        // ln x: (-1)^{k-1}(k-1)!/x^k
        let f = x.ln();
        for k in 1..=6 {
            let s = if k % 2 == 1 { 1.0 } else { -1.0 };
            assert!(close(f.derivative([k, 0, 0]), s * factorial(k - 1) / x0.powi(k as i32), 1e-12));
        }
        // tan' = 1 + tan², tan'' = 2 tan (1 + tan²)
        let f = x.tan();
        let t = x0.tan();
        assert!(close(f.derivative([1, 0, 0]), 1.0 + t * t, 1e-13));
        assert!(close(f.derivative([2, 0, 0]), 2.0 * t * (1.0 + t * t), 1e-13));
        // sqrt: d³ = 3/8 x^{-5/2}
        assert!(close(x.sqrt().derivative([3, 0, 0]), 0.375 * x0.powf(-2.5), 1e-13));
        // tanh' = 1 - tanh²
        let th = x0.tanh();
        assert!(close(x.tanh().derivative([1, 0, 0]), 1.0 - th * th, 1e-13));
    }

    #[test]
    fn mixed_partials_of_a_product() {
        // f = sin(x) * exp(y) * z^2 at (0.3, -0.2, 1.5); ∂x²∂y∂z² f = -sin(x) e^y * 2
        let s = JetShape::new(&[3, 2, 2]);
        let x = Jet::variable(s, 0, 0.3);
        let y = Jet::variable(s, 1, -0.2);
        let z = Jet::variable(s, 2, 1.5);
        let f = x.sin().mul(&y.exp()).mul(&z.powi(2));
        let expect = -(0.3f64.sin()) * (-0.2f64).exp() * 2.0;
        assert!(close(f.derivative([2, 1, 2]), expect, 1e-13));
        assert!(close(f.derivative([3, 2, 1]), -(0.3f64.cos()) * (-0.2f64).exp() * 3.0, 1e-13));
    }

    #[test]
    fn atan2_matches_the_angle_in_every_quadrant() {
        let s = JetShape::new(&[4]);
        for &th in &[0.3, 2.0, -2.5, -0.4, 3.1] {
            let v = Jet::variable(s, 0, th);
            let a = Jet::atan2(&v.sin().scale(2.0), &v.cos().scale(2.0));
            assert!(close(a.value(), th, 1e-14));
            assert!(close(a.derivative([1, 0, 0]), 1.0, 1e-13));
            for k in 2..=4 {
                assert!(a.derivative([k, 0, 0]).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn powers_and_division_agree() {
        let s = JetShape::new(&[5, 2]);
        let x = Jet::variable(s, 0, -1.3);
        let y = Jet::variable(s, 1, 0.8);
        let a = x.mul(&y).add_scalar(2.0);
        let lhs = a.powi(-3);
        let rhs = Jet::constant(s, 1.0).div(&a.mul(&a).mul(&a));
        for (p, q) in lhs.coeffs().iter().zip(rhs.coeffs()) {
            assert!(close(*p, *q, 1e-12));
        }
        // general power through exp/ln: (y)^(x) with x a jet
        let f = y.pow(&x);
        // ∂/∂x y^x = ln(y) y^x
        assert!(close(f.derivative([1, 0, 0]), 0.8f64.ln() * 0.8f64.powf(-1.3), 1e-13));
    }
}
