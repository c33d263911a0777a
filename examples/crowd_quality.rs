//! The quality table of `docs/crowds.md`: every scene of `crowd::scenes` walked by the
//! realizer's avoidance (`crowd::sim`, roots only) and by ORCA (`dodgy_2d`), side by side, at
//! 30 steps a second for at most 120 s, on the same routes round the same walls.
//!
//! `cargo run --release --example crowd_quality`

#[path = "../benches/common/orca.rs"]
mod orca;

use std::sync::Arc;

use bml_realizer::world::crowd::quality::{measure, Quality, Track};
use bml_realizer::world::crowd::scenes::{self, Scene, Walk};
use bml_realizer::world::crowd::sim::{Mover, Sim};

const DT: f32 = 1.0 / 30.0;
const LIMIT: f64 = 120.0;

/// A crowd of movers that steps as a whole.
trait Stepped {
    fn step(&mut self, dt: f32);
    fn time(&self) -> f64;
    fn movers(&self) -> &[Mover];
}

impl Stepped for Sim {
    fn step(&mut self, dt: f32) {
        Sim::step(self, dt)
    }
    fn time(&self) -> f64 {
        self.time
    }
    fn movers(&self) -> &[Mover] {
        &self.movers
    }
}

impl Stepped for orca::Orca {
    fn step(&mut self, dt: f32) {
        orca::Orca::step(self, dt)
    }
    fn time(&self) -> f64 {
        self.time
    }
    fn movers(&self) -> &[Mover] {
        &self.movers
    }
}

fn movers(walks: &[Walk]) -> Vec<Mover> {
    (walks.iter())
        .map(|w| Mover::new(w.from, w.to, 0.25, w.speed))
        .collect()
}

/// Steps `crowd` until everyone has arrived (or given up) or [`LIMIT`], recording everyone's track, and
/// measures it in `scene`.
fn walk(mut crowd: impl Stepped, scene: &Scene) -> Quality {
    let mut tracks: Vec<Track> = (crowd.movers().iter())
        .map(|m| Track {
            at: vec![m.at],
            goal: m.goal,
            speed: m.speed,
            radius: m.radius,
            arrived: None,
            gave_up: None,
        })
        .collect();
    while !crowd.movers().iter().all(Mover::standing) && crowd.time() < LIMIT {
        crowd.step(DT);
        for (t, m) in tracks.iter_mut().zip(crowd.movers()) {
            t.at.push(m.at);
            t.arrived = m.arrived;
            t.gave_up = m.gave_up;
        }
    }
    let walls = bml_realizer::world::space::Obstacles::new(scene.walls.clone());
    measure(&tracks, DT, &walls, &scene.spaces)
}

fn main() {
    println!("| scene | who | collisions (pairs) | deepest (cm) | into walls / groups | stranded | time / straight (mean, worst) | path / straight | energy / least | heading reversals |");
    println!("|---|---|---|---|---|---|---|---|---|---|");
    for scene in scenes::all() {
        let walls = Arc::new(scene.obstacles());
        let ours = walk(Sim::among(movers(&scene.walks), walls.clone()), &scene);
        let theirs = walk(orca::Orca::among(movers(&scene.walks), walls), &scene);
        for (who, q) in [("realizer", ours), ("ORCA", theirs)] {
            println!(
                "| {} ({}) | {who} | {} | {:.1} | {} / {} | {} ({} gave up) | {:.2}, {:.2} | {:.3} | {:.3} | {:.2} |",
                scene.name,
                scene.walks.len(),
                q.collisions,
                q.deepest * 100.0,
                q.through_walls,
                q.into_groups,
                q.stranded,
                q.gave_up,
                q.time_ratio,
                q.worst_time_ratio,
                q.path_ratio,
                q.energy_ratio,
                q.reversals
            );
        }
    }
}
