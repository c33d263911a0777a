//! A world shared over a broker, as a user records and watches it: `serve --mqtt … --frames`
//! writes what a served character did (the header, then frames on the real-time clock, up to
//! `--until`), and a walker held back by another realizer's people asks one of them for room —
//! the realizer that moves that one has it step aside, as a walker of its own would — so the
//! walker gets through a row it could not pass alone (tests/crowd_asking.rs is the same corridor
//! in one process).

#[path = "common/broker.rs"]
mod kit;

use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use glam::Vec2;
use kit::{ended, hear, planner_on, until_online, Broker, Served, NS};

fn temp(name: &str, port: u16) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("bmlr-broker-world-{port}"));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

#[test]
fn serve_frames_records_a_walk_on_the_real_time_clock_and_exits_at_until() {
    let Some(broker) = Broker::start() else {
        return;
    };
    let world = temp("world.json", broker.port);
    std::fs::write(
        &world,
        r#"{"characters": {"a": {"position": [0, 0, 0], "facing": 90}}}"#,
    )
    .unwrap();
    let frames = temp("frames.jsonl", broker.port);
    let mut p = planner_on(&broker, "planner", &["bml/+/feedback", "bml/realizers/+"]);
    let started = Instant::now();
    let mut r = Served(
        Command::new(env!("CARGO_BIN_EXE_bmlr"))
            .args(["serve", "--mqtt", &broker.url(), "--name", "r"])
            .args(["--characters", "a", "--world", world.to_str().unwrap()])
            .args(["--frames", frames.to_str().unwrap(), "--until", "8"])
            .stdout(Stdio::null())
            .stderr(Stdio::inherit())
            .spawn()
            .unwrap(),
    );
    until_online(&p, &["r"]);
    let bml = format!(r#"<bml {NS} id="walk"><locomotion id="w" target="2,0"/></bml>"#);
    p.publish("bml/a/bml", bml.into_bytes(), false);
    let heard = hear(&p, 10.0, |h| ended(h, "a", "walk"));
    assert!(ended(&heard, "a", "walk"), "{heard:?}");
    let status = r.wait().unwrap();
    let took = started.elapsed();
    assert!(status.success(), "{status}");
    assert!(
        (7.5..12.0).contains(&took.as_secs_f64()),
        "exited after {took:?}"
    );
    let lines: Vec<serde_json::Value> = (std::fs::read_to_string(&frames).unwrap().lines())
        .map(|l| serde_json::from_str(l).expect("a JSON line"))
        .collect();
    assert!(
        lines[0]["skeleton"]["joints"].is_array(),
        "the header first"
    );
    let roots: Vec<(f64, Vec2)> = (lines[1..].iter())
        .map(|f| {
            let root = &f["characters"]["a"]["root"];
            let x = |k: usize| root[k].as_f64().unwrap() as f32;
            (f["time"].as_f64().unwrap(), Vec2::new(x(0), x(2)))
        })
        .collect();
    // real time up to --until, in order
    let last = roots.last().unwrap().0;
    assert!((7.9..=8.0).contains(&last), "the last frame at {last} s");
    assert!(roots.windows(2).all(|w| w[0].0 < w[1].0));
    // (the loop also ticks when messages arrive: the file still holds about 60 frames a second)
    assert!((400..=490).contains(&roots.len()), "{} frames", roots.len());
    let gap = (roots.windows(2))
        .map(|w| w[1].0 - w[0].0)
        .fold(0f64, f64::max);
    assert!(gap < 0.1, "a gap of {gap} s between frames");
    // the root went from (0, 0) to the target (2, 0)
    assert!(roots[0].1.distance(Vec2::ZERO) < 0.05, "{:?}", roots[0]);
    let end = roots.last().unwrap().1;
    assert!(end.distance(Vec2::new(2.0, 0.0)) < 0.15, "ended at {end}");
    let _ = std::fs::remove_dir_all(world.parent().unwrap());
}

/// A realizer serving `characters` of the world file `world`, as `name`.
fn serving(broker: &Broker, name: &str, characters: &str, world: &str) -> Served {
    Served(
        Command::new(env!("CARGO_BIN_EXE_bmlr"))
            .args(["serve", "--mqtt", &broker.url(), "--name", name])
            .args(["--characters", characters, "--world", world, "--no-idle"])
            .stdout(Stdio::null())
            .stderr(Stdio::inherit())
            .spawn()
            .unwrap(),
    )
}

#[test]
fn a_walker_held_back_by_another_realizer_s_row_asks_and_one_of_them_steps_aside() {
    let Some(broker) = Broker::start() else {
        return;
    };
    // the corridor of tests/crowd_asking.rs: 4.6 m wide, shut at z = 3 by six people with gaps
    // of 0.3 m between bodies 0.5 m wide; the walker is one realizer's, the row another's
    let row = [-1.95f32, -1.15, -0.35, 0.45, 1.25, 2.05];
    let people: Vec<String> = (row.iter().enumerate())
        .map(|(k, x)| format!(r#""s{k}": {{"position": [{x}, 0, 3], "facing": 180}}"#))
        .collect();
    let world = temp("corridor.json", broker.port);
    std::fs::write(
        &world,
        format!(
            r#"{{"obstacles": [{{"box": [-4, -1, -2.3, 8], "height": 2}}, {{"box": [2.3, -1, 4, 8], "height": 2}}],
                "characters": {{"w": {{"position": [0.1, 0, 0]}}, {}}}}}"#,
            people.join(", ")
        ),
    )
    .unwrap();
    let w = world.to_str().unwrap();
    let names: Vec<String> = (0..row.len()).map(|k| format!("s{k}")).collect();
    let _walker = serving(&broker, "rw", "w", w);
    let _row = serving(&broker, "rs", &names.join(","), w);
    let mut p = planner_on(
        &broker,
        "planner",
        &["bml/+/feedback", "bml/realizers/+", "bml/world/+/+"],
    );
    until_online(&p, &["rw", "rs"]);
    // (both have heard each other's states)
    std::thread::sleep(Duration::from_millis(500));
    let bml = format!(r#"<bml {NS} id="through"><locomotion id="l" target="0.1,6"/></bml>"#);
    p.publish("bml/w/bml", bml.into_bytes(), false);
    let heard = hear(&p, 25.0, |h| ended(h, "w", "through"));
    let warned: Vec<_> = (heard.iter())
        .filter(|(_, m)| m.contains("warningFeedback"))
        .collect();
    assert!(warned.is_empty(), "{warned:?}");
    assert!(ended(&heard, "w", "through"), "the walk did not end");
    // (and the one who stepped aside goes back: after a second without asks)
    let mut heard = heard;
    heard.extend(hear(&p, 4.0, |_| false));
    let states: Vec<(String, bml_realizer::ports::broker::RootState)> = (heard.iter())
        .filter_map(|(t, m)| {
            let (_cell, id) = t.strip_prefix("bml/world/")?.split_once('/')?;
            Some((
                id.to_string(),
                bml_realizer::ports::broker::RootState::from_json(m.as_bytes()).ok()?,
            ))
        })
        .collect();
    let at = |s: &bml_realizer::ports::broker::RootState| Vec2::new(s.position[0], s.position[2]);
    // the walker asked one of the row (its states say whom), and that one stepped aside
    let asked: Vec<&str> = (states.iter())
        .filter(|(id, _)| id == "w")
        .filter_map(|(_, s)| s.asks.as_deref())
        .collect();
    assert!(!asked.is_empty(), "the walker never asked anyone");
    assert!(
        asked.iter().all(|a| names.iter().any(|n| n == a)),
        "{asked:?}"
    );
    let farthest = (states.iter())
        .filter_map(|(id, s)| {
            let k: usize = id.strip_prefix('s')?.parse().ok()?;
            Some(at(s).distance(Vec2::new(row[k], 3.0)))
        })
        .fold(0f32, f32::max);
    eprintln!(
        "asked {:?}; the farthest one of the row stepped: {farthest} m",
        asked.first()
    );
    assert!(farthest > 0.2, "nobody stepped aside ({farthest} m)");
    // bodies of 0.25 m, each seen as its realizer last said: never closer than 0.45 m
    let mut last: std::collections::BTreeMap<&str, Vec2> = Default::default();
    let mut closest = f32::INFINITY;
    for (id, s) in &states {
        last.insert(id, at(s));
        if let Some(w) = last.get("w") {
            for p in (last.iter()).filter(|(o, _)| **o != "w").map(|o| o.1) {
                closest = closest.min(w.distance(*p));
            }
        }
    }
    eprintln!("the walker came {closest} m from one of the row");
    assert!(
        closest >= 0.45,
        "the walker came {closest} m from one of the row"
    );
    for (k, home) in row.iter().enumerate() {
        let back = last[format!("s{k}").as_str()];
        // (one pressed less than the crowd's DISPLACED from its place stays where it is)
        assert!(
            back.distance(Vec2::new(*home, 3.0))
                <= bml_realizer::world::crowd::sim::DISPLACED + 0.002,
            "s{k} is at {back}, not back at its place"
        );
    }
    let end = (states.iter()).rev().find(|(id, _)| id == "w").unwrap();
    assert!(
        at(&end.1).distance(Vec2::new(0.1, 6.0)) < 0.15,
        "the walker ended at {}",
        at(&end.1)
    );
    let _ = std::fs::remove_dir_all(world.parent().unwrap());
}
