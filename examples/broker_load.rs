//! Load and latency of `bmlr serve --mqtt` on a mosquitto on loopback, measured beside
//! `bmlr serve --stdio` in one run (`docs/broker.md`, `docs/performance.md`):
//!
//! ```sh
//! cargo build --release && cargo run --release --example broker_load
//! ```
//!
//! - Load: 3 000 blocks published at once (QoS 1); every feedback message counted until every
//!   block has ended; the rate is messages over the time from the first to the last, and
//!   nothing may be missing (each block's start, its sync points and its end).
//! - Latency: 300 blocks one at a time; the time from sending a block to its first feedback
//!   message, through the broker and through a `serve --stdio` pipe.
//!
//! It starts its own mosquitto (Debian package `mosquitto`) on a free port and the `bmlr`
//! built beside this example.

use std::io::{BufRead, BufReader, Write};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use bml_realizer::broker::{BrokerUrl, Inbound, Link, LinkOptions};

const NS: &str = r#"xmlns="http://www.bml-initiative.org/bml/bml-1.0""#;

fn block(id: &str) -> String {
    format!(r#"<bml {NS} id="{id}"><head id="h" lexeme="NOD" start="0" end="0.2"/></bml>"#)
}

/// Killed when dropped.
struct Kill(Child);

impl Drop for Kill {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

fn bmlr() -> std::path::PathBuf {
    let exe = std::env::current_exe().expect("this example's path");
    exe.parent()
        .and_then(|d| d.parent())
        .expect("the target directory")
        .join("bmlr")
}

fn percentile(sorted: &[f64], p: f64) -> f64 {
    sorted[((sorted.len() - 1) as f64 * p).round() as usize]
}

fn summary(name: &str, mut ms: Vec<f64>) -> (f64, f64, f64) {
    ms.sort_by(f64::total_cmp);
    let (median, p99, worst) = (
        percentile(&ms, 0.5),
        percentile(&ms, 0.99),
        ms[ms.len() - 1],
    );
    println!(
        "{name}: median {median:.3} ms, p99 {p99:.3} ms, worst {worst:.3} ms ({} blocks)",
        ms.len()
    );
    (median, p99, worst)
}

/// Whether the broker is told to set TCP_NODELAY (`BROKER_NODELAY=false` to see without).
fn nodelay() -> bool {
    std::env::var("BROKER_NODELAY").map_or(true, |v| v != "false")
}

fn main() {
    let port = std::net::TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port();
    // (mosquitto's own sockets wait for acknowledgements unless told not to: set_tcp_nodelay)
    let conf = std::env::temp_dir().join(format!("broker_load_{port}.conf"));
    std::fs::write(
        &conf,
        format!(
            "listener {port} 127.0.0.1\nallow_anonymous true\nset_tcp_nodelay {}\n",
            nodelay()
        ),
    )
    .unwrap();
    let spawn = |p: &str| {
        Command::new(p)
            .args(["-c", conf.to_str().unwrap()])
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
    };
    let Ok(broker) = spawn("mosquitto").or_else(|_| spawn("/usr/sbin/mosquitto")) else {
        eprintln!("broker_load: mosquitto is not installed (Debian package mosquitto)");
        std::process::exit(2);
    };
    let _broker = Kill(broker);
    while std::net::TcpStream::connect(("127.0.0.1", port)).is_err() {
        std::thread::sleep(Duration::from_millis(20));
    }
    let url = format!("mqtt://127.0.0.1:{port}");
    let _realizer = Kill(
        Command::new(bmlr())
            .args(["serve", "--mqtt", &url, "--name", "load", "--no-idle"])
            .stderr(Stdio::null())
            .spawn()
            .expect("bmlr built beside this example"),
    );
    let mut link = Link::connect(LinkOptions {
        url: BrokerUrl::parse(&url).unwrap(),
        client_id: "planner".into(),
        subscriptions: vec!["bml/+/feedback".into(), "bml/realizers/+".into()],
        presence: None,
        inbox: 1_000_000,
        start_tries: 6,
    })
    .expect("the broker");
    // wait for the realizer
    loop {
        if let Some(Inbound::Message { topic, .. }) = link.recv_timeout(Duration::from_secs(10)) {
            if topic == "bml/realizers/load" {
                break;
            }
        }
    }

    // load
    let n = 3_000;
    for k in 0..n {
        link.publish("bml/_/bml", block(&format!("l{k}")).into_bytes(), false);
    }
    link.flush();
    let (mut count, mut ends, mut syncs, mut first, mut last) =
        (0usize, 0usize, 0usize, None, Instant::now());
    let deadline = Instant::now() + Duration::from_secs(120);
    while ends < n && Instant::now() < deadline {
        link.flush();
        if let Some(Inbound::Message { topic, payload }) =
            link.recv_timeout(Duration::from_millis(100))
        {
            if topic != "bml/_/feedback" {
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
    }
    let secs = last.duration_since(first.unwrap_or(last)).as_secs_f64();
    println!(
        "load: {count} feedback messages in {secs:.3} s = {:.0} messages/s; {ends} of {n} blocks ended, {syncs} sync points",
        count as f64 / secs.max(1e-9)
    );

    // latency through the broker
    let mut broker_ms = Vec::new();
    for k in 0..300 {
        let id = format!("m{k}");
        let sent = Instant::now();
        link.publish("bml/_/bml", block(&id).into_bytes(), false);
        link.flush();
        loop {
            if let Some(Inbound::Message { payload, .. }) =
                link.recv_timeout(Duration::from_secs(5))
            {
                if String::from_utf8_lossy(&payload).contains(&format!("\"{id}")) {
                    broker_ms.push(sent.elapsed().as_secs_f64() * 1e3);
                    break;
                }
            } else {
                panic!("no feedback for {id}");
            }
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    // and through a stdio pipe
    let mut child = Command::new(bmlr())
        .args(["serve", "--stdio", "--no-idle"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdin = child.stdin.take().unwrap();
    let mut lines = BufReader::new(child.stdout.take().unwrap()).lines();
    let mut stdio_ms = Vec::new();
    for k in 0..300 {
        let id = format!("s{k}");
        let sent = Instant::now();
        writeln!(stdin, "{}", block(&id)).unwrap();
        stdin.flush().unwrap();
        for line in lines.by_ref() {
            if line.unwrap().contains(&format!("\"{id}")) {
                stdio_ms.push(sent.elapsed().as_secs_f64() * 1e3);
                break;
            }
        }
        std::thread::sleep(Duration::from_millis(5));
    }
    drop(stdin);
    let _ = child.kill();
    let _ = child.wait();
    let b = summary("through the broker", broker_ms);
    let s = summary("through serve --stdio", stdio_ms);
    println!(
        "added by the broker: median {:.3} ms, p99 {:.3} ms, worst {:.3} ms",
        b.0 - s.0,
        b.1 - s.1,
        b.2 - s.2
    );
}
