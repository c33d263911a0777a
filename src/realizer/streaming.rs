//! Sound the host streams in: [`Realizer::open_stream`] makes an `AudioStream`
//! (`voice::stream`), registers it as the anticipator of its name for the character (so that a
//! speech's `start="anticipators:NAME:start" end="anticipators:NAME:end"` follow it), hands it
//! to the character's engines that play streams (the speech engine, for `bmlt:stream="NAME"`)
//! and keeps it by name for [`Realizer::push_audio`] and [`Realizer::end_audio`]. A port that
//! speaks in lines (`bmlr serve`) takes the same three calls as one-line JSON messages
//! ([`Realizer::stream_message`], documented in `docs/voice.md`).

use base64::Engine as _;
use serde::Deserialize;

use super::Realizer;
use crate::character::voice::stream::AudioStream;
use crate::language::feedback::KnownWarning;
use crate::planning::plan::anticipator::Anticipator;

/// An audio stream as an anticipator (`start`, `end`).
struct StreamAnticipator(AudioStream);

impl Anticipator for StreamAnticipator {
    fn id(&self) -> &str {
        self.0.name()
    }

    fn predict(&self, sync: &str) -> Option<f64> {
        self.0.predict(sync)
    }

    fn update(&mut self, now: f64) -> bool {
        self.0.update(now)
    }

    fn announces(&self) -> bool {
        true
    }
}

/// One stream message of a line port: exactly one of the three calls.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct Message {
    open_stream: Option<String>,
    character: Option<String>,
    push_audio: Option<String>,
    rate: Option<u32>,
    /// 16-bit little-endian mono samples, base64.
    pcm: Option<String>,
    marks: Option<String>,
    end_audio: Option<String>,
}

impl Realizer {
    /// Opens a stream called `name` for `character` (None: blocks without a characterId) and
    /// returns the host's handle: push chunks with `AudioStream::push` (or
    /// [`push_audio`](Self::push_audio)), end it with `AudioStream::end` (or
    /// [`end_audio`](Self::end_audio)). A speech plays it with `bmlt:stream="NAME"`, timed by
    /// `start="anticipators:NAME:start" end="anticipators:NAME:end"`; open the stream before
    /// performing that block. Opening a name again replaces the stream.
    pub fn open_stream(&mut self, character: Option<&str>, name: &str) -> AudioStream {
        let stream = AudioStream::new(name);
        stream.update(self.now);
        let manager = self.manager(character.map(str::to_string));
        manager.add_anticipator(Box::new(StreamAnticipator(stream.clone())));
        for engine in manager.registry_mut().engines_mut() {
            if let Some(streams) = engine.as_streams() {
                streams.add_stream(stream.clone());
            }
        }
        self.streams.insert(name.to_string(), stream.clone());
        stream
    }

    /// The open stream called `name`.
    fn stream(&self, name: &str) -> Result<&AudioStream, String> {
        self.streams.get(name).ok_or_else(|| {
            let open: Vec<&String> = self.streams.keys().collect();
            format!("no stream '{name}' is open (open: {open:?}); open it first")
        })
    }

    /// Adds a chunk to the stream `name`: `pcm` mono 16-bit samples at `rate` Hz (every chunk
    /// of a stream at the same rate) and the chunk's `marks` (Polly speech marks or a word
    /// list, times from the stream's first sample). The error says why it was refused (no such
    /// stream, another rate, the stream ended or full, marks that do not parse).
    pub fn push_audio(
        &mut self,
        name: &str,
        pcm: &[i16],
        rate: u32,
        marks: Option<&str>,
    ) -> Result<(), String> {
        self.stream(name)?.push(pcm, rate, marks)
    }

    /// Ends the stream `name`: the speech playing it ends with its sound.
    pub fn end_audio(&mut self, name: &str) -> Result<(), String> {
        self.stream(name)?.end();
        Ok(())
    }

    /// Carries out one stream message of a line port, a JSON object on one line:
    /// `{"open_stream": NAME, "character": ID}` (character optional),
    /// `{"push_audio": NAME, "rate": HZ, "pcm": BASE64, "marks": TEXT}` (samples 16-bit
    /// little-endian mono; marks optional), or `{"end_audio": NAME}`. A message that does not
    /// parse is a `PARSING_FAILURE` warning, one the stream refuses an `EXECUTION_FAILURE`
    /// warning, each naming `source` and saying why; the error is returned too.
    pub fn stream_message(&mut self, source: &str, line: &str) -> Result<(), String> {
        self.message(source, line, None)
    }

    /// [`stream_message`](Self::stream_message) from a port that belongs to one character
    /// (a broker's topic of `character`; None: the default character's): a stream it opens
    /// is that character's, and a message naming another character is refused.
    pub fn stream_message_on(
        &mut self,
        source: &str,
        line: &str,
        character: Option<&str>,
    ) -> Result<(), String> {
        self.message(source, line, Some(character))
    }

    /// A stream message from a port of any character (`port` None) or of one.
    fn message(
        &mut self,
        source: &str,
        line: &str,
        port: Option<Option<&str>>,
    ) -> Result<(), String> {
        let outcome = match serde_json::from_str::<Message>(line) {
            Err(e) => Err((
                KnownWarning::ParsingFailure,
                format!("not a stream message: {e}"),
            )),
            Ok(mut m) => match port {
                Some(own) if m.character.is_some() && m.character.as_deref() != own => Err((
                    KnownWarning::ExecutionFailure,
                    format!(
                        "a stream for character '{}' came on the port of '{}'",
                        m.character.unwrap_or_default(),
                        own.unwrap_or("(the default character)")
                    ),
                )),
                _ => {
                    if let Some(own) = port {
                        m.character = own.map(str::to_string);
                    }
                    self.carry_out(m)
                        .map_err(|e| (KnownWarning::ExecutionFailure, e))
                }
            },
        };
        outcome.map_err(|(kind, why)| {
            let text = format!("{source}: {why}");
            self.warn_input(kind, text.clone());
            text
        })
    }

