//! The engine layer: what an engine is to the realizer (the `Engine` trait), the registry that
//! maps behaviour kinds to engines, and what engines produce (actions for the runtime, frame
//! output). Timing models, the scheduler's view of an engine, are in [`crate::timing`], a layer
//! below both.

mod registry;

use std::collections::BTreeMap;
use std::fmt;
use std::sync::Arc;

pub use registry::{EngineId, KindKey, Registry};

use crate::bml::{Behaviour, TrajectoryType};
use crate::body::{Pose, Skeleton};
use crate::feedback::Feedback;
use crate::timing::SyncName;
use crate::timing::TimingModel;
use crate::world::World;

/// One behaviour of one block: how the runtime and the engines name a plan unit.
#[derive(Debug, Clone, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct UnitKey {
    /// Block id.
    pub block: crate::bml::Id,
    /// Behaviour id.
    pub behaviour: crate::bml::Id,
}

impl UnitKey {
    /// The key of `block:behaviour` (ids are shared, not copied, when given as `bml::Id`s).
    pub fn new(block: impl Into<crate::bml::Id>, behaviour: impl Into<crate::bml::Id>) -> Self {
        UnitKey {
            block: block.into(),
            behaviour: behaviour.into(),
        }
    }
}

impl fmt::Display for UnitKey {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}", self.block, self.behaviour)
    }
}

/// How a motion unit moves its joints.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MotionKind {
    /// It sets or changes joint rotations directly.
    Kinematic,
    /// It applies torques to a physically simulated body (mixed dynamics).
    Physical,
}

/// What a motion unit steers: its joints, how, and whether it layers over other units.
#[derive(Debug, Clone, PartialEq)]
pub struct Steering {
    /// Joints whose rotation it sets or changes (the root joint also for its translation), in
    /// the skeleton's joint order.
    pub joints: Vec<usize>,
    /// Kinematic or physical.
    pub kind: MotionKind,
    /// Whether it adds to what other units set (a layer) rather than replacing it.
    pub additive: bool,
}

impl Steering {
    /// Kinematic steering of the joints of `skeleton` named `names` (unknown names are left out).
    pub fn kinematic<'a>(
        skeleton: &Skeleton,
        names: impl IntoIterator<Item = &'a str>,
        additive: bool,
    ) -> Steering {
        let mut joints: Vec<usize> = names
            .into_iter()
            .filter_map(|n| skeleton.joint(n))
            .collect();
        joints.sort_unstable();
        joints.dedup();
        Steering {
            joints,
            kind: MotionKind::Kinematic,
            additive,
        }
    }
}

/// Named numeric parameters of a unit, in a fixed order: `(name, value)`.
pub type Params = Vec<(String, f64)>;

/// `defaults` with the `<parameter>`s a behaviour gives applied: an unknown name or a value that is
/// not a finite number is refused, naming `owner` and the parameters it has.
pub fn named_params(
    owner: &str,
    defaults: impl IntoIterator<Item = (impl Into<String>, f64)>,
    given: &[crate::bml::Param],
) -> Result<Params, String> {
    let mut params: Params = defaults.into_iter().map(|(n, v)| (n.into(), v)).collect();
    for p in given {
        let Some(slot) = params.iter_mut().find(|x| x.0 == p.name) else {
            let known: Vec<&str> = params.iter().map(|x| x.0.as_str()).collect();
            return Err(format!(
                "{owner} has no parameter '{}' (it has {known:?})",
                p.name
            ));
        };
        slot.1 = p
            .value
            .trim()
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| format!("parameter '{}' = '{}' is not a number", p.name, p.value))?;
    }
    Ok(params)
}

/// [`Engine::set_parameter`] for a unit `key` whose parameters are `params` (of `owner`), if it
/// is running: a finite value for a name it has.
pub fn set_named_param(
    key: &UnitKey,
    owner: &str,
    params: Option<&mut Params>,
    name: &str,
    value: f64,
) -> Result<Option<Vec<f64>>, EngineError> {
    let params = params.ok_or_else(|| EngineError(format!("{key} is not running")))?;
    let slot = params
        .iter_mut()
        .find(|p| p.0 == name)
        .ok_or_else(|| EngineError(format!("{key}: {owner} has no parameter '{name}'")))?;
    if !value.is_finite() {
        return Err(EngineError(format!(
            "{key}: {name} = {value} is not finite"
        )));
    }
    slot.1 = value;
    Ok(None)
}

