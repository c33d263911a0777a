//! The physical controllers' laws (thesis §3.7): the PD law, the rag doll's nothing, torques
//! and pulls of several controllers on one joint adding up, one stiffness multiplier for the
//! balance, and a PD-driven hinge settling without overshoot at critical damping.

use bml_realizer::character::body::{Pose, Skeleton};
use bml_realizer::character::dynamics::controllers::{
    pd, Balance, Controller, Drive, PoseController, RagDoll,
};
use bml_realizer::character::dynamics::sim::{Simulation, STEP};
use glam::{DQuat, DVec3};

const WHOLE_BODY: [usize; 15] = [0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14];
const LOWER_BODY: [usize; 8] = [0, 1, 9, 10, 11, 12, 13, 14];

fn sim(parts: &[usize]) -> Simulation {
    let s = Skeleton::adult();
    Simulation::new(&s, &Pose::rest(&s), parts, STEP).unwrap()
}

#[test]
fn the_pd_law_is_exactly_kp_times_the_error_plus_kd_times_the_velocity_error() {
    assert_eq!(
        pd(100.0, 10.0, 1.0, 0.25, 0.5, 2.0),
        100.0 * 0.75 + 10.0 * -1.5
    );
    assert_eq!(pd(3.0, 0.0, -2.0, -2.0, 0.0, 7.0), 0.0);
}

#[test]
fn the_rag_doll_asks_nothing_of_any_joint() {
    let s = sim(&WHOLE_BODY);
    let mut d = Drive::new(15);
    RagDoll.drive(&s, &mut d);
    assert!(d.torques.iter().all(|t| *t == DVec3::ZERO));
    assert!(d.pulls.iter().all(Option::is_none));
}

/// Two pose controllers on one joint: stiffnesses and dampings add, and the target is where
/// the two springs balance (the stiffness-weighted mean); torques from two controllers add.
#[test]
fn controllers_on_one_joint_add_up() {
    let s = sim(&LOWER_BODY);
    let knee = 10;
    let (a, b) = (DQuat::from_rotation_x(0.2), DQuat::from_rotation_x(0.5));
    let mut d = Drive::new(15);
    PoseController {
        targets: vec![(knee, a, 100.0, 10.0)],
    }
    .drive(&s, &mut d);
    PoseController {
        targets: vec![(knee, b, 300.0, 20.0)],
    }
    .drive(&s, &mut d);
    let p = d.pulls[knee].unwrap();
    assert_eq!((p.kp, p.kd), (400.0, 30.0));
    let (axis, angle) = p.target.to_axis_angle();
    assert!((axis.x - 1.0).abs() < 1e-9);
    // the springs' rest: (100 × 0.2 + 300 × 0.5) / 400 = 0.425 rad, to the nlerp's accuracy
    assert!((angle - 0.425).abs() < 2e-3, "{angle}");
    // a balance controller's torques add to what is there (at the ankles the sum is then held
    // to what the sole can push)
    let mut once = Drive::new(15);
    Balance::default().drive(&s, &mut once);
    let mut twice = once.clone();
    Balance::default().drive(&s, &mut twice);
    for (i, (x, y)) in once.torques.iter().zip(&twice.torques).enumerate() {
        if ![11, 14].contains(&i) {
            assert!((*y - 2.0 * *x).length() < 1e-9, "part {i}");
        }
    }
}

/// The stiffness multiplier scales every gain of the balance controller: its pulls' stiffness
/// and damping, and (with the gravity compensation, which does not scale, taken out) its
/// torques, while the body is off its set point.
#[test]
fn one_multiplier_scales_every_balance_gain() {
    let mut s = sim(&LOWER_BODY);
    // off its set point: pushed and stepped once
    s.push(0, DVec3::new(30.0, 0.0, 20.0));
    s.step(&Pose::rest(&Skeleton::adult()), &Drive::new(15));
    let drive = |k: f64| {
        let mut d = Drive::new(15);
        Balance {
            stiffness: k,
            ..Balance::default()
        }
        .drive(&s, &mut d);
        d
    };
    let (zero, one, three) = (drive(0.0), drive(1.0), drive(3.0));
    // the legs and the spine are pulled, and the pushed body is off its set point
    let pulled = one.pulls.iter().filter(|p| p.is_some()).count();
    assert_eq!(pulled, 7, "{:?}", one.pulls);
    let off = (0..15)
        .filter(|&i| (one.torques[i] - zero.torques[i]).length() > 1.0)
        .count();
    assert!(off >= 4, "only {off} torques answer the error");
    for i in 0..15 {
        assert_eq!(one.pulls[i].is_some(), three.pulls[i].is_some(), "part {i}");
        if let (Some(a), Some(b)) = (one.pulls[i], three.pulls[i]) {
            assert!((b.kp - 3.0 * a.kp).abs() < 1e-9 && (b.kd - 3.0 * a.kd).abs() < 1e-9);
        }
        let (a, b) = (
            one.torques[i] - zero.torques[i],
            three.torques[i] - zero.torques[i],
        );
        // ankle torques are clipped to what the sole can push: compare where neither clips
        if ![11, 14].contains(&i) {
            assert!(
                (b - 3.0 * a).length() < 1e-6 * (1.0 + b.length()),
                "part {i}: {a} vs {b}"
            );
        }
    }
}