    fn carry_out(&mut self, m: Message) -> Result<(), String> {
        match (m.open_stream, m.push_audio, m.end_audio) {
            (Some(name), None, None) if name.is_empty() => Err("open_stream: an empty name".into()),
            (Some(name), None, None) => {
                self.open_stream(m.character.as_deref(), &name);
                Ok(())
            }
            (None, Some(name), None) => {
                let rate = m.rate.ok_or("push_audio: no \"rate\"")?;
                let bytes = (base64::engine::general_purpose::STANDARD)
                    .decode(m.pcm.as_deref().unwrap_or(""))
                    .map_err(|e| format!("push_audio: \"pcm\" is not base64: {e}"))?;
                if bytes.len() % 2 != 0 {
                    return Err("push_audio: \"pcm\" holds an odd number of bytes".into());
                }
                let pcm: Vec<i16> = (bytes.chunks_exact(2))
                    .map(|b| i16::from_le_bytes([b[0], b[1]]))
                    .collect();
                self.push_audio(&name, &pcm, rate, m.marks.as_deref())
            }
            (None, None, Some(name)) => self.end_audio(&name),
            _ => Err(
                "a stream message holds exactly one of \"open_stream\", \"push_audio\" and \"end_audio\""
                    .into(),
            ),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::language::feedback::Feedback;

    fn warnings(r: &mut Realizer) -> Vec<String> {
        (r.tick(r.now).feedback.into_iter())
            .filter_map(|f| match f {
                Feedback::Warning(w) => Some(format!("{}: {}", w.kind.as_str(), w.text)),
                _ => None,
            })
            .collect()
    }

    #[test]
    fn stream_messages_open_push_and_end_a_stream() {
        let mut r = Realizer::new().with_idle(false);
        r.stream_message("<stdin>", r#"{"open_stream": "reply"}"#)
            .unwrap();
        // 3 samples: 1, -2, 256
        r.stream_message(
            "<stdin>",
            r#"{"push_audio": "reply", "rate": 16000, "pcm": "AQD+/wAB"}"#,
        )
        .unwrap();
        let audio = r.streams["reply"].audio().unwrap();
        assert_eq!(audio.samples, [1, -2, 256]);
        r.stream_message("<stdin>", r#"{"end_audio": "reply"}"#)
            .unwrap();
        assert!(r.streams["reply"].ended());
        assert!(warnings(&mut r).is_empty());
    }

    #[test]
    fn a_port_of_one_character_opens_its_streams_and_refuses_anothers() {
        let mut r = Realizer::new().with_idle(false);
        r.stream_message_on("t", r#"{"open_stream": "a"}"#, Some("bob"))
            .unwrap();
        let e = (r.stream_message_on(
            "t",
            r#"{"open_stream": "b", "character": "ann"}"#,
            Some("bob"),
        ))
        .unwrap_err();
        assert!(e.contains("'ann' came on the port of 'bob'"), "{e}");
        assert!(!r.streams.contains_key("b"));
        let w = warnings(&mut r);
        assert!(
            w.len() == 1 && w[0].starts_with("EXECUTION_FAILURE"),
            "{w:?}"
        );
        // the stream is bob's: a speech of bob's plays it (its start is the stream's)
        assert!(
            r.character("bob").is_some(),
            "the stream made bob's manager"
        );
    }

    #[test]
    fn bad_stream_messages_are_warnings_that_say_why() {
        let mut r = Realizer::new();
        for (line, kind, why) in [
            (
                "{\"open_stream\": ",
                "PARSING_FAILURE",
                "not a stream message",
            ),
            (
                r#"{"push": "x"}"#,
                "PARSING_FAILURE",
                "unknown field `push`",
            ),
            (
                r#"{"end_audio": "x"}"#,
                "EXECUTION_FAILURE",
                "no stream 'x' is open",
            ),
            (r#"{}"#, "EXECUTION_FAILURE", "exactly one of"),
            (r#"{"open_stream": ""}"#, "EXECUTION_FAILURE", "empty name"),
        ] {
            let e = r.stream_message("<stdin>:3", line).unwrap_err();
            assert!(e.contains(why) && e.starts_with("<stdin>:3: "), "{e}");
            let w = warnings(&mut r);
            assert!(w.len() == 1 && w[0].starts_with(kind), "{w:?}");
        }
        r.stream_message("s", r#"{"open_stream": "a"}"#).unwrap();
        for (line, why) in [
            (r#"{"push_audio": "a", "pcm": ""}"#, "no \"rate\""),
            (
                r#"{"push_audio": "a", "rate": 8000, "pcm": "!!"}"#,
                "not base64",
            ),
            (r#"{"push_audio": "a", "rate": 8000, "pcm": "AQA="}"#, ""),
            (
                r#"{"push_audio": "a", "rate": 8000, "pcm": "AQ=="}"#,
                "odd number",
            ),
            (
                r#"{"push_audio": "a", "rate": 9000, "pcm": "AQA="}"#,
                "9000 Hz after",
            ),
        ] {
            match r.stream_message("s", line) {
                Ok(()) => assert!(why.is_empty(), "{line} was taken"),
                Err(e) => assert!(!why.is_empty() && e.contains(why), "{e}"),
            }
        }
    }
}
