//! Boundary data (SPEC §2): vector-valued functions of one to three parameters.
//!
//! Everything a condition can prescribe — a curve `g(v)`, a moving curve `g(v, t)`, a
//! boundary surface `S(u, v)` of a solid, a primary surface `S(s, v, t)` — is a [`Field`]:
//! a map from parameters to R³ whose partial derivatives of every order are available
//! exactly as [`VecJet`]s. Conventions for the parameter slots:
//!
//! | use                          | slots        |
//! |------------------------------|--------------|
//! | boundary curve               | `(v, t)`     |
//! | primary surface              | `(s, v, t)`  |
//! | solid boundary surface       | `(u, v)`     |
//!
//! A field ignores slots it does not depend on (a B-spline curve is constant in `t`).

pub mod analytic;
mod bspline;
pub(crate) use bspline::basis_derivatives;
mod combine;
mod expr_field;
mod extension;
pub mod fourier;
mod memo_field;
mod nurbs;
mod trimline;

pub use bspline::{BSplineCurve, BSplineError};
pub use combine::Combination;
pub use expr_field::ExprField;
pub use extension::EvenExtension;
pub use memo_field::MemoField;
pub use nurbs::{NurbsCurve, NurbsError, NurbsSurface};
pub use trimline::Trimline;

use crate::Vec3;
use crate::jet::{Jet, JetShape, MAX_VARS};
use std::fmt::Debug;
use std::sync::Arc;

/// The jets of the three components of a vector function.
#[derive(Clone, Debug, PartialEq)]
pub struct VecJet(pub [Jet; 3]);

impl VecJet {
    /// The constant jet with value `p`.
    pub fn constant(shape: JetShape, p: Vec3) -> Self {
        VecJet([Jet::constant(shape, p.x), Jet::constant(shape, p.y), Jet::constant(shape, p.z)])
    }

    /// A jet from Taylor coefficients given as vectors in storage order.
    pub fn from_vec_coeffs(shape: JetShape, c: &[Vec3]) -> Self {
        VecJet(std::array::from_fn(|k| Jet::from_coeffs(shape, c.iter().map(|p| p[k]).collect())))
    }

    /// The shape.
    pub fn shape(&self) -> JetShape {
        self.0[0].shape()
    }

    /// The value.
    pub fn value(&self) -> Vec3 {
        Vec3::new(self.0[0].value(), self.0[1].value(), self.0[2].value())
    }

    /// The partial derivative of multi-index `m` (exact).
    pub fn derivative(&self, m: [usize; MAX_VARS]) -> Vec3 {
        Vec3::new(self.0[0].derivative(m), self.0[1].derivative(m), self.0[2].derivative(m))
    }

    /// True when every coefficient is finite.
    pub fn is_finite(&self) -> bool {
        self.0.iter().all(|j| j.is_finite())
    }
}

/// A vector-valued function of up to three parameters with exact partial derivatives.
pub trait Field: Send + Sync + Debug {
    /// Number of parameter slots the field reads (see the module docs).
    fn arity(&self) -> usize;

    /// The jet of the field at `at`, truncated to `shape`. `at` holds at least `arity()`
    /// slots; extra slots are ignored.
    fn jet(&self, at: &[f64], shape: JetShape) -> VecJet;

    /// The value at `at`: through [`derivatives_in`](Self::derivatives_in) (order 0), so a
    /// field with a fast one-slot path evaluates through it (the default there is the jet).
    fn eval(&self, at: &[f64]) -> Vec3 {
        let mut out = [Vec3::ZERO];
        self.derivatives_in(at, 0, &mut out);
        out[0]
    }

    /// `∂ᵏF/∂(slot)ᵏ` at `at` for `k = 0 … out.len() − 1`, exactly (the other slots held
    /// fixed). Expression fields answer from their compiled tape in fixed-length Taylor
    /// series; the default goes through [`jet`](Self::jet).
    fn derivatives_in(&self, at: &[f64], slot: usize, out: &mut [Vec3]) {
        derivatives_by_jet(self, at, slot, out)
    }

    /// [`derivatives_in`](Self::derivatives_in) at many points: point `p` is
    /// `at[p·stride ..][..stride]` and its `k` derivatives go to `out[p·k ..][..k]`. The
    /// same numbers as one call per point; fields override it to share work between the
    /// points (expression fields keep one tape workspace for the batch).
    fn derivatives_in_many(&self, at: &[f64], stride: usize, slot: usize, k: usize, out: &mut [Vec3]) {
        derivatives_point_by_point(self, at, stride, slot, k, out)
    }

