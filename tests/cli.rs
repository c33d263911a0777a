//! The `bmlr` command line: exit codes and output of `bmlr validate` (DESIGN §5).

use std::process::Command;

fn bmlr(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_bmlr"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

const RT: &str = "fixtures/realizertester/bml-1";

#[test]
fn validate_valid_file_exits_0() {
    let (code, out, _) = bmlr(&["validate", &format!("{RT}/core/testspeechgestures.xml")]);
    assert_eq!(code, 0);
    assert_eq!(out, format!("{RT}/core/testspeechgestures.xml: valid\n"));
}

#[test]
fn validate_block_without_id_exits_1_with_file_line_col() {
    let (code, out, err) = bmlr(&[
        "validate",
        &format!("{RT}/core/testface.xml"),
        &format!("{RT}/core/bmlnoid.xml"),
    ]);
    assert_eq!(code, 1);
    assert!(
        out.contains(&format!(
            "{RT}/core/bmlnoid.xml:13:1: error[missing-block-id]: the <bml> block has no id"
        )),
        "{out}"
    );
    assert!(err.contains("2 files checked: 1 valid, 1 invalid"), "{err}");
}

#[test]
fn validate_unknown_extension_warns_and_exits_0() {
    let (code, out, _) = bmlr(&["validate", &format!("{RT}/murml/murmlhandlocation.xml")]);
    assert_eq!(code, 0);
    assert!(out.contains("warning[unsupported-extension]: unsupported extension behaviour <murmlgesture id=\"gesture1\">"), "{out}");
    assert!(out.contains("valid (1 warning)"));
}

#[test]
fn validate_missing_file_exits_2() {
    let (code, _, err) = bmlr(&["validate", "no/such/file.xml"]);
    assert_eq!(code, 2);
    assert!(err.contains("no/such/file.xml: cannot read"), "{err}");
}

#[test]
fn usage_error_exits_2() {
    let (code, _, _) = bmlr(&["validate"]);
    assert_eq!(code, 2);
}
