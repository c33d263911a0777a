//! Every block the realizer accepts ends, whatever numbers it holds: random blocks with extreme
//! times and offsets (tiny, huge, negative, beyond the limits, ties between behaviours, APPEND
//! and REPLACE between blocks) go through the runtime on the virtual clock until nothing more
//! will happen. Each block that was scheduled (a PENDING prediction) reports exactly one start
//! and one end, or one REVOKED end and no start; the others were refused with a warning.

#[path = "common/random_bml.rs"]
mod random_bml;

use std::collections::BTreeMap;

use bml_realizer::language::bml::Limits;
use bml_realizer::language::feedback::{BlockStatus, Feedback};
use bml_realizer::realizer::Realizer;
use proptest::prelude::*;

const NUMBERS: &[&str] = &[
    "0", "1e-9", "0.001", "1", "2.5", "1e5", "999999", "1e6", "1e7", "1e308", "-1", "-1e6", "-0",
];
const KINDS: &[&str] = &[
    r#"gesture lexeme="BEAT""#,
    r#"head lexeme="NOD" repetition="1000""#,
    r#"gaze target="user""#,
    r#"faceLexeme lexeme="SMILE""#,
    r#"wait max-wait="1e6""#,
    r#"locomotion target="user""#,
];
const SYNCS: &[&str] = &["start", "ready", "stroke", "relax", "end"];
const COMPOSITIONS: &[&str] = &["", r#" composition="APPEND""#, r#" composition="REPLACE""#];

/// A behaviour: its kind, and (sync, number, tied to an earlier behaviour's sync?) attributes.
type Beh = (usize, Vec<(usize, usize, Option<usize>)>);

fn block(i: usize, composition: usize, behaviours: &[Beh]) -> String {
    let mut body = String::new();
    for (b, (kind, syncs)) in behaviours.iter().enumerate() {
        let kind = KINDS[*kind];
        let name = kind.split(' ').next().unwrap();
        let syncs = syncs.iter().map(|&(sync, number, tie)| {
            let sync = if name == "wait" || name == "locomotion" {
                sync % 2 * 4
            } else {
                sync
            };
            let value = match tie.filter(|_| b > 0) {
                Some(other) => format!("x{}:{}+{}", other % b, SYNCS[sync], NUMBERS[number]),
                None => NUMBERS[number].to_string(),
            };
            (SYNCS[sync], value)
        });
        body.push_str(&random_bml::behaviour(kind, b, syncs));
    }
    format!(
        r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="b{i}"{}>{body}</bml>"#,
        COMPOSITIONS[composition]
    )
}

fn behaviour() -> impl Strategy<Value = Beh> {
    (
        0..KINDS.len(),
        proptest::collection::vec(
            (
                0..SYNCS.len(),
                0..NUMBERS.len(),
                proptest::option::of(0usize..4),
            ),
            0..3,
        ),
    )
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 300, ..ProptestConfig::default() })]

    #[test]
    fn every_scheduled_block_starts_and_ends_once(
        blocks in proptest::collection::vec(
            (0..COMPOSITIONS.len(), 0.0f64..3.0, proptest::collection::vec(behaviour(), 1..4)),
            1..4,
        )
    ) {
        // with the time limit, and without it (then the runtime's own guard must hold)
        for limits in [Limits::default(), Limits { time: f64::MAX, ..Limits::default() }] {
            settles(&blocks, limits)?;
        }
    }
}

type Blocks = Vec<(usize, f64, Vec<Beh>)>;

