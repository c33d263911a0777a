//! A swing pumped by a kinematic rider (the thesis' check after Isaacs and Cohen): a seat on a
//! 2 m rod, simulated on rapier3d, carries a rider whose torso leans back and forth by a set
//! motion (kinematic). The rider reaches the seat only through mixed dynamics — its rigid
//! inertia added to the seat, the momentum of its lean passed on (`dynamics::coupling`) — so the
//! swing gains amplitude when the lean keeps time with it (much less when the lean is well off
//! its frequency), and keeps it when the rider sits still.

use bml_realizer::character::dynamics::coupling::{relative_momentum, Carrier, Composite};
use bml_realizer::character::dynamics::mass::{cuboid, MassProperties};
use bml_realizer::character::dynamics::rnea::{JointMotion, Link};
use glam::{DQuat, DVec3};
use rapier3d::prelude::*;

const STEP: f32 = 1.0 / 200.0;
const ROD: f32 = 2.0;

/// The rider's torso: 40 kg, a 0.35 × 0.6 × 0.25 m box standing on the seat.
fn torso() -> Link {
    let m = cuboid(
        DVec3::new(0.35, 0.6, 0.25),
        40.0 / (0.35 * 0.6 * 0.25),
        DVec3::new(0.0, 0.3, 0.0),
    );
    Link {
        parent: None,
        offset: DVec3::ZERO,
        mass: m.mass,
        com: m.com,
        inertia: m.inertia,
    }
}

/// Swings for `seconds`, released at 5°, the torso leaning by `lean(t)` (angle about z,
/// its first and second derivatives): the swing's angle every step.
fn swing(seconds: f32, lean: impl Fn(f64) -> (f64, f64, f64)) -> Vec<f64> {
    let mut w = PhysicsWorld::new();
    w.integration_parameters.dt = STEP;
    let pivot = Vector::new(0.0, 3.0, 0.0);
    let anchor = w
        .bodies
        .insert(RigidBodyBuilder::fixed().translation(pivot));
    let start = 5f32.to_radians();
    let at = pivot + Vector::new(ROD * start.sin(), -ROD * start.cos(), 0.0);
    let seat = w.bodies.insert(
        RigidBodyBuilder::dynamic()
            .translation(at)
            .rotation(Vector::new(0.0, 0.0, start))
            .can_sleep(false)
            .angular_damping(0.0)
            .linear_damping(0.0),
    );
    // a 5 kg seat, 0.4 × 0.05 × 0.3 m
    let density = 5.0 / (0.4 * 0.05 * 0.3);
    let own: MassProperties = cuboid(DVec3::new(0.4, 0.05, 0.3), density, DVec3::ZERO);
    let collider = ColliderBuilder::cuboid(0.2, 0.025, 0.15)
        .density(density as f32)
        .collision_groups(InteractionGroups::none());
    w.colliders
        .insert_with_parent(collider, seat, &mut w.bodies);
    let joint = RevoluteJointBuilder::new(Vector::Z)
        .local_anchor1(Vector::ZERO)
        .local_anchor2(Vector::new(0.0, ROD, 0.0));
    w.impulse_joints.insert(anchor, seat, joint, true);
    let link = [torso()];
    let own = Composite::of(&own);
    let mut carrier = Carrier::default();
    let mut angles = Vec::new();
    for k in 0..(seconds / STEP) as usize {
        let t = f64::from(k as f32 * STEP);
        let (phi, dphi, ddphi) = lean(t);
        let motion = [JointMotion {
            rotation: DQuat::from_rotation_z(phi),
            velocity: DVec3::new(0.0, 0.0, dphi),
            acceleration: DVec3::new(0.0, 0.0, ddphi),
        }];
        let mut rider = Composite::default();
        rider.add(&link, &motion);
        let moving = relative_momentum(&link, &motion);
        let body = &mut w.bodies[seat];
        body.reset_forces(false);
        body.reset_torques(false);
        carrier.load(body, &own, rider, moving, f64::from(STEP));
        w.step();
        let d = w.bodies[seat].translation() - pivot;
        angles.push(f64::from(d.x.atan2(-d.y)));
    }
    angles
}

/// The largest swing angle in the seconds `from..to`.
fn amplitude(angles: &[f64], from: f64, to: f64) -> f64 {
    let step = f64::from(STEP);
    angles[(from / step) as usize..(to / step) as usize]
        .iter()
        .fold(0.0, |a, b| a.max(b.abs()))
}

/// The swing's period sitting still: from its upward zero crossings.
fn period(angles: &[f64]) -> f64 {
    let step = f64::from(STEP);
    let ups: Vec<f64> = (1..angles.len())
        .filter(|&i| angles[i - 1] < 0.0 && angles[i] >= 0.0)
        .map(|i| i as f64 * step)
        .collect();
    (ups[ups.len() - 1] - ups[0]) / (ups.len() - 1) as f64
}

#[test]
fn a_rider_leaning_in_time_pumps_the_swing() {
    let still = swing(60.0, |_| (0.0, 0.0, 0.0));
    let first = amplitude(&still, 0.0, 5.0);
    let kept = amplitude(&still, 55.0, 60.0) / first;
    assert!(
        (kept - 1.0).abs() < 0.02,
        "sitting still the swing kept {kept} of its amplitude"
    );
    let omega = 2.0 * std::f64::consts::PI / period(&still);
    // leaning ±15° (forward as the swing comes back), at the swing's frequency and well off it
    let lean = |f: f64| {
        move |t: f64| {
            let (a, x) = (15f64.to_radians(), f * t);
            (-a * x.sin(), -a * f * x.cos(), a * f * f * x.sin())
        }
    };
    let runs: Vec<Vec<f64>> = [1.0, 0.6, 1.6]
        .iter()
        .map(|&r| swing(60.0, lean(r * omega)))
        .collect();
    let last = |a: &[f64]| amplitude(a, 50.0, 60.0);
    let tens: Vec<f64> = (0..6)
        .map(|i| amplitude(&runs[0], 10.0 * i as f64, 10.0 * (i + 1) as f64))
        .collect();
    eprintln!(
        "period {:.3} s; amplitude in each 10 s leaning in time: {tens:.3?} rad; in the last 10 s: {:.3} at 0.6 times the frequency, {:.3} at 1.6 times, {:.3} sitting still",
        2.0 * std::f64::consts::PI / omega,
        last(&runs[1]),
        last(&runs[2]),
        last(&still)
    );
    assert!(
        tens.windows(2).all(|w| w[1] > w[0]),
        "it does not grow on: {tens:?}"
    );
    assert!(
        tens[5] > 2.5 * tens[0],
        "leaning in time grew the swing only {tens:?}"
    );
    for off in &runs[1..] {
        assert!(
            last(off) < 0.5 * tens[5],
            "off its frequency it grew as much: {}",
            last(off)
        );
    }
}
