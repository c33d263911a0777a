//! The RealizerTester expectations (its test classes' assertions) reproduced through
//! `bmlr run` on the virtual clock: each test sends the catalogued files in order (sleeps become
//! `+SECS` clock advances), reads the feedback log back and checks the catalogued assertions with
//! their exact semantics (0.1 s for equalities, strict inequalities, subsequence order). The full
//! harness with its own port and self-tests is the `realizer-tests` crate's job; this file is the
//! runtime's acceptance.

use std::process::Command;

use bml_realizer::language::feedback::{
    self, BlockStatus, Feedback, SyncPointProgress, WarningFeedback,
};

const EPS: f64 = 0.1;
use bml_realizer::language::bml::{
    FACE_SYNCS as FACE4, GAZE_SYNCS as GAZE4, GESTURE_SYNCS as GESTURE7, START_END as SE,
};

struct Log {
    fb: Vec<Feedback>,
}

/// Runs `bmlr run` with RealizerTester files (relative to bml-1/) and `+SECS` items; it must
/// succeed.
fn run(items: &[&str]) -> Log {
    let (log, code) = run_with_code(items);
    assert_eq!(code, 0, "bmlr run failed");
    log
}

/// [`run`], with the exit code (1 when some input is invalid).
fn run_with_code(items: &[&str]) -> (Log, i32) {
    let dir = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/fixtures/realizertester/bml-1/"
    );
    let args: Vec<String> = items
        .iter()
        .map(|i| {
            if i.starts_with('+') {
                i.to_string()
            } else {
                format!("{dir}{i}")
            }
        })
        .collect();
    let out = Command::new(env!("CARGO_BIN_EXE_bmlr"))
        .arg("run")
        .args(&args)
        .output()
        .unwrap();
    let code = out.status.code().unwrap_or(-1);
    if code != 0 {
        eprintln!("{}", String::from_utf8_lossy(&out.stderr));
    }
    let text = String::from_utf8(out.stdout).unwrap();
    let log = Log {
        fb: text
            .lines()
            .map(|l| feedback::from_line(l).unwrap_or_else(|e| panic!("{e}: {l}")))
            .collect(),
    };
    (log, code)
}

impl Log {
    /// The part of the log from the `n`-th (0-based) IN_PREP prediction of `block` on.
    fn since_submission(&self, block: &str, n: usize) -> Log {
        let at = self
            .fb
            .iter()
            .enumerate()
            .filter(|(_, f)| {
                matches!(f, Feedback::Prediction(p)
                    if p.blocks.iter().any(|b| b.id == block && b.status == Some(BlockStatus::InPrep)))
            })
            .nth(n)
            .map(|(i, _)| i)
            .expect("submission");
        Log {
            fb: self.fb[at..].to_vec(),
        }
    }

    fn syncs(&self) -> impl Iterator<Item = &SyncPointProgress> {
        self.fb.iter().filter_map(|f| match f {
            Feedback::SyncPointProgress(s) => Some(s),
            _ => None,
        })
    }

    fn warnings(&self) -> Vec<&WarningFeedback> {
        self.fb
            .iter()
            .filter_map(|f| match f {
                Feedback::Warning(w) => Some(w),
                _ => None,
            })
            .collect()
    }

    fn progress(&self, which: &str) -> Vec<(&str, f64)> {
        self.fb
            .iter()
            .filter_map(|f| match f {
                Feedback::BlockProgress(p) if p.sync == which => {
                    Some((p.block.as_str(), p.global_time))
                }
                _ => None,
            })
            .collect()
    }

    fn starts(&self) -> Vec<&str> {
        self.progress("start").into_iter().map(|p| p.0).collect()
    }

    fn stops(&self) -> Vec<&str> {
        self.progress("end").into_iter().map(|p| p.0).collect()
    }

