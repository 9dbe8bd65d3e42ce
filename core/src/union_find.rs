//! Disjoint sets over `0..n` (components, vertex fans, patches): path halving, and the smaller root
//! always wins a union, so a set's representative is its smallest member whatever the order of the
//! unions — numberings derived from roots are deterministic.

/// Disjoint sets over `0..n`.
#[derive(Clone, Debug, Default)]
pub struct UnionFind(Vec<u32>);

impl UnionFind {
    /// `n` singletons.
    pub fn new(n: usize) -> Self {
        let mut uf = UnionFind(Vec::new());
        uf.reset(n);
        uf
    }

    /// Back to `n` singletons, reusing the allocation.
    pub fn reset(&mut self, n: usize) {
        debug_assert!(u32::try_from(n).is_ok());
        self.0.clear();
        self.0.extend(0..n as u32);
    }

    /// Number of elements.
    pub fn len(&self) -> usize {
        self.0.len()
    }

    /// No element at all.
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// The representative of `x`'s set: its smallest member.
    pub fn find(&mut self, mut x: u32) -> u32 {
        while self.0[x as usize] != x {
            let up = self.0[self.0[x as usize] as usize];
            self.0[x as usize] = up;
            x = up;
        }
        x
    }

    /// Merges the sets of `a` and `b`; true when they were apart.
    pub fn union(&mut self, a: u32, b: u32) -> bool {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            self.0[ra.max(rb) as usize] = ra.min(rb);
        }
        ra != rb
    }
}

#[cfg(test)]
mod tests {
    use super::UnionFind;

    #[test]
    fn representative_is_the_smallest_member_in_any_union_order() {
        for order in [[(4, 3), (3, 1), (5, 4)], [(5, 4), (4, 3), (1, 3)]] {
            let mut uf = UnionFind::new(6);
            for (a, b) in order {
                assert!(uf.union(a, b));
            }
            assert!(!uf.union(1, 5));
            assert_eq!([1, 3, 4, 5].map(|x| uf.find(x)), [1; 4]);
            assert_eq!(uf.find(0), 0);
            assert_eq!(uf.find(2), 2);
        }
    }
}
