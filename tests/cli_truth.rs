//! The commands tell the truth, through the built binary: `bmlr validate` refuses what `run` would
//! refuse (contradictory constraints, a root outside the BML 1.0 namespace), accepts the standard's
//! `<lexeme>` child form, warns about lexemes nothing moves; misspelled joints in `--assets` files
//! are errors.

use std::process::Command;

mod common;
use common::bmlr;

const NS: &str = r#"xmlns="http://www.bml-initiative.org/bml/bml-1.0""#;

/// A temporary directory of this test process, with `files` written into it.
fn dir_with(name: &str, files: &[(&str, &str)]) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("bmlr-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    for (file, text) in files {
        std::fs::write(dir.join(file), text).unwrap();
    }
    dir
}

fn validate(name: &str, body: &str) -> (i32, String) {
    let dir = dir_with(
        name,
        &[("b.xml", &format!(r#"<bml {NS} id="b1">{body}</bml>"#))],
    );
    let (code, out, _) = bmlr(&["validate", dir.join("b.xml").to_str().unwrap()], "");
    (code, out)
}

#[test]
fn validate_refuses_contradictory_constraints_naming_them() {
    for (name, body, constraints) in [
        (
            "cycle",
            r#"<gesture id="a" lexeme="BEAT" start="b:end"/><gesture id="b" lexeme="BEAT" start="a:end"/>"#,
            ["a:start = b:end", "b:start = a:end"],
        ),
        (
            "inverted",
            r#"<speech id="s1"><text>Hello there world</text></speech>
               <gesture id="g1" lexeme="BEAT" start="s1:end" end="s1:start"/>"#,
            ["g1:start = s1:end", "g1:end = s1:start"],
        ),
    ] {
        let (code, out) = validate(name, body);
        assert_eq!(code, 1, "{out}");
        assert!(out.contains("error[contradictory-constraints]"), "{out}");
        for c in constraints {
            assert!(out.contains(c), "{c} in {out}");
        }
    }
    // and a block that only needs stretching is valid
    let (code, out) = validate(
        "stretch",
        r#"<speech id="s1"><text>Hello <sync id="w"/>there world</text></speech>
           <gesture id="g1" lexeme="BEAT" start="s1:start" stroke="s1:w"/>"#,
    );
    assert_eq!(code, 0, "{out}");
}

#[test]
fn a_bml_root_outside_the_bml_namespace_is_an_error() {
    for (name, root) in [
        ("nons", r#"<bml id="b1">"#),
        (
            "otherns",
            r#"<bml xmlns="http://example.org/other" id="b1">"#,
        ),
    ] {
        let dir = dir_with(
            name,
            &[(
                "b.xml",
                &format!(r#"{root}<gesture id="g1" lexeme="BEAT"/></bml>"#),
            )],
        );
        let (code, out, _) = bmlr(&["validate", dir.join("b.xml").to_str().unwrap()], "");
        assert_eq!(code, 1, "{out}");
        assert!(out.contains("error[wrong-root]"), "{out}");
    }
}

#[test]
fn face_and_face_shift_take_the_standards_lexeme_child() {
    let (code, out) = validate(
        "facechild",
        r#"<face id="f"><lexeme lexeme="RAISE_BROWS" amount="0.7"/></face>
           <faceShift id="fs"><lexeme lexeme="RAISE_BROWS" amount="0.4"/></faceShift>"#,
    );
    assert_eq!(code, 0, "{out}");
    let parsed = bml_realizer::language::bml::load(&format!(
        r#"<bml {NS} id="b1"><face id="f"><lexeme lexeme="RAISE_BROWS" amount="0.7"/></face></bml>"#
    ))
    .unwrap();
    let bml_realizer::language::bml::BehaviourKind::Face(f) = &parsed.block.behaviours[0].kind
    else {
        panic!("a face")
    };
    assert_eq!(
        (f.lexeme.as_deref(), f.amount),
        (Some("RAISE_BROWS"), Some(0.7))
    );
    // neither form, or both, is an error
    let (code, out) = validate("facenone", r#"<face id="f"/><faceShift id="fs"/>"#);
    assert_eq!(code, 1, "{out}");
    assert_eq!(out.matches("error[missing-attribute]").count(), 2, "{out}");
    let (code, out) = validate(
        "faceboth",
        r#"<face id="f" lexeme="RAISE_BROWS"><lexeme lexeme="FROWN"/></face>"#,
    );
    assert_eq!(code, 1, "{out}");
}

#[test]
fn lexemes_that_nothing_moves_warn_in_validate_and_at_run_time_once() {
    let body = r#"<gesture id="g1" lexeme="SHRUGGY"/><gesture id="g2" lexeme="BEAT"/>"#;
    let (code, out) = validate("unbound", body);
    assert_eq!(code, 0, "{out}");
    assert!(
        out.contains("warning[unknown-lexeme]") && out.contains("SHRUGGY"),
        "{out}"
    );
    assert!(!out.contains("'BEAT'"), "{out}");
    let (code, out, _) = bmlr(&["run", "-"], &format!(r#"<bml {NS} id="b1">{body}</bml>"#));
    assert_eq!(code, 0);
    let warnings: Vec<&str> = out
        .lines()
        .filter(|l| l.contains("warningFeedback"))
        .collect();
    assert_eq!(warnings.len(), 1, "{out}");
    assert!(
        warnings[0].contains(r#"id="b1:g1" type="LEXEME_NOT_SUPPORTED""#),
        "{out}"
    );
    // it still plays its timing
    assert!(out.contains(r#"id="b1:g1:end""#), "{out}");
}

#[test]
fn a_misspelled_joint_in_an_assets_file_is_an_error() {
    let unit = r#"{"units": {"swing": {"keys": {"start": 0, "end": 1},
        "duration": {"preferred": 1, "min": 0.5, "max": 3},
        "rotations": {"r_shouldr": ["0", "0", "40"]}}}}"#;
    let dir = dir_with("badjoint", &[("units.json", unit)]);
    let (code, _, err) = bmlr(&["run", "--assets", dir.to_str().unwrap(), "-"], "");
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("units.json") && err.contains("'r_shouldr'"),
        "{err}"
    );
    let keys = r#"{"gestures": [{"lexeme": "TAP", "keys": {"stroke": {"r_elbw": [0, 0, 30]}}}]}"#;
    let dir = dir_with("badkey", &[("gestures.json", keys)]);
    let (code, _, err) = bmlr(&["run", "--assets", dir.to_str().unwrap(), "-"], "");
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("gestures.json") && err.contains("'r_elbw'"),
        "{err}"
    );
}

#[test]
fn a_world_file_gives_named_and_moving_targets_and_unknown_targets_list_them() {
    let (code, out, err) = bmlr(
        &[
            "run",
            "--world",
            "fixtures/examples/world.json",
            "fixtures/examples/follow-walker.xml",
        ],
        "",
    );
    assert_eq!(code, 0, "{err}");
    assert!(!out.contains("warningFeedback"), "{out}");
    assert!(out.contains(r#"id="follow:end""#), "{out}");
    // without the file, the targets are unknown, and the warning lists what the world has
    let (_, out, _) = bmlr(&["run", "fixtures/examples/follow-walker.xml"], "");
    assert!(
        out.contains("no target &apos;walker&apos; in the world (it has bluebox, speaker, user"),
        "{out}"
    );
    let (code, out, _) = bmlr(
        &[
            "plan",
            "--world",
            "fixtures/examples/world.json",
            "fixtures/examples/follow-walker.xml",
        ],
        "",
    );
    assert_eq!(code, 0, "{out}");
    // a bad file: exit 2, naming it
    let dir = dir_with("badworld", &[("w.json", r#"{"points": {"a": [0, 1]}}"#)]);
    let w = dir.join("w.json");
    for cmd in ["run", "plan"] {
        let (code, _, err) = bmlr(
            &[
                cmd,
                "--world",
                w.to_str().unwrap(),
                "fixtures/examples/welcome.xml",
            ],
            "",
        );
        assert_eq!(code, 2, "{err}");
        assert!(err.contains("w.json"), "{err}");
    }
    let (code, _, err) = bmlr(&["serve", "--stdio", "--world", w.to_str().unwrap()], "");
    assert_eq!(code, 2, "{err}");
}

/// The head follows a point moving along its path: looking at it at 0.5 s and at 3.5 s turns
/// the head to opposite sides.
#[test]
fn gaze_follows_a_point_moving_along_its_path() {
    use bml_realizer::character::body::Skeleton;
    use bml_realizer::realizer::Realizer;
    let mut r = Realizer::new();
    let text = std::fs::read_to_string("fixtures/examples/world.json").unwrap();
    *r.world_mut() = bml_realizer::world::World::from_json(&text).unwrap().0;
    let bml = std::fs::read_to_string("fixtures/examples/follow-walker.xml").unwrap();
    r.perform_bml(&bml).unwrap();
    let skeleton = Skeleton::adult();
    let skull = skeleton.joint("skullbase").unwrap();
    let mut facing = |t: f64| {
        let frame = r.tick(t);
        let (_, q) = frame.poses[0].pose.joint_world(&skeleton, skull);
        let forward = q * glam::Vec3::Z;
        forward.x
    };
    let (early, late) = (facing(0.5), facing(3.5));
    // +x is the character's left: the walker starts there and ends on the right
    assert!(
        early > 0.2 && late < -0.2,
        "facing x at 0.5 s {early}, at 3.5 s {late}"
    );
}

#[test]
fn run_and_plan_exit_1_after_running_the_rest_when_a_block_is_invalid_and_name_its_file() {
    let dir = dir_with(
        "invalid",
        &[
            // not well-formed, but its id can be read
            (
                "bad.xml",
                &format!(r#"<bml {NS} id="bad"><gesture lexeme="BEAT"></bml>"#),
            ),
            ("noid.xml", "<bml <<"),
        ],
    );
    let (bad, noid) = (dir.join("bad.xml"), dir.join("noid.xml"));
    let (bad, noid) = (bad.to_str().unwrap(), noid.to_str().unwrap());
    let (code, out, err) = bmlr(&["run", bad, "fixtures/examples/welcome.xml", noid], "");
    assert_eq!(code, 1, "{err}");
    assert!(out.contains(r#"id="greet:end""#), "the rest ran: {out}");
    let warnings: Vec<&str> = out
        .lines()
        .filter(|l| l.contains("PARSING_FAILURE"))
        .collect();
    assert_eq!(warnings.len(), 2, "{out}");
    assert!(
        warnings[0].contains(r#"id="bad""#) && warnings[0].contains(&format!("{bad}:1:")),
        "{}",
        warnings[0]
    );
    assert!(
        warnings[1].contains(r#"id="&lt;no id&gt;""#) && warnings[1].contains(noid),
        "{}",
        warnings[1]
    );
    assert!(err.contains("2 blocks could not be parsed"), "{err}");
    let (code, _, _) = bmlr(&["plan", bad, "fixtures/examples/welcome.xml"], "");
    assert_eq!(code, 1);
    // on stdin too
    let stream = format!(r#"<bml {NS} id="x"><gesture lexeme="BEAT"></bml>"#);
    let (code, out, _) = bmlr(&["run", "-"], &stream);
    assert_eq!(code, 1);
    assert!(out.contains("&lt;stdin&gt;:1:"), "{out}");
    let (code, _, _) = bmlr(&["run", "fixtures/examples/welcome.xml"], "");
    assert_eq!(code, 0);
}

#[test]
fn bvh_records_the_character_that_received_the_blocks() {
    let dir = dir_with(
        "bvhchar",
        &[(
            "anna.xml",
            &format!(
                r#"<bml {NS} id="b1" characterId="anna"><gesture id="g1" lexeme="BEAT"/></bml>"#
            ),
        )],
    );
    let (file, bvh) = (dir.join("anna.xml"), dir.join("out.bvh"));
    let (file, bvh) = (file.to_str().unwrap(), bvh.to_str().unwrap());
    let (code, _, err) = bmlr(&["run", "--bvh", bvh, file], "");
    assert_eq!(code, 0, "{err}");
    // the right wrist moves: the BVH's motion lines differ over time
    let text = std::fs::read_to_string(bvh).unwrap();
    let motion: Vec<&str> = text
        .split("Frame Time:")
        .nth(1)
        .unwrap()
        .lines()
        .skip(1)
        .collect();
    assert!(motion.len() > 30);
    assert_ne!(motion[0], motion[motion.len() / 2], "a still BVH");
    // a character that received nothing: said so, exit 1
    let (code, _, err) = bmlr(&["run", "--bvh", bvh, "--character", "bob", file], "");
    assert_eq!(code, 1, "{err}");
    assert!(
        err.contains("'bob' received no blocks") && err.contains("'anna'"),
        "{err}"
    );
}

#[test]
fn writing_into_a_closed_pipe_is_no_panic() {
    use std::process::Stdio;
    for args in [
        vec![
            "validate",
            "fixtures/realizertester/bml-1/core/testspeech.xml",
            "fixtures/realizertester/bml-1/core/testgaze.xml",
        ],
        vec!["run", "fixtures/examples/welcome.xml"],
        vec!["plan", "fixtures/examples/welcome.xml"],
    ] {
        let mut child = Command::new(env!("CARGO_BIN_EXE_bmlr"))
            .args(&args)
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        drop(child.stdout.take()); // the reader goes away before anything is written
        let out = child.wait_with_output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!err.contains("panicked"), "{args:?}: {err}");
        assert_ne!(out.status.code(), Some(101), "{args:?}: {err}");
    }
}

#[test]
fn serve_without_a_port_names_both_and_conformance_says_when_its_realizer_cannot_start() {
    let (code, _, err) = bmlr(&["serve"], "");
    assert_eq!(code, 2);
    assert!(err.contains("--stdio") && err.contains("--tcp"), "{err}");
    let (code, _, err) = bmlr(&["conformance", "--realizer", "no-such-realizer-cmd"], "");
    assert_eq!(code, 2);
    assert!(
        err.contains("cannot start") && err.contains("not found"),
        "{err}"
    );
    // `bmlr` in the command is this binary (here it exits at once on a bad flag)
    let (code, _, err) = bmlr(
        &["conformance", "--realizer", "bmlr serve --no-such-flag"],
        "",
    );
    assert_eq!(code, 2);
    assert!(
        err.contains(env!("CARGO_BIN_EXE_bmlr")) && err.contains("exited at once"),
        "{err}"
    );
}

/// A repeated head and a gesture whose stroke is tied to the head's third stroke (`stroke:2`,
/// counted from 0 as OpenBMLParser does).
const THIRD_STROKE: &str = r#"<head id="h" lexeme="NOD" repetition="3" start="0"/><gesture id="g" lexeme="BEAT" stroke="h:stroke:2"/>"#;

/// The row of docs/bml-support.md on stroke iterations.
fn stroke_iteration_row() -> String {
    let docs = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/docs/bml-support.md"))
        .unwrap();
    let row = docs.lines().find(|l| l.starts_with("| stroke iterations"));
    row.expect("docs/bml-support.md has a row on stroke iterations")
        .to_string()
}

#[test]
fn docs_say_stroke_iterations_are_realized_and_their_example_validates() {
    let row = stroke_iteration_row();
    assert!(row.contains("| realized"), "{row}");
    assert!(
        row.contains("unknown-sync-point") && row.contains("NO_SUCH_TARGET"),
        "{row}"
    );
    // the example the row gives is valid BML to validate
    let example = row.split('`').nth(1).unwrap();
    assert_eq!(example, "h1:stroke:2");
    let body = format!(
        r#"<head id="h1" lexeme="NOD" repetition="3"/><gesture id="g" lexeme="BEAT" stroke="{example}"/>"#
    );
    let (code, out) = validate("docs-stroke", &body);
    assert_eq!(code, 0, "{out}");
}

#[test]
fn validate_takes_a_repeated_head_s_later_strokes_and_refuses_strokes_a_behaviour_lacks() {
    let (code, out) = validate("stroke-ok", THIRD_STROKE);
    assert_eq!(code, 0, "{out}");
    for (name, body, says) in [
        (
            "stroke-gesture",
            r#"<gesture id="g1" lexeme="BEAT"/><head id="h" lexeme="NOD" stroke="g1:stroke:2"/>"#,
            "error[unknown-sync-point]: <gesture> 'g1' has no sync point 'stroke:2'",
        ),
        (
            "stroke-past",
            r#"<head id="h" lexeme="NOD" repetition="3"/><gesture id="g" lexeme="BEAT" stroke="h:stroke:3"/>"#,
            "sync points are start, ready, strokeStart, stroke, stroke:1, stroke:2, strokeEnd",
        ),
        (
            "stroke-start",
            r#"<head id="h" lexeme="NOD" repetition="3"/><gesture id="g" lexeme="BEAT" stroke="b1:h:start:2"/>"#,
            "error[malformed-sync-ref]",
        ),
        (
            "stroke-many",
            r#"<head id="h" lexeme="NOD" repetition="1001"/>"#,
            "error[limit-exceeded]: attribute 'repetition' is 1001, more than the limit of 1000",
        ),
    ] {
        let (code, out) = validate(name, body);
        assert_eq!(code, 1, "{name}: {out}");
        assert!(out.contains(says), "{name}: {out}");
    }
}

#[test]
fn plan_and_run_tie_a_gesture_to_a_repeated_head_s_third_stroke() {
    let dir = dir_with(
        "stroke-run",
        &[(
            "b.xml",
            &format!(r#"<bml {NS} id="b1">{THIRD_STROKE}</bml>"#),
        )],
    );
    let file = dir.join("b.xml");
    let (code, out, err) = bmlr(&["plan", file.to_str().unwrap()], "");
    assert_eq!(code, 0, "{err}");
    for line in [
        "b1:h:stroke 0.300",
        "b1:h:stroke:1 0.800",
        "b1:h:stroke:2 1.300",
        "b1:g:stroke 1.300",
    ] {
        assert!(out.contains(line), "{line} not in\n{out}");
    }
    let (code, out, err) = bmlr(&["run", file.to_str().unwrap()], "");
    assert_eq!(code, 0, "{err}");
    for line in [
        r#"id="b1:h:stroke:1" time="0.800""#,
        r#"id="b1:h:stroke:2" time="1.300""#,
        r#"id="b1:g:stroke" time="1.300""#,
    ] {
        assert!(out.contains(line), "{line} not in\n{out}");
    }
    assert!(!out.contains("warningFeedback"), "{out}");
    // the feedback reads back (bmlr diff of the log against itself)
    std::fs::write(dir.join("fb.xml"), &out).unwrap();
    let fb = dir.join("fb.xml");
    let (code, said, err) = bmlr(&["diff", fb.to_str().unwrap(), fb.to_str().unwrap()], "");
    assert_eq!(code, 0, "{said}{err}");
    // to another block's head without that stroke: dropped, saying which strokes there are
    let other = dir.join("c.xml");
    std::fs::write(
        &other,
        format!(
            r#"<bml {NS} id="b2"><gesture id="g" lexeme="BEAT" stroke="b1:g:stroke:1"/></bml>"#
        ),
    )
    .unwrap();
    let (_, out, _) = bmlr(
        &["run", file.to_str().unwrap(), other.to_str().unwrap()],
        "",
    );
    let warning = out
        .lines()
        .find(|l| l.contains("NO_SUCH_TARGET"))
        .unwrap_or_default();
    assert!(
        warning.contains("id=\"b2:g\"")
            && warning.contains("has no sync point &apos;stroke:1&apos;"),
        "{out}"
    );
}
