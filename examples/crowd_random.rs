//! Random crowds, tried as a new user would: N whole-body walkers on random trips in a square,
//! realized in-process at a host's frame rate and judged from every frame.
//!
//! ```sh
//! cargo run --release --example crowd_random [N [SIDE [FPS [SEED [UNTIL]]]]]
//! cargo run --release --example crowd_random door|door10|corridor|corridor15 [FPS [UNTIL]]
//! ```
//!
//! N walkers (300 by default) start and end at random spots of a SIDE × SIDE m square (30),
//! starts 0.8 m apart and goals 0.8 m apart, each sent `<locomotion target="x,z"/>` at t = 0;
//! the realizer is ticked at FPS (10) until every block has ended, or UNTIL seconds (60), with
//! generator SEED (1). Printed: who did not arrive (within 0.3 m of its goal, its block ended)
//! and what they said, the closest two roots came, the fastest a root moved between frames, the
//! largest drop of the hips between frames, and the wall time against the scene's time.
//!
//! `door`: a wall with a 0.9 m door, 30 walkers on each side crossing to the other (`door10`:
//! 10 a side); `corridor` (`corridor15`: 15 each way, 40 m long):
//! a 4 m wide corridor, 100 walking each way (UNTIL 150 s). Printed besides: how near a root
//! came to a wall.
//!
//! `PICTURE=file.png` draws a contact sheet of the floor from above every `PICTURE_EVERY`
//! seconds (5) over the area `PICTURE_AREA=x0,z0,x1,z1` (the walkers' starts and goals),
//! `PICTURE_COLUMNS` panels a row (4).

use std::time::Instant;

use bml_realizer::language::feedback::Feedback;
use bml_realizer::world::space::distance::point_segment;
use glam::{Vec2, Vec3};

/// A walker within this of its goal has arrived (m).
const ARRIVED: f32 = 0.3;

// (the same scenes for the same seed, shared with tests/crowd_press.rs)
#[path = "common/lcg.rs"]
mod lcg;
#[path = "common/trips.rs"]
mod trips;
use trips::{id, passage, trips, walking, SETTLE};
#[path = "common/sheet.rs"]
mod sheet;

fn argument<T: std::str::FromStr>(k: usize, default: T) -> T {
    std::env::args()
        .nth(k)
        .map(|s| (s.parse().ok()).unwrap_or_else(|| panic!("argument {k} '{s}' is not a number")))
        .unwrap_or(default)
}

/// What the frames showed.
#[derive(Default)]
struct Seen {
    closest: (f32, usize, usize, f64),
    fastest: (f32, usize, f64),
    drop: (f32, usize, f64),
    /// The nearest a root came to a wall (m), who, when.
    wall: (f32, usize, f64),
}

