//! The speech engine: `speech` (and BMLT `text`) timed by the built-in TTS ([`SpeechTiming`],
//! `voice::builtin`) — rigid, inline syncs at the start of the word after them — and spoken with
//! the lips: each frame, the phones being said are turned into visemes with coarticulation
//! (`voice::lipsync`) and the visemes into the face's blendshapes (jaw and lips), the frame's
//! viseme the strongest of them. While a speech runs, `volume` (0–100) and `rate` (1 = the
//! model's rate) can change; a rate change retimes the words still to come (and the lips with
//! them). Interrupting a speech stops it at once. A voice that synthesizes sound (flite) plays
//! it from the speech's start at its volume (`engine::Sound`); the built-in voice is silent. The
//! frame shows each running speech's progress, volume and rate.
//!
//! Incremental speech (the `bmlis` extension of AsapRealizer's incremental TTS):
//! `bmlis:generatefiller="true"` adds a hesitation filler after the text — the speech gets a
//! `relax` sync where the text ends and its `end` after the filler; a chunked successor that
//! speaks cuts the filler (co-articulation on the voice).

use crate::character::face::{Face, FaceModel};
use crate::character::voice::stream::AudioStream;
use crate::character::voice::{lipsync, Phone, Utterance};
use crate::engines::interface::{Engine, EngineError, Frame, Output, Unit, UnitKey, Units};
use crate::language::bml::{Behaviour, BehaviourKind, TextPart};
use crate::planning::timing::{SpeechTiming, SyncKey, SyncName, TimingModel, TimingModels};
use std::sync::Arc;

mod stream;
use stream::{stream_name, Streamed};

/// Volume of a speech that no one changed.
pub const DEFAULT_VOLUME: f64 = 100.0;

/// The incremental-speech extension namespace (AsapRealizer's `bmlis`).
pub const NS_BMLIS: &str = "http://www.asap-project.org/bmlis";

/// Length of a hesitation filler ("uhm"), seconds.
pub const FILLER_SECONDS: f64 = 0.5;

/// A speech's own sound (`bmlt:audiofile`) and its timing marks (`bmlt:marks`), if it brings
/// them: paths as given or relative to the working directory.
fn own_sound(b: &Behaviour) -> Option<(String, Option<String>)> {
    let attr = |name: &str| {
        (b.foreign_attrs.iter())
            .find(|a| a.ns == crate::language::bml::NS_BMLT && a.name == name)
            .map(|a| a.value.trim().to_string())
    };
    Some((attr("audiofile")?, attr("marks")))
}

/// The XML namespace (`xml:lang`).
const NS_XML: &str = "http://www.w3.org/XML/1998/namespace";

/// A speech's language (`xml:lang`), if it gives one.
fn language(b: &Behaviour) -> Option<String> {
    (b.foreign_attrs.iter())
        .find(|a| a.ns == NS_XML && a.name == "lang")
        .map(|a| a.value.trim().to_ascii_lowercase())
}

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
    /// The synthesized sound, if the voice makes any.
    audio: Option<Arc<crate::character::voice::Audio>>,
    /// The phones, in the TTS's time (seconds from the speech's start at rate 1).
    phones: Vec<Phone>,
    /// The TTS's time of each sync key, in key order.
    anchors: Vec<f64>,
    /// Global time → TTS time: (global, TTS) knots, increasing; linear between them.
    knots: Vec<(f64, f64)>,
    /// The stream it plays, if it plays one (its sound and lips come from there, in the
    /// sound's own time).
    streamed: Option<Streamed>,
}

impl Speaking {
    /// The TTS's time at global time `t`.
    fn tts_time(&self, t: f64) -> f64 {
        let k = self.knots.partition_point(|&(g, _)| g <= t);
        match (k.checked_sub(1).map(|i| self.knots[i]), self.knots.get(k)) {
            (Some((g0, a0)), Some(&(g1, a1))) if g1 > g0 => a0 + (a1 - a0) * (t - g0) / (g1 - g0),
            (Some((_, a0)), _) => a0,
            (None, Some(&(_, a1))) => a1,
            (None, None) => 0.0,
        }
    }

