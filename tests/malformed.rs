//! Malformed BML: each problem gets its own diagnostic code at the right line:column, and no input
//! makes the parser panic.

use bml_realizer::language::bml::{self, Code, Severity};
use proptest::prelude::*;

const NS: &str = r#"xmlns="http://www.bml-initiative.org/bml/bml-1.0""#;

/// The errors of `src` as (code, line, col).
fn errors(src: &str) -> Vec<(Code, u32, u32)> {
    let err = bml::load(src).expect_err("input should be rejected");
    err.errors()
        .map(|d| (d.code, d.pos.line, d.pos.col))
        .collect()
}

fn block(body: &str) -> String {
    format!("<bml {NS} id=\"b1\">\n{body}\n</bml>")
}

#[test]
fn not_xml() {
    assert_eq!(errors("this is not xml")[0].0, Code::NotXml);
    let e = bml::load(&block("  <speech id=\"s1\"><text>hi</speech>")).unwrap_err();
    let d = e.first();
    assert_eq!(d.code, Code::NotXml);
    assert_eq!(d.pos.line, 2, "{d}");
    assert_eq!(errors("")[0].0, Code::NotXml);
}

#[test]
fn wrong_root() {
    assert_eq!(
        errors("<?xml version=\"1.0\"?>\n<foo id=\"x\"/>"),
        [(Code::WrongRoot, 2, 1)]
    );
    let e = bml::load(r#"<bml xmlns="urn:other" id="x"/>"#).unwrap_err();
    assert_eq!(e.first().code, Code::WrongRoot);
    assert!(e.first().message.contains("urn:other"));
}

#[test]
fn missing_block_id() {
    let e = bml::load(&format!("<bml {NS}/>")).unwrap_err();
    assert_eq!(e.first().code, Code::MissingBlockId);
    assert!(e.first().message.contains("no id"), "{}", e.first().message);
    assert_eq!(
        errors(&format!("<bml {NS} id=\" \"/>")),
        [(Code::MissingBlockId, 1, 56)]
    );
}

#[test]
fn duplicate_behaviour_id() {
    let src = block("  <gesture id=\"g1\" lexeme=\"BEAT\"/>\n  <head id=\"g1\" lexeme=\"NOD\"/>");
    assert_eq!(errors(&src), [(Code::DuplicateId, 3, 3)]);
    let e = bml::load(&src).unwrap_err();
    assert!(
        e.first().message.contains("already used at 2:3"),
        "{}",
        e.first().message
    );
}

#[test]
fn reference_to_unknown_behaviour() {
    let src = block("  <gesture id=\"g1\" lexeme=\"BEAT\" start=\"speech9:start\"/>");
    assert_eq!(errors(&src), [(Code::UnknownBehaviour, 2, 34)]);
}

#[test]
fn unknown_sync_point() {
    let src = block(
        "  <speech id=\"speech1\"><text>Hi <sync id=\"s1\"/>there</text></speech>\n  <head id=\"h\" lexeme=\"NOD\" start=\"speech1:unknown\"/>",
    );
    assert_eq!(errors(&src), [(Code::UnknownSyncPoint, 3, 29)]);
    let msg = bml::load(&src).unwrap_err().first().message.clone();
    assert!(msg.contains("start, s1, end"), "{msg}");
    // a sync that exists on one kind but not another
    let src = block(
        "  <gaze id=\"g\" target=\"x\"/>\n  <head id=\"h\" lexeme=\"NOD\" start=\"g:stroke\"/>",
    );
    assert_eq!(errors(&src)[0].0, Code::UnknownSyncPoint);
}

#[test]
fn malformed_offset() {
    let src = block("  <gesture id=\"s1\" lexeme=\"BEAT\"/>\n  <head id=\"h\" lexeme=\"NOD\" start=\"s1:start+abc\"/>");
    assert_eq!(errors(&src), [(Code::MalformedOffset, 3, 29)]);
}

#[test]
fn empty_sync_ref() {
    let src = block("  <head id=\"h\" lexeme=\"NOD\" start=\"\"/>");
    assert_eq!(errors(&src), [(Code::EmptySyncRef, 2, 29)]);
    let src = block("  <head id=\"h\" lexeme=\"NOD\"/>\n  <constraint><synchronize ref=\"h:start\"><sync ref=\" \"/></synchronize></constraint>");
    assert_eq!(errors(&src), [(Code::EmptySyncRef, 3, 48)]);
}

#[test]
fn unknown_composition() {
    assert_eq!(
        errors(&format!("<bml {NS} id=\"b\" composition=\"SOMETIMES\"/>")),
        [(Code::UnknownComposition, 1, 63)]
    );
    assert_eq!(
        errors(&format!(
            "<bml {NS} id=\"b\" composition=\"APPEND-AFTER()\"/>"
        ))[0]
            .0,
        Code::UnknownComposition
    );
}

#[test]
fn other_specific_errors() {
    let code = |body: &str| errors(&block(body))[0].0;
    assert_eq!(code("<gesture lexeme=\"BEAT\"/>"), Code::MissingId);
    assert_eq!(code("<gesture id=\"g\"/>"), Code::MissingAttribute);
    assert_eq!(
        code("<gesture id=\"g\" lexeme=\"BEAT\" mode=\"LEFT\"/>"),
        Code::InvalidEnumValue
    );
    assert_eq!(
        code("<gaze id=\"g\" target=\"t\" influence=\"KNEES\"/>"),
        Code::InvalidEnumValue
    );
    assert_eq!(
        code("<head id=\"h\" lexeme=\"NOD\" repetition=\"two\"/>"),
        Code::InvalidNumber
    );
    assert_eq!(
        code("<head id=\"h\" lexeme=\"NOD\" colour=\"red\"/>"),
        Code::UnknownAttribute
    );
    assert_eq!(code("<dance id=\"d\"/>"), Code::UnknownElement);
    assert_eq!(code("<speech id=\"s\"/>"), Code::MissingElement);
    assert_eq!(code("hello"), Code::UnexpectedText);
    assert_eq!(
        code("<head id=\"h\" lexeme=\"NOD\" start=\"-1\"/>"),
        Code::InvalidConstraint
    );
    assert_eq!(code("<constraint><synchronize><sync ref=\"1\"/><sync ref=\"2\"/></synchronize></constraint>"), Code::InvalidConstraint);
    assert_eq!(code("<constraint/>"), Code::InvalidConstraint);
    assert_eq!(
        code("<head id=\"h\" lexeme=\"NOD\" start=\"a:b:c:d\"/>"),
        Code::MalformedSyncRef
    );
    assert_eq!(code("<head id=\"h:1\" lexeme=\"NOD\"/>"), Code::InvalidId);
}

#[test]
fn reserved_and_forbidden_xml_is_rejected() {
    // found by the fuzzer: an element with the reserved prefix xmlns
    let src = block("  <xmlns:x id=\"i1\"/>");
    assert_eq!(errors(&src), [(Code::NotXml, 2, 3)]);
    let src = block("  <bmlt:/audiofile xmlns:bmlt=\"urn:t\" id=\"a\"/>");
    assert_eq!(errors(&src), [(Code::NotXml, 2, 3)]);
    // found by the fuzzer: a character reference to a control character
    let src = block("  <speech id=\"s\"><text>bell &#7;</text></speech>");
    assert_eq!(errors(&src), [(Code::NotXml, 2, 29)]);
    let src = block("  <speech id=\"s\" xmlns:x=\"urn:x\" x:a=\"&#x1;\"><text>hi</text></speech>");
    assert_eq!(errors(&src)[0].0, Code::NotXml);
    let src = block("  <speech id=\"s\"><text>bell \u{7}</text></speech>");
    let e = bml::load(&src).unwrap_err();
    assert_eq!(e.first().code, Code::NotXml);
    assert!(
        e.first().message.contains("U+0007"),
        "{}",
        e.first().message
    );
}

#[test]
fn byte_order_mark_does_not_shift_positions_or_raw_content() {
    let src = format!("\u{feff}{}", block("  <bmlt:keyframe xmlns:bmlt=\"http://hmi.ewi.utwente.nl/bmlt\" id=\"k\"><Frame t=\"0\"/></bmlt:keyframe>\n  <head id=\"h\" lexeme=\"NOD\" start=\"x:start\"/>"));
    let (block, diags) = bml::check(&src);
    let bml::BehaviourKind::Keyframe(k) = &block.unwrap().behaviours[0].kind else {
        panic!()
    };
    assert_eq!(k.content, "<Frame t=\"0\"/>");
    assert_eq!(
        (diags[0].code, diags[0].pos.line, diags[0].pos.col),
        (Code::UnknownBehaviour, 3, 29)
    );
}

#[test]
fn duplicate_attributes_are_not_xml_even_through_different_prefixes() {
    assert_eq!(
        errors(&block("  <head id=\"h\" lexeme=\"NOD\" lexeme=\"SHAKE\"/>")),
        [(Code::NotXml, 2, 29)]
    );
    let src = block(
        "  <head id=\"h\" lexeme=\"NOD\" xmlns:a=\"urn:x\" xmlns:b=\"urn:x\" a:k=\"1\" b:k=\"2\"/>",
    );
    assert_eq!(errors(&src)[0].0, Code::NotXml);
    let src = block("  <head id=\"h\" lexeme=\"NOD\" xmlns:a=\"urn:x\" xmlns:a=\"urn:y\"/>");
    assert_eq!(errors(&src)[0].0, Code::NotXml);
}

#[test]
fn xml_lang_survives_a_write_parse_round_trip() {
    let src = block("  <speech id=\"s\" xml:lang=\"nl\"><text>Hallo</text></speech>");
    let b = bml::parse(&src).unwrap().block;
    assert_eq!(b.behaviours[0].foreign_attrs[0].value, "nl");
    assert_eq!(bml::parse(&bml::write(&b)).unwrap().block, b);
}

#[test]
fn a_sync_may_follow_only_one_anticipator_sync() {
    let src = block(
        "  <head id=\"h\" lexeme=\"NOD\" start=\"anticipators:a:x\"/>\n  <constraint><synchronize ref=\"anticipators:b:y\"><sync ref=\"h:start\"/></synchronize></constraint>",
    );
    let e = bml::load(&src).unwrap_err();
    assert_eq!(e.first().code, Code::InvalidConstraint);
    assert!(
        e.first().message.contains("only one anticipator"),
        "{}",
        e.first().message
    );
    // the same anticipator sync twice, or two different syncs of the behaviour, are fine
    let ok = block(
        "  <head id=\"h\" lexeme=\"NOD\" start=\"anticipators:a:x\" end=\"anticipators:b:y\"/>",
    );
    assert!(bml::load(&ok).is_ok());
}

#[test]
fn every_error_is_reported_not_just_the_first() {
    let src = block("  <gesture id=\"g1\"/>\n  <head id=\"h\" lexeme=\"NOD\" start=\"x:start+abc\" mode=\"?\"/>");
    let codes: Vec<Code> = errors(&src).into_iter().map(|e| e.0).collect();
    assert_eq!(
        codes,
        [
            Code::MissingAttribute,
            Code::MalformedOffset,
            Code::UnknownAttribute
        ]
    );
}

#[test]
fn unknown_extensions_are_warnings_and_kept() {
    let src = block(
        "  <x:dance xmlns:x=\"urn:dance\" id=\"d1\" start=\"1\" x:style=\"tango\"><x:step/></x:dance>\n  <head id=\"h\" lexeme=\"NOD\" x:tilt=\"3\" xmlns:x=\"urn:dance\"/>",
    );
    let parsed = bml::load(&src).expect("only warnings");
    assert!(parsed
        .warnings
        .iter()
        .all(|w| w.severity == Severity::Warning));
    let codes: Vec<Code> = parsed.warnings.iter().map(|w| w.code).collect();
    assert_eq!(
        codes,
        [Code::UnsupportedExtension, Code::UnsupportedAttribute]
    );
    let d = parsed.block.behaviour("d1").unwrap();
    match &d.kind {
        bml::BehaviourKind::Unknown(u) => {
            assert_eq!(u.ns, "urn:dance");
            assert_eq!(u.name, "dance");
            assert_eq!(u.attrs[0].name, "style");
            assert_eq!(u.content, "<x:step/>");
        }
        k => panic!("{k:?}"),
    }
    assert_eq!(d.syncs[0].sync, "start");
    assert_eq!(
        parsed.block.behaviour("h").unwrap().foreign_attrs[0].value,
        "3"
    );
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(2000))]

    /// Arbitrary text never panics the parser and always yields a diagnostic or a block.
    #[test]
    fn arbitrary_text_never_panics(s in "\\PC{0,200}") {
        let (block, diags) = bml::check(&s);
        prop_assert!(block.is_some() || diags.iter().any(|d| d.severity == Severity::Error));
    }

    /// Cutting or corrupting a real block anywhere never panics.
    #[test]
    fn corrupted_fixture_never_panics(cut in 0usize..2000, byte in 0u8..128, at in 0usize..2000) {
        let src = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/fixtures/realizertester/bml-1/core/testspeechgestures.xml")).unwrap();
        let mut bytes = src.into_bytes();
        bytes.truncate(cut.min(bytes.len()));
        if !bytes.is_empty() {
            let i = at % bytes.len();
            bytes[i] = byte;
        }
        let text = String::from_utf8_lossy(&bytes);
        let _ = bml::check(&text);
    }
}