fn main() {
    let scene = std::env::args()
        .nth(1)
        .filter(|a| a.parse::<f64>().is_err());
    let (mut r, goals, walls, what, fps, until) = match scene.as_deref() {
        Some(name) => {
            let Some(trips::Passage {
                starts,
                goals,
                walls,
            }) = passage(name)
            else {
                eprintln!("crowd_random: no scene '{name}' (door, door10, corridor or corridor15)");
                std::process::exit(2);
            };
            let r = walking(&starts, &goals, &walls);
            let fps: f64 = argument(2, 10.0);
            let what = format!("{} walkers, {name}, {fps} fps", goals.len());
            (r, goals, walls, what, fps, argument(3, 150.0))
        }
        None => {
            let n: usize = argument(1, 300);
            let side: f32 = argument(2, 30.0);
            let fps: f64 = argument(3, 10.0);
            let seed: u64 = argument(4, 1);
            let (r, goals) = trips(n, side, seed);
            let what = format!("{n} walkers, {side} m square, {fps} fps, seed {seed}");
            (r, goals, Vec::new(), what, fps, argument(5, 60.0))
        }
    };
    let n = goals.len();

    let clock = Instant::now();
    let mut seen = Seen {
        closest: (f32::MAX, 0, 0, 0.0),
        wall: (f32::MAX, 0, 0.0),
        ..Seen::default()
    };
    let mut ended = vec![false; n];
    let mut all_ended = None;
    let mut said: Vec<Vec<String>> = vec![Vec::new(); n];
    let mut last: Vec<Option<Vec3>> = vec![None; n];
    let mut frame = 0u32;
    let mut time = 0.0;
    let picture = std::env::var("PICTURE").ok();
    let every: f64 = (std::env::var("PICTURE_EVERY").ok())
        .and_then(|s| s.parse().ok())
        .unwrap_or(5.0);
    let mut sheet = sheet::Sheet::default();
    while time <= until {
        time = f64::from(frame) / fps;
        frame += 1;
        let f = r.tick(time);
        for fb in &f.feedback {
            let (block, text, end) = match fb {
                Feedback::BlockProgress(p) => {
                    (p.block.as_str(), String::new(), p.sync.as_str() == "end")
                }
                Feedback::Warning(w) => (w.id.as_str(), w.text.clone(), false),
                _ => continue,
            };
            let k = (block.trim_start_matches('b').split(':').next())
                .and_then(|s| s.parse::<usize>().ok());
            if let Some(k) = k.filter(|&k| k < n) {
                ended[k] |= end;
                if !text.is_empty() {
                    said[k].push(text);
                }
            }
        }
        let roots: Vec<Vec3> = (0..n)
            .map(|k| f.character(&id(k)).expect("a pose").pose.root)
            .collect();
        look(&roots, &mut last, &mut seen, time, fps);
        near_walls(&roots, &walls, &mut seen, time);
        trace(&roots, &goals, time, fps);
        if picture.is_some() && ((time / every).round() * every - time).abs() < 0.5 / fps {
            sheet.take(time, roots.iter().map(|p| Vec2::new(p.x, p.z)).collect());
        }
        // (once every walk has ended, those who stepped aside for a late one go back)
        if ended.iter().all(|&e| e) && *all_ended.get_or_insert(time) + SETTLE <= time {
            break;
        }
    }
    let wall = clock.elapsed().as_secs_f64();
    if let Some(path) = picture {
        let columns = (std::env::var("PICTURE_COLUMNS").ok())
            .and_then(|s| s.parse().ok())
            .unwrap_or(4);
        sheet.save(
            &path,
            area(&goals, last.as_slice()),
            columns,
            &walls,
            &goals,
        );
    }

    let mut stranded = 0;
    for k in 0..n {
        let at = last[k].map_or(Vec2::ZERO, |p| Vec2::new(p.x, p.z));
        let off = at.distance(goals[k]);
        if off > ARRIVED || !ended[k] {
            stranded += 1;
            println!(
                "{}: {off:.2} m from its goal {} (ended: {}) {:?}",
                id(k),
                goals[k],
                ended[k],
                said[k]
            );
        }
    }
    let (d, a, b, t) = seen.closest;
    let (v, who, tv) = seen.fastest;
    let (h, whoh, th) = seen.drop;
    println!("{what}: {stranded} did not arrive");
    println!(
        "closest roots {d:.3} m ({} and {} at {t:.1} s)",
        id(a),
        id(b)
    );
    println!("fastest root {v:.2} m/s ({} at {tv:.1} s)", id(who));
    println!(
        "largest hip drop {:.1} cm ({} at {th:.1} s)",
        h * 100.0,
        id(whoh)
    );
    if !walls.is_empty() {
        let (d, who, t) = seen.wall;
        println!("nearest a wall {d:.3} m ({} at {t:.1} s)", id(who));
    }
    println!("{time:.1} s of scene in {wall:.1} s wall");
}

/// The floor to draw: `PICTURE_AREA=x0,z0,x1,z1`, else round every goal and last place.
fn area(goals: &[Vec2], last: &[Option<Vec3>]) -> (Vec2, Vec2) {
    let given: Vec<f32> = (std::env::var("PICTURE_AREA").ok().into_iter())
        .flat_map(|s| {
            s.split(',')
                .filter_map(|v| v.parse().ok())
                .collect::<Vec<f32>>()
        })
        .collect();
    if let [a, b, c, d] = given[..] {
        return (Vec2::new(a, b), Vec2::new(c, d));
    }
    let places = (goals.iter().copied()).chain(last.iter().flatten().map(|p| Vec2::new(p.x, p.z)));
    let (lo, hi) = places.fold((Vec2::MAX, Vec2::MIN), |(lo, hi), p| (lo.min(p), hi.max(p)));
    (lo - Vec2::ONE, hi + Vec2::ONE)
}