/// The value of parameter `name` among `params`.
pub fn named_param(params: &[(String, f64)], name: &str) -> Option<f64> {
    params.iter().find(|p| p.0 == name).map(|p| p.1)
}

/// A scheduled behaviour handed to its engine: the behaviour and its sync points' global times
/// (in sync order; a persistent end is infinite).
#[derive(Debug, Clone)]
pub struct Unit<'a> {
    /// Which unit.
    pub key: &'a UnitKey,
    /// The behaviour as written.
    pub behaviour: &'a Behaviour,
    /// (sync name, global time) in sync order; the unit's own list, which [`Units::add`] keeps
    /// without copying it.
    pub syncs: SyncTimes,
    /// The world as it is when the unit is added (targets).
    pub world: &'a World,
}

/// A change of a parameter of a running behaviour over time (BMLA `parametervaluechange`).
#[derive(Debug, Clone, PartialEq)]
pub struct ParameterChange {
    /// The behaviour whose parameter changes.
    pub target: UnitKey,
    /// Parameter name, e.g. `volume`.
    pub param: String,
    /// Start value; `None` reads the target's value when the change starts.
    pub initial: Option<f64>,
    /// Value reached at `end` and held afterwards.
    pub target_value: f64,
    /// Linear or instant.
    pub kind: TrajectoryType,
    /// Global time the change starts.
    pub start: f64,
    /// Global time the target value is reached.
    pub end: f64,
    /// The behaviour that asked for the change (for warnings).
    pub by: UnitKey,
}

impl ParameterChange {
    /// The value at global time `t` starting from `from`: linear or instant, held after `end`.
    pub fn value_at(&self, from: f64, t: f64) -> f64 {
        match self.kind {
            TrajectoryType::Instant => self.target_value,
            TrajectoryType::Linear => {
                let span = self.end - self.start;
                let alpha = if span > 0.0 {
                    ((t - self.start) / span).clamp(0.0, 1.0)
                } else {
                    1.0
                };
                from + alpha * (self.target_value - from)
            }
        }
    }
}

/// What an engine asks the runtime to do (control behaviours act on blocks and other engines).
#[derive(Debug, Clone, PartialEq)]
pub enum Action {
    /// Interrupt behaviours of block `target`: those in `include` (all if empty) except `exclude`.
    Interrupt {
        /// The behaviour asking (for warnings).
        by: UnitKey,
        /// Block to interrupt.
        target: String,
        /// Behaviours to interrupt (empty: all).
        include: Vec<String>,
        /// Behaviours to spare.
        exclude: Vec<String>,
    },
    /// Activate the pre-planned block `target`.
    Activate {
        /// The behaviour asking (for warnings).
        by: UnitKey,
        /// Block to activate.
        target: String,
    },
    /// Change a parameter of another behaviour over time.
    ChangeParameter(ParameterChange),
}

/// What one engine shows of one running unit in a frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Output {
    /// The unit (shared with the engine: no copy per frame).
    pub key: Arc<UnitKey>,
    /// The engine's name.
    pub engine: &'static str,
    /// Progress through the unit, 0 at start and 1 at end.
    pub progress: f64,
    /// Current parameter values (e.g. `volume` of a speech).
    pub params: Vec<(&'static str, f64)>,
}

/// A character's body at a moment.
#[derive(Debug, Clone, PartialEq)]
pub struct CharacterPose {
    /// The character (`None`: the default character).
    pub character: Option<String>,
    /// Its pose (joint order of the character's skeleton).
    pub pose: Pose,
}

/// Everything the realizer produced for one moment: engine output, each character's pose, and the
/// feedback sent since the previous frame.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Frame {
    /// Global time of the frame.
    pub time: f64,
    /// One entry per running unit that shows something.
    pub outputs: Vec<Output>,
    /// The pose of every character, in character order.
    pub poses: Vec<CharacterPose>,
    /// Feedback sent since the previous frame, in order.
    pub feedback: Vec<Feedback>,
}

/// Why an engine refused a unit or a parameter.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct EngineError(pub String);

/// An engine realizes the behaviour kinds it is registered for. The runtime tells it which
/// units to play and when their sync points pass; it answers with timing models, interruption
/// timing, parameters, frame output and actions.
pub trait Engine {
    /// A short name (frame output, logs).
    fn name(&self) -> &'static str;

