//! The transitions people make, measured on the frames through forward kinematics: turning on
//! the spot by stepping (no joint but the eyes faster than 15 rad/s), setting off at a run from
//! standing (no foot point more than 1 cm below where it stands on the floor, no joint faster
//! than 25 rad/s), and rounding a wall's end by footsteps (the heading changing by at most 30°
//! from one step to the next).

#[path = "common/motion.rs"]
mod motion;

use bml_realizer::character::body::{Pose, Skeleton};
use bml_realizer::realizer::Realizer;
use bml_realizer::world::World;
use motion::fastest_joint_but_the_eyes;

const FPS: f64 = 60.0;

fn block(locomotion: &str) -> String {
    format!(
        r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" xmlns:bmlt="http://hmi.ewi.utwente.nl/bmlt" id="b" characterId="w"><locomotion id="l" {locomotion}/></bml>"#
    )
}

/// The poses and contacts of character `w` (standing at the origin facing +z, or as `world`
/// places it) at 60 fps until nothing more will happen (at most `seconds`).
fn frames(world: &str, locomotion: &str, seconds: f64) -> Vec<(f64, Pose, [bool; 2])> {
    let mut r = Realizer::new().with_idle(false);
    *r.world_mut() = World::from_json(world).unwrap().0;
    r.perform_bml(&block(locomotion)).unwrap();
    let mut out = Vec::new();
    for i in 0..=(seconds * FPS) as u32 {
        let t = f64::from(i) / FPS;
        let frame = r.tick(t);
        let p = frame.character("w").expect("w is drawn");
        out.push((t, p.pose.clone(), p.contacts.unwrap_or([true, true])));
        if i > 0 && r.next_event().is_none() {
            break;
        }
    }
    out
}

const STANDING: &str = r#"{"characters": {"w": {"position": [0, 0, 0], "facing": 0}}}"#;

/// The fastest any joint but the eyes turns from frame to frame (rad/s), which and when.
fn fastest_joint(frames: &[(f64, Pose, [bool; 2])]) -> (f32, String, f64) {
    let skeleton = Skeleton::adult();
    fastest_joint_but_the_eyes(&skeleton, frames.iter().map(|(t, p, _)| (*t, p)))
}

/// The furthest any foot point (ankle, ball) goes below its height standing (m), which and when.
fn deepest_foot(frames: &[(f64, Pose, [bool; 2])]) -> (f32, String, f64) {
    let skeleton = Skeleton::adult();
    let points: Vec<usize> = [
        "l_talocrural",
        "r_talocrural",
        "l_metatarsal",
        "r_metatarsal",
    ]
    .iter()
    .map(|n| skeleton.joint(n).unwrap())
    .collect();
    let rest = frames[0].1.world(&skeleton);
    let mut worst = (0.0, String::new(), 0.0);
    for (t, pose, _) in frames {
        let world = pose.world(&skeleton);
        for &j in &points {
            let below = rest.positions[j].y - world.positions[j].y;
            if below > worst.0 {
                worst = (below, skeleton.joints()[j].name.clone(), *t);
            }
        }
    }
    worst
}

#[test]
fn turning_on_the_spot_turns_no_joint_faster_than_15_rad_per_s() {
    // the goal behind: the walker turns round on the spot, stepping, then walks
    for target in ["0,-3", "-3,-1", "3,-1"] {
        let run = frames(STANDING, &format!(r#"target="{target}""#), 12.0);
        let (speed, joint, t) = fastest_joint(&run);
        eprintln!("turn to {target}: fastest joint {joint} at {speed:.1} rad/s at {t:.2} s");
        assert!(
            speed <= 15.0,
            "to {target}: {joint} turns at {speed:.1} rad/s at {t:.2} s"
        );
    }
}

#[test]
fn setting_off_at_a_run_keeps_the_feet_on_the_floor_and_the_joints_humanly_fast() {
    let run = frames(STANDING, r#"target="0,12" manner="RUN""#, 10.0);
    let (below, foot, t) = deepest_foot(&run);
    let (speed, joint, u) = fastest_joint(&run);
    eprintln!(
        "run start: {foot} {:.1} cm below standing at {t:.2} s; {joint} at {speed:.1} rad/s at {u:.2} s",
        below * 100.0
    );
    assert!(
        below <= 0.01,
        "{foot} {:.1} cm into the floor at {t:.2} s",
        below * 100.0
    );
    assert!(
        speed <= 25.0,
        "{joint} turns at {speed:.1} rad/s at {u:.2} s"
    );
}

/// The walker's heading (rad about +y, 0 along +z) from its root (pelvis) rotation.
fn heading(pose: &Pose) -> f32 {
    let ahead = pose.rotations[0] * glam::Vec3::Z;
    ahead.x.atan2(ahead.z)
}

/// The smallest angle between two headings (rad).
fn between(a: f32, b: f32) -> f32 {
    let d = (b - a).rem_euclid(std::f32::consts::TAU);
    d.min(std::f32::consts::TAU - d)
}

#[test]
fn rounding_a_wall_s_end_by_footsteps_turns_at_most_30_degrees_a_step() {
    let world = r#"{"characters": {"w": {"position": [0, 0, 0], "facing": 0}},
                    "obstacles": [{"segment": [-4, 5, 3, 5], "height": 2.0}]}"#;
    let run = frames(world, r#"target="4,10" bmlt:planner="footsteps""#, 20.0);
    // the frames where a foot comes down
    let falls: Vec<usize> = (1..run.len())
        .filter(|&k| (0..2).any(|s| !run[k - 1].2[s] && run[k].2[s]))
        .collect();
    assert!(falls.len() > 8, "{} footfalls", falls.len());
    // each step's heading: the pelvis's, averaged over the step (it turns to and fro with
    // every step), as a unit vector so that the mean does not wrap
    let steps: Vec<(f64, f32)> = (falls.windows(2))
        .map(|w| {
            let sum: glam::Vec2 = (w[0]..w[1])
                .map(|k| {
                    let h = heading(&run[k].1);
                    glam::Vec2::new(h.sin(), h.cos())
                })
                .sum();
            (run[w[1]].0, sum.x.atan2(sum.y))
        })
        .collect();
    let mut worst = (0.0f32, 0.0);
    for w in steps.windows(2) {
        let turn = between(w[0].1, w[1].1);
        if turn > worst.0 {
            worst = (turn, w[1].0);
        }
    }
    eprintln!(
        "footsteps: {} steps, the most turned from one to the next {:.1} deg, at {:.2} s",
        steps.len(),
        worst.0.to_degrees(),
        worst.1
    );
    assert!(
        worst.0.to_degrees() <= 30.0,
        "the heading turned {:.1} deg in one step, at {:.2} s",
        worst.0.to_degrees(),
        worst.1
    );
}
