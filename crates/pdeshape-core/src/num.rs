//! Reductions that keep NaN.
//!
//! `f64::max` returns the other argument when one is NaN, so a maximum error taken with it
//! over samples that include a NaN reports the largest *finite* sample: a broken patch
//! would pass its own check. Every error, norm and size in this crate is reduced with
//! [`max_nan`] / [`MaxNan::max_nan`], which return NaN as soon as any input is NaN.
//!
//! ```
//! use pdeshape_core::num::{MaxNan, max_nan};
//! assert!(max_nan(1.0, f64::NAN).is_nan());
//! assert!(max_nan(f64::NAN, 1.0).is_nan());
//! assert_eq!([0.5, 2.0, 1.0].into_iter().max_nan(), 2.0);
//! assert!([0.5, f64::NAN, 1.0].into_iter().max_nan().is_nan());
//! // f64::max drops it:
//! assert_eq!([0.5, f64::NAN, 1.0].into_iter().fold(0.0, f64::max), 1.0);
//! ```

/// The larger of `a` and `b`; NaN when either is NaN.
#[inline]
pub fn max_nan(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() { f64::NAN } else { a.max(b) }
}

/// The smaller of `a` and `b`; NaN when either is NaN.
#[inline]
pub fn min_nan(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() { f64::NAN } else { a.min(b) }
}

/// NaN-keeping maximum of an iterator of `f64`.
pub trait MaxNan: Iterator<Item = f64> + Sized {
    /// The largest item, `0.0` for no items (the reductions here are of errors and norms),
    /// NaN when any item is NaN.
    fn max_nan(self) -> f64 {
        self.fold(0.0, max_nan)
    }
}

impl<I: Iterator<Item = f64>> MaxNan for I {}

/// `Σ aᵢbᵢ` over the common length, with four partial sums so the products pipeline (the
/// order of summation differs from a left-to-right loop by round-off only).
pub fn dot(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    let (a, b) = (&a[..n], &b[..n]);
    let mut s = [0.0; 4];
    let (ca, cb) = (a.chunks_exact(4), b.chunks_exact(4));
    let (ra, rb) = (ca.remainder(), cb.remainder());
    for (x, y) in ca.zip(cb) {
        for j in 0..4 {
            s[j] += x[j] * y[j];
        }
    }
    let mut r = (s[0] + s[1]) + (s[2] + s[3]);
    for (x, y) in ra.iter().zip(rb) {
        r += x * y;
    }
    r
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nan_anywhere_gives_nan() {
        for k in 0..4 {
            let mut xs = [1.0, 2.0, 3.0, 4.0];
            xs[k] = f64::NAN;
            assert!(xs.into_iter().max_nan().is_nan(), "NaN at {k}");
            assert!(xs.into_iter().fold(f64::INFINITY, min_nan).is_nan(), "NaN at {k}");
        }
        assert_eq!([1.0, 4.0, 3.0].into_iter().max_nan(), 4.0);
        assert_eq!(std::iter::empty().max_nan(), 0.0);
        assert_eq!([1.0, f64::INFINITY].into_iter().max_nan(), f64::INFINITY);
    }
}
