//! Weighted union-find over numbered nodes: which nodes `at`-constraints tie together, and at what
//! fixed distance from each other (`value(node) = value(root) + offset(node)`).

use smallvec::SmallVec;

/// Nodes joined by fixed distances (those of a typical block on the stack).
#[derive(Debug, Clone, Default)]
pub(crate) struct Offsets {
    parent: SmallVec<[usize; 16]>,
    offset: SmallVec<[f64; 16]>,
}

impl Offsets {
    /// `n` separate nodes.
    #[cfg(test)]
    pub(crate) fn new(n: usize) -> Self {
        let mut o = Self::default();
        o.reset(n);
        o
    }

    /// Makes this `n` separate nodes. (Filling a list in place: a constructor that returned
    /// one would copy its inline storage.)
    pub(crate) fn reset(&mut self, n: usize) {
        self.parent.clear();
        self.parent.extend(0..n);
        self.offset.clear();
        self.offset.resize(n, 0.0);
    }

    /// The node's root and its offset from it.
    pub(crate) fn find(&mut self, v: usize) -> (usize, f64) {
        let p = self.parent[v];
        if p == v {
            return (v, 0.0);
        }
        let (root, off) = self.find(p);
        self.parent[v] = root;
        self.offset[v] += off;
        (root, self.offset[v])
    }

    /// Records `value(a) = value(b) + d` (ignored if `a` and `b` are already joined).
    pub(crate) fn join(&mut self, a: usize, b: usize, d: f64) {
        let ((ra, oa), (rb, ob)) = (self.find(a), self.find(b));
        if ra != rb {
            // value(ra) = value(a) - oa = value(b) + d - oa = value(rb) + ob + d - oa
            self.parent[ra] = rb;
            self.offset[ra] = ob + d - oa;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Offsets;

    #[test]
    fn distances_compose_through_joins() {
        let mut o = Offsets::new(4);
        o.join(1, 0, 2.0); // v1 = v0 + 2
        o.join(2, 1, 0.5); // v2 = v1 + 0.5
        o.join(3, 2, -1.0); // v3 = v2 - 1
        let (r0, a) = o.find(0);
        let (r3, d) = o.find(3);
        assert_eq!(r0, r3);
        assert!((d - a - 1.5).abs() < 1e-12);
        let mut separate = Offsets::new(2);
        assert_ne!(
            separate.find(0).0,
            separate.find(1).0,
            "unjoined nodes have their own roots"
        );
    }
}
