//! Weighted union-find over numbered nodes: which nodes `at`-constraints tie together, and at what
//! fixed distance from each other (`value(node) = value(root) + offset(node)`).

use smallvec::SmallVec;

use super::diff::EPSILON;

/// Nodes joined by fixed distances (those of a typical block on the stack).
#[derive(Debug, Clone, Default)]
pub(crate) struct Offsets {
    /// Per node: the node above it and its distance from that one (`ROOT`, 0 for a root).
    nodes: SmallVec<[(usize, f64); 16]>,
}

/// The "node above" of a root.
const ROOT: usize = usize::MAX;

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
        self.nodes.clear();
        self.nodes.resize(n, (ROOT, 0.0));
    }

    /// The number of nodes.
    pub(crate) fn len(&self) -> usize {
        self.nodes.len()
    }

    /// The node's root and its offset from it; the path to the root is shortened on the way.
    pub(crate) fn find(&mut self, v: usize) -> (usize, f64) {
        walk(&mut self.nodes, v)
    }

    /// Records `value(a) = value(b) + d`. Returns whether that is consistent: `false` if `a` and
    /// `b` are already joined at a distance more than [`EPSILON`] away from `d` (the record is
    /// then left as it was).
    pub(crate) fn join(&mut self, a: usize, b: usize, d: f64) -> bool {
        let ((ra, oa), (rb, ob)) = (self.find(a), self.find(b));
        if ra == rb {
            return (oa - (ob + d)).abs() <= EPSILON;
        }
        // value(ra) = value(a) - oa = value(b) + d - oa = value(rb) + ob + d - oa
        self.nodes[ra] = (rb, ob + d - oa);
        true
    }

    /// The least values of all nodes when the joins are the only ties between them: node 0 is
    /// at 0, and `value(v) >= bound` for each `(v, bound)` of `bounds`. Every group of joined
    /// nodes sits as early as its bounds allow, node 0's group where node 0 is at 0; `None` if a
    /// bound in node 0's group does not hold there (more than [`EPSILON`] short), or if a value
    /// is beyond the range of `f64`. Every node must be in node 0's group or in a group with a
    /// bound.
    ///
    /// This is the least solution of the difference system with the joins as equalities and the
    /// bounds as constraints from node 0 (without a search over its edges). It is written into
    /// `x`, one value per node (see [`super::room`] for a list on the caller's stack).
    pub(crate) fn least(
        &mut self,
        bounds: impl Iterator<Item = (usize, f64)>,
        x: &mut [f64],
    ) -> Option<()> {
        assert_eq!(x.len(), self.nodes.len(), "one value per node");
        // read as a slice from here on (no inline-or-heap check per step)
        let nodes = self.nodes.as_mut_slice();
        // every node straight under its root; x[v] holds v's distance from its root, and for a
        // root, where it must be for every bound in its group to hold
        for (v, xv) in x.iter_mut().enumerate() {
            let (root, off) = walk(nodes, v);
            *xv = if root == v { f64::NEG_INFINITY } else { off };
        }
        let root = |x: &[f64], v: usize| match nodes[v].0 {
            ROOT => (v, 0.0),
            r => (r, x[v]),
        };
        for (v, bound) in bounds {
            let (r, off) = root(x, v);
            x[r] = x[r].max(bound - off);
        }
        let (r0, off0) = root(x, 0);
        let fixed = -off0;
        if x[r0] > fixed + EPSILON {
            return None;
        }
        x[r0] = fixed;
        // the other nodes where their roots are
        for v in 0..nodes.len() {
            let r = nodes[v].0;
            if r != ROOT {
                x[v] += x[r];
            }
        }
        // times beyond the range of f64 (offsets near its limits) are no solution
        x.iter().all(|t| t.is_finite()).then_some(())
    }
}

/// [`Offsets::find`] on the list of nodes.
fn walk(nodes: &mut [(usize, f64)], v: usize) -> (usize, f64) {
    let (up, d) = nodes[v];
    if up == ROOT {
        return (v, 0.0);
    }
    if nodes[up].0 == ROOT {
        return (up, d); // right under the root (the common case)
    }
    let (root, off) = walk(nodes, up);
    nodes[v] = (root, d + off);
    (root, d + off)
}

#[cfg(test)]
mod tests {
    use super::Offsets;
    use crate::language::bml::Relation;
    use crate::planning::schedule::diff::{DiffSystem, EPSILON};
    use proptest::prelude::*;

