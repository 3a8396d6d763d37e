//! Disjoint sets over 0..n with path halving; a set's root is its smallest member, so the
//! result does not depend on the order the joins come in.

pub struct UnionFind {
    parent: Vec<u32>,
}

impl UnionFind {
    pub fn new(n: usize) -> Self {
        UnionFind {
            parent: (0..n as u32).collect(),
        }
    }

    /// The smallest member of `v`'s set.
    pub fn root(&mut self, mut v: usize) -> usize {
        while self.parent[v] as usize != v {
            let up = self.parent[self.parent[v] as usize];
            self.parent[v] = up;
            v = up as usize;
        }
        v
    }

    /// Joins the sets of `a` and `b`.
    pub fn join(&mut self, a: usize, b: usize) {
        let (ra, rb) = (self.root(a), self.root(b));
        let (lo, hi) = (ra.min(rb), ra.max(rb));
        self.parent[hi] = lo as u32;
    }
}
