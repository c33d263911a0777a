//! The gaze engine: `gaze` and `gazeShift` as real motion of eyes, neck and trunk toward a named
//! point of the [`World`].
//!
//! - The aim is a yaw (about +y, toward the character's left) and a pitch (about +x, down) from the
//!   point between the eyes to the target, recomputed every frame, so moving targets are tracked.
//! - `influence` distributes the aim over the body: EYES moves only the eyes; NECK and HEAD add
//!   the neck (vc4) and skull base; SHOULDER the upper spine (vt6); WAIST the lower spine (vl5);
//!   WHOLE the root. Each joint takes a fixed share of the aim as a yaw-then-pitch rotation (no
//!   torsion: Donders' law), so the head's orientation depends on the aim only, not on where it
//!   came from. The eyes then take what is left, aimed exactly from their real position
//!   (vergence), within ±35° yaw and ±30° pitch and within the eye joint's limits (its swing
//!   ellipse is smaller at the box's corners).
//! - Timing: from `start` to `ready` the aim moves from the rest aim to the target along a
//!   minimum-jerk profile (single-peaked velocity). The eyes lead with a saccade whose duration is
//!   affine in its amplitude (21 ms + 3.8 ms per degree, the slope that keeps the symmetric
//!   profile's peak velocity below 8.7 rad/s at any amplitude), and then stay on the target while
//!   the head catches up (the eye-in-head angle shrinks); it holds
//!   until `relax`, then returns to the rest aim by `end`. A `gazeShift` moves over its whole span
//!   and makes its target the new rest aim, kept after it ends (`engines::motion`).
//! - Of several gazes running at once the one that started last wins.
//! - Whom the character's walk attends to (the one it asks for room, the walker it makes room
//!   for: `engine::Attend`) is looked at with the neck and head influence under any BML gaze,
//!   as much as the walk attends to them, the eyes leading.
//! - `offsetAngle` in `offsetDirection` turns the aim away from the target (LEFT, RIGHT, UP, DOWN
//!   and the diagonals; POLAR gives no offset).
//! - A target the world does not have is refused when the behaviour starts (the runtime reports
//!   EXECUTION_FAILURE).

use glam::{Quat, Vec3};

use crate::character::body::{Pose, Skeleton};
use crate::engines::interface::{
    Attend, Attention, Engine, EngineError, Steering, Unit, UnitKey, Units,
};
use crate::engines::motion::{at, envelope, finished_shift};
use crate::language::bml::{Behaviour, BehaviourKind, Influence, OffsetDirection};
use crate::planning::timing::SyncName;
use crate::planning::timing::{DefaultTimingModels, TimingModel, TimingModels};
use crate::world::World;

/// Saccade duration at zero amplitude (seconds).
pub const SACCADE_BASE: f64 = 0.021;
/// The eyes' peak angular velocity never exceeds this (rad/s).
pub const SACCADE_PEAK_VELOCITY: f64 = 8.7;
/// Saccade duration per radian of amplitude (seconds; 3.8 ms per degree): the least slope for
/// which the symmetric minimum-jerk profile, whose peak velocity is 1.875 × amplitude /
/// duration, stays below [`SACCADE_PEAK_VELOCITY`] at every amplitude.
pub const SACCADE_PER_RADIAN: f64 = 1.875 / SACCADE_PEAK_VELOCITY;

/// How long a saccade of `amplitude` radians takes: affine in the amplitude.
pub fn saccade_duration(amplitude: f64) -> f64 {
    SACCADE_BASE + SACCADE_PER_RADIAN * amplitude.abs()
}

/// Eye yaw limit (each side), degrees.
pub const EYE_YAW_LIMIT: f32 = 35.0;
/// Eye pitch limit (up and down), degrees.
pub const EYE_PITCH_LIMIT: f32 = 30.0;

/// Shares of the aim per joint for an influence: (joint, yaw share, pitch share).
fn shares(influence: Influence) -> &'static [(&'static str, f32, f32)] {
    match influence {
        Influence::Eyes => &[],
        Influence::Neck | Influence::Head => &[("vc4", 0.25, 0.25), ("skullbase", 0.35, 0.35)],
        Influence::Shoulder => &[
            ("vt6", 0.15, 0.1),
            ("vc4", 0.2, 0.2),
            ("skullbase", 0.3, 0.35),
        ],
        Influence::Waist => &[
            ("vl5", 0.15, 0.05),
            ("vt6", 0.1, 0.1),
            ("vc4", 0.2, 0.2),
            ("skullbase", 0.25, 0.35),
        ],
        Influence::Whole => &[
            ("HumanoidRoot", 0.2, 0.0),
            ("vl5", 0.1, 0.05),
            ("vt6", 0.1, 0.1),
            ("vc4", 0.2, 0.2),
            ("skullbase", 0.2, 0.35),
        ],
    }
}