    /// The timing model of `behaviour`, or `None` if this engine cannot realize it.
    fn timing(&self, behaviour: &Behaviour) -> Option<TimingModel>;

    /// Behaviours of the same exclusive group cannot run at once (gaze, posture; the
    /// replacement groups of procedural units).
    fn exclusive_group(&self, _behaviour: &Behaviour) -> Option<&str> {
        None
    }

    /// Body resources the behaviour occupies (e.g. `left_hand`, `voice`): a chunked block
    /// co-articulates with the block before it where they share one (the earlier behaviour skips
    /// the rest of its retraction).
    fn resources(&self, _behaviour: &Behaviour) -> &'static [&'static str] {
        &[]
    }

    /// Whether the engine interprets the extension attribute `{ns}name` on its behaviours (the
    /// runtime warns CUSTOM_ATTRIBUTE_NOT_SUPPORTED for the others).
    fn interprets(&self, _ns: &str, _name: &str) -> bool {
        false
    }

    /// Why this engine plays `behaviour` with its timing only, moving nothing (a lexeme no
    /// binding defines, say), or `None` if it moves the body. The runtime warns
    /// (LEXEME_NOT_SUPPORTED) once when such a behaviour starts, and `bmlr validate` warns too.
    fn unanimated(&self, _behaviour: &Behaviour) -> Option<String> {
        None
    }

    /// Takes a scheduled unit into the engine's plan.
    fn add(&mut self, unit: Unit<'_>) -> Result<(), EngineError>;

    /// Forgets a unit (it ended, was interrupted before starting, or its block was removed).
    fn remove(&mut self, key: &UnitKey);

    /// The sync point `sync` of `key` passed at global time `time`. Control engines act here.
    fn sync_passed(&mut self, _key: &UnitKey, _sync: &str, _time: f64, _actions: &mut Vec<Action>) {
    }

    /// Interrupts a running unit at global time `now`: the new global times of its syncs (same
    /// length as `syncs`; passed syncs keep theirs). The default ends motion gracefully: syncs up
    /// to `relax` move to `now` and the retraction after it keeps its length; a unit already past
    /// `relax`, or without one, ends at once.
    fn interrupt(&mut self, _key: &UnitKey, now: f64, syncs: &[(SyncName, f64)]) -> Vec<f64> {
        relax_now(now, syncs)
    }

    /// Whether `behaviour` can be realized with these sync times: the default checks
    /// them against the engine's timing model — sync order, a duration within the model's bounds,
    /// a rigid behaviour's internal distances. Called when pegs move without rescheduling.
    fn check_timing(&self, behaviour: &Behaviour, syncs: &[(SyncName, f64)]) -> Result<(), String> {
        match self.timing(behaviour) {
            Some(model) => model.admits(syncs),
            None => Ok(()),
        }
    }

    /// The unit's sync times moved (an anticipator's prediction changed): new global times,
    /// in sync order. Passed syncs keep theirs.
    fn retime(&mut self, _key: &UnitKey, _syncs: &[(SyncName, f64)]) {}

    /// Number of units the engine holds (bounded-memory checks).
    fn len(&self) -> usize;

    /// Whether the engine holds no unit.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Plays every unit at global time `now` into `frame`.
    fn play(&mut self, _now: f64, _frame: &mut Frame) {}

    /// Moves the body: applies the units running at `now` to `pose` (joint rotations on top of
    /// what earlier engines set), with targets from `world`. Engines that move nothing keep the
    /// default.
    fn animate(&mut self, _now: f64, _skeleton: &Skeleton, _world: &World, _pose: &mut Pose) {}

    /// The joints a unit for `behaviour` steers on `skeleton`, how, and whether additively;
    /// `None` for behaviours that move no joints.
    fn steers(&self, _behaviour: &Behaviour, _skeleton: &Skeleton) -> Option<Steering> {
        None
    }

    /// The animation predictor's part: writes what this engine's *predictable* units
    /// (whose motion is a function of time alone, such as keyframes and procedural units) will
    /// have set at global time `t` into `pose`, without changing any state. Returns whether any
    /// of its units is running then. Engines whose motion depends on the world or on the past
    /// keep the default (nothing predictable).
    fn predict(&self, _t: f64, _skeleton: &Skeleton, _world: &World, _pose: &mut Pose) -> bool {
        false
    }

    /// Global times at which this engine needs the predicted pose for its frame at `now` (a
    /// transition's end); the runtime then calls [`predicted`](Engine::predicted) before
    /// [`animate`](Engine::animate).
    fn prediction_times(&self, _now: f64) -> Vec<f64> {
        Vec::new()
    }

    /// The predicted poses (rest pose plus every engine's [`predict`](Engine::predict)) at the
    /// times [`prediction_times`](Engine::prediction_times) asked for.
    fn predicted(&mut self, _poses: Vec<(f64, Pose)>) {}

    /// Current value of parameter `name` of unit `key`.
    fn parameter(&self, _key: &UnitKey, _name: &str) -> Option<f64> {
        None
    }

    /// Sets parameter `name` of a running unit at global time `now`. A parameter that changes
    /// timing (a speech's `rate`) returns the unit's new sync times (as for
    /// [`interrupt`](Engine::interrupt)); others return `None`.
    fn set_parameter(
        &mut self,
        key: &UnitKey,
        name: &str,
        _value: f64,
        _now: f64,
    ) -> Result<Option<Vec<f64>>, EngineError> {
        Err(EngineError(format!(
            "{key} has no parameter '{name}' that can change while it runs"
        )))
    }
}

