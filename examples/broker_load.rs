//! Load and latency of `bmlr serve` on a broker — MQTT (mosquitto) and STOMP (ActiveMQ, the
//! `asap` flavour) — measured beside `bmlr serve --stdio` in one run (`docs/broker.md`,
//! `docs/performance.md`):
//!
//! ```sh
//! cargo build --release && cargo run --release --example broker_load
//! ```
//!
//! For each broker:
//! - Load: 3 000 blocks sent at once; every feedback message counted until every block has
//!   ended; the rate is messages over the time from the first to the last, and nothing may be
//!   missing (each block's start, its sync points and its end).
//! - Latency: 300 blocks one at a time; the time from sending a block to its first feedback
//!   message, through the broker, set against the same through a `serve --stdio` pipe.
//!
//! It starts its own brokers on free loopback ports (Debian packages `mosquitto` and
//! `activemq`; a missing one is reported and its rows left out) and the `bmlr` built beside
//! this example.

use std::io::{BufRead, BufReader, Write};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use bml_realizer::ports::broker::{
    BrokerUrl, Inbound, Link, LinkOptions, StompLink, StompOptions, StompUrl, Wire,
};

// (the tests' ActiveMQ starter, shared rather than copied)
#[path = "../tests/common/activemq.rs"]
mod activemq;
#[path = "common/process.rs"]
mod process;
use process::{bmlr, Kill};
// (and their mosquitto starter)
#[path = "../tests/common/mosquitto.rs"]
mod kit;

const NS: &str = r#"xmlns="http://www.bml-initiative.org/bml/bml-1.0""#;
/// Blocks sent at once for the load.
const LOAD: usize = 3_000;
/// Blocks sent one at a time for the latency.
const ONE_BY_ONE: usize = 300;

