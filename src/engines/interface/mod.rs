//! The engine layer: what an engine is to the realizer, the registry that maps behaviour kinds to
//! engines, and what engines produce. The [`Engine`] trait is the narrow core every engine
//! implements (its timing model; adding, retiming, interrupting and removing a unit; playing);
//! what only some engines do is in the capability traits of [`capabilities`] (moving the body,
//! predicting it, parameters, body resources, control actions), which an engine offers through
//! the `as_…` methods of its core. Timing models, the scheduler's view of an engine, are in
//! [`crate::planning::timing`], a layer below both. `docs/engines.md` shows a complete engine written
//! outside the crate.

pub mod capabilities;
mod frame;
mod params;
mod registry;
mod units;

use std::fmt;

pub use capabilities::{
    Action, Attend, Attention, BalanceReading, Control, Expression, Motion, MotionKind, Parameters,
    Physics, Prediction, Resources, Revising, Revision, Sound, Speaking, Steering, Streams, Travel,
};
pub use frame::{CharacterPose, Frame, Output};
pub use params::{named_param, named_params, set_named_param, ParameterChange, Params};
pub use registry::{EngineId, KindKey, Registry};
pub use units::{SyncTimes, Units};

use crate::language::bml::Behaviour;
use crate::planning::timing::SyncName;
use crate::planning::timing::TimingModel;
use crate::world::World;

/// One behaviour of one block: how the runtime and the engines name a plan unit.
#[derive(Debug, Clone, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct UnitKey {
    /// Block id.
    pub block: crate::language::bml::Id,
    /// Behaviour id.
    pub behaviour: crate::language::bml::Id,
}

