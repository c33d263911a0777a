//! The cost of synthetic vision: 100 characters on a 12 × 12 m square among 20 pillars, each
//! looking at 10 Hz. One second of 60 Hz frames is sensed (every character looks ten times, a
//! sixth of them in each frame), so a frame costs a sixtieth of the time measured; it must
//! stay under a tenth of a 60 Hz frame (1.67 ms) on one core (run with `RAYON_NUM_THREADS=1`).
//! Measured with 225 rays a look (15 × 15, at least the 200 asked) and with the default 576.

use std::hint::black_box;
use std::sync::Arc;

use bml_realizer::character::body::{Pose, Skeleton};
use bml_realizer::world::perception::{Perception, Scene, Thing, Vision};
use bml_realizer::world::space::obstacles::{Obstacle, Shape};
use bml_realizer::world::space::Obstacles;
use criterion::{criterion_group, criterion_main, Criterion};
use glam::{Quat, Vec2, Vec3};

/// 100 characters on a 10 × 10 lattice 1.2 m apart, each turned its own way, and 20 pillars.
fn scene() -> Scene {
    let skeleton = Skeleton::adult();
    let mut things = Vec::new();
    for k in 0..100 {
        let at = Vec3::new(
            (k % 10) as f32 * 1.2 - 6.0,
            0.0,
            (k / 10) as f32 * 1.2 - 6.0,
        );
        let mut pose = Pose::rest(&skeleton);
        pose.root += at;
        pose.rotations[0] = Quat::from_rotation_y(k as f32 * 2.4);
        let (body, eyes) = Thing::body(&format!("c{k:03}"), &skeleton, &pose);
        things.push((body, Some(eyes)));
    }
    let pillars = (0..20)
        .map(|k| Obstacle {
            shape: Shape::Circle {
                centre: Vec2::new((k % 5) as f32 * 3.0 - 6.6, (k / 5) as f32 * 3.0 - 5.4),
                radius: 0.2,
            },
            height: 2.5,
        })
        .collect();
    Scene::new(things, Arc::new(Obstacles::new(pillars)))
}

fn vision(c: &mut Criterion) {
    let scene = scene();
    for side in [15, 24] {
        let settings = Vision {
            side,
            ..Vision::default()
        };
        c.bench_function(
            &format!(
                "vision 100 characters 10 Hz {} rays, 60 frames",
                side * side
            ),
            |b| {
                b.iter(|| {
                    let mut p = Perception::new(settings.clone());
                    let mut out = Vec::new();
                    // the first frame meets everyone; then a second of frames
                    for k in 0..=60 {
                        p.sense(k as f64 / 60.0, &scene, &mut out);
                    }
                    black_box(out.len())
                })
            },
        );
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20);
    targets = vision
}
criterion_main!(benches);