/// A yaw-then-pitch rotation (no torsion).
pub(crate) fn donders(yaw: f32, pitch: f32) -> Quat {
    Quat::from_rotation_y(yaw) * Quat::from_rotation_x(pitch)
}

/// Yaw and pitch of direction `d` (in a frame facing +z, y up).
pub(crate) fn yaw_pitch(d: Vec3) -> (f32, f32) {
    let yaw = d.x.atan2(d.z);
    let pitch = (-d.y).atan2((d.x * d.x + d.z * d.z).sqrt());
    (yaw, pitch)
}

#[derive(Debug, Clone)]
struct GazeUnit {
    target: String,
    influence: Influence,
    shift: bool,
    /// `offsetAngle` in `offsetDirection`, as (yaw, pitch) radians added to the aim.
    offset: (f32, f32),
}

/// The (yaw, pitch) offset of `offsetAngle` degrees in `offsetDirection` (the character's right
/// is −yaw, down is +pitch; diagonals split the angle evenly). POLAR has no direction of its own
/// and gives no offset.
pub fn offset(angle: Option<f64>, direction: Option<OffsetDirection>) -> (f32, f32) {
    let a = angle.unwrap_or(0.0).to_radians() as f32;
    let d = a * std::f32::consts::FRAC_1_SQRT_2;
    match direction {
        Some(OffsetDirection::Right) => (-a, 0.0),
        Some(OffsetDirection::Left) => (a, 0.0),
        Some(OffsetDirection::Up) => (0.0, -a),
        Some(OffsetDirection::Down) => (0.0, a),
        Some(OffsetDirection::UpRight) => (-d, -d),
        Some(OffsetDirection::UpLeft) => (d, -d),
        Some(OffsetDirection::DownRight) => (-d, d),
        Some(OffsetDirection::DownLeft) => (d, d),
        Some(OffsetDirection::Polar) | None => (0.0, 0.0),
    }
}

/// The gaze engine (see the module documentation).
#[derive(Debug, Default)]
pub struct GazeEngine {
    models: DefaultTimingModels,
    units: Units<GazeUnit>,
    /// Where the character looks when no gaze runs (set by gaze shifts).
    rest: Option<(String, Influence)>,
    /// The point between the eyes in the rest pose (the skeleton does not change).
    eyes_at_rest: Option<Vec3>,
    /// The body aim of the last frame (joint, yaw, pitch) and the gazes that made it.
    last: (BodyAim, Vec<UnitKey>),
    /// A gaze removed while it turned the body (its block replaced, say): the aim it left, held
    /// under the gazes that follow until one has turned fully, then faded out over [`HAND_OVER`]
    /// s (since when, once fading).
    ghost: Option<(BodyAim, Option<f64>)>,
    /// Whom the character's walk attends to this frame (`engine::Attend`).
    attention: Option<Attention>,
}

/// A body aim: (joint, yaw, pitch) per joint the gaze turns.
type BodyAim = Vec<(usize, f32, f32)>;

/// How much faster than the head the eyes go to whom the walk attends to (the eyes are on them
/// once the attention is a third grown: 80 ms of its quarter-second easing).
pub const ATTENTION_EYES: f32 = 3.0;

/// How long the aim a removed gaze left takes to fade once nothing turns over it (s).
pub const HAND_OVER: f64 = 0.4;

fn gaze(b: &Behaviour) -> Option<(&str, Influence, bool, (f32, f32))> {
    let (g, shift) = match &b.kind {
        BehaviourKind::Gaze(g) => (g, false),
        BehaviourKind::GazeShift(g) => (g, true),
        _ => return None,
    };
    Some((
        &g.target,
        g.influence.unwrap_or(Influence::Neck),
        shift,
        offset(g.offset_angle, g.offset_direction),
    ))
}

