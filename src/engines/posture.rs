//! The posture engine: `posture` and `postureShift` stances as real motion of the legs and the
//! root. A stance is a target for the hips, knees and ankles and the root's height and pitch:
//! STANDING is the rest pose, SITTING folds hips and knees to right angles and lowers the root to
//! a chair's height, CROUCHING bends deeper, LYING turns the body onto its back. A posture moves
//! to its stance from `start` to `ready` (minimum jerk), holds it until `relax` and returns to the
//! rest stance by `end`; a `postureShift` moves over its whole span and its stance becomes the rest
//! stance, kept after it ends. Of several postures running at once the one that started last wins
//!. `<pose part lexeme>` children hold a part of the body in a pose bound in
//! `fixtures/bindings/poses.json` to a procedural unit (arms akimbo, crossed or hanging, legs
//! spread, head tilted; mirrored for the other side), eased in and out with the stance; a pose
//! the bindings lack refuses the posture, naming the poses there are.

use std::sync::Arc;

use glam::{Quat, Vec3};

use crate::character::body::{Pose, Skeleton};
use crate::engines::interface::{Engine, EngineError, Steering, Unit, Units};
use crate::engines::motion::{at, envelope, finished_shift};
use crate::engines::procedural::{Library, ProcUnit};
use crate::language::bml::{Behaviour, BehaviourKind, PosePart, StanceType};
use crate::planning::timing::{DefaultTimingModels, TimingModel, TimingModels};
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

/// The embedded pose bindings.
const POSES: &str = include_str!("../../fixtures/bindings/poses.json");

/// A pose held by a unit of the procedural library on some sides (`false` as authored, `true`
/// mirrored).
type HeldPose = (Arc<ProcUnit>, &'static [bool]);

/// `<pose part lexeme>` bound to procedural units.
#[derive(Debug, Clone, Default)]
pub struct PoseBindings {
    poses: Vec<(PosePart, String, HeldPose)>,
}

impl PoseBindings {
    /// The default bindings.
    pub fn default_bindings() -> PoseBindings {
        static BINDINGS: std::sync::LazyLock<PoseBindings> = std::sync::LazyLock::new(|| {
            PoseBindings::from_json(POSES, &Library::default_library())
                .expect("the embedded pose bindings are valid")
        });
        BINDINGS.clone()
    }

    /// Reads `{"poses": [{"part", "lexeme", "procedural", "sides": right|left|both}]}`.
    pub fn from_json(text: &str, library: &Library) -> Result<PoseBindings, String> {
        #[derive(serde::Deserialize)]
        #[serde(deny_unknown_fields)]
        struct File {
            #[serde(default, rename = "description")]
            _description: crate::data::Note,
            poses: Vec<Pose>,
        }
        #[derive(serde::Deserialize)]
        #[serde(deny_unknown_fields)]
        struct Pose {
            part: String,
            lexeme: String,
            procedural: String,
            sides: Sides,
        }
        #[derive(serde::Deserialize)]
        #[serde(rename_all = "lowercase")]
        enum Sides {
            Right,
            Left,
            Both,
        }
        let file: File = crate::data::from_json(text)?;
        let mut poses = Vec::new();
        for (i, p) in file.poses.into_iter().enumerate() {
            let part = PosePart::parse(&p.part)
                .ok_or_else(|| format!("poses[{i}].part: unknown pose part '{}'", p.part))?;
            let unit = library
                .get(&p.procedural)
                .ok_or_else(|| format!("{}: no procedural unit '{}'", p.lexeme, p.procedural))?
                .clone();
            let sides: &'static [bool] = match p.sides {
                Sides::Right => &[false],
                Sides::Left => &[true],
                Sides::Both => &[false, true],
            };
            poses.push((part, p.lexeme, (unit, sides)));
        }
        Ok(PoseBindings { poses })
    }

    /// `first`'s bindings, then these: for a pose both bind, `first`'s wins.
    pub fn extended_by(mut self, first: PoseBindings) -> PoseBindings {
        let mut poses = first.poses;
        poses.append(&mut self.poses);
        PoseBindings { poses }
    }

    fn get(&self, part: PosePart, lexeme: &str) -> Result<HeldPose, String> {
        self.poses
            .iter()
            .find(|p| p.0 == part && p.1 == lexeme)
            .map(|p| p.2.clone())
            .ok_or_else(|| {
                let known: Vec<String> = self
                    .poses
                    .iter()
                    .map(|p| format!("{} {}", p.0.as_str(), p.1))
                    .collect();
                format!(
                    "no pose {lexeme} for {} (the pose bindings have {known:?})",
                    part.as_str()
                )
            })
    }
}

#[derive(Debug, Clone)]
struct PostureUnit {
    stance: StanceType,
    shift: bool,
    poses: Vec<HeldPose>,
}

