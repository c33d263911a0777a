//! The speech engine: `speech` (and BMLT `text`) with the headless timing model of
//! [`SpeechTiming`] — rigid, words at a syllable rate, inline syncs at word boundaries. While a
//! speech runs, `volume` (0–100) and `rate` (1 = the model's rate) can change; a rate change
//! retimes the words still to come. Interrupting a speech stops it at once. No audio is produced
//! (headless); the frame shows each running speech's progress, volume and rate.

use std::collections::HashMap;

use crate::bml::{Behaviour, BehaviourKind};
use crate::engine::timing::{SpeechTiming, TimingModel, TimingModels};
use crate::engine::{stop_now, Engine, EngineError, Frame, Output, Unit, UnitKey};
use crate::schedule::SyncName;

/// Volume of a speech that no one changed.
pub const DEFAULT_VOLUME: f64 = 100.0;

#[derive(Debug, Clone)]
struct Speaking {
    syncs: Vec<(SyncName, f64)>,
    volume: f64,
    rate: f64,
}

/// The speech engine (see the module documentation).
#[derive(Debug)]
pub struct SpeechEngine {
    timing: SpeechTiming,
    units: HashMap<UnitKey, Speaking>,
}

impl SpeechEngine {
    /// A speech engine that times speech with `timing`.
    pub fn new(timing: SpeechTiming) -> Self {
        SpeechEngine {
            timing,
            units: HashMap::new(),
        }
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
        self.units.insert(
            unit.key.clone(),
            Speaking {
                syncs: unit.syncs.to_vec(),
                volume: DEFAULT_VOLUME,
                rate: 1.0,
            },
        );
        Ok(())
    }

    fn remove(&mut self, key: &UnitKey) {
        self.units.remove(key);
    }

    fn interrupt(&mut self, key: &UnitKey, now: f64, syncs: &[(SyncName, f64)]) -> Vec<f64> {
        let times = stop_now(now, syncs);
        if let Some(u) = self.units.get_mut(key) {
            for (s, t) in u.syncs.iter_mut().zip(&times) {
                s.1 = *t;
            }
        }
        times
    }

    fn len(&self) -> usize {
        self.units.len()
    }

    fn play(&mut self, now: f64, frame: &mut Frame) {
        let mut running: Vec<(&UnitKey, &Speaking)> = self
            .units
            .iter()
            .filter(|(_, u)| {
                let (start, end) = span(&u.syncs);
                start <= now && now < end
            })
            .collect();
        running.sort_by(|a, b| a.0.cmp(b.0)); // deterministic frames
        for (key, u) in running {
            let (start, end) = span(&u.syncs);
            frame.outputs.push(Output {
                key: key.clone(),
                engine: "speech",
                progress: ((now - start) / (end - start)).clamp(0.0, 1.0),
                params: vec![("volume".into(), u.volume), ("rate".into(), u.rate)],
            });
        }
    }

    fn parameter(&self, key: &UnitKey, name: &str) -> Option<f64> {
        let u = self.units.get(key)?;
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
            .units
            .get_mut(key)
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
