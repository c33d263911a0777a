//! The audio engine: BMLT `audiofile` plays a WAV file (read with `hound`; mono or stereo, any
//! rate and sample format). The clip's length is its rigid timing: `start` at its first sample,
//! `end` at its last. `volume` (0–100, default 100) can change while it plays; an interrupt cuts
//! it at once (the mix fades it out over 10 ms). A file that cannot be read plays its default
//! timing (1 s) silently, with a warning that names the file and why. `fileName` is a path, as
//! given or relative to the working directory; where no such file exists, the built-in clips
//! answer to their names ([`BUILT_IN`]: `audio/audience.wav`, the clip RealizerTester plays).

use std::collections::HashMap;
use std::sync::{Arc, Mutex};

use crate::character::voice::Audio;
use crate::engines::interface::{stop_now, Engine, EngineError, Unit, UnitKey, Units};
use crate::language::bml::{Behaviour, BehaviourKind};
use crate::planning::timing::{
    DefaultTimingModels, Flexibility, SyncName, TimingModel, TimingModels,
};

/// The clips built into the realizer, by name (`fixtures/audio/`).
pub const BUILT_IN: &[(&str, &[u8])] = &[(
    "audio/audience.wav",
    include_bytes!("../../fixtures/audio/audience.wav"),
)];

/// A clip playing: its sound (none for a file that could not be read) and volume (0–100).
#[derive(Debug, Clone)]
struct Clip {
    audio: Option<Arc<Audio>>,
    volume: f64,
}

/// The audio engine (see the module documentation).
#[derive(Debug, Default)]
pub struct AudioEngine {
    models: DefaultTimingModels,
    units: Units<Clip>,
    /// Files read so far (a behaviour's timing, warning and unit all need the same one).
    files: Mutex<HashMap<String, Result<Arc<Audio>, String>>>,
}

fn file_name(b: &Behaviour) -> Option<&str> {
    match &b.kind {
        BehaviourKind::AudioFile { file_name } => Some(file_name),
        _ => None,
    }
}

impl AudioEngine {
    /// The sound of `file` (read once).
    fn read(&self, file: &str) -> Result<Arc<Audio>, String> {
        let mut files = self.files.lock().unwrap_or_else(|e| e.into_inner());
        files
            .entry(file.to_string())
            .or_insert_with(|| {
                let path = std::path::Path::new(file);
                let built_in = BUILT_IN
                    .iter()
                    .find(|(name, _)| *name == file && !path.exists());
                match built_in {
                    Some((_, bytes)) => {
                        crate::character::sound::read_wav_from(std::io::Cursor::new(*bytes), file)
                    }
                    None => crate::character::sound::read_wav(path),
                }
                .map(Arc::new)
            })
            .clone()
    }
}

impl Engine for AudioEngine {
    crate::units_remove!();
    crate::units_retime_len!();
    crate::units_play!("audio");

    fn name(&self) -> &'static str {
        "audio"
    }

    fn timing(&self, behaviour: &Behaviour) -> Option<TimingModel> {
        let file = file_name(behaviour)?;
        match self.read(file) {
            Ok(a) => {
                let length = a.samples.len() as f64 / f64::from(a.rate.max(1));
                Some(TimingModel::new(
                    &[("start", 0.0), ("end", length.max(1e-3))],
                    Flexibility::Rigid,
                ))
            }
            Err(_) => self.models.model(behaviour),
        }
    }

    fn unanimated(&self, behaviour: &Behaviour) -> Option<String> {
        let file = file_name(behaviour)?;
        let why = self.read(file).err()?;
        Some(format!(
            "audiofile '{}': cannot read {why}; it plays its default timing, silently",
            behaviour.id
        ))
    }

    fn add(&mut self, unit: Unit<'_>) -> Result<(), EngineError> {
        let file = file_name(unit.behaviour)
            .ok_or_else(|| EngineError("the audio engine realizes bmlt:audiofile only".into()))?;
        let audio = self.read(file).ok();
        self.units.add(
            unit,
            Clip {
                audio,
                volume: 100.0,
            },
        );
        Ok(())
    }

    fn interrupt(&mut self, key: &UnitKey, now: f64, syncs: &[(SyncName, f64)]) -> Vec<f64> {
        let times = stop_now(now, syncs);
        self.units.retime(key, &times);
        times
    }

    fn as_sound(&self) -> Option<&dyn crate::engines::interface::Sound> {
        Some(self)
    }

    fn as_parameters(&mut self) -> Option<&mut dyn crate::engines::interface::Parameters> {
        Some(self)
    }
}

impl crate::engines::interface::Sound for AudioEngine {
    fn sounds(&self, now: f64, out: &mut Vec<crate::character::sound::Playing>) {
        self.units.playing(now, out, |c| {
            Some((c.audio.clone()?, (c.volume / 100.0) as f32))
        });
    }
}

impl crate::engines::interface::Parameters for AudioEngine {
    fn parameter(&self, key: &UnitKey, name: &str) -> Option<f64> {
        (name == "volume").then(|| self.units.get(key).map(|c| c.volume))?
    }

    fn set_parameter(
        &mut self,
        key: &UnitKey,
        name: &str,
        value: f64,
        _now: f64,
    ) -> Result<Option<Vec<f64>>, EngineError> {
        if name != "volume" || !value.is_finite() {
            return Err(EngineError(format!(
                "an audiofile's volume (0-100) can change; not {name}={value}"
            )));
        }
        let (_, clip) = (self.units.get_mut(key))
            .ok_or_else(|| EngineError(format!("{key} is not playing")))?;
        clip.volume = value.clamp(0.0, 100.0);
        Ok(None)
    }
}
