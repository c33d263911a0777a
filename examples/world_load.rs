//! One world over many realizers on one mosquitto, shared by area against everyone to everyone,
//! measured in one run (`docs/broker.md`, `docs/performance.md`):
//!
//! ```sh
//! cargo build --release && cargo run --release --example world_load [REALIZERS [EACH [SECS]]]
//! ```
//!
//! REALIZERS `bmlr serve --mqtt` processes (8 by default) each serve EACH walkers (1 250): the
//! floor is cut into districts of 70 × 70 m in two rows, one per realizer, and each walker sets
//! off for a spot in the next district. The same scene runs twice for SECS seconds of wall time
//! (20): shared by cells of 10 m (the default), then with `--cell 0` (one cell: every realizer
//! hears every state, the everyone-to-everyone design). For each realizer: the states it heard,
//! those it published, the CPU it used (user + system, from /proc) and mosquitto's. It starts
//! its own mosquitto on a free loopback port (Debian package `mosquitto`) and the `bmlr` built
//! beside this example.

use std::io::Read;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use bml_realizer::ports::broker::{BrokerUrl, Inbound, Link, LinkOptions};

#[path = "common/process.rs"]
mod process;
use process::{bmlr, Kill};
// (the broker tests' mosquitto starter, shared rather than copied)
#[path = "../tests/common/mosquitto.rs"]
mod kit;

const NS: &str = r#"xmlns="http://www.bml-initiative.org/bml/bml-1.0""#;

/// A district's side (m); walkers keep 2 m from its edges, 1.2 m from each other.
const DISTRICT: f32 = 70.0;

// (the same scene for the same seed, shared by the examples)
#[path = "common/lcg.rs"]
mod lcg;
use lcg::Lcg;

/// District `k`'s corner nearest the origin (two rows, as many columns as needed).
fn district(k: usize, count: usize) -> (f32, f32) {
    let columns = count.div_ceil(2);
    (
        (k % columns) as f32 * DISTRICT,
        (k / columns) as f32 * DISTRICT,
    )
}

/// `n` spots in district `k`, 1.2 m apart (checked against the last 300: a grid of jittered
/// spots would do as well).
fn spots(rng: &mut Lcg, corner: (f32, f32), n: usize) -> Vec<(f32, f32)> {
    let mut out: Vec<(f32, f32)> = Vec::new();
    while out.len() < n {
        let p = (
            corner.0 + 2.0 + rng.unit() * (DISTRICT - 4.0),
            corner.1 + 2.0 + rng.unit() * (DISTRICT - 4.0),
        );
        let clear = (out.iter().rev().take(300)).all(|q| (p.0 - q.0).hypot(p.1 - q.1) >= 1.2);
        if clear {
            out.push(p);
        }
    }
    out
}

/// CPU seconds (user + system) process `pid` has used, from /proc.
fn cpu_seconds(pid: u32) -> f64 {
    let Ok(stat) = std::fs::read_to_string(format!("/proc/{pid}/stat")) else {
        return f64::NAN;
    };
    // (fields after the command's closing parenthesis; utime and stime are the 12th and 13th)
    let rest = stat.rsplit_once(')').map_or("", |r| r.1);
    let f: Vec<&str> = rest.split_whitespace().collect();
    let field = |k: usize| {
        f.get(k)
            .and_then(|v| v.parse::<f64>().ok())
            .unwrap_or(f64::NAN)
    };
    let tick = 100.0; // (USER_HZ on Linux)
    (field(11) + field(12)) / tick
}

/// What one realizer said and used.
struct Measured {
    dropped: f64,
    heard: f64,
    published: f64,
    cells: f64,
    cpu: f64,
}

/// A field's number in a realizer's world summary line (`heard N states, published N, …`).
fn field(summary: &str, name: &str) -> f64 {
    let words: Vec<&str> = (summary.split([' ', ',']))
        .filter(|w| !w.is_empty())
        .collect();
    (words.iter().position(|w| *w == name))
        .and_then(|k| words.get(k + 1)?.parse().ok())
        .unwrap_or(f64::NAN)
}

