//! Classes of indices joined pairwise (disjoint sets: union–find with path halving): which
//! vertices of touching parts coincide, which fitted faces must share their knots.

/// Classes of `0 … n − 1`, each named by its smallest member.
#[derive(Clone, Debug)]
pub struct Classes {
    parent: Vec<usize>,
}

impl Classes {
    /// `n` classes of one member each.
    pub fn new(n: usize) -> Classes {
        Classes { parent: (0..n).collect() }
    }

    /// The class of `i`: its smallest member (a root is never put under a larger one).
    pub fn of(&mut self, mut i: usize) -> usize {
        while self.parent[i] != i {
            self.parent[i] = self.parent[self.parent[i]];
            i = self.parent[i];
        }
        i
    }

    /// Joins the classes of `a` and `b`.
    pub fn join(&mut self, a: usize, b: usize) {
        let (ra, rb) = (self.of(a), self.of(b));
        self.parent[ra.max(rb)] = ra.min(rb);
    }

    /// The class of every index.
    pub fn all(mut self) -> Vec<usize> {
        (0..self.parent.len()).map(|i| self.of(i)).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Chains joined in both orders name each class by its smallest member.
    #[test]
    fn classes_are_named_by_their_smallest_member() {
        let mut c = Classes::new(8);
        for (a, b) in [(5, 3), (3, 7), (6, 1), (7, 6), (2, 4)] {
            c.join(a, b);
        }
        assert_eq!(c.all(), vec![0, 1, 2, 1, 2, 1, 1, 1]);
    }
}
