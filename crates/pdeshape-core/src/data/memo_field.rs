//! A field whose one-slot derivatives are kept by the parameters asked for: for boundary
//! data that cost much per point (an N-sided fill's loop on CAD faces: each point a foot
//! curve and a reparametrisation in truncated Taylor arithmetic) and that grids ask for
//! at the same `v` again and again (every cell of a fit's row of cells), and jets at up
//! to three parameters (a mesh hole's collar, asked at the same points by the fills of
//! several fullnesses). The values are the inner field's, bit for bit.

use super::{Field, FieldRef, VecJet};
use crate::Vec3;
use crate::jet::{Jet, JetShape};
use crate::memo::BoundedMemo;
use std::sync::Arc;

/// Keys: the first two slots' bits, the slot, the number of derivatives.
type Key = (u64, u64, usize, usize);

/// Jet keys: the three slots' bits and the shape.
type JetKey = ([u64; 3], JetShape);

/// `inner` with its [`Field::derivatives_in`] and [`Field::jet`] (at up to three slots)
/// memoised (at most 16 384 results of each kept).
pub struct MemoField {
    inner: FieldRef,
    memo: BoundedMemo<Key, Arc<[Vec3]>>,
    jets: BoundedMemo<JetKey, Arc<VecJet>>,
    /// With [`MemoField::covering`]: jets of shapes within this one are cut from the
    /// point's jet of this shape.
    cover: Option<JetShape>,
}

impl MemoField {
    /// Wraps `inner`.
    pub fn new(inner: FieldRef) -> Self {
        MemoField { inner, memo: BoundedMemo::new(16_384), jets: BoundedMemo::new(16_384), cover: None }
    }

    /// Wraps `inner`, whose jets are asked at the same points in many shapes within
    /// `cover` (a fill's solves ask its boundary data for values, first and second cross
    /// derivatives, each with its own number of derivatives along the loop): a point's jet
    /// is computed once, in shape `cover`, and the smaller ones are its Taylor
    /// coefficients within theirs. A jet's coefficient of a multi-index is a sum over
    /// smaller multi-indices only, so it does not depend on the shape it was computed in
    /// beyond the order of that sum's terms: round-off. The shape computed does not
    /// depend on the order of the requests (nor on threads).
    pub fn covering(inner: FieldRef, cover: JetShape) -> Self {
        MemoField { cover: Some(cover), ..MemoField::new(inner) }
    }
}

impl std::fmt::Debug for MemoField {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "MemoField({:?})", self.inner)
    }
}

