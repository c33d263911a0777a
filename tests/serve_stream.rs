//! Streaming through `bmlr serve`'s line ports, as a host process does: the stream messages
//! (`{"open_stream"}`, `{"push_audio"}` with base64 samples and Polly marks, `{"end_audio"}`)
//! between the `<bml>` blocks, over `--stdio`, over `--tcp`, over `--mqtt` (a real mosquitto)
//! and over `--stomp` (a real ActiveMQ, on AsapRealizer's topics); without the broker those two
//! say "skipped" and pass (`.ci/run` installs both and fails on a skip). espeak-ng's sentence
//! (`fixtures/voice/espeak-bob.wav`) pushed in 10 chunks on the wall clock: the speech starts
//! with the first chunk, its end is predicted and revised, it ends with its sound (feedback on
//! the wall clock), a nod tied to its end follows; a bad message costs one warning that says why.

#[path = "common/activemq.rs"]
mod amq;
#[path = "common/broker.rs"]
mod broker;
// (the ActiveMQ helper finds the free-port helper as `kit`)
use broker as kit;
#[path = "common/chunked.rs"]
mod chunked;
#[path = "common/espeak_report.rs"]
mod espeak_report;

use std::io::{BufRead, BufReader, Write};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc::{self, Receiver};
use std::time::{Duration, Instant};

use base64::Engine as _;
use bml_realizer::language::feedback::{from_line, Feedback};
use bml_realizer::ports::broker::{Inbound, Link, StompLink, StompOptions, StompUrl};
use chunked::sync_time;

const NS: &str = r#"xmlns="http://www.bml-initiative.org/bml/bml-1.0" xmlns:bmlt="http://hmi.ewi.utwente.nl/bmlt""#;

/// A port of `bmlr serve`: lines go in, feedback comes out on a channel.
struct Port {
    send: Box<dyn FnMut(&str)>,
    feedback: Receiver<Feedback>,
    _server: Child,
    _broker: Option<Box<dyn std::any::Any>>,
}

impl Drop for Port {
    fn drop(&mut self) {
        let _ = self._server.kill();
        let _ = self._server.wait();
    }
}

fn bmlr(args: &[&str]) -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_bmlr"));
    c.args(["serve", "--no-idle"]).args(args);
    c
}

/// Feedback lines read on a thread of their own.
fn lines_to_channel(read: impl std::io::Read + Send + 'static) -> Receiver<Feedback> {
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        for line in BufReader::new(read).lines() {
            let Ok(line) = line else { return };
            if tx.send(from_line(&line).unwrap()).is_err() {
                return;
            }
        }
    });
    rx
}

