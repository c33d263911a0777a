//! The 41 RealizerTester tests, each with the catalogued files, order, waits and assertions
//! (those of the original Java test classes and the incremental-speech fixture), and the runner
//! that resets the realizer before each one.

use crate::check::{Check, Failure};
use crate::port::{Ctx, Fixture, TestPort};

/// One conformance test.
pub struct Test {
    /// The original's method name.
    pub name: &'static str,
    /// Where it comes from.
    pub origin: &'static str,
    /// The realizer configuration it needs.
    pub fixture: Fixture,
    /// Sends, waits and asserts.
    pub run: fn(&mut Ctx) -> Check,
}

const GESTURE7: &[&str] = &[
    "start",
    "ready",
    "strokeStart",
    "stroke",
    "strokeEnd",
    "relax",
    "end",
];
const GAZE4: &[&str] = &["start", "ready", "relax", "end"];
const FACE4: &[&str] = &["start", "attackPeak", "relax", "end"];
const SE: &[&str] = &["start", "end"];

/// `a:b` → (`a`, `b`).
fn split(id: &str) -> (&str, &str) {
    id.split_once(':').unwrap_or((id, ""))
}

impl Ctx<'_> {
    fn order(&self, bb: &str, syncs: &[&str]) -> Check {
        let (b, beh) = split(bb);
        self.rec.syncs_in_order(b, beh, syncs)
    }

    /// NoExc, NoWarn, NoDup.
    fn clean(&self) -> Check {
        self.rec.no_exceptions()?;
        self.rec.no_warnings()?;
        self.rec.no_duplicate_feedback()
    }

    fn send_all(&mut self, files: &[&str]) -> Check {
        files.iter().try_for_each(|f| self.send(f))
    }

    fn wait_ends(&mut self, blocks: &[&str]) -> Check {
        blocks.iter().try_for_each(|b| self.wait_end(b))
    }
}

// ---- §1.7 AbstractRealizerTest ------------------------------------------------------------

fn empty_block(c: &mut Ctx) -> Check {
    c.send("core/empty.xml")?;
    c.wait_end("bml1")?;
    c.clean()?;
    c.rec.block_starts_and_stops(&["bml1"])
}

fn invalid_block(c: &mut Ctx) -> Check {
    c.send("core/bmlnoid.xml")?;
    c.sleep_ms(500);
    match c.rec.warnings.len() {
        1 => Ok(()),
        n => Err(Failure(format!("expected exactly 1 warning, got {n}"))),
    }
}

fn face(c: &mut Ctx) -> Check {
    c.send("core/testface.xml")?;
    c.wait_end("bml1")?;
    c.order("bml1:face1", FACE4)?;
    c.clean()?;
    c.rec.block_starts_and_stops(&["bml1"])
}

fn beat_gesture(c: &mut Ctx) -> Check {
    c.send("core/testbeatgesture.xml")?;
    c.wait_end("bml1")?;
    c.order("bml1:g1", GESTURE7)?;
    c.clean()?;
    c.rec.block_starts_and_stops(&["bml1"])
}

fn speech(c: &mut Ctx) -> Check {
    c.send("core/testspeech.xml")?;
    c.wait_end("bml1")?;
    c.order("bml1:speech1", SE)?;
    c.rec.relative_sync_time("bml1:speech1:start", 0.0)?;
    c.rec.block_starts_and_stops(&["bml1"])?;
    c.clean()
}

fn speech2(c: &mut Ctx) -> Check {
    c.send("core/testspeech2.xml")?;
    c.wait_end("bml1")?;
    c.order("bml1:speech1", &["start", "syncstart1", "end"])?;
    c.rec.relative_sync_time("bml1:speech1:start", 6.0)?;
    c.rec.block_starts_and_stops(&["bml1"])?;
    c.clean()
}

fn nod_timed_to_sync(c: &mut Ctx, file: &str) -> Check {
    c.send(file)?;
    c.wait_end("bml1")?;
    c.order("bml1:speech1", &["start", "syncstart1", "end"])?;
    c.order("bml1:nod1", GESTURE7)?;
    c.rec.block_starts_and_stops(&["bml1"])?;
    c.rec.relative_sync_time("bml1:speech1:start", 6.0)?;
    c.rec.relative_sync_time("bml1:nod1:end", 9.0)?;
    c.rec
        .linked_syncs("bml1:speech1:syncstart1", 0.0, "bml1:nod1:start", 0.0)?;
    c.clean()
}

