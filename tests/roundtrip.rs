//! Round trips: `parse(write(block)) == block` for generated BML models, and
//! `decode(encode(fb)) == fb` for generated feedback in both codecs (≥ 1000 cases each).

use bml_realizer::language::bml::*;
use bml_realizer::language::feedback::*;
use proptest::collection::vec;
use proptest::option;
use proptest::prelude::*;

fn id() -> impl Strategy<Value = String> {
    "[a-z][a-z0-9_]{0,6}"
}
fn ids() -> impl Strategy<Value = Vec<String>> {
    vec(id(), 0..3)
}
/// Printable text including the XML specials.
fn text() -> impl Strategy<Value = String> {
    "[a-zA-Z0-9 ,.!?&<>'\"=/-]{1,12}"
}
/// A number of seconds within the parser's default time limit (10^6 s either way).
fn num() -> impl Strategy<Value = f64> {
    prop_oneof![
        (-100_000i64..100_000).prop_map(|k| k as f64 / 1000.0),
        -1e6f64..1e6
    ]
}
fn foreign() -> impl Strategy<Value = Vec<ForeignAttr>> {
    vec(
        (
            prop_oneof![Just("urn:x"), Just("urn:y")],
            "[a-z]{1,5}",
            text(),
        ),
        0..3,
    )
    .prop_map(|v| {
        let mut out: Vec<ForeignAttr> = Vec::new();
        for (ns, name, value) in v {
            if !out.iter().any(|a| a.ns == ns && a.name == name) {
                out.push(ForeignAttr {
                    ns: ns.into(),
                    name,
                    value,
                });
            }
        }
        out
    })
}

/// An id as the model stores it.
fn sid() -> impl Strategy<Value = bml_realizer::language::bml::Id> {
    id().prop_map(Into::into)
}

fn sync_ref() -> impl Strategy<Value = SyncRef> {
    let point = prop_oneof![
        (sid(), sid()).prop_map(|(b, s)| SyncPoint::Local {
            behaviour: b,
            sync: s
        }),
        (sid(), sid(), sid()).prop_map(|(k, b, s)| SyncPoint::External {
            block: k,
            behaviour: b,
            sync: s
        }),
        (sid(), sid()).prop_map(|(a, s)| SyncPoint::Anticipator {
            anticipator: a,
            sync: s
        }),
    ];
    prop_oneof![
        num().prop_map(SyncRef::Time),
        (point, num()).prop_map(|(point, offset)| SyncRef::Point { point, offset }),
    ]
}

fn speech() -> impl Strategy<Value = Speech> {
    vec(
        prop_oneof![
            text().prop_map(TextPart::Text),
            sid().prop_map(TextPart::Sync)
        ],
        0..5,
    )
    .prop_map(|parts| {
        // the parser merges adjacent text: generate the merged form
        let mut text: Vec<TextPart> = Vec::new();
        for p in parts {
            match (text.last_mut(), p) {
                (Some(TextPart::Text(t)), TextPart::Text(n)) => t.push_str(&n),
                (_, p) => text.push(p),
            }
        }
        Speech { text }
    })
}

/// Raw XML content with the namespace bindings it relies on.
fn raw_content() -> impl Strategy<Value = (&'static str, Vec<(String, String)>)> {
    prop_oneof![
        Just(("", vec![])),
        Just(("<step/>", vec![])),
        Just(("a &amp; b", vec![])),
        Just((
            "<q:speak q:rate=\"1\">Hi</q:speak>",
            vec![("q".to_string(), "urn:q".to_string())]
        )),
        Just((
            "<bmlt:procanimation id=\"x\" name=\"n\"/>",
            vec![("bmlt".to_string(), NS_BMLT.to_string())]
        )),
    ]
}

fn params() -> impl Strategy<Value = Vec<Param>> {
    vec(
        (text(), text()).prop_map(|(name, value)| Param { name, value }),
        0..3,
    )
}

fn pick<T: Copy + std::fmt::Debug + 'static>(all: &'static [T]) -> impl Strategy<Value = T> {
    proptest::sample::select(all)
}