/// White space between elements is passed over (also when written as a character reference),
/// text that is not blank is reported once where it starts (also when a reference splits it), and
/// a speech's text keeps its own white space, around inline syncs too.
#[test]
fn blank_text_between_elements_is_skipped_and_speech_text_is_kept() {
    let blank = "\n\t<!-- c -->\n<bml xmlns=\"http://www.bml-initiative.org/bml/bml-1.0\" id=\"b\">\n\t&#32;\t<head id=\"h\" lexeme=\"NOD\"/>&#x20;\n</bml>\n";
    let parsed = bml::load(blank).expect("blank text between elements is fine");
    assert!(parsed.warnings.is_empty(), "{:?}", parsed.warnings);
    assert_eq!(parsed.block.behaviours.len(), 1);
    let split = block("<head id=\"h\" lexeme=\"NOD\"/>\n  a&#32;b <wait id=\"w\"/>");
    // `a` is on line 3 (the block's second body line), after the two spaces that open it
    assert_eq!(errors(&split), vec![(Code::UnexpectedText, 3, 3)]);
    let speech = block(
        "<speech id=\"s\">\n<text> Hey punk <sync id=\"x\"/> <sync id=\"y\"/>what? </text>\n</speech>",
    );
    let parsed = bml::load(&speech).unwrap().block;
    let bml::BehaviourKind::Speech(s) = &parsed.behaviours[0].kind else {
        panic!("a speech");
    };
    assert_eq!(
        s.text,
        vec![
            bml::TextPart::Text(" Hey punk ".into()),
            bml::TextPart::Sync("x".into()),
            bml::TextPart::Text(" ".into()),
            bml::TextPart::Sync("y".into()),
            bml::TextPart::Text("what? ".into()),
        ]
    );
}

