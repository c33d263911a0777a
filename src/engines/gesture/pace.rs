//! How fast a gesture's phases can go: for each span between a lexeme's keys (and from rest
//! and back), the least time in which the right wrist keeps under a person's preferred hand
//! speed and every joint under a preferred turning speed, on a minimum-jerk move, measured on
//! the default adult. The gesture engine stretches its timing to these paces.

use glam::Quat;

use super::GestureKeys;
use crate::character::body::{Pose, Skeleton};

/// The fastest a hand moves by preference (m/s), at the peak of a minimum-jerk move between a
/// gesture's keys. Measured conversational gestures peak at about 1–2.5 m/s; 2 keeps a hand
/// that starts somewhere other than rest below the top of that range.
pub const HAND_SPEED: f64 = 2.0;

/// The fastest a gesture's joint turns by preference (rad/s), at the peak of a minimum-jerk
/// move: a wave's wrist swinging ±25° at 2.5 Hz peaks near 7 rad/s.
pub const JOINT_SPEED: f64 = 8.0;

/// The peak of a minimum-jerk move's speed relative to its mean: the largest slope of
/// 10u³ − 15u⁴ + 6u⁵, at u = ½.
pub(super) const MIN_JERK_PEAK: f64 = 1.875;

/// The least time from one sync of a gesture to another for the hand to keep under
/// [`HAND_SPEED`] and every joint under [`JOINT_SPEED`] between the keys there.
#[derive(Debug, Clone)]
pub(super) struct Pace {
    pub(super) from: &'static str,
    pub(super) to: &'static str,
    pub(super) seconds: f64,
}

/// The paces of `keys` (right-arm rotations at syncs, rest at `start` and `end`), measured on
/// the default adult: for each pair of neighbouring keys, the minimum-jerk peak times the larger
/// of the fastest the right wrist moves per unit of interpolation over [`HAND_SPEED`] and the
/// largest angle a joint turns over [`JOINT_SPEED`].
pub(super) fn paces(keys: &GestureKeys) -> Vec<Pace> {
    let adult = Skeleton::adult();
    let rest: &[(String, Quat)] = &[];
    // the sync points of a gesture, in order
    let mut chain: Vec<(&'static str, &[(String, Quat)])> = crate::language::bml::GESTURE_SYNCS
        .iter()
        .filter_map(|&sync| keys.iter().find(|k| k.0 == sync).map(|k| (sync, &k.1[..])))
        .collect();
    if chain.first().is_none_or(|k| k.0 != "start") {
        chain.insert(0, ("start", rest));
    }
    if chain.last().is_none_or(|k| k.0 != "end") {
        chain.push(("end", rest));
    }
    chain
        .windows(2)
        .map(|w| Pace {
            from: w[0].0,
            to: w[1].0,
            seconds: MIN_JERK_PEAK
                * (wrist_rate(&adult, w[0].1, w[1].1) / HAND_SPEED)
                    .max(largest_turn(w[0].1, w[1].1) / JOINT_SPEED),
        })
        .collect()
}

/// The rotation a key gives `joint` (rest if it leaves the joint out).
fn rot(key: &[(String, Quat)], joint: &str) -> Quat {
    key.iter()
        .find(|x| x.0 == joint)
        .map_or(Quat::IDENTITY, |x| x.1)
}

/// The largest angle (radians) a joint turns from the rotations `from` to `to` (joints left out
/// are at rest).
fn largest_turn(from: &[(String, Quat)], to: &[(String, Quat)]) -> f64 {
    (from.iter().chain(to))
        .map(|(j, _)| f64::from(rot(from, j).angle_between(rot(to, j))))
        .fold(0.0, f64::max)
}

/// The largest distance the right wrist moves per unit of a slerp from the rotations `from` to
/// `to` (joints left out are at rest), sampled at 64 steps (metres).
pub(super) fn wrist_rate(
    skeleton: &Skeleton,
    from: &[(String, Quat)],
    to: &[(String, Quat)],
) -> f64 {
    const STEPS: usize = 64;
    let Some(wrist) = skeleton.joint("r_wrist") else {
        return 0.0;
    };
    let joints: Vec<(usize, Quat, Quat)> = (from.iter().chain(to))
        .filter_map(|(name, _)| Some((skeleton.joint(name)?, rot(from, name), rot(to, name))))
        .collect();
    let at = |w: f32| {
        let mut pose = Pose::rest(skeleton);
        for &(j, a, b) in &joints {
            pose.rotate(j, a.slerp(b, w));
        }
        pose.joint_world(skeleton, wrist).0
    };
    (1..=STEPS)
        .map(|i| {
            let (u0, u1) = ((i - 1) as f32 / STEPS as f32, i as f32 / STEPS as f32);
            f64::from(at(u1).distance(at(u0))) * STEPS as f64
        })
        .fold(0.0, f64::max)
}