impl UnitKey {
    /// The key of `block:behaviour` (ids are shared, not copied, when given as `bml::Id`s).
    pub fn new(
        block: impl Into<crate::language::bml::Id>,
        behaviour: impl Into<crate::language::bml::Id>,
    ) -> Self {
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

/// Why an engine refused a unit or a parameter.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct EngineError(pub String);

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

/// An engine realizes the behaviour kinds it is registered for. The runtime hands it scheduled
/// units, tells it when their times move, interrupts them, asks it to play each frame and
/// removes units that ended. Only [`name`](Engine::name), [`timing`](Engine::timing),
/// [`add`](Engine::add), [`remove`](Engine::remove) and [`len`](Engine::len) have no default.
/// An engine that does more returns itself from the matching `as_…` method (for example
/// `fn as_motion(&mut self) -> Option<&mut dyn Motion> { Some(self) }`).
pub trait Engine: Send {
    /// A short name (frame output, logs).
    fn name(&self) -> &'static str;

    /// The timing model of `behaviour`, or `None` if this engine cannot realize it.
    fn timing(&self, behaviour: &Behaviour) -> Option<TimingModel>;

    /// Whether `behaviour` can be realized with these sync times: the default checks
    /// them against the engine's timing model — sync order, a duration within the model's bounds,
    /// a rigid behaviour's internal distances. Called when pegs move without rescheduling.
    fn check_timing(&self, behaviour: &Behaviour, syncs: &[(SyncName, f64)]) -> Result<(), String> {
        match self.timing(behaviour) {
            Some(model) => model.admits(syncs),
            None => Ok(()),
        }
    }

    /// Whether the engine interprets the extension attribute `{ns}name` on its behaviours (the
    /// runtime warns CUSTOM_ATTRIBUTE_NOT_SUPPORTED for the others).
    fn interprets(&self, _ns: &str, _name: &str) -> bool {
        false
    }

    /// Why this engine plays `behaviour` with its timing only, showing nothing (a lexeme no
    /// binding defines, say), or `None` if it realizes it. The runtime warns
    /// (LEXEME_NOT_SUPPORTED) once when such a behaviour starts, and `bmlr validate` warns too.
    fn unanimated(&self, _behaviour: &Behaviour) -> Option<String> {
        None
    }

    /// Takes a scheduled unit into the engine's plan.
    fn add(&mut self, unit: Unit<'_>) -> Result<(), EngineError>;

    /// Forgets a unit (it ended, was interrupted before starting, or its block was removed).
    fn remove(&mut self, key: &UnitKey);

    /// The unit's sync times moved (an anticipator's prediction changed, a parameter changed its
    /// timing): new global times, in sync order. Passed syncs keep theirs.
    fn retime(&mut self, _key: &UnitKey, _syncs: &[(SyncName, f64)]) {}

    /// Interrupts a running unit at global time `now`: the new global times of its syncs (same
    /// length as `syncs`; passed syncs keep theirs). The default ends motion gracefully: syncs up
    /// to `relax` move to `now` and the retraction after it keeps its length; a unit already past
    /// `relax`, or without one, ends at once.
    fn interrupt(&mut self, _key: &UnitKey, now: f64, syncs: &[(SyncName, f64)]) -> Vec<f64> {
        relax_now(now, syncs)
    }

    /// Number of units the engine holds (bounded-memory checks).
    fn len(&self) -> usize;

    /// Whether the engine holds no unit.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Shows every unit running at global time `now` in `frame` (its outputs).
    fn play(&mut self, _now: f64, _frame: &mut Frame) {}

    /// The engine's motion, if it moves the body.
    fn as_motion(&mut self) -> Option<&mut dyn Motion> {
        None
    }

    /// The engine's part in animation prediction, if it predicts or needs predicted poses.
    fn as_prediction(&mut self) -> Option<&mut dyn Prediction> {
        None
    }

    /// Its sound, if it makes any.
    fn as_sound(&self) -> Option<&dyn Sound> {
        None
    }

    /// Its utterances, if it speaks.
    fn as_speaking(&self) -> Option<&dyn Speaking> {
        None
    }

    /// Its streams, if it plays sound the host streams in.
    fn as_streams(&mut self) -> Option<&mut dyn Streams> {
        None
    }

    /// Its face motion, if it moves the face.
    fn as_expression(&mut self) -> Option<&mut dyn Expression> {
        None
    }

    /// The parameters of its running units, if some can change while they run.
    fn as_parameters(&mut self) -> Option<&mut dyn Parameters> {
        None
    }

    /// The body resources and exclusive groups of its behaviours, if they have any.
    fn as_resources(&self) -> Option<&dyn Resources> {
        None
    }

    /// Its simulated body, if it simulates one (the host's pushes go there).
    fn as_physics(&mut self) -> Option<&mut dyn Physics> {
        None
    }

    /// Warnings about its units since it was last asked (a simulated body that fell), as
    /// (unit, what happened); the runtime sends each as a warning feedback.
    fn take_warnings(&mut self) -> Vec<(UnitKey, String)> {
        Vec::new()
    }

    /// Its travel about the world, if it moves the whole character (locomotion).
    fn as_travel(&mut self) -> Option<&mut dyn Travel> {
        None
    }

    /// Its revisions of its units' sync times, if it makes any.
    fn as_revising(&mut self) -> Option<&mut dyn Revising> {
        None
    }

    /// Its look at whom the character's travel attends to, if it directs the eyes (gaze).
    fn as_attend(&mut self) -> Option<&mut dyn Attend> {
        None
    }

    /// Whether the engine revises the sync times of `behaviour`'s units while they run (through
    /// [`Revising::take_revisions`]): the runtime then keeps every sync of it on a peg of its own,
    /// so that behaviours tied to one follow its revisions.
    fn self_timed(&self, _behaviour: &Behaviour) -> bool {
        false
    }

    /// The warning type an error of [`add`](Engine::add) is reported with.
    fn refusal(&self, _error: &EngineError) -> crate::language::feedback::KnownWarning {
        crate::language::feedback::KnownWarning::ExecutionFailure
    }

    /// Its actions on the plan, if it realizes control behaviours.
    fn as_control(&mut self) -> Option<&mut dyn Control> {
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn syncs(v: &[(&'static str, f64)]) -> Vec<(SyncName, f64)> {
        v.iter()
            .map(|&(s, t)| (crate::language::bml::Id::new_static(s), t))
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
}