fn speech_nod_timed_to_sync(c: &mut Ctx) -> Check {
    nod_timed_to_sync(c, "core/testspeech_nodtimedtosync.xml")
}

fn speech_nod_timed_to_sync_inverse_order(c: &mut Ctx) -> Check {
    nod_timed_to_sync(c, "core/testspeech_nodtimedtosyncinverseorder.xml")
}

fn speech_gestures_sync_2x(c: &mut Ctx) -> Check {
    c.send("core/testspeechgesturesync2x.xml")?;
    c.wait_end("bml1")?;
    c.clean()?;
    c.order("bml1:beat5", GESTURE7)?;
    c.order("bml1:beatstop", GESTURE7)?;
    c.order("bml1:speech1", SE)?;
    c.order("bml1:speech2", SE)?;
    c.rec
        .linked_syncs("bml1:speech1:start", 0.0, "bml1:beat5:stroke", 0.0)?;
    c.rec
        .linked_syncs("bml1:speech2:start", 0.0, "bml1:beatstop:end", 0.0)?;
    c.rec
        .linked_syncs("bml1:beatstop:start", 0.0, "bml1:beat5:end", 3.0)
}

fn nod(c: &mut Ctx) -> Check {
    c.send("core/testnodlong.xml")?;
    c.wait_end("bml1")?;
    c.rec.block_starts_and_stops(&["bml1"])?;
    c.order("bml1:nod1", GESTURE7)?;
    c.rec.relative_sync_time("bml1:nod1:start", 0.0)?;
    c.rec.relative_sync_time("bml1:nod1:end", 5.0)?;
    c.clean()
}

fn gaze(c: &mut Ctx) -> Check {
    c.send("core/testgaze.xml")?;
    c.wait_end("bml1")?;
    c.rec.block_starts_and_stops(&["bml1"])?;
    c.order("bml1:gaze1", GAZE4)?;
    c.rec.relative_sync_time("bml1:gaze1:start", 1.0)?;
    c.rec.relative_sync_time("bml1:gaze1:end", 10.0)?;
    c.clean()
}

/// The BML 1.0 override: exactly one warning naming one of the two gazes; the other plays.
fn gaze_overlap(c: &mut Ctx) -> Check {
    c.send("core/testgazeoverlap.xml")?;
    c.wait_end("bml1")?;
    c.rec.no_duplicate_feedback()?;
    let w = &c.rec.warnings;
    if w.len() != 1 || w[0].modified_behaviours.len() != 1 {
        return Err(Failure(format!(
            "expected exactly 1 warning naming 1 behaviour, got {} {:?}",
            w.len(),
            w.iter().map(|x| &x.modified_behaviours).collect::<Vec<_>>()
        )));
    }
    c.rec.block_starts_and_stops(&["bml1"])?;
    let other = match w[0].modified_behaviours[0].as_str() {
        "gaze2" => "gaze1",
        "gaze1" => "gaze2",
        x => {
            return Err(Failure(format!(
                "the warning names '{x}', not gaze1 or gaze2"
            )))
        }
    };
    c.order(&format!("bml1:{other}"), GAZE4)?;
    c.rec
        .relative_sync_time(&format!("bml1:{other}:start"), 1.0)?;
    c.rec.relative_sync_time(&format!("bml1:{other}:end"), 10.0)
}

fn point(c: &mut Ctx) -> Check {
    c.send("core/testpoint.xml")?;
    c.wait_end("bml1")?;
    c.rec.block_starts_and_stops(&["bml1"])?;
    c.order("bml1:point1", GESTURE7)?;
    c.rec.relative_sync_time("bml1:point1:start", 1.0)?;
    c.rec.relative_sync_time("bml1:point1:end", 10.0)?;
    c.clean()
}

fn speech_gestures(c: &mut Ctx) -> Check {
    c.send("core/testspeechgestures.xml")?;
    c.wait_end("bml1")?;
    c.sleep_ms(1000);
    c.clean()?;
    c.order("bml1:welkom", &["start", "deicticheart1", "beat1b1", "end"])?;
    for g in ["g1", "relaxleft", "transleft"] {
        c.order(&format!("bml1:{g}"), GESTURE7)?;
    }
    let r = &c.rec;
    r.relative_sync_time("bml1:g1:start", 2.0)?;
    r.relative_sync_time("bml1:g1:end", 4.0)?;
    r.relative_sync_time("bml1:welkom:deicticheart1", 2.0)?;
    r.relative_sync_time("bml1:transleft:start", 0.0)?;
    r.relative_sync_time("bml1:transleft:end", 2.0)?;
    r.relative_sync_time("bml1:relaxleft:start", 4.5)?;
    r.relative_sync_time("bml1:relaxleft:end", 6.8)?;
    r.block_starts_and_stops(&["bml1"])
}

