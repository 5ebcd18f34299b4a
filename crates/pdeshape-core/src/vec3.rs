//! A small 3-vector type for points and derivatives in R³.

use crate::num::{max_nan, min_nan};
use std::ops::{Add, AddAssign, Div, Index, IndexMut, Mul, MulAssign, Neg, Sub, SubAssign};

/// A vector (or point) in R³.
///
/// ```
/// use pdeshape_core::Vec3;
/// let a = Vec3::new(1.0, 0.0, 0.0);
/// let b = Vec3::new(0.0, 1.0, 0.0);
/// assert_eq!(a.cross(b), Vec3::new(0.0, 0.0, 1.0));
/// assert_eq!((a + b).dot(a), 1.0);
/// ```
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Vec3 {
    /// x component.
    pub x: f64,
    /// y component.
    pub y: f64,
    /// z component.
    pub z: f64,
}

impl Vec3 {
    /// The zero vector.
    pub const ZERO: Vec3 = Vec3 { x: 0.0, y: 0.0, z: 0.0 };

    /// Creates a vector from its components.
    #[inline]
    pub const fn new(x: f64, y: f64, z: f64) -> Self {
        Vec3 { x, y, z }
    }

    /// Creates a vector from an array `[x, y, z]`.
    #[inline]
    pub const fn from_array(a: [f64; 3]) -> Self {
        Vec3 { x: a[0], y: a[1], z: a[2] }
    }

    /// The components as an array `[x, y, z]`.
    #[inline]
    pub const fn to_array(self) -> [f64; 3] {
        [self.x, self.y, self.z]
    }

    /// Dot product `a·b`.
    #[inline]
    pub fn dot(self, o: Vec3) -> f64 {
        self.x * o.x + self.y * o.y + self.z * o.z
    }

    /// Cross product `a×b`.
    #[inline]
    pub fn cross(self, o: Vec3) -> Vec3 {
        Vec3::new(self.y * o.z - self.z * o.y, self.z * o.x - self.x * o.z, self.x * o.y - self.y * o.x)
    }

    /// Euclidean length `|a|`.
    #[inline]
    pub fn norm(self) -> f64 {
        self.dot(self).sqrt()
    }

    /// Euclidean length without underflow or overflow on the way: the components are
    /// scaled by the largest before squaring, so `|a|` is right (to round-off) for any
    /// finite `a`, from subnormal to `f64::MAX`, where [`norm`](Self::norm) squares to 0 below
    /// ~1e-154 and to inf above ~1e154. NaN propagates. When the squares' sum lies in
    /// `(1e-290, 1e290)` it is `norm` itself: nothing overflows, and components whose
    /// squares underflow are below 1e-145 of the length, under its rounding. Otherwise the
    /// scaled form, slower.
    ///
    /// ```
    /// use pdeshape_core::Vec3;
    /// assert_eq!(Vec3::new(3e-200, 4e-200, 0.0).norm(), 0.0);
    /// assert!((Vec3::new(3e-200, 4e-200, 0.0).scaled_norm() / 5e-200 - 1.0).abs() < 1e-15);
    /// assert!((Vec3::new(3e200, 4e200, 0.0).scaled_norm() / 5e200 - 1.0).abs() < 1e-15);
    /// assert!(Vec3::new(f64::NAN, 1.0, 0.0).scaled_norm().is_nan());
    /// assert_eq!(Vec3::new(f64::INFINITY, 1.0, 0.0).scaled_norm(), f64::INFINITY);
    /// assert_eq!(Vec3::new(3.0, 4.0, 0.0).scaled_norm(), 5.0);
    /// // at the edge of the fast range: 1e-145 squared is 1e-290
    /// assert!((Vec3::new(3e-145, 4e-145, 0.0).scaled_norm() / 5e-145 - 1.0).abs() < 1e-15);
    /// ```
    #[inline]
    pub fn scaled_norm(self) -> f64 {
        let s = self.dot(self);
        // false for NaN and inf: those take the scaled form, which propagates them
        if s > 1e-290 && s < 1e290 {
            return s.sqrt();
        }
        let m = self.max_abs();
        if m == 0.0 || !m.is_finite() {
            return m;
        }
        m * (self / m).norm()
    }

    /// Largest absolute component (the ∞-norm); NaN when a component is NaN.
    #[inline]
    pub fn max_abs(self) -> f64 {
        max_nan(max_nan(self.x.abs(), self.y.abs()), self.z.abs())
    }