fn kind() -> impl Strategy<Value = BehaviourKind> {
    let gaze = || {
        (
            text(),
            option::of(pick(Influence::ALL)),
            option::of(num()),
            option::of(pick(OffsetDirection::ALL)),
        )
            .prop_map(|(target, influence, offset_angle, offset_direction)| Gaze {
                target,
                influence,
                offset_angle,
                offset_direction,
            })
    };
    let posture = || {
        (
            pick(StanceType::ALL),
            vec(
                (pick(PosePart::ALL), text()).prop_map(|(part, lexeme)| Pose { part, lexeme }),
                0..3,
            ),
        )
            .prop_map(|(stance, poses)| Posture { stance, poses })
    };
    let anim = || {
        (
            option::of(text()),
            option::of(text()),
            params(),
            prop_oneof![
                Just(String::new()),
                Just("<SkeletonInterpolator>0 1</SkeletonInterpolator>".to_string())
            ],
        )
            .prop_map(|(name, file_name, params, content)| Animation {
                name,
                file_name,
                params,
                content,
                namespaces: vec![],
            })
    };
    prop_oneof![
        speech().prop_map(BehaviourKind::Speech),
        speech().prop_map(BehaviourKind::Text),
        (text(), option::of(pick(Mode::ALL)))
            .prop_map(|(lexeme, mode)| BehaviourKind::Gesture(Gesture { lexeme, mode })),
        (text(), option::of(pick(Mode::ALL)))
            .prop_map(|(target, mode)| BehaviourKind::Pointing(Pointing { target, mode })),
        (text(), option::of(0..=MAX_REPETITION), option::of(num())).prop_map(
            |(lexeme, repetition, amount)| BehaviourKind::Head(Head {
                lexeme,
                repetition,
                amount
            })
        ),
        text().prop_map(|target| BehaviourKind::HeadDirectionShift { target }),
        gaze().prop_map(BehaviourKind::Gaze),
        gaze().prop_map(BehaviourKind::GazeShift),
        (
            option::of(text()),
            any::<u32>(),
            option::of(pick(Side::ALL)),
            option::of(num())
        )
            .prop_map(|(lexeme, au, side, amount)| BehaviourKind::Face(Face {
                au: if lexeme.is_none() { Some(au) } else { None },
                lexeme,
                side,
                amount
            })),
        (text(), option::of(num()))
            .prop_map(|(lexeme, amount)| BehaviourKind::FaceLexeme(FaceLexeme { lexeme, amount })),
        (text(), option::of(num()))
            .prop_map(|(lexeme, amount)| BehaviourKind::FaceShift(FaceLexeme { lexeme, amount })),
        (any::<u32>(), option::of(pick(Side::ALL)), option::of(num()))
            .prop_map(|(au, side, amount)| BehaviourKind::FaceFacs(FaceFacs { au, side, amount })),
        posture().prop_map(BehaviourKind::Posture),
        posture().prop_map(BehaviourKind::PostureShift),
        (text(), option::of(text()))
            .prop_map(|(target, manner)| BehaviourKind::Locomotion(Locomotion { target, manner })),
        option::of(num()).prop_map(|max_wait| BehaviourKind::Wait(Wait { max_wait })),
        (id(), ids(), ids()).prop_map(|(target, include, exclude)| BehaviourKind::Interrupt(
            Interrupt {
                target,
                include,
                exclude
            }
        )),
        id().prop_map(|target| BehaviourKind::Activate(Activate { target })),
        (
            option::of(id()),
            id(),
            text(),
            pick(TrajectoryType::ALL),
            option::of(num()),
            num()
        )
            .prop_map(
                |(target_block, target_behaviour, param_id, kind, initial_value, target_value)| {
                    BehaviourKind::ParameterValueChange(ParameterValueChange {
                        target_block,
                        target_behaviour,
                        param_id,
                        trajectory: Trajectory {
                            kind,
                            initial_value,
                            target_value,
                        },
                    })
                }
            ),
        anim().prop_map(BehaviourKind::ProcAnimation),
        anim().prop_map(BehaviourKind::ProcAnimationGesture),
        anim().prop_map(BehaviourKind::Keyframe),
        (text(), option::of(text()), params()).prop_map(|(class, name, params)| {
            BehaviourKind::Controller(Controller {
                class,
                name,
                params,
            })
        }),
        text().prop_map(|file_name| BehaviourKind::AudioFile { file_name }),
        (text(), text(), params()).prop_map(|(joint, kind, params)| BehaviourKind::Noise(Noise {
            joint,
            kind,
            params
        })),
        (text(), option::of(num())).prop_map(|(target_name, intensity)| BehaviourKind::FaceMorph(
            FaceMorph {
                target_name,
                intensity
            }
        )),
        (text(), params())
            .prop_map(|(class, params)| BehaviourKind::Transition(Transition { class, params })),
        (
            prop_oneof![Just("urn:x"), Just("urn:y")],
            "[a-z]{1,8}",
            foreign(),
            raw_content(),
        )
            .prop_map(|(ns, name, attrs, content)| {
                BehaviourKind::Unknown(UnknownBehaviour {
                    ns: ns.into(),
                    name,
                    attrs,
                    content: content.0.into(),
                    namespaces: content.1,
                })
            }),
    ]
}