/// The units an engine holds, each with its key (shared with frame outputs) and current global
/// sync times, in the order of their start times (ties: the order they were added). So frames
/// are deterministic, a unit that starts later is applied later (and wins where two overlap),
/// and the units that have started at some moment come first: a frame looks at those only.
/// Kept in a map ordered by start, so that adding one of thousands of units (a chain of 10 000
/// gestures, or several such blocks whose units interleave) costs a logarithm, not a shift of
/// the rest. A unit is found by key from the front: the units asked for (running, ending) are
/// the ones that have started, which come first.
#[derive(Debug, Clone)]
pub struct Units<T> {
    units: BTreeMap<Order, Held<T>>,
    /// How many units were ever added (the tie-break of equal starts).
    added: u64,
}

/// A unit's place: its start time (a unit without syncs sorts last), then when it was added.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Order {
    start: f64,
    added: u64,
}

impl Eq for Order {}

impl PartialOrd for Order {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Order {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.start
            .total_cmp(&other.start)
            .then(self.added.cmp(&other.added))
    }
}

#[derive(Debug, Clone)]
struct Held<T> {
    key: Arc<UnitKey>,
    syncs: SyncTimes,
    data: T,
}

impl<T> Held<T> {
    fn start(&self) -> f64 {
        self.syncs.first().map_or(f64::INFINITY, |s| s.1)
    }
}

/// A unit's (sync, global time) list, in sync order.
pub type SyncTimes = Vec<(SyncName, f64)>;

impl<T> Default for Units<T> {
    fn default() -> Self {
        Units {
            units: BTreeMap::new(),
            added: 0,
        }
    }
}

impl<T> Units<T> {
    /// No units.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds a unit with the engine's own data `data`.
    pub fn add(&mut self, unit: Unit<'_>, data: T) {
        let held = Held {
            key: Arc::new(unit.key.clone()),
            syncs: unit.syncs,
            data,
        };
        self.insert(held);
    }

    fn insert(&mut self, held: Held<T>) {
        self.added += 1;
        let order = Order {
            start: held.start(),
            added: self.added,
        };
        self.units.insert(order, held);
    }

    /// Where the unit `key` is.
    fn find(&self, key: &UnitKey) -> Option<Order> {
        self.units
            .iter()
            .find(|(_, u)| *u.key == *key)
            .map(|(order, _)| *order)
    }

    /// Forgets a unit.
    pub fn remove(&mut self, key: &UnitKey) {
        if let Some(order) = self.find(key) {
            self.units.remove(&order);
        }
    }

    /// New sync times for a unit.
    pub fn retime(&mut self, key: &UnitKey, times: &[f64]) {
        let Some(order) = self.find(key) else {
            return;
        };
        let Some(mut held) = self.units.remove(&order) else {
            return;
        };
        for (s, t) in held.syncs.iter_mut().zip(times) {
            s.1 = *t;
        }
        self.insert(held);
    }

    /// A unit's data.
    pub fn get(&self, key: &UnitKey) -> Option<&T> {
        self.units
            .values()
            .find(|u| *u.key == *key)
            .map(|u| &u.data)
    }