    /// True when the field does not depend on slot `slot` (e.g. time for a B-spline).
    fn is_constant_in(&self, _slot: usize) -> bool {
        false
    }

    /// For a curve that lies on another surface (a trim curve carried onto its patch): that
    /// surface's normal (not normalised) at the curve's point `at`, so a patch attached
    /// along the curve can be compared with it (seam continuity). `None` for other data.
    fn host_normal(&self, _at: &[f64]) -> Option<Vec3> {
        None
    }

    /// The component expressions with their variable names, for fields defined by
    /// expressions (used to expand boundary data into basis functions, SPEC §5).
    fn expressions(&self) -> Option<(&[crate::expr::Expr; 3], &[String])> {
        None
    }

    /// `Some(d)` when the field is proved, from how it is built, a trigonometric polynomial
    /// of degree at most `d` in slot 0 that does not depend on its other slots; `None` when
    /// nothing is known. Expression fields are analysed ([`crate::expr::trig_degree`]);
    /// other fields say so themselves (a fill's ring `c + ρ (e₁ cos v + e₂ sin v)` has
    /// degree 1; a trimline keeps its expression surface's degree in `v`; a point has
    /// degree 0 and a combination its terms' largest). A spectral patch with `M ≥ d` takes
    /// such a datum's Fourier tails as zero.
    fn trig_degree(&self) -> Option<usize> {
        let (comps, vars) = self.expressions()?;
        components_trig_degree(comps, 0, 1..vars.len())
    }
}

/// The largest degree in variable `var` of three component expressions, each proved a
/// trigonometric polynomial in it ([`crate::expr::trig_degree`]) and free of the
/// variables `free_of`; `None` if one is not.
pub(crate) fn components_trig_degree(
    comps: &[crate::expr::Expr; 3],
    var: usize,
    free_of: std::ops::Range<usize>,
) -> Option<usize> {
    comps.iter().try_fold(0, |acc, e| {
        let free = free_of.clone().all(|i| !e.depends_on(i));
        free.then(|| crate::expr::trig_degree(e, var)).flatten().map(|d| acc.max(d))
    })
}

/// [`Field::derivatives_in_many`] as one [`Field::derivatives_in`] call a point: the
/// default, and what overrides fall back to for the counts they do not batch.
pub fn derivatives_point_by_point<F: Field + ?Sized>(
    f: &F,
    at: &[f64],
    stride: usize,
    slot: usize,
    k: usize,
    out: &mut [Vec3],
) {
    if k == 0 {
        return;
    }
    for (p, o) in at.chunks_exact(stride).zip(out.chunks_exact_mut(k)) {
        f.derivatives_in(p, slot, o);
    }
}

/// [`Field::derivatives_in`] through a jet of order `out.len() − 1` in `slot`.
pub fn derivatives_by_jet<F: Field + ?Sized>(f: &F, at: &[f64], slot: usize, out: &mut [Vec3]) {
    let Some(order) = out.len().checked_sub(1) else { return };
    let mut orders = [0; MAX_VARS];
    orders[slot] = order;
    let j = f.jet(at, JetShape::new(&orders));
    for (k, d) in out.iter_mut().enumerate() {
        let mut m = [0; MAX_VARS];
        m[slot] = k;
        *d = j.derivative(m);
    }
}

/// A shared, type-erased field.
pub type FieldRef = Arc<dyn Field>;

/// A constant point (a degenerate curve: a pole of the patch).
#[derive(Clone, Debug, PartialEq)]
pub struct PointField {
    /// The point.
    pub point: Vec3,
    /// Number of parameter slots reported by [`Field::arity`].
    pub arity: usize,
}

impl Field for PointField {
    fn arity(&self) -> usize {
        self.arity
    }
    fn jet(&self, _at: &[f64], shape: JetShape) -> VecJet {
        VecJet::constant(shape, self.point)
    }
    fn is_constant_in(&self, _slot: usize) -> bool {
        true
    }

    /// A finite point is a trigonometric polynomial of degree 0.
    fn trig_degree(&self) -> Option<usize> {
        self.point.is_finite().then_some(0)
    }
}

/// A closure field, convenient in tests and for programmatic data: `f(at, shape)`.
pub struct FnField<F> {
    f: F,
    arity: usize,
}