/// Found by the fuzzer: kept content that declares a prefix inside itself does not need (or
/// record) the prefix from outside, so writing the block, which declares that prefix on its
/// root, changes nothing.
#[test]
fn a_prefix_declared_inside_kept_content_survives_a_round_trip() {
    let src = block(
        "  <x:thing xmlns:x=\"urn:x\" id=\"t\"><bmlt:a xmlns:bmlt=\"http://hmi.ewi.utwente.nl/bmlt\"/></x:thing>",
    );
    let b = bml::parse(&src).unwrap().block;
    assert_eq!(bml::parse(&bml::write(&b)).unwrap().block, b);
}

/// Found by the fuzzer: a carriage return in speech text (written `&#13;`) and line breaks in an
/// attribute value survive a write → parse round trip (a reader turns raw ones into a line feed
/// and spaces).
#[test]
fn carriage_returns_and_line_breaks_in_values_survive_a_round_trip() {
    let src = block(
        "  <speech id=\"s\"><text>one&#13;two</text></speech>\n  <gesture id=\"g\" lexeme=\"A&#10;B&#9;C&#13;D\"/>",
    );
    let b = bml::parse(&src).unwrap().block;
    assert_eq!(bml::parse(&bml::write(&b)).unwrap().block, b);
}

/// What XML allows but the reader refuses, each with an error that says why rather than a
/// wrong reading.
#[test]
fn a_namespace_name_with_a_reference_and_a_quoted_doctype_gt_are_refused_clearly() {
    let src = block(r#"  <head id="h" lexeme="NOD" xmlns:p="urn:a&amp;b" p:x="1"/>"#);
    let e = bml::load(&src).unwrap_err();
    assert_eq!(e.first().code, Code::NotXml);
    assert!(
        e.first().message.contains("holds a reference"),
        "{}",
        e.first().message
    );
    let src = format!(
        "<!DOCTYPE bml [<!ENTITY gt2 \">\">]>\n{}",
        block("  <head id=\"h\" lexeme=\"NOD\"/>")
    );
    let e = bml::load(&src).unwrap_err();
    assert_eq!((e.first().code, e.first().pos.line), (Code::NotXml, 1));
    assert!(
        e.first().message.contains("not supported"),
        "{}",
        e.first().message
    );
}

/// Found by the fuzzer with the quick-xml reader: a namespace name with a raw line break was
/// accepted, written back as a character reference, and then refused. A namespace name is a URI
/// reference, which holds no white space: it is refused when read.
#[test]
fn a_namespace_name_with_white_space_is_refused_when_read() {
    let src = format!("<bml {NS} xmlns:b=\"http://x\n/bmla\" id=\"b2\" b:interrupt=\"b1\"/>");
    let e = bml::load(&src).unwrap_err();
    assert_eq!(e.first().code, Code::NotXml);
    assert!(
        e.first().message.contains("U+000A"),
        "{}",
        e.first().message
    );
    // a namespace name with characters a URI may hold goes through a write unchanged
    let src = format!("<bml {NS} xmlns:b=\"urn:a'b(c)\" id=\"b2\" b:x=\"1\"/>");
    let block = bml::load(&src).unwrap().block;
    assert!(
        bml::write(&block).contains("=\"urn:a'b(c)\""),
        "{}",
        bml::write(&block)
    );
}