    fn start(&self, b: &str) -> f64 {
        self.progress("start")
            .into_iter()
            .find(|p| p.0 == b)
            .unwrap_or_else(|| panic!("no start feedback for {b}"))
            .1
    }

    fn stop(&self, b: &str) -> f64 {
        self.progress("end")
            .into_iter()
            .find(|p| p.0 == b)
            .unwrap_or_else(|| panic!("no end feedback for {b}"))
            .1
    }

    fn sync(&self, id: &str) -> &SyncPointProgress {
        let p: Vec<&str> = id.split(':').collect();
        self.syncs()
            .find(|s| s.block == p[0] && s.behaviour == p[1] && s.sync == p[2])
            .unwrap_or_else(|| panic!("no sync feedback {id}"))
    }

    fn rel(&self, id: &str) -> f64 {
        self.sync(id).time
    }

    fn global(&self, id: &str) -> f64 {
        self.sync(id).global_time
    }

    fn no_warnings(&self) {
        assert!(self.warnings().is_empty(), "{:?}", self.warnings());
    }

    fn no_dup_syncs(&self) {
        let mut seen = std::collections::HashSet::new();
        for s in self.syncs() {
            assert!(
                seen.insert((&s.block, &s.behaviour, &s.sync)),
                "duplicate sync {}:{}:{}",
                s.block,
                s.behaviour,
                s.sync
            );
        }
    }

    fn no_dup(&self) {
        self.no_dup_syncs();
        for list in [self.starts(), self.stops()] {
            let mut v = list.clone();
            v.sort();
            v.dedup();
            assert_eq!(v.len(), list.len(), "duplicate block progress: {list:?}");
        }
    }

    fn blocks(&self, ids: &[&str]) {
        assert_eq!(self.starts(), ids, "starts");
        assert_eq!(self.stops(), ids, "stops");
    }

    /// `expected` is a subsequence of the syncs reported for `block:beh` (arrival order).
    fn order(&self, bb: &str, expected: &[&str]) {
        let (b, beh) = bb.split_once(':').unwrap();
        let seen: Vec<&str> = self
            .syncs()
            .filter(|s| s.block == b && s.behaviour == beh)
            .map(|s| s.sync.as_str())
            .collect();
        let mut it = seen.iter();
        for e in expected {
            assert!(
                it.any(|s| s == e),
                "{bb}: expected {expected:?} in {seen:?}"
            );
        }
    }

    fn assert_rel(&self, id: &str, t: f64) {
        let r = self.rel(id);
        assert!((r - t).abs() <= EPS, "{id}: {r} != {t}");
    }

    fn link(&self, a: &str, oa: f64, b: &str, ob: f64) {
        let (ga, gb) = (self.global(a) + oa, self.global(b) + ob);
        assert!((ga - gb).abs() <= EPS, "{a} ({ga}) != {b} ({gb})");
    }
}

// §1.7 AbstractRealizerTest

#[test]
fn empty_block() {
    let log = run(&["core/empty.xml"]);
    log.no_warnings();
    log.no_dup();
    log.blocks(&["bml1"]);
}

#[test]
fn invalid_block_gives_exactly_one_warning() {
    let (log, code) = run_with_code(&["core/bmlnoid.xml"]);
    assert_eq!(code, 1, "an invalid block is invalid input");
    let w = log.warnings();
    assert_eq!(w.len(), 1);
    assert_eq!(w[0].kind.as_str(), "PARSING_FAILURE");
    assert_eq!(w[0].id, "<no id>");
    assert!(log.starts().is_empty());
}

#[test]
fn face() {
    let log = run(&["core/testface.xml"]);
    log.order("bml1:face1", FACE4);
    log.no_warnings();
    log.no_dup();
    log.blocks(&["bml1"]);
}

#[test]
fn beat_gesture() {
    let log = run(&["core/testbeatgesture.xml"]);
    log.order("bml1:g1", GESTURE7);
    log.no_warnings();
    log.no_dup();
    log.blocks(&["bml1"]);
}