impl Field for MemoField {
    fn arity(&self) -> usize {
        self.inner.arity()
    }
    fn jet(&self, at: &[f64], shape: JetShape) -> VecJet {
        if at.len() > 3 {
            return self.inner.jet(at, shape);
        }
        let mut bits = [0; 3];
        for (b, x) in bits.iter_mut().zip(at) {
            *b = x.to_bits();
        }
        // a different number of slots at the same values is another point of another field
        let point = [bits[0], bits[1], bits[2] ^ ((at.len() as u64) << 60)];
        let asked = shape.orders();
        let computed = match self.cover {
            Some(c) if c.orders().iter().zip(&asked).all(|(c, a)| a <= c) => c,
            _ => shape,
        };
        let key = (point, computed);
        let j = match self.jets.get(&key) {
            Some(j) => j,
            None => {
                let j = Arc::new(self.inner.jet(at, computed));
                self.jets.insert(key, j.clone());
                j
            }
        };
        if computed == shape {
            return (*j).clone();
        }
        VecJet(std::array::from_fn(|k| {
            Jet::from_coeffs(shape, shape.multi_indices().map(|m| j.0[k].coeff(m)).collect())
        }))
    }
    fn derivatives_in(&self, at: &[f64], slot: usize, out: &mut [Vec3]) {
        // covering: through the point's one jet (the inner field's default answers from
        // its jet of this shape as well)
        if self.cover.is_some() && at.len() <= 3 {
            return super::derivatives_by_jet(self, at, slot, out);
        }
        // only the slots a key holds (later slots would be ignored by it)
        if at.len() > 2 {
            return self.inner.derivatives_in(at, slot, out);
        }
        let key = (at[0].to_bits(), at.get(1).map_or(0, |x| x.to_bits()), slot, out.len());
        if let Some(v) = self.memo.get(&key) {
            out.copy_from_slice(&v);
            return;
        }
        self.inner.derivatives_in(at, slot, out);
        self.memo.insert(key, Arc::from(&*out));
    }
    fn is_constant_in(&self, slot: usize) -> bool {
        self.inner.is_constant_in(slot)
    }
    fn host_normal(&self, at: &[f64]) -> Option<Vec3> {
        self.inner.host_normal(at)
    }
    fn expressions(&self) -> Option<(&[crate::expr::Expr; 3], &[String])> {
        self.inner.expressions()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::ExprField;
    use crate::data::tests::Counted;

    /// The same bits as the inner field, which is asked once per point, slot and order.
    #[test]
    fn values_are_the_inner_fields_and_asked_once() {
        let e = ExprField::parse(["cos(3*v)", "sin(v)*t", "v*v"], &["v", "t"], &|_| None).unwrap();
        let inner = Arc::new(Counted::new(e.clone()));
        let m = MemoField::new(inner.clone());
        for _ in 0..3 {
            for v in [0.1, 0.7, 2.0] {
                for n in [1, 3] {
                    let (mut a, mut b) = (vec![Vec3::ZERO; n], vec![Vec3::ZERO; n]);
                    m.derivatives_in(&[v, 0.5], 0, &mut a);
                    e.derivatives_in(&[v, 0.5], 0, &mut b);
                    assert_eq!(a, b);
                }
            }
        }
        assert_eq!(inner.count(), 6);
        for _ in 0..3 {
            for v in [0.1, 0.7] {
                for shape in [JetShape::new(&[2, 1]), JetShape::new(&[1, 1])] {
                    assert_eq!(m.jet(&[v, 0.5], shape), e.jet(&[v, 0.5], shape));
                }
            }
        }
        assert_eq!(inner.count(), 10, "each jet asked once per point and shape");
    }

    /// Covering: each point's jet computed once, in the covering shape; smaller shapes and
    /// derivatives along a slot cut from it agree with the inner field's own to round-off,
    /// and a shape beyond the cover is the inner field's own.
    #[test]
    fn covering_cuts_smaller_jets_from_one() {
        let e = ExprField::parse(["cos(3*v)*exp(t)", "sin(v)*t*t", "v*v/(1+t*t)"], &["v", "t"], &|_| None).unwrap();
        let inner = Arc::new(Counted::new(e.clone()));
        let m = MemoField::covering(inner.clone(), JetShape::new(&[2, 3]));
        let points = [[0.1, 0.5], [0.7, -0.2], [2.0, 1.3]];
        for _ in 0..2 {
            for at in points {
                for orders in [[0, 0], [1, 1], [2, 2], [0, 3], [2, 3], [1, 0]] {
                    let shape = JetShape::new(&orders);
                    let (a, b) = (m.jet(&at, shape), e.jet(&at, shape));
                    for k in 0..3 {
                        assert_eq!(a.0[k].shape(), shape);
                        for (x, y) in a.0[k].coeffs().iter().zip(b.0[k].coeffs()) {
                            // the same Taylor arithmetic, its sums cut at another shape:
                            // round-off of coefficients of size ~10
                            assert!((x - y).abs() <= 1e-14 * (1.0 + y.abs()), "{at:?} {orders:?}: {x} {y}");
                        }
                    }
                }
                for slot in [0, 1] {
                    let (mut a, mut b) = (vec![Vec3::ZERO; 3], vec![Vec3::ZERO; 3]);
                    m.derivatives_in(&at, slot, &mut a);
                    e.derivatives_in(&at, slot, &mut b);
                    for (x, y) in a.iter().zip(&b) {
                        assert!((*x - *y).norm() <= 1e-13 * (1.0 + y.norm()), "{at:?} slot {slot}: {x:?} {y:?}");
                    }
                }
            }
        }
        assert_eq!(inner.count(), points.len(), "one jet a point");
        // beyond the cover: the inner field's own, bit for bit
        let big = JetShape::new(&[3, 1]);
        assert_eq!(m.jet(&points[0], big), e.jet(&points[0], big));
        assert_eq!(inner.count(), points.len() + 1);
    }
}
