//! The unit tests of `timing`.

use super::*;
use crate::language::bml;

fn behaviours(body: &str) -> Vec<Behaviour> {
    let src = format!(
        r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" xmlns:bmla="http://www.asap-project.org/bmla" xmlns:bmlt="http://hmi.ewi.utwente.nl/bmlt" id="b">{body}</bml>"#
    );
    bml::load(&src).unwrap().block.behaviours
}

fn keys(m: &TimingModel) -> Vec<(&str, f64)> {
    m.keys
        .iter()
        .map(|k| (k.name.as_ref(), (k.at * 1e9).round() / 1e9))
        .collect()
}

#[test]
fn timing_models_admit_only_ordered_times_within_their_bounds() {
    let syncs = |v: &[(&'static str, f64)]| -> Vec<(crate::language::bml::Id, f64)> {
        v.iter()
            .map(|&(n, t)| (crate::language::bml::Id::new_static(n), t))
            .collect()
    };
    let mut m = TimingModel::stretchable(&[("start", 0.0), ("stroke", 0.5), ("end", 1.0)]);
    assert!(m
        .admits(&syncs(&[("start", 1.0), ("stroke", 1.2), ("end", 3.0)]))
        .is_ok());
    let err = m.admits(&syncs(&[("start", 1.0), ("stroke", 0.9), ("end", 3.0)]));
    assert_eq!(err.unwrap_err(), "'stroke' comes before 'start'");
    m.flexibility = Flexibility::Stretchable {
        min_duration: 0.5,
        max_duration: 2.0,
    };
    assert!(m
        .admits(&syncs(&[("start", 0.0), ("stroke", 0.1), ("end", 0.4)]))
        .is_err());
    assert!(m
        .admits(&syncs(&[("start", 0.0), ("stroke", 0.1), ("end", 2.5)]))
        .is_err());
    assert!(m
        .admits(&syncs(&[("start", 0.0), ("stroke", 0.1), ("end", 2.0)]))
        .is_ok());
    let rigid = TimingModel::new(&[("start", 0.0), ("end", 1.0)], Flexibility::Rigid);
    assert!(rigid
        .admits(&syncs(&[("start", 3.0), ("end", 4.0)]))
        .is_ok());
    assert!(rigid
        .admits(&syncs(&[("start", 3.0), ("end", 4.5)]))
        .is_err());
}

#[test]
fn speech_is_rigid_with_syncs_at_the_start_of_the_next_word() {
    // RealizerTester core/testspeech2.xml
    let b = behaviours(
        r#"<speech id="s"><text>Hey punk <sync id="syncstart1" />what do ya want?</text></speech>"#,
    );
    let m = DefaultTimingModels::default().model(&b[0]).unwrap();
    let BehaviourKind::Speech(speech) = &b[0].kind else {
        unreachable!()
    };
    use crate::character::voice::Tts;
    let u = crate::character::voice::builtin::Builtin
        .speak(&speech.text)
        .unwrap();
    assert_eq!(u.words[2].text, "what");
    let k = keys(&m);
    assert_eq!(
        (k[0], k[1].0, k[2].0),
        (("start", 0.0), "syncstart1", "end")
    );
    assert!((k[1].1 - u.words[2].start).abs() < 1e-9 && (k[2].1 - u.end).abs() < 1e-9);
    assert!(u.words[1].end <= u.words[2].start);
    assert_eq!(m.flexibility, Flexibility::Rigid);
    m.check().unwrap();
}

#[test]
fn syncs_at_the_edges_of_the_text_coincide_with_start_and_end() {
    let b =
        behaviours(r#"<speech id="s"><text><sync id="a"/>One two<sync id="z"/></text></speech>"#);
    let m = DefaultTimingModels::default().model(&b[0]).unwrap();
    let k = keys(&m);
    assert_eq!(k[0..2], [("start", 0.0), ("a", 0.0)]);
    assert_eq!(k[2].1, k[3].1, "z at the end");
    let b = behaviours(r#"<speech id="s"><text/></speech>"#);
    assert_eq!(
        DefaultTimingModels::default()
            .model(&b[0])
            .unwrap()
            .preferred_duration(),
        crate::character::voice::builtin::EMPTY
    );
}

#[test]
fn speech_rate_is_configurable() {
    let b = behaviours(r#"<speech id="s"><text>one two three</text></speech>"#);
    let normal = DefaultTimingModels::default().model(&b[0]).unwrap();
    let slow = DefaultTimingModels {
        speech: SpeechTiming {
            rate: 0.5,
            ..Default::default()
        },
    };
    let slow = slow.model(&b[0]).unwrap();
    assert!((slow.preferred_duration() - 2.0 * normal.preferred_duration()).abs() < 1e-12);
}

#[test]
fn a_repeated_head_has_a_stroke_each_nod_s_cycle_apart() {
    let b = behaviours(r#"<head id="h" lexeme="NOD" repetition="3"/>"#);
    let m = DefaultTimingModels::default().model(&b[0]).unwrap();
    m.check().unwrap();
    let keys: Vec<(&str, f64)> = m.keys.iter().map(|k| (k.name.as_str(), k.at)).collect();
    let want = [
        ("start", 0.0),
        ("ready", 0.1),
        ("strokeStart", 0.15),
        ("stroke", 0.3),
        ("stroke:1", 0.8),
        ("stroke:2", 1.3),
        ("strokeEnd", 1.45),
        ("relax", 1.5),
        ("end", 1.6),
    ];
    assert_eq!(keys.len(), want.len());
    for ((name, at), (w, wat)) in keys.iter().zip(want) {
        assert_eq!(*name, w);
        assert!((at - wat).abs() < 1e-12, "{name} at {at}, not {wat}");
    }
    // preparation and retraction limited as one nod's
    assert_eq!(m.keys[1].max_phase, 1.0);
    assert_eq!(m.keys[8].max_phase, 1.0);
}

#[test]
fn a_span_stretched_to_a_minimum_moves_the_later_keys() {
    // the gesture: ready 0.3, strokeStart 0.4, stroke 0.5, ..., end 1.0; ready limited to 1 s
    let m = limited(GESTURE, 1.0);
    let longer = m.clone().with_span_at_least("start", "strokeStart", 1.6);
    let at = |m: &TimingModel, k: &str| m.keys[m.key(k).unwrap()].at;
    assert!((at(&longer, "ready") - 1.2).abs() < 1e-12);
    assert!((at(&longer, "strokeStart") - 1.6).abs() < 1e-12);
    assert!((at(&longer, "stroke") - 1.7).abs() < 1e-12);
    assert!((at(&longer, "end") - 2.2).abs() < 1e-12);
    // the preparation's limit grew with it, so the model is still valid
    assert_eq!(longer.keys[longer.key("ready").unwrap()].max_phase, 1.2);
    longer.check().unwrap();
    // long enough already, reversed or unknown: unchanged
    for same in [
        m.clone().with_span_at_least("start", "ready", 0.2),
        m.clone().with_span_at_least("stroke", "ready", 5.0),
        m.clone().with_span_at_least("start", "nope", 5.0),
    ] {
        assert_eq!(same.keys, m.keys);
    }
}

#[test]
fn every_kind_has_a_valid_model_whose_keys_match_its_sync_points() {
    let all = behaviours(concat!(
        r#"<speech id="a"><text>Hi <sync id="w"/>there</text></speech><gesture id="b" lexeme="BEAT"/><pointing id="c" target="t"/>"#,
        r#"<head id="d" lexeme="NOD"/><headDirectionShift id="e" target="t"/><gaze id="f" target="t"/><gazeShift id="g" target="t"/>"#,
        r#"<face id="h" lexeme="SMILE"/><faceLexeme id="i" lexeme="RAISE_BROWS"/><faceFacs id="j" au="1"/><faceShift id="k" lexeme="OPEN_MOUTH"/>"#,
        r#"<posture id="l"><stance type="STANDING"/></posture><postureShift id="m"><stance type="SITTING"/></postureShift>"#,
        r#"<locomotion id="n" target="t"/><wait id="o" max-wait="2.5"/><bmla:interrupt id="p" target="x"/><bmla:activate id="q" target="x"/>"#,
        r#"<bmla:parametervaluechange id="r" target="a" paramId="volume"><bmla:trajectory type="linear" targetValue="1"/></bmla:parametervaluechange>"#,
        r#"<bmlt:procanimation id="s" name="n"/><bmlt:procanimationgesture id="t" name="n"/><bmlt:keyframe id="u" name="n"/>"#,
        r#"<bmlt:controller id="v" class="C"/><bmlt:audiofile id="w" fileName="f.wav"/><bmlt:noise id="x" joint="j" type="perlin"/>"#,
        r#"<bmlt:facemorph id="y" targetname="m"/><bmlt:transition id="z" class="SlerpTransition"/><bmlt:text id="zz"><bmlt:text>a b</bmlt:text></bmlt:text>"#,
    ));
    assert_eq!(all.len(), 27);
    let models = DefaultTimingModels::default();
    for b in &all {
        let m = models
            .model(b)
            .unwrap_or_else(|| panic!("no model for {}", b.id));
        m.check().unwrap_or_else(|e| panic!("{}: {e}", b.id));
        let names: Vec<&str> = m.keys.iter().map(|k| k.name.as_ref()).collect();
        assert_eq!(names, b.sync_points(), "{}", b.id);
    }
    let wait = models.model(&all[14]).unwrap();
    assert_eq!(wait.preferred_duration(), 2.5);
    assert!(
        models.model(&all[21]).unwrap().persistent,
        "controller persists"
    );
}

#[test]
fn unknown_extensions_have_no_model() {
    let b = behaviours(r#"<x:dance xmlns:x="urn:x" id="d"/>"#);
    assert_eq!(DefaultTimingModels::default().model(&b[0]), None);
}

#[test]
fn check_rejects_broken_models() {
    let bad = |keys: &[(&'static str, f64)]| TimingModel::stretchable(keys).check().unwrap_err();
    assert!(bad(&[]).contains("at least"));
    assert!(bad(&[("ready", 0.0), ("end", 1.0)]).contains("first key"));
    assert!(bad(&[("start", 0.0), ("end", 0.0)]).contains("last key"));
    assert!(bad(&[
        ("start", 0.0),
        ("stroke", 0.8),
        ("ready", 0.5),
        ("end", 1.0)
    ])
    .contains("comes before"));
    assert!(bad(&[("start", 0.0), ("a", 0.2), ("a", 0.3), ("end", 1.0)]).contains("twice"));
    // a repeat far from the first
    const MANY: [&str; 20] = [
        "start", "k1", "k2", "k3", "k4", "k5", "k6", "k7", "k8", "k9", "k10", "k11", "k12", "k13",
        "k14", "k15", "k16", "k17", "k3", "end",
    ];
    let keys: Vec<(&'static str, f64)> = MANY
        .iter()
        .enumerate()
        .map(|(i, &n)| (n, i as f64))
        .collect();
    assert!(bad(&keys).contains("key k3 appears twice"));
    let mut unique = keys.clone();
    unique[18].0 = "k18";
    TimingModel::stretchable(&unique).check().unwrap();
}
