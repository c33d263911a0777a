//! One world over four realizers on one mosquitto, shared by area: 4 realizers × 50 walkers,
//! each realizer's walkers crossing from its quadrant of a 100 × 100 m square into the next
//! one's (whose walkers leave for the one after). Everyone arrives, no two bodies come closer
//! than 0.45 m (the frames of all four realizers put on one clock by their `posix_zero`), the
//! states travel on the topics of their cells, and each realizer hears well under half of what
//! an everyone-to-everyone world would send it. Needs mosquitto (skipped, saying so, without).

#[path = "common/broker.rs"]
mod kit;

use std::collections::{BTreeMap, BTreeSet};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use bml_realizer::ports::broker::Inbound;
use glam::Vec2;
use kit::{planner_on, until_online, Broker, NS};

/// Walkers per realizer, and the realizers.
const EACH: usize = 50;
const REALIZERS: usize = 4;

/// The side of a quadrant (m); walkers keep 3 m from its edges.
const QUADRANT: f32 = 50.0;

/// The closest two bodies' roots may come (m).
const CLOSEST: f32 = 0.45;

/// A small deterministic generator (the scene is the same on every run).
struct Lcg(u64);

impl Lcg {
    fn unit(&mut self) -> f32 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }
}

/// The corner of quadrant `k` nearest the origin's opposite: quadrants go round clockwise
/// from north-east (+x, +z).
fn quadrant(k: usize) -> Vec2 {
    let (sx, sz) = [(1.0, 1.0), (1.0, -1.0), (-1.0, -1.0), (-1.0, 1.0)][k % 4];
    Vec2::new(
        if sx > 0.0 { 0.0 } else { -QUADRANT },
        if sz > 0.0 { 0.0 } else { -QUADRANT },
    )
}

/// `n` spots in quadrant `k`, at least 1.4 m apart and 3 m from its edges.
fn spots(rng: &mut Lcg, k: usize, n: usize) -> Vec<Vec2> {
    let mut out: Vec<Vec2> = Vec::new();
    while out.len() < n {
        let p = quadrant(k)
            + Vec2::new(3.0, 3.0)
            + Vec2::new(rng.unit(), rng.unit()) * (QUADRANT - 6.0);
        if out.iter().all(|q| q.distance(p) >= 1.4) {
            out.push(p);
        }
    }
    out
}

/// A realizer process whose stderr is kept (its summary of the world's traffic).
struct Realizer(Child);

impl Drop for Realizer {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// One realizer's frames: its characters' roots (x, z) at POSIX times.
fn roots(path: &std::path::Path) -> BTreeMap<String, Vec<(f64, Vec2)>> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header: serde_json::Value = serde_json::from_str(lines.next().unwrap()).unwrap();
    let zero = header["posix_zero"]
        .as_f64()
        .expect("the header has posix_zero");
    assert_eq!(header["roots_only"], true);
    let mut out: BTreeMap<String, Vec<(f64, Vec2)>> = BTreeMap::new();
    for line in lines {
        let Ok(frame) = serde_json::from_str::<serde_json::Value>(line) else {
            continue; // (the last line of a killed writer may be cut)
        };
        let t = zero + frame["time"].as_f64().unwrap();
        for (id, c) in frame["characters"].as_object().unwrap() {
            let r = &c["root"];
            let at = Vec2::new(r[0].as_f64().unwrap() as f32, r[2].as_f64().unwrap() as f32);
            out.entry(id.clone()).or_default().push((t, at));
        }
    }
    out
}

/// Where a track was at POSIX time `t` (linear between frames; `None` outside it).
fn at(track: &[(f64, Vec2)], t: f64) -> Option<Vec2> {
    let k = track.partition_point(|(s, _)| *s <= t);
    let (t0, p0) = *track.get(k.checked_sub(1)?)?;
    let (t1, p1) = *track.get(k)?;
    let f = ((t - t0) / (t1 - t0).max(1e-9)) as f32;
    Some(p0.lerp(p1, f))
}

