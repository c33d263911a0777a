//! Random blocks built around a known feasible timing: the `Optimal`
//! strategy schedules every behaviour, satisfies every constraint within 1e-6, places nothing
//! before the block start, keeps each behaviour's sync order, and gives identical times for any
//! order of the behaviours.

use bml_realizer::language::bml::{self, Anchor, Relation, SyncPoint};
use bml_realizer::planning::schedule::{BlockSchedule, NoExternal, Optimal, SchedulingStrategy};
use bml_realizer::planning::timing::{DefaultTimingModels, Flexibility, TimingModels};
use proptest::prelude::*;

const KINDS: &[&str] = &[
    r#"<gesture id="ID" lexeme="BEAT"/>"#,
    r#"<head id="ID" lexeme="NOD"/>"#,
    r#"<gaze id="ID" target="t"/>"#,
    r#"<faceLexeme id="ID" lexeme="RAISE_BROWS"/>"#,
    r#"<speech id="ID"><text>one <sync id="a"/>two three <sync id="b"/>four</text></speech>"#,
    r#"<speech id="ID"><text>Hello there, <sync id="a"/>friend.</text></speech>"#,
];

/// A sync key of a generated behaviour: (behaviour index, key index modulo its key count).
type Key = (usize, usize);

#[derive(Debug, Clone)]
struct Spec {
    /// (kind index, start in ms, stretch in %)
    behaviours: Vec<(usize, u32, u32)>,
    /// (relation 0 at / 1 before / 2 after, (behaviour, key) or absolute, other side, slack in ms)
    constraints: Vec<(u8, Key, Option<Key>, u32)>,
    seed: u64,
}

fn spec() -> impl Strategy<Value = Spec> {
    (1usize..6).prop_flat_map(|n| {
        (
            proptest::collection::vec((0..KINDS.len(), 0u32..8_000, 50u32..300), n),
            proptest::collection::vec(
                (
                    0u8..3,
                    (0..n, 0usize..8),
                    proptest::option::of((0..n, 0usize..8)),
                    0u32..1_000,
                ),
                0..8,
            ),
            any::<u64>(),
        )
            .prop_map(|(behaviours, constraints, seed)| Spec {
                behaviours,
                constraints,
                seed,
            })
    })
}

/// The block text and the truth: every key's time under the chosen starts and stretches.
fn build(spec: &Spec) -> (String, Vec<Vec<(String, f64)>>) {
    let models = DefaultTimingModels::default();
    let mut body = String::new();
    let mut truth = Vec::new();
    for (i, &(kind, start, stretch)) in spec.behaviours.iter().enumerate() {
        let xml = KINDS[kind].replace("ID", &format!("b{i}"));
        let src =
            format!(r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="x">{xml}</bml>"#);
        let beh = bml::load(&src).unwrap().block.behaviours.remove(0);
        let model = models.model(&beh).unwrap();
        let scale = match model.flexibility {
            Flexibility::Rigid => 1.0,
            Flexibility::Stretchable { .. } => stretch as f64 / 100.0,
        };
        let start = start as f64 / 1000.0;
        truth.push(
            model
                .keys
                .iter()
                .map(|k| (k.name.to_string(), start + scale * k.at))
                .collect::<Vec<_>>(),
        );
        body.push_str(&xml);
    }
    let time_of = |(b, k): Key| -> (String, f64) {
        let keys = &truth[b];
        let (name, t) = &keys[k % keys.len()];
        (format!("b{b}:{name}"), *t)
    };
    let reference = |name: &str, base: f64, t: f64| -> String {
        let o = t - base;
        if o >= 0.0 {
            format!("{name}+{o}")
        } else {
            format!("{name}-{}", -o)
        }
    };
    body.push_str("<constraint>");
    for &(rel, a, b, slack) in &spec.constraints {
        let (sa, ta) = time_of(a);
        let slack = slack as f64 / 1000.0;
        // the other side: a behaviour key, or an absolute time, chosen so that the truth satisfies it
        let (r, tr) = match b {
            Some(b) => time_of(b),
            None => (String::new(), 0.0),
        };
        let target = match rel {
            0 => ta,                    // sa = R
            1 => ta + slack,            // sa <= R
            _ => (ta - slack).max(0.0), // sa >= R
        };
        let rref = if b.is_some() {
            reference(&r, tr, target)
        } else {
            format!("{target}")
        };
        let tag = ["synchronize", "before", "after"][rel as usize];
        body.push_str(&format!(
            r#"<{tag} ref="{rref}"><sync ref="{sa}"/></{tag}>"#
        ));
    }
    body.push_str("</constraint>");
    if spec.constraints.is_empty() {
        body = body.replace("<constraint></constraint>", "");
    }
    (
        format!(r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="x">{body}</bml>"#),
        truth,
    )
}

fn time(s: &BlockSchedule, a: &Anchor) -> f64 {
    match a {
        Anchor::BlockStart => 0.0,
        Anchor::Point(SyncPoint::Local { behaviour, sync }) => {
            s.time(behaviour, sync).expect("scheduled")
        }
        other => panic!("unexpected anchor {other:?}"),
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(600))]

    #[test]
    fn random_feasible_blocks_are_scheduled_within_every_constraint(spec in spec()) {
        let (src, _truth) = build(&spec);
        let block = bml::load(&src).map_err(|e| TestCaseError::fail(format!("{e}\n{src}")))?.block;
        let s = Optimal.schedule(&block, &DefaultTimingModels::default(), &NoExternal)
            .map_err(|e| TestCaseError::fail(format!("{e}\n{src}")))?;
        prop_assert!(s.dropped.is_empty(), "feasible block dropped {:?}\n{}", s.dropped, src);
        for c in bml::extract(&block) {
            let (l, r) = (time(&s, &c.left), time(&s, &c.right) + c.offset);
            let ok = match c.relation {
                Relation::At => (l - r).abs() <= 1e-6,
                Relation::Before => l <= r + 1e-6,
                Relation::After => l >= r - 1e-6,
            };
            prop_assert!(ok, "{c} violated: {l} vs {r}\n{src}");
        }
        for b in &s.behaviours {
            let times: Vec<f64> = b.syncs.iter().map(|(_, t)| *t).collect();
            prop_assert!(times.iter().all(|t| *t >= -1e-9), "{} before block start: {times:?}", b.id);
            prop_assert!(times.windows(2).all(|w| w[1] >= w[0] - 1e-9), "{} out of order: {times:?}", b.id);
            prop_assert!(times.last() > times.first(), "{} ends before it starts", b.id);
        }
        // the same block with its behaviours in another order
        let mut shuffled = block.clone();
        let mut r = spec.seed | 1;
        for i in (1..shuffled.behaviours.len()).rev() {
            r ^= r << 13; r ^= r >> 7; r ^= r << 17;
            shuffled.behaviours.swap(i, (r % (i as u64 + 1)) as usize);
        }
        let t = Optimal.schedule(&shuffled, &DefaultTimingModels::default(), &NoExternal).unwrap();
        for b in &s.behaviours {
            let other = t.behaviour(&b.id).unwrap();
            for ((n1, t1), (n2, t2)) in b.syncs.iter().zip(&other.syncs) {
                prop_assert_eq!(n1, n2);
                prop_assert!((t1 - t2).abs() <= 1e-9, "{}:{} {} vs {}\n{}", b.id, n1, t1, t2, src);
            }
        }
    }
}