    /// The knots for sync times `syncs`, keeping what was said up to `now`.
    fn reknot(&mut self, now: f64, syncs: &[(SyncName, f64)]) {
        let said = self.tts_time(now);
        self.knots.retain(|&(g, _)| g <= now);
        self.knots.push((now, said));
        let later = (syncs.iter().zip(&self.anchors)).filter(|((_, g), &a)| *g > now && a >= said);
        self.knots.extend(later.map(|((_, g), &a)| (*g, a)));
    }
}

/// The speech engine (see the module documentation).
#[derive(Debug)]
pub struct SpeechEngine {
    timing: SpeechTiming,
    units: Units<Speaking>,
    /// The last frame's time.
    now: f64,
    /// The last [`CACHE`] texts said (with their own sound and marks, if any), with what the
    /// voice made of them: timing, warnings and the unit ask for the same text, and a voice
    /// that runs a program is asked once.
    said: std::sync::Mutex<std::collections::VecDeque<(Saying, Arc<Said>)>>,
    /// The streams the host opened.
    streams: Vec<AudioStream>,
}

/// What is said: the text, the speech's own sound and marks files if it brings them, and its
/// language if it gives one.
type Saying = (
    Vec<TextPart>,
    Option<(String, Option<String>)>,
    Option<String>,
);

/// How many texts the engine remembers.
const CACHE: usize = 64;

/// What the voice made of a text: the utterance, or (when it failed) the built-in TTS's and why.
#[derive(Debug)]
pub struct Said {
    /// The utterance (phones, syncs, end, sound).
    pub utterance: Utterance,
    /// Why the chosen voice could not say it as asked (a voice missing, a speech's own sound
    /// unreadable, its marks bad or past the sound's end), if it could not.
    pub failed: Option<String>,
}

impl SpeechEngine {
    /// A speech engine that times speech with `timing`.
    pub fn new(timing: SpeechTiming) -> Self {
        SpeechEngine {
            timing,
            units: Units::new(),
            now: 0.0,
            said: std::sync::Mutex::new(std::collections::VecDeque::new()),
            streams: Vec::new(),
        }
    }

    /// What the voice makes of `behaviour`'s text, or its own sound makes of it (remembered).
    fn say(&self, behaviour: &Behaviour) -> Arc<Said> {
        let saying: Saying = (
            Self::text(behaviour).to_vec(),
            own_sound(behaviour),
            language(behaviour),
        );
        let mut cache = self.said.lock().unwrap_or_else(|e| e.into_inner());
        if let Some((_, s)) = cache.iter().find(|(t, _)| *t == saying) {
            return s.clone();
        }
        let said = Arc::new(match &saying.1 {
            Some((audio, marks)) => Self::own(&saying.0, audio, marks.as_deref()),
            None => self.voiced(&saying.0, saying.2.as_deref()),
        });
        cache.push_back((saying, said.clone()));
        if cache.len() > CACHE {
            cache.pop_front();
        }
        said
    }

    /// What the TTS makes of `text` (the built-in TTS's timing, silent, if it fails), in
    /// `language` where the voice speaks several (espeak-ng: its voice of that name, else its
    /// own with a warning).
    fn voiced(&self, text: &[TextPart], language: Option<&str>) -> Said {
        let mut timing = self.timing;
        let mut warning = None;
        if let (crate::planning::timing::Voice::Espeak(own), Some(language)) =
            (timing.voice, language)
        {
            use crate::character::voice::espeak::{Espeak, VoiceName};
            match VoiceName::new(language) {
                Ok(name) if Espeak::new(name).has_voice() => {
                    timing.voice = crate::planning::timing::Voice::Espeak(name)
                }
                _ => {
                    warning = Some(format!(
                        "espeak-ng has no voice for xml:lang '{language}'; it speaks with '{}'",
                        own.as_str()
                    ))
                }
            }
        }
        match timing.speak(text) {
            Ok(utterance) => Said {
                utterance,
                failed: warning,
            },
            Err(e) => Said {
                utterance: SpeechTiming::default().speak(text).unwrap_or_default(),
                failed: Some(e),
            },
        }
    }

