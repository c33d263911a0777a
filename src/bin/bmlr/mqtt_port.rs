//! `bmlr conformance --mqtt URL`: the RealizerTester suite against a realizer reached only
//! through the broker. Blocks are published on the character's block topic, feedback is read
//! from its feedback topic; the incremental-speech tests go to another character (served by a
//! realizer with retimable speech). Each test starts with an empty REPLACE block, as over a
//! process's stdin.

use std::time::{Duration, Instant};

use bml_realizer::broker::{BrokerUrl, Inbound, Link, LinkOptions, Topics};
use realizer_tests::port::replace_setup;
use realizer_tests::{Fixture, TestPort};

/// The suite's port on a broker.
pub struct MqttPort {
    link: Link,
    topics: Topics,
    /// The characters of the standard and the incremental-speech fixtures.
    characters: [String; 2],
    running: Fixture,
}

impl MqttPort {
    /// Connects to `url` and listens to the feedback of both characters.
    pub fn connect(url: &str, prefix: &str, characters: [String; 2]) -> Result<MqttPort, String> {
        let url = BrokerUrl::parse(url)?;
        let topics = Topics::new(prefix)?;
        let subscriptions = characters.iter().map(|c| topics.feedback(c)).collect();
        let link = Link::connect(LinkOptions {
            url,
            client_id: format!("bmlr-conformance-{}", std::process::id()),
            subscriptions,
            presence: None,
            inbox: 100_000,
            start_tries: 6,
        })?;
        Ok(MqttPort {
            link,
            topics,
            characters,
            running: Fixture::Standard,
        })
    }

    fn character(&self) -> &str {
        &self.characters[usize::from(self.running == Fixture::IncrementalSpeech)]
    }

    /// The feedback of the running character heard until `deadline`, then what is already
    /// there.
    fn collect_until(&mut self, deadline: Instant) -> Vec<String> {
        let topic = self.topics.feedback(self.character());
        let mut out = Vec::new();
        let take = |i: Inbound, out: &mut Vec<String>| {
            if let Inbound::Message { topic: t, payload } = i {
                if t == topic {
                    out.push(String::from_utf8_lossy(&payload).into_owned());
                }
            }
        };
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            if left.is_zero() {
                break;
            }
            match self.link.recv_timeout(left) {
                Some(i) => take(i, &mut out),
                None => break,
            }
        }
        while let Some(i) = self.link.try_recv() {
            take(i, &mut out);
        }
        out
    }
}

impl TestPort for MqttPort {
    fn perform_bml(&mut self, bml: &str) {
        let topic = self.topics.bml(self.character());
        self.link.publish(&topic, bml.as_bytes().to_vec(), false);
        self.link.flush();
    }

    fn sleep(&mut self, secs: f64) -> Vec<String> {
        self.collect_until(Instant::now() + Duration::from_secs_f64(secs.max(0.0)))
    }

    fn step(&mut self) -> Option<Vec<String>> {
        Some(self.sleep(0.01))
    }

    fn real_time(&self) -> bool {
        true
    }

    fn reset(&mut self, fixture: Fixture) -> Result<(), String> {
        self.running = fixture;
        if replace_setup(self) {
            return Ok(());
        }
        Err(format!(
            "the realizer of '{}' did not end the REPLACE setup block (is one serving it on the broker?)",
            self.character()
        ))
    }
}