    /// A unit's sync times and data.
    pub fn get_mut(&mut self, key: &UnitKey) -> Option<(&mut SyncTimes, &mut T)> {
        self.units
            .values_mut()
            .find(|u| *u.key == *key)
            .map(|u| (&mut u.syncs, &mut u.data))
    }

    /// How many units.
    pub fn len(&self) -> usize {
        self.units.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.units.is_empty()
    }

    /// Every unit's sync times and data, in start order.
    pub fn all(&self) -> impl Iterator<Item = (&SyncTimes, &T)> + '_ {
        self.units.values().map(|u| (&u.syncs, &u.data))
    }

    /// Every unit's sync times and data, the data mutable (engines that compile a unit lazily).
    pub fn all_mut(&mut self) -> impl Iterator<Item = (&SyncTimes, &mut T)> + '_ {
        self.units.values_mut().map(|u| (&u.syncs, &mut u.data))
    }

    /// The units that have started by `now` (start ≤ now), in start order, the data mutable:
    /// what a frame at `now` can show.
    pub fn started_mut(&mut self, now: f64) -> impl Iterator<Item = (&SyncTimes, &mut T)> + '_ {
        self.units
            .values_mut()
            .take_while(move |u| u.start() <= now)
            .map(|u| (&u.syncs, &mut u.data))
    }

    /// The units running at `now` (start ≤ now < end) with their progress (0 at start, 1 at end;
    /// 0 for a unit without a finite end), in start order.
    pub fn running(&self, now: f64) -> impl Iterator<Item = (&Arc<UnitKey>, f64, &T)> + '_ {
        let started = self.units.values().take_while(move |u| u.start() <= now);
        started.filter_map(move |u| {
            let (start, end) = (u.syncs.first()?.1, u.syncs.last()?.1);
            if now >= end {
                return None;
            }
            let p = if end.is_finite() {
                (now - start) / (end - start)
            } else {
                0.0
            };
            Some((&u.key, p.clamp(0.0, 1.0), &u.data))
        })
    }
}

/// `Engine::retime` and `Engine::len` for an engine that keeps its units in `self.units`
/// ([`Units`]).
#[macro_export]
macro_rules! units_retime_len {
    () => {
        fn retime(
            &mut self,
            key: &$crate::engine::UnitKey,
            syncs: &[($crate::timing::SyncName, f64)],
        ) {
            let times: Vec<f64> = syncs.iter().map(|s| s.1).collect();
            self.units.retime(key, &times);
        }

        fn len(&self) -> usize {
            self.units.len()
        }
    };
}

/// `Engine::remove` for an engine that keeps its units in `self.units`.
#[macro_export]
macro_rules! units_remove {
    () => {
        fn remove(&mut self, key: &$crate::engine::UnitKey) {
            self.units.remove(key);
        }
    };
}

/// `Engine::play` showing each running unit's progress under the engine name `$name` (or, with
/// `field f`, the name in the engine's field `f`).
#[macro_export]
macro_rules! units_play {
    (field $f:ident) => {
        fn play(&mut self, now: f64, frame: &mut $crate::engine::Frame) {
            for (key, progress, _) in self.units.running(now) {
                frame.outputs.push($crate::engine::Output {
                    key: key.clone(),
                    engine: self.$f,
                    progress,
                    params: Vec::new(),
                });
            }
        }
    };
    ($name:expr) => {
        fn play(&mut self, now: f64, frame: &mut $crate::engine::Frame) {
            for (key, progress, _) in self.units.running(now) {
                frame.outputs.push($crate::engine::Output {
                    key: key.clone(),
                    engine: $name,
                    progress,
                    params: Vec::new(),
                });
            }
        }
    };
}

/// `Engine::interrupt` with the timing `$how` ([`relax_now`] or [`stop_now`]), keeping the
/// engine's own copy of the unit's times.
#[macro_export]
macro_rules! units_interrupt {
    ($how:path) => {
        fn interrupt(
            &mut self,
            key: &$crate::engine::UnitKey,
            now: f64,
            syncs: &[($crate::timing::SyncName, f64)],
        ) -> Vec<f64> {
            let times = $how(now, syncs);
            self.units.retime(key, &times);
            times
        }
    };
}