#[test]
fn speech() {
    let log = run(&["core/testspeech.xml"]);
    log.order("bml1:speech1", SE);
    log.assert_rel("bml1:speech1:start", 0.0);
    log.blocks(&["bml1"]);
    log.no_warnings();
    log.no_dup();
}

#[test]
fn speech2() {
    let log = run(&["core/testspeech2.xml"]);
    log.order("bml1:speech1", &["start", "syncstart1", "end"]);
    log.assert_rel("bml1:speech1:start", 6.0);
    log.blocks(&["bml1"]);
    log.no_warnings();
    log.no_dup();
}

fn nod_timed_to_sync(file: &str) {
    let log = run(&[file]);
    log.order("bml1:speech1", &["start", "syncstart1", "end"]);
    log.order("bml1:nod1", GESTURE7);
    log.blocks(&["bml1"]);
    log.assert_rel("bml1:speech1:start", 6.0);
    log.assert_rel("bml1:nod1:end", 9.0);
    log.link("bml1:speech1:syncstart1", 0.0, "bml1:nod1:start", 0.0);
    log.no_warnings();
    log.no_dup();
}

#[test]
fn speech_nod_timed_to_sync() {
    nod_timed_to_sync("core/testspeech_nodtimedtosync.xml");
}

#[test]
fn speech_nod_timed_to_sync_inverse_order() {
    nod_timed_to_sync("core/testspeech_nodtimedtosyncinverseorder.xml");
}

#[test]
fn speech_gestures_sync_2x() {
    let log = run(&["core/testspeechgesturesync2x.xml"]);
    log.no_warnings();
    log.no_dup();
    log.order("bml1:beat5", GESTURE7);
    log.order("bml1:beatstop", GESTURE7);
    log.order("bml1:speech1", SE);
    log.order("bml1:speech2", SE);
    log.link("bml1:speech1:start", 0.0, "bml1:beat5:stroke", 0.0);
    log.link("bml1:speech2:start", 0.0, "bml1:beatstop:end", 0.0);
    log.link("bml1:beatstop:start", 0.0, "bml1:beat5:end", 3.0);
}

#[test]
fn nod() {
    let log = run(&["core/testnodlong.xml"]);
    log.blocks(&["bml1"]);
    log.order("bml1:nod1", GESTURE7);
    log.assert_rel("bml1:nod1:start", 0.0);
    log.assert_rel("bml1:nod1:end", 5.0);
    log.no_warnings();
    log.no_dup();
}

#[test]
fn gaze() {
    let log = run(&["core/testgaze.xml"]);
    log.blocks(&["bml1"]);
    log.order("bml1:gaze1", GAZE4);
    log.assert_rel("bml1:gaze1:start", 1.0);
    log.assert_rel("bml1:gaze1:end", 10.0);
    log.no_warnings();
    log.no_dup();
}

#[test]
fn gaze_overlap_drops_one_gaze_with_one_warning() {
    let log = run(&["core/testgazeoverlap.xml"]);
    log.no_dup();
    let w = log.warnings();
    assert_eq!(w.len(), 1, "{w:?}");
    log.blocks(&["bml1"]);
    let other = match w[0].id.as_str() {
        "bml1:gaze2" => "gaze1",
        "bml1:gaze1" => "gaze2",
        id => panic!("warning names {id}"),
    };
    log.order(&format!("bml1:{other}"), GAZE4);
    log.assert_rel(&format!("bml1:{other}:start"), 1.0);
    log.assert_rel(&format!("bml1:{other}:end"), 10.0);
}

#[test]
fn point() {
    let log = run(&["core/testpoint.xml"]);
    log.blocks(&["bml1"]);
    log.order("bml1:point1", GESTURE7);
    log.assert_rel("bml1:point1:start", 1.0);
    log.assert_rel("bml1:point1:end", 10.0);
    log.no_warnings();
    log.no_dup();
}

