//! The `Optimal` strategy on the thesis examples and RealizerTester files (their
//! expected timings), before/after constraints, conflicts and order invariance.

use bml_realizer::language::bml;
use bml_realizer::language::feedback::KnownWarning;
use bml_realizer::planning::schedule::{BlockSchedule, NoExternal, Optimal, SchedulingStrategy};
use bml_realizer::planning::timing::DefaultTimingModels;

fn fixture(path: &str) -> String {
    std::fs::read_to_string(format!("{}/fixtures/{path}", env!("CARGO_MANIFEST_DIR"))).unwrap()
}

fn schedule(src: &str) -> BlockSchedule {
    let block = bml::load(src).unwrap_or_else(|e| panic!("{e}")).block;
    Optimal
        .schedule(&block, &DefaultTimingModels::syllable_timed(), &NoExternal)
        .unwrap()
}

fn block(body: &str) -> String {
    format!(r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="b1">{body}</bml>"#)
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() < 1e-6
}

#[track_caller]
fn at(s: &BlockSchedule, beh: &str, sync: &str) -> f64 {
    s.time(beh, sync)
        .unwrap_or_else(|| panic!("{beh}:{sync} not scheduled: {s:?}"))
}

#[test]
fn realizertester_speech_gestures() {
    let s = schedule(&fixture("realizertester/bml-1/core/testspeechgestures.xml"));
    assert!(s.dropped.is_empty(), "{:?}", s.dropped);
    let expect = [
        ("g1", "start", 2.0),
        ("g1", "end", 4.0),
        ("welkom", "deicticheart1", 2.0),
        ("transleft", "start", 0.0),
        ("transleft", "end", 2.0),
        ("relaxleft", "start", 4.5),
        ("relaxleft", "end", 6.8),
    ];
    for (b, sync, t) in expect {
        assert!(
            close(at(&s, b, sync), t),
            "{b}:{sync} = {} (want {t})",
            at(&s, b, sync)
        );
    }
}

#[test]
fn realizertester_speech_and_nod_sync_timed() {
    let s = schedule(&fixture(
        "realizertester/bml-1/core/testspeechandnod_synctimed.xml",
    ));
    assert!(close(at(&s, "speech1", "s1"), 10.0));
    assert!(close(at(&s, "speech1", "start"), at(&s, "nod1", "start")));
    assert!(at(&s, "speech1", "start") < 10.0 && at(&s, "speech1", "end") > 10.0);
}

#[test]
fn realizertester_nod_timed_to_sync_in_both_orders() {
    let a = schedule(&fixture(
        "realizertester/bml-1/core/testspeech_nodtimedtosync.xml",
    ));
    let b = schedule(&fixture(
        "realizertester/bml-1/core/testspeech_nodtimedtosyncinverseorder.xml",
    ));
    assert!(close(at(&a, "speech1", "start"), 6.0));
    assert!(close(
        at(&a, "nod1", "start"),
        at(&a, "speech1", "syncstart1")
    ));
    assert!(close(at(&a, "nod1", "end"), 9.0));
    for beh in ["speech1", "nod1"] {
        assert_eq!(
            a.behaviour(beh).unwrap().syncs,
            b.behaviour(beh).unwrap().syncs,
            "{beh}"
        );
    }
}

#[test]
fn thesis_examples_schedule_identically_in_both_orders() {
    for (x, y) in [("ex27a", "ex27b"), ("ex28a", "ex28b"), ("ex29a", "ex29b")] {
        let a = schedule(&fixture(&format!("thesis/{x}.xml")));
        let b = schedule(&fixture(&format!("thesis/{y}.xml")));
        assert!(
            a.dropped.is_empty() && b.dropped.is_empty(),
            "{x}: {:?} {:?}",
            a.dropped,
            b.dropped
        );
        for beh in &a.behaviours {
            assert_eq!(Some(beh), b.behaviour(&beh.id), "{x} vs {y}: {}", beh.id);
        }
    }
    for ex in ["ex24", "ex25", "ex26", "ex30"] {
        let s = schedule(&fixture(&format!("thesis/{ex}.xml")));
        assert!(s.dropped.is_empty(), "{ex}: {:?}", s.dropped);
    }
}

#[test]
fn ex28_nod_keeps_its_shape_and_the_beat_follows_its_stroke() {
    let s = schedule(&fixture("thesis/ex28a.xml"));
    assert!(close(at(&s, "nod1", "start"), 3.0) && close(at(&s, "nod1", "end"), 5.0));
    // the nod is stretched uniformly: its stroke at half its preferred span (0.3 of 0.6 s)
    assert!(
        close(at(&s, "nod1", "stroke"), 4.0),
        "{}",
        at(&s, "nod1", "stroke")
    );
    assert!(close(at(&s, "beat1", "stroke"), 4.0));
    // the beat keeps its preferred timing around the stroke
    assert!(close(at(&s, "beat1", "start"), 3.5) && close(at(&s, "beat1", "end"), 4.5));
}

#[test]
fn ex26_clusters_start_on_their_after_constraints() {
    let s = schedule(&fixture("thesis/ex26.xml"));
    assert!(
        close(at(&s, "walk1", "start"), 0.0),
        "the walk's cluster has no after constraint"
    );
    assert!(
        close(at(&s, "point1", "start"), at(&s, "walk1", "end")),
        "point starts when the walk ends"
    );
    assert!(at(&s, "speech1", "start") >= 2.0 - 1e-9);
    assert!(close(at(&s, "point1", "stroke"), at(&s, "speech1", "s1")));
}

#[test]
fn ungrounded_cluster_starts_with_its_longest_lead() {
    // ex25: the gesture's preparation (0.5 s to stroke) is longer than "Hello" (0.4 s)
    let s = schedule(&fixture("thesis/ex25.xml"));
    assert!(close(at(&s, "g1", "start"), 0.0));
    assert!(close(at(&s, "g1", "stroke"), 0.5));
    assert!(close(at(&s, "speech1", "world"), 0.5) && close(at(&s, "speech1", "start"), 0.1));
}

#[test]
fn after_relative_constraint_holds_as_equality_for_a_free_cluster() {
    let s = schedule(&block(
        r#"<gesture id="g1" lexeme="BEAT" start="1"/><speech id="s1"><text>Hi there</text></speech>
           <constraint><after ref="g1:end"><sync ref="s1:start"/></after></constraint>"#,
    ));
    assert!(close(at(&s, "s1", "start"), at(&s, "g1", "end")));
    assert!(close(at(&s, "g1", "end"), 2.0));
}

#[test]
fn absolute_after_gives_exactly_its_time_and_before_bounds() {
    let s = schedule(&block(
        r#"<speech id="s1"><text>Hi</text></speech><gesture id="g1" lexeme="BEAT"/>
           <constraint><after ref="2"><sync ref="s1:start"/></after><before ref="5"><sync ref="g1:end"/></before></constraint>"#,
    ));
    assert!(close(at(&s, "s1", "start"), 2.0));
    assert!(at(&s, "g1", "end") <= 5.0 + 1e-9);
    assert!(close(at(&s, "g1", "start"), 0.0));
    // a before bound that forces stretching: g1 end before 0.5 (preferred 1 s)
    let s = schedule(&block(
        r#"<gesture id="g1" lexeme="BEAT"/><constraint><before ref="0.5"><sync ref="g1:end"/></before></constraint>"#,
    ));
    assert!(at(&s, "g1", "end") <= 0.5 + 1e-9);
}

#[test]
fn every_sync_is_in_order_and_not_before_block_start() {
    for f in [
        "core/testspeechgestures.xml",
        "core/testspeechgesturesync2x.xml",
        "core/testgaze.xml",
        "core/testpose.xml",
        "core/testshortbeh.xml",
    ] {
        let s = schedule(&fixture(&format!("realizertester/bml-1/{f}")));
        for b in &s.behaviours {
            let times: Vec<f64> = b.syncs.iter().map(|(_, t)| *t).collect();
            assert!(times.iter().all(|t| *t >= -1e-9), "{f} {}: {times:?}", b.id);
            assert!(
                times.windows(2).all(|w| w[1] >= w[0] - 1e-9),
                "{f} {}: {times:?}",
                b.id
            );
            assert!(
                times.last() > times.first(),
                "{f} {}: end after start",
                b.id
            );
        }
    }
}

#[test]
fn contradiction_drops_a_non_required_behaviour_and_names_the_constraints() {
    let s = schedule(&block(
        r#"<speech id="s1" start="1"><text>Hello world</text></speech>
           <gesture id="g1" lexeme="BEAT" start="s1:end" end="s1:start"/>"#,
    ));
    assert_eq!(s.dropped.len(), 1);
    assert_eq!(s.dropped[0].behaviour, "g1");
    assert_eq!(s.dropped[0].warning, KnownWarning::CannotSatisfyConstraints);
    assert!(
        s.dropped[0].reason.contains("g1:start = s1:end"),
        "{}",
        s.dropped[0].reason
    );
    assert!(
        close(at(&s, "s1", "start"), 1.0),
        "the rest of the block is scheduled"
    );
}

#[test]
fn a_drops_warning_names_the_constraints_of_other_behaviours_that_it_lifts() {
    // h1 contradicts itself; g1 and p1 were tied to it and move freely once it is dropped
    let s = schedule(&block(
        r#"<head id="h1" lexeme="NOD" start="2" end="1"/>
           <gesture id="g1" lexeme="BEAT" stroke="h1:stroke"/>
           <gaze id="z1" target="t" start="0.5"/>
           <constraint id="c1"><before ref="h1:end"><sync ref="z1:end"/></before></constraint>"#,
    ));
    assert_eq!(s.dropped.len(), 1);
    let reason = &s.dropped[0].reason;
    assert_eq!(s.dropped[0].behaviour, "h1");
    assert!(reason.contains("g1:stroke = h1:stroke"), "{reason}");
    assert!(reason.contains("z1:end <= h1:end"), "{reason}");
    // its own attributes are the conflict, not something it lifts
    assert!(!reason.contains("no longer hold: h1:start"), "{reason}");
}

#[test]
fn contradiction_inside_required_fails_the_block() {
    let src = block(
        r#"<required><speech id="s1" start="1"><text>Hello world</text></speech>
           <gesture id="g1" lexeme="BEAT" start="s1:end" end="s1:start"/></required>"#,
    );
    let b = bml::load(&src).unwrap().block;
    let e = Optimal
        .schedule(&b, &DefaultTimingModels::syllable_timed(), &NoExternal)
        .unwrap_err();
    assert!(e.reason.contains("g1:start = s1:end"), "{}", e.reason);
}

#[test]
fn unsupported_and_unresolvable_behaviours_are_dropped_with_their_warning() {
    let s = schedule(&block(
        r#"<x:dance xmlns:x="urn:x" id="d1"/><gesture id="g1" lexeme="BEAT" start="bml0:s1:end"/><head id="h1" lexeme="NOD"/>"#,
    ));
    let w: Vec<(&str, KnownWarning)> = s
        .dropped
        .iter()
        .map(|d| (d.behaviour.as_str(), d.warning))
        .collect();
    assert_eq!(
        w,
        [
            ("d1", KnownWarning::BehaviorTypeNotSupported),
            ("g1", KnownWarning::NoSuchTarget)
        ]
    );
    assert!(close(at(&s, "h1", "start"), 0.0));
}

mod order_invariance {
    use super::*;
    use proptest::prelude::*;

    const FILES: &[&str] = &[
        "realizertester/bml-1/core/testspeechgestures.xml",
        "realizertester/bml-1/core/testspeechgesturesync2x.xml",
        "realizertester/bml-1/core/testspeechandnod_synctimed.xml",
        "thesis/ex26.xml",
        "thesis/ex28a.xml",
        "thesis/ex29a.xml",
        "thesis/ex30.xml",
    ];

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(300))]

        /// any order of the behaviours in a block gives the same times.
        #[test]
        fn permuting_behaviours_gives_identical_times(file in proptest::sample::select(FILES), seed in any::<u64>()) {
            let original = bml::load(&fixture(file)).unwrap().block;
            let mut shuffled = original.clone();
            let mut r = seed | 1;
            for i in (1..shuffled.behaviours.len()).rev() {
                r ^= r << 13; r ^= r >> 7; r ^= r << 17;
                shuffled.behaviours.swap(i, (r % (i as u64 + 1)) as usize);
            }
            let models = DefaultTimingModels::syllable_timed();
            let a = Optimal.schedule(&original, &models, &NoExternal).unwrap();
            let b = Optimal.schedule(&shuffled, &models, &NoExternal).unwrap();
            for beh in &a.behaviours {
                prop_assert_eq!(Some(beh), b.behaviour(&beh.id), "{}", file);
            }
        }
    }
}

