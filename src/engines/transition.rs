//! The transition engine: BMLT `transition` units. Given only a start, an end and the
//! joints to move, a transition starts at the pose the body had when it began and ends at the
//! pose the animation predictor computes for its end from the predictable units (keyframes,
//! procedural units: [`Prediction::predict`](crate::engines::interface::Prediction::predict)), so that the motion that follows starts without a jump:
//!
//! ```xml
//! <bmlt:transition id="t1" class="SlerpTransition" start="kf1:end" end="p1:start">
//!   <bmlt:parameter name="joints" value="r_shoulder r_elbow r_wrist"/>
//! </bmlt:transition>
//! ```
//!
//! The slerp variant (class `SlerpTransition`, or any class whose name contains `slerp`) turns
//! every joint from its start rotation toward the predicted one with a minimum-jerk weight: exact
//! at both ends. Without a `joints` parameter every joint moves. The engine is registered last, so
//! the pose it starts from is the frame's final pose and its blend overrides the joints it moves.

use crate::character::body::{Pose, Skeleton};
use crate::engines::interface::{Engine, EngineError, Steering, Unit, Units};
use crate::engines::motion::min_jerk;
use crate::language::bml::{Behaviour, BehaviourKind};
use crate::planning::timing::{TimingModel, MIN_DURATION};
use crate::world::World;

#[derive(Debug, Clone)]
struct TransitionUnit {
    /// Joint names to move (empty: all).
    joints: Vec<String>,
    /// The pose when it began, caught on its first frame.
    from: Option<Pose>,
}

/// The transition engine (see the module documentation).
#[derive(Debug, Default)]
pub struct TransitionEngine {
    units: Units<TransitionUnit>,
    /// The final pose of the previous frame (this engine animates last).
    last: Option<Pose>,
    /// Predicted poses at the ends of the running transitions, for this frame.
    predictions: Vec<(f64, Pose)>,
}

impl Engine for TransitionEngine {
    crate::units_remove!();
    crate::units_retime_len!();
    crate::units_play!("transition");
    crate::units_interrupt!(crate::engines::interface::stop_now);

    fn name(&self) -> &'static str {
        "transition"
    }

    fn timing(&self, behaviour: &Behaviour) -> Option<TimingModel> {
        matches!(behaviour.kind, BehaviourKind::Transition(_))
            .then(|| TimingModel::stretchable(&[("start", 0.0), ("end", 0.5)]))
    }

    fn add(&mut self, unit: Unit<'_>) -> Result<(), EngineError> {
        let BehaviourKind::Transition(t) = &unit.behaviour.kind else {
            return Err(EngineError(
                "the transition engine realizes bmlt:transition".into(),
            ));
        };
        if !t.class.to_ascii_lowercase().contains("slerp") {
            return Err(EngineError(format!(
                "{}: transition class '{}' is not supported (SlerpTransition)",
                unit.key, t.class
            )));
        }
        let mut joints = Vec::new();
        for p in &t.params {
            match p.name.as_str() {
                "joints" => joints = p.value.split_whitespace().map(str::to_string).collect(),
                other => {
                    return Err(EngineError(format!(
                        "{}: a transition has no parameter '{other}' (it has \"joints\")",
                        unit.key
                    )))
                }
            }
        }
        self.units.add(unit, TransitionUnit { joints, from: None });
        Ok(())
    }

    fn as_motion(&mut self) -> Option<&mut dyn crate::engines::interface::Motion> {
        Some(self)
    }

    fn as_prediction(&mut self) -> Option<&mut dyn crate::engines::interface::Prediction> {
        Some(self)
    }
}

impl crate::engines::interface::Motion for TransitionEngine {
    fn steers(&self, behaviour: &Behaviour, skeleton: &Skeleton) -> Option<Steering> {
        let BehaviourKind::Transition(t) = &behaviour.kind else {
            return None;
        };
        let named = t.params.iter().find(|p| p.name == "joints");
        Some(match named {
            Some(p) => Steering::kinematic(skeleton, p.value.split_whitespace(), false),
            None => Steering {
                joints: (0..skeleton.len()).collect(),
                kind: crate::engines::interface::MotionKind::Kinematic,
                additive: false,
            },
        })
    }

    fn animate(&mut self, now: f64, skeleton: &Skeleton, _world: &World, pose: &mut Pose) {
        for (syncs, u) in self.units.all_mut() {
            let (Some(start), Some(end)) = (syncs.first().map(|s| s.1), syncs.last().map(|s| s.1))
            else {
                continue;
            };
            if now < start || now > end {
                continue;
            }
            let Some((_, target)) = self.predictions.iter().find(|p| p.0 == end) else {
                continue;
            };
            let from = u
                .from
                .get_or_insert_with(|| self.last.clone().unwrap_or_else(|| pose.clone()));
            let w = if end - start > MIN_DURATION {
                min_jerk((now - start) / (end - start)) as f32
            } else {
                1.0
            };
            let mut blend = |i: usize| {
                pose.rotations[i] = match w {
                    w if w <= 0.0 => from.rotations[i],
                    w if w >= 1.0 => target.rotations[i],
                    w => from.rotations[i].slerp(target.rotations[i], w).normalize(),
                };
            };
            if u.joints.is_empty() {
                (0..skeleton.len()).for_each(&mut blend);
            } else {
                u.joints
                    .iter()
                    .filter_map(|j| skeleton.joint(j))
                    .for_each(blend);
            }
        }
        self.predictions.clear();
        // keep this frame's pose for a transition that starts next frame (its block may start
        // then: units are added when their block starts); a copy of one pose, no allocation
        match &mut self.last {
            Some(last) => last.clone_from(pose),
            None => self.last = Some(pose.clone()),
        }
    }
}

impl crate::engines::interface::Prediction for TransitionEngine {
    fn prediction_times(&self, now: f64) -> Vec<f64> {
        self.units
            .all()
            .filter_map(|(syncs, _)| {
                let (start, end) = (syncs.first()?.1, syncs.last()?.1);
                (start <= now && now <= end).then_some(end)
            })
            .collect()
    }

    fn predicted(&mut self, poses: Vec<(f64, Pose)>) {
        self.predictions = poses;
    }
}
