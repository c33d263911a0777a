//! Honest exit codes: `bmlr run` and `bmlr plan` exit 1 on a block that lost a behaviour to
//! contradictory constraints (the block `bmlr validate` calls invalid), and no command panics
//! when its reader goes away — a closed stdout or a closed stderr (`2>&1 | head -1`).

mod common;

use std::process::{Command, Stdio};

/// A block whose nod must end before it starts: it is dropped with CANNOT_SATISFY_CONSTRAINTS.
const CONTRADICTORY: &str = r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="c">
  <gesture id="a" lexeme="BEAT" mode="RIGHT_HAND" start="0" end="1"/>
  <head id="b" lexeme="NOD" start="a:end" end="a:start"/>
</bml>"#;

#[test]
fn run_and_plan_exit_1_when_a_behaviour_is_dropped_for_contradictory_constraints() {
    let file = std::env::temp_dir().join(format!("bmlr-contra-{}.xml", std::process::id()));
    std::fs::write(&file, CONTRADICTORY).unwrap();
    let path = file.to_str().unwrap();
    let (code, _, _) = common::bmlr(&["validate", path], "");
    assert_eq!(code, 1, "validate calls it invalid");
    for command in ["run", "plan"] {
        let (code, out, err) = common::bmlr(&[command, path], "");
        assert_eq!(code, 1, "{command}: {err}");
        assert!(
            err.contains("1 block (c) lost behaviours to constraints that cannot all hold"),
            "{command}: {err}"
        );
        // the rest of the block still ran (or was planned)
        assert!(out.contains("c:a"), "{command}: {out}");
    }
    let (code, _, err) = common::bmlr(&["run", "fixtures/examples/welcome.xml"], "");
    assert_eq!(code, 0, "a block scheduled whole: {err}");
    std::fs::remove_file(&file).ok();
}

/// Which of the command's outputs is closed before it writes.
#[derive(Clone, Copy, Debug)]
enum Closed {
    Stdout,
    Stderr,
    Both,
}

/// `bmlr ARGS` with the read end of `closed` already gone: its exit code (None: a signal).
fn with_closed(args: &[&str], closed: Closed) -> Option<i32> {
    let gone = || {
        let (reader, writer) = std::io::pipe().unwrap();
        drop(reader);
        Stdio::from(writer)
    };
    let (out, err) = match closed {
        Closed::Stdout => (gone(), Stdio::null()),
        Closed::Stderr => (Stdio::null(), gone()),
        Closed::Both => (gone(), gone()),
    };
    Command::new(env!("CARGO_BIN_EXE_bmlr"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .stdin(Stdio::null())
        .stdout(out)
        .stderr(err)
        .status()
        .unwrap()
        .code()
}

#[test]
fn no_command_panics_on_a_closed_stdout_or_stderr() {
    let welcome = "fixtures/examples/welcome.xml";
    let (_, log, _) = common::bmlr(&["run", welcome], "");
    let dir = std::env::temp_dir().join(format!("bmlr-closed-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (log_file, svg) = (dir.join("log.xml"), dir.join("t.svg"));
    std::fs::write(&log_file, log).unwrap();
    let (log, svg) = (log_file.to_str().unwrap(), svg.to_str().unwrap());
    let commands: &[&[&str]] = &[
        &["validate", welcome, "fixtures/examples/two-alice.xml"],
        &["validate", "no-such-file.xml"],
        &["run", welcome],
        &["run", "--format", "jsonl", welcome],
        &["run", "no-such-file.xml"],
        &["plan", welcome],
        &["timeline", "--svg", svg, log],
        &["diff", log, log],
        &["diff", log, welcome],
        &["run", "--nonsense"],
    ];
    for args in commands {
        for closed in [Closed::Stdout, Closed::Stderr, Closed::Both] {
            let code = with_closed(args, closed);
            assert!(
                code.is_some_and(|c| c != 101),
                "bmlr {} with {closed:?} closed: exit {code:?}",
                args.join(" ")
            );
        }
    }
    std::fs::remove_dir_all(&dir).ok();
}