/// A PD pull with kd = 2√(kp I) on the elbow (a hinge) of a body held still, without gravity:
/// the forearm turns to its target within 2 % and never past it.
#[test]
fn a_critically_damped_hinge_settles_without_overshoot() {
    let mut s = sim(&WHOLE_BODY);
    s.set_gravity(DVec3::ZERO);
    let elbow = 7; // r_forearm
    let target = -1.0; // bent 57° (elbows bend about −x)
                       // the forearm and hand about the elbow
    let h = s.humanoid().clone();
    let inertia: f64 = [7usize, 8]
        .iter()
        .map(|&i| {
            let m = h.parts[i].mass();
            let c = (h.rest[i] - h.rest[elbow]).as_dvec3() + m.com;
            m.inertia.x_axis.x + m.mass * (c.y * c.y + c.z * c.z)
        })
        .sum();
    let kp = 20.0;
    let kd = 2.0 * (kp * inertia).sqrt();
    let hold: Vec<(usize, DQuat, f64, f64)> = (1..15)
        .filter(|&i| i != elbow)
        .map(|i| (i, DQuat::IDENTITY, 2000.0, 50.0))
        .collect();
    let mut angles = Vec::new();
    for _ in 0..(3.0 / STEP) as usize {
        let mut d = Drive::new(15);
        PoseController {
            targets: hold.clone(),
        }
        .drive(&s, &mut d);
        d.pull(elbow, DQuat::from_rotation_x(target), kp, kd);
        s.step(&rest_pose(), &d);
        let p = s.parts();
        let rel = p[6].orientation.inverse() * p[elbow].orientation;
        angles.push(2.0 * rel.x.atan2(rel.w));
    }
    let last = *angles.last().unwrap();
    assert!(
        (last - target).abs() < 0.02 * target.abs(),
        "settled at {last}"
    );
    let furthest = angles.iter().copied().fold(0.0, f64::min);
    assert!(furthest >= target - 0.005, "overshot to {furthest}");
}

fn rest_pose() -> Pose {
    Pose::rest(&Skeleton::adult())
}

/// How far (radians) the simulated joints of `sim` lie outside the skeleton's limits at worst,
/// and at which part, leaving out the parts in `except`.
fn beyond_limits(sim: &Simulation, skeleton: &Skeleton, except: &[&str]) -> (f32, usize) {
    let mut pose = Pose::rest(skeleton);
    sim.write(&mut pose);
    let limits = skeleton.limits();
    let mut worst = (0.0, 0);
    for i in 1..sim.humanoid().parts.len() {
        if except.contains(&sim.humanoid().parts[i].name) {
            continue;
        }
        let j = sim.humanoid().joints[i];
        let q = pose.rotations[j];
        let Some(inside) = limits.of(j).and_then(|l| l.clamped(q)) else {
            continue;
        };
        let excess = q.angle_between(inside);
        if excess > worst.0 {
            worst = (excess, i);
        }
    }
    worst
}

/// A rag doll pushed over falls limp — its joints free, not held still — and its joints stay
/// near the skeleton's ranges as it falls, lands and lies. rapier limits a ball joint's angles
/// about x, y and z one by one, where the ranges are an ellipse of swing about the bone axis
/// and a twist: a hip flexed to its end and turned lies up to 0.5 rad past its range, and
/// the shoulders, whose ranges reach half a turn where the per-axis angles lose their meaning,
/// are left out (they went 1.3 rad past). Without limits on the balls a foot lay 0.99 rad
/// past its range; with motors of zero gain on the free joints (rapier holds such a joint
/// still) the body fell as one piece, the arm turning on the trunk at 2 rad/s at most (limp,
/// 20 rad/s).
#[test]
fn a_falling_rag_doll_is_limp_and_keeps_its_joints_near_their_ranges() {
    let skeleton = Skeleton::adult();
    let mut s = sim(&WHOLE_BODY);
    s.let_go();
    s.push(1, DVec3::new(40.0, 0.0, 25.0));
    let pose = Pose::rest(&skeleton);
    let drive = Drive::new(15);
    let shoulders = ["l_upperarm", "r_upperarm"];
    let mut worst = (0.0_f32, 0, 0.0);
    let mut limp: f64 = 0.0;
    while s.time < 3.0 {
        s.step(&pose, &drive);
        let (excess, part) = beyond_limits(&s, &skeleton, &shoulders);
        if excess > worst.0 {
            worst = (excess, part, s.time);
        }
        // the arm swings on the trunk as the body falls
        let (arm, trunk) = (s.parts()[3].angular, s.parts()[1].angular);
        limp = limp.max((arm - trunk).length());
    }
    let name = s.humanoid().parts[worst.1].name;
    eprintln!(
        "furthest beyond its range: {name} by {:.3} rad at {:.2} s; the arm turned on the trunk at up to {limp:.1} rad/s",
        worst.0, worst.2
    );
    assert!(
        worst.0 < 0.6,
        "{name} is {} rad beyond its range at {} s",
        worst.0,
        worst.2
    );
    assert!(
        limp > 5.0,
        "the arm turned on the trunk at {limp} rad/s at most"
    );
}
