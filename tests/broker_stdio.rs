//! The same blocks through the broker (`bmlr serve --mqtt`) and through `bmlr serve --stdio` give
//! the same feedback, message for message, apart from the wall clock: both run on it, so every
//! global time is compared relative to its block's start (to the millisecond either side: each
//! is rounded on its own), `bmla:posixTime` is left out, and a warning about a block that
//! cannot be read names its source (`<stdin>` or the topic). Skipped without mosquitto, like
//! the other broker tests.

#[path = "common/broker.rs"]
mod kit;

use std::collections::BTreeMap;
use std::io::{BufRead, BufReader, Write};
use std::process::{Command, Stdio};
use std::sync::mpsc;
use std::time::Duration;

use kit::*;

/// The script: each block is sent when the one before it has ended (or, for one that cannot
/// start, been refused). It covers speech after a nod, a gesture with a gaze on its stroke, a
/// block that cannot be read, a behaviour with an unknown target inside a running block, and
/// an APPEND.
fn script() -> Vec<(String, &'static str)> {
    vec![
        (
            format!(
                r#"<bml {NS} id="b1"><head id="h" lexeme="NOD" start="0" end="0.3"/><speech id="s" start="h:end"><text>Hello there.</text></speech></bml>"#
            ),
            r#"id="b1:end""#,
        ),
        (
            format!(
                r#"<bml {NS} id="b2"><gesture id="g" lexeme="BEAT" start="0.1"/><gaze id="z" target="bluebox" start="g:stroke" end="g:end"/></bml>"#
            ),
            r#"id="b2:end""#,
        ),
        (
            format!(r#"<bml {NS} id="b3"><head id="h""#),
            "warningFeedback",
        ),
        (
            format!(
                r#"<bml {NS} id="b4" composition="APPEND"><faceLexeme id="f" lexeme="RAISE_BROWS" start="0" end="0.4" amount="0.5"/><gaze id="z" target="nowhere" start="f:end" end="0.8"/></bml>"#
            ),
            r#"id="b4:end""#,
        ),
        (
            format!(
                r#"<bml {NS} id="b5" composition="APPEND"><speech id="s"><text>And <sync id="m"/>again.</text></speech><head id="h" lexeme="SHAKE" start="s:m" end="s:end"/></bml>"#
            ),
            r#"id="b5:end""#,
        ),
    ]
}

/// How long one step of the script may take.
const STEP: Duration = Duration::from_secs(10);

/// The feedback of `script` through `bmlr serve --stdio`, one message a line.
fn through_stdio() -> Vec<String> {
    let mut child = Command::new(env!("CARGO_BIN_EXE_bmlr"))
        .args(["serve", "--stdio", "--no-idle"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .expect("bmlr runs");
    let out = child.stdout.take().unwrap();
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        for line in BufReader::new(out).lines().map_while(Result::ok) {
            if tx.send(line).is_err() {
                break;
            }
        }
    });
    let mut stdin = child.stdin.take().unwrap();
    let mut all = Vec::new();
    for (block, done) in script() {
        writeln!(stdin, "{block}").unwrap();
        stdin.flush().unwrap();
        loop {
            let line = rx.recv_timeout(STEP).expect("the step ends within 10 s");
            let last = line.contains(done);
            all.push(line);
            if last {
                break;
            }
        }
    }
    drop(stdin);
    // (the realizer exits when its input is closed and nothing more is scheduled)
    all.extend(rx.iter());
    let _ = child.wait();
    all
}

/// The feedback of `script` through the broker, one message a message.
fn through_broker(broker: &Broker) -> Vec<String> {
    let _r = realizer(broker, "same", &[], &["--no-idle"]);
    let mut p = planner(broker, "script");
    until_online(&p, &["same"]);
    let mut all = Vec::new();
    for (block, done) in script() {
        p.publish("bml/_/bml", block.into_bytes(), false);
        let heard = hear(&p, STEP.as_secs_f64(), |h| {
            h.iter()
                .any(|(t, m)| t == "bml/_/feedback" && m.contains(done))
        });
        let feedback: Vec<String> = (heard.into_iter())
            .filter(|(t, _)| t == "bml/_/feedback")
            .map(|(_, m)| m)
            .collect();
        assert!(
            feedback.iter().any(|m| m.contains(done)),
            "no {done}: {feedback:?}"
        );
        all.extend(feedback);
    }
    // anything said after the last block's end
    let after = hear(&p, 0.5, |_| false);
    all.extend(
        (after.into_iter())
            .filter(|(t, _)| t == "bml/_/feedback")
            .map(|(_, m)| m),
    );
    all
}

/// A number attribute's value in milliseconds.
fn millis(value: &str) -> i64 {
    let (whole, frac) = value.split_once('.').unwrap_or((value, "0"));
    let frac = format!("{frac:0<3}");
    let sign = if whole.starts_with('-') { -1 } else { 1 };
    sign * (whole.trim_start_matches('-').parse::<i64>().unwrap() * 1000
        + frac[..3].parse::<i64>().unwrap())
}

/// Global times, relative to their block's start in the comparison.
const GLOBAL: [&str; 3] = ["globalTime=\"", "globalStart=\"", "globalEnd=\""];

/// `message` without its `bmla:posixTime`, each global time replaced by `#`, and those times
/// in milliseconds after the block's start (which `starts` learns from the block's first
/// message with a global time: its first prediction).
fn relative(message: &str, starts: &mut BTreeMap<String, i64>) -> (String, Vec<i64>) {
    // a warning about a block that cannot be read names where it came from: the input or
    // the topic
    let mut text = (message.replace("&lt;stdin&gt;:", "SOURCE:")).replace("bml/_/bml:", "SOURCE:");
    const POSIX: &str = " bmla:posixTime=\"";
    while let Some(i) = text.find(POSIX) {
        let end = i + POSIX.len() + text[i + POSIX.len()..].find('"').unwrap();
        text.replace_range(i..=end, "");
    }
    // the block a message is about: its first id, up to the first colon
    let block = (message.split_once(r#"id=""#))
        .and_then(|(_, r)| r.split(['"', ':']).next())
        .unwrap_or("")
        .to_string();
    let mut times = Vec::new();
    let mut from = 0;
    while let Some((i, name)) = (GLOBAL.iter())
        .filter_map(|a| Some((from + text[from..].find(a)?, a)))
        .min()
    {
        let (v0, v1) = (
            i + name.len(),
            i + name.len() + text[i + name.len()..].find('"').unwrap(),
        );
        let ms = millis(&text[v0..v1]);
        let start = *starts.entry(block.clone()).or_insert(ms);
        times.push(ms - start);
        text.replace_range(v0..v1, "#");
        from = v0 + 1;
    }
    (text, times)
}

#[test]
fn the_same_blocks_give_the_same_feedback_through_the_broker_and_through_stdio() {
    let Some(broker) = Broker::start() else {
        return;
    };
    let stdio = through_stdio();
    let mqtt = through_broker(&broker);
    let (mut s_starts, mut m_starts) = Default::default();
    let s: Vec<_> = stdio.iter().map(|m| relative(m, &mut s_starts)).collect();
    let m: Vec<_> = mqtt.iter().map(|m| relative(m, &mut m_starts)).collect();
    for (k, ((a, _), (b, _))) in s.iter().zip(&m).enumerate() {
        assert_eq!(a, b, "message {k} differs (stdio, then broker)");
    }
    assert_eq!(s.len(), m.len(), "stdio: {stdio:#?}\nbroker: {mqtt:#?}");
    for ((text, a), (_, b)) in s.iter().zip(&m) {
        for (x, y) in a.iter().zip(b) {
            assert!(
                (x - y).abs() <= 1,
                "{text}: {x} ms vs {y} ms after the block's start"
            );
        }
    }
    // the script ran: five blocks, four ended, one refused, one warning inside a block
    let count = |what: &str| stdio.iter().filter(|m| m.contains(what)).count();
    assert_eq!(count("blockProgress") / 2, 4, "{stdio:#?}");
    assert_eq!(count("warningFeedback"), 2, "{stdio:#?}");
    assert!(count("syncPointProgress") > 20, "{stdio:#?}");
    eprintln!("{} messages alike", stdio.len());
}