    /// A system of joins and bounds over `n` nodes, with times in eighths of a second (exact in
    /// binary, so a bound either holds exactly or misses by at least 1/8).
    #[derive(Debug, Clone)]
    struct Ties {
        n: usize,
        /// `(a, b, d)`: value(a) = value(b) + d.
        joins: Vec<(usize, usize, f64)>,
        bounds: Vec<(usize, f64)>,
    }

    fn ties() -> impl Strategy<Value = Ties> {
        (2usize..12).prop_flat_map(|n| {
            let eighths = |lo: i32, hi: i32| (lo..hi).prop_map(|e| f64::from(e) / 8.0);
            (
                proptest::collection::vec(eighths(-16, 64), n),
                proptest::collection::vec((0..n, 0..n, prop::bool::weighted(0.1)), 0..2 * n),
                proptest::collection::vec((0..n, eighths(-16, 64)), 0..n),
            )
                .prop_map(move |(x, pairs, mut bounds)| {
                    // joins at the distances of a known assignment; one in ten off by 1/2
                    let joins = pairs
                        .into_iter()
                        .map(|(a, b, off)| (a, b, x[a] - x[b] + if off { 0.5 } else { 0.0 }))
                        .collect::<Vec<_>>();
                    // a bound in every group away from node 0 (the scheduler bounds every item)
                    let mut o = Offsets::new(n);
                    for &(a, b, d) in &joins {
                        o.join(a, b, d);
                    }
                    for (v, &xv) in x.iter().enumerate().skip(1) {
                        let r = o.find(v).0;
                        let bounded = bounds.iter().any(|&(w, _)| o.find(w).0 == r);
                        if r != o.find(0).0 && !bounded {
                            bounds.push((v, xv - 1.0));
                        }
                    }
                    Ties { n, joins, bounds }
                })
        })
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(600))]

        /// The joined groups give the same least solution as the difference system with
        /// the joins as `at` constraints and the bounds as constraints from node 0, and both
        /// refuse the same systems (contradicting joins, a bound node 0's group cannot meet).
        #[test]
        fn least_by_groups_is_the_least_solution_of_the_difference_system(t in ties()) {
            let mut s = DiffSystem::new();
            for v in 0..t.n {
                s.var(if v == 0 { 0.0 } else { f64::MIN / 4.0 });
            }
            let mut o = Offsets::new(t.n);
            let mut consistent = true;
            for (tag, &(a, b, d)) in t.joins.iter().enumerate() {
                s.relate(a, Relation::At, b, d, tag);
                consistent &= o.join(a, b, d);
            }
            for &(v, bound) in &t.bounds {
                s.at_least(v, 0, bound, 0);
            }
            let expected = s.into_least().filter(|x| x[0] <= EPSILON);
            let mut x = vec![0.0; t.n];
            let got = if consistent {
                o.least(t.bounds.iter().copied(), &mut x).map(|()| x)
            } else {
                None
            };
            match (expected, got) {
                (None, None) => {}
                (Some(x), Some(y)) => {
                    for (v, (a, b)) in x.iter().zip(&y).enumerate() {
                        prop_assert!((a - b).abs() <= 1e-9, "node {v}: {a} vs {b} ({x:?} vs {y:?})");
                    }
                }
                (x, y) => prop_assert!(false, "difference system {x:?}, groups {y:?}"),
            }
        }
    }

    /// A join that repeats a known distance is consistent; one that contradicts it is refused
    /// and changes nothing.
    #[test]
    fn a_join_against_a_known_distance_reports_whether_it_agrees() {
        let mut o = Offsets::new(3);
        assert!(o.join(1, 0, 2.0));
        assert!(o.join(2, 1, 1.0));
        assert!(o.join(2, 0, 3.0), "the same distance again");
        assert!(!o.join(2, 0, 3.5), "half a second off");
        assert_eq!(o.find(2).1 - o.find(0).1, 3.0);
        let mut x = [0.0; 3];
        assert_eq!(o.least([(1, 0.0)].into_iter(), &mut x), Some(()));
        assert_eq!(x, [0.0, 2.0, 3.0]);
        // a bound that node 0's group cannot meet; elsewhere, groups move up to their bounds
        assert_eq!(o.least([(1, 2.5)].into_iter(), &mut x), None);
        let mut apart = Offsets::new(3);
        apart.join(2, 1, 1.0);
        assert_eq!(
            apart.least([(2, 4.0), (1, 0.5)].into_iter(), &mut x),
            Some(())
        );
        assert_eq!(x, [0.0, 3.0, 4.0]);
    }

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
