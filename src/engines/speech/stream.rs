//! A speech that plays a stream (`bmlt:stream="NAME"`): its sound and lips come from the chunks
//! the host pushes, planned again whenever one comes, and its inline syncs follow the words of
//! the marks as they come. A sync whose next word has been marked (or any, once the stream has
//! ended) is at that word's start in the sound; one still unknown is where the built-in voice
//! would say it, at the pace of the words known so far, never before now nor after the
//! speech's predicted end (so that none passes before its word can have come). The stream is
//! told the length the built-in voice gives the text, so that its end is not predicted before
//! the text can have been said. The speech's start and end are the stream anticipator's; they
//! are left to it.

use super::{Speaking, SpeechEngine};
use crate::character::voice::stream::AudioStream;
use crate::character::voice::{Phone, Tts};
use crate::engines::interface::{Revising, Revision, SyncTimes};
use crate::language::bml::{Behaviour, TextPart};

/// The stream a speech plays (`bmlt:stream`), if it names one.
pub(super) fn stream_name(b: &Behaviour) -> Option<&str> {
    (b.foreign_attrs.iter())
        .find(|a| a.ns == crate::language::bml::NS_BMLT && a.name == "stream")
        .map(|a| a.value.trim())
}

/// A speech playing a stream: the stream, the text, how many samples the lips were planned
/// for (planned again when more come), and where its inline syncs are in the sound as far as
/// the marks tell, else as the built-in voice would say the text.
#[derive(Debug, Clone)]
pub(super) struct Streamed {
    pub(super) stream: AudioStream,
    text: Vec<TextPart>,
    planned: usize,
    /// Each inline sync's time in the sound, if its word has come.
    known: Vec<Option<f64>>,
    /// As the built-in voice says the text: each inline sync's time, each word's start, the end.
    estimate: Estimate,
    /// The voice's pace against the built-in voice's (from the words marked so far; 1 before).
    pace: f64,
}

/// Times as the built-in voice says a text (seconds from its start).
#[derive(Debug, Clone, Default)]
struct Estimate {
    syncs: Vec<f64>,
    words: Vec<f64>,
    end: f64,
}

impl Streamed {
    /// A speech of `text` playing `stream`, which is told how long the text is expected to be.
    pub(super) fn new(stream: AudioStream, text: Vec<TextPart>) -> Self {
        let said = crate::character::voice::builtin::Builtin
            .speak(&text)
            .unwrap_or_default();
        let estimate = Estimate {
            syncs: said.syncs.iter().map(|s| s.1).collect(),
            words: said.words.iter().map(|w| w.start).collect(),
            end: said.end,
        };
        stream.expect(estimate.end);
        Streamed {
            stream,
            text,
            planned: 0,
            known: vec![None; estimate.syncs.len()],
            estimate,
            pace: 1.0,
        }
    }

    /// The lips for the sound received so far, if more came (or the stream ended) since they
    /// were planned; the inline syncs' times are found again with them.
    pub(super) fn replan(&mut self) -> Option<Vec<Phone>> {
        let audio = self.stream.audio()?;
        let ended = self.stream.ended();
        // (a count that cannot be one of samples marks the end as planned)
        let planned = if ended {
            usize::MAX
        } else {
            audio.samples.len()
        };
        if planned == self.planned {
            return None;
        }
        self.planned = planned;
        let marks = self.stream.marks();
        let marked = marks.words.len();
        // the pace of the last word marked against the built-in voice's, and the length
        // expected at that pace
        let paced = (marks.words.last()).zip(self.estimate.words.get(marked.wrapping_sub(1)));
        if let Some((said, built_in)) = paced.filter(|(_, b)| **b > 0.2) {
            self.pace = said.start / built_in;
            self.stream.expect(self.estimate.end * self.pace);
        }
        let marks = (!marks.words.is_empty() || !marks.visemes.is_empty()).then_some(&marks);
        let u = crate::character::voice::recorded::utterance(&self.text, audio, marks).0;
        self.known = (u.syncs.iter())
            .map(|&(_, t)| {
                // the word after the sync: its index is the number of words before it
                let next = u.words.iter().filter(|w| w.start < t - 1e-6).count();
                (ended || (next < marked && next < u.words.len())).then_some(t)
            })
            .collect();
        Some(u.phones)
    }

    /// The speech's new sync times at `now`, if they moved: the start and end as `held`, the
    /// inline syncs from what is known, the others where the built-in voice would say them
    /// at the pace of the words known so far (passed ones as they were), all in order.
    fn revised(&self, held: &SyncTimes, now: f64) -> Option<Vec<f64>> {
        if held.len() != self.known.len() + 2 {
            return None; // (a filler's relax: not a stream's)
        }
        let (start, end) = (held[0].1, held[held.len() - 1].1);
        if now < start {
            return None;
        }
        let mut times = vec![start];
        for (i, known) in self.known.iter().enumerate() {
            let held_t = held[i + 1].1;
            let earliest = times.last().copied().unwrap_or(start);
            let t = match known {
                _ if held_t < now - 1e-9 => held_t, // passed (or as good as)
                Some(t) => (start + t).max(now),
                // (not yet said: not before now, and before the end)
                None => (start + self.estimate.syncs[i] * self.pace)
                    .max(now)
                    .min(end),
            };
            times.push(t.max(earliest));
        }
        times.push(end);
        let moved = (times.iter().zip(held)).any(|(t, h)| (t - h.1).abs() > 1e-9);
        moved.then_some(times)
    }
}

impl Revising for SpeechEngine {
    /// The streamed speeches whose inline syncs moved with the chunks that came.
    fn take_revisions(&mut self, now: f64) -> Vec<Revision> {
        let mut revisions = Vec::new();
        for (held, u, key) in self.units.keyed_mut() {
            let Some(s) = u.streamed.as_mut() else {
                continue;
            };
            if let Some(phones) = s.replan() {
                u.phones = phones;
            }
            if let Some(times) = s.revised(held, now) {
                revisions.push(Revision {
                    unit: key.clone(),
                    times,
                    others_follow: true,
                });
            }
        }
        revisions
    }
}

/// The unit data of a speech that plays `stream` (none open: a silent speech).
pub(super) fn speaking(stream: Option<AudioStream>, text: Vec<TextPart>) -> Speaking {
    Speaking {
        volume: super::DEFAULT_VOLUME,
        rate: 1.0,
        audio: None,
        phones: Vec::new(),
        anchors: Vec::new(),
        knots: Vec::new(),
        streamed: stream.map(|s| Streamed::new(s, text)),
    }
}