fn very_short_behaviour(c: &mut Ctx) -> Check {
    c.send("core/testshortbeh.xml")?;
    c.wait_end("bml1")?;
    c.rec.no_duplicate_feedback()?;
    c.rec.block_starts_and_stops(&["bml1"])
}

// ---- §1.8 AbstractDraft1RealizerTest ------------------------------------------------------

fn append(c: &mut Ctx) -> Check {
    c.send("core/testspeech.xml")?;
    c.send("core/testspeechappend.xml")?;
    c.wait_end("bml2")?;
    c.order("bml1:speech1", SE)?;
    c.order("bml2:speech1", SE)?;
    c.clean()?;
    c.rec.block_start_linked_to_block_stop("bml2", "bml1")?;
    c.rec.duration_greater_than_zero("bml1")?;
    c.rec.duration_greater_than_zero("bml2")?;
    c.rec.block_starts_and_stops(&["bml1", "bml2"])
}

fn append_replace(c: &mut Ctx) -> Check {
    let (one, two) = (
        "core/appendandreplace/testspeech1.xml",
        "core/appendandreplace/testspeech2.xml",
    );
    c.send(one)?;
    c.send(two)?;
    c.sleep_ms(3000);
    c.send("core/appendandreplace/replace.xml")?;
    c.wait_ends(&["bml1", "bml2", "bml3"])?;
    c.rec.block_starts_and_stops(&["bml1", "bml2", "bml3"])?;
    c.clear();
    c.send(one)?;
    c.send(two)?;
    c.wait_ends(&["bml1", "bml2"])?;
    c.rec.no_exceptions()?;
    c.rec.no_warnings()?;
    c.rec.block_starts_and_stops(&["bml1", "bml2"])
}

fn replace(c: &mut Ctx) -> Check {
    c.send("core/replace/testlongspeechandnod.xml")?;
    c.sleep_ms(700);
    c.send("core/replace/replace.xml")?;
    c.wait_ends(&["bml1", "bml3"])?;
    c.rec.block_starts_and_stops(&["bml1", "bml3"])
}

fn speech_nod_timed_to_sync_constraint_spec(c: &mut Ctx) -> Check {
    c.send("core/testspeechandnod_synctimed.xml")?;
    c.wait_end("bml1")?;
    c.order("bml1:speech1", &["start", "s1", "end"])?;
    c.order("bml1:nod1", GESTURE7)?;
    c.rec.block_starts_and_stops(&["bml1"])?;
    c.rec.relative_sync_time("bml1:speech1:s1", 10.0)?;
    c.rec
        .linked_syncs("bml1:speech1:start", 0.0, "bml1:nod1:start", 0.0)?;
    c.rec
        .sync_before_relative_time("bml1:speech1:start", 10.0)?;
    c.rec.sync_after_relative_time("bml1:speech1:end", 10.0)?;
    c.clean()
}

// ---- §1.9 AbstractBML1RealizerTest ---------------------------------------------------------

fn gaze_waist(c: &mut Ctx) -> Check {
    c.send("core/testgazewaist.xml")?;
    c.wait_end("bml1")?;
    c.order("bml1:gaze1", GAZE4)?;
    c.rec.block_starts_and_stops(&["bml1"])?;
    c.clean()
}

fn posture_shift(c: &mut Ctx) -> Check {
    c.send("core/testpose.xml")?;
    c.wait_end("bml1")?;
    c.rec.relative_sync_time("bml1:pose1:start", 5.0)?;
    c.rec.relative_sync_time("bml1:pose1:end", 8.0)?;
    c.order("bml1:pose1", SE)?;
    c.rec.block_starts_and_stops(&["bml1"])?;
    c.clean()
}

fn gaze_shift(c: &mut Ctx) -> Check {
    c.send("core/testgazeshift.xml")?;
    c.wait_end("bml1")?;
    c.order("bml1:gaze1", SE)?;
    c.rec.block_starts_and_stops(&["bml1"])?;
    c.clean()
}

// ---- §1.10 AbstractASAPRealizerTest --------------------------------------------------------

