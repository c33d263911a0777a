//! The idle layer: what a standing person does while nothing else moves them — breathing (the
//! chest and the shoulders rise and fall), a slow shift of weight from foot to foot (the pelvis
//! sways sideways, the spine leans back against it, the feet stay where they stand: the legs
//! follow by inverse kinematics), the eyes' small saccades (`saccades`) and their look away as
//! an utterance begins (`aversion`). It is the pose every frame starts from, so
//! behaviours play on top of it and inverse kinematics and gaze aim from where it put the body.
//! It is not a behaviour: it has no timing and never shows in the feedback. Deterministic: the
//! same character (by id) at the same time gets the same pose.

use glam::{Quat, Vec3};

use super::aversion::{Aversion, Utterance};
use super::pose::Pose;
use super::saccades::Saccades;
use super::skeleton::Skeleton;

/// Breaths per second (15 a minute, a person at rest).
pub const BREATHING_HZ: f32 = 0.25;
/// How far the upper chest turns back at the top of a breath, degrees.
pub const BREATHING_CHEST_DEG: f32 = 0.6;
/// How far the shoulders rise at the top of a breath, degrees at the collarbone.
pub const BREATHING_SHOULDER_DEG: f32 = 0.8;
/// One weight shift, left and back, takes this long, seconds.
pub const WEIGHT_SHIFT_PERIOD: f32 = 7.0;
/// How far the pelvis moves sideways, metres.
pub const WEIGHT_SHIFT_M: f32 = 0.008;
/// How far the pelvis rolls with it, degrees (the spine rolls back by as much).
pub const WEIGHT_SHIFT_ROLL_DEG: f32 = 0.6;

/// The idle motion of one character.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Idle {
    /// Phase offset in seconds, from the character's id (characters do not breathe in step).
    phase: f32,
    /// The joints it turns, found once: chest (vt6), collarbones (left, right), pelvis
    /// (sacroiliac) and lower spine (vl5).
    joints: [Option<usize>; 5],
    /// Hip, knee and ankle of each leg, with the ankle's place at rest (world).
    legs: [Option<([usize; 3], Vec3)>; 2],
    /// The legs solved once for [`LEG_TABLE`] amounts of the weight shift from −1 to 1: how far
    /// the pelvis sinks and the six leg rotations (left hip, knee, ankle, then right). A frame
    /// interpolates between the two nearest (measured: solving both legs every frame cost more
    /// than all the rest of a standing character's frame).
    table: [(f32, [Quat; 6]); LEG_TABLE],
    /// The eyes' idle saccades.
    saccades: Saccades,
    /// The eyes' looks away as an utterance begins.
    aversion: Aversion,
}

/// Entries of the legs' table (the solutions differ by well under a millimetre at the feet
/// between neighbours).
const LEG_TABLE: usize = 33;

impl Idle {
    /// The idle motion of character `id` ("" the default one) on `skeleton`.
    pub fn new(id: &str, skeleton: &Skeleton) -> Idle {
        // FNV-1a: a fixed hash, so the phase is the same in every run and on every platform
        let hash = id.bytes().fold(0x811c_9dc5u32, |h, b| {
            (h ^ u32::from(b)).wrapping_mul(0x0100_0193)
        });
        let mut idle = Idle {
            phase: (hash % 10_000) as f32 / 10_000.0 * WEIGHT_SHIFT_PERIOD,
            joints: [
                "vt6",
                "l_sternoclavicular",
                "r_sternoclavicular",
                "sacroiliac",
                "vl5",
            ]
            .map(|j| skeleton.joint(j)),
            legs: ["l", "r"].map(|side| {
                let j = |n: &str| skeleton.joint(&format!("{side}_{n}"));
                let leg = [j("hip")?, j("knee")?, j("talocrural")?];
                Some((leg, Pose::rest(skeleton).joint_world(skeleton, leg[2]).0))
            }),
            table: [(0.0, [Quat::IDENTITY; 6]); LEG_TABLE],
            saccades: Saccades::new(id, skeleton),
            aversion: Aversion::new(id),
        };
        for k in 0..LEG_TABLE {
            let shift = -1.0 + 2.0 * k as f32 / (LEG_TABLE - 1) as f32;
            let mut pose = Pose::rest(skeleton);
            idle.shift_pelvis(shift, &mut pose);
            let rest_y = pose.root.y;
            idle.plant_feet(skeleton, &mut pose);
            let mut legs = [Quat::IDENTITY; 6];
            for (s, leg) in idle.legs.iter().enumerate() {
                for (i, &joint) in leg.iter().flat_map(|l| l.0.iter()).enumerate() {
                    legs[3 * s + i] = pose.rotations[joint];
                }
            }
            idle.table[k] = (rest_y - pose.root.y, legs);
        }
        idle
    }

    /// The weight shift's pelvis: `shift` (−1 to 1) of the sway sideways and the roll.
    fn shift_pelvis(&self, shift: f32, pose: &mut Pose) {
        pose.root += Vec3::X * (WEIGHT_SHIFT_M * shift);
        if let Some(j) = self.joints[3] {
            pose.rotate(
                j,
                Quat::from_rotation_z((WEIGHT_SHIFT_ROLL_DEG * shift).to_radians()),
            );
        }
    }

