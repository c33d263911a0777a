//! The keyframe engine: BMLT `keyframe` behaviours with an inline `<SkeletonInterpolator>` — keys
//! of local joint rotations (quaternions `w x y z`; with `encoding="T1R"` the root's translation
//! first) at times in seconds:
//!
//! ```xml
//! <bmlt:keyframe id="kf1">
//!   <SkeletonInterpolator rotationEncoding="quaternions" parts="r_shoulder r_elbow" encoding="R">
//!     0   1 0 0 0   1 0 0 0
//!     0.5 0.92 0 0.38 0   0.71 0 0.71 0
//!   </SkeletonInterpolator>
//! </bmlt:keyframe>
//! ```
//!
//! The keys are laid out linearly between the behaviour's `start` and `end` (its preferred length
//! is the last key's time), each key is hit exactly at its time, and rotations are interpolated by
//! slerp between neighbouring keys, or, with `<bmlt:parameter name="interpolation"
//! value="hermite"/>` (or `squad`), by a C¹ Hermite spline (see [`Interpolation`]). The named joints take the keyframe's rotations (they replace,
//! not add to, what other engines set).
//!
//! Densely sampled keys (motion capture: at least [`SAMPLED_KEYS`] keys evenly spaced, more
//! than 40 a second) are smoothed once when the unit is added, by a zero-phase Butterworth
//! low-pass at [`MOTION_CUTOFF`] Hz on each quaternion component (then renormalized) and on the
//! root's translation (thesis §3.5): recorded jitter would otherwise become large accelerations
//! in the inverse dynamics of a simulated body's kinematic chains. Sparse, authored keys and
//! procedural motion are never filtered.

use glam::{Quat, Vec3};
use quick_xml::events::Event;
use quick_xml::Reader;

use crate::character::body::{Pose, Skeleton};
use crate::character::dynamics::butterworth::Butterworth;
use crate::character::dynamics::kinematics::same_hemisphere;
use crate::engines::interface::{Engine, EngineError, Steering, Unit, Units};
use crate::language::bml::{Behaviour, BehaviourKind};
use crate::planning::timing::SyncName;
use crate::planning::timing::{Flexibility, SyncKey, TimingModel, MIN_DURATION};
use crate::world::World;

/// Keys read from a `<SkeletonInterpolator>`.
#[derive(Debug, Clone, PartialEq)]
pub struct Keys {
    /// Joint names, in the order of each key's rotations.
    pub parts: Vec<String>,
    /// Whether each key starts with the root's translation.
    pub root_translation: bool,
    /// (time, root translation, rotation per part), by time.
    pub keys: Vec<(f64, Vec3, Vec<Quat>)>,
}

/// How rotations are interpolated between keys.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Interpolation {
    /// Spherical linear, key to key (continuous, with a kink at every key).
    #[default]
    Slerp,
    /// A cubic Hermite spline on the rotation sphere (C¹: the angular velocity is continuous
    /// through every key, whatever the key spacing), in its Bézier form evaluated by repeated
    /// slerp; each key's tangent is the average of the angular velocities toward its neighbours
    /// (one-sided at the first and last key).
    Hermite,
}

/// A rotation as a rotation vector (axis × angle), the shorter way round.
fn rotvec(q: Quat) -> Vec3 {
    if q.w < 0.0 { -q } else { q }.to_scaled_axis()
}

/// The Hermite control rotations `(a, b)` of every segment and part: segment `i` runs from key
/// `i` through `a` and `b` to key `i + 1`.
pub fn hermite_controls(keys: &[(f64, Vec3, Vec<Quat>)]) -> Vec<Vec<(Quat, Quat)>> {
    let n = keys.len();
    let parts = keys.first().map_or(0, |k| k.2.len());
    // angular velocity (rotation vector per second, in the key's own frame) at every key
    let velocity = |i: usize, p: usize| -> Vec3 {
        let q = keys[i].2[p];
        let next = (i + 1 < n)
            .then(|| rotvec(q.inverse() * keys[i + 1].2[p]) / (keys[i + 1].0 - keys[i].0) as f32);
        let prev = (i > 0)
            .then(|| -rotvec(q.inverse() * keys[i - 1].2[p]) / (keys[i].0 - keys[i - 1].0) as f32);
        match (prev, next) {
            (Some(a), Some(b)) => (a + b) / 2.0,
            (Some(v), None) | (None, Some(v)) => v,
            (None, None) => Vec3::ZERO,
        }
    };
    (0..n.saturating_sub(1))
        .map(|i| {
            let dt = (keys[i + 1].0 - keys[i].0) as f32;
            (0..parts)
                .map(|p| {
                    let a = keys[i].2[p] * Quat::from_scaled_axis(velocity(i, p) * dt / 3.0);
                    let b =
                        keys[i + 1].2[p] * Quat::from_scaled_axis(-velocity(i + 1, p) * dt / 3.0);
                    (a.normalize(), b.normalize())
                })
                .collect()
        })
        .collect()
}