#[test]
fn persistent_controller_has_no_end_unless_a_constraint_names_it() {
    let s = schedule(&block(
        r#"<bmlt:controller xmlns:bmlt="http://hmi.ewi.utwente.nl/bmlt" id="c" class="Balance" start="1"/>"#,
    ));
    assert!(close(at(&s, "c", "start"), 1.0));
    assert_eq!(at(&s, "c", "end"), f64::INFINITY);
    let s = schedule(&block(
        r#"<bmlt:controller xmlns:bmlt="http://hmi.ewi.utwente.nl/bmlt" id="c" class="Balance" start="1" end="4"/>"#,
    ));
    assert!(close(at(&s, "c", "end"), 4.0));
    // naming the end from another behaviour gives the controller an end to synchronise to
    let s = schedule(&block(
        r#"<bmlt:controller xmlns:bmlt="http://hmi.ewi.utwente.nl/bmlt" id="c" class="Balance" start="1"/><gesture id="g" lexeme="BEAT" start="c:end"/>"#,
    ));
    assert!(s.dropped.is_empty());
    assert!(close(at(&s, "g", "start"), at(&s, "c", "end")) && at(&s, "c", "end").is_finite());
}

/// A persistent behaviour has no length of its own to keep: tied to another behaviour's end, it
/// lasts as long as that one, which keeps its own timing (it was squeezed to the controller's
/// nominal second before).
#[test]
fn a_persistent_controller_tied_to_a_gesture_does_not_squeeze_it() {
    let alone = schedule(&block(r#"<gesture id="g" lexeme="BEAT" start="0.5"/>"#));
    let length = at(&alone, "g", "end") - at(&alone, "g", "start");
    for (start, end) in [("0", "g:end"), ("g:start", "g:end"), ("0", "g:relax")] {
        let s = schedule(&block(&format!(
            r#"<gesture id="g" lexeme="BEAT" start="0.5"/><bmlt:controller xmlns:bmlt="http://hmi.ewi.utwente.nl/bmlt" id="c" class="Balance" start="{start}" end="{end}"/>"#
        )));
        assert!(s.dropped.is_empty(), "{:?}", s.dropped);
        let got = at(&s, "g", "end") - at(&s, "g", "start");
        assert!(
            close(got, length),
            "{start}..{end}: the gesture lasts {got}, not {length}"
        );
        assert!(close(at(&s, "g", "start"), 0.5));
    }
}

#[test]
fn an_invalid_engine_timing_model_drops_the_behaviour_instead_of_panicking() {
    use bml_realizer::planning::timing::{TimingModel, TimingModels};
    struct Broken;
    impl TimingModels for Broken {
        fn model(&self, b: &bml::Behaviour) -> Option<TimingModel> {
            let mut m = DefaultTimingModels::syllable_timed().model(b)?;
            if b.id == "g1" {
                m.keys.clear();
            }
            Some(m)
        }
    }
    let b = bml::load(&block(
        r#"<gesture id="g1" lexeme="BEAT"/><head id="h1" lexeme="NOD"/>"#,
    ))
    .unwrap()
    .block;
    let s = Optimal.schedule(&b, &Broken, &NoExternal).unwrap();
    assert_eq!(s.dropped.len(), 1);
    assert_eq!(
        (s.dropped[0].behaviour.as_str(), s.dropped[0].warning),
        ("g1", KnownWarning::InvalidTiming)
    );
    assert!(s.time("h1", "end").is_some());
}