/// How far a unit has turned toward its target at `t` (0..1), for the body and for the eyes:
/// they lead with a saccade of `amplitude` radians ([`saccade_duration`], at most the whole
/// shift), the body follows until `ready`.
fn weights(u: &GazeUnit, syncs: &[(SyncName, f64)], t: f64, amplitude: f64) -> Option<(f64, f64)> {
    let span = if u.shift {
        at(syncs, "end")? - at(syncs, "start")?
    } else {
        at(syncs, "ready")? - at(syncs, "start")?
    };
    let lead = if span > 0.0 {
        (saccade_duration(amplitude) / span).min(1.0)
    } else {
        1.0
    };
    Some((
        envelope(syncs, t, u.shift, 1.0)?,
        envelope(syncs, t, u.shift, lead)?,
    ))
}

impl GazeEngine {
    /// The point between the eyes in the rest pose.
    fn eyes_at_rest(&mut self, skeleton: &Skeleton) -> Vec3 {
        *self
            .eyes_at_rest
            .get_or_insert_with(|| eyes_at_rest(skeleton))
    }
}

/// The point between the eyes in the rest pose of `skeleton` (the root without eyes): where gaze
/// and head direction measure their aims from.
pub(crate) fn eyes_at_rest(skeleton: &Skeleton) -> Vec3 {
    let rest = Pose::rest(skeleton);
    match (
        skeleton.joint("l_eyeball_joint"),
        skeleton.joint("r_eyeball_joint"),
    ) {
        (Some(l), Some(r)) => {
            (rest.joint_world(skeleton, l).0 + rest.joint_world(skeleton, r).0) / 2.0
        }
        _ => rest.root,
    }
}

impl Engine for GazeEngine {
    crate::units_remove!();
    crate::units_retime_len!();
    crate::units_play!("gaze");
    crate::units_interrupt!(crate::engines::interface::relax_now);

