//! A speech's sound as it streams in (a realtime voice, a cloud TTS answering in chunks): the
//! host pushes chunks of samples, with the chunk's timing marks if the voice gives them, and
//! ends the stream. An [`AudioStream`] is a shared handle: the host keeps one, the speech engine
//! plays from another, and the realizer makes it an anticipator (`anticipators:NAME:start`,
//! `…:end`) that the speech's own syncs hang on, from its [`predict`](AudioStream::predict)
//! and [`update`](AudioStream::update). `start` is the first time the realizer looks after the first chunk came (until then it is
//! predicted an hour ahead, so the speech waits); `end` is predicted as the sound received so
//! far plus [`LOOKAHEAD`], never before the present, or the length the speech expects of its
//! text ([`expect`](AudioStream::expect)) if that is longer, and revised with every chunk, until
//! the stream ends: then it is the sound's end. A stream that gets no chunk for [`TIMEOUT`] seconds
//! is taken as ended. Marks are Polly speech marks or a word list (`voice::marks`), their times
//! counted from the stream's first sample.

use std::sync::{Arc, Mutex, PoisonError};

use super::marks::{self, Marks};
use super::Audio;

/// How much more sound an open stream is expected to bring than it has (seconds).
pub const LOOKAHEAD: f64 = 0.5;

/// How long a stream may go without a chunk before it is taken as ended (seconds).
pub const TIMEOUT: f64 = 10.0;

/// Where the start of a stream that has no sound yet is predicted (seconds ahead).
pub const NOT_YET: f64 = 3600.0;

/// Most samples a stream holds (10 minutes at 48 kHz).
pub const MAX_SAMPLES: usize = 48_000 * 600;

#[derive(Debug, Default)]
struct State {
    audio: Option<Arc<Audio>>,
    marks: Marks,
    /// Marks text received (re-read whole with every chunk: the forms are line-based).
    marks_text: String,
    /// Global time of the first tick that saw sound.
    started: Option<f64>,
    /// Whether sound has been pushed since the last update.
    fresh: bool,
    ended: bool,
    /// The clock at the last update and at the last chunk.
    now: f64,
    last_chunk: f64,
    /// How many lookaheads an open stream's end was predicted past its sound, at the last
    /// update.
    steps: u32,
    /// The length of sound expected (seconds), if the speech knows its text.
    expected: Option<f64>,
}

/// A stream of one speech's sound (see the module documentation). Clones share the stream.
#[derive(Debug, Clone)]
pub struct AudioStream {
    name: String,
    state: Arc<Mutex<State>>,
}

impl AudioStream {
    /// A new, empty stream called `name` (what `bmlt:stream` and `anticipators:NAME` name).
    pub fn new(name: &str) -> AudioStream {
        AudioStream {
            name: name.to_string(),
            state: Arc::default(),
        }
    }

    fn state(&self) -> std::sync::MutexGuard<'_, State> {
        self.state.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// The stream's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Adds `pcm` (mono, 16-bit, at `rate`) and the chunk's `marks` (Polly speech marks or a
    /// word list, times from the stream's first sample). The error says why a chunk is refused
    /// (a rate other than the first chunk's, the stream ended or full, marks that do not parse).
    pub fn push(&self, pcm: &[i16], rate: u32, marks: Option<&str>) -> Result<(), String> {
        let mut s = self.state();
        let name = &self.name;
        if s.ended {
            return Err(format!("stream '{name}' has ended"));
        }
        if rate == 0 {
            return Err(format!("stream '{name}': a rate of 0"));
        }
        if let Some(m) = marks.filter(|m| !m.trim().is_empty()) {
            let mut text = s.marks_text.clone();
            text.push_str(m.trim_end());
            text.push('\n');
            s.marks = marks::parse(&text, &format!("stream '{name}'"))?;
            s.marks_text = text;
        }
        let mut audio = match s.audio.take() {
            Some(a) if a.rate != rate => {
                let first = a.rate;
                s.audio = Some(a);
                return Err(format!(
                    "stream '{name}': a chunk at {rate} Hz after chunks at {first} Hz"
                ));
            }
            Some(a) => Arc::unwrap_or_clone(a),
            None => Audio {
                rate,
                samples: Vec::new(),
            },
        };
        if audio.samples.len() + pcm.len() > MAX_SAMPLES {
            s.audio = Some(Arc::new(audio));
            return Err(format!("stream '{name}': more than {MAX_SAMPLES} samples"));
        }
        audio.samples.extend_from_slice(pcm);
        s.audio = Some(Arc::new(audio));
        s.fresh = true;
        s.last_chunk = s.now;
        Ok(())
    }

    /// Says how long the whole sound is expected to be (a speech's estimate from its text):
    /// until the stream ends its end is predicted no earlier than that after its start.
    pub fn expect(&self, seconds: f64) {
        let mut s = self.state();
        if seconds.is_finite() && seconds > 0.0 && s.expected != Some(seconds) {
            s.expected = Some(seconds);
            s.fresh = true;
        }
    }

    /// Ends the stream: its end is its sound's end.
    pub fn end(&self) {
        let mut s = self.state();
        s.ended = true;
        s.fresh = true;
    }

