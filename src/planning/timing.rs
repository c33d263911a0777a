//! Timing models: what an engine tells the scheduler about a behaviour's timing — its sync keys in
//! order with preferred offsets from the start, whether the timing is rigid (TTS speech, audio) or may
//! stretch within duration bounds, and whether it persists. Also the default models for every BML
//! kind, so that the scheduler works before the animation engines exist, and a deterministic
//! speech timing model of the built-in TTS (phone durations, inline syncs at word starts).

use crate::language::bml::{Behaviour, BehaviourKind, Speech};

/// A sync point's name: static for the standard names, owned for a speech's inline syncs.
pub type SyncName = crate::language::bml::Id;

/// Duration of behaviours that act once and end (interrupt, activate, parametervaluechange): the
/// smallest step feedback can show (1 ms), so that `end > start` holds.
pub const INSTANT: f64 = 0.001;

/// Shortest duration of a stretchable behaviour (`end > start`, BML 1.0); engines may set more.
pub const MIN_DURATION: f64 = 1e-6;

/// How a behaviour's internal timing may change when it is constrained.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Flexibility {
    /// Internal timing is fixed: the whole behaviour can only move (TTS speech, audio files).
    Rigid,
    /// Phases may stretch or shrink, keeping the total duration within bounds.
    Stretchable {
        /// Shortest total duration, seconds.
        min_duration: f64,
        /// Longest total duration, seconds (may be infinite).
        max_duration: f64,
    },
}

/// A sync point of the model with its preferred offset from the behaviour's start.
#[derive(Debug, Clone, PartialEq)]
pub struct SyncKey {
    /// Sync point name (`start`, `stroke`, an inline speech sync, ...).
    pub name: crate::language::bml::Id,
    /// Preferred offset from `start`, seconds.
    pub at: f64,
    /// The longest the phase that ends at this key may last, seconds (infinite: no limit). Only
    /// a stretchable model's limits count; the scheduler never stretches a phase past it.
    pub max_phase: f64,
}

impl SyncKey {
    /// A key at `at` seconds from `start` whose phase has no limit.
    pub fn new(name: impl Into<crate::language::bml::Id>, at: f64) -> Self {
        SyncKey {
            name: name.into(),
            at,
            max_phase: f64::INFINITY,
        }
    }
}

/// The timing an engine gives the scheduler for one behaviour.
#[derive(Debug, Clone, PartialEq)]
pub struct TimingModel {
    /// All sync keys in their required order; the first is `start` at 0, the last is `end`.
    pub keys: Vec<SyncKey>,
    /// Rigid or stretchable.
    pub flexibility: Flexibility,
    /// Whether the behaviour runs until stopped when its end is not constrained.
    pub persistent: bool,
}

impl TimingModel {
    /// Whether sync times (in key order; a persistent end may be infinite) realize this model:
    /// non-decreasing, a duration within the bounds of a stretchable model, the internal distances
    /// of a rigid one (within 1 µs).
    pub fn admits(&self, syncs: &[(crate::language::bml::Id, f64)]) -> Result<(), String> {
        const TOLERANCE: f64 = 1e-6;
        if let Some(w) = syncs.windows(2).find(|w| w[1].1 < w[0].1 - 1e-9) {
            return Err(format!("'{}' comes before '{}'", w[1].0, w[0].0));
        }
        let (Some(first), Some(last)) = (syncs.first(), syncs.last()) else {
            return Ok(());
        };
        let duration = last.1 - first.1;
        match self.flexibility {
            Flexibility::Stretchable {
                min_duration,
                max_duration,
            } if duration.is_finite()
                && (duration < min_duration - TOLERANCE || duration > max_duration + TOLERANCE) =>
            {
                return Err(format!(
                    "a duration of {duration:.3} s is outside the engine's bounds [{min_duration}, {max_duration}] s"
                ));
            }
            Flexibility::Rigid => {
                for (k, (name, t)) in syncs.iter().enumerate() {
                    let Some(key) = self.keys.get(k) else { break };
                    if t.is_finite() && ((t - first.1) - key.at).abs() > TOLERANCE {
                        return Err(format!(
                            "'{name}' moved within a behaviour whose timing is fixed"
                        ));
                    }
                }
            }
            Flexibility::Stretchable { .. } => {
                let phases = syncs.windows(2).zip(self.keys.windows(2));
                for (w, k) in phases {
                    let (a, b) = (&w[0], &w[1]);
                    if k[1].name == b.0 && b.1 - a.1 > k[1].max_phase + TOLERANCE {
                        return Err(format!(
                            "the phase {}-{} lasts {:.3} s, more than its limit of {} s",
                            a.0,
                            b.0,
                            b.1 - a.1,
                            k[1].max_phase
                        ));
                    }
                }
            }
        }
        Ok(())
    }