#[test]
fn four_realizers_share_one_world_by_cells_and_everyone_crosses() {
    let Some(broker) = Broker::start() else {
        return;
    };
    let dir = std::env::temp_dir().join(format!("bmlr-cells-{}", broker.port));
    std::fs::create_dir_all(&dir).unwrap();
    let mut rng = Lcg(7);
    let mut characters = serde_json::Map::new();
    let mut trips = Vec::new();
    for k in 0..REALIZERS {
        let (from, to) = (spots(&mut rng, k, EACH), spots(&mut rng, k + 1, EACH));
        for (n, (a, b)) in from.into_iter().zip(to).enumerate() {
            let id = format!("q{k}w{n}");
            let facing = (b - a).x.atan2((b - a).y).to_degrees();
            characters.insert(
                id.clone(),
                serde_json::json!({"position": [a.x, 0.0, a.y], "facing": facing}),
            );
            trips.push((k, id, b));
        }
    }
    let world = dir.join("world.json");
    let text = serde_json::json!({ "characters": characters }).to_string();
    std::fs::write(&world, text).unwrap();
    let mut realizers = Vec::new();
    for k in 0..REALIZERS {
        let ids: Vec<&str> = (trips.iter())
            .filter(|t| t.0 == k)
            .map(|t| t.1.as_str())
            .collect();
        let frames = dir.join(format!("r{k}.jsonl"));
        let child = Command::new(env!("CARGO_BIN_EXE_bmlr"))
            .args(["serve", "--mqtt", &broker.url(), "--name", &format!("r{k}")])
            .args(["--characters", &ids.join(",")])
            .arg("--world")
            .arg(&world)
            .args(["--no-idle", "--fps", "20", "--frames-roots", "--frames"])
            .arg(&frames)
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .expect("bmlr runs");
        realizers.push(Realizer(child));
    }
    let names: Vec<String> = (0..REALIZERS).map(|k| format!("r{k}")).collect();
    let names: Vec<&str> = names.iter().map(String::as_str).collect();
    let p = planner_on(
        &broker,
        "planner",
        &["bml/+/feedback", "bml/realizers/+", "bml/world/+/+"],
    );
    until_online(&p, &names);
    let mut p = p;
    for (_, id, goal) in &trips {
        let bml = format!(
            r#"<bml {NS} id="cross"><locomotion id="w" target="{},{}"/></bml>"#,
            goal.x, goal.y
        );
        p.publish(&format!("bml/{id}/bml"), bml.into_bytes(), false);
    }
    // (the states are counted, not kept: a quarter of a million of them)
    let (mut arrived, mut warned, mut states) = (BTreeSet::new(), Vec::new(), 0usize);
    let until = Instant::now() + Duration::from_secs(180);
    while arrived.len() < trips.len() && Instant::now() < until {
        let Some(Inbound::Message { topic, payload }) = p.recv_timeout(Duration::from_millis(20))
        else {
            continue;
        };
        let text = String::from_utf8_lossy(&payload);
        if let Some(s) = topic.strip_prefix("bml/world/") {
            // states travel on the topics of their cells: bml/world/I_J/CHARACTER
            let (cell, who) = s.split_once('/').expect("bml/world/CELL/CHARACTER");
            let (i, j) = cell.split_once('_').expect("a cell is I_J");
            assert!(i.parse::<i64>().is_ok() && j.parse::<i64>().is_ok(), "{s}");
            assert!(trips.iter().any(|t| t.1 == who), "{s}");
            states += 1;
        } else if text.contains("warningFeedback") {
            warned.push((topic, text.into_owned()));
        } else if text.contains(r#"id="cross:end""#) {
            arrived.insert(topic);
        }
    }
    // the realizers stop (SIGTERM: they say what they heard, and the frames are flushed)
    for r in &realizers {
        let _ = Command::new("kill")
            .args(["-TERM", &r.0.id().to_string()])
            .status();
    }
    let mut said = Vec::new();
    for r in &mut realizers {
        let mut err = String::new();
        use std::io::Read;
        r.0.stderr.take().unwrap().read_to_string(&mut err).unwrap();
        let _ = r.0.wait();
        said.push(err);
    }
    let stuck: Vec<&str> = (trips.iter())
        .filter(|(_, id, _)| !arrived.contains(&format!("bml/{id}/feedback")))
        .map(|t| t.1.as_str())
        .collect();
    assert!(stuck.is_empty(), "not arrived: {stuck:?}\n{warned:?}");
    // A realizer late on its clock says so (four realizers planning 50 walks each at once on a
    // loaded two-core machine are); that is honest feedback, not a fault of the shared world.
    // Any other warning is.
    let (late, other): (Vec<_>, Vec<_>) =
        (warned.iter()).partition(|(_, text)| text.contains("the realizer fell behind its clock"));
    if !late.is_empty() {
        eprintln!("{} warnings of a realizer behind its clock", late.len());
    }
    assert!(other.is_empty(), "{other:?}");
    assert!(states > 0);
    // each realizer heard under 40 % of what everyone-to-everyone would have sent it: every
    // state the other realizers published (its own do not come back: the subscriptions are
    // MQTT 5 "no local")
    let summary = |err: &str, field: &str| -> f64 {
        let line = (err.lines())
            .find_map(|l| l.strip_prefix("bmlr serve: world: "))
            .unwrap_or_else(|| panic!("no world summary: {err}"));
        let words: Vec<&str> = line.split([' ', ',']).filter(|w| !w.is_empty()).collect();
        let k = words.iter().position(|w| *w == field).unwrap();
        words[k + 1].parse().unwrap()
    };
    let everyone: f64 = said.iter().map(|e| summary(e, "published")).sum();
    for (k, err) in said.iter().enumerate() {
        let heard = summary(err, "heard");
        let others = everyone - summary(err, "published");
        let share = heard / others;
        eprintln!(
            "r{k}: heard {heard} of {others} the others published ({:.1} %)",
            100.0 * share
        );
        assert!(share < 0.4, "r{k} heard {heard} of {others}");
    }
    // (the planner, listening to every cell, heard what was published)
    eprintln!("the planner heard {states} states");
    // no two bodies closer than CLOSEST, on one clock, every 50 ms
    let mut tracks = BTreeMap::new();
    for k in 0..REALIZERS {
        tracks.extend(roots(&dir.join(format!("r{k}.jsonl"))));
    }
    assert_eq!(tracks.len(), REALIZERS * EACH);
    let from = tracks.values().map(|t| t[0].0).fold(f64::MIN, f64::max);
    let to = tracks
        .values()
        .map(|t| t.last().unwrap().0)
        .fold(f64::MAX, f64::min);
    let ids: Vec<&String> = tracks.keys().collect();
    let (mut closest, mut pair, mut t) = (f32::INFINITY, (0, 0, 0.0), from);
    while t <= to {
        let here: Vec<Option<Vec2>> = ids.iter().map(|id| at(&tracks[*id], t)).collect();
        for a in 0..here.len() {
            for b in a + 1..here.len() {
                if let (Some(p), Some(q)) = (here[a], here[b]) {
                    let d = p.distance(q);
                    if d < closest {
                        (closest, pair) = (d, (a, b, t - from));
                    }
                }
            }
        }
        t += 0.05;
    }
    eprintln!(
        "closest: {closest:.3} m ({} and {} at {:.2} s)",
        ids[pair.0], ids[pair.1], pair.2
    );
    assert!(
        closest >= CLOSEST,
        "{} and {} came {closest} m apart",
        ids[pair.0],
        ids[pair.1]
    );
    // and everyone ended within 0.3 m of the goal
    for (_, id, goal) in &trips {
        let end = tracks[id].last().unwrap().1;
        assert!(
            end.distance(*goal) < 0.3,
            "{id} ended {} m from its goal",
            end.distance(*goal)
        );
    }
    std::thread::sleep(Duration::from_millis(10));
    let _ = std::fs::remove_dir_all(&dir);
}