    /// `text` said by the sound in file `audio`, timed by the marks in file `marks`
    /// (`voice::recorded`). An unreadable sound leaves the built-in TTS's timing, silent;
    /// unreadable marks leave the sound to time the text.
    fn own(text: &[TextPart], audio: &str, marks: Option<&str>) -> Said {
        let sound = match crate::character::sound::read_wav(std::path::Path::new(audio)) {
            Ok(a) => Arc::new(a),
            Err(e) => {
                return Said {
                    utterance: SpeechTiming::default().speak(text).unwrap_or_default(),
                    failed: Some(format!("its audiofile cannot be read ({e})")),
                }
            }
        };
        let mut problems = Vec::new();
        let marks = marks.and_then(|file| {
            let read = std::fs::read_to_string(file).map_err(|e| format!("{file}: {e}"));
            match read.and_then(|t| crate::character::voice::marks::parse(&t, file)) {
                Ok(m) => Some(m),
                Err(e) => {
                    problems.push(format!("its marks are not used ({e})"));
                    None
                }
            }
        });
        let (utterance, warnings) =
            crate::character::voice::recorded::utterance(text, sound, marks.as_ref());
        problems.extend(warnings);
        Said {
            utterance,
            failed: (!problems.is_empty()).then(|| problems.join("; ")),
        }
    }

    /// The text of a speech behaviour.
    fn text(behaviour: &Behaviour) -> &[TextPart] {
        match &behaviour.kind {
            BehaviourKind::Speech(s) | BehaviourKind::Text(s) => &s.text,
            _ => &[],
        }
    }

    /// The phones of `behaviour` (with a filler's "uhm" after the text when it asks for one)
    /// and the TTS's time of each of its sync keys.
    fn spoken(&self, behaviour: &Behaviour) -> (Vec<Phone>, Vec<f64>) {
        if !matches!(behaviour.kind, BehaviourKind::Speech(_)) {
            return (Vec::new(), Vec::new()); // shown text: the lips stay still
        }
        let said = self.say(behaviour);
        let u = &said.utterance;
        let mut phones = u.phones.clone();
        let mut anchors: Vec<f64> = std::iter::once(0.0)
            .chain(u.syncs.iter().map(|s| s.1))
            .chain([u.end])
            .collect();
        if wants_filler(behaviour) {
            let (a, m) = (u.end + FILLER_SECONDS * 0.6, u.end + FILLER_SECONDS);
            phones.push(Phone {
                symbol: "AH",
                start: u.end,
                end: a,
            });
            phones.push(Phone {
                symbol: "M",
                start: a,
                end: m,
            });
            anchors.push(m);
        }
        (phones, anchors)
    }
}

impl Engine for SpeechEngine {
    crate::units_remove!();

