//! `bmlr serve --mqtt URL`: the realizer on an MQTT broker (`docs/broker.md`). Blocks arrive on
//! `PREFIX/CHARACTER/bml` (one block a message; the topic names the character, `_` the default
//! one), feedback leaves on `PREFIX/CHARACTER/feedback` (one element a message), presence is
//! `PREFIX/realizers/NAME`. The link to the broker (`bml_realizer::broker::Link`) keeps itself
//! connected; this loop owns the realizer, ticks it on the wall clock and routes the feedback.
//! A payload that is not a block for that topic's character is answered with a warning on the
//! character's feedback topic; a block for a character this realizer does not serve is left to
//! the realizer that does. Realizers on one broker share one world: each publishes where its
//! characters stand on `PREFIX/world/CHARACTER` (20 Hz) and places the others' characters in
//! its own world (`Realizer::place_remote`), so that its walkers go round them.

use std::collections::{BTreeMap, BTreeSet, VecDeque};
use std::process::ExitCode;
use std::time::Duration;

use bml_realizer::bml::Checked;
use bml_realizer::broker::{
    Inbound, Ipaaca, Link, LinkOptions, RootState, Topics, DEFAULT_CHARACTER, PUBLISH_PERIOD,
};
use bml_realizer::clock::{Clock, WallClock};
use bml_realizer::feedback::{Feedback, Format, KnownWarning, WarningFeedback};
use bml_realizer::realizer::{Realizer, NO_ID};

/// Blocks performed in one frame at most (the rest wait for the next frames, so that a flood
/// cannot hold the clock up).
const PER_FRAME: usize = 1_024;

/// Messages taken from the link in one frame at most (into the characters' queues).
const TAKEN_PER_FRAME: usize = 65_536;

/// Blocks that may wait for one character; beyond, the newest are dropped with a warning on
/// its feedback topic.
pub const QUEUE_LIMIT: usize = 10_000;

/// What `serve --mqtt` was given.
pub struct MqttServe {
    /// The link's options (broker, client id, subscriptions, presence).
    pub link: LinkOptions,
    /// The topics.
    pub topics: Topics,
    /// The characters served (all when empty).
    pub characters: BTreeSet<String>,
    /// Feedback encoding.
    pub format: Format,
    /// Engine loop period.
    pub period: Duration,
    /// Stop after this many seconds (on the realizer's clock).
    pub until: f64,
    /// ipaaca's messages instead of the block and feedback topics (`--ipaaca COMPONENT`).
    pub ipaaca: Option<Ipaaca>,
}

/// Serves until `until` (or for ever). Exit 2 when the broker cannot be reached at the start.
pub fn serve(args: MqttServe, realizer: Realizer) -> ExitCode {
    let url = args.link.url.clone();
    let link = match Link::connect(args.link.clone()) {
        Ok(l) => l,
        Err(e) => {
            eprintln!("bmlr serve: --mqtt {e}");
            return ExitCode::from(2);
        }
    };
    eprintln!("bmlr serve: on the broker at {url}");
    let mut s = Server {
        realizer,
        clock: WallClock::new(),
        link,
        args,
        others: BTreeMap::new(),
        published: f64::NEG_INFINITY,
        bad_states: BTreeSet::new(),
        waiting: BTreeMap::new(),
    };
    s.run();
    let Server { link, .. } = s;
    link.close(Duration::from_secs(2));
    ExitCode::SUCCESS
}

struct Server {
    realizer: Realizer,
    clock: WallClock,
    link: Link,
    args: MqttServe,
    /// The other realizers' characters: their last state and when it arrived (local clock).
    others: BTreeMap<String, (RootState, f64)>,
    /// When this realizer last published its characters' states.
    published: f64,
    /// Characters whose state could not be read (said once each on stderr).
    bad_states: BTreeSet<String>,
    /// Blocks waiting, per character served (taken in turns: one character's flood does not
    /// hold up the others), and how many were dropped since last said.
    waiting: BTreeMap<String, (VecDeque<Vec<u8>>, usize)>,
}

impl Server {
    fn run(&mut self) {
        loop {
            // wait for something only when nothing waits
            let idle = self.waiting.values().all(|q| q.0.is_empty());
            let wait = if idle {
                self.args.period
            } else {
                Duration::ZERO
            };
            if let Some(first) = self.link.recv_timeout(wait) {
                self.hear(first);
                for _ in 1..TAKEN_PER_FRAME {
                    match self.link.try_recv() {
                        Some(i) => self.hear(i),
                        None => break,
                    }
                }
            }
            self.perform_waiting();
            self.tick();
            if self.realizer.now() >= self.args.until {
                return;
            }
        }
    }

