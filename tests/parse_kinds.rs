//! Parse tests for every behaviour kind and extension: every attribute value is asserted.

use bml_realizer::language::bml::*;

const HEAD: &str = r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0"
     xmlns:bmla="http://www.asap-project.org/bmla" xmlns:bmlt="http://hmi.ewi.utwente.nl/bmlt"
     xmlns:ce="http://www.bml-initiative.org/bml/coreextensions-1.0""#;

fn one(body: &str) -> Behaviour {
    let src = format!("{HEAD} id=\"b\">{body}</bml>");
    let parsed = parse(&src).unwrap_or_else(|e| panic!("{e}\n{src}"));
    assert_eq!(parsed.block.behaviours.len(), 1);
    parsed.block.behaviours.into_iter().next().unwrap()
}

fn sync(b: &Behaviour, name: &str) -> String {
    b.syncs
        .iter()
        .find(|s| s.sync == name)
        .map(|s| s.value.to_string())
        .unwrap_or_default()
}

#[test]
fn block_attributes_core_and_both_extension_namespaces() {
    let src = format!(
        "{HEAD} id=\"b7\" characterId=\"anna\" composition=\"append-after(b1, b2)\" bmla:preplan=\"true\" bmla:onStart=\"p1,p2\" bmlt:interrupt=\"old\" bmla:appendAfter=\"a1\" bmla:chunkAfter=\"c1\" bmlt:chunkBefore=\"c2\" bmla:prependBefore=\"p3\" bmlt:allowexternalrefs=\"TRUE\"/>"
    );
    let b = parse(&src).unwrap().block;
    assert_eq!(b.id, "b7");
    assert_eq!(b.character_id.as_deref(), Some("anna"));
    assert_eq!(
        b.composition,
        Composition::AppendAfter(vec!["b1".into(), "b2".into()])
    );
    assert!(b.ext.preplan);
    assert_eq!(b.ext.on_start, ["p1", "p2"]);
    assert_eq!(b.ext.interrupt, ["old"]);
    assert_eq!(b.ext.append_after, ["a1"]);
    assert_eq!(b.ext.chunk_after, ["c1"]);
    assert_eq!(b.ext.chunk_before, ["c2"]);
    assert_eq!(b.ext.prepend_before, ["p3"]);
    assert!(b.ext.allow_external_refs);
    assert!(b.behaviours.is_empty());
}

#[test]
fn composition_values_are_case_insensitive_and_scheduling_is_an_alias() {
    for (text, want) in [
        ("MERGE", Composition::Merge),
        ("append", Composition::Append),
        ("Replace", Composition::Replace),
        (
            "APPEND-AFTER(x)",
            Composition::AppendAfter(vec!["x".into()]),
        ),
    ] {
        let b = parse(&format!("{HEAD} id=\"b\" composition=\"{text}\"/>"))
            .unwrap()
            .block;
        assert_eq!(b.composition, want, "{text}");
    }
    let b = parse(&format!("{HEAD} id=\"b\" scheduling=\"replace\"/>"))
        .unwrap()
        .block;
    assert_eq!(b.composition, Composition::Replace);
    let b = parse(&format!("{HEAD} id=\"b\"/>")).unwrap().block;
    assert_eq!(b.composition, Composition::Merge);
}