#[test]
fn speech_gestures() {
    let log = run(&["core/testspeechgestures.xml", "+1"]);
    log.no_warnings();
    log.no_dup();
    log.order("bml1:welkom", &["start", "deicticheart1", "beat1b1", "end"]);
    for g in ["g1", "relaxleft", "transleft"] {
        log.order(&format!("bml1:{g}"), GESTURE7);
    }
    log.assert_rel("bml1:g1:start", 2.0);
    log.assert_rel("bml1:g1:end", 4.0);
    log.assert_rel("bml1:welkom:deicticheart1", 2.0);
    log.assert_rel("bml1:transleft:start", 0.0);
    log.assert_rel("bml1:transleft:end", 2.0);
    log.assert_rel("bml1:relaxleft:start", 4.5);
    log.assert_rel("bml1:relaxleft:end", 6.8);
    log.blocks(&["bml1"]);
}

#[test]
fn very_short_behaviour() {
    let log = run(&["core/testshortbeh.xml"]);
    log.no_dup();
    log.blocks(&["bml1"]);
}

// §1.8 AbstractDraft1RealizerTest

#[test]
fn append_starts_exactly_at_the_previous_end() {
    let log = run(&["core/testspeech.xml", "core/testspeechappend.xml"]);
    log.order("bml1:speech1", SE);
    log.order("bml2:speech1", SE);
    log.no_warnings();
    log.no_dup();
    assert_eq!(log.start("bml2"), log.stop("bml1"));
    assert!(log.stop("bml1") > log.start("bml1"));
    assert!(log.stop("bml2") > log.start("bml2"));
    log.blocks(&["bml1", "bml2"]);
}

#[test]
fn append_replace_and_id_reuse() {
    let a = "core/appendandreplace/testspeech1.xml";
    let b = "core/appendandreplace/testspeech2.xml";
    let log = run(&[a, b, "+3", "core/appendandreplace/replace.xml", "+1", a, b]);
    let phase2 = log.since_submission("bml1", 1);
    let phase1 = Log {
        fb: log.fb[..log.fb.len() - phase2.fb.len()].to_vec(),
    };
    phase1.blocks(&["bml1", "bml2", "bml3"]);
    phase2.no_warnings();
    phase2.blocks(&["bml1", "bml2"]);
}

#[test]
fn replace_ends_the_running_block_first() {
    let log = run(&[
        "core/replace/testlongspeechandnod.xml",
        "+0.7",
        "core/replace/replace.xml",
    ]);
    log.blocks(&["bml1", "bml3"]);
    assert_eq!(log.stop("bml1"), 0.7);
}

#[test]
fn speech_nod_timed_to_sync_constraint_spec() {
    let log = run(&["core/testspeechandnod_synctimed.xml"]);
    log.order("bml1:speech1", &["start", "s1", "end"]);
    log.order("bml1:nod1", GESTURE7);
    log.blocks(&["bml1"]);
    log.assert_rel("bml1:speech1:s1", 10.0);
    log.link("bml1:speech1:start", 0.0, "bml1:nod1:start", 0.0);
    assert!(log.rel("bml1:speech1:start") < 10.0);
    assert!(log.rel("bml1:speech1:end") > 10.0);
    log.no_warnings();
    log.no_dup();
}

// §1.9 AbstractBML1RealizerTest

#[test]
fn gaze_waist_without_end_still_ends() {
    let log = run(&["core/testgazewaist.xml"]);
    log.order("bml1:gaze1", GAZE4);
    log.blocks(&["bml1"]);
    log.no_warnings();
    log.no_dup();
}

#[test]
fn posture_shift() {
    let log = run(&["core/testpose.xml"]);
    log.assert_rel("bml1:pose1:start", 5.0);
    log.assert_rel("bml1:pose1:end", 8.0);
    log.order("bml1:pose1", SE);
    log.blocks(&["bml1"]);
    log.no_warnings();
    log.no_dup();
}