fn parameter_value_change_from_external_block(c: &mut Ctx) -> Check {
    c.send("asap/parametervaluechange/speechandnod.xml")?;
    c.wait_scheduled("bml1")?;
    c.send("asap/parametervaluechange/volumechange.xml")?;
    c.wait_ends(&["bml1", "bml2"])?;
    c.rec.no_exceptions()?;
    c.rec.no_warnings()?;
    c.rec.no_duplicate_syncs()?;
    c.order("bml1:speech1", &["start", "s1", "end"])?;
    c.order("bml1:speech2", SE)?;
    c.order("bml2:pvc1", SE)?;
    c.rec
        .linked_syncs("bml1:speech1:start", 0.0, "bml2:pvc1:start", 0.0)?;
    c.rec
        .linked_syncs("bml1:speech1:end", 0.0, "bml2:pvc1:end", 0.0)
}

fn activate(c: &mut Ctx) -> Check {
    c.send("asap/activate/testpreplannedspeech1.xml")?;
    c.wait_scheduled("bml1")?;
    c.send("asap/activate/testactivate.xml")?;
    c.wait_ends(&["bml2", "bml1"])?;
    c.order("bml1:speech1", SE)?;
    c.order("bml2:nod1", GESTURE7)?;
    c.rec
        .linked_syncs("bml2:nod1:end", 0.0, "bml1:speech1:start", 0.0)?;
    c.clean()
}

fn parameter_value_change(c: &mut Ctx) -> Check {
    c.send("asap/parametervaluechange.xml")?;
    c.wait_end("bml1")?;
    c.rec.no_exceptions()?;
    c.rec.no_warnings()?;
    c.rec.no_duplicate_syncs()?;
    c.order("bml1:speech1", SE)?;
    c.order("bml1:speech2", SE)?;
    c.order("bml1:pvc1", SE)?;
    c.rec
        .linked_syncs("bml1:speech1:end", 0.0, "bml1:pvc1:end", 0.0)
}

fn preplan(c: &mut Ctx) -> Check {
    c.send("asap/preplan/testspeech1.xml")?;
    c.send("asap/preplan/testspeechinterrupt.xml")?;
    c.sleep_ms(3000);
    c.send("asap/preplan/testnod.xml")?;
    c.wait_ends(&["bml1", "bml2", "bml3"])?;
    c.clean()
}

fn append_after(c: &mut Ctx) -> Check {
    c.send_all(&[
        "asap/appendafter/testspeech1.xml",
        "asap/appendafter/testspeech2.xml",
        "asap/appendafter/testspeech3.xml",
        "asap/appendafter/testnodappendafter.xml",
    ])?;
    c.wait_ends(&["bml3", "bml4"])?;
    c.clean()?;
    for b in ["bml1", "bml2", "bml3"] {
        c.order(&format!("{b}:speech1"), SE)?;
    }
    c.order("bml4:nod1", GESTURE7)?;
    c.rec.after_block("bml1", "bml2", Some(0.5))?;
    c.rec.after_block("bml2", "bml3", Some(0.5))?;
    c.rec.after_block("bml2", "bml4", Some(0.5))
}

fn interrupt(c: &mut Ctx) -> Check {
    c.send("asap/interruptblock/testlongspeechandnod.xml")?;
    c.send("asap/interruptblock/testinterruptbml1.xml")?;
    c.wait_ends(&["bml1", "bml2"])?;
    c.clean()?;
    c.rec.block_start_linked_to_block_stop("bml2", "bml1")
}

fn interrupt_behaviour(c: &mut Ctx) -> Check {
    c.send("asap/interrupt/testlongspeechandnod.xml")?;
    c.wait_start("bml1")?;
    c.send("asap/interrupt/testspeechinterrupt.xml")?;
    c.wait_ends(&["bml1", "bml2"])?;
    c.clean()?;
    c.rec
        .linked_syncs("bml2:i1:start", 0.0, "bml1:speech1:end", 0.0)?;
    c.rec
        .linked_syncs("bml2:i1:start", 0.0, "bml1:nod1:relax", 0.0)
}

fn interrupt_behaviour2_round(c: &mut Ctx) -> Check {
    c.send_all(&[
        "asap/interruptbehavior/testlongspeechandnod.xml",
        "asap/interruptbehavior/testinterruptionspeech.xml",
        "asap/interruptbehavior/testspeechinterrupt.xml",
    ])?;
    c.wait_ends(&["bml1", "bml2", "bml3"])
}

