//! rapier3d measured for the physical body (docs/physics.md): a pendulum simulated at 200 Hz
//! keeps its analytic period over ten periods and its amplitude, with an impulse joint and with a
//! multibody joint; the test prints what each costs, which is how the choice between them is
//! made. (The bob must not be allowed to sleep: at a small swing rapier puts it to sleep after
//! about 7 s.)

use rapier3d::prelude::*;

const STEP: f32 = 1.0 / 200.0;

/// Simulates a pendulum (a ball of radius `r` on a massless rod of length `l`, released at
/// `start` radians) for `seconds`; returns the times its angle crossed zero going up, its largest
/// angle in the last second, and the wall time the simulation took.
fn swing(
    multibody: bool,
    l: f32,
    r: f32,
    start: f32,
    seconds: f32,
) -> (Vec<f64>, f32, std::time::Duration) {
    let mut w = PhysicsWorld::new();
    w.integration_parameters.dt = STEP;
    let pivot = Vector::new(0.0, 2.0, 0.0);
    let anchor = w
        .bodies
        .insert(RigidBodyBuilder::fixed().translation(pivot));
    let at = pivot + Vector::new(l * start.sin(), -l * start.cos(), 0.0);
    let bob = w.bodies.insert(
        RigidBodyBuilder::dynamic()
            .translation(at)
            .angular_damping(0.0)
            .linear_damping(0.0)
            .can_sleep(false),
    );
    let collider = ColliderBuilder::ball(r)
        .density(1000.0)
        .collision_groups(InteractionGroups::none());
    w.colliders.insert_with_parent(collider, bob, &mut w.bodies);
    // the rod: the pivot is at the anchor's origin and `l` from the bob's centre, along the rod
    let rod = Vector::new(-start.sin(), start.cos(), 0.0) * l;
    let joint = RevoluteJointBuilder::new(Vector::Z)
        .local_anchor1(Vector::ZERO)
        .local_anchor2(rod);
    if multibody {
        w.multibody_joints.insert(anchor, bob, joint, true);
    } else {
        w.impulse_joints.insert(anchor, bob, joint, true);
    }
    let (mut crossings, mut last, mut late) = (Vec::new(), start, 0.0f32);
    let steps = (seconds / STEP) as u32;
    let clock = std::time::Instant::now();
    for k in 0..steps {
        w.step();
        let p = w.bodies[bob].translation() - pivot;
        let angle = p.x.atan2(-p.y);
        if k + (1.0 / STEP) as u32 >= steps {
            late = late.max(angle.abs());
        }
        if last < 0.0 && angle >= 0.0 {
            // linear between the two steps
            let f = f64::from(-last / (angle - last));
            crossings.push((f64::from(k) + f) * f64::from(STEP));
        }
        last = angle;
    }
    (crossings, late, clock.elapsed())
}

#[test]
fn a_simulated_pendulum_keeps_its_period_with_either_kind_of_joint() {
    let (l, r, start) = (1.0f32, 0.05f32, 5f32.to_radians());
    // a ball on a rod: I_pivot = m l² + 2/5 m r²; for a 5° swing the period is longer by θ₀²/16
    let (l, r, th) = (f64::from(l), f64::from(r), f64::from(start));
    let small = 2.0 * std::f64::consts::PI * ((l * l + 0.4 * r * r) / (9.81 * l)).sqrt();
    let period = small * (1.0 + th * th / 16.0);
    for multibody in [false, true] {
        let (crossings, late, took) =
            swing(multibody, l as f32, r as f32, start, 11.0 * period as f32);
        assert!(crossings.len() >= 11, "{crossings:?}");
        let measured = (crossings[10] - crossings[0]) / 10.0;
        let error = (measured - period).abs() / period;
        let kind = if multibody { "multibody" } else { "impulse" };
        let kept = late / start;
        eprintln!("{kind} joint: period {measured:.5} s (analytic {period:.5} s, {:.3} %), amplitude kept {:.1} %, {} steps in {took:?}", 100.0 * error, 100.0 * kept, (11.0 * period / f64::from(STEP)) as u32);
        assert!(error < 0.005, "{kind}: {measured} vs {period}");
        // the impulse joint keeps the swing's energy; rapier's multibody joint loses most of it
        // (13 % of the amplitude left after 22 s): docs/physics.md chooses the impulse joint
        if !multibody {
            assert!(kept > 0.95, "{kind}: the swing lost energy: {kept}");
        }
    }
}
