//! `bmlr conformance --mqtt URL` and `--stomp URL`: the RealizerTester suite against a
//! realizer reached only through a broker. Blocks are published on a block topic, feedback is
//! read from the matching feedback topic; the incremental-speech tests go to another pair (a
//! character served by a realizer with retimable speech on MQTT; another pair of topics on
//! STOMP). Each test starts with an empty REPLACE block, as over a process's stdin.

use std::time::{Duration, Instant};

use bml_realizer::ports::broker::{
    BrokerUrl, Inbound, Link, LinkOptions, StompLink, StompOptions, StompUrl, Topics, Wire,
};
use realizer_tests::port::replace_setup;
use realizer_tests::{Fixture, TestPort};

/// The suite's port on a broker.
pub struct BrokerPort {
    wire: Box<dyn Wire>,
    /// (block topic, feedback topic) of the standard and the incremental-speech fixtures.
    pairs: [(String, String); 2],
    running: Fixture,
}

impl BrokerPort {
    /// On MQTT: the block and feedback topics of `characters` under `prefix`.
    pub fn mqtt(url: &str, prefix: &str, characters: [String; 2]) -> Result<BrokerPort, String> {
        let url = BrokerUrl::parse(url)?;
        let topics = Topics::new(prefix)?;
        let pairs = characters.map(|c| (topics.bml(&c), topics.feedback(&c)));
        let link = Link::connect(LinkOptions {
            url,
            client_id: format!("bmlr-conformance-{}", std::process::id()),
            subscriptions: pairs.iter().map(|p| p.1.clone()).collect(),
            presence: None,
            inbox: 100_000,
            start_tries: 6,
        })?;
        Ok(BrokerPort::on(Box::new(link), pairs))
    }

    /// On STOMP: the topic pairs (blocks in, feedback out) of the two fixtures.
    pub fn stomp(url: &str, pairs: [(String, String); 2]) -> Result<BrokerPort, String> {
        let url = StompUrl::parse(url)?;
        let pairs = pairs.map(|(i, o)| (format!("/topic/{i}"), format!("/topic/{o}")));
        let mut subscriptions: Vec<String> = pairs.iter().map(|p| p.1.clone()).collect();
        subscriptions.dedup();
        let link = StompLink::connect(StompOptions {
            url,
            subscriptions,
            presence: None,
            inbox: 100_000,
            start_tries: 6,
        })?;
        Ok(BrokerPort::on(Box::new(link), pairs))
    }

    fn on(wire: Box<dyn Wire>, pairs: [(String, String); 2]) -> BrokerPort {
        BrokerPort {
            wire,
            pairs,
            running: Fixture::Standard,
        }
    }

    fn pair(&self) -> &(String, String) {
        &self.pairs[usize::from(self.running == Fixture::IncrementalSpeech)]
    }

    /// The feedback of the running fixture heard until `deadline`, then what is already there.
    fn collect_until(&mut self, deadline: Instant) -> Vec<String> {
        let topic = self.pair().1.clone();
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
            match self.wire.recv_timeout(left) {
                Some(i) => take(i, &mut out),
                None => break,
            }
        }
        while let Some(i) = self.wire.try_recv() {
            take(i, &mut out);
        }
        out
    }
}

impl TestPort for BrokerPort {
    fn perform_bml(&mut self, bml: &str) {
        let topic = self.pair().0.clone();
        self.wire.send(&topic, bml.as_bytes().to_vec(), &[]);
        self.wire.flush();
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
            "the realizer on '{}' did not end the REPLACE setup block (is one serving it on the broker?)",
            self.pair().0
        ))
    }
}
