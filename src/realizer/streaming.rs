//! Sound the host streams in: [`Realizer::open_stream`] makes an `AudioStream`
//! (`voice::stream`), registers it as the anticipator of its name for the character (so that a
//! speech's `start="anticipators:NAME:start" end="anticipators:NAME:end"` follow it) and hands it
//! to the character's engines that play streams (the speech engine, for `bmlt:stream="NAME"`).

use super::Realizer;
use crate::plan::anticipator::Anticipator;
use crate::voice::stream::AudioStream;

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

impl Realizer {
    /// Opens a stream called `name` for `character` (None: blocks without a characterId) and
    /// returns the host's handle: push chunks with `AudioStream::push`, end it with
    /// `AudioStream::end`. A speech plays it with `bmlt:stream="NAME"`, timed by
    /// `start="anticipators:NAME:start" end="anticipators:NAME:end"`. Opening a name again
    /// replaces the stream.
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
        stream
    }
}
