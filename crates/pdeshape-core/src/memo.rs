//! A bounded memo: values by key behind a mutex, emptied when it reaches its bound, so a
//! scan over many keys (a slider dragged, an animation played, a grid evaluated at new
//! rows) cannot grow it without end. The spectral patches' rows, the cardinal functions
//! shared by spectral solves and a dynamic blend's frames are kept in one.
//!
//! A poisoned lock (a panic while it was held) turns the memo off: lookups miss and
//! inserts are dropped, and the values are computed again.

use std::collections::HashMap;
use std::hash::Hash;
use std::sync::Mutex;

/// Values by key, at most `bound` of them.
pub struct BoundedMemo<K, V> {
    map: Mutex<HashMap<K, V>>,
    bound: usize,
}

impl<K: Eq + Hash, V: Clone> BoundedMemo<K, V> {
    /// An empty memo that is emptied whenever it holds `bound` values (`bound ≥ 1`).
    pub fn new(bound: usize) -> Self {
        BoundedMemo { map: Mutex::new(HashMap::new()), bound: bound.max(1) }
    }

    /// The value kept for `key`.
    pub fn get(&self, key: &K) -> Option<V> {
        self.map.lock().ok().and_then(|m| m.get(key).cloned())
    }

    /// Keeps `value` for `key`, emptying the memo first when it is full.
    pub fn insert(&self, key: K, value: V) {
        if let Ok(mut m) = self.map.lock() {
            if m.len() >= self.bound {
                m.clear();
            }
            m.insert(key, value);
        }
    }

    /// The value for `key`: the one kept, or `make()`'s, kept when it is `Ok`. `make` runs
    /// outside the lock (two threads asking for a new key at once may both compute it).
    pub fn get_or_try_insert_with<E>(&self, key: K, make: impl FnOnce() -> Result<V, E>) -> Result<V, E> {
        if let Some(v) = self.get(&key) {
            return Ok(v);
        }
        let v = make()?;
        self.insert(key, v.clone());
        Ok(v)
    }

    /// Empties the memo.
    pub fn clear(&self) {
        if let Ok(mut m) = self.map.lock() {
            m.clear();
        }
    }

    /// The number of values kept.
    pub fn len(&self) -> usize {
        self.map.lock().map(|m| m.len()).unwrap_or(0)
    }

    /// Whether no value is kept.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

impl<K, V> std::fmt::Debug for BoundedMemo<K, V> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let len = self.map.lock().map(|m| m.len()).ok();
        f.debug_struct("BoundedMemo").field("len", &len).field("bound", &self.bound).finish()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keeps_values_up_to_its_bound_then_starts_over() {
        let m = BoundedMemo::new(3);
        for k in 0..3 {
            m.insert(k, k * 10);
        }
        assert_eq!((m.len(), m.get(&2)), (3, Some(20)));
        m.insert(3, 30); // full: emptied, then 3 kept
        assert_eq!((m.len(), m.get(&0), m.get(&3)), (1, None, Some(30)));
        m.clear();
        assert!(m.is_empty());
    }

    #[test]
    fn computes_a_value_once_and_does_not_keep_errors() {
        let m = BoundedMemo::new(8);
        let mut calls = 0;
        let mut make = |ok: bool| {
            calls += 1;
            if ok { Ok::<_, &str>(calls) } else { Err("no") }
        };
        assert_eq!(m.get_or_try_insert_with(1, || make(false)), Err("no"));
        assert_eq!(m.get_or_try_insert_with(1, || make(true)), Ok(2));
        assert_eq!(m.get_or_try_insert_with(1, || make(true)), Ok(2), "kept, not computed again");
        assert_eq!(calls, 2);
    }
}
