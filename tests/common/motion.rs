//! How fast the body moves, for the tests that judge motion: the fastest any joint but the eyes
//! turns from one frame to the next (the eyes' saccades are meant to be fast).

use bml_realizer::character::body::{Pose, Skeleton};
use glam::Quat;

/// The fastest any joint of `skeleton` but the eyeballs turns between consecutive `frames`
/// (time, pose): its speed (rad/s), its name and when (the later frame's time).
pub fn fastest_joint_but_the_eyes<'a>(
    skeleton: &Skeleton,
    frames: impl IntoIterator<Item = (f64, &'a Pose)>,
) -> (f32, String, f64) {
    let mut worst = (0.0, String::new(), 0.0);
    let mut previous: Option<(f64, &Pose)> = None;
    for (t, pose) in frames {
        if let Some((t0, before)) = previous {
            let dt = (t - t0) as f32;
            for (j, joint) in skeleton.joints().iter().enumerate() {
                if joint.name.contains("eyeball") || dt <= 0.0 {
                    continue;
                }
                let turned = (before.rotations[j].inverse() * pose.rotations[j]).normalize();
                let speed = turned.angle_between(Quat::IDENTITY) / dt;
                if speed > worst.0 {
                    worst = (speed, joint.name.clone(), t);
                }
            }
        }
        previous = Some((t, pose));
    }
    worst
}
