//! Streaming over `bmlr serve --stdio`, as a host process does: the stream messages
//! (`{"open_stream"}`, `{"push_audio"}` with base64 samples and Polly marks, `{"end_audio"}`)
//! between the `<bml>` lines. espeak-ng's sentence (`fixtures/voice/espeak-bob.wav`) pushed in
//! 10 chunks on the wall clock: the speech starts with the first chunk, its end is predicted
//! and revised, it ends with its sound (feedback on the wall clock), a nod tied to its end
//! follows; a bad message costs one warning that says why.

#[path = "common/chunked.rs"]
mod chunked;
#[path = "common/espeak_report.rs"]
mod espeak_report;

use std::io::{BufRead, BufReader, Write};
use std::process::{Command, Stdio};
use std::time::Duration;

use base64::Engine as _;
use bml_realizer::feedback::{from_line, Feedback};
use chunked::sync_time;

const NS: &str = r#"xmlns="http://www.bml-initiative.org/bml/bml-1.0" xmlns:bmlt="http://hmi.ewi.utwente.nl/bmlt""#;

#[test]
fn a_host_streams_a_speech_through_serve_stdio() {
    let dir = env!("CARGO_MANIFEST_DIR");
    let audio = bml_realizer::sound::read_wav(std::path::Path::new(&format!(
        "{dir}/fixtures/voice/espeak-bob.wav"
    )))
    .unwrap();
    let report = espeak_report::fixture();
    let lines = espeak_report::polly_lines(&report);
    let length = audio.samples.len() as f64 / f64::from(audio.rate);
    let mut child = Command::new(env!("CARGO_BIN_EXE_bmlr"))
        .args(["serve", "--stdio", "--no-idle"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .unwrap();
    let mut stdin = child.stdin.take().unwrap();
    let stdout = BufReader::new(child.stdout.take().unwrap());
    let reader = std::thread::spawn(move || {
        let mut log = Vec::new();
        for line in stdout.lines() {
            let f = from_line(&line.unwrap()).unwrap();
            let done =
                matches!(&f, Feedback::BlockProgress(p) if p.block == "b" && p.sync == "end");
            log.push(f);
            if done {
                break;
            }
        }
        log
    });
    let mut send = |line: String| {
        writeln!(stdin, "{line}").unwrap();
        stdin.flush().unwrap();
    };
    send(r#"{"open_stream": "reply"}"#.into());
    send(r#"{"push": "reply"}"#.into());
    send(format!(
        r#"<bml {NS} id="b"><speech id="s" bmlt:stream="reply" start="anticipators:reply:start" end="anticipators:reply:end"><text>{}</text></speech><head id="n" lexeme="NOD" start="s:end"/></bml>"#,
        report.text
    ));
    std::thread::sleep(Duration::from_millis(300));
    for (span, marks) in chunked::chunks(audio.samples.len(), audio.rate, &lines, 10) {
        let pcm = &audio.samples[span];
        let bytes: Vec<u8> = pcm.iter().flat_map(|s| s.to_le_bytes()).collect();
        let message = serde_json::json!({
            "push_audio": "reply",
            "rate": audio.rate,
            "pcm": base64::engine::general_purpose::STANDARD.encode(bytes),
            "marks": marks,
        });
        send(message.to_string());
        std::thread::sleep(Duration::from_millis(200));
    }
    send(r#"{"end_audio": "reply"}"#.into());
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || tx.send(reader.join().unwrap()));
    let log = rx
        .recv_timeout(Duration::from_secs(20))
        .expect("the block ends within 20 s");
    drop(stdin);
    let _ = child.wait();
    let warnings: Vec<&str> = (log.iter())
        .filter_map(|f| match f {
            Feedback::Warning(w) => Some(w.text.as_str()),
            _ => None,
        })
        .collect();
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(warnings[0].contains("unknown field `push`"), "{warnings:?}");
    let start = sync_time(&log, "s", "start").expect("the speech starts");
    let end = sync_time(&log, "s", "end").expect("the speech ends");
    // on the wall clock at 60 frames a second: within two frames of its sound
    assert!(
        (end - start - length).abs() < 2.0 / 60.0 + 1e-3,
        "it lasts {:.3} s, its sound {length:.3} s",
        end - start
    );
    let predictions = log
        .iter()
        .filter(|f| matches!(f, Feedback::Prediction(_)))
        .count();
    assert!(predictions >= 9, "{predictions} predictions");
    let nod = sync_time(&log, "n", "start").expect("the nod starts");
    assert!(
        (nod - end).abs() < 1e-3,
        "the nod at {nod}, the speech's end at {end}"
    );
}