#[test]
fn gaze_shift() {
    let log = run(&["core/testgazeshift.xml"]);
    log.order("bml1:gaze1", SE);
    log.blocks(&["bml1"]);
    log.no_warnings();
    log.no_dup();
}

// §1.10 AbstractASAPRealizerTest (the ones that need only the runtime)

#[test]
fn parameter_value_change_from_external_block() {
    let log = run(&[
        "asap/parametervaluechange/speechandnod.xml",
        "asap/parametervaluechange/volumechange.xml",
    ]);
    log.no_warnings();
    log.no_dup_syncs();
    log.order("bml1:speech1", &["start", "s1", "end"]);
    log.order("bml1:speech2", SE);
    log.order("bml2:pvc1", SE);
    log.link("bml1:speech1:start", 0.0, "bml2:pvc1:start", 0.0);
    log.link("bml1:speech1:end", 0.0, "bml2:pvc1:end", 0.0);
}

#[test]
fn activate() {
    let log = run(&[
        "asap/activate/testpreplannedspeech1.xml",
        "asap/activate/testactivate.xml",
    ]);
    log.order("bml1:speech1", SE);
    log.order("bml2:nod1", GESTURE7);
    log.link("bml2:nod1:end", 0.0, "bml1:speech1:start", 0.0);
    log.no_warnings();
    log.no_dup();
    // the pre-planned block starts only when activated
    assert_eq!(log.start("bml1"), log.global("bml2:nod1:end"));
    assert!(log.start("bml1") > 0.0);
}

#[test]
fn parameter_value_change() {
    let log = run(&["asap/parametervaluechange.xml"]);
    log.no_warnings();
    log.no_dup_syncs();
    log.order("bml1:speech1", SE);
    log.order("bml1:speech2", SE);
    log.order("bml1:pvc1", SE);
    log.link("bml1:speech1:end", 0.0, "bml1:pvc1:end", 0.0);
}

#[test]
fn preplan_interrupt_and_on_start() {
    let log = run(&[
        "asap/preplan/testspeech1.xml",
        "asap/preplan/testspeechinterrupt.xml",
        "+3",
        "asap/preplan/testnod.xml",
    ]);
    log.no_warnings();
    log.no_dup();
    // every block ends exactly once, the interrupted one at the moment bml3 arrives
    let mut stops = log.stops();
    stops.sort();
    assert_eq!(stops, ["bml1", "bml2", "bml3"]);
    assert_eq!(log.stop("bml1"), 3.0);
    assert_eq!(log.start("bml2"), 3.0);
}

#[test]
fn append_after_starts_right_after_its_targets() {
    let log = run(&[
        "asap/appendafter/testspeech1.xml",
        "asap/appendafter/testspeech2.xml",
        "asap/appendafter/testspeech3.xml",
        "asap/appendafter/testnodappendafter.xml",
    ]);
    log.no_warnings();
    log.no_dup();
    for b in ["bml1", "bml2", "bml3"] {
        log.order(&format!("{b}:speech1"), SE);
    }
    log.order("bml4:nod1", GESTURE7);
    for (prev, next) in [("bml1", "bml2"), ("bml2", "bml3"), ("bml2", "bml4")] {
        let d = log.start(next) - log.stop(prev);
        assert!((0.0..=0.5).contains(&d), "{prev} -> {next}: {d}");
    }
    assert_eq!(log.start("bml4"), log.stop("bml2"));
}

#[test]
fn interrupt_block_attribute() {
    let log = run(&[
        "asap/interruptblock/testlongspeechandnod.xml",
        "asap/interruptblock/testinterruptbml1.xml",
    ]);
    log.no_warnings();
    log.no_dup();
    assert!((log.start("bml2") - log.stop("bml1")).abs() <= EPS);
}

