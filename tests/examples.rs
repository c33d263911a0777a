//! The documented examples (`fixtures/examples/README.md`) run through `bmlr run`, and their
//! feedback is what the README says.

use std::process::Command;

use bml_realizer::language::feedback::{self, BlockStatus, Feedback};

const README: &str = include_str!("../fixtures/examples/README.md");

/// Runs the example command line `cmd` (as written in the README) and returns its feedback.
fn run(cmd: &str) -> Vec<Feedback> {
    assert!(
        README.contains(&format!("bmlr {cmd}\n")),
        "README shows `bmlr {cmd}`"
    );
    let out = Command::new(env!("CARGO_BIN_EXE_bmlr"))
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .args(cmd.split_whitespace())
        .output()
        .unwrap();
    assert!(out.status.success());
    assert!(
        out.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .map(|l| feedback::from_line(l).unwrap())
        .collect()
}

fn sync(fb: &[Feedback], id: &str) -> f64 {
    fb.iter()
        .find_map(|f| match f {
            Feedback::SyncPointProgress(s)
                if format!("{}:{}:{}", s.block, s.behaviour, s.sync) == id =>
            {
                Some(s.global_time)
            }
            _ => None,
        })
        .unwrap_or_else(|| panic!("no {id}"))
}

fn block(fb: &[Feedback], id: &str, which: &str) -> (f64, Option<BlockStatus>) {
    fb.iter()
        .find_map(|f| match f {
            Feedback::BlockProgress(p) if p.block == id && p.sync == which => {
                Some((feedback::round_ms(p.global_time), p.status))
            }
            _ => None,
        })
        .unwrap_or_else(|| panic!("no {id}:{which}"))
}

fn ms(t: f64) -> f64 {
    feedback::round_ms(t)
}

fn no_warnings(fb: &[Feedback]) {
    assert!(!fb.iter().any(|f| matches!(f, Feedback::Warning(_))));
}

#[test]
fn welcome() {
    let fb = run("run fixtures/examples/welcome.xml");
    no_warnings(&fb);
    // the speech as the built-in TTS says it: "welcome" starts at the stress sync
    use bml_realizer::character::voice::Tts;
    let text = [
        bml_realizer::language::bml::TextPart::Text("Hello and ".into()),
        bml_realizer::language::bml::TextPart::Sync(bml_realizer::language::bml::Id::new_static(
            "stress",
        )),
        bml_realizer::language::bml::TextPart::Text("welcome to the realizer!".into()),
    ];
    let u = bml_realizer::character::voice::builtin::Builtin
        .speak(&text)
        .unwrap();
    assert_eq!(u.words[2].text, "welcome");
    // the beat's stroke on the stress; its preparation, paced for the hand's travel, needs more
    // time than the speech has before "welcome", so the beat starts the block and the speech
    // waits for it
    let stress = sync(&fb, "greet:hello:stress");
    let speech = sync(&fb, "greet:hello:start");
    assert_eq!(ms(sync(&fb, "greet:beat:stroke")), ms(stress));
    assert_eq!(sync(&fb, "greet:beat:start"), 0.0);
    let preparation = sync(&fb, "greet:beat:ready");
    assert!((0.5..0.7).contains(&preparation), "{preparation}");
    assert_eq!(ms(stress), ms(speech + u.words[2].start));
    assert_eq!(ms(sync(&fb, "greet:hello:end")), ms(speech + u.end));
    let u_end = speech + u.end;
    assert_eq!(ms(sync(&fb, "greet:nod:start")), ms(u_end));
    let end = ms(sync(&fb, "greet:nod:end"));
    assert_eq!(block(&fb, "greet", "end"), (end, Some(BlockStatus::Done)));
}

#[test]
fn faces() {
    let fb = run("run fixtures/examples/faces.xml");
    no_warnings(&fb);
    for (id, start) in [("f:a", 0.0), ("f:b", 1.5), ("f:c", 3.0)] {
        assert_eq!(ms(sync(&fb, &format!("{id}:start"))), start);
        assert_eq!(ms(sync(&fb, &format!("{id}:attackPeak"))), ms(start + 0.3));
        assert_eq!(ms(sync(&fb, &format!("{id}:end"))), start + 1.5);
    }
    assert_eq!(ms(sync(&fb, "f:s:start")), 4.5);
}

#[test]
fn gaze_then_point() {
    let fb = run("run fixtures/examples/gaze-then-point.xml");
    no_warnings(&fb);
    assert_eq!(ms(sync(&fb, "look:gaze1:ready")), 0.8);
    assert_eq!(ms(sync(&fb, "look:point1:start")), 0.8);
    assert_eq!(ms(sync(&fb, "look:point1:end")), 4.0);
    assert_eq!(block(&fb, "look", "end").0, 4.0);
}

#[test]
fn interrupted_speech() {
    let fb =
        run("run fixtures/examples/long-speech.xml +1.5 fixtures/examples/interrupt-speech.xml");
    no_warnings(&fb);
    assert_eq!(sync(&fb, "talk:speech1:end"), 1.5);
    assert_eq!(sync(&fb, "talk:nod1:relax"), 1.5);
    assert_eq!(ms(sync(&fb, "talk:nod1:end")), 2.083);
    assert_eq!(
        block(&fb, "talk", "end"),
        (2.083, Some(BlockStatus::Interrupted))
    );
}

#[test]
fn preplanned_reply() {
    let fb = run("run fixtures/examples/reply.xml +2 fixtures/examples/listen.xml");
    no_warnings(&fb);
    // scheduled at once: the PENDING prediction comes before anything starts
    let pending = fb.iter().position(|f| {
        matches!(f, Feedback::Prediction(p) if p.blocks[0].id == "reply" && p.blocks[0].status == Some(BlockStatus::Pending))
    });
    let first_start = fb
        .iter()
        .position(|f| matches!(f, Feedback::BlockProgress(_)))
        .unwrap();
    assert!(pending.unwrap() < first_start);
    assert_eq!(block(&fb, "turn", "start").0, 2.0);
    assert_eq!(block(&fb, "reply", "start").0, 2.0);
    assert_eq!(sync(&fb, "reply:answer:start"), 2.0);
    assert_eq!(block(&fb, "reply", "end").1, Some(BlockStatus::Done));
}

#[test]
fn motion_from_data() {
    let fb = run("run fixtures/examples/lift-and-wave.xml");
    no_warnings(&fb);
    assert_eq!(ms(sync(&fb, "moves:raise:end")), 1.0);
    assert_eq!(ms(sync(&fb, "moves:lead:start")), 1.0);
    assert_eq!(ms(sync(&fb, "moves:lead:end")), 1.5);
    assert_eq!(ms(sync(&fb, "moves:lift:start")), 1.5);
    assert_eq!(ms(sync(&fb, "moves:lift:stroke")), 2.25);
    // HELLO: the procedural wave at its preferred 3 s
    assert_eq!(ms(sync(&fb, "moves:hello:end")), 3.5);
    assert_eq!(ms(sync(&fb, "moves:sway:end")), 3.0);
    assert_eq!(block(&fb, "moves", "end"), (3.5, Some(BlockStatus::Done)));
}

#[test]
fn balancing_while_gesturing() {
    let fb = run("run fixtures/examples/balance.xml");
    no_warnings(&fb);
    assert_eq!(ms(sync(&fb, "stand:balance:start")), 0.0);
    assert_eq!(ms(sync(&fb, "stand:wave:start")), 0.5);
    assert_eq!(sync(&fb, "stand:frame:start"), sync(&fb, "stand:wave:end"));
    assert_eq!(block(&fb, "stand", "end"), (6.0, Some(BlockStatus::Done)));
}

#[test]
fn two_characters_in_one_world() {
    let fb = run("run --world fixtures/examples/world.json fixtures/examples/two-alice.xml fixtures/examples/two-bob.xml");
    no_warnings(&fb);
    assert_eq!(ms(sync(&fb, "a:g:ready")), 1.0);
    assert_eq!(ms(sync(&fb, "b:g:ready")), 1.0);
    assert_eq!(ms(sync(&fb, "b:p:start")), 1.0);
    assert_eq!(block(&fb, "a", "end"), (6.0, Some(BlockStatus::Done)));
    assert_eq!(block(&fb, "b", "end"), (6.0, Some(BlockStatus::Done)));
}

#[test]
fn walking_to_the_door_then_speaking() {
    let fb = run("run --world fixtures/examples/room.json fixtures/examples/walk-to-door.xml");
    no_warnings(&fb);
    assert_eq!(ms(sync(&fb, "door:w:start")), 0.0);
    assert_eq!(ms(sync(&fb, "door:w:ready")), 2.263);
    assert_eq!(ms(sync(&fb, "door:w:relax")), 4.446);
    assert_eq!(sync(&fb, "door:look:start"), sync(&fb, "door:w:relax"));
    assert_eq!(ms(sync(&fb, "door:w:end")), 6.025);
    assert_eq!(sync(&fb, "door:s:start"), sync(&fb, "door:w:end"));
    assert_eq!(block(&fb, "door", "end").1, Some(BlockStatus::Done));
}

#[test]
fn forty_walkers_cross_the_plaza_round_the_group() {
    let fb = run("run --world fixtures/examples/plaza/world.json fixtures/examples/plaza");
    no_warnings(&fb);
    for k in 0..40 {
        let (t, status) = block(&fb, &format!("cross{k:02}"), "end");
        assert_eq!(status, Some(BlockStatus::Done), "cross{k:02}");
        assert!(t < 35.0, "cross{k:02} ended at {t} s");
    }
}
