//! The voice: a text-to-speech interface ([`Tts`]) that turns a speech's text with inline syncs
//! into phones with times, word times, sync times and optional audio; the built-in TTS
//! ([`builtin`]: English letter-to-sound rules, a lexicon of common words, a duration model; no
//! audio); flite run as a program ([`flite`]: its phone timings and its sound); espeak-ng run as
//! a program ([`espeak`]: its sound in its many languages, its phonemes timed to it); a metronome
//! voice whose timing can be worked out by hand ([`syllables`]); a speech's own sound with its
//! timing marks ([`recorded`], [`marks`], and [`listen`] to time a text to a sound without
//! marks); and lip sync ([`lipsync`]: phones to visemes with coarticulation). The scheduler
//! keeps a speech rigid with the times its voice gives.

pub mod builtin;
pub mod espeak;
pub mod flite;
pub mod ipa;
pub mod lipsync;
pub mod listen;
pub mod marks;
mod pieces;
pub mod recorded;
pub mod stream;
pub mod syllables;

use crate::language::bml::{Id, TextPart};

/// A phone of an utterance: its ARPAbet symbol (without stress digit; `pau` for a pause) and
/// when it is spoken (seconds from the speech's start).
#[derive(Debug, Clone, PartialEq)]
pub struct Phone {
    /// ARPAbet symbol, e.g. `AA`, `P`, `pau`.
    pub symbol: &'static str,
    /// Start (seconds from the speech's start).
    pub start: f64,
    /// End.
    pub end: f64,
}

impl Phone {
    /// The middle of the phone.
    pub fn centre(&self) -> f64 {
        (self.start + self.end) / 2.0
    }

    /// Whether the phone is a vowel.
    pub fn is_vowel(&self) -> bool {
        builtin::is_vowel(self.symbol)
    }
}

/// A word of an utterance and when it is spoken.
#[derive(Debug, Clone, PartialEq)]
pub struct Word {
    /// The word as written (without punctuation).
    pub text: String,
    /// Start (seconds from the speech's start).
    pub start: f64,
    /// End.
    pub end: f64,
}

/// Sound samples live in [`crate::character::sound`], below the voices that make them.
pub use crate::character::sound::Audio;

/// What a TTS makes of a speech: phones, words, the inline syncs' times, the end, and audio if
/// it synthesizes sound.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Utterance {
    /// Every phone in order, pauses included (`pau`).
    pub phones: Vec<Phone>,
    /// Every word in order.
    pub words: Vec<Word>,
    /// Each inline sync with its time (the start of the word after it, or the end).
    pub syncs: Vec<(Id, f64)>,
    /// When the speech ends (seconds from its start).
    pub end: f64,
    /// The sound, if synthesized.
    pub audio: Option<std::sync::Arc<Audio>>,
}

/// A text-to-speech engine.
pub trait Tts: Send + Sync + std::fmt::Debug {
    /// A short name (`builtin`, `flite`).
    fn name(&self) -> &'static str;

    /// The utterance of `text` (words and inline syncs). The error says what failed (a missing
    /// program, text it cannot say).
    fn speak(&self, text: &[TextPart]) -> Result<Utterance, String>;
}