    /// Performs waiting blocks, one per character in turn, [`PER_FRAME`] at most and for no
    /// longer than a frame; says what was dropped.
    fn perform_waiting(&mut self) {
        let dropped: Vec<(String, usize)> = (self.waiting.iter_mut())
            .filter(|(_, q)| q.1 > 0)
            .map(|(c, q)| (c.clone(), std::mem::take(&mut q.1)))
            .collect();
        for (c, n) in dropped {
            let text =
                format!("{n} blocks dropped: more than {QUEUE_LIMIT} waited for this character");
            self.refuse(&c, text);
        }
        let (mut done, start) = (0, self.clock.now());
        // (within a frame: the clock and the other messages are not held up)
        while done < PER_FRAME && self.clock.now() - start < self.args.period.as_secs_f64() {
            let next: Vec<(String, Vec<u8>)> = (self.waiting.iter_mut())
                .filter_map(|(c, q)| Some((c.clone(), q.0.pop_front()?)))
                .take(PER_FRAME - done)
                .collect();
            if next.is_empty() {
                break;
            }
            done += next.len();
            for (c, payload) in next {
                self.perform(&c, payload);
            }
        }
    }

    fn tick(&mut self) {
        let now = self.clock.now().min(self.args.until);
        // the others' characters where they are now, as far as their states tell
        for (id, (state, heard)) in &self.others {
            let _ = self
                .realizer
                .place_remote(id, state.placement_after(now - heard));
        }
        let frame = self.realizer.tick(now);
        self.send(frame.feedback, None);
        if now - self.published >= PUBLISH_PERIOD {
            self.published = now;
            self.publish_states(now);
        }
        let dropped = self.link.take_dropped();
        if dropped > 0 {
            eprintln!("bmlr serve: the broker was away too long: {dropped} feedback messages were dropped");
        }
    }

    fn hear(&mut self, inbound: Inbound) {
        match inbound {
            Inbound::Lost(why) => eprintln!("bmlr serve: lost the broker ({why}); trying again"),
            Inbound::Reconnected => eprintln!("bmlr serve: back on the broker; characters kept"),
            Inbound::Message { topic, payload } => {
                if let Some(character) = self.args.topics.world_character(&topic) {
                    let character = character.to_string();
                    return self.hear_state(character, &payload);
                }
                let (character, payload) = match self.block_of(&topic, payload) {
                    Some(Ok(c)) => c,
                    Some(Err((character, why))) => return self.refuse(&character, why),
                    None => return,
                };
                if self.serves(&character) {
                    let q = self.waiting.entry(character).or_default();
                    if q.0.len() < QUEUE_LIMIT {
                        q.0.push_back(payload);
                    } else {
                        q.1 += 1;
                    }
                }
            }
        }
    }

    /// The character (a topic level) and the block text of a message on `topic`: `None` when
    /// it is no block topic; an error (with the character to tell) when it is an ipaaca
    /// message that cannot be read.
    #[allow(clippy::type_complexity)]
    fn block_of(
        &self,
        topic: &str,
        payload: Vec<u8>,
    ) -> Option<Result<(String, Vec<u8>), (String, String)>> {
        let Some(ip) = &self.args.ipaaca else {
            let character = self.args.topics.bml_character(topic)?;
            return Some(Ok((character.to_string(), payload)));
        };
        Some(match ip.read(topic, &payload)? {
            Ok((character, text)) => {
                let character = character.unwrap_or_else(|| DEFAULT_CHARACTER.to_string());
                if !bml_realizer::broker::level_ok(&character) {
                    let why = format!("'{character}' is not a character name");
                    return Some(Err((DEFAULT_CHARACTER.to_string(), why)));
                }
                Ok((character, text.into_bytes()))
            }
            Err(why) => Err((DEFAULT_CHARACTER.to_string(), why)),
        })
    }

    /// Where blocks for `character` come from (named in warnings).
    fn source(&self, character: &str) -> String {
        match &self.args.ipaaca {
            Some(ip) => format!("{} ({character})", ip.subscription()),
            None => self.args.topics.bml(character),
        }
    }

    /// Whether this realizer serves `character` (a topic level): one of `--characters`, or,
    /// without them, any character no other realizer moves.
    fn serves(&self, character: &str) -> bool {
        if self.args.characters.is_empty() {
            !self.others.contains_key(character)
        } else {
            self.args.characters.contains(character)
        }
    }