impl<F> FnField<F>
where
    F: Fn(&[Jet]) -> [Jet; 3] + Send + Sync,
{
    /// A field from a function of jets (its derivatives are then exact by construction).
    ///
    /// ```
    /// use pdeshape_core::data::{Field, FnField};
    /// use pdeshape_core::jet::JetShape;
    /// let circle = FnField::new(2, |p| [p[0].cos(), p[0].sin(), p[1].clone()]);
    /// let j = circle.jet(&[0.0, 0.5], JetShape::new(&[2, 0]));
    /// assert_eq!(j.derivative([2, 0, 0]).x, -1.0);
    /// ```
    pub fn new(arity: usize, f: F) -> Self {
        FnField { f, arity }
    }
}

impl<F> Debug for FnField<F> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "FnField(arity {})", self.arity)
    }
}

impl<F> Field for FnField<F>
where
    F: Fn(&[Jet]) -> [Jet; 3] + Send + Sync,
{
    fn arity(&self) -> usize {
        self.arity
    }
    fn jet(&self, at: &[f64], shape: JetShape) -> VecJet {
        let vars: Vec<Jet> = at.iter().enumerate().map(|(i, &x)| Jet::variable(shape, i, x)).collect();
        VecJet((self.f)(&vars))
    }
}

/// Convenience: the `k`-th derivative in slot 0 of a curve at `(v, t)`.
pub fn curve_derivative(f: &dyn Field, v: f64, t: f64, k: usize) -> Vec3 {
    let at = [v, t];
    f.jet(&at, JetShape::new(&[k])).derivative([k, 0, 0])
}

#[cfg(test)]
pub(crate) mod tests {
    use super::fourier::{FourierSeries, sample_count};
    use super::*;
    use proptest::prelude::*;
    use std::sync::atomic::{AtomicUsize, Ordering};

    /// An expression field that counts its evaluations (jets and `derivatives_in` calls).
    #[derive(Debug)]
    pub(crate) struct Counted(pub(crate) ExprField, pub(crate) AtomicUsize);

    impl Counted {
        pub(crate) fn new(e: ExprField) -> Self {
            Counted(e, AtomicUsize::new(0))
        }

        /// Evaluations so far.
        pub(crate) fn count(&self) -> usize {
            self.1.load(Ordering::Relaxed)
        }
    }

    impl Field for Counted {
        fn arity(&self) -> usize {
            self.0.arity()
        }
        fn jet(&self, at: &[f64], shape: JetShape) -> VecJet {
            self.1.fetch_add(1, Ordering::Relaxed);
            self.0.jet(at, shape)
        }
        fn derivatives_in(&self, at: &[f64], slot: usize, out: &mut [Vec3]) {
            self.1.fetch_add(1, Ordering::Relaxed);
            self.0.derivatives_in(at, slot, out)
        }
    }

    /// Checks a claimed [`Field::trig_degree`] `d` independently: the DFT of `f` at
    /// `8 (d + 1)` points of slot 0 (enough that nothing aliases) has no coefficient above
    /// `d` beyond round-off.
    pub(crate) fn assert_no_modes_above(f: &dyn Field, d: usize, what: &str) {
        let n = 8 * (d + 1);
        let g: Vec<Vec3> = (0..n).map(|k| f.eval(&[std::f64::consts::TAU * k as f64 / n as f64, 0.0])).collect();
        let size = g.iter().fold(0.0, |a: f64, x| crate::num::max_nan(a, x.norm()));
        for m in d + 1..=n / 2 {
            let (mut c, mut sn) = (Vec3::ZERO, Vec3::ZERO);
            for (k, x) in g.iter().enumerate() {
                let th = std::f64::consts::TAU * (m * k) as f64 / n as f64;
                c += *x * th.cos();
                sn += *x * th.sin();
            }
            // sums of n terms of the size of the data: round-off of n ulps
            let tail = crate::num::max_nan(c.norm(), sn.norm()) / n as f64;
            let bound = 4.0 * n as f64 * f64::EPSILON * crate::num::max_nan(size, 1.0);
            assert!(tail <= bound, "{what}, mode {m}: {tail:e}");
        }
    }

