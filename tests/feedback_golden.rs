//! Feedback codecs against golden logs: the exact XML and JSON lines of a representative message
//! set (all four elements, BMLA status and posix time, escaping). CI validates every line of the XML
//! log against bml-schemas/feedback-1.0.xsd. Regenerate with `UPDATE_GOLDEN=1 cargo test`.

use bml_realizer::language::feedback::*;

fn messages() -> Vec<Feedback> {
    let mut v = vec![
        Feedback::Prediction(PredictionFeedback {
            character_id: None,
            blocks: vec![BlockPrediction {
                id: "bml1".into(),
                global_start: Some(0.0),
                global_end: None,
                status: Some(BlockStatus::InPrep),
            }],
            behaviours: vec![],
        }),
        Feedback::Prediction(PredictionFeedback {
            character_id: Some("anna".into()),
            blocks: vec![BlockPrediction {
                id: "bml1".into(),
                global_start: Some(0.0),
                global_end: Some(3.25),
                status: Some(BlockStatus::Pending),
            }],
            behaviours: vec![BehaviourPrediction {
                kind: "gesture".into(),
                block: "bml1".into(),
                behaviour: "g1".into(),
                syncs: vec![
                    ("start".into(), 0.0),
                    ("stroke".into(), 0.85),
                    ("end".into(), 2.1),
                ],
                attributes: Vec::new(),
            }],
        }),
        Feedback::BlockProgress(BlockProgress {
            block: "bml1".into(),
            sync: "start".into(),
            global_time: 0.0,
            character_id: Some("anna".into()),
            status: Some(BlockStatus::InExec),
            posix_time: None,
        }),
        Feedback::SyncPointProgress(SyncPointProgress {
            block: "bml1".into(),
            behaviour: "g1".into(),
            sync: "stroke".into(),
            time: 0.85,
            global_time: 12.3456,
            character_id: None,
            posix_time: Some(1_700_000_003_120),
            skipped: false,
        }),
        Feedback::Warning(WarningFeedback {
            id: "bml1:gaze2".into(),
            kind: KnownWarning::ImpossibleToSchedule.into(),
            character_id: None,
            text: "gaze2 overlaps gaze1 on the neck & eyes; <dropped>\nsecond line".into(),
        }),
        Feedback::Warning(WarningFeedback {
            id: "<no id>".into(),
            kind: WarningType::Other("UNKNOWN_ANTICIPATOR_SYNC".into()),
            character_id: None,
            text: String::new(),
        }),
    ];
    for status in [
        BlockStatus::Done,
        BlockStatus::Interrupted,
        BlockStatus::Revoked,
    ] {
        v.push(Feedback::BlockProgress(BlockProgress {
            block: "bml1".into(),
            sync: "end".into(),
            global_time: 3.2504,
            character_id: None,
            status: Some(status),
            posix_time: None,
        }));
    }
    v
}

fn golden(name: &str, lines: Vec<String>) {
    let path = format!("{}/fixtures/feedback/{name}", env!("CARGO_MANIFEST_DIR"));
    let text = lines.join("\n") + "\n";
    if std::env::var_os("UPDATE_GOLDEN").is_some() {
        std::fs::write(&path, &text).unwrap();
    }
    assert_eq!(
        std::fs::read_to_string(&path).unwrap(),
        text,
        "{path} differs from the encoder"
    );
}

#[test]
fn xml_log_is_exact() {
    golden("sample.xml.log", messages().iter().map(to_xml).collect());
}

#[test]
fn jsonl_log_is_exact() {
    golden("sample.jsonl", messages().iter().map(to_json).collect());
}

#[test]
fn golden_logs_decode_to_the_messages_rounded_to_milliseconds() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/fixtures/feedback");
    for file in ["sample.xml.log", "sample.jsonl"] {
        let text = std::fs::read_to_string(format!("{dir}/{file}")).unwrap();
        let decoded: Vec<Feedback> = text.lines().map(|l| from_line(l).unwrap()).collect();
        assert_eq!(decoded.len(), messages().len());
        let Feedback::SyncPointProgress(s) = &decoded[3] else {
            panic!()
        };
        assert_eq!(
            (s.time, s.global_time, s.posix_time),
            (0.85, 12.346, Some(1_700_000_003_120))
        );
        let Feedback::Warning(w) = &decoded[4] else {
            panic!()
        };
        assert_eq!(
            w.text,
            "gaze2 overlaps gaze1 on the neck & eyes; <dropped>\nsecond line"
        );
        assert_eq!(decoded[0], messages()[0]);
    }
}
