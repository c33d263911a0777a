//! Crowd avoidance at scale, side by side with ORCA (`dodgy_2d`) in one run: the avoidance
//! step alone (every agent chooses its velocity once) for 1 000 agents, and a whole crowd step
//! of the realizer's roots-only simulation for 10 000 agents (to run at 30 Hz it must stay
//! under 33 ms). The agents stand on a square lattice 1.2 m apart, each heading for the point
//! mirrored through the centre, after 3 s of walking (so that they are amid one another).

#[path = "common/orca.rs"]
mod orca;

use std::hint::black_box;

use bml_realizer::world::crowd::sim::{Mover, Sim};
use criterion::{criterion_group, criterion_main, Criterion};
use glam::Vec2;

fn lattice(n: usize) -> Vec<(Vec2, Vec2)> {
    let side = (n as f32).sqrt().ceil() as usize;
    (0..n)
        .map(|k| {
            let p = Vec2::new((k % side) as f32, (k / side) as f32) * 1.2
                - Vec2::splat(side as f32 * 0.6);
            (p, -p)
        })
        .collect()
}

fn movers(n: usize) -> Vec<Mover> {
    (lattice(n).into_iter())
        .map(|(a, b)| Mover::new(a, b, 0.25, 1.3))
        .collect()
}

fn ours(n: usize) -> Sim {
    let mut s = Sim::new(movers(n));
    for _ in 0..90 {
        s.step(1.0 / 30.0);
    }
    s
}

fn theirs(n: usize) -> orca::Orca {
    let mut s = orca::Orca::new(movers(n));
    for _ in 0..90 {
        s.step(1.0 / 30.0);
    }
    s
}

fn avoidance(c: &mut Criterion) {
    let mut g = c.benchmark_group("avoidance step, 1000 agents");
    g.sample_size(20);
    let s = ours(1000);
    g.bench_function("realizer (sampled, one thread, every agent decides)", |b| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        b.iter_batched(
            || {
                let mut s = s.clone();
                // every agent decides in the measured step
                s.force_decisions();
                s
            },
            |mut s| pool.install(|| s.step(1.0 / 30.0)),
            criterion::BatchSize::LargeInput,
        )
    });
    let o = theirs(1000);
    g.bench_function("ORCA (dodgy_2d, one thread)", |b| {
        b.iter(|| black_box(o.choose(1.0 / 30.0)))
    });
    g.finish();
}

fn ten_thousand(c: &mut Criterion) {
    let mut g = c.benchmark_group("crowd step, roots only");
    g.sample_size(10);
    let mut s = ours(10_000);
    g.bench_function("10000 agents, all cores (30 Hz)", |b| {
        b.iter(|| s.step(1.0 / 30.0))
    });
    g.finish();
}

criterion_group!(benches, avoidance, ten_thousand);
criterion_main!(benches);
