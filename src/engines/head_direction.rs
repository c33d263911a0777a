//! The head-direction engine: `headDirectionShift` turns the head (neck and skull base) to face a
//! named point of the [`World`] and keeps it there: the new default direction of the head. The
//! turn is a yaw-then-pitch rotation (no torsion, as for gaze) taking the face's forward
//! direction to the direction from the eyes to the target, shared 40 % by the neck (vc4) and 60 %
//! by the skull base (as powers of the one rotation, so that together they make all of it), moving from the previous direction along a minimum-jerk profile from
//! `start` to `end`; a moving target is followed. The eyes are left to the gaze engine (which
//! runs after this one and aims them from wherever the head is). A target the world does not
//! have is refused when the behaviour starts.

use glam::{Quat, Vec3};

use crate::character::body::{Pose, Skeleton};
use crate::engines::gaze::{donders, eyes_at_rest, yaw_pitch};
use crate::engines::interface::{Engine, EngineError, Steering, Unit, Units};
use crate::engines::motion::{envelope, finished_shift};
use crate::language::bml::{Behaviour, BehaviourKind};
use crate::planning::timing::{DefaultTimingModels, TimingModel, TimingModels};
use crate::world::World;

/// (joint, share of the turn).
const SHARES: &[(&str, f32)] = &[("vc4", 0.4), ("skullbase", 0.6)];

#[derive(Debug, Clone)]
struct DirectionUnit {
    target: String,
}

/// The head-direction engine (see the module documentation).
#[derive(Debug, Default)]
pub struct HeadDirectionEngine {
    models: DefaultTimingModels,
    units: Units<DirectionUnit>,
    /// The target the head faces when no shift runs.
    rest: Option<String>,
    /// The point between the eyes in the rest pose (the skeleton does not change).
    eyes_at_rest: Option<Vec3>,
}

impl Engine for HeadDirectionEngine {
    crate::units_remove!();
    crate::units_retime_len!();
    crate::units_play!("headDirection");
    crate::units_interrupt!(crate::engines::interface::stop_now);

    fn name(&self) -> &'static str {
        "headDirection"
    }

    fn timing(&self, behaviour: &Behaviour) -> Option<TimingModel> {
        matches!(behaviour.kind, BehaviourKind::HeadDirectionShift { .. })
            .then(|| self.models.model(behaviour))?
    }

    fn add(&mut self, unit: Unit<'_>) -> Result<(), EngineError> {
        let BehaviourKind::HeadDirectionShift { target } = &unit.behaviour.kind else {
            return Err(EngineError(
                "the head-direction engine realizes headDirectionShift".into(),
            ));
        };
        if unit.world.get(target).is_none() {
            return Err(EngineError(format!(
                "{}: {}",
                unit.key,
                unit.world.unknown_target(target)
            )));
        }
        let target = target.clone();
        self.units.add(unit, DirectionUnit { target });
        Ok(())
    }

    fn as_motion(&mut self) -> Option<&mut dyn crate::engines::interface::Motion> {
        Some(self)
    }
}

impl crate::engines::interface::Motion for HeadDirectionEngine {
    fn steers(&self, behaviour: &Behaviour, skeleton: &Skeleton) -> Option<Steering> {
        matches!(behaviour.kind, BehaviourKind::HeadDirectionShift { .. })
            .then(|| Steering::kinematic(skeleton, SHARES.iter().map(|s| s.0), true))
    }

    fn animate(&mut self, now: f64, skeleton: &Skeleton, world: &World, pose: &mut Pose) {
        // a shift that reached its end is the head's direction from then on
        if let Some(u) = finished_shift(&self.units, now, |_| true) {
            self.rest = Some(u.target.clone());
        }
        // of shifts running at once, the one that started last
        let active = self
            .units
            .all()
            .filter_map(|(syncs, u)| Some((syncs.first()?.1, envelope(syncs, now, true, 1.0)?, u)))
            .max_by(|a, b| a.0.total_cmp(&b.0));
        if active.is_none() && self.rest.is_none() {
            return;
        }
        let from = *self
            .eyes_at_rest
            .get_or_insert_with(|| eyes_at_rest(skeleton));
        let aim = |target: Option<&String>| {
            target
                .and_then(|t| world.get(t))
                .map_or((0.0, 0.0), |p| yaw_pitch(p - from))
        };
        let (ry, rp) = aim(self.rest.as_ref());
        let (yaw, pitch) = match active {
            Some((_, w, u)) => {
                let (ty, tp) = aim(Some(&u.target));
                let w = w as f32;
                (ry + w * (ty - ry), rp + w * (tp - rp))
            }
            None => (ry, rp),
        };
        // powers of one rotation compose exactly: the skull ends up turned by all of it
        let turn = donders(yaw, pitch);
        for (joint, share) in SHARES {
            if let Some(i) = skeleton.joint(joint) {
                pose.rotate(i, Quat::IDENTITY.slerp(turn, *share));
            }
        }
    }
}
