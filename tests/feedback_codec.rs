//! Feedback decoding rejects malformed lines with a reason, and never accepts a line that it could
//! not write back (regressions found by the `feedback` fuzz target).

use bml_realizer::language::feedback::*;

fn err(line: &str) -> String {
    from_line(line).expect_err("line should be rejected").0
}

const NS: &str = r#"xmlns="http://www.bml-initiative.org/bml/bml-1.0""#;

#[test]
fn malformed_xml_lines_are_rejected_with_a_reason() {
    assert!(err("").contains("no feedback element"));
    assert!(err("<blockProgress").contains("not well-formed"));
    assert!(err(&format!(r#"<blockProgress {NS} globalTime="1"/>"#)).contains("no id"));
    assert!(
        err(&format!(r#"<blockProgress {NS} id="b1" globalTime="1"/>"#)).contains("block:sync")
    );
    assert!(err(&format!(
        r#"<blockProgress {NS} id="b1:start" globalTime="soon"/>"#
    ))
    .contains("not a number"));
    assert!(err(&format!(
        r#"<syncPointProgress {NS} id="b1:g1" time="0" globalTime="1"/>"#
    ))
    .contains("block:behaviour:sync"));
    // four parts only for a later stroke of a repeated head
    assert!(err(&format!(
        r#"<syncPointProgress {NS} id="b1:g1:start:2" time="0" globalTime="1"/>"#
    ))
    .contains("block:behaviour:stroke:N"));
    let line =
        format!(r#"<syncPointProgress {NS} id="b1:h1:stroke:2" time="1.300" globalTime="1.300"/>"#);
    let Ok(Feedback::SyncPointProgress(p)) = from_line(&line) else {
        panic!("{line} not read");
    };
    assert_eq!(
        (p.block.as_str(), p.behaviour.as_str(), p.sync.as_str()),
        ("b1", "h1", "stroke:2")
    );
    assert_eq!(to_xml(&Feedback::SyncPointProgress(p)), line);
    assert!(err(&format!(
        r#"<blockProgress {NS} xmlns:bmla="http://www.asap-project.org/bmla" id="b:end" globalTime="1" bmla:status="FINE"/>"#
    ))
    .contains("unknown bmla:status"));
    assert!(
        err(r#"<blockProgress xmlns="urn:other" id="b:start" globalTime="1"/>"#)
            .contains("namespace")
    );
    assert!(err(&format!(r#"<applause {NS}/>"#)).contains("unknown feedback element"));
}

#[test]
fn names_that_cannot_be_written_back_are_rejected() {
    // found by fuzzing: a JSON key `s'tart` became an XML attribute name that does not parse
    let json = r#"{"feedback":"predictionFeedback","behaviors":[{"feedback":"gesture","id":"b:g","s'tart":0}]}"#;
    assert!(err(json).contains("not an XML name"));
    // and a sync named xmlns would become a namespace declaration
    let json = r#"{"feedback":"predictionFeedback","behaviors":[{"feedback":"gesture","id":"b:g","xmlns":0}]}"#;
    assert!(err(json).contains("not an XML name"));
    let line = format!(
        r#"<predictionFeedback {NS}><gesture id="b:g" st*art="0.000"/></predictionFeedback>"#
    );
    let e = err(&line);
    assert!(e.contains("not an XML name"), "{e}");
    assert!(err(r#"{"feedback":"predictionFeedback","behaviors":[{"feedback":"gesture","id":"b:g","st art":1}]}"#).contains("not an XML name"));
    assert!(err(
        r#"{"feedback":"predictionFeedback","behaviors":[{"feedback":"bml","id":"b:g"}]}"#
    )
    .contains("'bml'"));
}

#[test]
fn malformed_json_lines_are_rejected_with_a_reason() {
    assert!(err("{").contains("not JSON"));
    let e = err("[1]");
    assert!(e.contains("feedback element"), "{e}");
    assert!(err(r#"{"id":"b:start"}"#).contains("\"feedback\""));
    assert!(err(r#"{"feedback":"blockProgress","id":"b:start"}"#).contains("globalTime"));
    assert!(err(
        r#"{"feedback":"blockProgress","id":"b:start","globalTime":1,"bmla:posixTime":-5}"#
    )
    .contains("posixTime"));
    // a wrong value deep inside names its place
    let e = err(
        r#"{"feedback":"predictionFeedback","bml":[{"feedback":"bml","id":"b","globalStart":"x"}]}"#,
    );
    assert!(e.contains("bml[0].globalStart: invalid type"), "{e}");
    let e = err(
        r#"{"feedback":"predictionFeedback","behaviors":[{"feedback":"gesture","id":"b:g","stroke":"soon"}]}"#,
    );
    assert!(e.contains("behaviors[0]") && e.contains("soon"), "{e}");
    assert!(err(r#"{"feedback":"applause"}"#).contains("unknown feedback \"applause\""));
}

#[test]
fn both_formats_decode_to_the_same_message() {
    let xml = format!(
        r#"<syncPointProgress {NS} id="bml1:g1:stroke" time="0.850" globalTime="12.346"/>"#
    );
    let json =
        r#"{"feedback":"syncPointProgress","id":"bml1:g1:stroke","time":0.85,"globalTime":12.346}"#;
    let a = from_line(&xml).unwrap();
    assert_eq!(a, from_line(json).unwrap());
    let Feedback::SyncPointProgress(s) = a else {
        panic!()
    };
    assert_eq!(
        (
            s.block.as_str(),
            s.behaviour.as_str(),
            s.sync.as_str(),
            s.time
        ),
        ("bml1", "g1", "stroke", 0.85)
    );
}

#[test]
fn millisecond_rounding_is_idempotent_even_for_huge_times() {
    // found by fuzzing: 5.5555555555555555e75 changed on every round
    for t in [5.555_555_555_555_555_5e75, 1e12, 123.4567, -0.0005, 1e-300] {
        assert_eq!(round_ms(round_ms(t)), round_ms(t), "{t}");
    }
    assert_eq!(round_ms(1.2344), 1.234);
    assert_eq!(round_ms(2.0004), 2.0);
}

#[test]
fn json_times_read_back_exactly() {
    // found by fuzzing: without serde_json's float_roundtrip 3e50 read back as 3.0000000000000002e50
    let xml = format!(r#"<blockProgress {NS} id="bml1:end" globalTime="3.e50"/>"#);
    let fb = from_line(&xml).unwrap();
    assert_eq!(from_json(&to_json(&fb)).unwrap(), fb);
}

#[test]
fn a_peer_s_prediction_keeps_its_behaviours_attributes() {
    // as AsapRealizer and BML 1.0 write it: the behaviours inside the block's <bml>, ids
    // unqualified, with their attributes beside the predicted times
    let xml = r#"<predictionFeedback xmlns="http://www.bml-initiative.org/bml/bml-1.0" characterId="Armandia"><bml id="bml1" globalStart="1.0" globalEnd="3.0"><gesture id="g1" lexeme="BEAT" mode="RIGHT_HAND" repetition="2" start="1.0" stroke="1.5" end="2.2"/><gaze id="z1" target="person1" influence="HEAD" start="1.0" end="3.0"/><speech id="s1" start="1" end="2.5"><text>Hello <sync id="tm1"/></text></speech></bml></predictionFeedback>"#;
    let Feedback::Prediction(p) = from_line(xml).unwrap() else {
        panic!("a prediction");
    };
    assert_eq!(p.blocks.len(), 1);
    assert_eq!(p.behaviours.len(), 3);
    let g = &p.behaviours[0];
    assert_eq!((g.block.as_str(), g.behaviour.as_str()), ("bml1", "g1"));
    let attrs: Vec<(&str, &str)> = (g.attributes.iter())
        .map(|(a, b)| (a.as_str(), b.as_str()))
        .collect();
    assert_eq!(
        attrs,
        [
            ("lexeme", "BEAT"),
            ("mode", "RIGHT_HAND"),
            ("repetition", "2")
        ]
    );
    let syncs: Vec<&str> = g.syncs.iter().map(|s| s.0.as_str()).collect();
    assert_eq!(syncs, ["start", "stroke", "end"]);
    assert_eq!(
        p.behaviours[1].attributes[0],
        ("target".into(), "person1".into())
    );
    // (and written back, the attributes go with it)
    let back = from_line(&Format::Xml.encode(&Feedback::Prediction(p.clone()))).unwrap();
    assert_eq!(back, Feedback::Prediction(p));
    // a standard sync point that is not a time is still an error
    let bad = xml.replace(r#"stroke="1.5""#, r#"stroke="soon""#);
    assert!(from_line(&bad).is_err());
}
