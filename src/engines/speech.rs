//! The speech engine: `speech` (and BMLT `text`) with the headless timing model of
//! [`SpeechTiming`] — rigid, words at a syllable rate, inline syncs at word boundaries. While a
//! speech runs, `volume` (0–100) and `rate` (1 = the model's rate) can change; a rate change
//! retimes the words still to come. Interrupting a speech stops it at once. No audio is produced
//! (headless); the frame shows each running speech's progress, volume and rate.
//!
//! Incremental speech (the `bmlis` extension of AsapRealizer's incremental TTS):
//! `bmlis:generatefiller="true"` adds a hesitation filler after the text — the speech gets a
//! `relax` sync where the text ends and its `end` after the filler; a chunked successor that
//! speaks cuts the filler (co-articulation on the voice).

use crate::bml::{Behaviour, BehaviourKind};
use crate::engine::{Engine, EngineError, Frame, Output, Unit, UnitKey, Units};
use crate::timing::SyncKey;
use crate::timing::{SpeechTiming, TimingModel, TimingModels};

/// Volume of a speech that no one changed.
pub const DEFAULT_VOLUME: f64 = 100.0;

/// The incremental-speech extension namespace (AsapRealizer's `bmlis`).
pub const NS_BMLIS: &str = "http://www.asap-project.org/bmlis";

/// Length of a hesitation filler ("uhm"), seconds.
pub const FILLER_SECONDS: f64 = 0.5;

/// Whether a speech asks for a hesitation filler after its text.
fn wants_filler(b: &Behaviour) -> bool {
    b.foreign_attrs
        .iter()
        .any(|a| a.ns == NS_BMLIS && a.name == "generatefiller" && a.value.trim() == "true")
}

#[derive(Debug, Clone)]
struct Speaking {
    volume: f64,
    rate: f64,
}

/// The speech engine (see the module documentation).
#[derive(Debug)]
pub struct SpeechEngine {
    timing: SpeechTiming,
    units: Units<Speaking>,
}

impl SpeechEngine {
    /// A speech engine that times speech with `timing`.
    pub fn new(timing: SpeechTiming) -> Self {
        SpeechEngine {
            timing,
            units: Units::new(),
        }
    }
}

impl Engine for SpeechEngine {
    crate::units_remove!();
    crate::units_retime_len!();
    crate::units_interrupt!(crate::engine::stop_now);

    fn name(&self) -> &'static str {
        "speech"
    }

    fn timing(&self, behaviour: &Behaviour) -> Option<TimingModel> {
        let mut model = match behaviour.kind {
            BehaviourKind::Speech(_) | BehaviourKind::Text(_) => {
                crate::timing::DefaultTimingModels {
                    speech: self.timing,
                }
                .model(behaviour)?
            }
            _ => return None,
        };
        if wants_filler(behaviour) {
            // the text ends at `relax`; the filler runs from there to `end`
            let end = model.keys.last().map_or(0.0, |k| k.at);
            let at = model.keys.len() - 1;
            model.keys.insert(at, SyncKey::new("relax", end));
            if let Some(last) = model.keys.last_mut() {
                last.at = end + FILLER_SECONDS;
            }
        }
        Some(model)
    }

    fn interprets(&self, ns: &str, name: &str) -> bool {
        ns == NS_BMLIS && name == "generatefiller"
    }

    fn add(&mut self, unit: Unit<'_>) -> Result<(), EngineError> {
        // keys are unique: the runtime never adds a unit twice
        self.units.add(
            unit,
            Speaking {
                volume: DEFAULT_VOLUME,
                rate: 1.0,
            },
        );
        Ok(())
    }

    fn play(&mut self, now: f64, frame: &mut Frame) {
        for (key, progress, u) in self.units.running(now) {
            frame.outputs.push(Output {
                key: key.clone(),
                engine: "speech",
                progress,
                params: vec![("volume", u.volume), ("rate", u.rate)],
            });
        }
    }

    fn as_parameters(&mut self) -> Option<&mut dyn crate::engine::Parameters> {
        Some(self)
    }

    fn as_resources(&self) -> Option<&dyn crate::engine::Resources> {
        Some(self)
    }
}

impl crate::engine::Parameters for SpeechEngine {
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
        let (syncs, u) = self
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
                for s in syncs.iter_mut() {
                    if s.1 > now {
                        s.1 = now + (s.1 - now) * factor;
                    }
                }
                Ok(Some(syncs.iter().map(|s| s.1).collect()))
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

impl crate::engine::Resources for SpeechEngine {
    fn resources(&self, _behaviour: &Behaviour) -> &'static [&'static str] {
        &["voice"]
    }
}