/// Graceful interruption timing (see [`Engine::interrupt`]).
pub fn relax_now(now: f64, syncs: &[(SyncName, f64)]) -> Vec<f64> {
    let relax = syncs
        .iter()
        .position(|(s, _)| s == "relax")
        .filter(|&r| syncs[r].1 > now);
    match relax {
        Some(r) => {
            let shift = syncs[r].1 - now;
            syncs
                .iter()
                .enumerate()
                .map(|(i, &(_, t))| {
                    if t <= now {
                        t
                    } else if i <= r {
                        now
                    } else {
                        (t - shift).max(now)
                    }
                })
                .collect()
        }
        None => stop_now(now, syncs),
    }
}

/// Immediate interruption timing: every sync still ahead moves to `now` (speech, audio).
pub fn stop_now(now: f64, syncs: &[(SyncName, f64)]) -> Vec<f64> {
    syncs.iter().map(|&(_, t)| t.min(now)).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn syncs(v: &[(&'static str, f64)]) -> Vec<(SyncName, f64)> {
        v.iter()
            .map(|&(s, t)| (crate::bml::Id::new_static(s), t))
            .collect()
    }

    #[test]
    fn graceful_interrupt_goes_to_relax_now_and_keeps_the_retraction() {
        let s = syncs(&[
            ("start", 0.0),
            ("ready", 1.0),
            ("stroke", 2.0),
            ("relax", 3.0),
            ("end", 4.5),
        ]);
        assert_eq!(relax_now(1.5, &s), [0.0, 1.0, 1.5, 1.5, 3.0]);
        // past relax: ends at once
        assert_eq!(relax_now(3.5, &s), [0.0, 1.0, 2.0, 3.0, 3.5]);
        // no relax sync: stops
        let se = syncs(&[("start", 0.0), ("end", 4.0)]);
        assert_eq!(relax_now(1.0, &se), [0.0, 1.0]);
        assert_eq!(stop_now(1.0, &s), [0.0, 1.0, 1.0, 1.0, 1.0]);
    }

    #[test]
    fn named_parameters_take_given_values_and_refuse_unknown_names_and_non_numbers() {
        let given = |n: &str, v: &str| crate::bml::Param {
            name: n.into(),
            value: v.into(),
        };
        let defaults = [("a", 1.0), ("b", 2.0)];
        let p = named_params("unit 'u'", defaults, &[given("b", " 5 ")]).unwrap();
        assert_eq!(p, [("a".to_string(), 1.0), ("b".to_string(), 5.0)]);
        let e = named_params("unit 'u'", defaults, &[given("c", "1")]).unwrap_err();
        assert_eq!(e, r#"unit 'u' has no parameter 'c' (it has ["a", "b"])"#);
        let e = named_params("unit 'u'", defaults, &[given("a", "inf")]).unwrap_err();
        assert_eq!(e, "parameter 'a' = 'inf' is not a number");
        let key = UnitKey::new("b", "u");
        let mut p = p;
        assert_eq!(set_named_param(&key, "u", Some(&mut p), "a", 7.0), Ok(None));
        assert_eq!(named_param(&p, "a"), Some(7.0));
        let err = |r: Result<Option<Vec<f64>>, EngineError>| r.unwrap_err().0;
        assert_eq!(
            err(set_named_param(&key, "u", None, "a", 1.0)),
            "b:u is not running"
        );
        assert_eq!(
            err(set_named_param(&key, "u", Some(&mut p), "z", 1.0)),
            "b:u: u has no parameter 'z'"
        );
        assert_eq!(
            err(set_named_param(&key, "u", Some(&mut p), "a", f64::NAN)),
            "b:u: a = NaN is not finite"
        );
        assert_eq!(
            named_param(&p, "a"),
            Some(7.0),
            "refused values change nothing"
        );
    }

    #[test]
    fn parameter_trajectories_follow_s63_to_s65() {
        let mut c = ParameterChange {
            target: UnitKey::new("b", "s"),
            param: "volume".into(),
            initial: Some(0.0),
            target_value: 100.0,
            kind: TrajectoryType::Linear,
            start: 1.0,
            end: 3.0,
            by: UnitKey::new("b", "p"),
        };
        assert_eq!(c.value_at(0.0, 1.0), 0.0);
        assert_eq!(c.value_at(0.0, 2.5), 75.0);
        assert_eq!(c.value_at(0.0, 9.0), 100.0); // held after the end
        c.kind = TrajectoryType::Instant;
        assert_eq!(c.value_at(0.0, 1.0), 100.0);
    }
}