/// Notes the nearest any of `roots` came to one of `walls` (segments [x1, z1, x2, z2]).
fn near_walls(roots: &[Vec3], walls: &[[f32; 4]], seen: &mut Seen, time: f64) {
    for (k, p) in roots.iter().enumerate() {
        let p = Vec2::new(p.x, p.z);
        for &[x1, z1, x2, z2] in walls {
            let (d, _) = point_segment(p, Vec2::new(x1, z1), Vec2::new(x2, z2));
            if d < seen.wall.0 {
                seen.wall = (d, k, time);
            }
        }
    }
}

/// With `TRACE=w0001,w0002` in the environment: those walkers' places every second (every
/// frame between `TRACE_FROM` and `TRACE_TO` seconds), their goals and the nearest other body.
fn trace(roots: &[Vec3], goals: &[Vec2], time: f64, fps: f64) {
    let Ok(ids) = std::env::var("TRACE") else {
        return;
    };
    // every frame within TRACE_FROM..TRACE_TO (s), else once a second
    let window = |name: &str| std::env::var(name).ok().and_then(|s| s.parse::<f64>().ok());
    let every = match (window("TRACE_FROM"), window("TRACE_TO")) {
        (Some(a), Some(b)) => (a..=b).contains(&time),
        _ => false,
    };
    if !every && (time * fps).round() as i64 % fps.round().max(1.0) as i64 != 0 {
        return;
    }
    let ground = |p: Vec3| Vec2::new(p.x, p.z);
    for k in (0..roots.len()).filter(|&k| ids.split(',').any(|s| s == id(k))) {
        let p = ground(roots[k]);
        let (d, j) = (0..roots.len())
            .filter(|&j| j != k)
            .map(|j| (ground(roots[j]).distance(p), j))
            .min_by(|a, b| a.0.total_cmp(&b.0))
            .unwrap_or((f32::MAX, k));
        println!(
            "{time:5.1} {} at {:6.2},{:6.2} goal {:.2} m; nearest {} {d:.2} m",
            id(k),
            p.x,
            p.y,
            p.distance(goals[k]),
            id(j)
        );
        if std::env::var("TRACE_NEAR").is_ok() {
            let g = goals[k] - p;
            for j in (0..roots.len()).filter(|&j| j != k) {
                let q = ground(roots[j]) - p;
                if q.length() < 2.0 {
                    println!(
                        "        {} at {:5.2},{:5.2} (ahead {:5.2}) its goal {:.2} m off",
                        id(j),
                        q.x,
                        q.y,
                        q.dot(g.normalize_or_zero()),
                        ground(roots[j]).distance(goals[j])
                    );
                }
            }
        }
    }
}

/// Judges one frame's roots against the last frame's.
fn look(roots: &[Vec3], last: &mut [Option<Vec3>], seen: &mut Seen, time: f64, fps: f64) {
    let ground = |p: Vec3| Vec2::new(p.x, p.z);
    // pairs by a grid of 1 m cells: only neighbours can be closer than the closest so far
    let mut cells: std::collections::HashMap<(i32, i32), Vec<usize>> = Default::default();
    for (k, p) in roots.iter().enumerate() {
        let c = (p.x.floor() as i32, p.z.floor() as i32);
        cells.entry(c).or_default().push(k);
    }
    for (k, p) in roots.iter().enumerate() {
        let (cx, cz) = (p.x.floor() as i32, p.z.floor() as i32);
        for dx in -1..=1 {
            for dz in -1..=1 {
                for &j in cells.get(&(cx + dx, cz + dz)).into_iter().flatten() {
                    let d = ground(*p).distance(ground(roots[j]));
                    if j > k && d < seen.closest.0 {
                        seen.closest = (d, k, j, time);
                    }
                }
            }
        }
        if let Some(q) = last[k] {
            let v = ground(*p).distance(ground(q)) * fps as f32;
            if v > seen.fastest.0 {
                seen.fastest = (v, k, time);
            }
            if q.y - p.y > seen.drop.0 {
                seen.drop = (q.y - p.y, k, time);
            }
        }
        last[k] = Some(*p);
    }
}