    /// Keeps another realizer's state of `character` (not one served here).
    fn hear_state(&mut self, character: String, payload: &[u8]) {
        if self.args.characters.contains(&character) || self.is_ours(&character) {
            return;
        }
        match RootState::from_json(payload) {
            Ok(state) => {
                self.others.insert(character, (state, self.clock.now()));
            }
            Err(e) => {
                if self.bad_states.insert(character.clone()) {
                    let topic = self.args.topics.world(&character);
                    eprintln!("bmlr serve: {topic}: not a root state ({e}); ignored");
                }
            }
        }
    }

    /// Whether `character` (a topic level) is one this realizer has made.
    fn is_ours(&self, character: &str) -> bool {
        let id = if character == DEFAULT_CHARACTER {
            ""
        } else {
            character
        };
        self.realizer.character(id).is_some() && !self.realizer.is_remote(id)
    }

    /// Publishes where this realizer's characters stand: those it has made, and the
    /// `--characters` the world places.
    fn publish_states(&mut self, now: f64) {
        let world = self.realizer.world();
        let mut ours: BTreeSet<String> = (self.realizer.characters())
            .map(|(id, _)| id.to_string())
            .filter(|id| !id.is_empty() && !self.realizer.is_remote(id))
            .collect();
        ours.extend(
            (self.args.characters.iter())
                .filter(|c| world.is_placed(c))
                .cloned(),
        );
        let crowd = world.crowd();
        let states: Vec<(String, String)> = (ours.into_iter())
            .filter(|id| world.is_placed(id))
            .map(|id| {
                let velocity = crowd.index(&id).map_or(glam::Vec3::ZERO, |i| {
                    let v = crowd.agent(i).velocity;
                    glam::Vec3::new(v.x, 0.0, v.y)
                });
                let state = RootState::new(now, world.placement(&id), velocity);
                (self.args.topics.world(&id), state.to_json())
            })
            .collect();
        for (topic, json) in states {
            self.link.publish(&topic, json.into_bytes(), false);
        }
    }

    /// Performs a block from `character`'s topic; what it produces at once without a character
    /// (a block that could not be read) is that topic's.
    fn perform(&mut self, character: &str, payload: Vec<u8>) {
        // the clock up to date first: the block is planned at this time
        self.tick();
        let limits = *self.realizer.limits();
        let topic_character = (character != DEFAULT_CHARACTER).then(|| character.to_string());
        let text = match String::from_utf8(payload) {
            Ok(t) => t,
            Err(_) => return self.refuse(character, "the payload is not UTF-8 text".into()),
        };
        let mut checked = Checked::new(&text, &limits);
        if let Some(block) = checked.block.as_mut() {
            if block.character_id.is_none() {
                block.character_id = topic_character.clone();
            }
            if block.character_id != topic_character {
                let named = block.character_id.as_deref().unwrap_or(DEFAULT_CHARACTER);
                let id = block.id.to_string();
                return self.refuse(
                    character,
                    format!("block {id} is for character '{named}' but came on the topic of '{character}'"),
                );
            }
        }
        let source = self.source(character);
        let _ = self.realizer.perform_checked(checked, Some(&source));
        let mut feedback = self
            .realizer
            .tick(self.clock.now().min(self.args.until))
            .feedback;
        // (a block that could not be read names no character: the topic's is meant)
        for fb in &mut feedback {
            if let Feedback::Warning(w) = fb {
                w.character_id = w.character_id.take().or_else(|| topic_character.clone());
            }
        }
        self.send(feedback, Some(character));
    }

    fn refuse(&mut self, character: &str, text: String) {
        let warning = Feedback::Warning(WarningFeedback {
            id: NO_ID.into(),
            kind: KnownWarning::ParsingFailure.into(),
            character_id: (character != DEFAULT_CHARACTER).then(|| character.to_string()),
            text: format!("{}: {text}", self.source(character)),
        });
        self.send(vec![warning], Some(character));
    }

    /// Publishes each message on its character's feedback topic (one without a character on
    /// `fallback`'s, or the default character's).
    fn send(&mut self, feedback: Vec<Feedback>, fallback: Option<&str>) {
        for fb in feedback {
            let character = fb
                .character_id()
                .or(fallback)
                .unwrap_or(DEFAULT_CHARACTER)
                .to_string();
            let (topic, payload) = match &self.args.ipaaca {
                Some(ip) => ip.feedback(&character, &Format::Xml.encode(&fb)),
                None => (
                    self.args.topics.feedback(&character),
                    self.args.format.encode(&fb).into_bytes(),
                ),
            };
            self.link.publish(&topic, payload, false);
        }
        self.link.flush();
    }
}