/// The cubic Bézier curve `q0, a, b, q1` on the rotation sphere at `u` (repeated slerp).
fn bezier(q0: Quat, a: Quat, b: Quat, q1: Quat, u: f32) -> Quat {
    let (p01, p12, p23) = (q0.slerp(a, u), a.slerp(b, u), b.slerp(q1, u));
    p01.slerp(p12, u).slerp(p12.slerp(p23, u), u).normalize()
}

/// Reads the first `<SkeletonInterpolator>` of `content`.
pub fn read_keys(content: &str) -> Result<Keys, String> {
    let mut reader = Reader::from_str(content);
    let mut parts: Option<Vec<String>> = None;
    let mut root_translation = false;
    let mut text = String::new();
    let mut inside = false;
    loop {
        match reader.read_event() {
            Ok(Event::Start(e)) if e.local_name().as_ref() == b"SkeletonInterpolator" => {
                inside = true;
                for a in e.attributes().flatten() {
                    let v = a.unescape_value().map_err(|x| x.to_string())?.into_owned();
                    match a.key.local_name().as_ref() {
                        b"parts" => {
                            parts = Some(v.split_whitespace().map(str::to_string).collect())
                        }
                        b"encoding" => match v.trim() {
                            "R" => root_translation = false,
                            "T1R" => root_translation = true,
                            other => {
                                return Err(format!(
                                    "encoding '{other}' is not supported (R or T1R)"
                                ))
                            }
                        },
                        b"rotationEncoding" if v.trim() != "quaternions" => {
                            return Err(format!(
                                "rotationEncoding '{v}' is not supported (quaternions)"
                            ))
                        }
                        _ => {}
                    }
                }
            }
            Ok(Event::Text(t)) if inside => text.push_str(&String::from_utf8_lossy(t.as_ref())),
            Ok(Event::End(e)) if e.local_name().as_ref() == b"SkeletonInterpolator" => break,
            Ok(Event::Eof) => {
                if !inside {
                    return Err("no <SkeletonInterpolator> in the keyframe".into());
                }
                break;
            }
            Err(e) => return Err(format!("the keyframe content is not well-formed: {e}")),
            Ok(_) => {}
        }
    }
    let parts = parts.ok_or("the SkeletonInterpolator has no parts")?;
    let per_key = 1 + if root_translation { 3 } else { 0 } + 4 * parts.len();
    let numbers: Vec<f64> = text
        .split_whitespace()
        .map(|n| {
            n.parse::<f64>()
                .map_err(|_| format!("'{n}' is not a number"))
        })
        .collect::<Result<_, _>>()?;
    if numbers.is_empty() || !numbers.len().is_multiple_of(per_key) {
        return Err(format!(
            "{} numbers do not make keys of {per_key} (time, {}{} quaternions)",
            numbers.len(),
            if root_translation { "root x y z, " } else { "" },
            parts.len()
        ));
    }
    let mut keys: Vec<(f64, Vec3, Vec<Quat>)> = Vec::new();
    for k in numbers.chunks(per_key) {
        let t = k[0];
        if !t.is_finite() || keys.last().is_some_and(|l| t <= l.0) {
            return Err(format!("key times must increase (at {t})"));
        }
        let (root, rest) = if root_translation {
            (Vec3::new(k[1] as f32, k[2] as f32, k[3] as f32), &k[4..])
        } else {
            (Vec3::ZERO, &k[1..])
        };
        let rotations = rest
            .chunks(4)
            .map(|q| {
                Quat::from_xyzw(q[1] as f32, q[2] as f32, q[3] as f32, q[0] as f32).normalize()
            })
            .collect();
        keys.push((t, root, rotations));
    }
    Ok(Keys {
        parts,
        root_translation,
        keys,
    })
}

/// The cut-off (Hz) of the low-pass on sampled motion: the thesis uses 15–25 Hz.
pub const MOTION_CUTOFF: f64 = 20.0;

/// Keys counted as sampled motion (not authored keyframes) from this many on.
pub const SAMPLED_KEYS: usize = 8;