/// The posture engine (see the module documentation).
#[derive(Debug)]
pub struct PostureEngine {
    models: DefaultTimingModels,
    bindings: PoseBindings,
    units: Units<PostureUnit>,
    /// The stance and poses held when no posture runs (set by posture shifts).
    rest: Option<(StanceType, Vec<HeldPose>)>,
}

impl Default for PostureEngine {
    fn default() -> Self {
        PostureEngine::new(PoseBindings::default_bindings())
    }
}

impl PostureEngine {
    /// A posture engine holding the poses of `bindings`.
    pub fn new(bindings: PoseBindings) -> Self {
        PostureEngine {
            models: DefaultTimingModels::default(),
            bindings,
            units: Units::new(),
            rest: None,
        }
    }
}

/// Holds `poses` on `pose` with weight `w`.
fn hold(skeleton: &Skeleton, pose: &mut Pose, poses: &[HeldPose], w: f32) {
    for (unit, sides) in poses {
        for &mirrored in sides.iter() {
            // the bound units were checked when the bindings were read
            let _ = unit.apply(0.5, &unit.params, mirrored, w, skeleton, pose);
        }
    }
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
    for mirrored in [false, true] {
        for (joint, deg) in [
            ("r_hip", s.hips),
            ("r_knee", s.knees),
            ("r_talocrural", s.ankles),
        ] {
            if let Some(i) = skeleton.joint_mirrored(joint, mirrored) {
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
    crate::units_interrupt!(crate::engines::interface::relax_now);

    fn name(&self) -> &'static str {
        "posture"
    }

    fn timing(&self, behaviour: &Behaviour) -> Option<TimingModel> {
        posture(behaviour)?;
        self.models.model(behaviour)
    }

    fn add(&mut self, unit: Unit<'_>) -> Result<(), EngineError> {
        let (stance, shift) = posture(unit.behaviour).ok_or_else(|| {
            EngineError("the posture engine realizes posture and postureShift".into())
        })?;
        let written = match &unit.behaviour.kind {
            BehaviourKind::Posture(p) | BehaviourKind::PostureShift(p) => &p.poses,
            _ => return Err(EngineError("not a posture".into())),
        };
        let poses = written
            .iter()
            .map(|p| self.bindings.get(p.part, &p.lexeme))
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| EngineError(format!("{}: {e}", unit.key)))?;
        self.units.add(
            unit,
            PostureUnit {
                stance,
                shift,
                poses,
            },
        );
        Ok(())
    }

    fn as_motion(&mut self) -> Option<&mut dyn crate::engines::interface::Motion> {
        Some(self)
    }

    fn as_resources(&self) -> Option<&dyn crate::engines::interface::Resources> {
        Some(self)
    }
}

impl crate::engines::interface::Motion for PostureEngine {
    fn steers(&self, behaviour: &Behaviour, skeleton: &Skeleton) -> Option<Steering> {
        let poses = match &behaviour.kind {
            BehaviourKind::Posture(p) | BehaviourKind::PostureShift(p) => &p.poses,
            _ => return None,
        };
        let legs = [
            "HumanoidRoot",
            "l_hip",
            "l_knee",
            "l_talocrural",
            "r_hip",
            "r_knee",
            "r_talocrural",
        ];
        let mut s = Steering::kinematic(skeleton, legs, poses.is_empty());
        for p in poses {
            if let Ok((unit, sides)) = self.bindings.get(p.part, &p.lexeme) {
                s.joints.extend(unit.steering(skeleton, sides).joints);
            }
        }
        s.joints.sort_unstable();
        s.joints.dedup();
        Some(s)
    }

    fn animate(&mut self, now: f64, skeleton: &Skeleton, _world: &World, pose: &mut Pose) {
        // a shift that reached its end is the rest stance (and poses) from then on
        if let Some(u) = finished_shift(&self.units, now, |u| u.shift) {
            self.rest = Some((u.stance, u.poses.clone()));
        }
        let (rest_type, rest_poses) = match &self.rest {
            Some((s, p)) => (*s, p.as_slice()),
            None => (StanceType::Standing, &[][..]),
        };
        let rest = stance(rest_type);
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
        // the rest poses fade out while a posture with other poses holds, and its poses in
        match active {
            Some((_, w, u)) => {
                hold(skeleton, pose, rest_poses, 1.0 - w);
                hold(skeleton, pose, &u.poses, w);
            }
            None => hold(skeleton, pose, rest_poses, 1.0),
        }
    }
}

impl crate::engines::interface::Resources for PostureEngine {
    fn exclusive_group(&self, behaviour: &Behaviour) -> Option<&str> {
        matches!(behaviour.kind, BehaviourKind::Posture(_)).then_some("posture")
    }

    fn resources(&self, _behaviour: &Behaviour) -> &'static [&'static str] {
        &["legs"]
    }
}
