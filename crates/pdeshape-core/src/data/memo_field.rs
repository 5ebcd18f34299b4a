//! A field whose one-slot derivatives are kept by the parameters asked for: for boundary
//! data that cost much per point (an N-sided fill's loop on CAD faces: each point a foot
//! curve and a reparametrisation in truncated Taylor arithmetic) and that grids ask for
//! at the same `v` again and again (every cell of a fit's row of cells), and jets at up
//! to three parameters (a mesh hole's collar, asked at the same points by the fills of
//! several fullnesses). The values are the inner field's, bit for bit.

use super::{Field, FieldRef, VecJet};
use crate::Vec3;
use crate::jet::JetShape;
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
}

impl MemoField {
    /// Wraps `inner`.
    pub fn new(inner: FieldRef) -> Self {
        MemoField { inner, memo: BoundedMemo::new(16_384), jets: BoundedMemo::new(16_384) }
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
        let key = ([bits[0], bits[1], bits[2] ^ ((at.len() as u64) << 60)], shape);
        if let Some(j) = self.jets.get(&key) {
            return (*j).clone();
        }
        let j = self.inner.jet(at, shape);
        self.jets.insert(key, Arc::new(j.clone()));
        j
    }
    fn derivatives_in(&self, at: &[f64], slot: usize, out: &mut [Vec3]) {
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
    use std::sync::atomic::{AtomicUsize, Ordering};

    /// Counts the inner field's evaluations.
    #[derive(Debug)]
    struct Counted(ExprField, AtomicUsize);
    impl Field for Counted {
        fn arity(&self) -> usize {
            2
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

    /// The same bits as the inner field, which is asked once per point, slot and order.
    #[test]
    fn values_are_the_inner_fields_and_asked_once() {
        let e = ExprField::parse(["cos(3*v)", "sin(v)*t", "v*v"], &["v", "t"], &|_| None).unwrap();
        let inner = Arc::new(Counted(e.clone(), AtomicUsize::new(0)));
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
        assert_eq!(inner.1.load(Ordering::Relaxed), 6);
        for _ in 0..3 {
            for v in [0.1, 0.7] {
                for shape in [JetShape::new(&[2, 1]), JetShape::new(&[1, 1])] {
                    assert_eq!(m.jet(&[v, 0.5], shape), e.jet(&[v, 0.5], shape));
                }
            }
        }
        assert_eq!(inner.1.load(Ordering::Relaxed), 10, "each jet asked once per point and shape");
    }
}