    fn name(&self) -> &'static str {
        "gaze"
    }

    fn timing(&self, behaviour: &Behaviour) -> Option<TimingModel> {
        gaze(behaviour)?;
        self.models.model(behaviour)
    }

    fn add(&mut self, unit: Unit<'_>) -> Result<(), EngineError> {
        let (target, influence, shift, offset) = gaze(unit.behaviour)
            .ok_or_else(|| EngineError("the gaze engine realizes gaze and gazeShift".into()))?;
        if unit.world.get(target).is_none() {
            return Err(EngineError(format!(
                "{}: {}",
                unit.key,
                unit.world.unknown_target(target)
            )));
        }
        self.units.add(
            unit,
            GazeUnit {
                target: target.to_string(),
                influence,
                shift,
                offset,
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

    fn as_attend(&mut self) -> Option<&mut dyn Attend> {
        Some(self)
    }
}

impl Attend for GazeEngine {
    fn attend(&mut self, cue: Option<Attention>) {
        self.attention = cue.filter(|a| a.weight > 0.0 && a.at.is_finite());
    }
}

impl crate::engines::interface::Motion for GazeEngine {
    fn steers(&self, behaviour: &Behaviour, skeleton: &Skeleton) -> Option<Steering> {
        let (_, influence, _, _) = gaze(behaviour)?;
        let eyes = ["l_eyeball_joint", "r_eyeball_joint"];
        Some(Steering::kinematic(
            skeleton,
            shares(influence).iter().map(|s| s.0).chain(eyes),
            true,
        ))
    }

    fn animate(&mut self, now: f64, skeleton: &Skeleton, world: &World, pose: &mut Pose) {
        // a shift that has reached its end is the rest aim from then on
        if let Some(u) = finished_shift(&self.units, now, |u| u.shift) {
            self.rest = Some((u.target.clone(), u.influence));
        }
        let Some(aim) = self.aim(now, skeleton, world) else {
            self.last = (Vec::new(), Vec::new());
            return;
        };
        let applied = aim.turn_body(skeleton, pose);
        aim.turn_eyes(skeleton, pose);
        self.last.0 = applied;
    }
}

/// Where the gaze points in one frame: the rest aim (a gaze shift's target, if one ended) and the
/// running gazes over it, each blending from what is under it toward its own target with its
/// weights. They are layered in start order, so the one that started last wins once it has
/// turned, and one that takes over mid-turn turns on from where the head is.
struct Aim {
    /// Where the eyes are with the body at rest.
    eyes: Vec3,
    /// The rest target and influence.
    rest: Option<(Vec3, Influence)>,
    /// The running gazes, the winner last.
    layers: Vec<Target>,
    /// The aim a removed gaze left (joint, yaw, pitch) and how much of it holds (0–1).
    ghost: (BodyAim, f32),
}

/// The target of one running gaze in a frame.
#[derive(Clone, Copy)]
struct Target {
    point: Vec3,
    influence: Influence,
    /// How far the body and the eyes have turned from what is under it to the target (0–1).
    body_weight: f32,
    eye_weight: f32,
    /// (yaw, pitch) offset from the target, radians.
    offset: (f32, f32),
}

impl GazeEngine {
    /// The aim at `now`, or `None` when there is neither a target nor a rest aim.
    fn aim(&mut self, now: f64, skeleton: &Skeleton, world: &World) -> Option<Aim> {
        let eyes = self.eyes_at_rest(skeleton);
        let rest = (self.rest.as_ref()).and_then(|(t, i)| Some((world.get(t)?, *i)));
        // the saccade's amplitude: from the rest aim (straight ahead without one) to the target
        let from = rest.map_or(Vec3::Z, |(p, _)| p - eyes);
        let amplitude = |target: &str| {
            (world.get(target)).map_or(0.0, |p| f64::from(from.angle_between(p - eyes)))
        };
        // the gaze that started last wins; ties go to the one that ends first
        let keys: Vec<UnitKey> = self.units.keyed().map(|(_, _, k)| k.clone()).collect();
        if self.last.1.iter().any(|k| !keys.contains(k)) && !self.last.0.is_empty() {
            self.ghost = Some((self.last.0.clone(), None));
        }
        self.last.1 = keys;
        let mut active: Vec<(f64, f64, Target)> = (self.units.all())
            .filter_map(|(syncs, u)| {
                let (wb, we) = weights(u, syncs, now, amplitude(&u.target))?;
                let target = Target {
                    point: world.get(&u.target)?,
                    influence: u.influence,
                    body_weight: wb as f32,
                    eye_weight: we as f32,
                    offset: u.offset,
                };
                Some((at(syncs, "start")?, at(syncs, "end")?, target))
            })
            .filter(|a| a.2.body_weight > 0.0 || a.2.eye_weight > 0.0)
            .collect();
        active.sort_by(|a, b| a.0.total_cmp(&b.0).then(b.1.total_cmp(&a.1)));
        // whom the walk attends to lies under the BML gazes: the eyes go there at once, the
        // head as the attention grows
        let attended = self.attention.map(|a| Target {
            point: a.at,
            influence: Influence::Neck,
            body_weight: a.weight.min(1.0),
            eye_weight: (ATTENTION_EYES * a.weight).min(1.0),
            offset: (0.0, 0.0),
        });
        let layers: Vec<Target> = (attended.into_iter())
            .chain(active.into_iter().map(|a| a.2))
            .collect();
        // the aim a removed gaze left holds until a gaze over it has turned fully, then fades
        let turned = layers.last().is_none_or(|t| t.body_weight >= 0.999);
        let ghost = match self.ghost.as_mut() {
            Some((joints, since)) => {
                if turned && since.is_none() {
                    *since = Some(now);
                }
                let held = since.map_or(1.0, |s| 1.0 - ((now - s) / HAND_OVER).min(1.0));
                (joints.clone(), held as f32)
            }
            None => (Vec::new(), 0.0),
        };
        if ghost.1 <= 0.0 {
            self.ghost = None;
        }
        let some = !layers.is_empty() || rest.is_some() || ghost.1 > 0.0;
        some.then_some(Aim {
            eyes,
            rest,
            layers,
            ghost,
        })
    }
}

/// The yaw and pitch share of `influence` at joint `j`.
fn share(influence: Influence, j: &str) -> (f32, f32) {
    (shares(influence).iter().find(|s| s.0 == j)).map_or((0.0, 0.0), |s| (s.1, s.2))
}

/// `a` turned by whole turns to lie within half a turn of `near`.
fn unwrap_near(a: f32, near: f32) -> f32 {
    near + crate::character::body::limits::wrap(a - near)
}

impl Aim {
    /// The target's (yaw, pitch) from the eyes at rest, with its offset.
    fn aim_of(&self, t: &Target) -> (f32, f32) {
        let (y, p) = yaw_pitch(t.point - self.eyes);
        (y + t.offset.0, p + t.offset.1)
    }

    /// The spine, neck and head: the rest aim's shares, the aim a removed gaze left over them,
    /// each layer blended over that. Returns what it applied (joint, yaw, pitch).
    fn turn_body(&self, skeleton: &Skeleton, pose: &mut Pose) -> BodyAim {
        let (rest_yaw, rest_pitch, rest_influence) = match self.rest {
            Some((p, i)) => {
                let (y, pi) = yaw_pitch(p - self.eyes);
                (y, pi, i)
            }
            None => (0.0, 0.0, Influence::Eyes),
        };
        let aims: Vec<(f32, f32)> = self.layers.iter().map(|t| self.aim_of(t)).collect();
        let mut joints: Vec<&str> = Vec::new();
        let influences =
            std::iter::once(rest_influence).chain(self.layers.iter().map(|t| t.influence));
        for s in influences.flat_map(shares) {
            if !joints.contains(&s.0) {
                joints.push(s.0);
            }
        }
        let mut indices: Vec<(usize, &str)> = joints
            .into_iter()
            .filter_map(|j| Some((skeleton.joint(j)?, j)))
            .collect();
        for &(i, _, _) in &self.ghost.0 {
            if !indices.iter().any(|x| x.0 == i) {
                indices.push((i, ""));
            }
        }
        let mut applied = Vec::with_capacity(indices.len());
        for (i, j) in indices {
            let (ry, rp) = share(rest_influence, j);
            let (mut yaw, mut pitch) = (ry * rest_yaw, rp * rest_pitch);
            if let Some(&(_, gy, gp)) = self.ghost.0.iter().find(|g| g.0 == i) {
                let g = self.ghost.1;
                yaw = (1.0 - g) * yaw + g * gy;
                pitch = (1.0 - g) * pitch + g * gp;
            }
            for (t, &(ty, tp)) in self.layers.iter().zip(&aims) {
                let (sy, sp) = share(t.influence, j);
                let w = t.body_weight;
                yaw = (1.0 - w) * yaw + w * sy * ty;
                pitch = (1.0 - w) * pitch + w * sp * tp;
            }
            pose.rotate(i, donders(yaw, pitch));
            applied.push((i, yaw, pitch));
        }
        applied
    }

    /// The eyes: aimed exactly from where they are now (after the body turned), each layer
    /// blended over the rest aim, within their limits. A target straight behind is seen on the
    /// side the body turned toward (the eyes take what the body left of the same turn).
    fn turn_eyes(&self, skeleton: &Skeleton, pose: &mut Pose) {
        let (yaw_max, pitch_max) = (EYE_YAW_LIMIT.to_radians(), EYE_PITCH_LIMIT.to_radians());
        let limit =
            |(y, p): (f32, f32)| (y.clamp(-yaw_max, yaw_max), p.clamp(-pitch_max, pitch_max));
        let rest_point = self.rest.map(|r| r.0);
        for eye in ["l_eyeball_joint", "r_eyeball_joint"] {
            let Some(e) = skeleton.joint(eye) else {
                continue;
            };
            // where the eye is now and how its parent (the head) is turned: forward kinematics
            // along the eye's ancestors only
            let (at_eye, eye_orientation) = pose.joint_world(skeleton, e);
            let inv = (eye_orientation * pose.rotations[e].inverse()).inverse();
            let eye_aim = |p: Vec3| yaw_pitch(inv * (p - at_eye));
            let (mut yaw, mut pitch) = rest_point.map_or((0.0, 0.0), |p| limit(eye_aim(p)));
            for t in &self.layers {
                let (ty, _) = self.aim_of(t);
                // what the body left of the turn to this target
                let body: f32 = shares(t.influence).iter().map(|s| s.1).sum();
                let (y, p) = eye_aim(t.point);
                let (y, p) = limit((
                    unwrap_near(y + t.offset.0, ty * (1.0 - body)),
                    p + t.offset.1,
                ));
                yaw += t.eye_weight * (y - yaw);
                pitch += t.eye_weight * (p - pitch);
            }
            // (set, not added: a gaze wins over the idle layer's saccades)
            pose.rotations[e] = donders(yaw, pitch);
            // the eye's anatomical range (a swing ellipse and a little twist, which the yaw and
            // pitch box only approximates: its corners lie outside): an aim beyond it holds the
            // eye at its edge
            if let Some(inside) =
                (skeleton.limits().of(e)).and_then(|l| l.clamped(pose.rotations[e]))
            {
                pose.rotations[e] = inside;
            }
        }
    }
}

impl crate::engines::interface::Resources for GazeEngine {
    fn exclusive_group(&self, behaviour: &Behaviour) -> Option<&str> {
        matches!(behaviour.kind, BehaviourKind::Gaze(_)).then_some("gaze")
    }

    fn resources(&self, _behaviour: &Behaviour) -> &'static [&'static str] {
        &["eyes"]
    }
}

#[cfg(test)]
mod tests;
