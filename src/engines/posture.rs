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
use crate::engine::{Engine, EngineError, Unit, UnitKey, Units};
use crate::engines::gaze::min_jerk;
use crate::schedule::SyncName;
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

fn at(syncs: &[(SyncName, f64)], name: &str) -> Option<f64> {
    syncs.iter().find(|s| s.0 == name).map(|s| s.1)
}

/// How far a unit is toward its stance at `t` (0..1), `None` outside `start..end`.
fn weight(u: &PostureUnit, syncs: &[(SyncName, f64)], t: f64) -> Option<f32> {
    let (start, end) = (at(syncs, "start")?, at(syncs, "end")?);
    if t < start || t >= end {
        return None;
    }
    let (ready, relax) = if u.shift {
        (end, f64::INFINITY)
    } else {
        (at(syncs, "ready")?, at(syncs, "relax")?)
    };
    let w = if t < ready {
        min_jerk((t - start) / (ready - start).max(1e-9))
    } else if t < relax {
        1.0
    } else {
        1.0 - min_jerk((t - relax) / (end - relax).max(1e-9))
    };
    Some(w as f32)
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

    fn exclusive_group(&self, behaviour: &Behaviour) -> Option<&'static str> {
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

    fn remove(&mut self, key: &UnitKey) {
        if let Some(u) = self.units.get(key) {
            if u.shift {
                self.rest = Some(u.stance);
            }
        }
        self.units.remove(key);
    }

    fn animate(&mut self, now: f64, skeleton: &Skeleton, _world: &World, pose: &mut Pose) {
        // a shift that reached its end is the rest stance from then on
        for (syncs, u) in self.units.all() {
            if u.shift && at(syncs, "end").is_some_and(|e| e <= now) {
                self.rest = Some(u.stance);
            }
        }
        let rest = stance(self.rest.unwrap_or(StanceType::Standing));
        let active = self
            .units
            .all()
            .filter_map(|(syncs, u)| Some((at(syncs, "start")?, weight(u, syncs, now)?, u)))
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