    /// The pose at global time `t`: the rest pose with breathing, the weight shift and the
    /// eyes' saccades, looking away at the start of `utterance` (the last one the character
    /// began, if any).
    pub fn pose(&self, skeleton: &Skeleton, t: f64, utterance: Option<&Utterance>) -> Pose {
        let mut pose = Pose::rest(skeleton);
        let look = self.aversion.look(t, &self.saccades, utterance);
        self.saccades.apply(look, &mut pose);
        let t = t as f32 + self.phase;
        let tau = std::f32::consts::TAU;
        // breathing: in for the first part of the cycle, out after (a raised cosine, 0 at rest)
        let breath = 0.5 - 0.5 * (tau * BREATHING_HZ * t).cos();
        let [chest, l_clavicle, r_clavicle, _pelvis, spine] = self.joints;
        let turn = |joint: Option<usize>, q: Quat, pose: &mut Pose| {
            if let Some(j) = joint {
                pose.rotate(j, q);
            }
        };
        let chest_turn = -(BREATHING_CHEST_DEG * breath).to_radians();
        turn(chest, Quat::from_rotation_x(chest_turn), &mut pose);
        let shoulder = (BREATHING_SHOULDER_DEG * breath).to_radians();
        turn(l_clavicle, Quat::from_rotation_z(shoulder), &mut pose);
        turn(r_clavicle, Quat::from_rotation_z(-shoulder), &mut pose);
        // weight shift: the pelvis sways sideways and rolls, the lower spine rolls it back
        let shift = (tau * t / WEIGHT_SHIFT_PERIOD).sin();
        self.shift_pelvis(shift, &mut pose);
        let roll = (WEIGHT_SHIFT_ROLL_DEG * shift).to_radians();
        turn(spine, Quat::from_rotation_z(-roll), &mut pose);
        // the legs, from the table
        let u = (shift + 1.0) / 2.0 * (LEG_TABLE - 1) as f32;
        let k = (u.floor() as usize).min(LEG_TABLE - 2);
        let f = u - k as f32;
        let ((d0, a), (d1, b)) = (&self.table[k], &self.table[k + 1]);
        pose.root.y -= d0 + (d1 - d0) * f;
        for (s, leg) in self.legs.iter().enumerate() {
            for (i, &joint) in leg.iter().flat_map(|l| l.0.iter()).enumerate() {
                pose.rotations[joint] = a[3 * s + i].slerp(b[3 * s + i], f);
            }
        }
        pose
    }

    /// Keeps both feet flat where they stand at rest: the pelvis a little lower where a leg
    /// would not reach, hips and knees by two-link IK.
    fn plant_feet(&self, skeleton: &Skeleton, pose: &mut Pose) {
        let joints = skeleton.joints();
        let mut drop = 0.0f32;
        for (leg, ankle) in self.legs.iter().flatten() {
            let reach = joints[leg[1]].offset.length() + joints[leg[2]].offset.length() - 1.5e-4;
            let d = pose.joint_world(skeleton, leg[0]).0 - *ankle;
            let h = glam::Vec2::new(d.x, d.z).length().min(reach);
            drop = drop.max(d.y - (reach * reach - h * h).sqrt());
        }
        pose.root.y -= drop;
        for (leg, ankle) in self.legs.iter().flatten() {
            let Some(frame) = super::ik::LimbRoot::chain(skeleton, pose, leg[0]) else {
                continue;
            };
            let placed = super::ik::place_limb(
                skeleton,
                frame,
                *leg,
                *ankle,
                super::ik::LEG_POLE,
                super::ik::LEG_HINGE,
            );
            if let Some((hip, knee)) = placed {
                pose.rotations[leg[0]] = hip;
                pose.rotations[leg[1]] = knee;
                let shin = pose.joint_world(skeleton, leg[1]).1;
                pose.rotations[leg[2]] = shin.inverse().normalize();
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_chest_rises_and_falls_every_four_seconds_and_the_pelvis_sways() {
        let s = Skeleton::adult();
        let idle = Idle::new("", &s);
        let chest = |t: f64| idle.pose(&s, t, None).world(&s).positions[s.joint("vc7").unwrap()];
        let root = |t: f64| idle.pose(&s, t, None).root.x;
        // the breathing repeats every 4 s, and moves the neck base by about a millimetre
        let heights: Vec<f32> = (0..80).map(|i| chest(f64::from(i) * 0.05).z).collect();
        let range = heights.iter().fold(f32::NEG_INFINITY, |a, &b| a.max(b))
            - heights.iter().fold(f32::INFINITY, |a, &b| a.min(b));
        assert!((0.0005..0.005).contains(&range), "{range}");
        assert!(
            (chest(1.3).z - chest(5.3).z).abs() < 1e-4,
            "every 4 s the same breath"
        );
        // the weight shift: ±8 mm over 7 s
        let xs: Vec<f32> = (0..140).map(|i| root(f64::from(i) * 0.05)).collect();
        let max = xs.iter().fold(0f32, |a, &b| a.max(b.abs()));
        assert!((max - WEIGHT_SHIFT_M).abs() < 1e-3, "{max}");
        // the feet stay put while the pelvis sways (no more than a tenth of a millimetre)
        let ankle =
            |t: f64| idle.pose(&s, t, None).world(&s).positions[s.joint("l_talocrural").unwrap()];
        let moved = (0..140).map(|i| ankle(f64::from(i) * 0.05).distance(ankle(0.0)));
        let most = moved.fold(0f32, f32::max);
        assert!(most < 1e-4, "{most}");
        // deterministic, and another character is out of step
        assert_eq!(
            idle.pose(&s, 2.0, None),
            Idle::new("", &s).pose(&s, 2.0, None)
        );
        assert_ne!(
            idle.pose(&s, 2.0, None),
            Idle::new("anna", &s).pose(&s, 2.0, None)
        );
    }
}
