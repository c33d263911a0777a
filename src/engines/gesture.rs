//! The gesture engine: `gesture` lexemes as arm motion defined by data. A bindings file
//! (`fixtures/bindings/gestures.json`, embedded as the default lexicon) gives for each lexeme the
//! right arm's local joint rotations at some of the gesture's sync points (Z, X, Y Euler degrees).
//! The arm is at those rotations exactly at those syncs, slerps between them, moves from where it
//! was at `start` to the first key and back by `end`. `LEFT_HAND` mirrors the keys onto the left
//! arm (across the body's middle plane), `BOTH_HANDS` plays both arms. Each lexeme's timing is
//! the default gesture timing with every span between its keys (and from rest and back) at least
//! as long as the hand needs to move it at a person's pace ([`HAND_SPEED`], [`JOINT_SPEED`]). A
//! lexeme the lexicon lacks is played with its timing only.

use std::sync::Arc;

use glam::{EulerRot, Quat};
use indexmap::IndexMap;

use crate::bml::{Behaviour, BehaviourKind, Param};
use crate::body::{Pose, Skeleton};
use crate::engine::{Engine, EngineError, Steering, Unit, Units};
use crate::engines::motion::{hands, min_jerk, sides};
use crate::engines::procedural::{mirror_name, mirror_rotation, Library, ProcUnit};
use crate::timing::SyncName;
use crate::timing::{DefaultTimingModels, TimingModel, TimingModels};
use crate::world::World;

/// The embedded default lexicon.
const DEFAULT: &str = include_str!("../../fixtures/bindings/gestures.json");

/// A lexeme's keys: (sync name, [(right-arm joint, rotation)]).
pub type GestureKeys = Vec<(String, Vec<(String, Quat)>)>;

/// What a binding plays: keys of the right arm, or a procedural unit (authored for the right arm)
/// with parameters.
#[derive(Debug, Clone)]
pub enum Bound {
    /// Rotations at sync points (shared by every unit that plays them).
    Keys(Arc<GestureKeys>),
    /// A unit of the procedural library and its parameters.
    Procedural(Arc<ProcUnit>, Vec<(String, f64)>),
}

/// One binding: a lexeme, an attribute filter, and what it plays.
#[derive(Debug, Clone)]
struct Binding {
    lexeme: String,
    /// (attribute, value) pairs the gesture must have: `mode`, or an extension attribute's local
    /// name.
    when: Vec<(String, String)>,
    bound: Bound,
    /// The least time each span between the keys (and from rest and back) takes by preference.
    paces: Vec<Pace>,
}

/// The fastest a hand moves by preference (m/s), at the peak of a minimum-jerk move between a
/// gesture's keys. Measured conversational gestures peak at about 1–2.5 m/s; 2 keeps a hand
/// that starts somewhere other than rest below the top of that range.
pub const HAND_SPEED: f64 = 2.0;

/// The fastest a gesture's joint turns by preference (rad/s), at the peak of a minimum-jerk
/// move: a wave's wrist swinging ±25° at 2.5 Hz peaks near 7 rad/s.
pub const JOINT_SPEED: f64 = 8.0;

/// The peak of a minimum-jerk move's speed relative to its mean: the largest slope of
/// 10u³ − 15u⁴ + 6u⁵, at u = ½.
const MIN_JERK_PEAK: f64 = 1.875;

/// The least time from one sync of a gesture to another for the hand to keep under
/// [`HAND_SPEED`] and every joint under [`JOINT_SPEED`] between the keys there.
#[derive(Debug, Clone)]
struct Pace {
    from: &'static str,
    to: &'static str,
    seconds: f64,
}

