//! Criterion bench `physics`: simulated characters with mixed dynamics. Each character's lower
//! body and trunk stand on rapier3d under the balance controller while its arms play a waving
//! gesture (kinematic poses precomputed by the realizer at 200 Hz, fed one per step, so their
//! inverse dynamics pushes on the trunk). One iteration is one 200 Hz physics step of every
//! character, on one thread: real time for N characters means an iteration under 5 ms.
//!
//! Run: `cargo bench --bench physics`

use std::hint::black_box;

use bml_realizer::character::body::{Pose, Skeleton};
use bml_realizer::character::dynamics::controllers::{Balance, Controller, Drive};
use bml_realizer::character::dynamics::sim::{Simulation, STEP};
use bml_realizer::realizer::Realizer;
use criterion::{criterion_group, criterion_main, Criterion};

/// The lower body and the trunk simulated; head and arms kinematic.
const LOWER_BODY: [usize; 8] = [0, 1, 9, 10, 11, 12, 13, 14];

/// Two seconds of a WAVE then a BEAT on the arms, at 200 Hz.
fn arm_poses() -> Vec<Pose> {
    let mut r = Realizer::new().with_idle(false);
    r.perform_bml(
        r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="b">
          <gesture id="w" lexeme="WAVE" mode="BOTH_HANDS" start="0"/></bml>"#,
    )
    .unwrap();
    (0..(3.0 / STEP) as usize)
        .map(|k| r.tick(k as f64 * STEP).poses[0].pose.clone())
        .collect()
}

fn characters(c: &mut Criterion) {
    let skeleton = Skeleton::adult();
    let poses = arm_poses();
    let balance = Balance::default();
    let mut group = c.benchmark_group("physics");
    group.sample_size(20);
    for n in [1usize, 100] {
        let mut sims: Vec<Simulation> = (0..n)
            .map(|_| Simulation::new(&skeleton, &Pose::rest(&skeleton), &LOWER_BODY, STEP).unwrap())
            .collect();
        let mut k = 0usize;
        let mut drive = Drive::new(15);
        group.bench_function(format!("{n} characters, one 200 Hz step"), |b| {
            b.iter(|| {
                // loop the gesture (it starts and ends at rest)
                let pose = &poses[k % poses.len()];
                k += 1;
                for sim in &mut sims {
                    drive
                        .torques
                        .iter_mut()
                        .for_each(|t| *t = glam::DVec3::ZERO);
                    drive.pulls.iter_mut().for_each(|p| *p = None);
                    balance.drive(sim, &mut drive);
                    sim.step(black_box(pose), &drive);
                }
            })
        });
    }
    group.finish();
}

criterion_group!(benches, characters);
criterion_main!(benches);