    /// The unit vector in the direction of `a`, or `None` for a zero vector or one with a
    /// non-finite component. Where the squared length under- or overflows (components
    /// below ~1e-154 or above ~1e154: a scene at 1e-160 or 1e150) the vector is scaled by
    /// its largest component first, so its direction is kept.
    ///
    /// ```
    /// use pdeshape_core::Vec3;
    /// assert_eq!(Vec3::new(3e200, 0.0, 4e200).normalized(), Some(Vec3::new(0.6, 0.0, 0.8)));
    /// assert!(Vec3::new(0.0, 1e-200, 0.0).normalized().is_some());
    /// assert!(Vec3::ZERO.normalized().is_none());
    /// ```
    #[inline]
    pub fn normalized(self) -> Option<Vec3> {
        let n = self.norm();
        if n > 0.0 && n.is_finite() {
            return Some(self / n);
        }
        let m = self.max_abs();
        if !(m > 0.0 && m.is_finite()) {
            return None;
        }
        let s = self / m;
        Some(s / s.norm())
    }

    /// Componentwise minimum (NaN where either component is NaN, so a bounding box of
    /// points with a NaN is NaN, not the box of the other points).
    #[inline]
    pub fn min(self, o: Vec3) -> Vec3 {
        Vec3::new(min_nan(self.x, o.x), min_nan(self.y, o.y), min_nan(self.z, o.z))
    }

    /// Componentwise maximum (NaN where either component is NaN).
    #[inline]
    pub fn max(self, o: Vec3) -> Vec3 {
        Vec3::new(max_nan(self.x, o.x), max_nan(self.y, o.y), max_nan(self.z, o.z))
    }

    /// True when all three components are finite.
    #[inline]
    pub fn is_finite(self) -> bool {
        self.x.is_finite() && self.y.is_finite() && self.z.is_finite()
    }

    /// Linear interpolation `(1 − t)a + t b`.
    #[inline]
    pub fn lerp(self, o: Vec3, t: f64) -> Vec3 {
        self + (o - self) * t
    }
}

impl Add for Vec3 {
    type Output = Vec3;
    #[inline]
    fn add(self, o: Vec3) -> Vec3 {
        Vec3::new(self.x + o.x, self.y + o.y, self.z + o.z)
    }
}
impl AddAssign for Vec3 {
    #[inline]
    fn add_assign(&mut self, o: Vec3) {
        *self = *self + o;
    }
}
impl Sub for Vec3 {
    type Output = Vec3;
    #[inline]
    fn sub(self, o: Vec3) -> Vec3 {
        Vec3::new(self.x - o.x, self.y - o.y, self.z - o.z)
    }
}
impl SubAssign for Vec3 {
    #[inline]
    fn sub_assign(&mut self, o: Vec3) {
        *self = *self - o;
    }
}
impl Mul<f64> for Vec3 {
    type Output = Vec3;
    #[inline]
    fn mul(self, s: f64) -> Vec3 {
        Vec3::new(self.x * s, self.y * s, self.z * s)
    }
}
impl Mul<Vec3> for f64 {
    type Output = Vec3;
    #[inline]
    fn mul(self, v: Vec3) -> Vec3 {
        v * self
    }
}
impl MulAssign<f64> for Vec3 {
    #[inline]
    fn mul_assign(&mut self, s: f64) {
        *self = *self * s;
    }
}
impl Div<f64> for Vec3 {
    type Output = Vec3;
    #[inline]
    fn div(self, s: f64) -> Vec3 {
        Vec3::new(self.x / s, self.y / s, self.z / s)
    }
}
impl Neg for Vec3 {
    type Output = Vec3;
    #[inline]
    fn neg(self) -> Vec3 {
        Vec3::new(-self.x, -self.y, -self.z)
    }
}
impl Index<usize> for Vec3 {
    type Output = f64;
    #[inline]
    fn index(&self, i: usize) -> &f64 {
        match i {
            0 => &self.x,
            1 => &self.y,
            2 => &self.z,
            _ => panic!("Vec3 index {i} out of range"),
        }
    }
}
impl IndexMut<usize> for Vec3 {
    #[inline]
    fn index_mut(&mut self, i: usize) -> &mut f64 {
        match i {
            0 => &mut self.x,
            1 => &mut self.y,
            2 => &mut self.z,
            _ => panic!("Vec3 index {i} out of range"),
        }
    }
}
impl std::iter::Sum for Vec3 {
    fn sum<I: Iterator<Item = Vec3>>(iter: I) -> Vec3 {
        iter.fold(Vec3::ZERO, |a, b| a + b)
    }
}

impl std::fmt::Display for Vec3 {
    /// `(x, y, z)`, each component as `f64` prints (precision passes through: `{:.3}`).
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match f.precision() {
            Some(p) => write!(f, "({:.p$}, {:.p$}, {:.p$})", self.x, self.y, self.z),
            None => write!(f, "({}, {}, {})", self.x, self.y, self.z),
        }
    }
}