    fn name(&self) -> &'static str {
        "speech"
    }

    fn retime(&mut self, key: &UnitKey, syncs: &[(SyncName, f64)]) {
        let now = self.now;
        if let Some((held, u)) = self.units.get_mut(key) {
            u.reknot(now, syncs);
            for (h, s) in held.iter_mut().zip(syncs) {
                h.1 = s.1;
            }
        }
    }

    fn interrupt(&mut self, key: &UnitKey, now: f64, syncs: &[(SyncName, f64)]) -> Vec<f64> {
        let times = crate::engines::interface::stop_now(now, syncs);
        self.units.retime(key, &times);
        times
    }

    fn len(&self) -> usize {
        self.units.len()
    }

    fn timing(&self, behaviour: &Behaviour) -> Option<TimingModel> {
        let mut model = match &behaviour.kind {
            BehaviourKind::Speech(s) if stream_name(behaviour).is_some() => {
                // its length is the stream's: any, its inline syncs spread evenly until their
                // words come (`stream`)
                let ids: Vec<&str> = s.sync_ids().collect();
                let n = ids.len() as f64 + 1.0;
                let mut keys = vec![SyncKey::new("start", 0.0)];
                for (k, id) in ids.iter().enumerate() {
                    keys.push(SyncKey::new(*id, (k as f64 + 1.0) / n));
                }
                keys.push(SyncKey::new("end", 1.0));
                TimingModel {
                    keys,
                    flexibility: crate::planning::timing::Flexibility::Stretchable {
                        min_duration: 1e-3,
                        max_duration: 1e6,
                    },
                    persistent: false,
                }
            }
            BehaviourKind::Speech(_) if own_sound(behaviour).is_some() => {
                // a sound of its own cannot stretch: rigid, at its own pace
                let timing = SpeechTiming {
                    rate: 1.0,
                    retimable: false,
                    ..self.timing
                };
                timing.model_of(&self.say(behaviour).utterance)
            }
            BehaviourKind::Speech(_) => self.timing.model_of(&self.say(behaviour).utterance),
            // shown text is timed as the built-in voice would say it, and may stretch
            BehaviourKind::Text(_) => crate::planning::timing::DefaultTimingModels {
                speech: SpeechTiming {
                    voice: crate::planning::timing::Voice::Builtin,
                    ..self.timing
                },
            }
            .model(behaviour)?,
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

    fn unanimated(&self, behaviour: &Behaviour) -> Option<String> {
        if !matches!(behaviour.kind, BehaviourKind::Speech(_)) {
            return None;
        }
        if let Some(name) = stream_name(behaviour) {
            return (!self.streams.iter().any(|s| s.name() == name)).then(|| {
                format!(
                    "speech '{}': no stream '{name}' is open (the host opens it before the block comes); it is silent",
                    behaviour.id
                )
            });
        }
        let said = self.say(behaviour);
        let why = said.failed.as_ref()?;
        Some(match &said.utterance.audio {
            Some(_) => format!("speech '{}': {why}", behaviour.id),
            None => format!(
                "speech '{}': {why}; it is timed by the built-in TTS instead, without sound",
                behaviour.id
            ),
        })
    }

    fn interprets(&self, ns: &str, name: &str) -> bool {
        (ns == NS_BMLIS && name == "generatefiller")
            || (ns == crate::language::bml::NS_BMLT
                && matches!(name, "audiofile" | "marks" | "stream"))
            || (ns == NS_XML
                && name == "lang"
                && matches!(self.timing.voice, crate::planning::timing::Voice::Espeak(_)))
    }

    fn add(&mut self, unit: Unit<'_>) -> Result<(), EngineError> {
        // keys are unique: the runtime never adds a unit twice
        let streamed = stream_name(unit.behaviour).map(|name| {
            let stream = self.streams.iter().find(|s| s.name() == name).cloned();
            (stream, Self::text(unit.behaviour).to_vec())
        });
        if let Some((stream, text)) = streamed {
            self.units.add(unit, stream::speaking(stream, text));
            return Ok(());
        }
        let (phones, anchors) = self.spoken(unit.behaviour);
        let audio = matches!(unit.behaviour.kind, BehaviourKind::Speech(_))
            .then(|| self.say(unit.behaviour).utterance.audio.clone())
            .flatten();
        let knots = (unit.syncs.iter().zip(&anchors))
            .map(|(s, &a)| (s.1, a))
            .collect();
        self.units.add(
            unit,
            Speaking {
                volume: DEFAULT_VOLUME,
                rate: 1.0,
                audio,
                phones,
                anchors,
                knots,
                streamed: None,
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

    fn as_parameters(&mut self) -> Option<&mut dyn crate::engines::interface::Parameters> {
        Some(self)
    }

    fn as_resources(&self) -> Option<&dyn crate::engines::interface::Resources> {
        Some(self)
    }

    fn as_expression(&mut self) -> Option<&mut dyn crate::engines::interface::Expression> {
        Some(self)
    }

    fn as_sound(&self) -> Option<&dyn crate::engines::interface::Sound> {
        Some(self)
    }

    fn as_speaking(&self) -> Option<&dyn crate::engines::interface::Speaking> {
        Some(self)
    }

    fn as_streams(&mut self) -> Option<&mut dyn crate::engines::interface::Streams> {
        Some(self)
    }

    fn as_revising(&mut self) -> Option<&mut dyn crate::engines::interface::Revising> {
        Some(self)
    }

    fn self_timed(&self, behaviour: &Behaviour) -> bool {
        // a streamed speech's inline syncs follow its words as they come
        stream_name(behaviour).is_some()
            && matches!(&behaviour.kind, BehaviourKind::Speech(s) if s.sync_ids().next().is_some())
    }
}

impl crate::engines::interface::Streams for SpeechEngine {
    fn add_stream(&mut self, stream: AudioStream) {
        self.streams.retain(|s| s.name() != stream.name());
        self.streams.push(stream);
    }
}

impl crate::engines::interface::Speaking for SpeechEngine {
    /// The speech being said at `now` that began last: from its start to its end.
    fn utterance(&self, now: f64) -> Option<crate::character::body::aversion::Utterance> {
        (self.units.started(now))
            .filter_map(|(syncs, _)| Some((syncs.first()?.1, syncs.last()?.1)))
            .filter(|&(_, end)| now < end)
            .map(|(start, end)| crate::character::body::aversion::Utterance { start, end })
            .last()
    }
}

impl crate::engines::interface::Sound for SpeechEngine {
    /// The synthesized sound of every speech being said, from its start peg at its volume (its
    /// own rate: a rate change moves the lips, not the sound), until its end or interrupt.
    fn sounds(&self, now: f64, out: &mut Vec<crate::character::sound::Playing>) {
        self.units.playing(now, out, |u| {
            let audio = match &u.streamed {
                Some(s) => s.stream.audio()?,
                None => u.audio.clone()?,
            };
            Some((audio, (u.volume / 100.0) as f32))
        });
    }
}

impl crate::engines::interface::Expression for SpeechEngine {
    /// The lips of every speech being said at `now`: its visemes as blendshapes (several
    /// speeches at once combine by maximum), and the strongest viseme.
    fn express(&mut self, now: f64, face: &mut Face) {
        self.now = now;
        let model = FaceModel::default_model();
        let mut strongest = (0.0f32, None);
        for (syncs, u) in self.units.started_mut(now) {
            let (Some(start), Some(end)) = (syncs.first(), syncs.last()) else {
                continue;
            };
            // (revisions replan too, but a speech that started on this frame's own time was
            // added after they were taken: its first frame plans here)
            if let Some(phones) = u.streamed.as_mut().and_then(Streamed::replan) {
                u.phones = phones;
            }
            if now < start.1 || now > end.1 || u.phones.is_empty() {
                continue;
            }
            // a stream's lips go with its sound, from its start
            let said = match u.streamed {
                Some(_) => now - start.1,
                None => u.tts_time(now),
            };
            let w = lipsync::weights(&u.phones, said);
            let mut shapes = [0.0f32; 52];
            for (v, &wv) in w.iter().enumerate() {
                if let Some(x) = face.visemes.get_mut(v) {
                    *x = x.max(wv.clamp(0.0, 1.0));
                }
                for &(m, weight) in model.viseme(v) {
                    shapes[m] += wv * weight;
                }
                if wv > strongest.0 {
                    strongest = (wv, Some(v));
                }
            }
            for (m, &x) in shapes.iter().enumerate() {
                face.raise_morph(m, x);
            }
        }
        if strongest.1.is_some() {
            face.viseme = strongest.1;
        }
    }
}

impl crate::engines::interface::Parameters for SpeechEngine {
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
                u.reknot(now, syncs);
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

impl crate::engines::interface::Resources for SpeechEngine {
    fn resources(&self, _behaviour: &Behaviour) -> &'static [&'static str] {
        &["voice"]
    }
}