fn behaviour() -> impl Strategy<Value = Behaviour> {
    let description =
        (option::of(any::<i64>()), text(), raw_content()).prop_map(|(priority, kind, content)| {
            Description {
                priority,
                kind,
                content: content.0.into(),
                namespaces: content.1,
                pos: Pos::default(),
            }
        });
    (
        id(),
        kind(),
        vec((any::<proptest::sample::Index>(), sync_ref()), 0..4),
        any::<bool>(),
        vec(description, 0..2),
        foreign(),
    )
        .prop_map(|(id, kind, syncs, required, descriptions, foreign_attrs)| {
            let names = kind.standard_syncs();
            let mut attrs: Vec<SyncAttr> = Vec::new();
            for (i, value) in syncs {
                let sync = names[i.index(names.len())];
                if !attrs.iter().any(|a| a.sync == sync) {
                    attrs.push(SyncAttr {
                        sync,
                        value,
                        pos: Pos::default(),
                    });
                }
            }
            let unknown = matches!(kind, BehaviourKind::Unknown(_));
            Behaviour {
                id: id.into(),
                kind,
                syncs: attrs,
                required,
                descriptions: if unknown { vec![] } else { descriptions },
                foreign_attrs: if unknown { vec![] } else { foreign_attrs },
                pos: Pos::default(),
            }
        })
}

fn constraint_element() -> impl Strategy<Value = ConstraintElement> {
    let syncs = |n: usize| {
        vec(
            sync_ref().prop_map(|reference| ConstraintSync {
                reference,
                pos: Pos::default(),
            }),
            n..4,
        )
    };
    let item = prop_oneof![
        syncs(2).prop_map(|syncs| ConstraintItem::Synchronize {
            reference: None,
            syncs,
            pos: Pos::default()
        }),
        (sync_ref(), syncs(1)).prop_map(|(r, syncs)| ConstraintItem::Synchronize {
            reference: Some(r),
            syncs,
            pos: Pos::default()
        }),
        (sync_ref(), syncs(1)).prop_map(|(reference, syncs)| ConstraintItem::Before {
            reference,
            syncs,
            pos: Pos::default()
        }),
        (sync_ref(), syncs(1)).prop_map(|(reference, syncs)| ConstraintItem::After {
            reference,
            syncs,
            pos: Pos::default()
        }),
    ];
    (option::of(id()), vec(item, 1..3), any::<bool>()).prop_map(|(id, items, required)| {
        ConstraintElement {
            id,
            items,
            required,
            pos: Pos::default(),
        }
    })
}

fn block() -> impl Strategy<Value = Block> {
    let composition = prop_oneof![
        Just(Composition::Merge),
        Just(Composition::Append),
        Just(Composition::Replace),
        vec(id(), 1..3).prop_map(Composition::AppendAfter),
    ];
    let ext = (
        any::<bool>(),
        ids(),
        ids(),
        ids(),
        ids(),
        ids(),
        ids(),
        any::<bool>(),
    )
        .prop_map(
            |(
                preplan,
                on_start,
                interrupt,
                append_after,
                chunk_after,
                chunk_before,
                prepend_before,
                allow_external_refs,
            )| BlockExt {
                preplan,
                on_start,
                interrupt,
                append_after,
                chunk_after,
                chunk_before,
                prepend_before,
                allow_external_refs,
            },
        );
    (
        id(),
        option::of(text()),
        composition,
        ext,
        vec(behaviour(), 0..6),
        vec(constraint_element(), 0..3),
        foreign(),
    )
        .prop_map(
            |(id, character_id, composition, ext, behaviours, constraints, foreign_attrs)| Block {
                id: id.into(),
                character_id,
                composition,
                ext,
                behaviours,
                constraints,
                foreign_attrs,
                pos: Pos::default(),
            },
        )
}