    /// A model with static key names at preferred times (seconds from `start`).
    pub fn new(keys: &[(&'static str, f64)], flexibility: Flexibility) -> Self {
        TimingModel {
            keys: keys
                .iter()
                .map(|(name, at)| SyncKey::new(crate::language::bml::Id::new_static(name), *at))
                .collect(),
            flexibility,
            persistent: false,
        }
    }

    /// A persistent behaviour's model (noise, a physical controller): `start` and `end`, any
    /// duration above [`MIN_DURATION`], and without a constrained end it runs until its block
    /// is interrupted or replaced.
    pub fn persistent_span() -> Self {
        let mut m = Self::new(
            &[("start", 0.0), ("end", 1.0)],
            Flexibility::Stretchable {
                min_duration: MIN_DURATION,
                max_duration: f64::INFINITY,
            },
        );
        m.persistent = true;
        m
    }

    /// A stretchable model with the default bounds (any duration above [`MIN_DURATION`]).
    pub fn stretchable(keys: &[(&'static str, f64)]) -> Self {
        Self::new(
            keys,
            Flexibility::Stretchable {
                min_duration: MIN_DURATION,
                max_duration: f64::INFINITY,
            },
        )
    }

    /// The default gesture timing (ready, stroke phases, relax at their usual places) lasting
    /// `duration` seconds.
    pub fn gesture(duration: f64) -> Self {
        let m = Self::stretchable(GESTURE);
        let preferred = m.preferred_duration();
        m.scaled(duration / preferred)
    }

    /// The default face timing (attack peak, relax at their usual places) lasting `duration`.
    pub fn face(duration: f64) -> Self {
        let m = Self::stretchable(FACE);
        let preferred = m.preferred_duration();
        m.scaled(duration / preferred)
    }

    /// The same keys with every offset (and every phase limit) multiplied by `factor`.
    fn scaled(mut self, factor: f64) -> Self {
        for k in &mut self.keys {
            k.at *= factor;
            k.max_phase *= factor;
        }
        self
    }

    /// The same model with the phase that ends at each named key limited to the given seconds
    /// (names the model does not have are left out).
    pub fn with_phase_limits(mut self, limits: &[(&str, f64)]) -> Self {
        for &(name, max) in limits {
            if let Some(k) = self.key(name) {
                self.keys[k].max_phase = max;
            }
        }
        self
    }

    /// The same model with the span from key `from` to key `to` lasting at least `seconds` by
    /// preference: a shorter span is stretched uniformly (its phases, and the limits of those
    /// phases where the stretched phase would exceed them) and the keys after it move later by
    /// as much. Unknown names, or `to` not after `from`, leave the model as it is.
    pub fn with_span_at_least(mut self, from: &str, to: &str, seconds: f64) -> Self {
        let (Some(a), Some(b)) = (self.key(from), self.key(to)) else {
            return self;
        };
        let span = self.keys.get(b).map_or(0.0, |k| k.at) - self.keys[a].at;
        if b <= a || span >= seconds || !seconds.is_finite() {
            return self;
        }
        let origin = self.keys[a].at;
        let mut previous = origin;
        for i in a + 1..self.keys.len() {
            let old = self.keys[i].at;
            let at = if i <= b && span > 0.0 {
                origin + (old - origin) * seconds / span
            } else if i <= b {
                // a span of length zero: its keys spread evenly
                origin + seconds * (i - a) as f64 / (b - a) as f64
            } else {
                old + seconds - span
            };
            let key = &mut self.keys[i];
            key.at = at;
            if i <= b {
                key.max_phase = key.max_phase.max(at - previous);
            }
            previous = at;
        }
        self
    }

    /// The preferred duration (offset of `end`).
    pub fn preferred_duration(&self) -> f64 {
        self.keys.last().map_or(0.0, |k| k.at)
    }

    /// Index of the key named `name`.
    pub fn key(&self, name: &str) -> Option<usize> {
        self.keys.iter().position(|k| k.name == name)
    }

    /// Checks the model's invariants: at least `start` and `end`, `start` first at 0, `end` last and
    /// after `start`, offsets finite and non-decreasing, names unique.
    pub fn check(&self) -> Result<(), String> {
        let (Some(first), Some(last)) = (self.keys.first(), self.keys.last()) else {
            return Err("a timing model needs at least start and end".into());
        };
        if first.name != "start" || first.at != 0.0 {
            return Err(format!(
                "the first key must be start at 0, not {} at {}",
                first.name, first.at
            ));
        }
        if last.name != "end" || self.keys.len() < 2 || last.at <= 0.0 {
            return Err(format!(
                "the last key must be end after start, not {} at {}",
                last.name, last.at
            ));
        }
        for w in self.keys.windows(2) {
            if !(w[1].at.is_finite() && w[1].at >= w[0].at) {
                return Err(format!(
                    "key {} at {} comes before {} at {}",
                    w[1].name, w[1].at, w[0].name, w[0].at
                ));
            }
            if w[1].at - w[0].at > w[1].max_phase || w[1].max_phase.is_nan() {
                return Err(format!(
                    "the phase {}-{} lasts {} s, more than its limit of {} s",
                    w[0].name,
                    w[1].name,
                    w[1].at - w[0].at,
                    w[1].max_phase
                ));
            }
        }
        // unique names (a model has a few keys: pairwise)
        for (i, key) in self.keys.iter().enumerate() {
            if self.keys[..i].iter().any(|k| k.name == key.name) {
                return Err(format!("key {} appears twice", key.name));
            }
        }
        Ok(())
    }
}

/// Gives the scheduler the timing model of a behaviour. Engines implement this; `None` means the
/// behaviour kind is not supported (the behaviour is dropped with a warning).
pub trait TimingModels {
    /// The model for `behaviour`, or `None` if no engine handles its kind.
    fn model(&self, behaviour: &Behaviour) -> Option<TimingModel>;
}

/// Which voice times speech.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Voice {
    /// The built-in TTS (`voice::builtin`): phones with durations.
    #[default]
    Builtin,
    /// The metronome voice (`voice::syllables`): 0.2 s per syllable, pauses after punctuation.
    Syllables,
    /// CMU Flite run as a program (`voice::flite`; Debian package `flite`): its phone timings and
    /// its sound.
    Flite,
    /// espeak-ng run as a program with a voice (`voice::espeak`; Debian package `espeak-ng`): its
    /// sound in its languages, its phonemes timed to it.
    Espeak(crate::character::voice::espeak::VoiceName),
}

/// Speech timing from a voice (the built-in TTS by default): rigid, each inline sync where the
/// voice puts it, `end` where it stops.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpeechTiming {
    /// The voice.
    pub voice: Voice,
    /// Speaking rate (1 = the TTS's own; 2 = twice as fast).
    pub rate: f64,
    /// An incremental TTS that can change its speaking rate (AsapRealizer's incremental speech):
    /// speech is stretchable between 1/[`RETIME_RANGE`] and [`RETIME_RANGE`] times its preferred
    /// length instead of rigid. Off by default: a TTS decides its timing.
    pub retimable: bool,
}

/// How far a retimable speech may stretch or compress (factor on its preferred duration).
pub const RETIME_RANGE: f64 = 3.0;

impl Default for SpeechTiming {
    fn default() -> Self {
        SpeechTiming {
            voice: Voice::Builtin,
            rate: 1.0,
            retimable: false,
        }
    }
}

impl SpeechTiming {
    /// The rigid timing of a speech: `start`, each inline sync where the voice puts it, `end`
    /// where it stops.
    pub fn model(&self, speech: &Speech) -> TimingModel {
        let u = self.speak(&speech.text).unwrap_or_else(|_| {
            SpeechTiming {
                voice: Voice::Builtin,
                ..*self
            }
            .speak(&speech.text)
            .unwrap_or_default()
        });
        self.model_of(&u)
    }

    /// The metronome voice's timing (hand-computable: 0.2 s per syllable).
    pub fn syllables() -> SpeechTiming {
        SpeechTiming {
            voice: Voice::Syllables,
            ..SpeechTiming::default()
        }
    }

    /// The utterance of `text` in this timing's voice (the built-in voices never fail; flite
    /// can: the error says why).
    pub fn speak(
        &self,
        text: &[crate::language::bml::TextPart],
    ) -> Result<crate::character::voice::Utterance, String> {
        use crate::character::voice::Tts;
        match self.voice {
            Voice::Builtin => crate::character::voice::builtin::Builtin.speak(text),
            Voice::Syllables => crate::character::voice::syllables::Syllables.speak(text),
            Voice::Flite => crate::character::voice::flite::Flite::default().speak(text),
            Voice::Espeak(name) => crate::character::voice::espeak::Espeak::new(name).speak(text),
        }
    }

    /// The rigid timing of an utterance (at this rate).
    pub fn model_of(&self, u: &crate::character::voice::Utterance) -> TimingModel {
        let rate = if self.rate > 0.0 { self.rate } else { 1.0 };
        let mut keys = Vec::with_capacity(u.syncs.len() + 2);
        keys.push(SyncKey::new(
            crate::language::bml::Id::new_static("start"),
            0.0,
        ));
        for (id, t) in &u.syncs {
            keys.push(SyncKey::new(id.clone(), t / rate));
        }
        let end = u.end / rate;
        keys.push(SyncKey::new(
            crate::language::bml::Id::new_static("end"),
            end,
        ));
        let flexibility = if self.retimable {
            Flexibility::Stretchable {
                min_duration: end / RETIME_RANGE,
                max_duration: end * RETIME_RANGE,
            }
        } else {
            Flexibility::Rigid
        };
        TimingModel {
            keys,
            flexibility,
            persistent: false,
        }
    }
}

/// The built-in models for every BML kind (timing only; the realizing engines refine them).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct DefaultTimingModels {
    /// Speech timing.
    pub speech: SpeechTiming,
}

const GESTURE: &[(&str, f64)] = &[
    ("start", 0.0),
    ("ready", 0.3),
    ("strokeStart", 0.4),
    ("stroke", 0.5),
    ("strokeEnd", 0.6),
    ("relax", 0.8),
    ("end", 1.0),
];
const POINTING: &[(&str, f64)] = &[
    ("start", 0.0),
    ("ready", 0.5),
    ("strokeStart", 0.6),
    ("stroke", 0.8),
    ("strokeEnd", 1.2),
    ("relax", 1.5),
    ("end", 2.0),
];
/// One nod or shake; `repetition` multiplies it.
const HEAD: &[(&str, f64)] = &[
    ("start", 0.0),
    ("ready", 0.1),
    ("strokeStart", 0.15),
    ("stroke", 0.3),
    ("strokeEnd", 0.45),
    ("relax", 0.5),
    ("end", 0.6),
];
const GAZE: &[(&str, f64)] = &[("start", 0.0), ("ready", 0.4), ("relax", 1.6), ("end", 2.0)];
const POSTURE: &[(&str, f64)] = &[("start", 0.0), ("ready", 1.0), ("relax", 2.0), ("end", 3.0)];
const FACE: &[(&str, f64)] = &[
    ("start", 0.0),
    ("attackPeak", 0.3),
    ("relax", 1.2),
    ("end", 1.5),
];

/// A head motion repeated `strokes` times: the first nod as [`HEAD`], each further stroke
/// (`stroke:1` …, as OpenBMLParser names them) one nod's cycle (`relax` − `start`, 0.5 s) after
/// the one before, and the last one's retraction after them; preparation and retraction
/// limited as one nod's are.
fn head(strokes: u32) -> TimingModel {
    let one = limited(HEAD, 1.0);
    if strokes <= 1 {
        return one;
    }
    let at = |name: &str| one.keys[one.key(name).expect("a head key")].at;
    let (stroke, cycle) = (
        one.key("stroke").expect("a stroke"),
        at("relax") - at("start"),
    );
    let extra = cycle * f64::from(strokes - 1);
    let mut keys = one.keys[..=stroke].to_vec();
    keys.extend((1..strokes).map(|n| {
        SyncKey::new(
            crate::language::bml::stroke_name(n),
            at("stroke") + cycle * f64::from(n),
        )
    }));
    keys.extend(one.keys[stroke + 1..].iter().map(|k| SyncKey {
        at: k.at + extra,
        ..k.clone()
    }));
    TimingModel { keys, ..one }
}

/// A stretchable model of `keys` whose preparation (start to `ready`; for a face, to
/// `attackPeak`) and retraction (`relax` to `end`) last at most `max` seconds: a hand, head or
/// gaze gets to where it is going in about a second, however far apart the constraints put the
/// behaviour's keys. What is left goes into the holds (`ready` to `strokeStart`, `strokeEnd` to
/// `relax`), which have no limit.
fn limited(keys: &[(&'static str, f64)], max: f64) -> TimingModel {
    TimingModel::stretchable(keys).with_phase_limits(&[
        ("ready", max),
        ("attackPeak", max),
        ("end", max),
    ])
}

impl DefaultTimingModels {
    /// The default models with the metronome voice for speech (see [`SpeechTiming::syllables`]):
    /// schedules that can be worked out by hand.
    pub fn syllable_timed() -> Self {
        DefaultTimingModels {
            speech: SpeechTiming::syllables(),
        }
    }
}

impl TimingModels for DefaultTimingModels {
    fn model(&self, b: &Behaviour) -> Option<TimingModel> {
        let se = |d: f64| TimingModel::stretchable(&[("start", 0.0), ("end", d)]);
        Some(match &b.kind {
            BehaviourKind::Speech(s) => self.speech.model(s),
            BehaviourKind::Text(s) => {
                // shown text may be stretched, unlike synthesized speech
                let mut m = self.speech.model(s);
                m.flexibility = Flexibility::Stretchable {
                    min_duration: MIN_DURATION,
                    max_duration: f64::INFINITY,
                };
                m
            }
            BehaviourKind::Gesture(_) | BehaviourKind::ProcAnimationGesture(_) => {
                limited(GESTURE, 1.0)
            }
            BehaviourKind::Pointing(_) => limited(POINTING, 1.5),
            BehaviourKind::Head(_) => head(b.strokes()),
            BehaviourKind::Gaze(_) => limited(GAZE, 1.5),
            BehaviourKind::Posture(_) => limited(POSTURE, 3.0),
            BehaviourKind::Face(_)
            | BehaviourKind::FaceLexeme(_)
            | BehaviourKind::FaceFacs(_)
            | BehaviourKind::FaceMorph(_) => limited(FACE, 3.0),
            BehaviourKind::GazeShift(_)
            | BehaviourKind::HeadDirectionShift { .. }
            | BehaviourKind::FaceShift(_) => se(1.0),
            BehaviourKind::PostureShift(_) => se(2.0),
            // a walk of about 3 m (the locomotion engine predicts each walk from its path)
            BehaviourKind::Locomotion(_) => TimingModel::stretchable(&[
                ("start", 0.0),
                ("ready", 1.0),
                ("relax", 2.4),
                ("end", 3.4),
            ]),
            BehaviourKind::Wait(w) => se(w.max_wait.filter(|d| *d > 0.0).unwrap_or(1.0)),
            BehaviourKind::Interrupt(_) | BehaviourKind::Activate(_) => {
                TimingModel::new(&[("start", 0.0), ("end", INSTANT)], Flexibility::Rigid)
            }
            // instant unless its end is constrained: then the change spans start to end
            BehaviourKind::ParameterValueChange(_) => se(INSTANT),
            BehaviourKind::AudioFile { .. } => {
                // the file's length decides; until the audio engine reads it, one second
                TimingModel::new(&[("start", 0.0), ("end", 1.0)], Flexibility::Rigid)
            }
            BehaviourKind::ProcAnimation(_)
            | BehaviourKind::Keyframe(_)
            | BehaviourKind::Noise(_)
            | BehaviourKind::Transition(_) => se(1.0),
            BehaviourKind::Controller(_) => {
                let mut m = se(1.0);
                m.persistent = true;
                m
            }
            BehaviourKind::Unknown(_) => return None,
        })
    }
}

#[cfg(test)]
mod tests;