impl Keys {
    /// The keys smoothed as sampled motion (see the module documentation), or `None` when
    /// they are not sampled motion: fewer than [`SAMPLED_KEYS`], unevenly spaced (a gap more
    /// than 1 % off the mean), or 40 a second or fewer (the cut-off would not be below half
    /// the rate).
    pub fn smoothed(&self) -> Option<Keys> {
        let n = self.keys.len();
        if n < SAMPLED_KEYS {
            return None;
        }
        let dt = self.duration() / (n - 1) as f64;
        let even = (self.keys.windows(2)).all(|w| ((w[1].0 - w[0].0) - dt).abs() <= 0.01 * dt);
        if !even || dt <= 0.0 || 1.0 / dt <= 2.0 * MOTION_CUTOFF {
            return None;
        }
        let filter = Butterworth::zero_phase(MOTION_CUTOFF, 1.0 / dt);
        let smooth = |values: Vec<f64>| filter.filtfilt(&values);
        let mut out = self.clone();
        let roots: [Vec<f64>; 3] =
            std::array::from_fn(|c| smooth(self.keys.iter().map(|k| f64::from(k.1[c])).collect()));
        for (i, key) in out.keys.iter_mut().enumerate() {
            key.1 = Vec3::new(roots[0][i] as f32, roots[1][i] as f32, roots[2][i] as f32);
        }
        for part in 0..self.parts.len() {
            // one hemisphere, so that q and −q do not average to nothing
            let turns = same_hemisphere(
                &(self.keys.iter())
                    .map(|k| k.2[part].as_dquat())
                    .collect::<Vec<_>>(),
            );
            let comps: [Vec<f64>; 4] =
                std::array::from_fn(|c| smooth(turns.iter().map(|q| q.to_array()[c]).collect()));
            for (i, key) in out.keys.iter_mut().enumerate() {
                let q =
                    glam::DQuat::from_array([comps[0][i], comps[1][i], comps[2][i], comps[3][i]]);
                key.2[part] = q.normalize().as_quat();
            }
        }
        Some(out)
    }

    /// Length from the first key to the last.
    pub fn duration(&self) -> f64 {
        self.keys.last().map_or(0.0, |l| l.0) - self.keys.first().map_or(0.0, |f| f.0)
    }

    /// The root translation and rotations at key time `t` (clamped to the keys) with `how`;
    /// `controls` are [`hermite_controls`] of the keys (used by [`Interpolation::Hermite`]).
    pub fn sample_with(
        &self,
        t: f64,
        how: Interpolation,
        controls: &[Vec<(Quat, Quat)>],
    ) -> (Vec3, Vec<Quat>) {
        if how == Interpolation::Slerp || controls.len() + 1 != self.keys.len() {
            return self.sample(t);
        }
        self.interpolate(t, |i, p, q, u| {
            let (ca, cb) = controls[i][p];
            bezier(q.0, ca, cb, q.1, u)
        })
    }

    /// The root translation and rotations at key time `t` (clamped to the keys), slerped.
    pub fn sample(&self, t: f64) -> (Vec3, Vec<Quat>) {
        self.interpolate(t, |_, _, q, u| q.0.slerp(q.1, u))
    }

    /// The keys at `t`: a key's own values outside the keys, else the root lerped and every
    /// part's rotation by `between(segment, part, (from, to), u)` within its segment.
    fn interpolate(
        &self,
        t: f64,
        between: impl Fn(usize, usize, (Quat, Quat), f32) -> Quat,
    ) -> (Vec3, Vec<Quat>) {
        let k = &self.keys;
        if t <= k[0].0 || k.len() == 1 {
            return (k[0].1, k[0].2.clone());
        }
        let last = &k[k.len() - 1];
        if t >= last.0 {
            return (last.1, last.2.clone());
        }
        let i = k.partition_point(|key| key.0 <= t) - 1;
        let (a, b) = (&k[i], &k[i + 1]);
        let u = ((t - a.0) / (b.0 - a.0)) as f32;
        let rotations =
            a.2.iter()
                .zip(&b.2)
                .enumerate()
                .map(|(p, (qa, qb))| between(i, p, (*qa, *qb), u))
                .collect();
        (a.1.lerp(b.1, u), rotations)
    }
}

/// Sets the keyframe's rotations at global time `now` for a unit timed by `syncs` (the keys laid
/// linearly from its first sync to its last); false outside its time.
pub(crate) fn play(
    (k, how, controls): (&Keys, Interpolation, &[Vec<(Quat, Quat)>]),
    joints: &[Option<usize>],
    syncs: &[(SyncName, f64)],
    now: f64,
    pose: &mut Pose,
) -> bool {
    let (Some(start), Some(end)) = (syncs.first().map(|s| s.1), syncs.last().map(|s| s.1)) else {
        return false;
    };
    if now < start || now > end {
        return false;
    }
    let first = k.keys[0].0;
    let span = end - start;
    let t = if span > 0.0 {
        first + (now - start) / span * k.duration()
    } else {
        first + k.duration()
    };
    let (root, rotations) = k.sample_with(t, how, controls);
    if k.root_translation {
        pose.root = root;
    }
    for (joint, q) in joints.iter().zip(rotations) {
        if let Some(i) = *joint {
            pose.rotations[i] = q;
        }
    }
    true
}

