//! The semantics of each kind of constraint (at, before, after, absolute and relative, offsets,
//! ungrounded clusters, anticipators), one test each, with the
//! `Optimal` strategy and the default timing models.

use bml_realizer::language::bml::{self, SyncPoint};
use bml_realizer::planning::schedule::{
    BlockSchedule, ExternalTimes, NoExternal, Optimal, SchedulingStrategy,
};
use bml_realizer::planning::timing::DefaultTimingModels;

fn block(body: &str) -> String {
    format!(
        r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" xmlns:bmlt="http://hmi.ewi.utwente.nl/bmlt" id="b1">{body}</bml>"#
    )
}

fn run_with(src: &str, external: &dyn ExternalTimes) -> BlockSchedule {
    let b = bml::load(src).unwrap_or_else(|e| panic!("{e}")).block;
    Optimal
        .schedule(&b, &DefaultTimingModels::default(), external)
        .unwrap()
}

fn run(src: &str) -> BlockSchedule {
    run_with(src, &NoExternal)
}

const SAMPLE: &str = r#"<speech id="s1" start="1"><text>Look <sync id="w"/>here, please.</text></speech>
    <gesture id="g1" lexeme="BEAT" stroke="s1:w+0.25"/><gaze id="z1" target="t" ready="g1:start"/>
    <faceLexeme id="f1" lexeme="RAISE_BROWS" attackPeak="s1:w" end="s1:end"/>"#;

#[test]
fn every_sync_of_every_behaviour_has_a_time() {
    let s = run(&block(SAMPLE));
    assert_eq!(s.behaviours.len(), 4);
    for b in &s.behaviours {
        assert!(
            b.syncs.iter().all(|(_, t)| t.is_finite()),
            "{}: {:?}",
            b.id,
            b.syncs
        );
    }
    assert_eq!(s.behaviour("g1").unwrap().syncs.len(), 7);
}

#[test]
fn absolute_at_is_block_start_plus_offset() {
    let s = run(&block(r#"<head id="h" lexeme="NOD" stroke="2.5"/>"#));
    assert_eq!(s.time("h", "stroke"), Some(2.5));
}

#[test]
fn relative_at_with_offset_means_time_plus_offset() {
    let s = run(&block(SAMPLE));
    let (w, stroke) = (s.time("s1", "w").unwrap(), s.time("g1", "stroke").unwrap());
    assert!((stroke - (w + 0.25)).abs() < 1e-9);
}

#[test]
fn no_sync_before_block_start() {
    // the gesture's preparation would start before the block if the stroke were at 0.1
    let s = run(&block(
        r#"<speech id="s1"><text>Hi <sync id="w"/>you</text></speech><gesture id="g1" lexeme="BEAT" stroke="s1:w"/>"#,
    ));
    for b in &s.behaviours {
        assert!(
            b.syncs.iter().all(|(_, t)| *t >= -1e-9),
            "{}: {:?}",
            b.id,
            b.syncs
        );
    }
}

#[test]
fn end_strictly_after_start() {
    // asked to squeeze a nod into zero time it still ends after it starts
    let s = run(&block(
        r#"<head id="h" lexeme="NOD" start="1" end="1.00001"/>"#,
    ));
    assert!(s.time("h", "end").unwrap() > s.time("h", "start").unwrap());
}

#[test]
fn default_sync_points_are_in_order() {
    let s = run(&block(SAMPLE));
    for b in &s.behaviours {
        assert!(
            b.syncs.windows(2).all(|w| w[1].1 >= w[0].1 - 1e-9),
            "{}: {:?}",
            b.id,
            b.syncs
        );
    }
}

#[test]
fn custom_syncs_lie_between_start_and_end() {
    let s = run(&block(SAMPLE));
    let (start, w, end) = (
        s.time("s1", "start").unwrap(),
        s.time("s1", "w").unwrap(),
        s.time("s1", "end").unwrap(),
    );
    assert!(start < w && w < end);
}

#[test]
fn a_persistent_behaviour_has_an_infinite_end() {
    let s = run(&block(
        r#"<bmlt:controller id="c" class="Balance" start="1"/>"#,
    ));
    assert_eq!(s.time("c", "end"), Some(f64::INFINITY));
}

struct Predicted(f64);

impl ExternalTimes for Predicted {
    fn time(&self, p: &SyncPoint) -> Option<f64> {
        matches!(p, SyncPoint::Anticipator { .. }).then_some(self.0)
    }
}

#[test]
fn anticipator_at_is_prediction_plus_offset() {
    let s = run_with(
        &block(r#"<head id="h" lexeme="NOD" stroke="anticipators:beat:b1+0.5"/>"#),
        &Predicted(3.0),
    );
    assert_eq!(s.time("h", "stroke"), Some(3.5));
}

#[test]
fn linking_a_sync_to_two_anticipator_syncs_is_rejected() {
    let src = block(
        r#"<head id="h" lexeme="NOD" stroke="anticipators:beat:b1"/><constraint><synchronize ref="anticipators:clap:c1"><sync ref="h:stroke"/></synchronize></constraint>"#,
    );
    let e = bml::load(&src).unwrap_err();
    assert!(
        e.first().message.contains("only one anticipator"),
        "{}",
        e.first().message
    );
}
