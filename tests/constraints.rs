//! Constraint extraction: the exact normalised constraint set of the thesis' BML examples 24–30
//! (translated to BML 1.0 in fixtures/thesis) and of RealizerTester files.

use bml_realizer::language::bml::{self, Anchor, Relation, Source, SyncPoint};

fn fixture(path: &str) -> String {
    std::fs::read_to_string(format!("{}/fixtures/{path}", env!("CARGO_MANIFEST_DIR"))).unwrap()
}

/// The constraints of a fixture, rendered `left REL right ± offset`, in extraction order.
fn constraints(path: &str) -> Vec<String> {
    let parsed = bml::load(&fixture(path)).unwrap_or_else(|e| panic!("{path}: {e}"));
    bml::extract(&parsed.block)
        .iter()
        .map(|c| c.to_string())
        .collect()
}

fn sorted(mut v: Vec<String>) -> Vec<String> {
    v.sort();
    v
}

#[test]
fn example_24_relative_ready_with_offset() {
    assert_eq!(
        constraints("thesis/ex24.xml"),
        ["g1:ready = beh1:start + 1"]
    );
}

#[test]
fn example_25_ungrounded_cluster() {
    assert_eq!(
        constraints("thesis/ex25.xml"),
        ["g1:stroke = speech1:world"]
    );
}

#[test]
fn example_26_absolute_and_relative_after() {
    assert_eq!(
        constraints("thesis/ex26.xml"),
        [
            "point1:stroke = speech1:s1",
            "point1:start >= walk1:end",
            "speech1:start >= @block + 2",
        ]
    );
}

#[test]
fn example_27_both_orders_give_the_same_set() {
    let a = constraints("thesis/ex27a.xml");
    assert_eq!(
        a,
        ["nod1:start = speech1:start", "nod1:end = speech1:sync1"]
    );
    assert_eq!(sorted(a), sorted(constraints("thesis/ex27b.xml")));
}

#[test]
fn example_28_absolute_nod_and_beat_on_its_stroke() {
    let a = constraints("thesis/ex28a.xml");
    assert_eq!(
        a,
        [
            "nod1:start = @block + 3",
            "nod1:end = @block + 5",
            "beat1:stroke = nod1:stroke",
        ]
    );
    assert_eq!(sorted(a), sorted(constraints("thesis/ex28b.xml")));
}

#[test]
fn example_29_cycle_with_offsets() {
    let a = constraints("thesis/ex29a.xml");
    assert_eq!(
        a,
        [
            "g2:start = g1:end",
            "nod1:start = g1:start - 2",
            "nod1:end = g2:end + 3",
        ]
    );
    assert_eq!(sorted(a), sorted(constraints("thesis/ex29b.xml")));
}

#[test]
fn example_30_time_pegs() {
    assert_eq!(
        constraints("thesis/ex30.xml"),
        [
            "point1:start = walk1:end",
            "point1:stroke = speech1:s1 + 0.5",
            "nod1:stroke = speech1:s1",
        ]
    );
}

#[test]
fn realizertester_speech_gestures() {
    assert_eq!(
        constraints("realizertester/bml-1/core/testspeechgestures.xml"),
        [
            "g1:start = welkom:deicticheart1",
            "g1:end = welkom:deicticheart1 + 2",
            "relaxleft:start = g1:end + 0.5",
            "relaxleft:end = g1:end + 2.8",
            "transleft:start = g1:start - 2",
            "transleft:end = g1:start",
        ]
    );
}

#[test]
fn realizertester_synchronize_with_number_is_absolute() {
    assert_eq!(
        constraints("realizertester/bml-1/core/testspeechandnod_synctimed.xml"),
        ["nod1:start = speech1:start", "speech1:s1 = @block + 10"]
    );
}

#[test]
fn realizertester_external_reference_keeps_its_block() {
    let parsed = bml::load(&fixture(
        "realizertester/bml-1/asap/interruptbehavior/testspeechinterrupt.xml",
    ))
    .unwrap();
    let cs = bml::extract(&parsed.block);
    assert_eq!(cs.len(), 2);
    assert_eq!(cs[0].to_string(), "i2:start = bml1:speech1:s1");
    assert_eq!(
        cs[1].right,
        Anchor::Point(SyncPoint::External {
            block: "bml1".into(),
            behaviour: "speech1".into(),
            sync: "s1".into()
        })
    );
}

#[test]
fn constraint_records_kind_source_position_and_required() {
    let src = r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="b">
  <gaze id="gaze1" target="X"/>
  <speech id="speech1"><text>Hi</text></speech>
  <required>
    <head id="nod1" lexeme="NOD" start="2"/>
    <constraint id="c1">
      <before ref="speech1:start"><sync ref="gaze1:ready"/></before>
    </constraint>
  </required>
  <constraint id="c2">
    <before ref="speech1:end"><sync ref="3"/></before>
    <after ref="anticipators:stop:stop+1"><sync ref="speech1:end-0.5"/></after>
    <synchronize><sync ref="gaze1:start"/><sync ref="speech1:start"/><sync ref="nod1:end+1"/></synchronize>
  </constraint>
</bml>"#;
    let parsed = bml::load(src).unwrap();
    let cs = bml::extract(&parsed.block);
    let text: Vec<String> = cs.iter().map(|c| c.to_string()).collect();
    assert_eq!(
        text,
        [
            "nod1:start = @block + 2",
            "gaze1:ready <= speech1:start",
            // 3 <= speech1:end is normalised with the behaviour on the left
            "speech1:end >= @block + 3",
            "speech1:end >= anticipators:stop:stop + 1.5",
            "speech1:start = gaze1:start",
            "nod1:end = gaze1:start - 1",
        ]
    );
    assert!(cs[0].required, "attribute of a behaviour inside <required>");
    assert!(cs[1].required, "constraint inside <required>");
    assert!(cs[2..].iter().all(|c| !c.required));
    assert_eq!(cs[1].relation, Relation::Before);
    assert_eq!(cs[2].relation, Relation::After);
    assert_eq!(
        cs[0].source,
        Source::Attribute {
            behaviour: 2, // nod1
            sync: "start"
        }
    );
    assert_eq!(
        cs[1].source,
        Source::Element {
            constraint: Some("c1".into())
        }
    );
    assert_eq!((cs[0].pos.line, cs[0].pos.col), (5, 34));
    assert_eq!((cs[1].pos.line, cs[1].pos.col), (7, 35));
}