    /// The sound received so far.
    pub fn audio(&self) -> Option<Arc<Audio>> {
        self.state().audio.clone()
    }

    /// The marks received so far.
    pub fn marks(&self) -> Marks {
        self.state().marks.clone()
    }

    /// Whether the stream ended (by [`end`](Self::end) or by [`TIMEOUT`]).
    pub fn ended(&self) -> bool {
        Self::closed(&self.state())
    }

    /// Seconds of sound received.
    fn received(s: &State) -> f64 {
        s.audio
            .as_ref()
            .map_or(0.0, |a| a.samples.len() as f64 / f64::from(a.rate.max(1)))
    }

    /// How many lookaheads past its sound an open stream's end is predicted: enough to stay a
    /// tenth of a second ahead of the present.
    fn steps(s: &State, start: f64) -> u32 {
        let short = s.now + 0.1 - (start + Self::received(s));
        (short / LOOKAHEAD).ceil().clamp(1.0, 1e6) as u32
    }

    /// Whether the stream ended or timed out.
    fn closed(s: &State) -> bool {
        s.ended || (s.started.is_some() && s.now - s.last_chunk > TIMEOUT)
    }
}

impl AudioStream {
    /// The predicted global time of `start` or `end` (see the module documentation).
    pub fn predict(&self, sync: &str) -> Option<f64> {
        let s = self.state();
        let start = s.started.unwrap_or(s.now + NOT_YET);
        match sync {
            "start" => Some(start),
            "end" => {
                let sound = start + Self::received(&s);
                Some(if Self::closed(&s) {
                    sound.max(start + 1e-3)
                } else {
                    let ahead = sound + f64::from(Self::steps(&s, start)) * LOOKAHEAD;
                    ahead.max(start + s.expected.unwrap_or(0.0))
                })
            }
            _ => None,
        }
    }

    /// Brings the predictions to global time `now` (the first call that finds sound starts
    /// the stream); whether they changed.
    pub fn update(&self, now: f64) -> bool {
        let mut s = self.state();
        let was_closed = Self::closed(&s);
        s.now = now;
        // the first chunk came after the clock read `last_chunk`: the stream starts at the
        // first later time the realizer looks (not at a catch-up look back at that time, which
        // would put its first frame of sound in the past)
        if s.started.is_none() && s.audio.is_some() && now > s.last_chunk {
            s.started = Some(now);
            s.last_chunk = now;
        }
        let steps = s.started.map_or(0, |start| Self::steps(&s, start));
        let changed = s.fresh || steps != s.steps || Self::closed(&s) != was_closed;
        s.steps = steps;
        s.fresh = false;
        changed
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_stream_starts_with_its_first_chunk_and_ends_with_its_sound() {
        let s = AudioStream::new("reply");
        assert!(!s.update(1.0));
        assert_eq!(s.predict("start"), Some(1.0 + NOT_YET));
        s.push(&[0; 8000], 8000, None).unwrap();
        // a look back at the clock the chunk came after does not start it in the past
        s.update(1.0);
        assert_eq!(s.predict("start"), Some(1.0 + NOT_YET));
        assert!(s.update(1.5));
        assert_eq!(s.predict("start"), Some(1.5));
        assert_eq!(s.predict("end"), Some(1.5 + 1.0 + LOOKAHEAD));
        s.push(
            &[0; 4000],
            8000,
            Some(r#"{"time":100,"type":"word","value":"hi"}"#),
        )
        .unwrap();
        s.end();
        assert!(s.update(1.6));
        assert_eq!(s.predict("end"), Some(3.0));
        assert_eq!(s.marks().words[0].start, 0.1);
        assert!(s.push(&[0; 10], 8000, None).unwrap_err().contains("ended"));
    }

    #[test]
    fn an_expected_length_holds_the_end_until_the_sound_passes_it_or_ends() {
        let s = AudioStream::new("reply");
        s.expect(3.0);
        s.push(&[0; 8000], 8000, None).unwrap();
        s.update(0.5);
        assert_eq!(
            s.predict("end"),
            Some(3.5),
            "the text's length, not 1 s + lookahead"
        );
        s.push(&[0; 24000], 8000, None).unwrap();
        assert!(s.update(0.6));
        assert_eq!(
            s.predict("end"),
            Some(0.5 + 4.0 + LOOKAHEAD),
            "the sound passed it"
        );
        s.end();
        s.update(0.7);
        assert_eq!(s.predict("end"), Some(4.5), "ended: the sound's end");
    }

    #[test]
    fn bad_chunks_are_refused_and_a_silent_stream_times_out() {
        let s = AudioStream::new("r");
        s.push(&[0; 800], 8000, None).unwrap();
        assert!(s
            .push(&[0; 800], 16000, None)
            .unwrap_err()
            .contains("16000 Hz"));
        assert!(s.push(&[0; 8], 8000, Some("{\"time\":")).is_err());
        s.update(0.1);
        assert!(!s.ended());
        s.update(TIMEOUT + 0.5);
        assert!(s.ended());
        assert_eq!(s.predict("end"), Some(0.2));
    }
}
