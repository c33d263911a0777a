//! The gesture engine: `gesture` lexemes as arm motion defined by data (S77). A bindings file
//! (`fixtures/bindings/gestures.json`, embedded as the default lexicon) gives for each lexeme the
//! right arm's local joint rotations at some of the gesture's sync points (Z, X, Y Euler degrees).
//! The arm is at those rotations exactly at those syncs, slerps between them, moves from where it
//! was at `start` to the first key and back by `end`. `LEFT_HAND` mirrors the keys onto the left
//! arm (across the body's middle plane), `BOTH_HANDS` plays both arms. A lexeme the lexicon lacks
//! is played with its timing only.

use std::collections::HashMap;

use glam::{EulerRot, Quat};

use crate::bml::{Behaviour, BehaviourKind, Mode};
use crate::body::{Pose, Skeleton};
use crate::engine::timing::{DefaultTimingModels, TimingModel, TimingModels};
use crate::engine::{Engine, EngineError, Unit, Units};
use crate::engines::motion::{hands, min_jerk};
use crate::schedule::SyncName;
use crate::world::World;

/// The embedded default lexicon.
const DEFAULT: &str = include_str!("../../fixtures/bindings/gestures.json");

/// A lexeme's keys: (sync name, [(right-arm joint, rotation)]).
pub type GestureKeys = Vec<(String, Vec<(String, Quat)>)>;

/// Gesture lexemes bound to keys.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Lexicon {
    gestures: HashMap<String, GestureKeys>,
}

impl Lexicon {
    /// The default lexicon (BEAT, WAVE, CONDUIT, CUP, POINT).
    pub fn default_lexicon() -> Lexicon {
        // read from its embedded JSON once per process, then copied
        static LEXICON: std::sync::LazyLock<Lexicon> = std::sync::LazyLock::new(|| {
            Lexicon::from_json(DEFAULT).expect("the embedded gesture lexicon is valid")
        });
        LEXICON.clone()
    }

    /// Reads a bindings file: `{"gestures": [{"lexeme": …, "keys": {SYNC: {JOINT: [z, x, y]}}}]}`.
    pub fn from_json(text: &str) -> Result<Lexicon, String> {
        let v: serde_json::Value =
            serde_json::from_str(text).map_err(|e| format!("not JSON: {e}"))?;
        let list = v["gestures"].as_array().ok_or("no \"gestures\" list")?;
        let mut gestures = HashMap::new();
        for g in list {
            let lexeme = g["lexeme"].as_str().ok_or("a gesture without \"lexeme\"")?;
            let keys = g["keys"]
                .as_object()
                .ok_or_else(|| format!("{lexeme}: no \"keys\""))?;
            let mut out: GestureKeys = Vec::new();
            for (sync, joints) in keys {
                let joints = joints
                    .as_object()
                    .ok_or_else(|| format!("{lexeme}:{sync}: joints must be an object"))?;
                let mut rot = Vec::new();
                for (joint, angles) in joints {
                    let a = crate::body::skeleton::three_numbers(angles).ok_or_else(|| {
                        format!("{lexeme}:{sync}:{joint}: three angles (z, x, y)")
                    })?;
                    let q = Quat::from_euler(
                        EulerRot::ZXY,
                        a[0].to_radians(),
                        a[1].to_radians(),
                        a[2].to_radians(),
                    );
                    rot.push((joint.clone(), q));
                }
                out.push((sync.clone(), rot));
            }
            gestures.insert(lexeme.to_string(), out);
        }
        Ok(Lexicon { gestures })
    }

    /// The keys of `lexeme`.
    pub fn keys(&self, lexeme: &str) -> Option<&GestureKeys> {
        self.gestures.get(lexeme)
    }
}

/// The left-arm twin of a right-arm joint and rotation (mirrored across the y-z plane).
pub fn mirror(joint: &str, q: Quat) -> (String, Quat) {
    let name = match joint.strip_prefix("r_") {
        Some(rest) => format!("l_{rest}"),
        None => joint.to_string(),
    };
    (name, Quat::from_xyzw(q.x, -q.y, -q.z, q.w))
}

#[derive(Debug, Clone)]
struct GestureUnit {
    /// (sync, [(joint, rotation)]) for the arms it moves, in sync order.
    keys: Vec<(String, Vec<(String, Quat)>)>,
    /// The keys resolved against the skeleton and the unit's syncs, made on first use.
    compiled: Option<Compiled>,
}

/// A unit's keys ready to play: the joints it moves, and per key the index of its sync and a
/// rotation per joint (identity where the key leaves a joint out).
#[derive(Debug, Clone)]
struct Compiled {
    joints: Vec<usize>,
    keys: Vec<(usize, Vec<Quat>)>,
}

fn compile(u: &GestureUnit, skeleton: &Skeleton, syncs: &[(SyncName, f64)]) -> Compiled {
    let mut names: Vec<&str> = Vec::new();
    for (_, k) in &u.keys {
        for (j, _) in k {
            if !names.contains(&j.as_str()) && skeleton.joint(j).is_some() {
                names.push(j);
            }
        }
    }
    let joints = names.iter().filter_map(|n| skeleton.joint(n)).collect();
    let mut keys: Vec<(usize, Vec<Quat>)> = u
        .keys
        .iter()
        .filter_map(|(sync, k)| {
            let i = syncs.iter().position(|s| s.0 == *sync)?;
            let rot = names
                .iter()
                .map(|n| k.iter().find(|x| x.0 == *n).map_or(Quat::IDENTITY, |x| x.1))
                .collect();
            Some((i, rot))
        })
        .collect();
    keys.sort_by_key(|k| k.0);
    Compiled { joints, keys }
}