/// The paces of `keys` (right-arm rotations at syncs, rest at `start` and `end`), measured on
/// the default adult: for each pair of neighbouring keys, the minimum-jerk peak times the larger
/// of the fastest the right wrist moves per unit of interpolation over [`HAND_SPEED`] and the
/// largest angle a joint turns over [`JOINT_SPEED`].
fn paces(keys: &GestureKeys) -> Vec<Pace> {
    let adult = Skeleton::adult();
    let rest: &[(String, Quat)] = &[];
    // the sync points of a gesture, in order
    let mut chain: Vec<(&'static str, &[(String, Quat)])> = crate::bml::GESTURE_SYNCS
        .iter()
        .filter_map(|&sync| keys.iter().find(|k| k.0 == sync).map(|k| (sync, &k.1[..])))
        .collect();
    if chain.first().is_none_or(|k| k.0 != "start") {
        chain.insert(0, ("start", rest));
    }
    if chain.last().is_none_or(|k| k.0 != "end") {
        chain.push(("end", rest));
    }
    chain
        .windows(2)
        .map(|w| Pace {
            from: w[0].0,
            to: w[1].0,
            seconds: MIN_JERK_PEAK
                * (wrist_rate(&adult, w[0].1, w[1].1) / HAND_SPEED)
                    .max(largest_turn(w[0].1, w[1].1) / JOINT_SPEED),
        })
        .collect()
}

/// The rotation a key gives `joint` (rest if it leaves the joint out).
fn rot(key: &[(String, Quat)], joint: &str) -> Quat {
    key.iter()
        .find(|x| x.0 == joint)
        .map_or(Quat::IDENTITY, |x| x.1)
}

/// The largest angle (radians) a joint turns from the rotations `from` to `to` (joints left out
/// are at rest).
fn largest_turn(from: &[(String, Quat)], to: &[(String, Quat)]) -> f64 {
    (from.iter().chain(to))
        .map(|(j, _)| f64::from(rot(from, j).angle_between(rot(to, j))))
        .fold(0.0, f64::max)
}

/// The largest distance the right wrist moves per unit of a slerp from the rotations `from` to
/// `to` (joints left out are at rest), sampled at 64 steps (metres).
fn wrist_rate(skeleton: &Skeleton, from: &[(String, Quat)], to: &[(String, Quat)]) -> f64 {
    const STEPS: usize = 64;
    let Some(wrist) = skeleton.joint("r_wrist") else {
        return 0.0;
    };
    let joints: Vec<(usize, Quat, Quat)> = (from.iter().chain(to))
        .filter_map(|(name, _)| Some((skeleton.joint(name)?, rot(from, name), rot(to, name))))
        .collect();
    let at = |w: f32| {
        let mut pose = Pose::rest(skeleton);
        for &(j, a, b) in &joints {
            pose.rotate(j, a.slerp(b, w));
        }
        pose.joint_world(skeleton, wrist).0
    };
    (1..=STEPS)
        .map(|i| {
            let (u0, u1) = ((i - 1) as f32 / STEPS as f32, i as f32 / STEPS as f32);
            f64::from(at(u1).distance(at(u0))) * STEPS as f64
        })
        .fold(0.0, f64::max)
}

/// Gesture lexemes bound to keys or procedural units.
#[derive(Debug, Clone, Default)]
pub struct Lexicon {
    bindings: Vec<Binding>,
}

impl Lexicon {
    /// The default lexicon (BEAT, WAVE, CONDUIT, CUP, POINT as keys; HELLO as the procedural
    /// `wave` unit).
    pub fn default_lexicon() -> Lexicon {
        // read from its embedded JSON once per process, then copied
        static LEXICON: std::sync::LazyLock<Lexicon> = std::sync::LazyLock::new(|| {
            Lexicon::from_json(DEFAULT, &Library::default_library())
                .expect("the embedded gesture lexicon is valid")
        });
        LEXICON.clone()
    }

    /// Reads a bindings file: `{"gestures": [BINDING, …]}`, each binding a `lexeme`, an optional
    /// filter `"when": {ATTRIBUTE: VALUE}`, and either `"keys": {SYNC: {JOINT: [z, x, y]}}` or
    /// `"procedural": UNIT` (a unit of `library`) with optional `"parameters": {NAME: NUMBER}`.
    pub fn from_json(text: &str, library: &Library) -> Result<Lexicon, String> {
        let file: LexiconFile = crate::data::from_json(text)?;
        let mut bindings = Vec::new();
        for (i, g) in file.gestures.into_iter().enumerate() {
            let lexeme = g.lexeme;
            let bound = match (g.keys, g.procedural) {
                (Some(keys), None) => Bound::Keys(Arc::new(
                    key_rotations(keys).map_err(|e| format!("gestures[{i}] ({lexeme}): {e}"))?,
                )),
                (None, Some(name)) => {
                    let unit = library.get(&name).ok_or_else(|| {
                        format!("{lexeme}: no procedural unit '{name}' in the library")
                    })?;
                    let overrides: Vec<Param> = g
                        .parameters
                        .iter()
                        .map(|(k, x)| Param {
                            name: k.clone(),
                            value: x.to_string(),
                        })
                        .collect();
                    let params = unit
                        .parameters(&overrides)
                        .map_err(|e| format!("{lexeme}: {e}"))?;
                    Bound::Procedural(unit.clone(), params)
                }
                _ => {
                    return Err(format!(
                        "gestures[{i}] ({lexeme}): either \"keys\" or \"procedural\""
                    ))
                }
            };
            let paces = match &bound {
                Bound::Keys(k) => paces(k),
                Bound::Procedural(..) => Vec::new(),
            };
            bindings.push(Binding {
                lexeme,
                when: g.when.into_iter().collect(),
                bound,
                paces,
            });
        }
        Ok(Lexicon { bindings })
    }

    /// `first`'s bindings, then this lexicon's: for a lexeme both bind, `first`'s win.
    pub fn extended_by(mut self, first: Lexicon) -> Lexicon {
        let mut bindings = first.bindings;
        bindings.append(&mut self.bindings);
        Lexicon { bindings }
    }

    /// The keys of `lexeme` (its first binding without a filter, if that is keys).
    pub fn keys(&self, lexeme: &str) -> Option<&GestureKeys> {
        match &self
            .bindings
            .iter()
            .find(|b| b.lexeme == lexeme && b.when.is_empty())?
            .bound
        {
            Bound::Keys(k) => Some(k),
            Bound::Procedural(..) => None,
        }
    }

    /// What `behaviour` (a gesture) plays: the first binding of its lexeme whose filter it passes.
    pub fn find(&self, behaviour: &Behaviour) -> Option<&Bound> {
        self.binding(behaviour).map(|b| &b.bound)
    }

    fn binding(&self, behaviour: &Behaviour) -> Option<&Binding> {
        let BehaviourKind::Gesture(g) = &behaviour.kind else {
            return None;
        };
        let attr = |name: &str| -> Option<&str> {
            if name == "mode" {
                return g.mode.map(|m| m.as_str());
            }
            behaviour
                .foreign_attrs
                .iter()
                .find(|a| a.name == name)
                .map(|a| a.value.as_str())
        };
        self.bindings.iter().find(|b| {
            b.lexeme == g.lexeme && b.when.iter().all(|(k, v)| attr(k) == Some(v.as_str()))
        })
    }

    /// The joints that the bindings' keys rotate (procedural units not included).
    pub fn key_joints(&self) -> impl Iterator<Item = (&str, &str)> {
        self.bindings.iter().flat_map(|b| {
            let keys: &[(String, Vec<(String, Quat)>)] = match &b.bound {
                Bound::Keys(k) => k,
                Bound::Procedural(..) => &[],
            };
            keys.iter().flat_map(move |(_, joints)| {
                joints
                    .iter()
                    .map(move |(j, _)| (b.lexeme.as_str(), j.as_str()))
            })
        })
    }

    /// The lexemes some binding names, in order, once each.
    pub fn lexemes(&self) -> Vec<&str> {
        let mut out: Vec<&str> = Vec::new();
        for b in &self.bindings {
            if !out.contains(&b.lexeme.as_str()) {
                out.push(&b.lexeme);
            }
        }
        out
    }

    /// Whether some binding filters on the extension attribute `name`.
    fn filters_on(&self, name: &str) -> bool {
        self.bindings
            .iter()
            .any(|b| b.when.iter().any(|(k, _)| k == name))
    }
}

/// A bindings file as written (see [`Lexicon::from_json`]).
#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct LexiconFile {
    #[serde(default, rename = "description")]
    _description: crate::data::Note,
    gestures: Vec<BindingFile>,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct BindingFile {
    lexeme: String,
    #[serde(default)]
    when: IndexMap<String, String>,
    /// Sync → joint → `[z, x, y]` degrees.
    keys: Option<IndexMap<String, IndexMap<String, [f32; 3]>>>,
    procedural: Option<String>,
    #[serde(default)]
    parameters: IndexMap<String, f64>,
}

/// The rotations of bound keys, from `[z, x, y]` degrees (each a finite number).
fn key_rotations(
    keys: IndexMap<String, IndexMap<String, [f32; 3]>>,
) -> Result<GestureKeys, String> {
    let mut out = GestureKeys::new();
    for (sync, joints) in keys {
        let mut rot = Vec::new();
        for (joint, a) in joints {
            if !a.iter().all(|v| v.is_finite()) {
                return Err(format!(
                    "keys.{sync}.{joint}: three finite angles (z, x, y)"
                ));
            }
            let [z, x, y] = a.map(f32::to_radians);
            rot.push((joint, Quat::from_euler(EulerRot::ZXY, z, x, y)));
        }
        out.push((sync, rot));
    }
    Ok(out)
}

/// The left-arm twin of a right-arm joint and rotation (mirrored across the y-z plane).
pub fn mirror(joint: &str, q: Quat) -> (String, Quat) {
    (mirror_name(joint), mirror_rotation(q))
}

#[derive(Debug, Clone)]
enum GestureUnit {
    Keys {
        /// (sync, [(right-arm joint, rotation)]), as bound.
        keys: Arc<GestureKeys>,
        /// Mirrorings to play: `[false]` right arm, `[true]` left arm, both for both hands.
        sides: &'static [bool],
        /// The keys resolved against the skeleton, the sides and the unit's syncs, made on first
        /// use.
        compiled: Option<Compiled>,
    },
    Procedural {
        unit: Arc<ProcUnit>,
        params: Vec<(String, f64)>,
        /// Mirrorings to play: `[false]` right arm, `[true]` left arm, both for both hands.
        sides: &'static [bool],
    },
}

/// A unit's keys ready to play: the joints it moves, and per key the index of its sync and a
/// rotation per joint (identity where the key leaves a joint out).
#[derive(Debug, Clone)]
struct Compiled {
    joints: Vec<usize>,
    keys: Vec<(usize, Vec<Quat>)>,
}

fn compile(
    keys: &GestureKeys,
    sides: &[bool],
    skeleton: &Skeleton,
    syncs: &[(SyncName, f64)],
) -> Compiled {
    // the keys of the arms the unit moves: the right arm's as bound, the left's mirrored
    let side_keys: Vec<Vec<(String, Quat)>> = keys
        .iter()
        .map(|(_, k)| {
            sides
                .iter()
                .flat_map(|&left| {
                    k.iter().map(
                        move |(j, q)| {
                            if left {
                                mirror(j, *q)
                            } else {
                                (j.clone(), *q)
                            }
                        },
                    )
                })
                .collect()
        })
        .collect();
    let mut names: Vec<&str> = Vec::new();
    for k in &side_keys {
        for (j, _) in k {
            if !names.contains(&j.as_str()) && skeleton.joint(j).is_some() {
                names.push(j);
            }
        }
    }
    let joints = names.iter().filter_map(|n| skeleton.joint(n)).collect();
    let mut keys: Vec<(usize, Vec<Quat>)> = keys
        .iter()
        .zip(&side_keys)
        .filter_map(|((sync, _), k)| {
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
        if !matches!(behaviour.kind, BehaviourKind::Gesture(_)) {
            return None;
        }
        let Some(binding) = self.lexicon.binding(behaviour) else {
            return self.models.model(behaviour);
        };
        match &binding.bound {
            Bound::Procedural(unit, _) => Some(unit.timing()),
            // the default timing, with each span long enough for the hand to move unhurried
            Bound::Keys(_) => self.models.model(behaviour).map(|m| {
                (binding.paces.iter()).fold(m, |m, p| m.with_span_at_least(p.from, p.to, p.seconds))
            }),
        }
    }

    fn interprets(&self, _ns: &str, name: &str) -> bool {
        self.lexicon.filters_on(name)
    }

    fn unanimated(&self, behaviour: &Behaviour) -> Option<String> {
        let BehaviourKind::Gesture(g) = &behaviour.kind else {
            return None;
        };
        self.lexicon.find(behaviour).is_none().then(|| {
            format!(
                "gesture '{}': no binding moves lexeme '{}'{}; it plays its timing only (bound: {})",
                behaviour.id,
                g.lexeme,
                g.mode.map_or(String::new(), |m| format!(" with mode {}", m.as_str())),
                self.lexicon.lexemes().join(", ")
            )
        })
    }

    fn add(&mut self, unit: Unit<'_>) -> Result<(), EngineError> {
        let BehaviourKind::Gesture(g) = &unit.behaviour.kind else {
            return Err(EngineError("the gesture engine realizes <gesture>".into()));
        };
        let sides = sides(g.mode);
        let played = match self.lexicon.find(unit.behaviour) {
            Some(Bound::Procedural(p, params)) => GestureUnit::Procedural {
                unit: p.clone(),
                params: params.clone(),
                sides,
            },
            Some(Bound::Keys(k)) => GestureUnit::Keys {
                keys: k.clone(),
                sides,
                compiled: None,
            },
            None => GestureUnit::Keys {
                keys: Arc::default(),
                sides,
                compiled: None,
            },
        };
        self.units.add(unit, played);
        Ok(())
    }

    fn as_motion(&mut self) -> Option<&mut dyn crate::engine::Motion> {
        Some(self)
    }

    fn as_resources(&self) -> Option<&dyn crate::engine::Resources> {
        Some(self)
    }
}

impl crate::engine::Motion for GestureEngine {
    fn steers(&self, behaviour: &Behaviour, skeleton: &Skeleton) -> Option<Steering> {
        let BehaviourKind::Gesture(g) = &behaviour.kind else {
            return None;
        };
        let sides = sides(g.mode);
        match self.lexicon.find(behaviour)? {
            Bound::Procedural(unit, _) => Some(unit.steering(skeleton, sides)),
            Bound::Keys(keys) => {
                let mut joints: Vec<usize> = sides
                    .iter()
                    .flat_map(|&m| {
                        keys.iter()
                            .flat_map(|(_, js)| js.iter())
                            .filter_map(move |(j, _)| skeleton.joint_mirrored(j, m))
                    })
                    .collect();
                joints.sort_unstable();
                joints.dedup();
                Some(Steering {
                    joints,
                    kind: crate::engine::MotionKind::Kinematic,
                    additive: true,
                })
            }
        }
    }

    fn animate(&mut self, now: f64, skeleton: &Skeleton, _world: &World, pose: &mut Pose) {
        // a unit that has not started shows nothing yet
        for (syncs, u) in self.units.started_mut(now) {
            match u {
                GestureUnit::Keys {
                    keys,
                    sides,
                    compiled,
                } => {
                    let c = compiled.get_or_insert_with(|| compile(keys, sides, skeleton, syncs));
                    play_keys(c, syncs, now, pose);
                }
                GestureUnit::Procedural {
                    unit,
                    params,
                    sides,
                } => {
                    unit.play(syncs, now, params, sides, skeleton, pose);
                }
            }
        }
    }
}

impl crate::engine::Resources for GestureEngine {
    fn resources(&self, behaviour: &Behaviour) -> &'static [&'static str] {
        match &behaviour.kind {
            BehaviourKind::Gesture(g) => hands(g.mode),
            _ => &[],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bml::Mode;
    use glam::Vec3;

    /// A lexeme whose keys barely move the hand keeps the default timing; one that raises the
    /// arm gets a preparation as long as the hand needs at [`HAND_SPEED`], and a wrist swing as
    /// long as the joint needs at [`JOINT_SPEED`].
    #[test]
    fn a_lexeme_is_paced_by_how_far_its_keys_move_the_hand() {
        let lib = Library::default_library();
        let engine = |json: &str| GestureEngine::new(Lexicon::from_json(json, &lib).unwrap());
        let gesture = |lexeme: &str| {
            let src = format!(
                r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="b"><gesture id="g" lexeme="{lexeme}"/></bml>"#
            );
            crate::bml::load(&src).unwrap().block.behaviours.remove(0)
        };
        let at = |m: &TimingModel, k: &str| m.keys[m.key(k).unwrap()].at;
        let still = engine(
            r#"{"gestures": [{"lexeme": "X", "keys": {"stroke": {"r_wrist": [0, 0, 1]}}}]}"#,
        );
        let m = still.timing(&gesture("X")).unwrap();
        assert_eq!(
            m.keys,
            DefaultTimingModels::default()
                .model(&gesture("X"))
                .unwrap()
                .keys
        );
        // the arm forward and up: the wrist sweeps an arc of the arm's length (0.55 m) through
        // 90°, about 0.86 m per unit of the slerp at its fastest
        let up = engine(
            r#"{"gestures": [{"lexeme": "X", "keys": {"ready": {"r_shoulder": [0, -90, 0]}, "strokeStart": {"r_shoulder": [0, -90, 0], "r_wrist": [0, 0, 60]}}}]}"#,
        );
        let m = up.timing(&gesture("X")).unwrap();
        let rate = wrist_rate(&Skeleton::adult(), &[], &up.lexicon.keys("X").unwrap()[0].1);
        assert!((0.7..1.0).contains(&rate), "{rate}");
        assert!((at(&m, "ready") - MIN_JERK_PEAK * rate / HAND_SPEED).abs() < 1e-9);
        // 60° at the wrist between ready and strokeStart
        let swing = MIN_JERK_PEAK * 60f64.to_radians() / JOINT_SPEED;
        assert!((at(&m, "strokeStart") - at(&m, "ready") - swing).abs() < 1e-6);
        m.check().unwrap();
    }

    #[test]
    fn the_default_lexicon_has_the_gestures_the_issue_names() {
        let l = Lexicon::default_lexicon();
        for lexeme in ["BEAT", "WAVE", "CONDUIT", "CUP", "POINT"] {
            assert!(l.keys(lexeme).is_some(), "{lexeme}");
        }
        let lib = Library::default_library();
        let bad = |j: &str| Lexicon::from_json(j, &lib).unwrap_err();
        assert!(
            bad(r#"{"gestures": [{"lexeme": "X", "keys": {"stroke": {"r_elbow": [1, 2]}}}]}"#)
                .starts_with("gestures[0].keys.stroke.r_elbow: invalid length 2")
        );
        assert!(bad(r#"{"gestures": [{"lexeme": "X", "kyes": {}}]}"#)
            .starts_with("gestures[0].kyes: unknown field"));
        assert!(
            bad(r#"{"gestures": [{"lexeme": "X", "procedural": "nope"}]}"#)
                .contains("no procedural unit 'nope'")
        );
        assert!(bad(
            r#"{"gestures": [{"lexeme": "X", "procedural": "wave", "parameters": {"speed": 2}}]}"#
        )
        .contains("no parameter 'speed'"));
        assert!(bad(r#"{"gestures": [{"lexeme": "X"}]}"#).contains("either"));
        assert!(matches!(
            l.find(&gesture("HELLO", None)),
            Some(Bound::Procedural(..))
        ));
    }

    fn gesture(lexeme: &str, mode: Option<Mode>) -> Behaviour {
        crate::bml::load(&format!(
            r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" xmlns:x="urn:x" id="b"><gesture id="g" lexeme="{lexeme}"{}{}/></bml>"#,
            mode.map_or(String::new(), |m| format!(r#" mode="{}""#, m.as_str())),
            if lexeme == "STYLED" { r#" x:style="big""# } else { "" }
        ))
        .unwrap()
        .block
        .behaviours
        .remove(0)
    }

    #[test]
    fn bindings_pick_by_lexeme_and_attribute_filter_in_file_order() {
        let l = Lexicon::from_json(
            r#"{"gestures": [
                {"lexeme": "B", "when": {"mode": "LEFT_HAND"}, "procedural": "lift"},
                {"lexeme": "B", "keys": {"stroke": {"r_elbow": [0, 0, 10]}}},
                {"lexeme": "STYLED", "when": {"style": "big"}, "procedural": "wave", "parameters": {"cycles": 5}},
                {"lexeme": "STYLED", "procedural": "wave"}
            ]}"#,
            &Library::default_library(),
        )
        .unwrap();
        assert!(matches!(
            l.find(&gesture("B", Some(Mode::LeftHand))),
            Some(Bound::Procedural(u, _)) if u.name == "lift"
        ));
        assert!(matches!(l.find(&gesture("B", None)), Some(Bound::Keys(_))));
        assert!(matches!(
            l.find(&gesture("B", Some(Mode::RightHand))),
            Some(Bound::Keys(_))
        ));
        match l.find(&gesture("STYLED", None)) {
            Some(Bound::Procedural(u, p)) => {
                assert_eq!(u.name, "wave");
                assert!(p.contains(&("cycles".to_string(), 5.0)));
            }
            other => panic!("{other:?}"),
        }
        assert!(l.find(&gesture("NONE", None)).is_none());
        assert!(l.filters_on("style") && !l.filters_on("lexeme"));
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
