//! Criterion bench `locomotion`: what walking costs. A route around obstacles (a U-shaped trap
//! and a field of a thousand posts); one steering step of a walker's combination (follow the
//! route, avoid obstacles); one 60 Hz frame of one walker (its fixed steps and the gait posed on
//! the skeleton); and one 60 Hz tick of 100 characters walking while they gesture.
//!
//! Run: `cargo bench --bench locomotion`

use std::hint::black_box;

use bml_realizer::character::body::{Pose, Skeleton};
use bml_realizer::realizer::Realizer;
use bml_realizer::world::locomotion::posing::{pose_gait, GaitJoints};
use bml_realizer::world::locomotion::steering::{
    ArriveParams, Behaviour, Combine, Context, Part, Steering, Vehicle,
};
use bml_realizer::world::locomotion::{Walk, Walker};
use bml_realizer::world::space::{path, Obstacle, Obstacles, Shape};
use bml_realizer::world::{Placement, World};
use criterion::{criterion_group, criterion_main, Criterion};
use glam::{Vec2, Vec3};

fn segment(a: (f32, f32), b: (f32, f32)) -> Obstacle {
    Obstacle {
        shape: Shape::Segment {
            a: Vec2::new(a.0, a.1),
            b: Vec2::new(b.0, b.1),
        },
        height: 2.0,
    }
}

fn trap() -> Obstacles {
    Obstacles::new(vec![
        segment((-1.5, 2.0), (1.5, 2.0)),
        segment((-1.5, 2.0), (-1.5, -0.5)),
        segment((1.5, 2.0), (1.5, -0.5)),
    ])
}

fn posts() -> Obstacles {
    Obstacles::new(
        (0..1000)
            .map(|i| Obstacle {
                shape: Shape::Circle {
                    centre: Vec2::new(3.0 + (i % 40) as f32 * 1.5, 3.0 + (i / 40) as f32 * 1.5),
                    radius: 0.4,
                },
                height: 2.0,
            })
            .collect(),
    )
}

fn paths(c: &mut Criterion) {
    let (t, p) = (trap(), posts());
    c.bench_function("path: out of a U-shaped trap", |b| {
        b.iter(|| path::plan(&t, Vec2::ZERO, black_box(Vec2::new(0.0, 5.0)), 0.33).unwrap())
    });
    c.bench_function("path: across 1000 posts", |b| {
        b.iter(|| path::plan(&p, Vec2::ZERO, black_box(Vec2::new(62.0, 40.0)), 0.33).unwrap())
    });
}

fn steering(c: &mut Criterion) {
    let o = posts();
    let mut s = Steering::new(Combine::Prioritised, 7);
    let mut avoid = Part::new(Behaviour::AvoidObstacles {
        radius: 0.25,
        lookahead: 0.6,
    });
    avoid.priority = 1;
    s.add(avoid);
    s.add(Part::new(Behaviour::FollowPoints {
        points: vec![Vec3::new(30.0, 0.0, 30.0), Vec3::new(60.0, 0.0, 40.0)],
        next: 0,
        reach: 0.45,
        params: ArriveParams {
            slow_radius: 1.0,
            stop_radius: 0.04,
            floor_speed: 0.12,
        },
    }));
    let mut v = Vehicle::new(Vec3::new(3.7, 0.0, 2.0), 0.2, 0.5, 1.3);
    v.velocity = Vec3::new(0.9, 0.0, 0.9);
    c.bench_function("steering: one step among 1000 posts", |b| {
        b.iter(|| {
            let mut v = v;
            let f = s.force(
                &mut v,
                Context {
                    obstacles: Some(&o),
                },
            );
            v.step(f, 1.0 / 240.0);
            black_box(v)
        })
    });
}

fn gait(c: &mut Criterion) {
    let skeleton = Skeleton::adult();
    let joints = GaitJoints::of(&skeleton).unwrap();
    let o = Obstacles::default();
    let mut w = Walker::new(Vec2::ZERO, 0.0, 0.25, 0.0);
    let walk = Walk {
        goal: Vec2::new(0.0, 1e5),
        speed: 1.3,
        running: false,
        face: None,
        stepping: false,
        footsteps: false,
    };
    w.start(walk, &o).unwrap();
    w.advance(3.0, &o);
    c.bench_function("gait: one walker, one 60 Hz frame (steps + pose)", |b| {
        b.iter_batched(
            || w.clone(),
            |mut w| {
                w.advance(w.time + 1.0 / 60.0, &o);
                let mut pose = Pose::rest(&skeleton);
                pose_gait(&skeleton, &joints, &w.gait, w.body(), &mut pose);
                black_box(pose)
            },
            criterion::BatchSize::SmallInput,
        )
    });
}

fn crowd(c: &mut Criterion) {
    let mut world = World::default();
    for i in 0..100 {
        let at = Placement::new(Vec3::new(i as f32 * 2.0, 0.0, 0.0), 0.0);
        world.place(&format!("c{i}"), at).unwrap();
    }
    let mut r = Realizer::new();
    *r.world_mut() = world;
    for i in 0..100 {
        let x = i as f32 * 2.0;
        r.perform_bml(&format!(
            r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="b" characterId="c{i}"><locomotion id="w" target="{x},100000"/><gesture id="g" lexeme="BEAT" start="0" end="100000"/><gesture id="g2" lexeme="WAVE" mode="LEFT_HAND" start="0" end="100000"/><gaze id="look" target="user" start="0" end="100000"/></bml>"#
        ))
        .unwrap();
    }
    let mut t = 0.0;
    for _ in 0..120 {
        t += 1.0 / 60.0;
        r.tick(t);
    }
    c.bench_function("tick: 100 characters walking with gestures (60 Hz)", |b| {
        b.iter(|| {
            t += 1.0 / 60.0;
            black_box(r.tick(t))
        })
    });
}

/// 1 000 walkers in counter-flowing rows 1.5 m apart (each row against its neighbours), full
/// bodies without gestures: one 60 Hz tick on all cores and on one thread.
fn thousand(c: &mut Criterion) {
    for parallel in [true, false] {
        let mut world = World::default();
        let (cols, rows) = (40, 25);
        for i in 0..cols * rows {
            let (x, z) = ((i % cols) as f32 * 2.0, (i / cols) as f32 * 1.5);
            let facing = if (i / cols) % 2 == 0 { 90.0 } else { -90.0 };
            let at = Placement::new(Vec3::new(x, 0.0, z), facing);
            world.place(&format!("c{i}"), at).unwrap();
        }
        let mut r = Realizer::new();
        r.set_parallel(parallel);
        *r.world_mut() = world;
        for i in 0..cols * rows {
            let z = (i / cols) as f32 * 1.5;
            let x = if (i / cols) % 2 == 0 {
                100_000.0
            } else {
                -100_000.0
            };
            r.perform_bml(&format!(
                r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="b" characterId="c{i}"><locomotion id="w" target="{x},{z}"/></bml>"#
            ))
            .unwrap();
        }
        let mut t = 0.0;
        for _ in 0..120 {
            t += 1.0 / 60.0;
            r.tick(t);
        }
        let name = if parallel { "all cores" } else { "one thread" };
        c.bench_function(
            &format!("tick: 1000 characters walking (60 Hz), {name}"),
            |b| {
                b.iter(|| {
                    t += 1.0 / 60.0;
                    black_box(r.tick(t))
                })
            },
        );
    }
}

criterion_group!(benches, paths, steering, gait, crowd);
criterion_group! {
    name = big;
    config = Criterion::default().sample_size(10);
    targets = thousand
}
criterion_main!(benches, big);
