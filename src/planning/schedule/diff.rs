//! Difference constraints `x[to] >= x[from] + weight` over numbered variables: the least solution
//! above per-variable lower bounds (longest paths), or, when the system is infeasible, one positive
//! cycle of constraints — a minimal conflicting set (removing any one of its constraints breaks it).
//!
//! Every BML timing constraint is of this form: `at` (two edges), `before`/`after` (one edge),
//! absolute constraints against the block-start variable, sync order inside a behaviour, engine
//! duration bounds. The least solution is unique, so it does not depend on the order in which
//! constraints were added (the scheduler's order invariance rests on this).
//!
//! The solver is a queue-based Bellman–Ford (SPFA): O(V·E) worst case, near-linear on the sparse,
//! mostly acyclic graphs that BML blocks give. It is written here rather than taken from petgraph
//! because the scheduler needs the cycle as constraint tags, lower bounds per variable, and no
//! allocation beyond a few flat vectors per solve.

use crate::language::bml::Relation;

/// Improvements smaller than this (seconds) are not propagated: constraints hold within it, and
/// cycles whose total weight is below it (float rounding of offsets) are not conflicts.
pub const EPSILON: f64 = 1e-9;

/// One constraint `x[to] >= x[from] + weight`, tagged with the caller's constraint id.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Edge {
    /// The variable that must come later.
    pub to: usize,
    /// The variable it is measured from.
    pub from: usize,
    /// Minimum distance `x[to] - x[from]` (may be negative).
    pub weight: f64,
    /// The caller's id for the constraint this edge comes from (reported in conflicts).
    pub tag: usize,
}

/// A set of difference constraints over `n` variables, each with a lower bound.
#[derive(Debug, Clone, Default)]
pub struct DiffSystem {
    lower: Vec<f64>,
    edges: Vec<Edge>,
}

/// The constraints that cannot hold together: a positive cycle of edges.
#[derive(Debug, Clone, PartialEq)]
pub struct Conflict {
    /// The cycle's edges in cycle order (`to` of each is `from` of the next).
    pub edges: Vec<Edge>,
}

impl Conflict {
    /// The caller's tags of the cycle's edges, in cycle order.
    pub fn tags(&self) -> impl Iterator<Item = usize> + '_ {
        self.edges.iter().map(|e| e.tag)
    }

    /// Total weight of the cycle: positive (beyond [`EPSILON`]) for a real conflict.
    pub fn weight(&self) -> f64 {
        self.edges.iter().map(|e| e.weight).sum()
    }
}

impl DiffSystem {
    /// An empty system.
    pub fn new() -> Self {
        Self::default()
    }

    /// An empty system with room for `vars` variables and `edges` edges.
    pub fn with_capacity(vars: usize, edges: usize) -> Self {
        DiffSystem {
            lower: Vec::with_capacity(vars),
            edges: Vec::with_capacity(edges),
        }
    }

    /// Adds a variable with lower bound `lower`; returns its index.
    pub fn var(&mut self, lower: f64) -> usize {
        self.lower.push(lower);
        self.lower.len() - 1
    }

    /// Number of variables.
    pub fn len(&self) -> usize {
        self.lower.len()
    }

    /// Whether there are no variables.
    pub fn is_empty(&self) -> bool {
        self.lower.is_empty()
    }

    /// The constraints added so far.
    pub fn edges(&self) -> &[Edge] {
        &self.edges
    }

    /// `x[to] >= x[from] + weight`.
    pub fn at_least(&mut self, to: usize, from: usize, weight: f64, tag: usize) {
        debug_assert!(to < self.len() && from < self.len() && weight.is_finite());
        self.edges.push(Edge {
            to,
            from,
            weight,
            tag,
        });
    }

    /// `x[a] <= x[b] + offset`.
    pub fn at_most(&mut self, a: usize, b: usize, offset: f64, tag: usize) {
        self.at_least(b, a, -offset, tag);
    }

    /// `x[a] == x[b] + offset`.
    pub fn equal(&mut self, a: usize, b: usize, offset: f64, tag: usize) {
        self.at_least(a, b, offset, tag);
        self.at_most(a, b, offset, tag);
    }

    /// `x[a] REL x[b] + offset` for a BML relation (`=`, `<=`, `>=`).
    pub fn relate(&mut self, a: usize, relation: Relation, b: usize, offset: f64, tag: usize) {
        match relation {
            Relation::At => self.equal(a, b, offset, tag),
            Relation::Before => self.at_most(a, b, offset, tag),
            Relation::After => self.at_least(a, b, offset, tag),
        }
    }

    /// The least solution with every variable at or above its lower bound, or a conflicting cycle.
    pub fn solve(&self) -> Result<Vec<f64>, Conflict> {
        self.least().ok_or_else(|| self.find_cycle())
    }

    /// The least solution, or `None` when the system is infeasible (without finding out why:
    /// for callers that only try).
    pub fn least(&self) -> Option<Vec<f64>> {
        let mut x = self.lower.clone();
        self.raise(&mut x).then_some(x)
    }

    /// [`Self::least`] for a system that is not needed afterwards: the solution is written over
    /// the lower bounds (no second list).
    pub fn into_least(mut self) -> Option<Vec<f64>> {
        let mut x = std::mem::take(&mut self.lower);
        self.raise(&mut x).then_some(x)
    }

