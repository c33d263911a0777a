//! The quality table of `docs/crowds.md`: every scene of `crowd::scenes` walked by the
//! realizer's avoidance (`crowd::sim`, roots only) and by ORCA (`dodgy_2d`), side by side, at
//! 30 steps a second for at most 120 s.
//!
//! `cargo run --release --example crowd_quality`

#[path = "../benches/common/orca.rs"]
mod orca;

use bml_realizer::crowd::quality::{measure, Quality, Track};
use bml_realizer::crowd::scenes::{self, Walk};
use bml_realizer::crowd::sim::{Mover, Sim};
use glam::Vec2;

const DT: f32 = 1.0 / 30.0;
const LIMIT: f64 = 120.0;

fn tracks(walks: &[Walk]) -> Vec<Track> {
    (walks.iter())
        .map(|w| Track {
            at: vec![w.from],
            goal: w.to,
            speed: w.speed,
            radius: 0.25,
            arrived: None,
        })
        .collect()
}

fn ours(walks: &[Walk]) -> Quality {
    let movers = (walks.iter())
        .map(|w| Mover::new(w.from, w.to, 0.25, w.speed))
        .collect();
    let mut s = Sim::new(movers);
    let mut t = tracks(walks);
    while !s.all_arrived() && s.time < LIMIT {
        s.step(DT);
        for (t, m) in t.iter_mut().zip(&s.movers) {
            t.at.push(m.at);
            t.arrived = m.arrived;
        }
    }
    measure(&t, DT)
}

fn orca(walks: &[Walk]) -> Quality {
    let agents = (walks.iter())
        .map(|w| orca::OrcaAgent {
            at: w.from,
            velocity: Vec2::ZERO,
            goal: w.to,
            radius: 0.25,
            speed: w.speed,
            arrived: None,
        })
        .collect();
    let mut s = orca::Orca::new(agents);
    let mut t = tracks(walks);
    while !s.all_arrived() && s.time < LIMIT {
        s.step(DT);
        for (t, a) in t.iter_mut().zip(&s.agents) {
            t.at.push(a.at);
            t.arrived = a.arrived;
        }
    }
    measure(&t, DT)
}

fn main() {
    println!("| scene | who | collisions (pairs) | deepest (cm) | stranded | time / straight (mean, worst) | path / straight | energy / least | heading reversals |");
    println!("|---|---|---|---|---|---|---|---|---|");
    for (name, walks) in scenes::all() {
        for (who, q) in [("realizer", ours(&walks)), ("ORCA", orca(&walks))] {
            println!(
                "| {name} ({}) | {who} | {} | {:.1} | {} | {:.2}, {:.2} | {:.3} | {:.3} | {:.2} |",
                walks.len(),
                q.collisions,
                q.deepest * 100.0,
                q.stranded,
                q.time_ratio,
                q.worst_time_ratio,
                q.path_ratio,
                q.energy_ratio,
                q.reversals
            );
        }
    }
}
