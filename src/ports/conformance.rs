//! This realizer as a RealizerTester port (`realizer_tests::TestPort`): in process on the virtual
//! clock, so the conformance suite runs fast and deterministically inside `cargo test` and
//! `bmlr conformance`. Feedback goes through the XML codec, as it would through a real port.

use std::sync::{Arc, Mutex};

use realizer_tests::{Fixture, TestPort};

use crate::engines::default_registry;
use crate::language::feedback::{Feedback, Format};
use crate::planning::timing::{DefaultTimingModels, SpeechTiming, Voice};
use crate::realizer::Realizer;

/// A fresh [`Realizer`] per test on a virtual clock; tests of the incremental-speech fixture get
/// retimable speech.
pub struct InProcess {
    realizer: Realizer,
    lines: Arc<Mutex<Vec<String>>>,
    end_delay: f64,
    voice: Voice,
}

impl Default for InProcess {
    fn default() -> Self {
        Self::new()
    }
}

impl InProcess {
    /// A port to a new realizer.
    pub fn new() -> Self {
        let lines = Arc::new(Mutex::new(Vec::new()));
        InProcess {
            realizer: Self::realizer(&lines, 0.0, Fixture::Standard, Voice::Builtin),
            lines,
            end_delay: 0.0,
            voice: Voice::Builtin,
        }
    }

    /// Speech said by `voice` (the built-in TTS by default; `Voice::Flite` runs flite).
    pub fn with_voice(mut self, voice: Voice) -> Self {
        self.voice = voice;
        self.realizer = Self::realizer(&self.lines, self.end_delay, Fixture::Standard, voice);
        self
    }

    /// A deliberately broken realizer that reports every block end `secs` seconds late (to show
    /// that the suite catches timing regressions).
    pub fn with_late_block_ends(mut self, secs: f64) -> Self {
        self.end_delay = secs;
        self.realizer = Self::realizer(&self.lines, secs, Fixture::Standard, self.voice);
        self
    }

    fn realizer(
        lines: &Arc<Mutex<Vec<String>>>,
        end_delay: f64,
        fixture: Fixture,
        voice: Voice,
    ) -> Realizer {
        let sink = lines.clone();
        let speech = SpeechTiming {
            voice,
            retimable: fixture == Fixture::IncrementalSpeech,
            ..SpeechTiming::default()
        };
        let mut r =
            Realizer::new().with_engines(move || default_registry(DefaultTimingModels { speech }));
        r.add_listener(Box::new(move |fb: &Feedback| {
            let mut fb = fb.clone();
            if let Feedback::BlockProgress(p) = &mut fb {
                if p.sync == "end" {
                    p.global_time += end_delay;
                }
            }
            sink.lock()
                .unwrap_or_else(|e| e.into_inner())
                .push(Format::Xml.encode(&fb));
        }));
        r
    }

    fn take(&mut self) -> Vec<String> {
        std::mem::take(&mut *self.lines.lock().unwrap_or_else(|e| e.into_inner()))
    }
}

impl TestPort for InProcess {
    fn perform_bml(&mut self, bml: &str) {
        // problems are reported as warning feedback
        let _ = self.realizer.perform_bml(bml);
    }

    fn sleep(&mut self, secs: f64) -> Vec<String> {
        let now = self.realizer.now();
        self.realizer.tick(now + secs.max(0.0));
        self.take()
    }

    fn step(&mut self) -> Option<Vec<String>> {
        let next = self.realizer.next_event()?;
        self.realizer.tick(next);
        Some(self.take())
    }

    fn real_time(&self) -> bool {
        false
    }

    fn reset(&mut self, fixture: Fixture) -> Result<(), String> {
        self.realizer = Self::realizer(&self.lines, self.end_delay, fixture, self.voice);
        self.lines.lock().unwrap_or_else(|e| e.into_inner()).clear();
        Ok(())
    }
}