fn block(id: &str) -> String {
    format!(r#"<bml {NS} id="{id}"><head id="h" lexeme="NOD" start="0" end="0.2"/></bml>"#)
}

/// A realizer served on a broker, and the planner's link to it.
struct Served {
    name: &'static str,
    wire: Box<dyn Wire>,
    /// Where blocks go and where feedback comes from.
    blocks: String,
    feedback: String,
    // (dropped after the link: the realizer first, then the broker)
    _realizer: Kill,
    _broker: Box<dyn std::any::Any>,
}

/// Whether mosquitto is told to set TCP_NODELAY (`BROKER_NODELAY=false` to see without).
fn nodelay() -> bool {
    std::env::var("BROKER_NODELAY").map_or(true, |v| v != "false")
}

/// mosquitto on a free port, a realizer on it, the planner's link; `None` when not installed.
fn on_mosquitto() -> Option<Served> {
    // (mosquitto's own sockets wait for acknowledgements unless told not to: set_tcp_nodelay)
    let Some(broker) = kit::Broker::tuned(nodelay()) else {
        eprintln!("broker_load: MQTT left out (mosquitto is not installed)");
        return None;
    };
    let url = broker.url();
    let realizer = serve(&["--mqtt", &url, "--name", "load"]);
    let link = Link::connect(LinkOptions {
        url: BrokerUrl::parse(&url).unwrap(),
        client_id: "planner".into(),
        subscriptions: vec!["bml/_/feedback".into()],
        presence: None,
        inbox: 1_000_000,
        start_tries: 6,
    })
    .expect("mosquitto");
    Some(Served {
        name: "MQTT (mosquitto)",
        wire: Box::new(link),
        blocks: "bml/_/bml".into(),
        feedback: "bml/_/feedback".into(),
        _realizer: realizer,
        _broker: Box::new(broker),
    })
}

/// ActiveMQ on free ports, a realizer on it speaking AsapRealizer's topics, the planner's link;
/// `None` when not installed.
fn on_activemq() -> Option<Served> {
    let Some(broker) = activemq::ActiveMq::start() else {
        eprintln!("broker_load: STOMP left out (Debian package activemq)");
        return None;
    };
    let url = broker.stomp_url();
    let realizer = serve(&["--stomp", &url, "--flavour", "asap", "--name", "load"]);
    let link = StompLink::connect(StompOptions {
        url: StompUrl::parse(&url).unwrap(),
        subscriptions: vec!["/topic/asap.bml.feedback".into()],
        presence: None,
        inbox: 1_000_000,
        start_tries: 6,
    })
    .expect("ActiveMQ");
    Some(Served {
        name: "STOMP (ActiveMQ)",
        wire: Box::new(link),
        blocks: "/topic/asap.bml.request".into(),
        feedback: "/topic/asap.bml.feedback".into(),
        _realizer: realizer,
        _broker: Box::new(broker),
    })
}

/// `bmlr serve ARGS --no-idle`.
fn serve(args: &[&str]) -> Kill {
    Kill(
        Command::new(bmlr())
            .arg("serve")
            .args(args)
            .arg("--no-idle")
            .stderr(Stdio::null())
            .spawn()
            .expect("bmlr built beside this example"),
    )
}

impl Served {
    /// Waits until the realizer's first block has been answered (it is subscribed then).
    fn wait_ready(&mut self) {
        let until = Instant::now() + Duration::from_secs(30);
        let mut k = 0;
        while Instant::now() < until {
            let id = format!("ready{k}");
            self.wire.send(&self.blocks, block(&id).into_bytes(), &[]);
            self.wire.flush();
            let heard_by = Instant::now() + Duration::from_millis(500);
            while let Some(i) = self.recv_until(heard_by) {
                if let Inbound::Message { payload, .. } = i {
                    if String::from_utf8_lossy(&payload).contains(&format!("\"{id}:")) {
                        // let its last messages pass
                        std::thread::sleep(Duration::from_millis(400));
                        while self.wire.try_recv().is_some() {}
                        return;
                    }
                }
            }
            k += 1;
        }
        panic!("{}: the realizer did not answer in 30 s", self.name);
    }

    fn recv_until(&self, until: Instant) -> Option<Inbound> {
        self.wire
            .recv_timeout(until.saturating_duration_since(Instant::now()))
    }

    /// Sends [`LOAD`] blocks at once; (feedback messages, seconds from first to last).
    fn load(&mut self) -> (usize, f64) {
        for k in 0..LOAD {
            let b = block(&format!("l{k}")).into_bytes();
            self.wire.send(&self.blocks, b, &[]);
        }
        self.wire.flush();
        let (mut count, mut ends, mut syncs, mut first, mut last) =
            (0usize, 0usize, 0usize, None, Instant::now());
        let deadline = Instant::now() + Duration::from_secs(120);
        while ends < LOAD && Instant::now() < deadline {
            self.wire.flush();
            let Some(Inbound::Message { topic, payload }) =
                self.wire.recv_timeout(Duration::from_millis(100))
            else {
                continue;
            };
            if topic != self.feedback {
                continue;
            }
            let now = Instant::now();
            first.get_or_insert(now);
            last = now;
            count += 1;
            let text = String::from_utf8_lossy(&payload);
            ends += usize::from(text.contains("blockProgress") && text.contains(":end\""));
            syncs += usize::from(text.contains("syncPointProgress"));
        }
        let secs = last.duration_since(first.unwrap_or(last)).as_secs_f64();
        println!(
            "{}: load: {count} feedback messages in {secs:.3} s = {:.0} messages/s; {ends} of {LOAD} blocks ended, {syncs} sync points",
            self.name,
            count as f64 / secs.max(1e-9)
        );
        assert_eq!(ends, LOAD, "{}: blocks did not end", self.name);
        assert_eq!(syncs, 7 * LOAD, "{}: sync points missing", self.name);
        (count, secs)
    }

    /// Block → its first feedback message (ms), [`ONE_BY_ONE`] blocks one at a time.
    fn latency(&mut self) -> Vec<f64> {
        let mut ms = Vec::new();
        for k in 0..ONE_BY_ONE {
            let id = format!("m{k}");
            let sent = Instant::now();
            self.wire.send(&self.blocks, block(&id).into_bytes(), &[]);
            self.wire.flush();
            loop {
                let Some(i) = self.wire.recv_timeout(Duration::from_secs(5)) else {
                    panic!("{}: no feedback for {id}", self.name);
                };
                if let Inbound::Message { payload, .. } = i {
                    if String::from_utf8_lossy(&payload).contains(&format!("\"{id}:")) {
                        ms.push(sent.elapsed().as_secs_f64() * 1e3);
                        break;
                    }
                }
            }
            std::thread::sleep(Duration::from_millis(5));
        }
        ms
    }
}

/// Block → its first feedback line through a `serve --stdio` pipe (ms).
fn stdio_latency() -> Vec<f64> {
    let mut child = Command::new(bmlr())
        .args(["serve", "--stdio", "--no-idle"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdin = child.stdin.take().unwrap();
    let mut lines = BufReader::new(child.stdout.take().unwrap()).lines();
    let mut ms = Vec::new();
    for k in 0..ONE_BY_ONE {
        let id = format!("s{k}");
        let sent = Instant::now();
        writeln!(stdin, "{}", block(&id)).unwrap();
        stdin.flush().unwrap();
        for line in lines.by_ref() {
            if line.unwrap().contains(&format!("\"{id}:")) {
                ms.push(sent.elapsed().as_secs_f64() * 1e3);
                break;
            }
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    drop(stdin);
    let _ = child.kill();
    let _ = child.wait();
    ms
}

fn percentile(sorted: &[f64], p: f64) -> f64 {
    sorted[((sorted.len() - 1) as f64 * p).round() as usize]
}

/// (median, p99, worst) of `ms`.
fn summary(mut ms: Vec<f64>) -> [f64; 3] {
    ms.sort_by(f64::total_cmp);
    [0.5, 0.99, 1.0].map(|p| percentile(&ms, p))
}

fn main() {
    let mut rows = Vec::new();
    for start in [on_mosquitto, on_activemq] {
        let Some(mut served) = start() else { continue };
        served.wait_ready();
        let (count, secs) = served.load();
        let latency = summary(served.latency());
        rows.push((served.name, count, secs, latency));
    }
    let stdio = summary(stdio_latency());
    println!("\n| | feedback rate | block → first feedback: median | p99 | worst |");
    println!("|---|---|---|---|---|");
    println!(
        "| `serve --stdio` | | {:.3} ms | {:.3} ms | {:.3} ms |",
        stdio[0], stdio[1], stdio[2]
    );
    for (name, count, secs, [median, p99, worst]) in rows {
        println!(
            "| {name} | {:.0} messages/s ({count} in {secs:.2} s) | {median:.3} ms (+{:.3}) | {p99:.3} ms (+{:.3}) | {worst:.3} ms |",
            count as f64 / secs.max(1e-9),
            median - stdio[0],
            p99 - stdio[1],
        );
    }
}
