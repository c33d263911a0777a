//! The timing-only engine: realizes the BML kinds whose animation engine has not landed yet
//! (gesture, pointing, head, gaze, posture, face, locomotion, BMLT animation kinds) and BMLT audio.
//! It takes the default timing models, plays units exactly at their scheduled sync times and lets
//! the runtime report every sync point; the frame shows each unit's progress. Motion interrupted
//! goes to `relax` at once and keeps its retraction; audio stops at once. It moves no joints: the
//! support table (`docs/bml-support.md`) marks these kinds "timing only".

use std::sync::Arc;

use crate::bml::{Behaviour, BehaviourKind};
use crate::engine::timing::{DefaultTimingModels, TimingModel, TimingModels};
use crate::engine::{relax_now, stop_now, Engine, EngineError, Frame, Output, Unit, UnitKey};
use crate::schedule::SyncName;

/// A unit's (sync, global time) list.
type Syncs = Vec<(SyncName, f64)>;

/// The timing-only engine (see the module documentation).
#[derive(Debug)]
pub struct TimingOnlyEngine {
    name: &'static str,
    models: DefaultTimingModels,
    stop_on_interrupt: bool,
    /// Units in the order they were added (deterministic frames without sorting).
    units: Vec<(Arc<UnitKey>, Syncs)>,
}

impl TimingOnlyEngine {
    /// The engine for motion kinds: interrupted units retract gracefully.
    pub fn motion(models: DefaultTimingModels) -> Self {
        TimingOnlyEngine {
            name: "motion",
            models,
            stop_on_interrupt: false,
            units: Vec::new(),
        }
    }

    /// The engine for audio: interrupted units stop at once.
    pub fn audio(models: DefaultTimingModels) -> Self {
        TimingOnlyEngine {
            name: "audio",
            models,
            stop_on_interrupt: true,
            units: Vec::new(),
        }
    }
}

impl Engine for TimingOnlyEngine {
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

    fn exclusive_group(&self, behaviour: &Behaviour) -> Option<&'static str> {
        match behaviour.kind {
            BehaviourKind::Gaze(_) => Some("gaze"),
            BehaviourKind::Posture(_) => Some("posture"),
            _ => None,
        }
    }

    fn add(&mut self, unit: Unit<'_>) -> Result<(), EngineError> {
        // keys are unique: the runtime never adds a unit twice
        self.units
            .push((Arc::new(unit.key.clone()), unit.syncs.to_vec()));
        Ok(())
    }

    fn remove(&mut self, key: &UnitKey) {
        self.units.retain(|(k, _)| **k != *key);
    }

    fn interrupt(&mut self, key: &UnitKey, now: f64, syncs: &[(SyncName, f64)]) -> Vec<f64> {
        let times = if self.stop_on_interrupt {
            stop_now(now, syncs)
        } else {
            relax_now(now, syncs)
        };
        if let Some((_, u)) = self.units.iter_mut().find(|(k, _)| **k == *key) {
            for (s, t) in u.iter_mut().zip(&times) {
                s.1 = *t;
            }
        }
        times
    }

    fn retime(&mut self, key: &UnitKey, syncs: &[(SyncName, f64)]) {
        if let Some((_, u)) = self.units.iter_mut().find(|(k, _)| **k == *key) {
            *u = syncs.to_vec();
        }
    }

    fn len(&self) -> usize {
        self.units.len()
    }

    fn play(&mut self, now: f64, frame: &mut Frame) {
        for (key, s) in &self.units {
            let (Some(first), Some(last)) = (s.first(), s.last()) else {
                continue;
            };
            let (start, end) = (first.1, last.1);
            if !(start <= now && now < end) {
                continue;
            }
            let progress = if end.is_finite() {
                (now - start) / (end - start)
            } else {
                0.0
            };
            frame.outputs.push(Output {
                key: key.clone(),
                engine: self.name,
                progress: progress.clamp(0.0, 1.0),
                params: Vec::new(),
            });
        }
    }
}
