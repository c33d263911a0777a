//! Hostile input through the built binary: deep nesting, thousands of attributes and namespace
//! declarations, and times far from the block start are refused with a `limit-exceeded`
//! diagnostic or a PARSING_FAILURE warning naming the limit, never a crash; the blocks after them
//! still run, and every flag changes its limit.

use std::process::Command;

mod common;
use common::bmlr;

const NS: &str = r#"xmlns="http://www.bml-initiative.org/bml/bml-1.0""#;

fn deep(n: usize) -> String {
    format!(
        r#"<bml {NS} id="deep">{}<gesture id="g" lexeme="BEAT"/>{}</bml>"#,
        "<required>".repeat(n),
        "</required>".repeat(n)
    )
}

fn wide(n: usize) -> String {
    let attrs: String = (0..n)
        .map(|i| format!(r#" xmlns:p{i}="urn:x{i}" p{i}:a="1""#))
        .collect();
    format!(r#"<bml {NS} id="wide"><gesture id="g" lexeme="BEAT"{attrs}/></bml>"#)
}

const GOOD: &str = r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="good"><gesture id="g" lexeme="BEAT"/></bml>"#;

fn write(name: &str, text: &str) -> String {
    let path = std::env::temp_dir().join(format!("bmlr-hostile-{}-{name}", std::process::id()));
    std::fs::write(&path, text).unwrap();
    path.to_str().unwrap().to_string()
}

#[test]
fn six_thousand_nested_elements_are_refused_not_a_stack_overflow() {
    let file = write("deep.xml", &deep(6000));
    let (code, out, err) = bmlr(&["validate", &file], "");
    assert_eq!(code, 1, "{err}");
    assert!(
        out.contains("error[limit-exceeded]") && out.contains("deeper than 64"),
        "{out}"
    );
    // run, and a port, go on with the next block
    let (code, out, err) = bmlr(&["run", &file, "fixtures/examples/welcome.xml"], "");
    assert_eq!(code, 1, "{err}");
    assert!(
        out.contains("PARSING_FAILURE") && out.contains(r#"id="greet:end""#),
        "{out}"
    );
    let (code, out, err) = bmlr(&["serve", "--stdio"], &format!("{}\n{GOOD}\n", deep(6000)));
    assert_eq!(code, 0, "{err}");
    assert!(
        out.contains("deeper than 64") && out.contains(r#"id="good:end""#),
        "{out}"
    );
    // the flag moves the limit
    let (_, out, _) = bmlr(&["validate", "--max-depth", "10000", &file], "");
    assert!(
        out.contains("nested in <required>") && !out.contains("deeper than"),
        "{out}"
    );
}

#[test]
fn thirty_thousand_attributes_are_refused_at_the_attribute_limit() {
    let file = write("wide.xml", &wide(30_000));
    let (code, out, _) = bmlr(&["validate", &file], "");
    assert_eq!(code, 1);
    assert!(out.contains("more than 256 attributes"), "{out}");
    let (_, out, _) = bmlr(
        &["serve", "--stdio"],
        &format!("{}\n{GOOD}\n", wide(30_000)),
    );
    assert!(
        out.contains("more than 256 attributes") && out.contains(r#"id="good:end""#),
        "{out}"
    );
    // a stream is split by the same reader, which reads no further than the limit either
    let (_, out, _) = bmlr(&["run", "-"], &format!("{}\n{GOOD}\n", wide(30_000)));
    assert!(
        out.contains("more than 256 attributes") && out.contains(r#"id="good:end""#),
        "{out}"
    );
    let (code, out, _) = bmlr(
        &[
            "validate",
            "--max-attributes",
            "100000",
            &write("w2.xml", &wide(200)),
        ],
        "",
    );
    assert_eq!(code, 0, "{out}");
}

#[test]
fn a_time_far_from_the_block_start_is_refused_and_every_other_block_ends() {
    let far = format!(
        r#"<bml {NS} id="far"><gesture id="g" lexeme="BEAT" start="1e308" end="0"/></bml>"#
    );
    let (code, out, _) = bmlr(&["validate", &write("far.xml", &far)], "");
    assert_eq!(code, 1);
    assert!(
        out.contains("error[limit-exceeded]") && out.contains("1e308"),
        "{out}"
    );
    // an APPEND block after it does not wait for ever
    let append = format!(
        r#"<bml {NS} id="next" composition="APPEND"><gesture id="g" lexeme="BEAT"/></bml>"#
    );
    let (code, out, _) = bmlr(&["run", "-"], &format!("{far}\n{append}\n"));
    assert_eq!(code, 1);
    assert!(out.contains(r#"id="next:end""#), "{out}");
    // a bad flag value is a usage error
    let (code, _, err) = bmlr(&["validate", "--max-time", "inf", "x.xml"], "");
    assert_eq!(code, 2, "{err}");
}

#[test]
fn a_block_over_the_size_limit_is_refused_by_its_size() {
    let big = format!(
        r#"<bml {NS} id="big">{}</bml>"#,
        (0..200)
            .map(|i| format!(r#"<gesture id="g{i}" lexeme="BEAT"/>"#))
            .collect::<String>()
    );
    let file = write("big.xml", &big);
    let (code, out, _) = bmlr(&["validate", "--max-block-bytes", "1000", &file], "");
    assert_eq!(code, 1);
    assert!(out.contains("more than the limit of 1000"), "{out}");
    let (code, out, _) = bmlr(&["validate", "--max-behaviours", "100", &file], "");
    assert_eq!(code, 1);
    assert!(out.contains("more than 100 behaviours"), "{out}");
    let (code, _, _) = bmlr(&["validate", &file], "");
    assert_eq!(code, 0);
}

/// The ports read one block per line: a line that is not UTF-8, a stray comment or CDATA
/// opener, a broken block and a garbage line each cost only themselves and one warning; `run -`
/// (where a block may span lines) picks up again at the next block the same way.
#[test]
fn bad_lines_cost_exactly_themselves_on_the_ports_and_in_run() {
    let good = |id: &str| format!(r#"<bml {NS} id="{id}"><gesture id="g" lexeme="BEAT"/></bml>"#);
    let mut input: Vec<u8> = Vec::new();
    input.extend_from_slice(format!("{}\n", good("first")).as_bytes());
    input.extend_from_slice(b"<bml id=\"bad\">\xff</bml>\n");
    input.extend_from_slice(b"<!-- a comment that never ends\n");
    input.extend_from_slice(b"<![CDATA[x]]>\n");
    input.extend_from_slice(format!("{}\n", good("second")).as_bytes());
    input.extend_from_slice(format!("<bml {NS} id=\"broken\"><speech></bml>\nhello\n").as_bytes());
    input.extend_from_slice(format!("{}\n", good("third")).as_bytes());
    for args in [vec!["serve", "--stdio"], vec!["run", "-"]] {
        let (code, out, err) = bmlr(&args, &input);
        for id in ["first", "second", "third"] {
            assert!(
                out.contains(&format!(r#"id="{id}:end""#)),
                "{args:?}: {id} lost: {out}"
            );
        }
        // in `run -` the comment that never ends takes the text up to the next block with it
        // (a comment may span lines there), so the CDATA line shares its warning
        let warnings = out
            .lines()
            .filter(|l| l.contains("PARSING_FAILURE"))
            .count();
        let expected = if args[0] == "run" { 4 } else { 5 };
        assert_eq!(warnings, expected, "{args:?}: {out}");
        assert!(out.contains("not UTF-8"), "{out}");
        let expected = if args[0] == "run" { 1 } else { 0 };
        assert_eq!(code, expected, "{args:?}: {err}");
    }
}

/// A port paused (SIGSTOP) and resumed reports the sync points it missed at their planned
/// `globalTime`, and says once how late it is.
#[cfg(unix)]
#[test]
fn a_paused_port_says_how_late_it_is() {
    use std::io::{Read, Write};
    use std::process::Stdio;
    let mut child = Command::new(env!("CARGO_BIN_EXE_bmlr"))
        .args(["serve", "--stdio"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let mut stdin = child.stdin.take().unwrap();
    let speech = format!(
        r#"<bml {NS} id="talk"><speech id="s"><text>one <sync id="a"/>two <sync id="b"/>three <sync id="c"/>four <sync id="d"/>five <sync id="e"/>six <sync id="f"/>seven <sync id="g"/>eight nine ten eleven twelve</text></speech></bml>"#
    );
    writeln!(stdin, "{speech}").unwrap();
    std::thread::sleep(std::time::Duration::from_millis(300));
    // the shell's own `kill` (no procps needed)
    let signal = |s: &str| {
        let cmd = format!("kill {s} {}", child.id());
        let status = Command::new("sh").args(["-c", &cmd]).status();
        assert!(status.unwrap().success());
    };
    signal("-STOP");
    std::thread::sleep(std::time::Duration::from_millis(1500));
    signal("-CONT");
    drop(stdin);
    let mut out = String::new();
    child
        .stdout
        .take()
        .unwrap()
        .read_to_string(&mut out)
        .unwrap();
    child.wait().unwrap();
    let late: Vec<&str> = out.lines().filter(|l| l.contains("fell behind")).collect();
    assert_eq!(late.len(), 1, "{out}");
    assert!(
        late[0].contains("EXECUTION_FAILURE") && late[0].contains("s late"),
        "{out}"
    );
    assert!(out.contains(r#"id="talk:end""#), "{out}");
}

/// 100 000 blocks piped into `serve --stdio` as fast as the pipe takes them, a bad line among
/// every thousand: the port stays under 64 MB, every block ends, every bad line warns once.
#[cfg(target_os = "linux")]
#[test]
fn a_hundred_thousand_blocks_through_the_stdio_port_in_bounded_memory() {
    use std::io::{BufRead, BufReader, Write};
    use std::process::Stdio;
    const BLOCKS: usize = 100_000;
    let mut child = Command::new(env!("CARGO_BIN_EXE_bmlr"))
        .args(["serve", "--stdio"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let pid = child.id();
    let mut stdin = child.stdin.take().unwrap();
    let writer = std::thread::spawn(move || {
        for i in 0..BLOCKS {
            let line = if i % 1000 == 999 {
                "this line is not a block\n".to_string()
            } else {
                format!("<bml {NS} id=\"b{i}\"/>\n")
            };
            stdin.write_all(line.as_bytes()).unwrap();
        }
    });
    let peak = std::sync::Arc::new(std::sync::atomic::AtomicU64::new(0));
    let watching = peak.clone();
    let watcher = std::thread::spawn(move || loop {
        let status = std::fs::read_to_string(format!("/proc/{pid}/status")).unwrap_or_default();
        let Some(kb) = status
            .lines()
            .find_map(|l| l.strip_prefix("VmHWM:"))
            .and_then(|v| v.split_whitespace().next()?.parse::<u64>().ok())
        else {
            return;
        };
        watching.store(kb, std::sync::atomic::Ordering::Relaxed);
        std::thread::sleep(std::time::Duration::from_millis(50));
    });
    let (mut ends, mut warnings) = (0, 0);
    for line in BufReader::new(child.stdout.take().unwrap()).lines() {
        let line = line.unwrap();
        if line.contains("blockProgress") && line.contains(":end\"") {
            ends += 1;
        } else if line.contains("PARSING_FAILURE") {
            warnings += 1;
        }
    }
    writer.join().unwrap();
    child.wait().unwrap();
    watcher.join().unwrap();
    assert_eq!((ends, warnings), (BLOCKS - BLOCKS / 1000, BLOCKS / 1000));
    let kb = peak.load(std::sync::atomic::Ordering::Relaxed);
    assert!(kb > 0 && kb < 64 * 1024, "peak RSS {kb} kB");
}
