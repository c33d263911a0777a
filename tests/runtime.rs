//! The realizer runtime through its library API: the thesis' continuous-interaction scenarios that
//! need only speech and control behaviours (thesis §6.5), robustness
//! against bad input, determinism, bounded memory, characters and engines registered from outside
//! the core.

use std::sync::{Arc, Mutex};

use bml_realizer::engines::default_registry;
use bml_realizer::engines::interface::{Engine, EngineError, KindKey, Unit, UnitKey};
use bml_realizer::language::bml::{Behaviour, BehaviourKind, NS_BML};
use bml_realizer::language::feedback::{BlockStatus, Feedback, Format};
use bml_realizer::planning::timing::{DefaultTimingModels, TimingModel};
use bml_realizer::realizer::Realizer;

const NS: &str = r#"xmlns="http://www.bml-initiative.org/bml/bml-1.0" xmlns:bmla="http://www.asap-project.org/bmla" xmlns:bmlt="http://hmi.ewi.utwente.nl/bmlt""#;

fn block(id: &str, attrs: &str, body: &str) -> String {
    format!(r#"<bml {NS} id="{id}" {attrs}>{body}</bml>"#)
}

/// Speech of `words` one-syllable words (0.2 s each at the default rate), optionally with a sync
/// after word `at`.
fn speech(id: &str, words: usize, sync: Option<(&str, usize)>, attrs: &str) -> String {
    let mut text = String::new();
    for w in 0..words {
        if let Some((s, at)) = sync {
            if at == w {
                text.push_str(&format!(r#"<sync id="{s}"/>"#));
            }
        }
        text.push_str("la ");
    }
    format!(r#"<speech id="{id}" {attrs}><text>{text}</text></speech>"#)
}

/// A realizer with the metronome voice.
fn metronome() -> Realizer {
    Realizer::new().with_speech_timing(bml_realizer::planning::timing::SpeechTiming::syllables())
}

struct Session {
    r: Realizer,
    log: Arc<Mutex<Vec<Feedback>>>,
}

impl Session {
    /// A session whose speech is timed by the metronome voice (0.2 s per syllable), so that the
    /// expected times below can be worked out by hand.
    fn new() -> Self {
        Self::with(metronome())
    }

    fn with(mut r: Realizer) -> Self {
        let log = Arc::new(Mutex::new(Vec::new()));
        let sink = log.clone();
        r.add_listener(Box::new(move |f: &Feedback| {
            sink.lock().unwrap().push(f.clone())
        }));
        Session { r, log }
    }

    fn send(&mut self, at: f64, bml: &str) {
        self.r.tick(at);
        let _ = self.r.perform_bml(bml);
    }

    fn finish(&mut self) {
        while let Some(t) = self.r.next_event() {
            self.r.tick(t);
        }
    }

    fn fb(&self) -> Vec<Feedback> {
        self.log.lock().unwrap().clone()
    }

    /// Global time of `block:behaviour:sync`.
    fn at(&self, id: &str) -> f64 {
        let p: Vec<&str> = id.split(':').collect();
        self.fb()
            .iter()
            .find_map(|f| match f {
                Feedback::SyncPointProgress(s)
                    if s.block == p[0] && s.behaviour == p[1] && s.sync == p[2] =>
                {
                    Some(s.global_time)
                }
                _ => None,
            })
            .unwrap_or_else(|| panic!("no feedback for {id}"))
    }

    fn has_sync(&self, block: &str, behaviour: &str) -> bool {
        self.fb().iter().any(|f| {
            matches!(f, Feedback::SyncPointProgress(s) if s.block == block && s.behaviour == behaviour)
        })
    }

    /// (block, "start"|"end", time, status) in order.
    fn progress(&self) -> Vec<(String, String, f64, Option<BlockStatus>)> {
        self.fb()
            .iter()
            .filter_map(|f| match f {
                Feedback::BlockProgress(p) => Some((
                    p.block.to_string(),
                    p.sync.to_string(),
                    p.global_time,
                    p.status,
                )),
                _ => None,
            })
            .collect()
    }

    fn block_time(&self, block: &str, which: &str) -> Option<f64> {
        self.progress()
            .into_iter()
            .find(|p| p.0 == block && p.1 == which)
            .map(|p| p.2)
    }

    fn warnings(&self) -> Vec<(String, String)> {
        self.fb()
            .iter()
            .filter_map(|f| match f {
                Feedback::Warning(w) => Some((w.id.clone(), w.kind.as_str().to_string())),
                _ => None,
            })
            .collect()
    }
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() < 1e-9
}

// ---- thesis scenarios (§3) ----------------------------------------------------------------

#[test]
fn scenario4_keeping_the_turn_by_speaking_louder() {
    let mut s = Session::new();
    // speech1: 10 words, sync1 after 3 words (0.6 s)
    s.send(
        0.0,
        &block("bml1", "", &speech("speech1", 10, Some(("sync1", 3)), "")),
    );
    s.send(
        0.1,
        &block(
            "speechchange",
            r#"bmlt:allowexternalrefs="true""#,
            r#"<bmla:parametervaluechange id="pvc" target="bml1:speech1" paramId="volume" start="bml1:speech1:sync1" end="bml1:speech1:sync1+1"><bmla:trajectory type="linear" targetValue="90"/></bmla:parametervaluechange>"#,
        ),
    );
    let key = UnitKey::new("bml1", "speech1");
    let volume = |r: &mut Realizer, t: f64| {
        let frame = r.tick(t);
        frame
            .outputs
            .iter()
            .find(|o| *o.key == key)
            .and_then(|o| o.params.iter().find(|p| p.0 == "volume").map(|p| p.1))
            .unwrap()
    };
    // v0 = 100 (the default) at sync1 (0.6 s), linear to 90 at 1.6 s, held afterwards
    assert!(close(volume(&mut s.r, 0.5), 100.0));
    assert!(close(volume(&mut s.r, 1.1), 95.0));
    assert!(close(volume(&mut s.r, 1.6), 90.0));
    assert!(close(volume(&mut s.r, 1.9), 90.0));
    s.finish();
    assert!(close(s.at("speechchange:pvc:start"), 0.6));
    assert!(close(s.at("speechchange:pvc:end"), 1.6));
    assert!(s.warnings().is_empty(), "{:?}", s.warnings());
}

#[test]
fn scenario5a_yielding_removes_what_has_not_started() {
    let mut s = Session::new();
    s.send(
        0.0,
        &block(
            "bml1",
            "",
            &(speech("speech1", 10, None, "")
                + r#"<gesture id="gesture1" lexeme="BEAT" start="speech1:end-0.5"/>"#),
        ),
    );
    s.send(
        1.0,
        &block(
            "yieldturn",
            "",
            r#"<bmla:interrupt id="i1" target="bml1"/>"#,
        ),
    );
    s.finish();
    assert!(close(s.at("bml1:speech1:end"), 1.0));
    assert!(!s.has_sync("bml1", "gesture1"));
    assert_eq!(s.block_time("bml1", "end"), Some(1.0));
    assert!(s.warnings().is_empty());
}

#[test]
fn scenario5b_excluded_gesture_completes_and_the_block_ends_after_it() {
    let mut s = Session::new();
    s.send(
        0.0,
        &block(
            "bml1",
            "",
            &(speech("speech1", 20, None, "")
                + r#"<gesture id="gesture1" lexeme="BEAT" start="0.5" end="2"/>"#),
        ),
    );
    s.send(
        1.8,
        &block(
            "yieldturn",
            "",
            r#"<bmla:interrupt id="i1" target="bml1" exclude="gesture1"/>"#,
        ),
    );
    s.finish();
    assert!(close(s.at("bml1:speech1:end"), 1.8));
    assert!(close(s.at("bml1:gesture1:end"), 2.0));
    assert_eq!(s.block_time("bml1", "end"), Some(2.0));
}

/// The blocks of scenario 6 (incremental speech plan), all pre-planned.
fn scenario6_plan(s: &mut Session) {
    let pre = r#"bmla:preplan="true""#;
    s.send(0.0, &block("bml1", pre, &speech("s", 1, None, "")));
    s.send(0.0, &block("bml2", pre, &speech("s", 1, None, "")));
    for id in ["bml3", "bml4", "bml5"] {
        s.send(
            0.0,
            &block(
                id,
                &format!(r#"{pre} composition="APPEND-AFTER(bml1,bml2)""#),
                &speech("s", 2, None, ""),
            ),
        );
    }
    s.send(
        0.0,
        &block(
            "bml6",
            &format!(r#"{pre} composition="APPEND-AFTER(bml3,bml4,bml5)""#),
            &speech("s", 2, None, ""),
        ),
    );
}

#[test]
fn scenario6c_eh_it_costs_40_crowns() {
    let mut s = Session::new();
    scenario6_plan(&mut s);
    s.send(
        1.0,
        &block(
            "bml7",
            r#"bmla:interrupt="bml2,bml4,bml5" bmla:onStart="bml1,bml3,bml6""#,
            "",
        ),
    );
    s.finish();
    let starts: Vec<(String, f64)> = s
        .progress()
        .into_iter()
        .filter(|p| p.1 == "start")
        .map(|p| (p.0, p.2))
        .collect();
    let names: Vec<&str> = starts.iter().map(|p| p.0.as_str()).collect();
    assert_eq!(names, ["bml7", "bml1", "bml3", "bml6"]);
    // "eh" (0.2 s) then "it costs" then "40 crowns", each right after the previous one
    assert_eq!(s.block_time("bml1", "start"), Some(1.0));
    assert!(close(s.block_time("bml3", "start").unwrap(), 1.2));
    assert!(close(s.block_time("bml6", "start").unwrap(), 1.6));
    // the removed pre-planned blocks never started and ended REVOKED
    for id in ["bml2", "bml4", "bml5"] {
        assert!(s.block_time(id, "start").is_none());
        let end = s.progress().into_iter().find(|p| p.0 == id && p.1 == "end");
        assert_eq!(end.unwrap().3, Some(BlockStatus::Revoked));
    }
    assert!(s.warnings().is_empty(), "{:?}", s.warnings());
}

#[test]
fn scenario6d_lets_say_40_crowns() {
    let mut s = Session::new();
    scenario6_plan(&mut s);
    s.send(
        1.0,
        &block(
            "bml7",
            r#"bmla:interrupt="bml1,bml2,bml3,bml5" bmla:onStart="bml4""#,
            "",
        ),
    );
    s.send(1.1, &block("bml8", r#"bmla:onStart="bml6""#, ""));
    s.finish();
    // bml4's append-after targets are gone: it starts at once; bml6 after bml4
    assert_eq!(s.block_time("bml4", "start"), Some(1.0));
    assert!(close(s.block_time("bml6", "start").unwrap(), 1.4));
}

#[test]
fn scenario7_preplan_and_activate_once() {
    let mut s = Session::new();
    s.send(
        0.0,
        &block("bml1", r#"bmla:preplan="true""#, &speech("s", 2, None, "")),
    );
    s.send(
        0.0,
        &block("bml2", r#"bmla:preplan="true""#, &speech("s", 2, None, "")),
    );
    s.r.tick(2.0);
    assert!(
        s.block_time("bml1", "start").is_none(),
        "pre-planned blocks wait"
    );
    s.send(
        2.0,
        &block("bmlX", "", r#"<bmla:activate id="a1" target="bml1"/>"#),
    );
    s.send(
        2.0,
        &block(
            "bml3",
            "",
            r#"<head id="nod1" lexeme="NOD"/><bmla:activate id="a2" start="nod1:end" target="bml2"/>"#,
        ),
    );
    s.finish();
    assert_eq!(s.block_time("bml1", "start"), Some(2.0));
    assert!(close(
        s.block_time("bml2", "start").unwrap(),
        s.at("bml3:nod1:end")
    ));
    // a second activation of a finished block does nothing
    s.send(
        5.0,
        &block("bmlY", "", r#"<bmla:activate id="a1" target="bml1"/>"#),
    );
    s.finish();
    let starts = s
        .progress()
        .into_iter()
        .filter(|p| p.0 == "bml1" && p.1 == "start")
        .count();
    assert_eq!(starts, 1);
    assert!(s.warnings().is_empty(), "{:?}", s.warnings());
}

#[test]
fn scenario9_and_10_staggered_and_gracious_interruption() {
    let mut s = Session::new();
    s.send(
        0.0,
        &block(
            "bml1",
            "",
            &(speech("speech1", 20, Some(("sync1", 5)), "")
                + r#"<gesture id="gesture1" lexeme="BEAT" start="0" end="3"/><head id="other" lexeme="NOD" start="0" end="4"/>"#),
        ),
    );
    s.send(
        0.0,
        &block("bml3", r#"bmla:preplan="true""#, &speech("s", 2, None, "")),
    );
    s.send(
        0.0,
        &block("bml4", r#"bmla:preplan="true""#, &speech("s", 1, None, "")),
    );
    s.send(
        0.0,
        &block(
            "bml2",
            "",
            r#"<head id="shake1" lexeme="SHAKE" start="2"/>
               <bmla:interrupt id="i1" target="bml1" start="shake1:stroke" exclude="speech1,gesture1"/>
               <bmla:interrupt id="i2" target="bml1" include="speech1" start="bml1:speech1:sync1"/>
               <bmla:interrupt id="i3" target="bml1" include="gesture1" start="bml1:gesture1:strokeEnd"/>
               <bmla:activate id="a1" target="bml3" start="bml1:speech1:sync1"/>
               <bmla:activate id="a2" target="bml4" start="bml1:gesture1:strokeStart"/>"#,
        ),
    );
    s.finish();
    let sync1 = s.at("bml1:speech1:sync1");
    assert!(close(sync1, 1.0));
    assert!(
        close(s.at("bml1:speech1:end"), sync1),
        "speech cut at sync1"
    );
    assert!(close(s.block_time("bml3", "start").unwrap(), sync1));
    assert!(close(
        s.block_time("bml4", "start").unwrap(),
        s.at("bml1:gesture1:strokeStart")
    ));
    assert!(close(
        s.at("bml1:gesture1:relax"),
        s.at("bml1:gesture1:strokeEnd")
    ));
    assert!(close(s.at("bml1:other:relax"), s.at("bml2:shake1:stroke")));
    assert!(s.warnings().is_empty(), "{:?}", s.warnings());
}

#[test]
fn scenario11_interrupt_shorthand_equals_the_three_steps() {
    let run = |shorthand: bool| {
        let mut s = Session::new();
        s.send(0.0, &block("bml1", "", &speech("s", 10, None, "")));
        s.send(0.0, &block("bml2", "", &speech("s", 12, None, "")));
        if shorthand {
            s.send(
                1.0,
                &block(
                    "bmlNew",
                    r#"bmla:interrupt="bml1,bml2""#,
                    &speech("s", 2, None, ""),
                ),
            );
        } else {
            s.send(1.0, &block("i", "", r#"<bmla:interrupt id="a" target="bml1"/><bmla:interrupt id="b" target="bml2"/>"#));
            s.send(1.0, &block("bmlNew", "", &speech("s", 2, None, "")));
        }
        s.finish();
        (
            s.block_time("bml1", "end"),
            s.block_time("bml2", "end"),
            s.block_time("bmlNew", "start"),
            s.block_time("bmlNew", "end"),
        )
    };
    assert_eq!(run(true), run(false));
    assert_eq!(run(true).0, Some(1.0));
}

#[test]
fn scenario12_on_start_shorthand_equals_activates() {
    let run = |shorthand: bool| {
        let mut s = Session::new();
        for p in ["p1", "p2"] {
            s.send(
                0.0,
                &block(p, r#"bmla:preplan="true""#, &speech("s", 2, None, "")),
            );
        }
        let body = speech("s", 3, None, "");
        if shorthand {
            s.send(1.0, &block("n", r#"bmla:onStart="p1,p2""#, &body));
        } else {
            let acts =
                r#"<bmla:activate id="a1" target="p1"/><bmla:activate id="a2" target="p2"/>"#;
            s.send(1.0, &block("n", "", &(body + acts)));
        }
        s.finish();
        (s.block_time("p1", "start"), s.block_time("p2", "start"))
    };
    assert_eq!(run(true), run(false));
    assert_eq!(run(true), (Some(1.0), Some(1.0)));
}

#[test]
fn scenario15_append_waits_forever_for_a_persistent_block_append_after_does_not() {
    let mut s = Session::new();
    s.send(
        0.0,
        &block("P", "", r#"<bmlt:controller id="c" class="Balance"/>"#),
    );
    s.send(0.0, &block("Q", "", &speech("s", 2, None, "")));
    s.send(
        0.0,
        &block("A", r#"composition="APPEND""#, &speech("s", 1, None, "")),
    );
    s.send(
        0.0,
        &block(
            "A2",
            r#"composition="APPEND-AFTER(Q)""#,
            &speech("s", 1, None, ""),
        ),
    );
    s.finish();
    assert!(s.block_time("A", "start").is_none());
    assert!(close(s.block_time("A2", "start").unwrap(), 0.4));
    assert_eq!(
        s.r.next_event(),
        None,
        "only the persistent controller remains"
    );
    let live = s.r.character("").unwrap().live_blocks();
    assert_eq!(
        live,
        [
            ("P".to_string(), BlockStatus::InExec),
            ("A".to_string(), BlockStatus::Lurking)
        ]
    );
}

// ---- feedback contract -----------------------------------------------------------------

#[test]
fn an_appended_block_reports_in_the_order_of_design_section_4() {
    let mut s = Session::new();
    s.send(0.0, &block("bml1", "", &speech("s", 2, None, "")));
    s.log.lock().unwrap().clear();
    s.send(
        0.0,
        &block("bml2", r#"composition="APPEND""#, &speech("t", 1, None, "")),
    );
    s.finish();
    let seq: Vec<String> = s
        .fb()
        .iter()
        .filter(|f| match f {
            Feedback::Prediction(p) => p.blocks[0].id == "bml2",
            Feedback::BlockProgress(p) => p.block == "bml2",
            Feedback::SyncPointProgress(p) => p.block == "bml2",
            Feedback::Warning(_) => true,
            Feedback::World(_) => false,
        })
        .map(|f| match f {
            Feedback::Prediction(p) => format!("prediction {}", p.blocks[0].status.unwrap()),
            Feedback::BlockProgress(p) => format!("{} {}", p.sync, p.global_time),
            Feedback::SyncPointProgress(p) => format!("{} {}", p.sync, p.global_time),
            Feedback::Warning(w) => format!("warning {}", w.text),
            Feedback::World(w) => w.to_json(),
        })
        .collect();
    assert_eq!(
        seq,
        [
            "prediction IN_PREP",
            "prediction PENDING",
            "prediction LURKING",
            "start 0.4",
            "prediction IN_EXEC",
            "start 0.4",
            "end 0.6000000000000001",
            "end 0.6000000000000001",
        ]
    );
    // the PENDING prediction already knows when bml2 will start and end
    let pending = s.fb().into_iter().find_map(|f| match f {
        Feedback::Prediction(p) if p.blocks[0].status == Some(BlockStatus::Pending) => Some(p),
        _ => None,
    });
    let b = &pending.unwrap().blocks[0];
    assert!(close(b.global_start.unwrap(), 0.4));
    assert!(close(b.global_end.unwrap(), 0.6));
}

#[test]
fn every_sync_of_an_executed_behaviour_is_reported_once_and_every_block_starts_and_ends_once() {
    let mut s = Session::new();
    for i in 0..20 {
        let comp = if i % 3 == 0 { "APPEND" } else { "MERGE" };
        s.send(
            i as f64 * 0.3,
            &block(
                &format!("b{i}"),
                &format!(r#"composition="{comp}""#),
                &(speech("s", 2 + i % 4, Some(("m", 1)), "")
                    + r#"<gesture id="g" lexeme="BEAT" stroke="s:m"/><head id="h" lexeme="NOD" start="g:relax"/>"#),
            ),
        );
    }
    s.finish();
    let fb = s.fb();
    for i in 0..20 {
        let b = format!("b{i}");
        let n = |w: &str| {
            fb.iter()
                .filter(|f| matches!(f, Feedback::BlockProgress(p) if p.block == b && p.sync == w))
                .count()
        };
        assert_eq!((n("start"), n("end")), (1, 1), "{b}");
        for (beh, syncs) in [("s", 3), ("g", 7), ("h", 7)] {
            let count = fb
                .iter()
                .filter(|f| matches!(f, Feedback::SyncPointProgress(p) if p.block == b && p.behaviour == beh))
                .count();
            assert_eq!(count, syncs, "{b}:{beh}");
        }
    }
}

// ---- bad input never stops the stream ---------------------------------------------------

#[test]
fn a_non_xml_block_is_a_parsing_failure_and_the_next_block_runs() {
    let mut s = Session::new();
    s.send(0.0, "this is not <bml");
    s.send(0.0, &block("ok", "", &speech("s", 1, None, "")));
    s.finish();
    assert_eq!(s.warnings(), [("<no id>".into(), "PARSING_FAILURE".into())]);
    assert!(s.block_time("ok", "end").is_some());
    // a block with an id but an error names its id
    s.send(
        1.0,
        &block("bad", "", r#"<gesture id="g" lexeme="BEAT" start="x:y"/>"#),
    );
    assert_eq!(s.warnings()[1], ("bad".into(), "PARSING_FAILURE".into()));
}

#[test]
fn unknown_interrupt_and_activate_targets_are_no_such_target() {
    let mut s = Session::new();
    s.send(
        0.0,
        &block(
            "b",
            r#"bmla:interrupt="ghost" composition="APPEND-AFTER(phantom)""#,
            r#"<bmla:interrupt id="i" target="nobody"/><bmla:activate id="a" target="nowhere"/>"#,
        ),
    );
    s.finish();
    let w = s.warnings();
    assert_eq!(w.len(), 4, "{w:?}");
    assert!(w.iter().all(|(_, k)| k == "NO_SUCH_TARGET"));
    assert!(w.iter().any(|(id, _)| id == "b:i"));
    assert!(w.iter().any(|(id, _)| id == "b:a"));
    assert!(s.block_time("b", "end").is_some());
}

#[test]
fn an_unsupported_behaviour_kind_is_reported_and_the_rest_of_its_block_runs() {
    let mut s = Session::new();
    s.send(
        0.0,
        &block(
            "b",
            r#"xmlns:x="urn:example:x""#,
            &(r#"<x:dance id="d1" start="0"/>"#.to_string() + &speech("s", 2, None, "")),
        ),
    );
    s.finish();
    assert_eq!(
        s.warnings(),
        [("b:d1".into(), "BEHAVIOR_TYPE_NOT_SUPPORTED".into())]
    );
    assert!(close(s.at("b:s:end"), 0.4));
    assert!(close(s.block_time("b", "end").unwrap(), 0.4));
}

#[test]
fn a_block_whose_id_is_active_is_rejected_and_the_running_block_is_untouched() {
    let mut s = Session::new();
    s.send(0.0, &block("b", "", &speech("s", 5, None, "")));
    s.send(
        0.5,
        &block(
            "b",
            r#"composition="REPLACE""#,
            &speech("other", 1, None, ""),
        ),
    );
    s.finish();
    assert_eq!(
        s.warnings(),
        [("b".into(), "IMPOSSIBLE_TO_SCHEDULE".into())]
    );
    assert!(close(s.at("b:s:end"), 1.0));
    assert!(!s.has_sync("b", "other"));
    // after DONE the id can be used again
    s.send(2.0, &block("b", "", &speech("other", 1, None, "")));
    s.finish();
    assert!(close(s.at("b:other:end"), 2.2));
}

#[test]
fn a_required_behaviour_that_cannot_be_scheduled_fails_its_block_only() {
    let mut s = Session::new();
    s.send(
        0.0,
        &block(
            "req",
            "",
            r#"<required><speech id="s" start="2" end="1"><text>Hi there</text></speech></required>"#,
        ),
    );
    s.send(0.0, &block("next", "", &speech("s", 1, None, "")));
    s.finish();
    assert_eq!(
        s.warnings(),
        [("req".into(), "CANNOT_SATISFY_CONSTRAINTS".into())]
    );
    assert!(s.block_time("req", "start").is_none());
    assert!(s.block_time("next", "end").is_some());
}

// ---- determinism, memory, characters, engines from outside ------------------------------

fn scripted_log() -> String {
    let mut s = Session::new();
    s.send(0.0, &block("a", "", &(speech("s", 7, Some(("m", 2)), "") + r#"<gesture id="g" lexeme="BEAT" stroke="s:m"/><head id="h" lexeme="NOD" start="g:end" end="g:end+1"/>"#)));
    s.send(
        0.3,
        &block("b", r#"composition="APPEND""#, &speech("s", 3, None, "")),
    );
    s.send(
        0.5,
        &block("c", r#"bmla:preplan="true""#, &speech("s", 2, None, "")),
    );
    s.send(
        0.7,
        &block(
            "d",
            r#"bmla:onStart="c""#,
            r#"<bmla:interrupt id="i" target="a" include="s" start="0.1"/>"#,
        ),
    );
    s.send(0.8, "garbage");
    s.finish();
    s.fb()
        .iter()
        .map(|f| Format::Xml.encode(f) + "\n")
        .collect()
}

#[test]
fn the_same_input_gives_byte_identical_feedback() {
    let a = scripted_log();
    assert!(a.lines().count() > 30);
    for _ in 0..3 {
        assert_eq!(scripted_log(), a);
    }
}

#[test]
fn memory_stays_bounded_while_streaming_100000_blocks() {
    let mut r = Realizer::new();
    let body = r#"<head id="h" lexeme="NOD" start="0" end="0.01"/>"#;
    let mut max_blocks = 0;
    for i in 0..100_000u32 {
        let t = f64::from(i) * 0.005;
        r.tick(t);
        let _ = r.perform_bml(&block(&format!("b{i}"), "", body));
        let sizes = r.character("").unwrap().sizes();
        max_blocks = max_blocks.max(sizes.blocks);
        assert!(sizes.engine_units <= 3, "{sizes:?}");
    }
    while let Some(t) = r.next_event() {
        r.tick(t);
    }
    let sizes = r.character("").unwrap().sizes();
    assert!(max_blocks <= 3, "{max_blocks}");
    assert_eq!(
        (sizes.blocks, sizes.engine_units, sizes.parameter_changes),
        (0, 0, 0)
    );
    assert_eq!(
        sizes.finished_ids,
        bml_realizer::realizer::blocks::FINISHED_HISTORY
    );
}

#[test]
fn blocks_are_routed_to_characters_and_their_feedback_names_them() {
    let mut s = Session::with(metronome().with_default_character(Some("anna".into())));
    s.send(
        0.0,
        &block("b1", r#"characterId="bob""#, &speech("s", 2, None, "")),
    );
    s.send(0.0, &block("b1", "", &speech("s", 1, None, ""))); // same id, another character
    s.finish();
    let by = |c: &str| {
        s.fb()
            .iter()
            .filter(|f| matches!(f, Feedback::BlockProgress(p) if p.character_id.as_deref() == Some(c) && p.sync == "end"))
            .count()
    };
    assert_eq!((by("anna"), by("bob")), (1, 1));
    assert!(s.warnings().is_empty());
    let names: Vec<&str> = s.r.characters().map(|c| c.0).collect();
    assert_eq!(names, ["anna", "bob"]);
}

/// An engine written outside the crate for a kind the core does not know.
struct Blinker {
    units: Vec<UnitKey>,
}

impl Engine for Blinker {
    fn name(&self) -> &'static str {
        "blinker"
    }
    fn timing(&self, b: &Behaviour) -> Option<TimingModel> {
        matches!(&b.kind, BehaviourKind::Unknown(u) if u.name == "blink")
            .then(|| TimingModel::stretchable(&[("start", 0.0), ("end", 0.15)]))
    }
    fn add(&mut self, unit: Unit<'_>) -> Result<(), EngineError> {
        self.units.push(unit.key.clone());
        Ok(())
    }
    fn remove(&mut self, key: &UnitKey) {
        self.units.retain(|k| k != key);
    }
    fn len(&self) -> usize {
        self.units.len()
    }
}

#[test]
fn a_new_kind_and_engine_register_from_outside_the_core() {
    let r = Realizer::new().with_engines(|| {
        let mut reg = default_registry(DefaultTimingModels::default());
        reg.register(
            Box::new(Blinker { units: Vec::new() }),
            &[KindKey::new("urn:example:face", "blink")],
        );
        // the built-in speech kind can be taken over too
        assert!(reg.kinds().contains(&&KindKey::new(NS_BML, "speech")));
        reg
    });
    let mut s = Session::with(r);
    s.send(
        0.0,
        &block(
            "b",
            r#"xmlns:f="urn:example:face""#,
            r#"<f:blink id="k" start="1"/>"#,
        ),
    );
    s.finish();
    assert!(s.warnings().is_empty(), "{:?}", s.warnings());
    assert!(close(s.at("b:k:end"), 1.15));
}

// ---- anticipators (thesis scenarios 1–3) -------------------------------------------------

use bml_realizer::planning::plan::anticipator::{Metronome, Scripted};

#[test]
fn scenario3_speech_starts_one_second_after_the_last_predicted_end_of_the_users_turn() {
    let mut s = Session::new();
    // predicted end of the user's speech: 5 s; revised at 2 s to 6 s; revised again at 8 s (after
    // the speech started: no effect)
    s.r.add_anticipator(
        None,
        Box::new(Scripted::new(
            "speechStopAnticipator",
            &[("stop", 5.0)],
            &[(2.0, "stop", 6.0), (8.0, "stop", 9.0)],
        )),
    );
    s.send(
        0.0,
        &block(
            "bml1",
            "",
            &speech(
                "speech1",
                5,
                None,
                r#"start="anticipators:speechStopAnticipator:stop+1""#,
            ),
        ),
    );
    s.finish();
    assert_eq!(
        s.block_time("bml1", "start"),
        Some(0.0),
        "the block starts on arrival"
    );
    assert!(close(s.at("bml1:speech1:start"), 7.0));
    assert!(
        close(s.at("bml1:speech1:end"), 8.0),
        "rigid speech keeps its length"
    );
    assert!(s.warnings().is_empty(), "{:?}", s.warnings());
    // no new scheduling feedback after the revision: one IN_PREP and one PENDING prediction
    let predictions = s
        .fb()
        .iter()
        .filter(|f| matches!(f, Feedback::Prediction(_)))
        .count();
    assert_eq!(predictions, 3); // IN_PREP, PENDING, IN_EXEC
}

#[test]
fn scenario2_a_tempo_change_retimes_the_ticks_still_to_come() {
    let metronome = Metronome::new("metronome1", 1.0, 60.0); // tick k at k s
    let mut s = Session::new();
    s.r.add_anticipator(None, Box::new(metronome.clone()));
    s.send(
        0.0,
        &block(
            "conduct",
            "",
            r#"<head id="b1" lexeme="NOD" stroke="anticipators:metronome1:tick1"/>
               <head id="b2" lexeme="NOD" stroke="anticipators:metronome1:tick2"/>
               <head id="b3" lexeme="NOD" stroke="anticipators:metronome1:tick3"/>"#,
        ),
    );
    s.r.tick(1.1);
    // from now on a tick every 0.5 s: at 1.1 the metronome is at tick 1.1, so tick2 comes at
    // 1.1 + 0.9 × 0.5 = 1.55 and tick3 at 2.05
    metronome.set_tempo(120.0, 1.1);
    s.finish();
    assert!(close(s.at("conduct:b1:stroke"), 1.0));
    assert!(close(s.at("conduct:b2:stroke"), 1.55));
    assert!(close(s.at("conduct:b3:stroke"), 2.05));
    // each nod keeps its shape around the moved stroke
    assert!(close(s.at("conduct:b3:start"), 1.75));
    assert!(s.warnings().is_empty(), "{:?}", s.warnings());
}

/// A gesture's stroke on a beat, and a nod from 1.5 to 2 s that must end before the beat
/// (predicted at 3 s, revised at 0.5 s to `revised`).
fn beat_block(revised: f64) -> Session {
    let mut s = Session::new();
    s.r.add_anticipator(
        None,
        Box::new(Scripted::new(
            "beat",
            &[("b1", 3.0)],
            &[(0.5, "b1", revised)],
        )),
    );
    s.send(
        0.0,
        &block(
            "b",
            "",
            r#"<gesture id="g1" lexeme="BEAT" stroke="anticipators:beat:b1"/>
               <head id="n1" lexeme="NOD" start="1.5" end="2"/>
               <constraint><before ref="anticipators:beat:b1"><sync ref="n1:end"/></before></constraint>"#,
        ),
    );
    s.finish();
    s
}

#[test]
fn a_moved_prediction_drags_what_must_stay_before_it() {
    let s = beat_block(1.8);
    assert!(close(s.at("b:g1:stroke"), 1.8));
    // n1:end <= beat still holds: the nod's end was dragged from 2 to 1.8, its start stays
    assert!(close(s.at("b:n1:start"), 1.5));
    assert!(close(s.at("b:n1:end"), 1.8));
    assert!(s.warnings().is_empty(), "{:?}", s.warnings());
}

#[test]
fn a_prediction_that_breaks_a_behaviours_timing_drops_it_with_invalid_timing() {
    let s = beat_block(1.4);
    // the stroke followed the beat
    assert!(close(s.at("b:g1:stroke"), 1.4));
    // the nod would have to end (1.4) before it starts (1.5): dropped before it started
    assert!(!s.has_sync("b", "n1"));
    assert_eq!(s.warnings(), [("b:n1".into(), "INVALID_TIMING".into())]);
    assert!(close(s.block_time("b", "end").unwrap(), s.at("b:g1:end")));
}

#[test]
fn an_unknown_anticipator_drops_the_behaviour_that_names_it() {
    let mut s = Session::new();
    s.send(
        0.0,
        &block(
            "b",
            "",
            &(speech("s", 1, None, r#"start="anticipators:nobody:stop""#)
                + r#"<head id="h" lexeme="NOD"/>"#),
        ),
    );
    s.finish();
    assert_eq!(s.warnings(), [("b:s".into(), "NO_SUCH_TARGET".into())]);
    assert!(s.has_sync("b", "h"));
}

#[test]
fn a_block_tied_to_a_sync_that_just_passed_starts_at_it() {
    let mut s = Session::new();
    s.send(0.0, &block("bml1", "", &speech("speech1", 10, None, "")));
    // a frame later, a parameter change tied to the speech's start (already past)
    s.send(
        0.05,
        &block(
            "bml2",
            "",
            r#"<bmla:parametervaluechange id="pvc1" target="bml1:speech1" paramId="volume" start="bml1:speech1:start" end="bml1:speech1:end"><bmla:trajectory type="linear" initialValue="0" targetValue="100"/></bmla:parametervaluechange>"#,
        ),
    );
    s.finish();
    assert!(s.warnings().is_empty(), "{:?}", s.warnings());
    assert!(close(s.at("bml2:pvc1:start"), 0.0));
    assert!(close(s.at("bml2:pvc1:end"), 2.0));
    assert_eq!(s.block_time("bml2", "start"), Some(0.0));
    // much later than LATE_START it cannot hold: the change is dropped with a warning
    let mut s = Session::new();
    s.send(0.0, &block("bml1", "", &speech("speech1", 10, None, "")));
    s.send(
        1.0,
        &block(
            "bml2",
            "",
            r#"<bmla:parametervaluechange id="pvc1" target="bml1:speech1" paramId="volume" start="bml1:speech1:start"><bmla:trajectory type="instant" targetValue="100"/></bmla:parametervaluechange>"#,
        ),
    );
    s.finish();
    assert_eq!(
        s.warnings(),
        [("bml2:pvc1".into(), "CANNOT_SATISFY_CONSTRAINTS".into())]
    );
}

/// A REPLACE block removes a queued APPEND block before it starts: the queued block ends REVOKED
/// and never reports a start; the running one ends INTERRUPTED.
#[test]
fn replace_revokes_a_queued_block_without_starting_it() {
    let mut s = Session::new();
    s.send(0.0, &block("a", "", &speech("s1", 15, None, "")));
    s.send(
        0.5,
        &block("b", r#"composition="APPEND""#, &speech("s1", 2, None, "")),
    );
    s.send(
        1.0,
        &block("c", r#"composition="REPLACE""#, &speech("s1", 2, None, "")),
    );
    s.finish();
    let progress = s.progress();
    let of = |b: &str| -> Vec<(String, Option<BlockStatus>)> {
        progress
            .iter()
            .filter(|p| p.0 == b)
            .map(|p| (p.1.clone(), p.3))
            .collect()
    };
    assert_eq!(of("b"), [("end".to_string(), Some(BlockStatus::Revoked))]);
    assert_eq!(
        of("a")[1],
        ("end".to_string(), Some(BlockStatus::Interrupted))
    );
    assert!(!s.has_sync("b", "s1"));
}

/// A `<bmla:interrupt>` behaviour that cuts a running block's speech ends that block
/// INTERRUPTED, and the syncs the speech never reached are marked skipped; those it reached are
/// not.
#[test]
fn an_interrupt_behaviour_ends_its_target_interrupted_with_skipped_syncs_marked() {
    let mut s = Session::new();
    s.send(
        0.0,
        &block("a", "", &speech("s1", 15, Some(("late", 10)), "")),
    );
    s.send(
        1.0,
        &block(
            "b",
            "",
            r#"<bmla:interrupt id="i1" target="a" include="s1"/>"#,
        ),
    );
    s.finish();
    let end = s
        .progress()
        .into_iter()
        .find(|p| p.0 == "a" && p.1 == "end")
        .unwrap();
    assert_eq!(end.3, Some(BlockStatus::Interrupted));
    let skipped: Vec<(String, bool)> = s
        .fb()
        .iter()
        .filter_map(|f| match f {
            Feedback::SyncPointProgress(p) if p.block == "a" => {
                Some((p.sync.to_string(), p.skipped))
            }
            _ => None,
        })
        .collect();
    assert_eq!(
        skipped,
        [
            ("start".to_string(), false),
            ("late".to_string(), true),
            ("end".to_string(), false)
        ]
    );
    assert!((s.at("a:s1:late") - 1.0).abs() < 1e-9);
}