    /// A point has degree 0, a combination of proved terms its largest term's degree; a
    /// term not proved, a non-finite weight, constant or point give `None`.
    #[test]
    fn points_and_combinations_prove_their_degree() {
        let vars = ["v", "t"];
        let curve = |e: [&str; 3]| -> FieldRef { Arc::new(ExprField::parse(e, &vars, &|_| None).unwrap()) };
        let point = |p: Vec3| -> FieldRef { Arc::new(PointField { point: p, arity: 2 }) };
        let circle = curve(["2*cos(v)", "2*sin(v)", "0.5"]);
        let wave = curve(["0", "0", "cos(2*v + 0.3)"]);
        let p = point(Vec3::new(0.0, 0.0, 1.5));
        assert_eq!(p.trig_degree(), Some(0));
        assert_eq!(point(Vec3::new(f64::NAN, 0.0, 0.0)).trig_degree(), None);
        let c = Combination::new(
            vec![(0.7, circle.clone()), (-1.2, wave.clone()), (3.0, p.clone())],
            Vec3::new(1.0, 0.0, 0.0),
        );
        assert_eq!(c.trig_degree(), Some(2));
        assert_no_modes_above(&c, 2, "combination");
        let c1 = Combination::new(vec![(0.7, circle.clone()), (1.0, p.clone())], Vec3::ZERO);
        assert_eq!(c1.trig_degree(), Some(1));
        assert_no_modes_above(&c1, 1, "combination of degree 1");
        for bad in [
            Combination::new(vec![(0.7, circle.clone()), (1.0, curve(["v", "0", "0"]))], Vec3::ZERO),
            Combination::new(vec![(0.7, circle.clone()), (1.0, curve(["t*cos(v)", "0", "0"]))], Vec3::ZERO),
            Combination::new(vec![(f64::INFINITY, circle.clone())], Vec3::ZERO),
            Combination::new(vec![(1.0, circle.clone())], Vec3::new(0.0, f64::NAN, 0.0)),
        ] {
            assert_eq!(bad.trig_degree(), None);
        }
    }

    proptest! {
        /// A finite Fourier series is recovered exactly (to round-off) by the FFT analysis.
        #[test]
        fn fft_recovers_finite_series(coefs in proptest::collection::vec(-2.0f64..2.0, 18)) {
            let m = 4;
            let f = |t: f64| {
                let mut p = Vec3::new(coefs[0], coefs[1], 0.0);
                for n in 1..=m {
                    let (s, c) = (n as f64 * t).sin_cos();
                    p.x += coefs[2 * n] * c + coefs[2 * n + 1] * s;
                    p.z += coefs[8 + n] * c;
                }
                p
            };
            let s = FourierSeries::analyse(f, m, sample_count(m));
            for k in 0..20 {
                let t = 0.31 * k as f64;
                prop_assert!((s.eval(t) - f(t)).norm() < 1e-12);
                // all derivatives from one sin_cos per mode = each derivative on its own
                let cs: Vec<(f64, f64)> = (0..=m).map(|n| (n as f64 * t).sin_cos()).map(|(s, c)| (c, s)).collect();
                for (j, d) in s.derivatives_from(&cs, 5).into_iter().enumerate() {
                    let want = s.eval_derivative(t, j);
                    // round-off is relative to the terms' size Σ nʲ |coefficients|, not to
                    // the sum, which can cancel (seed kept: order 5 near a zero of f⁽⁵⁾)
                    let terms: f64 = (1..=m)
                        .map(|n| (n as f64).powi(j as i32) * (coefs[2 * n].abs() + coefs[2 * n + 1].abs() + coefs[8 + n].abs()))
                        .sum::<f64>()
                        + if j == 0 { coefs[0].abs() + coefs[1].abs() } else { 0.0 };
                    prop_assert!((d - want).norm() <= 1e-13 * terms.max(1.0), "order {}", j);
                }
            }
        }
    }

    #[test]
    fn even_extension_is_continuous_periodic_and_cosine_only() {
        let g: FieldRef = Arc::new(FnField::new(1, |p| [p[0].clone(), p[0].mul(&p[0]), p[0].exp()]));
        let e = EvenExtension::new(g.clone(), 0.5, 2.0);
        let pi = std::f64::consts::PI;
        assert!((e.eval(&[0.0]) - g.eval(&[0.5])).norm() < 1e-15);
        assert!((e.eval(&[pi]) - g.eval(&[2.0])).norm() < 1e-15);
        assert!((e.eval(&[2.0 * pi - 0.3]) - e.eval(&[0.3])).norm() < 1e-14);
        // dθ-derivative on the reflected half has the opposite sign
        let d1 = curve_derivative(&e, 0.3, 0.0, 1);
        let d2 = curve_derivative(&e, 2.0 * pi - 0.3, 0.0, 1);
        assert!((d1 + d2).norm() < 1e-13);
        let s = FourierSeries::analyse(|t| e.eval(&[t]), 16, 256);
        assert!(s.b.iter().all(|b| b.norm() < 1e-13), "sine coefficients of an even function vanish");
        // coefficients decay like 1/n²
        assert!(s.a[15].norm() < 2.0 * s.a[3].norm() * (3.0f64 / 15.0).powi(2) + 1e-12);
    }
}
