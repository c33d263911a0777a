//! Property tests of the difference-constraint solver under the scheduler: on systems
//! built from a known feasible assignment it satisfies every constraint within 1e-9, respects lower
//! bounds, returns the least solution and ignores constraint order; an injected contradictory cycle
//! is reported, and the reported set is itself infeasible and minimal.

use bml_realizer::planning::schedule::diff::{DiffSystem, Edge};
use proptest::prelude::*;

#[derive(Debug, Clone)]
struct Case {
    truth: Vec<f64>,
    lower: Vec<f64>,
    /// (kind 0 = at_least, 1 = at_most, 2 = equal, a, b, slack)
    constraints: Vec<(u8, usize, usize, f64)>,
}

fn case() -> impl Strategy<Value = Case> {
    (2usize..30).prop_flat_map(|n| {
        (
            proptest::collection::vec(0i64..20_000, n),
            proptest::collection::vec(0i64..3_000, n),
            proptest::collection::vec((0u8..3, 0..n, 0..n, 0i64..2_000), 0..(3 * n)),
        )
            .prop_map(|(t, slack, cs)| {
                let truth: Vec<f64> = t.iter().map(|&k| k as f64 / 1000.0).collect();
                let lower = truth
                    .iter()
                    .zip(&slack)
                    .map(|(x, s)| (x - *s as f64 / 1000.0).max(0.0))
                    .collect();
                let constraints = cs
                    .into_iter()
                    .map(|(k, a, b, s)| (k, a, b, s as f64 / 1000.0))
                    .collect();
                Case {
                    truth,
                    lower,
                    constraints,
                }
            })
    })
}

/// Builds the system; every constraint holds for `truth` (with the given slack).
fn build(c: &Case) -> DiffSystem {
    let mut s = DiffSystem::new();
    for &l in &c.lower {
        s.var(l);
    }
    for (tag, &(kind, a, b, slack)) in c.constraints.iter().enumerate() {
        let d = c.truth[a] - c.truth[b];
        match kind {
            0 => s.at_least(a, b, d - slack, tag), // x_a >= x_b + (d - slack)
            1 => s.at_most(a, b, d + slack, tag),  // x_a <= x_b + (d + slack)
            _ => s.equal(a, b, d, tag),
        }
    }
    s
}

fn holds(e: &Edge, x: &[f64]) -> bool {
    x[e.to] >= x[e.from] + e.weight - 1e-9
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(600))]

    #[test]
    fn feasible_systems_are_solved_least_and_within_tolerance(c in case()) {
        let s = build(&c);
        let x = s.solve().expect("built from a feasible assignment");
        for e in s.edges() {
            prop_assert!(holds(e, &x), "{e:?} violated: {} vs {}", x[e.to], x[e.from] + e.weight);
        }
        for ((xi, lo), truth) in x.iter().zip(&c.lower).zip(&c.truth) {
            prop_assert!(*xi >= lo - 1e-12, "below its lower bound");
            prop_assert!(*xi <= truth + 1e-9, "not the least solution: {} > {}", xi, truth);
        }
    }

    #[test]
    fn constraint_order_does_not_change_the_solution(c in case(), seed in any::<u64>()) {
        let x = build(&c).solve().unwrap();
        let mut shuffled = c.clone();
        // deterministic Fisher–Yates from the seed
        let mut r = seed | 1;
        for i in (1..shuffled.constraints.len()).rev() {
            r ^= r << 13; r ^= r >> 7; r ^= r << 17;
            shuffled.constraints.swap(i, (r % (i as u64 + 1)) as usize);
        }
        let y = build(&shuffled).solve().unwrap();
        for (a, b) in x.iter().zip(&y) {
            prop_assert!((a - b).abs() <= 1e-9, "{a} vs {b}");
        }
    }

    #[test]
    fn an_injected_contradiction_is_reported_minimal_and_infeasible(
        c in case(), picks in proptest::collection::vec(any::<prop::sample::Index>(), 2..5), excess in 1i64..5_000
    ) {
        let mut s = build(&c);
        let n = s.len();
        // a cycle v0 -> v1 -> ... -> v0 whose weights sum to +excess
        let mut vs: Vec<usize> = picks.iter().map(|p| p.index(n)).collect();
        vs.dedup();
        if vs.len() < 2 || vs.first() == vs.last() {
            vs = vec![0, 1];
        }
        let base = c.constraints.len();
        let mut total = 0.0;
        for (i, w) in vs.windows(2).enumerate() {
            let weight = c.truth[w[1]] - c.truth[w[0]];
            total += weight;
            s.at_least(w[1], w[0], weight, base + i);
        }
        let (last, first) = (*vs.last().unwrap(), vs[0]);
        s.at_least(first, last, -total + excess as f64 / 1000.0, base + vs.len());
        let conflict = s.solve().expect_err("a positive cycle was added");
        prop_assert!(conflict.weight() > 1e-9);
        for w in conflict.edges.windows(2) {
            prop_assert_eq!(w[0].to, w[1].from);
        }
        prop_assert_eq!(conflict.edges.last().unwrap().to, conflict.edges[0].from);
        // the reported set alone is infeasible ...
        let only = |skip: Option<usize>| {
            let mut t = DiffSystem::new();
            for &l in &c.lower { t.var(l); }
            for (i, e) in conflict.edges.iter().enumerate() {
                if Some(i) != skip { t.at_least(e.to, e.from, e.weight, e.tag); }
            }
            t.solve()
        };
        prop_assert!(only(None).is_err());
        // ... and minimal: without any one of its constraints it is feasible
        for i in 0..conflict.edges.len() {
            prop_assert!(only(Some(i)).is_ok());
        }
    }
}