fn stdio() -> Port {
    let mut child = (bmlr(&["--stdio"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped()))
    .spawn()
    .unwrap();
    let mut stdin = child.stdin.take().unwrap();
    let feedback = lines_to_channel(child.stdout.take().unwrap());
    Port {
        send: Box::new(move |line| {
            writeln!(stdin, "{line}").unwrap();
            stdin.flush().unwrap();
        }),
        feedback,
        _server: child,
        _broker: None,
    }
}

fn tcp() -> Port {
    let mut child = (bmlr(&["--tcp", "127.0.0.1:0"]).stderr(Stdio::piped()))
        .spawn()
        .unwrap();
    let mut said = String::new();
    (BufReader::new(child.stderr.take().unwrap()))
        .read_line(&mut said)
        .unwrap();
    let addr = said
        .trim()
        .strip_prefix("bmlr serve: listening on ")
        .unwrap();
    let mut socket = std::net::TcpStream::connect(addr).unwrap();
    let feedback = lines_to_channel(socket.try_clone().unwrap());
    Port {
        send: Box::new(move |line| writeln!(socket, "{line}").unwrap()),
        feedback,
        _server: child,
        _broker: None,
    }
}

/// A realizer on a mosquitto, for character bob; the host publishes on bob's topic.
fn mqtt() -> Option<Port> {
    let broker = broker::Broker::start()?;
    let url = broker.url();
    let server = (bmlr(&["--mqtt", &url, "--name", "r", "--characters", "bob"]))
        .stdout(Stdio::null())
        .spawn()
        .unwrap();
    let mut host = broker::planner(&broker, "host");
    broker::until_online(&host, &["r"]);
    let (tx, feedback) = mpsc::channel();
    let inbox = broker::planner_on(&broker, "host-ears", &["bml/bob/feedback"]);
    std::thread::spawn(move || hear_into(inbox, tx));
    Some(Port {
        send: Box::new(move |line| host.publish("bml/bob/bml", line.as_bytes().to_vec(), false)),
        feedback,
        _server: server,
        _broker: Some(Box::new(broker)),
    })
}

/// A realizer on an ActiveMQ (`serve --stomp`, AsapRealizer's topics); the host sends on
/// `asap.bml.request` and hears `asap.bml.feedback`.
fn stomp() -> Option<Port> {
    let broker = amq::ActiveMq::start()?;
    let server = (Command::new(env!("CARGO_BIN_EXE_bmlr")))
        .args(["serve", "--no-idle", "--stomp", &broker.stomp_url()])
        .stdout(Stdio::null())
        .spawn()
        .unwrap();
    let link = |topics: &[&str]| {
        StompLink::connect(StompOptions {
            url: StompUrl::parse(&broker.stomp_url()).unwrap(),
            subscriptions: topics.iter().map(|t| t.to_string()).collect(),
            presence: None,
            inbox: 100_000,
            start_tries: 3,
        })
        .expect("the host connects")
    };
    let mut host = link(&[]);
    let ears = link(&["/topic/asap.bml.feedback"]);
    // (the realizer is there once a block of the host's own has ended)
    let (tx, feedback) = mpsc::channel();
    let until = Instant::now() + Duration::from_secs(20);
    let warmed = loop {
        assert!(
            Instant::now() < until,
            "the realizer never answered on STOMP"
        );
        host.send(
            "/topic/asap.bml.request",
            broker::block("warmup").into_bytes(),
            &[],
        );
        host.flush();
        let heard = Instant::now() + Duration::from_secs(1);
        let mut ended = false;
        while Instant::now() < heard && !ended {
            if let Some(Inbound::Message { payload, .. }) =
                ears.recv_timeout(Duration::from_millis(20))
            {
                let text = String::from_utf8_lossy(&payload);
                ended = text.starts_with("<blockProgress") && text.contains(r#"id="warmup:end""#);
            }
        }
        if ended {
            break ears;
        }
    };
    std::thread::spawn(move || loop {
        if let Some(Inbound::Message { payload, .. }) =
            warmed.recv_timeout(Duration::from_millis(50))
        {
            let f = from_line(&String::from_utf8_lossy(&payload)).unwrap();
            if tx.send(f).is_err() {
                return;
            }
        }
    });
    Some(Port {
        send: Box::new(move |line| {
            host.send("/topic/asap.bml.request", line.as_bytes().to_vec(), &[]);
            host.flush();
        }),
        feedback,
        _server: server,
        _broker: Some(Box::new(broker)),
    })
}

fn hear_into(link: Link, tx: mpsc::Sender<Feedback>) {
    loop {
        if let Some(Inbound::Message { payload, .. }) = link.recv_timeout(Duration::from_millis(50))
        {
            let f = from_line(&String::from_utf8_lossy(&payload)).unwrap();
            if tx.send(f).is_err() {
                return;
            }
        }
    }
}

/// espeak-ng's sentence, the sound every test streams.
fn sound() -> bml_realizer::character::voice::Audio {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/fixtures/voice/espeak-bob.wav");
    bml_realizer::character::sound::read_wav(std::path::Path::new(path)).unwrap()
}

/// Streams the sentence through `port`, with `bad` as the one bad message; the feedback until
/// block b's end.
fn stream_through(mut port: Port, bad: &str) -> Vec<Feedback> {
    let audio = sound();
    let report = espeak_report::fixture();
    let lines = espeak_report::polly_lines(&report);
    let send = &mut port.send;
    send(r#"{"open_stream": "reply"}"#);
    send(bad);
    send(&format!(
        r#"<bml {NS} id="b"><speech id="s" bmlt:stream="reply" start="anticipators:reply:start" end="anticipators:reply:end"><text>{}</text></speech><head id="n" lexeme="NOD" start="s:end"/></bml>"#,
        report.text
    ));
    std::thread::sleep(Duration::from_millis(300));
    for (span, marks) in chunked::chunks(audio.samples.len(), audio.rate, &lines, 10) {
        let bytes: Vec<u8> = audio.samples[span]
            .iter()
            .flat_map(|s| s.to_le_bytes())
            .collect();
        let message = serde_json::json!({
            "push_audio": "reply",
            "rate": audio.rate,
            "pcm": base64::engine::general_purpose::STANDARD.encode(bytes),
            "marks": marks,
        });
        send(&message.to_string());
        std::thread::sleep(Duration::from_millis(200));
    }
    send(r#"{"end_audio": "reply"}"#);
    let until = Instant::now() + Duration::from_secs(20);
    let mut log = Vec::new();
    while Instant::now() < until {
        let Ok(f) = port.feedback.recv_timeout(Duration::from_millis(100)) else {
            continue;
        };
        let done = matches!(&f, Feedback::BlockProgress(p) if p.block == "b" && p.sync == "end");
        log.push(f);
        if done {
            return log;
        }
    }
    panic!("block b did not end within 20 s: {log:?}");
}

/// The speech lasts its sound, is predicted as it comes, the nod follows its end, and the one
/// bad message is one warning that says `why`.
fn check(log: &[Feedback], why: &str) {
    let audio = sound();
    let length = audio.samples.len() as f64 / f64::from(audio.rate);
    let warnings: Vec<&str> = (log.iter())
        .filter_map(|f| match f {
            Feedback::Warning(w) => Some(w.text.as_str()),
            _ => None,
        })
        .collect();
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(warnings[0].contains(why), "{warnings:?}");
    let start = sync_time(log, "s", "start").expect("the speech starts");
    let end = sync_time(log, "s", "end").expect("the speech ends");
    // on the wall clock at 60 frames a second: within two frames of its sound
    assert!(
        (end - start - length).abs() < 2.0 / 60.0 + 1e-3,
        "it lasts {:.3} s, its sound {length:.3} s",
        end - start
    );
    let predictions = (log.iter())
        .filter(|f| matches!(f, Feedback::Prediction(_)))
        .count();
    assert!(predictions >= 9, "{predictions} predictions");
    let nod = sync_time(log, "n", "start").expect("the nod starts");
    assert!(
        (nod - end).abs() < 1e-3,
        "the nod at {nod}, the speech's end at {end}"
    );
}

#[test]
fn a_host_streams_a_speech_through_serve_stdio() {
    let log = stream_through(stdio(), r#"{"push": "reply"}"#);
    check(&log, "unknown field `push`");
}

#[test]
fn a_host_streams_a_speech_through_serve_tcp() {
    let log = stream_through(tcp(), r#"{"push": "reply"}"#);
    check(&log, "client 0: not a stream message: unknown field `push`");
}

#[test]
fn a_host_streams_a_speech_through_serve_mqtt_on_its_character_s_topic() {
    let Some(port) = mqtt() else { return };
    let log = stream_through(port, r#"{"open_stream": "x", "character": "ann"}"#);
    check(
        &log,
        "a stream for character 'ann' came on the port of 'bob'",
    );
    // every message is bob's (the topic's character), the warning too
    for f in &log {
        let character = match f {
            Feedback::Warning(w) => w.character_id.as_deref(),
            Feedback::BlockProgress(p) => p.character_id.as_deref(),
            Feedback::SyncPointProgress(p) => p.character_id.as_deref(),
            _ => Some("bob"),
        };
        assert_eq!(character, Some("bob"), "{f:?}");
    }
}

#[test]
fn a_host_streams_a_speech_through_serve_stomp_on_activemq() {
    let Some(port) = stomp() else { return };
    let log = stream_through(port, r#"{"push": "reply"}"#);
    check(&log, "not a stream message: unknown field `push`");
}