fn time() -> impl Strategy<Value = f64> {
    (-10_000_000i64..10_000_000).prop_map(|k| k as f64 / 1000.0)
}

fn feedback() -> impl Strategy<Value = Feedback> {
    let status = || option::of(pick(BlockStatus::ALL));
    let chr = || option::of("[A-Za-z0-9 &<>\"]{1,8}");
    prop_oneof![
        (
            id(),
            prop_oneof![Just("start".to_string()), Just("end".to_string()), id()],
            time(),
            chr(),
            status(),
            option::of(any::<u64>())
        )
            .prop_map(
                |(block, sync, global_time, character_id, status, posix_time)| {
                    Feedback::BlockProgress(BlockProgress {
                        block: block.into(),
                        sync: sync.into(),
                        global_time,
                        character_id,
                        status,
                        posix_time,
                    })
                }
            ),
        (
            id(),
            id(),
            id(),
            time(),
            time(),
            chr(),
            option::of(any::<u64>()),
            any::<bool>()
        )
            .prop_map(
                |(block, behaviour, sync, time, global_time, character_id, posix_time, skipped)| {
                    Feedback::SyncPointProgress(SyncPointProgress {
                        block: block.into(),
                        behaviour: behaviour.into(),
                        sync: sync.into(),
                        time,
                        global_time,
                        character_id,
                        posix_time,
                        skipped,
                    })
                }
            ),
        (
            chr(),
            vec(
                (id(), option::of(time()), option::of(time()), status()).prop_map(
                    |(id, global_start, global_end, status)| BlockPrediction {
                        id: id.into(),
                        global_start,
                        global_end,
                        status
                    }
                ),
                0..3
            ),
            vec(
                (
                    "(gesture|speech|head|gaze|faceLexeme)",
                    id(),
                    id(),
                    proptest::sample::subsequence(GESTURE_SYNCS, 0..=7),
                    vec(time(), 7)
                )
                    .prop_map(|(kind, block, behaviour, names, times)| {
                        BehaviourPrediction {
                            kind: kind.into(),
                            block: block.into(),
                            behaviour: behaviour.into(),
                            syncs: names.into_iter().map(Into::into).zip(times).collect(),
                            attributes: Vec::new(),
                        }
                    }),
                0..3
            )
        )
            .prop_map(|(character_id, blocks, behaviours)| Feedback::Prediction(
                PredictionFeedback {
                    character_id,
                    blocks,
                    behaviours
                }
            )),
        (
            prop_oneof![
                id(),
                (id(), id()).prop_map(|(a, b)| format!("{a}:{b}")),
                Just("<no id>".to_string())
            ],
            prop_oneof![
                pick(KnownWarning::ALL).prop_map(WarningType::Known),
                "X_[A-Z_]{1,8}".prop_map(WarningType::Other)
            ],
            chr(),
            "[ -~\n]{0,40}"
        )
            .prop_map(|(id, kind, character_id, text)| Feedback::Warning(
                WarningFeedback {
                    id,
                    kind,
                    character_id,
                    text
                }
            )),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(1500))]

    #[test]
    fn bml_model_round_trips_through_the_writer(b in block()) {
        let xml = write(&b);
        let parsed = parse(&xml).map_err(|e| TestCaseError::fail(format!("{e}\n{xml}")))?;
        prop_assert_eq!(&parsed.block, &b, "{}", xml);
    }

    #[test]
    fn feedback_round_trips_through_both_codecs(fb in feedback()) {
        for (line, decode) in [(to_xml(&fb), from_xml as fn(&str) -> _), (to_json(&fb), from_json)] {
            prop_assert!(!line.contains('\n'), "one message per line: {}", line);
            prop_assert_eq!(decode(&line).map_err(|e| TestCaseError::fail(format!("{e}\n{line}")))?, fb.clone());
            prop_assert_eq!(from_line(&line).unwrap(), fb.clone());
        }
    }
}