/// Runs the scene once with `--cell cell`; per realizer what it heard and used, and
/// mosquitto's CPU.
fn run(
    world: &std::path::Path,
    trips: &[Vec<(String, (f32, f32))>],
    cell: &str,
    secs: f64,
) -> Option<(Vec<Measured>, f64)> {
    let broker = kit::Broker::tuned(true)?;
    let url = broker.url();
    let mut realizers: Vec<Kill> = (trips.iter().enumerate())
        .map(|(k, mine)| {
            let ids: Vec<&str> = mine.iter().map(|t| t.0.as_str()).collect();
            let child = Command::new(bmlr())
                .args(["serve", "--mqtt", &url, "--name", &format!("r{k}")])
                .args(["--characters", &ids.join(","), "--cell", cell])
                .arg("--world")
                .arg(world)
                .args(["--no-idle", "--fps", "20"])
                .stdout(Stdio::null())
                .stderr(Stdio::piped())
                .spawn()
                .expect("bmlr runs (cargo build --release first)");
            Kill(child)
        })
        .collect();
    // (their stderr read as it comes: a full pipe would stop a realizer that says much)
    let said: Vec<std::thread::JoinHandle<String>> = (realizers.iter_mut())
        .map(|r| {
            let mut e = r.0.stderr.take().expect("stderr is piped");
            std::thread::spawn(move || {
                let mut text = String::new();
                let _ = e.read_to_string(&mut text);
                text
            })
        })
        .collect();
    let mut planner = Link::connect(LinkOptions {
        url: BrokerUrl::parse(&url).unwrap(),
        client_id: "planner".into(),
        subscriptions: vec!["bml/realizers/+".into(), "bml/+/feedback".into()],
        presence: None,
        inbox: 100_000,
        start_tries: 6,
    })
    .ok()?;
    // every realizer online before the walks start
    let (mut online, until) = (0, Instant::now() + Duration::from_secs(120));
    while online < trips.len() && Instant::now() < until {
        if let Some(Inbound::Message { payload, .. }) =
            planner.recv_timeout(Duration::from_millis(50))
        {
            online += usize::from(payload == b"online");
        }
    }
    let started = Instant::now();
    for (id, (x, z)) in trips.iter().flatten() {
        let bml = format!(r#"<bml {NS} id="cross"><locomotion id="w" target="{x},{z}"/></bml>"#);
        planner.publish(&format!("bml/{id}/bml"), bml.into_bytes(), false);
    }
    while planner.waiting() > 0 {
        planner.flush();
        std::thread::sleep(Duration::from_millis(5));
    }
    // (the walks that started and ended are counted)
    let (mut set_off, mut arrived) = (0usize, 0usize);
    while started.elapsed().as_secs_f64() < secs {
        if let Some(Inbound::Message { payload, .. }) =
            planner.recv_timeout(Duration::from_millis(50))
        {
            let text = String::from_utf8_lossy(&payload);
            set_off += usize::from(text.contains(r#"id="cross:start""#));
            arrived += usize::from(text.contains(r#"id="cross:end""#));
        }
    }
    println!("(--cell {cell}: {set_off} walks started, {arrived} ended within {secs} s)");
    let broker_cpu = cpu_seconds(broker.pid());
    let cpus: Vec<f64> = realizers.iter().map(|r| cpu_seconds(r.0.id())).collect();
    for r in &realizers {
        let _ = Command::new("kill")
            .args(["-TERM", &r.0.id().to_string()])
            .status();
    }
    let mut out = Vec::new();
    for ((r, cpu), said) in realizers.iter_mut().zip(cpus).zip(said) {
        let _ = r.0.wait();
        let err = said.join().unwrap_or_default();
        let summary = (err.lines())
            .find_map(|l| l.strip_prefix("bmlr serve: world: "))
            .unwrap_or("");
        out.push(Measured {
            heard: field(summary, "heard"),
            published: field(summary, "published"),
            cells: field(summary, "to"),
            dropped: field(summary, "dropped"),
            cpu,
        });
    }
    drop(broker);
    Some((out, broker_cpu))
}

fn main() {
    let arg = |k: usize, default: f64| -> f64 {
        std::env::args()
            .nth(k)
            .and_then(|a| a.parse().ok())
            .unwrap_or(default)
    };
    let (count, each, secs) = (arg(1, 8.0) as usize, arg(2, 1250.0) as usize, arg(3, 20.0));
    let mut rng = Lcg(11);
    let mut characters = serde_json::Map::new();
    let mut trips: Vec<Vec<(String, (f32, f32))>> = Vec::new();
    for k in 0..count {
        let from = spots(&mut rng, district(k, count), each);
        let to = spots(&mut rng, district((k + 1) % count, count), each);
        let mut mine = Vec::new();
        for (n, (a, b)) in from.into_iter().zip(to).enumerate() {
            let id = format!("r{k}w{n}");
            characters.insert(id.clone(), serde_json::json!({"position": [a.0, 0.0, a.1]}));
            mine.push((id, b));
        }
        trips.push(mine);
    }
    let world = std::env::temp_dir().join(format!("world_load_{}.json", std::process::id()));
    let text = serde_json::json!({ "characters": characters }).to_string();
    std::fs::write(&world, text).expect("the world file is written");
    println!(
        "{count} realizers x {each} walkers = {} on one mosquitto, {secs} s of wall time each run",
        count * each
    );
    println!("design | realizer | states heard | published | heard/s | share of the others' states | cells at most | dropped | CPU s");
    for (design, cell) in [("cells of 10 m", "10"), ("everyone (--cell 0)", "0")] {
        let Some((measured, broker_cpu)) = run(&world, &trips, cell, secs) else {
            break;
        };
        let all: f64 = measured.iter().map(|m| m.published).sum();
        for (k, m) in measured.iter().enumerate() {
            println!(
                "{design} | r{k} | {} | {} | {:.0} | {:.1} % | {} | {} | {:.1}",
                m.heard,
                m.published,
                m.heard / secs,
                100.0 * m.heard / (all - m.published),
                m.cells,
                m.dropped,
                m.cpu
            );
        }
        let heard: f64 = measured.iter().map(|m| m.heard).sum();
        let cpu: f64 = measured.iter().map(|m| m.cpu).sum();
        println!(
            "{design} | all | {heard} | {all} | {:.0} | | | | {cpu:.1} (mosquitto {broker_cpu:.1})",
            heard / secs
        );
    }
    let _ = std::fs::remove_file(world);
}