/// Plays compiled keys at `t` into `pose`: rest at `start`, the keys at their syncs, rest at
/// `end`, minimum-jerk slerp between neighbours. Nothing outside `start..=end`.
fn play_keys(c: &Compiled, syncs: &[(SyncName, f64)], t: f64, pose: &mut Pose) {
    let (Some(start), Some(end)) = (syncs.first().map(|s| s.1), syncs.last().map(|s| s.1)) else {
        return;
    };
    if t < start || t > end || c.keys.is_empty() {
        return;
    }
    // the segment around t: (time, key index or None for rest)
    let time = |k: usize| syncs[c.keys[k].0].1;
    let mut before: (f64, Option<usize>) = (start, None);
    let mut after: (f64, Option<usize>) = (end, None);
    for k in 0..c.keys.len() {
        if time(k) <= t {
            before = (time(k), Some(k));
        } else {
            after = (time(k), Some(k));
            break;
        }
    }
    let w = if after.0 > before.0 {
        min_jerk((t - before.0) / (after.0 - before.0)) as f32
    } else {
        0.0
    };
    for (j, &joint) in c.joints.iter().enumerate() {
        let q = |k: Option<usize>| k.map_or(Quat::IDENTITY, |k| c.keys[k].1[j]);
        pose.rotate(joint, q(before.1).slerp(q(after.1), w));
    }
}

/// The gesture engine (see the module documentation).
#[derive(Debug)]
pub struct GestureEngine {
    models: DefaultTimingModels,
    lexicon: Lexicon,
    units: Units<GestureUnit>,
}

impl Default for GestureEngine {
    fn default() -> Self {
        GestureEngine::new(Lexicon::default_lexicon())
    }
}

impl GestureEngine {
    /// A gesture engine with `lexicon`.
    pub fn new(lexicon: Lexicon) -> Self {
        GestureEngine {
            models: DefaultTimingModels::default(),
            lexicon,
            units: Units::new(),
        }
    }
}

impl Engine for GestureEngine {
    crate::units_remove!();
    crate::units_retime_len!();
    crate::units_play!("gesture");
    crate::units_interrupt!(crate::engine::relax_now);

    fn name(&self) -> &'static str {
        "gesture"
    }

    fn timing(&self, behaviour: &Behaviour) -> Option<TimingModel> {
        matches!(behaviour.kind, BehaviourKind::Gesture(_)).then(|| self.models.model(behaviour))?
    }

    fn resources(&self, behaviour: &Behaviour) -> &'static [&'static str] {
        match &behaviour.kind {
            BehaviourKind::Gesture(g) => hands(g.mode),
            _ => &[],
        }
    }

    fn add(&mut self, unit: Unit<'_>) -> Result<(), EngineError> {
        let BehaviourKind::Gesture(g) = &unit.behaviour.kind else {
            return Err(EngineError("the gesture engine realizes <gesture>".into()));
        };
        let right = self.lexicon.keys(&g.lexeme).cloned().unwrap_or_default();
        let keys = right
            .into_iter()
            .map(|(sync, joints)| {
                let arms: Vec<(String, Quat)> = match g.mode {
                    Some(Mode::LeftHand) => joints.iter().map(|(j, q)| mirror(j, *q)).collect(),
                    Some(Mode::BothHands) => joints
                        .iter()
                        .flat_map(|(j, q)| [(j.clone(), *q), mirror(j, *q)])
                        .collect(),
                    Some(Mode::RightHand) | None => joints,
                };
                (sync, arms)
            })
            .collect();
        self.units.add(
            unit,
            GestureUnit {
                keys,
                compiled: None,
            },
        );
        Ok(())
    }

    fn animate(&mut self, now: f64, skeleton: &Skeleton, _world: &World, pose: &mut Pose) {
        for (syncs, u) in self.units.all_mut() {
            if u.compiled.is_none() {
                u.compiled = Some(compile(u, skeleton, syncs));
            }
            if let Some(c) = &u.compiled {
                play_keys(c, syncs, now, pose);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    #[test]
    fn the_default_lexicon_has_the_gestures_the_issue_names() {
        let l = Lexicon::default_lexicon();
        for lexeme in ["BEAT", "WAVE", "CONDUIT", "CUP", "POINT"] {
            assert!(l.keys(lexeme).is_some(), "{lexeme}");
        }
        assert!(Lexicon::from_json(
            r#"{"gestures": [{"lexeme": "X", "keys": {"stroke": {"r_elbow": [1, 2]}}}]}"#
        )
        .unwrap_err()
        .contains("three angles"));
    }

    #[test]
    fn mirroring_reflects_the_motion_across_the_middle_plane() {
        let q = Quat::from_euler(EulerRot::ZXY, 0.4, 0.3, -0.5);
        let (name, m) = mirror("r_shoulder", q);
        assert_eq!(name, "l_shoulder");
        // a reflected vector rotated by the mirror = the reflection of the rotated vector
        let reflect = |v: Vec3| Vec3::new(-v.x, v.y, v.z);
        for v in [Vec3::X, Vec3::Y, Vec3::new(0.3, -0.2, 0.9)] {
            assert!((m * reflect(v) - reflect(q * v)).length() < 1e-5);
        }
    }
}
