//! The timing-only engine: realizes the BML kinds whose engine has not landed yet (face and face
//! shifts, locomotion, BMLT controllers and face morphs) and BMLT audio.
//! It takes the default timing models, plays units exactly at their scheduled sync times and lets
//! the runtime report every sync point; the frame shows each unit's progress. Motion interrupted
//! goes to `relax` at once and keeps its retraction; audio stops at once. It moves no joints: the
//! support table (`docs/bml-support.md`) marks these kinds "timing only".

use crate::engines::interface::{relax_now, stop_now, Engine, EngineError, Unit, UnitKey, Units};
use crate::language::bml::{Behaviour, BehaviourKind};
use crate::planning::timing::SyncName;
use crate::planning::timing::{DefaultTimingModels, TimingModel, TimingModels};

/// The timing-only engine (see the module documentation).
#[derive(Debug)]
pub struct TimingOnlyEngine {
    name: &'static str,
    models: DefaultTimingModels,
    stop_on_interrupt: bool,
    units: Units<()>,
}

impl TimingOnlyEngine {
    /// The engine for motion kinds: interrupted units retract gracefully.
    pub fn motion(models: DefaultTimingModels) -> Self {
        TimingOnlyEngine {
            name: "motion",
            models,
            stop_on_interrupt: false,
            units: Units::new(),
        }
    }

    /// The engine for audio: interrupted units stop at once.
    pub fn audio(models: DefaultTimingModels) -> Self {
        TimingOnlyEngine {
            name: "audio",
            models,
            stop_on_interrupt: true,
            units: Units::new(),
        }
    }
}

impl Engine for TimingOnlyEngine {
    crate::units_remove!();
    crate::units_retime_len!();
    crate::units_play!(field name);

    fn name(&self) -> &'static str {
        self.name
    }

    fn timing(&self, behaviour: &Behaviour) -> Option<TimingModel> {
        match behaviour.kind {
            BehaviourKind::Unknown(_)
            | BehaviourKind::Speech(_)
            | BehaviourKind::Text(_)
            | BehaviourKind::Wait(_)
            | BehaviourKind::Interrupt(_)
            | BehaviourKind::Activate(_)
            | BehaviourKind::ParameterValueChange(_) => None,
            _ => self.models.model(behaviour),
        }
    }

    fn add(&mut self, unit: Unit<'_>) -> Result<(), EngineError> {
        // keys are unique: the runtime never adds a unit twice
        self.units.add(unit, ());
        Ok(())
    }

    fn interrupt(&mut self, key: &UnitKey, now: f64, syncs: &[(SyncName, f64)]) -> Vec<f64> {
        let times = if self.stop_on_interrupt {
            stop_now(now, syncs)
        } else {
            relax_now(now, syncs)
        };
        self.units.retime(key, &times);
        times
    }
}