fn interrupt_behaviour2(c: &mut Ctx) -> Check {
    interrupt_behaviour2_round(c)?;
    c.clean()?;
    c.rec.sync_linked_to_block_start("bml1:speech1:s1", "bml3")
}

fn interrupt_behaviour_restart(c: &mut Ctx) -> Check {
    interrupt_behaviour2_round(c)?;
    c.order("bml3:speech1", SE)?;
    c.rec.no_duplicate_feedback()?;
    c.rec
        .sync_linked_to_block_start("bml1:speech1:s1", "bml3")?;
    c.send_text(
        r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="bmlrep" composition="REPLACE"/>"#,
    );
    c.wait_end("bmlrep")?;
    c.clear();
    interrupt_behaviour2_round(c)?;
    c.rec.no_exceptions()?;
    c.rec.no_warnings()?;
    c.rec.no_duplicate_syncs()?;
    c.order("bml3:speech1", SE)?;
    c.rec.sync_linked_to_block_start("bml1:speech1:s1", "bml3")
}

fn bmlt_audio(c: &mut Ctx) -> Check {
    c.send("bmlt/bmltaudio.xml")?;
    c.wait_end("bml1")?;
    c.clean()?;
    c.order("bml1:audio1", SE)
}

fn chunk_pair(c: &mut Ctx, dir: &str) -> Check {
    c.send(&format!("{dir}/firstchunk.xml"))?;
    c.send(&format!("{dir}/secondchunk.xml"))?;
    c.wait_ends(&["bml1", "bml2"])?;
    c.rec.no_exceptions()?;
    c.rec.no_warnings()?;
    c.rec.block_starts_and_stops(&["bml1", "bml2"])?;
    c.rec.no_duplicate_feedback()
}

fn chunk(c: &mut Ctx) -> Check {
    chunk_pair(c, "asap/chunking")?;
    c.order("bml1:g1", GESTURE7)?;
    c.order("bml2:g1", GESTURE7)?;
    c.rec
        .linked_syncs("bml1:g1:relax", 0.0, "bml2:g1:start", 0.0)
}

fn chunk_conflict_resolution(c: &mut Ctx) -> Check {
    chunk_pair(c, "asap/chunkingconflictres")?;
    c.rec
        .linked_syncs("bml1:g1:relax", 0.0, "bml2:g1:start", 0.0)?;
    c.rec.linked_syncs("bml1:g1:relax", 0.0, "bml1:g1:end", 0.0)
}

fn murml(c: &mut Ctx, file: &str, behaviour: &str, syncs: &[&str]) -> Check {
    c.send(file)?;
    c.wait_end("bml1")?;
    c.rec.no_exceptions()?;
    c.rec.no_warnings()?;
    c.rec.block_starts_and_stops(&["bml1"])?;
    c.order(&format!("bml1:{behaviour}"), syncs)
}

fn murml_face(c: &mut Ctx) -> Check {
    murml(c, "murml/murmlfacekeyframe.xml", "face1", FACE4)
}

fn murml_body(c: &mut Ctx) -> Check {
    murml(c, "murml/murmlbodykeyframe.xml", "gesture1", GESTURE7)
}

fn murml_palm_orientation(c: &mut Ctx) -> Check {
    murml(c, "murml/murmlpalmorientation.xml", "gesture1", GESTURE7)
}

fn murml_relative_palm_orientation(c: &mut Ctx) -> Check {
    murml(
        c,
        "murml/murmlrelativepalmorientation.xml",
        "gesture1",
        GESTURE7,
    )
}

// ---- the incremental-speech fixture ---------------------------------------------------------

fn hesitated_speech(c: &mut Ctx) -> Check {
    c.send("bmlis/filler.xml")?;
    c.wait_end("bml1")?;
    c.clean()?;
    c.rec.relative_sync_time("bml1:speech1:start", 0.0)?;
    c.rec
        .sync_after_sync("bml1:speech1:end", "bml1:speech1:relax")
}

fn chunk_speech(c: &mut Ctx) -> Check {
    chunk_pair(c, "asap/chunkspeech")?;
    c.rec
        .linked_syncs("bml1:speech1:relax", 0.0, "bml2:speech1:start", 0.0)
}

fn speech_retime(c: &mut Ctx) -> Check {
    c.send("bmlis/speech_retime.xml")?;
    c.wait_end("bml1")?;
    c.clean()?;
    c.rec.relative_sync_time("bml1:speech1:start", 0.5)?;
    c.rec.relative_sync_time("bml1:speech1:s1", 1.0)?;
    c.rec.relative_sync_time("bml1:speech1:end", 2.0)
}