fn content(b: &Behaviour) -> Option<&str> {
    match &b.kind {
        BehaviourKind::Keyframe(a) => Some(&a.content),
        _ => None,
    }
}

#[derive(Debug, Clone)]
struct KeyframeUnit {
    keys: Keys,
    how: Interpolation,
    /// Hermite control rotations per segment (empty for slerp).
    controls: Vec<Vec<(Quat, Quat)>>,
    /// The skeleton joint of each part, resolved on first use.
    joints: Option<Vec<Option<usize>>>,
}

/// The keyframe engine (see the module documentation).
#[derive(Debug, Default)]
pub struct KeyframeEngine {
    units: Units<KeyframeUnit>,
}

impl Engine for KeyframeEngine {
    crate::units_remove!();
    crate::units_retime_len!();
    crate::units_play!("keyframe");
    crate::units_interrupt!(crate::engines::interface::stop_now);

    fn name(&self) -> &'static str {
        "keyframe"
    }

    fn timing(&self, behaviour: &Behaviour) -> Option<TimingModel> {
        let c = content(behaviour)?;
        // a keyframe that cannot be read is refused when it starts, with the reason
        let d = read_keys(c).map_or(1.0, |k| k.duration());
        Some(TimingModel {
            keys: vec![
                SyncKey::new("start", 0.0),
                SyncKey::new("end", d.max(MIN_DURATION)),
            ],
            flexibility: Flexibility::Stretchable {
                min_duration: MIN_DURATION,
                max_duration: f64::INFINITY,
            },
            persistent: false,
        })
    }

    fn add(&mut self, unit: Unit<'_>) -> Result<(), EngineError> {
        let c = content(unit.behaviour)
            .ok_or_else(|| EngineError("the keyframe engine realizes bmlt:keyframe".into()))?;
        let keys = read_keys(c).map_err(|e| EngineError(format!("{}: {e}", unit.key)))?;
        let keys = keys.smoothed().unwrap_or(keys);
        let mut how = Interpolation::Slerp;
        if let BehaviourKind::Keyframe(a) = &unit.behaviour.kind {
            for p in &a.params {
                match (p.name.as_str(), p.value.trim()) {
                    ("interpolation", "slerp") => how = Interpolation::Slerp,
                    ("interpolation", "hermite" | "squad") => how = Interpolation::Hermite,
                    (name, value) => {
                        return Err(EngineError(format!(
                            "{}: keyframe parameter {name}=\"{value}\" is not supported (interpolation = slerp or hermite)",
                            unit.key
                        )))
                    }
                }
            }
        }
        let controls = match how {
            Interpolation::Slerp => Vec::new(),
            Interpolation::Hermite => hermite_controls(&keys.keys),
        };
        self.units.add(
            unit,
            KeyframeUnit {
                keys,
                how,
                controls,
                joints: None,
            },
        );
        Ok(())
    }

    fn as_motion(&mut self) -> Option<&mut dyn crate::engines::interface::Motion> {
        Some(self)
    }

    fn as_prediction(&mut self) -> Option<&mut dyn crate::engines::interface::Prediction> {
        Some(self)
    }
}

impl crate::engines::interface::Motion for KeyframeEngine {
    fn steers(&self, behaviour: &Behaviour, skeleton: &Skeleton) -> Option<Steering> {
        let keys = read_keys(content(behaviour)?).ok()?;
        let mut s = Steering::kinematic(skeleton, keys.parts.iter().map(String::as_str), false);
        if keys.root_translation && !s.joints.contains(&0) {
            s.joints.insert(0, 0);
        }
        Some(s)
    }

    fn animate(&mut self, now: f64, skeleton: &Skeleton, _world: &World, pose: &mut Pose) {
        for (syncs, u) in self.units.all_mut() {
            let k = &u.keys;
            let joints = u
                .joints
                .get_or_insert_with(|| k.parts.iter().map(|p| skeleton.joint(p)).collect());
            play((k, u.how, &u.controls), joints, syncs, now, pose);
        }
    }
}

impl crate::engines::interface::Prediction for KeyframeEngine {
    fn predict(&self, t: f64, skeleton: &Skeleton, _world: &World, pose: &mut Pose) -> bool {
        let mut any = false;
        for (syncs, u) in self.units.all() {
            let resolved;
            let joints = match &u.joints {
                Some(j) => j,
                None => {
                    resolved = u.keys.parts.iter().map(|p| skeleton.joint(p)).collect();
                    &resolved
                }
            };
            any |= play((&u.keys, u.how, &u.controls), joints, syncs, t, pose);
        }
        any
    }
}

#[cfg(test)]
mod tests;
