//! The pointing engine: `pointing` as real arm motion toward a named point of the [`World`].
//! The wrist goes to 97 % of the arm's reach on the line from the shoulder to the target (analytic
//! two-link IK, the elbow bending down and back), and the hand turns so that the index finger
//! points at the target. The arm moves there from `start` to `ready` (minimum jerk), holds —
//! following a moving target — until `relax`, and returns by `end` to the pose it started from
//! (the preparation mirrored). `mode` picks the hand; without one, the hand on the target's side.
//! A target the world does not have is refused when the behaviour starts.

use glam::Vec3;

use crate::character::body::ik::{arc, place_limb, LimbRoot, ARM_HINGE, ARM_POLE};
use crate::character::body::{Pose, Skeleton};
use crate::engines::interface::{Engine, EngineError, Steering, Unit, Units};
use crate::engines::motion::{envelope, hands};
use crate::language::bml::{Behaviour, BehaviourKind, Mode};
use crate::planning::timing::{DefaultTimingModels, TimingModel, TimingModels};
use crate::world::World;

/// How far along its reach the wrist goes.
pub const REACH: f32 = 0.97;

#[derive(Debug, Clone)]
struct PointingUnit {
    target: String,
    mode: Option<Mode>,
}

/// The pointing engine (see the module documentation).
#[derive(Debug, Default)]
pub struct PointingEngine {
    models: DefaultTimingModels,
    units: Units<PointingUnit>,
}

/// Points the `side` arm (`l` or `r`) of `pose` at `target`, `w` of the way.
fn point(skeleton: &Skeleton, pose: &mut Pose, side: &str, target: Vec3, w: f32) -> Option<()> {
    // right-side names, mirrored for the left without allocating
    let j = |n: &str| skeleton.joint_mirrored(n, side == "l");
    let (shoulder, elbow, wrist, index) = (
        j("r_shoulder")?,
        j("r_elbow")?,
        j("r_wrist")?,
        j("r_index1")?,
    );
    let joints = skeleton.joints();
    let (upper, lower) = (joints[elbow].offset, joints[wrist].offset);
    let hand = joints[index].offset;
    // the shoulder's frame by forward kinematics along its ancestors only
    let limb = LimbRoot::chain(skeleton, pose, shoulder)?;
    let s = limb.position;
    let reach = (upper.length() + lower.length()) * REACH;
    let goal = s + (target - s).normalize_or(Vec3::Z) * reach;
    // shoulder and elbow put the wrist at the goal, the elbow bending down and back
    let (local_s, local_e) = place_limb(
        skeleton,
        limb,
        [shoulder, elbow, wrist],
        goal,
        ARM_POLE,
        ARM_HINGE,
    )?;
    let o_s = limb.parent * local_s;
    // wrist: the index finger (from its base, along its bones) toward the target; the base
    // moves with the hand, so a few rounds settle it
    let finger = match (j("r_index2"), j("r_index3")) {
        (Some(a), Some(b)) => joints[a].offset + joints[b].offset,
        _ => hand,
    };
    let o_e = o_s * local_e;
    let mut o_w = o_e * pose.rotations[wrist];
    for _ in 0..4 {
        let base = goal + o_w * hand;
        o_w = arc(o_w * finger, target - base) * o_w;
    }
    let local_w = o_e.inverse() * o_w;
    for (i, full) in [(shoulder, local_s), (elbow, local_e), (wrist, local_w)] {
        let from = pose.rotations[i];
        pose.rotations[i] = from.slerp(full, w).normalize();
    }
    Some(())
}

impl Engine for PointingEngine {
    crate::units_remove!();
    crate::units_retime_len!();
    crate::units_play!("pointing");
    crate::units_interrupt!(crate::engines::interface::relax_now);

    fn name(&self) -> &'static str {
        "pointing"
    }

    fn timing(&self, behaviour: &Behaviour) -> Option<TimingModel> {
        matches!(behaviour.kind, BehaviourKind::Pointing(_))
            .then(|| self.models.model(behaviour))?
    }

    fn add(&mut self, unit: Unit<'_>) -> Result<(), EngineError> {
        let BehaviourKind::Pointing(p) = &unit.behaviour.kind else {
            return Err(EngineError(
                "the pointing engine realizes <pointing>".into(),
            ));
        };
        if unit.world.get(&p.target).is_none() {
            return Err(EngineError(format!(
                "{}: {}",
                unit.key,
                unit.world.unknown_target(&p.target)
            )));
        }
        let target = p.target.clone();
        let mode = p.mode;
        self.units.add(unit, PointingUnit { target, mode });
        Ok(())
    }

    fn as_motion(&mut self) -> Option<&mut dyn crate::engines::interface::Motion> {
        Some(self)
    }

    fn as_resources(&self) -> Option<&dyn crate::engines::interface::Resources> {
        Some(self)
    }
}

impl crate::engines::interface::Motion for PointingEngine {
    fn steers(&self, behaviour: &Behaviour, skeleton: &Skeleton) -> Option<Steering> {
        let BehaviourKind::Pointing(p) = &behaviour.kind else {
            return None;
        };
        let arm = ["r_shoulder", "r_elbow", "r_wrist"];
        let sides: &[bool] = match p.mode {
            Some(Mode::RightHand) => &[false],
            Some(Mode::LeftHand) => &[true],
            // both hands, or the target's side (known only while it runs)
            Some(Mode::BothHands) | None => &[false, true],
        };
        let mut joints: Vec<usize> = sides
            .iter()
            .flat_map(|&m| {
                arm.iter()
                    .filter_map(move |j| skeleton.joint_mirrored(j, m))
            })
            .collect();
        joints.sort_unstable();
        Some(Steering {
            joints,
            kind: crate::engines::interface::MotionKind::Kinematic,
            additive: false,
        })
    }

    fn animate(&mut self, now: f64, skeleton: &Skeleton, world: &World, pose: &mut Pose) {
        for (syncs, u) in self.units.all() {
            let (Some(w), Some(target)) = (
                envelope(syncs, now, false, 1.0).map(|w| w as f32),
                world.get(&u.target),
            ) else {
                continue;
            };
            let sides: &[&str] = match u.mode {
                Some(Mode::LeftHand) => &["l"],
                Some(Mode::RightHand) => &["r"],
                Some(Mode::BothHands) => &["l", "r"],
                // the hand on the target's side (the character's left is +x)
                None if target.x > 0.0 => &["l"],
                None => &["r"],
            };
            for side in sides {
                point(skeleton, pose, side, target, w);
            }
        }
    }
}

impl crate::engines::interface::Resources for PointingEngine {
    fn resources(&self, behaviour: &Behaviour) -> &'static [&'static str] {
        match &behaviour.kind {
            BehaviourKind::Pointing(p) => hands(p.mode),
            _ => &[],
        }
    }
}
