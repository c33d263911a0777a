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

use crate::character::body::{Pose, Skeleton};
use crate::engines::interface::{Engine, EngineError, Steering, Unit, Units};
use crate::engines::motion::{hands, min_jerk, sides};
use crate::engines::procedural::{mirror_name, mirror_rotation, Library, ProcUnit};
use crate::language::bml::{Behaviour, BehaviourKind, Param};
use crate::planning::timing::SyncName;
use crate::planning::timing::{DefaultTimingModels, TimingModel, TimingModels};
use crate::world::World;

mod pace;
use pace::{paces, Pace};
pub use pace::{HAND_SPEED, JOINT_SPEED};

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
    crate::units_interrupt!(crate::engines::interface::relax_now);

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

    fn as_motion(&mut self) -> Option<&mut dyn crate::engines::interface::Motion> {
        Some(self)
    }

    fn as_resources(&self) -> Option<&dyn crate::engines::interface::Resources> {
        Some(self)
    }
}

impl crate::engines::interface::Motion for GestureEngine {
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
                    kind: crate::engines::interface::MotionKind::Kinematic,
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

impl crate::engines::interface::Resources for GestureEngine {
    fn resources(&self, behaviour: &Behaviour) -> &'static [&'static str] {
        match &behaviour.kind {
            BehaviourKind::Gesture(g) => hands(g.mode),
            _ => &[],
        }
    }
}

#[cfg(test)]
mod tests;