#[test]
fn interrupt_behaviour_stops_speech_and_relaxes_the_nod() {
    let log = run(&[
        "asap/interrupt/testlongspeechandnod.xml",
        "asap/interrupt/testspeechinterrupt.xml",
    ]);
    log.no_warnings();
    log.no_dup();
    log.link("bml2:i1:start", 0.0, "bml1:speech1:end", 0.0);
    log.link("bml2:i1:start", 0.0, "bml1:nod1:relax", 0.0);
    // exactly at the interrupt time; the nod keeps its retraction after relax
    assert_eq!(log.global("bml1:speech1:end"), 2.0);
    assert_eq!(log.global("bml1:nod1:relax"), 2.0);
    assert!(log.global("bml1:nod1:end") > 2.0);
}

fn interrupt_behaviour2_phase(log: &Log) {
    log.order("bml3:speech1", SE);
    log.no_dup();
    let d = log.global("bml1:speech1:s1") - log.start("bml3");
    assert!(d.abs() <= EPS, "{d}");
}

#[test]
fn interrupt_behaviour2() {
    let log = run(&[
        "asap/interruptbehavior/testlongspeechandnod.xml",
        "asap/interruptbehavior/testinterruptionspeech.xml",
        "asap/interruptbehavior/testspeechinterrupt.xml",
    ]);
    log.no_warnings();
    interrupt_behaviour2_phase(&log);
    // the nod was removed before it started; the speech stopped at s1
    assert!(log.syncs().all(|s| s.behaviour != "nod1"));
    assert_eq!(
        log.global("bml1:speech1:end"),
        log.global("bml1:speech1:s1")
    );
}

#[test]
fn interrupt_behaviour_restart() {
    let files = [
        "asap/interruptbehavior/testlongspeechandnod.xml",
        "asap/interruptbehavior/testinterruptionspeech.xml",
        "asap/interruptbehavior/testspeechinterrupt.xml",
    ];
    let replace = std::env::temp_dir().join(format!("bmlr-rep-{}.xml", std::process::id()));
    std::fs::write(
        &replace,
        r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="bmlrep" composition="REPLACE"/>"#,
    )
    .unwrap();
    let dir = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/fixtures/realizertester/bml-1/"
    );
    let rep = replace.to_str().unwrap().to_string();
    let mut items: Vec<String> = files.iter().map(|f| format!("{dir}{f}")).collect();
    items.push("+30".into());
    items.push(rep);
    items.extend(files.iter().map(|f| format!("{dir}{f}")));
    let out = Command::new(env!("CARGO_BIN_EXE_bmlr"))
        .arg("run")
        .args(&items)
        .output()
        .unwrap();
    std::fs::remove_file(&replace).ok();
    let log = Log {
        fb: String::from_utf8(out.stdout)
            .unwrap()
            .lines()
            .map(|l| feedback::from_line(l).unwrap())
            .collect(),
    };
    let phase2 = log.since_submission("bml1", 1);
    let phase1 = Log {
        fb: log.fb[..log.fb.len() - phase2.fb.len()].to_vec(),
    };
    interrupt_behaviour2_phase(&phase1);
    phase2.no_warnings();
    phase2.no_dup_syncs();
    interrupt_behaviour2_phase(&phase2);
}

#[test]
fn bmlt_audio() {
    let log = run(&["bmlt/bmltaudio.xml"]);
    log.no_warnings();
    log.no_dup();
    log.order("bml1:audio1", SE);
}

#[test]
fn chunk_starts_when_the_previous_block_subsides() {
    let log = run(&[
        "asap/chunking/firstchunk.xml",
        "asap/chunking/secondchunk.xml",
    ]);
    log.no_warnings();
    log.blocks(&["bml1", "bml2"]);
    log.no_dup();
    log.order("bml1:g1", GESTURE7);
    log.order("bml2:g1", GESTURE7);
    log.link("bml1:g1:relax", 0.0, "bml2:g1:start", 0.0);
}