    /// Raises `x` (the lower bounds) to the least solution; `false` if the system is infeasible.
    fn raise(&self, x: &mut [f64]) -> bool {
        let (n, m) = (x.len(), self.edges.len());
        // one scratch allocation, split into: CSR offsets of the edges grouped by `from` (n + 1),
        // a fill cursor per variable (n), the grouped edge indices (m), the length of the path
        // that gave each variable its value (n), and a ring queue of variables (n) in which each
        // variable is at most once (`queued`, n)
        let need = (n + 1) + n + m + 3 * n;
        let mut scratch = vec![0usize; need];
        let (start, rest) = scratch.split_at_mut(n + 1);
        let (fill, rest) = rest.split_at_mut(n);
        let (out, rest) = rest.split_at_mut(m);
        let (path_len, rest) = rest.split_at_mut(n);
        let (ring, queued) = rest.split_at_mut(n);
        for e in &self.edges {
            start[e.from + 1] += 1;
        }
        for i in 0..n {
            start[i + 1] += start[i];
        }
        fill.copy_from_slice(&start[..n]);
        for (i, e) in self.edges.iter().enumerate() {
            out[fill[e.from]] = i;
            fill[e.from] += 1;
        }

        // a path longer than n edges repeats a variable, so it contains a positive cycle
        for (i, r) in ring.iter_mut().enumerate() {
            *r = i;
        }
        queued.fill(1);
        let (mut head, mut len) = (0usize, n);
        while len > 0 {
            let u = ring[head];
            head = if head + 1 == n { 0 } else { head + 1 };
            len -= 1;
            queued[u] = 0;
            for &ei in &out[start[u]..start[u + 1]] {
                let e = &self.edges[ei];
                let candidate = x[u] + e.weight;
                if candidate > x[e.to] + EPSILON {
                    x[e.to] = candidate;
                    path_len[e.to] = path_len[u] + 1;
                    if path_len[e.to] > n {
                        return false;
                    }
                    if queued[e.to] == 0 {
                        queued[e.to] = 1;
                        let tail = if head + len >= n {
                            head + len - n
                        } else {
                            head + len
                        };
                        ring[tail] = e.to;
                        len += 1;
                    }
                }
            }
        }
        true
    }

    /// Finds a positive cycle (the system is known to be infeasible) with classic Bellman–Ford:
    /// a variable still raised in round n has a predecessor chain that runs into the cycle. Only the
    /// error path pays for this.
    fn find_cycle(&self) -> Conflict {
        let n = self.len();
        let mut x = self.lower.clone();
        let mut pred: Vec<Option<usize>> = vec![None; n];
        let mut last = None;
        for _ in 0..n {
            last = None;
            for (ei, e) in self.edges.iter().enumerate() {
                let candidate = x[e.from] + e.weight;
                if candidate > x[e.to] + EPSILON {
                    x[e.to] = candidate;
                    pred[e.to] = Some(ei);
                    last = Some(e.to);
                }
            }
            if last.is_none() {
                break;
            }
        }
        let Some(mut u) = last else {
            return Conflict { edges: Vec::new() };
        };
        for _ in 0..n {
            if let Some(ei) = pred[u] {
                u = self.edges[ei].from;
            }
        }
        let first = u;
        let mut edges = Vec::new();
        while let Some(ei) = pred[u] {
            edges.push(self.edges[ei]);
            u = self.edges[ei].from;
            if u == first || edges.len() > n {
                break;
            }
        }
        edges.reverse();
        Conflict { edges }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn least_solution_of_a_small_chain() {
        let mut s = DiffSystem::new();
        let block = s.var(0.0);
        let a = s.var(0.0);
        let b = s.var(0.0);
        s.at_least(a, block, 2.0, 0); // a >= block + 2
        s.equal(b, a, 1.5, 1); // b = a + 1.5
        s.at_most(a, b, -1.5, 2); // consistent with the equality
        assert_eq!(s.solve().unwrap(), vec![0.0, 2.0, 3.5]);
        // written over the lower bounds, the same answer
        assert_eq!(s.into_least(), Some(vec![0.0, 2.0, 3.5]));
    }

    #[test]
    fn lower_bounds_are_respected() {
        let mut s = DiffSystem::new();
        let a = s.var(5.0);
        let b = s.var(0.0);
        s.at_least(b, a, -10.0, 0);
        assert_eq!(s.solve().unwrap(), vec![5.0, 0.0]);
    }

    #[test]
    fn contradictory_cycle_is_reported_with_its_tags() {
        // a = b + 1, b = c + 1, c >= a  → a >= a + 2
        let mut s = DiffSystem::new();
        let (a, b, c) = (s.var(0.0), s.var(0.0), s.var(0.0));
        s.equal(a, b, 1.0, 10);
        s.equal(b, c, 1.0, 11);
        s.at_least(c, a, 0.0, 12);
        let conflict = s.solve().unwrap_err();
        assert_eq!(s.clone().into_least(), None);
        let mut tags: Vec<usize> = conflict.tags().collect();
        tags.sort();
        assert_eq!(tags, vec![10, 11, 12]);
        assert!((conflict.weight() - 2.0).abs() < 1e-12);
        for w in conflict.edges.windows(2) {
            assert_eq!(w[0].to, w[1].from, "edges form a path");
        }
        assert_eq!(
            conflict.edges.last().unwrap().to,
            conflict.edges[0].from,
            "and close a cycle"
        );
    }

    #[test]
    fn rounding_sized_cycles_are_not_conflicts() {
        // 0.1 + 0.2 and 0.3 differ in the last bit
        let mut s = DiffSystem::new();
        let (a, b, c) = (s.var(0.0), s.var(0.0), s.var(0.0));
        s.equal(b, a, 0.1, 0);
        s.equal(c, b, 0.2, 1);
        s.equal(c, a, 0.3, 2);
        let x = s.solve().unwrap();
        assert!((x[c] - 0.3).abs() < 1e-12);
    }
}
