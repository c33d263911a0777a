//! The posture engine: `posture` and `postureShift` stances as real motion of the legs and the
//! root. A stance is a target for the hips, knees and ankles and the root's height and pitch:
//! STANDING is the rest pose, SITTING folds hips and knees to right angles and lowers the root to
//! a chair's height, CROUCHING bends deeper, LYING turns the body onto its back. A posture moves
//! to its stance from `start` to `ready` (minimum jerk), holds it until `relax` and returns to the
//! rest stance by `end`; a `postureShift` moves over its whole span and its stance becomes the rest
//! stance, kept after it ends. Of several postures running at once the one that started last wins
//! (R33). `<pose part lexeme>` children are not interpreted yet (the support table says so).

use glam::{Quat, Vec3};

use crate::bml::{Behaviour, BehaviourKind, StanceType};
use crate::body::{Pose, Skeleton};
use crate::engine::timing::{DefaultTimingModels, TimingModel, TimingModels};
use crate::engine::{Engine, EngineError, Unit, Units};
use crate::engines::motion::{at, envelope, finished_shift};
use crate::world::World;

/// A stance: pitch of the hips and knees and ankles (degrees, about +x), and the root's drop
/// (metres) and pitch (degrees).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stance {
    /// Hip pitch: negative raises the thighs forward.
    pub hips: f32,
    /// Knee pitch: positive folds the shins back.
    pub knees: f32,
    /// Ankle pitch.
    pub ankles: f32,
    /// How far the root goes down.
    pub drop: f32,
    /// Root pitch (the whole body; -90 lies on the back).
    pub pitch: f32,
}

/// The stance of a BML stance type.
pub fn stance(t: StanceType) -> Stance {
    let s = |hips, knees, ankles, drop, pitch| Stance {
        hips,
        knees,
        ankles,
        drop,
        pitch,
    };
    match t {
        StanceType::Standing => s(0.0, 0.0, 0.0, 0.0, 0.0),
        StanceType::Sitting => s(-90.0, 90.0, 0.0, 0.45, 0.0),
        StanceType::Crouching => s(-110.0, 130.0, -20.0, 0.55, 0.0),
        StanceType::Lying => s(0.0, 0.0, 0.0, 0.85, -90.0),
    }
}

#[derive(Debug, Clone)]
struct PostureUnit {
    stance: StanceType,
    shift: bool,
}

/// The posture engine (see the module documentation).
#[derive(Debug, Default)]
pub struct PostureEngine {
    models: DefaultTimingModels,
    units: Units<PostureUnit>,
    /// The stance held when no posture runs (set by posture shifts).
    rest: Option<StanceType>,
}

fn posture(b: &Behaviour) -> Option<(StanceType, bool)> {
    match &b.kind {
        BehaviourKind::Posture(p) => Some((p.stance, false)),
        BehaviourKind::PostureShift(p) => Some((p.stance, true)),
        _ => None,
    }
}

/// Puts `s` into `pose` (legs and root).
fn apply(skeleton: &Skeleton, pose: &mut Pose, s: Stance) {
    for side in ["l", "r"] {
        for (joint, deg) in [("hip", s.hips), ("knee", s.knees), ("talocrural", s.ankles)] {
            if let Some(i) = skeleton.joint(&format!("{side}_{joint}")) {
                pose.rotate(i, Quat::from_rotation_x(deg.to_radians()));
            }
        }
    }
    pose.root -= Vec3::Y * s.drop;
    pose.rotate(0, Quat::from_rotation_x(s.pitch.to_radians()));
}

/// `a` blended toward `b` by `w`.
fn blend(a: Stance, b: Stance, w: f32) -> Stance {
    let l = |x: f32, y: f32| x + (y - x) * w;
    Stance {
        hips: l(a.hips, b.hips),
        knees: l(a.knees, b.knees),
        ankles: l(a.ankles, b.ankles),
        drop: l(a.drop, b.drop),
        pitch: l(a.pitch, b.pitch),
    }
}

impl Engine for PostureEngine {
    crate::units_remove!();
    crate::units_retime_len!();
    crate::units_play!("posture");
    crate::units_interrupt!(crate::engine::relax_now);

    fn name(&self) -> &'static str {
        "posture"
    }

    fn timing(&self, behaviour: &Behaviour) -> Option<TimingModel> {
        posture(behaviour)?;
        self.models.model(behaviour)
    }

    fn exclusive_group(&self, behaviour: &Behaviour) -> Option<&str> {
        matches!(behaviour.kind, BehaviourKind::Posture(_)).then_some("posture")
    }

    fn resources(&self, _behaviour: &Behaviour) -> &'static [&'static str] {
        &["legs"]
    }

    fn add(&mut self, unit: Unit<'_>) -> Result<(), EngineError> {
        let (stance, shift) = posture(unit.behaviour).ok_or_else(|| {
            EngineError("the posture engine realizes posture and postureShift".into())
        })?;
        self.units.add(unit, PostureUnit { stance, shift });
        Ok(())
    }

    fn animate(&mut self, now: f64, skeleton: &Skeleton, _world: &World, pose: &mut Pose) {
        // a shift that reached its end is the rest stance from then on
        if let Some(u) = finished_shift(&self.units, now, |u| u.shift) {
            self.rest = Some(u.stance);
        }
        let rest = stance(self.rest.unwrap_or(StanceType::Standing));
        let active = self
            .units
            .all()
            .filter_map(|(syncs, u)| {
                let w = envelope(syncs, now, u.shift, 1.0)? as f32;
                Some((at(syncs, "start")?, w, u))
            })
            .max_by(|a, b| a.0.total_cmp(&b.0));
        let s = match active {
            Some((_, w, u)) => blend(rest, stance(u.stance), w),
            None => rest,
        };
        if s != stance(StanceType::Standing) {
            apply(skeleton, pose, s);
        }
    }
}
