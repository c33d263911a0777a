//! The speech engine: `speech` (and BMLT `text`) with the headless timing model of
//! [`SpeechTiming`] — rigid, words at a syllable rate, inline syncs at word boundaries. While a
//! speech runs, `volume` (0–100) and `rate` (1 = the model's rate) can change; a rate change
//! retimes the words still to come. Interrupting a speech stops it at once. No audio is produced
//! (headless); the frame shows each running speech's progress, volume and rate.

use std::sync::Arc;

use crate::bml::{Behaviour, BehaviourKind};
use crate::engine::timing::{SpeechTiming, TimingModel, TimingModels};
use crate::engine::{stop_now, Engine, EngineError, Frame, Output, Unit, UnitKey};
use crate::schedule::SyncName;

/// Volume of a speech that no one changed.
pub const DEFAULT_VOLUME: f64 = 100.0;

#[derive(Debug, Clone)]
struct Speaking {
    key: Arc<UnitKey>,
    syncs: Vec<(SyncName, f64)>,
    volume: f64,
    rate: f64,
}

/// The speech engine (see the module documentation).
#[derive(Debug)]
pub struct SpeechEngine {
    timing: SpeechTiming,
    /// Units in the order they were added.
    units: Vec<Speaking>,
}

impl SpeechEngine {
    /// A speech engine that times speech with `timing`.
    pub fn new(timing: SpeechTiming) -> Self {
        SpeechEngine {
            timing,
            units: Vec::new(),
        }
    }
}

impl SpeechEngine {
    fn unit_mut(&mut self, key: &UnitKey) -> Option<&mut Speaking> {
        self.units.iter_mut().find(|u| *u.key == *key)
    }
}

impl Engine for SpeechEngine {
    fn name(&self) -> &'static str {
        "speech"
    }

    fn timing(&self, behaviour: &Behaviour) -> Option<TimingModel> {
        match behaviour.kind {
            BehaviourKind::Speech(_) | BehaviourKind::Text(_) => {
                crate::engine::timing::DefaultTimingModels {
                    speech: self.timing,
                }
                .model(behaviour)
            }
            _ => None,
        }
    }

    fn add(&mut self, unit: Unit<'_>) -> Result<(), EngineError> {
        // keys are unique: the runtime never adds a unit twice
        self.units.push(Speaking {
            key: Arc::new(unit.key.clone()),
            syncs: unit.syncs.to_vec(),
            volume: DEFAULT_VOLUME,
            rate: 1.0,
        });
        Ok(())
    }

    fn remove(&mut self, key: &UnitKey) {
        self.units.retain(|u| *u.key != *key);
    }

    fn interrupt(&mut self, key: &UnitKey, now: f64, syncs: &[(SyncName, f64)]) -> Vec<f64> {
        let times = stop_now(now, syncs);
        if let Some(u) = self.unit_mut(key) {
            for (s, t) in u.syncs.iter_mut().zip(&times) {
                s.1 = *t;
            }
        }
        times
    }

    fn retime(&mut self, key: &UnitKey, syncs: &[(SyncName, f64)]) {
        if let Some(u) = self.unit_mut(key) {
            u.syncs = syncs.to_vec();
        }
    }

    fn len(&self) -> usize {
        self.units.len()
    }

    fn play(&mut self, now: f64, frame: &mut Frame) {
        for u in &self.units {
            let (start, end) = span(&u.syncs);
            if start <= now && now < end {
                frame.outputs.push(Output {
                    key: u.key.clone(),
                    engine: "speech",
                    progress: ((now - start) / (end - start)).clamp(0.0, 1.0),
                    params: vec![("volume", u.volume), ("rate", u.rate)],
                });
            }
        }
    }

    fn parameter(&self, key: &UnitKey, name: &str) -> Option<f64> {
        let u = self.units.iter().find(|u| *u.key == *key)?;
        match name {
            "volume" => Some(u.volume),
            "rate" => Some(u.rate),
            _ => None,
        }
    }

    fn set_parameter(
        &mut self,
        key: &UnitKey,
        name: &str,
        value: f64,
        now: f64,
    ) -> Result<Option<Vec<f64>>, EngineError> {
        let u = self
            .unit_mut(key)
            .ok_or_else(|| EngineError(format!("{key} is not speaking")))?;
        match name {
            "volume" if value.is_finite() => {
                u.volume = value.clamp(0.0, 100.0);
                Ok(None)
            }
            "rate" if value.is_finite() && value > 0.0 => {
                // the rest of the speech plays at the new rate
                let factor = u.rate / value;
                u.rate = value;
                for s in &mut u.syncs {
                    if s.1 > now {
                        s.1 = now + (s.1 - now) * factor;
                    }
                }
                Ok(Some(u.syncs.iter().map(|s| s.1).collect()))
            }
            "volume" | "rate" => Err(EngineError(format!(
                "{value} is not a valid {name} for {key} (volume 0-100, rate > 0)"
            ))),
            _ => Err(EngineError(format!(
                "speech {key} has no parameter '{name}' (it has volume and rate)"
            ))),
        }
    }
}

fn span(syncs: &[(SyncName, f64)]) -> (f64, f64) {
    (
        syncs.first().map_or(0.0, |s| s.1),
        syncs.last().map_or(0.0, |s| s.1),
    )
}
