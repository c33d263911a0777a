//! The unit tests of `gesture`.

use super::pace::{wrist_rate, MIN_JERK_PEAK};
use super::*;
use crate::language::bml::Mode;
use glam::Vec3;

/// A lexeme whose keys barely move the hand keeps the default timing; one that raises the
/// arm gets a preparation as long as the hand needs at [`HAND_SPEED`], and a wrist swing as
/// long as the joint needs at [`JOINT_SPEED`].
#[test]
fn a_lexeme_is_paced_by_how_far_its_keys_move_the_hand() {
    let lib = Library::default_library();
    let engine = |json: &str| GestureEngine::new(Lexicon::from_json(json, &lib).unwrap());
    let gesture = |lexeme: &str| {
        let src = format!(
            r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="b"><gesture id="g" lexeme="{lexeme}"/></bml>"#
        );
        crate::language::bml::load(&src)
            .unwrap()
            .block
            .behaviours
            .remove(0)
    };
    let at = |m: &TimingModel, k: &str| m.keys[m.key(k).unwrap()].at;
    let still =
        engine(r#"{"gestures": [{"lexeme": "X", "keys": {"stroke": {"r_wrist": [0, 0, 1]}}}]}"#);
    let m = still.timing(&gesture("X")).unwrap();
    assert_eq!(
        m.keys,
        DefaultTimingModels::default()
            .model(&gesture("X"))
            .unwrap()
            .keys
    );
    // the arm forward and up: the wrist sweeps an arc of the arm's length (0.55 m) through
    // 90°, about 0.86 m per unit of the slerp at its fastest
    let up = engine(
        r#"{"gestures": [{"lexeme": "X", "keys": {"ready": {"r_shoulder": [0, -90, 0]}, "strokeStart": {"r_shoulder": [0, -90, 0], "r_wrist": [0, 0, 60]}}}]}"#,
    );
    let m = up.timing(&gesture("X")).unwrap();
    let rate = wrist_rate(&Skeleton::adult(), &[], &up.lexicon.keys("X").unwrap()[0].1);
    assert!((0.7..1.0).contains(&rate), "{rate}");
    assert!((at(&m, "ready") - MIN_JERK_PEAK * rate / HAND_SPEED).abs() < 1e-9);
    // 60° at the wrist between ready and strokeStart
    let swing = MIN_JERK_PEAK * 60f64.to_radians() / JOINT_SPEED;
    assert!((at(&m, "strokeStart") - at(&m, "ready") - swing).abs() < 1e-6);
    m.check().unwrap();
}

#[test]
fn the_default_lexicon_has_the_gestures_the_issue_names() {
    let l = Lexicon::default_lexicon();
    for lexeme in ["BEAT", "WAVE", "CONDUIT", "CUP", "POINT"] {
        assert!(l.keys(lexeme).is_some(), "{lexeme}");
    }
    let lib = Library::default_library();
    let bad = |j: &str| Lexicon::from_json(j, &lib).unwrap_err();
    assert!(
        bad(r#"{"gestures": [{"lexeme": "X", "keys": {"stroke": {"r_elbow": [1, 2]}}}]}"#)
            .starts_with("gestures[0].keys.stroke.r_elbow: invalid length 2")
    );
    assert!(bad(r#"{"gestures": [{"lexeme": "X", "kyes": {}}]}"#)
        .starts_with("gestures[0].kyes: unknown field"));
    assert!(
        bad(r#"{"gestures": [{"lexeme": "X", "procedural": "nope"}]}"#)
            .contains("no procedural unit 'nope'")
    );
    assert!(bad(
        r#"{"gestures": [{"lexeme": "X", "procedural": "wave", "parameters": {"speed": 2}}]}"#
    )
    .contains("no parameter 'speed'"));
    assert!(bad(r#"{"gestures": [{"lexeme": "X"}]}"#).contains("either"));
    assert!(matches!(
        l.find(&gesture("HELLO", None)),
        Some(Bound::Procedural(..))
    ));
}

fn gesture(lexeme: &str, mode: Option<Mode>) -> Behaviour {
    crate::language::bml::load(&format!(
        r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" xmlns:x="urn:x" id="b"><gesture id="g" lexeme="{lexeme}"{}{}/></bml>"#,
        mode.map_or(String::new(), |m| format!(r#" mode="{}""#, m.as_str())),
        if lexeme == "STYLED" { r#" x:style="big""# } else { "" }
    ))
    .unwrap()
    .block
    .behaviours
    .remove(0)
}

#[test]
fn bindings_pick_by_lexeme_and_attribute_filter_in_file_order() {
    let l = Lexicon::from_json(
        r#"{"gestures": [
            {"lexeme": "B", "when": {"mode": "LEFT_HAND"}, "procedural": "lift"},
            {"lexeme": "B", "keys": {"stroke": {"r_elbow": [0, 0, 10]}}},
            {"lexeme": "STYLED", "when": {"style": "big"}, "procedural": "wave", "parameters": {"cycles": 5}},
            {"lexeme": "STYLED", "procedural": "wave"}
        ]}"#,
        &Library::default_library(),
    )
    .unwrap();
    assert!(matches!(
        l.find(&gesture("B", Some(Mode::LeftHand))),
        Some(Bound::Procedural(u, _)) if u.name == "lift"
    ));
    assert!(matches!(l.find(&gesture("B", None)), Some(Bound::Keys(_))));
    assert!(matches!(
        l.find(&gesture("B", Some(Mode::RightHand))),
        Some(Bound::Keys(_))
    ));
    match l.find(&gesture("STYLED", None)) {
        Some(Bound::Procedural(u, p)) => {
            assert_eq!(u.name, "wave");
            assert!(p.contains(&("cycles".to_string(), 5.0)));
        }
        other => panic!("{other:?}"),
    }
    assert!(l.find(&gesture("NONE", None)).is_none());
    assert!(l.filters_on("style") && !l.filters_on("lexeme"));
}

#[test]
fn mirroring_reflects_the_motion_across_the_middle_plane() {
    let q = Quat::from_euler(EulerRot::ZXY, 0.4, 0.3, -0.5);
    let (name, m) = mirror("r_shoulder", q);
    assert_eq!(name, "l_shoulder");
    // a reflected vector rotated by the mirror = the reflection of the rotated vector
    let reflect = |v: Vec3| Vec3::new(-v.x, v.y, v.z);
    for v in [Vec3::X, Vec3::Y, Vec3::new(0.3, -0.2, 0.9)] {
        assert!((m * reflect(v) - reflect(q * v)).length() < 1e-5);
    }
}