#[test]
fn speech_with_inline_syncs_and_description() {
    let b = one(
        r#"<speech id="s1" start="2" end="s1:start+5"><text>Hey punk <sync id="s"/>what &amp; <sync id="t"/>do?</text><description priority="3" type="audio/x-wav"><file name="a.wav"/></description></speech>"#,
    );
    assert_eq!(b.id, "s1");
    let BehaviourKind::Speech(s) = &b.kind else {
        panic!()
    };
    assert_eq!(
        s.text,
        [
            TextPart::Text("Hey punk ".into()),
            TextPart::Sync("s".into()),
            TextPart::Text("what & ".into()),
            TextPart::Sync("t".into()),
            TextPart::Text("do?".into()),
        ]
    );
    assert_eq!(s.plain_text(), "Hey punk what & do?");
    assert_eq!(b.sync_points(), ["start", "s", "t", "end"]);
    assert_eq!(sync(&b, "start"), "2");
    assert_eq!(sync(&b, "end"), "s1:start+5");
    assert_eq!(b.descriptions.len(), 1);
    assert_eq!(b.descriptions[0].priority, Some(3));
    assert_eq!(b.descriptions[0].kind, "audio/x-wav");
    assert_eq!(b.descriptions[0].content, r#"<file name="a.wav"/>"#);
}

#[test]
fn gesture_and_pointing() {
    let b = one(
        r#"<gesture id="g" lexeme="BEAT" mode="BOTH_HANDS" start="1" ready="2" strokeStart="3" stroke="4" strokeEnd="5" relax="6" end="7"/>"#,
    );
    assert_eq!(
        b.kind,
        BehaviourKind::Gesture(Gesture {
            lexeme: "BEAT".into(),
            mode: Some(Mode::BothHands)
        })
    );
    let names: Vec<&str> = b.syncs.iter().map(|s| s.sync).collect();
    assert_eq!(names, GESTURE_SYNCS);
    assert_eq!(sync(&b, "strokeEnd"), "5");
    let b = one(r#"<pointing id="p" target="bluebox" mode="LEFT_HAND"/>"#);
    assert_eq!(
        b.kind,
        BehaviourKind::Pointing(Pointing {
            target: "bluebox".into(),
            mode: Some(Mode::LeftHand)
        })
    );
    assert_eq!(b.sync_points(), GESTURE_SYNCS);
}

#[test]
fn head_and_head_direction_shift() {
    let b = one(r#"<head id="h" lexeme="SHAKE" repetition="3" amount="0.7" stroke="1"/>"#);
    assert_eq!(
        b.kind,
        BehaviourKind::Head(Head {
            lexeme: "SHAKE".into(),
            repetition: Some(3),
            amount: Some(0.7)
        })
    );
    assert_eq!(sync(&b, "stroke"), "1");
    let b = one(r#"<headDirectionShift id="h" target="door" start="0.5"/>"#);
    assert_eq!(
        b.kind,
        BehaviourKind::HeadDirectionShift {
            target: "door".into()
        }
    );
    assert_eq!(b.sync_points(), START_END);
}

#[test]
fn gaze_and_gaze_shift() {
    let want = Gaze {
        target: "bluebox".into(),
        influence: Some(Influence::Waist),
        offset_angle: Some(15.0),
        offset_direction: Some(OffsetDirection::UpLeft),
    };
    let b = one(
        r#"<gaze id="g" target="bluebox" influence="WAIST" offsetAngle="15" offsetDirection="UPLEFT" ready="1" relax="2"/>"#,
    );
    assert_eq!(b.kind, BehaviourKind::Gaze(want.clone()));
    assert_eq!(b.sync_points(), GAZE_SYNCS);
    assert_eq!(sync(&b, "relax"), "2");
    let b = one(
        r#"<gazeShift id="g" target="bluebox" influence="WAIST" offsetAngle="15" offsetDirection="UPLEFT"/>"#,
    );
    assert_eq!(b.kind, BehaviourKind::GazeShift(want));
    assert_eq!(b.sync_points(), START_END);
}

#[test]
fn face_kinds() {
    let b = one(r#"<face id="f" au="12" side="LEFT" amount="0.4" attackPeak="1"/>"#);
    assert_eq!(
        b.kind,
        BehaviourKind::Face(Face {
            lexeme: None,
            au: Some(12),
            side: Some(Side::Left),
            amount: Some(0.4)
        })
    );
    assert_eq!(sync(&b, "attackPeak"), "1");
    let b = one(r#"<faceLexeme id="f" lexeme="RAISE_BROWS" amount="1"/>"#);
    assert_eq!(
        b.kind,
        BehaviourKind::FaceLexeme(FaceLexeme {
            lexeme: "RAISE_BROWS".into(),
            amount: Some(1.0)
        })
    );
    assert_eq!(b.sync_points(), FACE_SYNCS);
    let b = one(r#"<faceFacs id="f" au="1" side="BOTH" amount="0.5"/>"#);
    assert_eq!(
        b.kind,
        BehaviourKind::FaceFacs(FaceFacs {
            au: 1,
            side: Some(Side::Both),
            amount: Some(0.5)
        })
    );
    let b = one(r#"<ce:faceFacs id="f" au="6"/>"#);
    assert_eq!(
        b.kind,
        BehaviourKind::FaceFacs(FaceFacs {
            au: 6,
            side: None,
            amount: None
        })
    );
    let b = one(r#"<faceShift id="f" lexeme="OPEN_MOUTH" amount="0.2"/>"#);
    assert_eq!(
        b.kind,
        BehaviourKind::FaceShift(FaceLexeme {
            lexeme: "OPEN_MOUTH".into(),
            amount: Some(0.2)
        })
    );
    assert_eq!(b.sync_points(), START_END);
}

#[test]
fn posture_and_posture_shift() {
    let want = Posture {
        stance: StanceType::Sitting,
        poses: vec![
            Pose {
                part: PosePart::Arms,
                lexeme: "ARMS_CROSSED".into(),
            },
            Pose {
                part: PosePart::LeftLeg,
                lexeme: "LEGS_CROSSED".into(),
            },
        ],
    };
    let b = one(
        r#"<posture id="p" start="1"><stance type="SITTING"/><pose part="ARMS" lexeme="ARMS_CROSSED"/><pose part="LEFT_LEG" lexeme="LEGS_CROSSED"/></posture>"#,
    );
    assert_eq!(b.kind, BehaviourKind::Posture(want.clone()));
    assert_eq!(b.sync_points(), GAZE_SYNCS);
    let b = one(
        r#"<postureShift id="p" start="5" end="8"><stance type="SITTING"/><pose part="ARMS" lexeme="ARMS_CROSSED"/><pose part="LEFT_LEG" lexeme="LEGS_CROSSED"/></postureShift>"#,
    );
    assert_eq!(b.kind, BehaviourKind::PostureShift(want));
    assert_eq!(
        (sync(&b, "start"), sync(&b, "end")),
        ("5".into(), "8".into())
    );
}

#[test]
fn locomotion_and_wait() {
    let b = one(r#"<locomotion id="w" target="painting1" manner="RUN" end="10"/>"#);
    assert_eq!(
        b.kind,
        BehaviourKind::Locomotion(Locomotion {
            target: "painting1".into(),
            manner: Some("RUN".into())
        })
    );
    assert_eq!(b.sync_points(), GAZE_SYNCS);
    let b = one(r#"<wait id="w" max-wait="2.5" start="1"/>"#);
    assert_eq!(
        b.kind,
        BehaviourKind::Wait(Wait {
            max_wait: Some(2.5)
        })
    );
}

#[test]
fn control_behaviours_in_both_namespaces() {
    for ns in ["bmla", "bmlt"] {
        let b = one(&format!(
            r#"<{ns}:interrupt id="i" target="bml1" include="s1, s2" exclude="g1" start="2"/>"#
        ));
        assert_eq!(
            b.kind,
            BehaviourKind::Interrupt(Interrupt {
                target: "bml1".into(),
                include: vec!["s1".into(), "s2".into()],
                exclude: vec!["g1".into()]
            })
        );
        assert_eq!(sync(&b, "start"), "2");
        let b = one(&format!(
            r#"<{ns}:activate id="a" target="bml3" start="1"/>"#
        ));
        assert_eq!(
            b.kind,
            BehaviourKind::Activate(Activate {
                target: "bml3".into()
            })
        );
        let b = one(&format!(
            r#"<{ns}:parametervaluechange id="pvc" target="b:speech1" paramId="volume" start="1" end="3"><{ns}:trajectory type="linear" initialValue="0" targetValue="100"/></{ns}:parametervaluechange>"#
        ));
        assert_eq!(
            b.kind,
            BehaviourKind::ParameterValueChange(ParameterValueChange {
                target_block: Some("b".into()),
                target_behaviour: "speech1".into(),
                param_id: "volume".into(),
                trajectory: Trajectory {
                    kind: TrajectoryType::Linear,
                    initial_value: Some(0.0),
                    target_value: 100.0
                },
            })
        );
        assert_eq!(
            (sync(&b, "start"), sync(&b, "end")),
            ("1".into(), "3".into())
        );
    }
}

#[test]
fn bmlt_behaviours() {
    let b = one(
        r#"<bmlt:procanimation id="p" name="squat" fileName="squat.xml" start="2"><bmlt:parameter name="mirror" value="true"/><bmlt:parameter name="joints" value="l_shoulder l_elbow"/></bmlt:procanimation>"#,
    );
    assert_eq!(
        b.kind,
        BehaviourKind::ProcAnimation(Animation {
            name: Some("squat".into()),
            file_name: Some("squat.xml".into()),
            params: vec![
                Param {
                    name: "mirror".into(),
                    value: "true".into()
                },
                Param {
                    name: "joints".into(),
                    value: "l_shoulder l_elbow".into()
                }
            ],
            content: String::new(),
            namespaces: vec![],
        })
    );
    assert!(
        b.has_sync("squatdown"),
        "procanimation sync points are defined by the animation"
    );
    let b = one(r#"<bmlt:procanimationgesture id="p" fileName="wave.xml" stroke="1"/>"#);
    assert_eq!(
        b.kind,
        BehaviourKind::ProcAnimationGesture(Animation {
            file_name: Some("wave.xml".into()),
            ..Default::default()
        })
    );
    assert_eq!(b.kind.standard_syncs(), GESTURE_SYNCS);
    let b = one(
        r#"<bmlt:keyframe id="k" name="wave_r"><SkeletonInterpolator rotationEncoding="quaternions">0 1 0 0 0</SkeletonInterpolator></bmlt:keyframe>"#,
    );
    assert_eq!(
        b.kind,
        BehaviourKind::Keyframe(Animation {
            name: Some("wave_r".into()),
            content: r#"<SkeletonInterpolator rotationEncoding="quaternions">0 1 0 0 0</SkeletonInterpolator>"#.into(),
            ..Default::default()
        })
    );
    let b = one(
        r#"<bmlt:controller id="c" class="BalanceController" name="bal" start="0" end="10"><bmlt:parameter name="pelvisheight" value="0.95"/></bmlt:controller>"#,
    );
    assert_eq!(
        b.kind,
        BehaviourKind::Controller(Controller {
            class: "BalanceController".into(),
            name: Some("bal".into()),
            params: vec![Param {
                name: "pelvisheight".into(),
                value: "0.95".into()
            }]
        })
    );
    let b = one(r#"<bmlt:audiofile id="a" fileName="audio/clap.wav" start="1"/>"#);
    assert_eq!(
        b.kind,
        BehaviourKind::AudioFile {
            file_name: "audio/clap.wav".into()
        }
    );
    assert_eq!(b.sync_points(), START_END);
    let b = one(
        r#"<bmlt:noise id="n" joint="skullbase" type="perlin"><bmlt:parameter name="basefreqx" value="1"/></bmlt:noise>"#,
    );
    assert_eq!(
        b.kind,
        BehaviourKind::Noise(Noise {
            joint: "skullbase".into(),
            kind: "perlin".into(),
            params: vec![Param {
                name: "basefreqx".into(),
                value: "1".into()
            }]
        })
    );
    let b = one(r#"<bmlt:facemorph id="f" targetname="smile" intensity="0.8" attackPeak="1"/>"#);
    assert_eq!(
        b.kind,
        BehaviourKind::FaceMorph(FaceMorph {
            target_name: "smile".into(),
            intensity: Some(0.8)
        })
    );
    assert_eq!(b.sync_points(), FACE_SYNCS);
    let b = one(
        r#"<bmlt:transition id="t" class="SlerpTransition" start="0" end="1"><bmlt:parameter name="joints" value="skullbase vc4"/></bmlt:transition>"#,
    );
    assert_eq!(
        b.kind,
        BehaviourKind::Transition(Transition {
            class: "SlerpTransition".into(),
            params: vec![Param {
                name: "joints".into(),
                value: "skullbase vc4".into()
            }]
        })
    );
    let b =
        one(r#"<bmlt:text id="t"><bmlt:text>Hello <sync id="w"/>world</bmlt:text></bmlt:text>"#);
    assert_eq!(
        b.kind,
        BehaviourKind::Text(Speech {
            text: vec![
                TextPart::Text("Hello ".into()),
                TextPart::Sync("w".into()),
                TextPart::Text("world".into())
            ]
        })
    );
    assert_eq!(b.sync_points(), ["start", "w", "end"]);
}

#[test]
fn required_element_flags_behaviours_and_constraints() {
    let src = format!(
        "{HEAD} id=\"b\"><gesture id=\"g0\" lexeme=\"BEAT\"/><required><gesture id=\"g1\" lexeme=\"BEAT\"/><constraint id=\"c\"><synchronize ref=\"g0:start\"><sync ref=\"g1:start\"/></synchronize></constraint></required><gesture id=\"g2\" lexeme=\"BEAT\"/></bml>"
    );
    let b = load(&src).unwrap().block;
    let req: Vec<(&str, bool)> = b
        .behaviours
        .iter()
        .map(|b| (b.id.as_str(), b.required))
        .collect();
    assert_eq!(req, [("g0", false), ("g1", true), ("g2", false)]);
    assert!(b.constraints[0].required);
    assert_eq!(b.constraints[0].id.as_deref(), Some("c"));
}

#[test]
fn realizertester_fixture_details() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/fixtures/realizertester/bml-1");
    let read = |p: &str| std::fs::read_to_string(format!("{dir}/{p}")).unwrap();
    // `<speech id = "welkom">`: whitespace around '='
    let b = load(&read("core/testspeechgestures.xml")).unwrap().block;
    assert_eq!(b.behaviours[0].id, "welkom");
    assert_eq!(
        b.behaviours[0].sync_points(),
        ["start", "deicticheart1", "beat1b1", "end"]
    );
    let b = load(&read("core/testgaze.xml")).unwrap().block;
    let BehaviourKind::Gaze(g) = &b.behaviours[0].kind else {
        panic!()
    };
    assert_eq!(
        (g.target.as_str(), g.influence),
        ("bluebox", Some(Influence::Neck))
    );
    let p = load(&read("asap/preplan/testnod.xml")).unwrap().block;
    assert_eq!(
        (p.ext.interrupt.as_slice(), p.ext.on_start.as_slice()),
        (&["bml1".to_string()][..], &["bml2".to_string()][..])
    );
    let m = load(&read("murml/murmlbodykeyframe.xml")).unwrap();
    assert_eq!(m.warnings.len(), 1);
    assert_eq!(m.warnings[0].code, Code::UnsupportedExtension);
    let BehaviourKind::Unknown(u) = &m.block.behaviours[0].kind else {
        panic!()
    };
    assert_eq!(u.name, "murmlgesture");
    assert!(u
        .content
        .contains("<posture>Humanoid (l_shoulder 3 100 0 0)</posture>"));
}
