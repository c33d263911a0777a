//! The commands tell the truth, through the built binary: `bmlr validate` refuses what `run` would
//! refuse (contradictory constraints, a root outside the BML 1.0 namespace), accepts the standard's
//! `<lexeme>` child form, warns about lexemes nothing moves; misspelled joints in `--assets` files
//! are errors.

use std::process::Command;

const NS: &str = r#"xmlns="http://www.bml-initiative.org/bml/bml-1.0""#;

fn bmlr(args: &[&str], input: &str) -> (i32, String, String) {
    use std::io::Write;
    use std::process::Stdio;
    let mut child = Command::new(env!("CARGO_BIN_EXE_bmlr"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let _ = child.stdin.take().unwrap().write_all(input.as_bytes());
    let out = child.wait_with_output().unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

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
    let parsed = bml_realizer::bml::load(&format!(
        r#"<bml {NS} id="b1"><face id="f"><lexeme lexeme="RAISE_BROWS" amount="0.7"/></face></bml>"#
    ))
    .unwrap();
    let bml_realizer::bml::BehaviourKind::Face(f) = &parsed.block.behaviours[0].kind else {
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