macro_rules! tests {
    ($($origin:literal ($fixture:ident): $($name:literal => $f:ident),+;)+) => {
        /// Every test, in the catalogue's order.
        pub const TESTS: &[Test] = &[$($(Test {
            name: $name,
            origin: $origin,
            fixture: Fixture::$fixture,
            run: $f,
        }),+),+];
    };
}

tests! {
    "AbstractRealizerTest" (Standard):
        "testEmptyBlock" => empty_block,
        "testInvalidBlock" => invalid_block,
        "testFace" => face,
        "testBeatGesture" => beat_gesture,
        "testSpeech" => speech,
        "testSpeech2" => speech2,
        "testSpeechNodTimedToSync" => speech_nod_timed_to_sync,
        "testSpeechNodTimedToSyncInverseOrder" => speech_nod_timed_to_sync_inverse_order,
        "testSpeechGesturesSync2x" => speech_gestures_sync_2x,
        "testNod" => nod,
        "testGaze" => gaze,
        "testGazeOverlap" => gaze_overlap,
        "testPoint" => point,
        "testSpeechGestures" => speech_gestures,
        "testVeryShortBehaviour" => very_short_behaviour;
    "AbstractDraft1RealizerTest" (Standard):
        "testAppend" => append,
        "testAppendReplace" => append_replace,
        "testReplace" => replace,
        "testSpeechNodTimedToSyncConstraintSpec" => speech_nod_timed_to_sync_constraint_spec;
    "AbstractBML1RealizerTest" (Standard):
        "testGazeWaist" => gaze_waist,
        "testPostureShift" => posture_shift,
        "testGazeShift" => gaze_shift;
    "AbstractASAPRealizerTest" (Standard):
        "testParameterValueChangeFromExternalBlock" => parameter_value_change_from_external_block,
        "testActivate" => activate,
        "testParameterValueChange" => parameter_value_change,
        "testPreplan" => preplan,
        "testAppendAfter" => append_after,
        "testInterrupt" => interrupt,
        "testInterruptBehaviour" => interrupt_behaviour,
        "testInterruptBehaviour2" => interrupt_behaviour2,
        "testInterruptBehaviourRestart" => interrupt_behaviour_restart,
        "testBMLTAudio" => bmlt_audio,
        "testChunk" => chunk,
        "testChunkConflictResolution" => chunk_conflict_resolution,
        "testMURMLFace" => murml_face,
        "testMURMLBody" => murml_body,
        "testMURMLPalmOrientation" => murml_palm_orientation,
        "testMURMLRelativePalmOrientation" => murml_relative_palm_orientation;
    "AsapRealizerTesterIncrementalSpeech" (IncrementalSpeech):
        "testHesitatedSpeech" => hesitated_speech,
        "testChunkSpeech" => chunk_speech,
        "testSpeechRetime" => speech_retime;
}

/// The result of one test.
#[derive(Debug, Clone, PartialEq)]
pub struct Outcome {
    /// Test name.
    pub name: &'static str,
    /// `None` if it passed, else why it failed.
    pub failure: Option<String>,
}

/// Runs the tests whose name contains `filter` (all if empty), resetting the port before each,
/// and calls `progress(index, total, outcome)` after each one.
pub fn run(
    port: &mut dyn TestPort,
    filter: &str,
    mut progress: impl FnMut(usize, usize, &Outcome),
) -> Vec<Outcome> {
    let selected: Vec<&Test> = TESTS.iter().filter(|t| t.name.contains(filter)).collect();
    let mut out = Vec::new();
    for (i, t) in selected.iter().enumerate() {
        let failure = match port.reset(t.fixture) {
            Err(e) => Some(format!("reset failed: {e}")),
            Ok(()) => {
                let mut ctx = Ctx::new(port);
                (t.run)(&mut ctx).err().map(|f| f.0)
            }
        };
        let o = Outcome {
            name: t.name,
            failure,
        };
        progress(i, selected.len(), &o);
        out.push(o);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_suite_has_the_41_catalogued_tests_with_unique_names_and_existing_files() {
        assert_eq!(TESTS.len(), 41);
        let mut names: Vec<&str> = TESTS.iter().map(|t| t.name).collect();
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), 41);
        assert_eq!(crate::files::FILES.len(), 59);
    }
}