fn settles(blocks: &Blocks, limits: Limits) -> Result<(), TestCaseError> {
    {
        let mut r = Realizer::new().with_limits(limits);
        let mut feedback = Vec::new();
        for (i, (composition, after, behaviours)) in blocks.iter().enumerate() {
            let now = r.now() + after;
            feedback.extend(r.tick(now).feedback);
            let _ = r.perform_bml(&block(i, *composition, behaviours));
            feedback.extend(r.tick(now).feedback);
        }
        let mut events = 0;
        while let Some(t) = r.next_event() {
            events += 1;
            prop_assert!(events < 100_000, "the realizer never settles");
            feedback.extend(r.tick(t).feedback);
        }
        // (scheduled, starts, ends, revoked ends) per block
        let mut seen: BTreeMap<String, (bool, usize, usize, usize)> = BTreeMap::new();
        for f in &feedback {
            match f {
                Feedback::Prediction(p) => {
                    for b in &p.blocks {
                        if b.status == Some(BlockStatus::Pending) {
                            seen.entry(b.id.to_string()).or_default().0 = true;
                        }
                    }
                }
                Feedback::BlockProgress(p) => {
                    let e = seen.entry(p.block.to_string()).or_default();
                    match (p.sync.as_str(), p.status) {
                        ("start", _) => e.1 += 1,
                        ("end", Some(BlockStatus::Revoked)) => e.3 += 1,
                        _ => e.2 += 1,
                    }
                }
                _ => {}
            }
        }
        for (id, (scheduled, starts, ends, revoked)) in seen {
            if scheduled {
                let once = (starts == 1 && ends == 1 && revoked == 0)
                    || (starts == 0 && ends == 0 && revoked == 1);
                prop_assert!(
                    once,
                    "{}: {} starts, {} ends, {} revoked",
                    id,
                    starts,
                    ends,
                    revoked
                );
            } else {
                prop_assert_eq!(
                    (starts, ends, revoked),
                    (0, 0, 0),
                    "{} was never scheduled",
                    id
                );
            }
        }
    }
    Ok(())
}

/// Found by the proptest: a locomotion ending 1e308 s after a nod tied at 0 and a wait at
/// 999 999 s made the simplex stall for ever (without the time limit on the block). Numbers that
/// far out never reach the linear program now; the block is scheduled at once and ends.
#[test]
fn a_block_with_huge_and_tiny_times_does_not_stall_the_scheduler() {
    let blocks: Blocks = vec![(
        2,
        0.0,
        vec![
            (5, vec![(1, 9, None)]),
            (4, vec![(0, 6, None)]),
            (1, vec![(2, 12, None)]),
        ],
    )];
    assert_eq!(
        block(0, 2, &blocks[0].2),
        r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="b0" composition="REPLACE"><locomotion target="user" id="x0" end="1e308"/><wait max-wait="1e6" id="x1" start="999999"/><head lexeme="NOD" repetition="1000" id="x2" stroke="-0"/></bml>"#
    );
    let limits = Limits {
        time: f64::MAX,
        ..Limits::default()
    };
    settles(&blocks, limits).unwrap();
}

/// A block that waits for a pre-planned block and asks that block to wait for it
/// (`appendAfter` and `prependBefore` naming the same block) made a cycle: once the first was
/// activated, neither ever started. The second request is refused with a warning and both end.
#[test]
fn blocks_cannot_be_made_to_wait_for_each_other() {
    const NS: &str = r#"xmlns="http://www.bml-initiative.org/bml/bml-1.0" xmlns:bmla="http://www.asap-project.org/bmla""#;
    let mut r = Realizer::new();
    let mut feedback = Vec::new();
    for text in [
        format!(
            r#"<bml {NS} id="a" bmla:preplan="true"><speech id="s"><text>Hello there.</text></speech></bml>"#
        ),
        format!(
            r#"<bml {NS} id="n" bmla:appendAfter="a" bmla:prependBefore="a"><speech id="s"><text>Me first.</text></speech></bml>"#
        ),
        format!(r#"<bml {NS} id="go" bmla:onStart="a"/>"#),
    ] {
        r.perform_bml(&text).unwrap();
    }
    feedback.extend(r.tick(0.0).feedback);
    while let Some(t) = r.next_event() {
        feedback.extend(r.tick(t).feedback);
    }
    let progress: Vec<String> = feedback
        .iter()
        .filter_map(|f| match f {
            Feedback::BlockProgress(p) => Some(format!("{}:{}", p.block, p.sync)),
            _ => None,
        })
        .collect();
    for id in ["a", "n"] {
        assert!(
            progress.contains(&format!("{id}:end")),
            "{id} never ends: {progress:?}"
        );
    }
    assert!(feedback.iter().any(|f| matches!(f, Feedback::Warning(w)
        if w.id == "n" && w.text.contains("wait for each other"))));
}
