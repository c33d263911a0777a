//! `bmlr serve --mqtt URL` and `--stomp URL`: the realizer on a message broker
//! (docs/broker.md). The link (`bml_realizer::ports::broker::Link` or `StompLink`, seen through `Wire`)
//! keeps itself connected; the dialect (`dialect.rs`) says which topics carry blocks and
//! feedback and in what form; this loop owns the realizer, ticks it on the wall clock, routes
//! the feedback and writes the frames (`--frames`). A payload that is not a block for that
//! topic's character is answered with a warning on the character's feedback topic (a payload
//! that is a JSON object is a stream message for the topic's character); a block for
//! a character this realizer does not serve is left to the realizer that does. Realizers on one
//! broker share one world by area (`world_share.rs`).

use std::collections::{BTreeMap, BTreeSet, VecDeque};
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::Duration;

use bml_realizer::language::bml::Checked;
use bml_realizer::language::feedback::{Feedback, Format, KnownWarning, WarningFeedback};
use bml_realizer::ports::broker::{Cells, Inbound, Topics, Wire, DEFAULT_CHARACTER};
use bml_realizer::realizer::clock::{Clock, WallClock};
use bml_realizer::realizer::{Realizer, NO_ID};

use crate::dialect::{block_character, Arrived, Dialect, Lane, Out};
use crate::live_frames::LiveFrames;
use crate::world_share::Sharing;

/// Blocks performed in one frame at most (the rest wait for the next frames, so that a flood
/// cannot hold the clock up).
const PER_FRAME: usize = 1_024;

/// Messages taken from the link in one frame at most (into the characters' queues).
const TAKEN_PER_FRAME: usize = 65_536;

/// Blocks that may wait for one character unless `--queue-limit` says otherwise; beyond, the
/// newest are dropped with a warning on its feedback topic.
pub const QUEUE_LIMIT: usize = 10_000;

/// The largest `--queue-limit` taken (a million small blocks are a few hundred MB).
pub const MAX_QUEUE_LIMIT: usize = 1_000_000;

/// What `serve --mqtt | --stomp` was given.
pub struct Brokered {
    /// The connected link.
    pub wire: Box<dyn Wire>,
    /// The broker's address (for messages).
    pub url: String,
    /// The topics of presence and the shared world.
    pub topics: Topics,
    /// The cells the shared world is cut into.
    pub cells: Cells,
    /// Topics are STOMP destinations under `/topic/`.
    pub stomp: bool,
    /// How blocks and feedback travel.
    pub dialect: Dialect,
    /// The characters served (all when empty).
    pub characters: BTreeSet<String>,
    /// Feedback encoding (where the dialect leaves it open).
    pub format: Format,
    /// Engine loop period.
    pub period: Duration,
    /// Blocks that may wait for one character (beyond, the newest are dropped).
    pub queue_limit: usize,
    /// Stop after this many seconds (on the realizer's clock).
    pub until: f64,
    /// The frames file written as the characters move.
    pub frames: Option<LiveFrames>,
}

/// Serves until `until`, or SIGTERM, or for ever.
pub fn serve(args: Brokered, realizer: Realizer) -> ExitCode {
    eprintln!("bmlr serve: on the broker at {}", args.url);
    let stop = Arc::new(AtomicBool::new(false));
    for signal in [signal_hook::consts::SIGTERM, signal_hook::consts::SIGINT] {
        let _ = signal_hook::flag::register(signal, stop.clone());
    }
    let sharing = Sharing::new(&args, &realizer);
    let mut s = Server {
        realizer,
        clock: WallClock::new(),
        args,
        sharing,
        waiting: BTreeMap::new(),
    };
    let zero = s.posix_zero();
    if let Some(f) = s.args.frames.as_mut() {
        f.start_clock(Some(zero));
    }
    if let Dialect::Ipaaca(ip, _) = &s.args.dialect {
        let hello = ip.notify("new");
        s.send_raw(hello.into_iter().map(|(t, p)| (t, p, Vec::new())));
    }
    s.run(&stop);
    s.sharing.counts.dropped = s.args.wire.states_dropped();
    eprintln!("bmlr serve: world: {}", s.sharing.counts);
    let Server { args, .. } = s;
    let Brokered {
        mut wire,
        frames,
        dialect,
        ..
    } = args;
    if let Dialect::Ipaaca(ip, _) = &dialect {
        for (t, p) in ip.notify("down") {
            wire.send(&t, p, &[]);
        }
    }
    wire.close(Duration::from_secs(2));
    if let Some(f) = frames {
        if let Err(e) = f.finish() {
            eprintln!("bmlr serve: --frames {e}");
            return ExitCode::from(2);
        }
    }
    ExitCode::SUCCESS
}

pub(crate) struct Server {
    pub(crate) realizer: Realizer,
    pub(crate) clock: WallClock,
    pub(crate) args: Brokered,
    /// The world shared with other realizers.
    pub(crate) sharing: Sharing,
    /// Blocks waiting (and the request IU that asked for each), per character served (taken
    /// in turns: one character's flood does not hold up the others), and how many were
    /// dropped since last said.
    waiting: BTreeMap<Lane, (VecDeque<Waiting>, usize)>,
}

/// A block waiting: its payload and the request IU that asked for it.
type Waiting = (Vec<u8>, Option<String>);

impl Server {
    fn run(&mut self, stop: &AtomicBool) {
        loop {
            // wait for something only when nothing waits
            let idle = self.waiting.values().all(|q| q.0.is_empty());
            let wait = if idle {
                self.args.period
            } else {
                Duration::ZERO
            };
            if let Some(first) = self.args.wire.recv_timeout(wait) {
                self.hear(first);
                for _ in 1..TAKEN_PER_FRAME {
                    match self.args.wire.try_recv() {
                        Some(i) => self.hear(i),
                        None => break,
                    }
                }
            }
            self.perform_waiting();
            self.tick();
            if self.realizer.now() >= self.args.until || stop.load(Ordering::SeqCst) {
                return;
            }
        }
    }

    /// Performs waiting blocks, one per character in turn, [`PER_FRAME`] at most and for no
    /// longer than a frame; says what was dropped.
    fn perform_waiting(&mut self) {
        let dropped: Vec<(String, usize)> = (self.waiting.iter_mut())
            .filter(|(_, q)| q.1 > 0)
            .map(|(lane, q)| (lane.character().to_string(), std::mem::take(&mut q.1)))
            .collect();
        for (c, n) in dropped {
            let limit = self.args.queue_limit;
            let text = format!("{n} blocks dropped: more than {limit} waited for this character");
            self.refuse(&c, text, None);
        }
        let (mut done, start) = (0, self.clock.now());
        // (within a frame: the clock and the other messages are not held up)
        while done < PER_FRAME && self.clock.now() - start < self.args.period.as_secs_f64() {
            type Next = (Lane, Waiting);
            let next: Vec<Next> = (self.waiting.iter_mut())
                .filter_map(|(c, q)| Some((c.clone(), q.0.pop_front()?)))
                .take(PER_FRAME - done)
                .collect();
            if next.is_empty() {
                break;
            }
            done += next.len();
            // the clock up to date once a round: its blocks are planned at this time
            self.tick();
            for (c, (payload, request)) in next {
                self.perform(&c, payload, request);
            }
        }
    }

    fn tick(&mut self) {
        let now = self.clock.now().min(self.args.until);
        self.place_others(now);
        let frame = self.realizer.tick(now);
        if let Some(f) = self.args.frames.as_mut() {
            f.push(frame.time, &frame.poses);
        }
        self.send(frame.feedback, None);
        self.share(now);
        let dropped = self.args.wire.take_dropped();
        if dropped > 0 {
            eprintln!("bmlr serve: the broker was away too long: {dropped} feedback messages were dropped");
        }
    }

    fn hear(&mut self, inbound: Inbound) {
        let (topic, payload) = match inbound {
            Inbound::Lost(why) => {
                return eprintln!("bmlr serve: lost the broker ({why}); trying again")
            }
            Inbound::Reconnected => {
                return eprintln!("bmlr serve: back on the broker; characters kept")
            }
            Inbound::Message { topic, payload } => (topic, payload),
        };
        let topic = match self.args.stomp {
            true => topic.strip_prefix("/topic/").unwrap_or(&topic).to_string(),
            false => topic,
        };
        if let Some((_, character)) = self.args.topics.world_character(&topic) {
            let character = character.to_string();
            return self.hear_state(character, &payload);
        }
        if let Some(answer) = self.answer_component(&topic, &payload) {
            return self.send_raw(answer);
        }
        match self.args.dialect.read(&topic, payload) {
            Some(Arrived::Block {
                lane,
                payload,
                request,
            }) => {
                if matches!(lane, Lane::Shared(_)) || self.serves(lane.character()) {
                    let q = self.waiting.entry(lane).or_default();
                    if q.0.len() < self.args.queue_limit {
                        q.0.push_back((payload, request));
                    } else {
                        q.1 += 1;
                    }
                }
            }
            Some(Arrived::Bad {
                character,
                why,
                request,
            }) => self.refuse(&character, why, request),
            Some(Arrived::Nothing) | None => {}
        }
    }

    /// ipaaca: another component announced itself as new: say this one is here (`old`).
    fn answer_component(&self, topic: &str, payload: &[u8]) -> Option<Vec<Out>> {
        let Dialect::Ipaaca(ip, _) = &self.args.dialect else {
            return None;
        };
        if !topic.ends_with("/componentNotify/M") {
            return None;
        }
        let bml_realizer::ports::broker::ipaaca::Heard::NewComponent { channel } =
            ip.read(topic, payload)?
        else {
            return None;
        };
        let note = ip
            .notify("old")
            .into_iter()
            .find(|(t, _)| t.starts_with(&format!("{channel}/")))?;
        Some(vec![(note.0, note.1, Vec::new())])
    }

    /// Whether this realizer serves `character` (a topic level): one of `--characters`, or,
    /// without them, any character no other realizer moves.
    fn serves(&self, character: &str) -> bool {
        if self.args.characters.is_empty() {
            !self.sharing.others.contains_key(character)
        } else {
            self.args.characters.contains(character)
        }
    }

    /// Performs a block from `lane`; what it produces at once without a character (a block
    /// that could not be read) is the lane's character's.
    fn perform(&mut self, lane: &Lane, payload: Vec<u8>, request: Option<String>) {
        let limits = *self.realizer.limits();
        let text = match String::from_utf8(payload) {
            Ok(t) => t,
            Err(_) => {
                let why = "the payload is not UTF-8 text".into();
                return self.refuse(lane.character(), why, request);
            }
        };
        if text.trim_start().starts_with('{') {
            return self.stream_message(lane, &text);
        }
        let mut checked = Checked::new(&text, &limits);
        let block = checked.block.as_mut();
        let character = match (lane, block) {
            (Lane::Shared(_), Some(b)) => {
                let c = block_character(b.character_id.as_deref());
                if !self.serves(&c) {
                    // (another realizer's character: it answers)
                    return;
                }
                c
            }
            (Lane::Shared(c), None) => c.clone(),
            (Lane::Topic(lane), Some(b)) => {
                let topic_character = (lane != DEFAULT_CHARACTER).then(|| lane.to_string());
                if b.character_id.is_none() {
                    b.character_id = topic_character.clone();
                }
                if b.character_id != topic_character {
                    let named = b.character_id.as_deref().unwrap_or(DEFAULT_CHARACTER);
                    let id = b.id.to_string();
                    let why = format!(
                        "block {id} is for character '{named}' but came on the topic of '{lane}'"
                    );
                    return self.refuse(lane, why, request);
                }
                lane.to_string()
            }
            (Lane::Topic(lane), None) => lane.to_string(),
        };
        let block_id = checked.block.as_ref().map(|b| b.id.to_string());
        let source = self.args.dialect.source(&character);
        let result = self.realizer.perform_checked(checked, Some(&source));
        if let Some(uid) = &request {
            let error = result.as_ref().err().map(|e| e.to_string());
            let answer =
                (self.args.dialect).answer_request(uid, block_id.as_deref(), error.as_deref());
            self.send_raw(answer);
        }
        self.answer(&character);
    }

    /// Sends what a message from `character`'s lane produced at once; a warning that names no
    /// character (a block or message that could not be read) is the lane's character's.
    fn answer(&mut self, character: &str) {
        let mut feedback = self.realizer.take_feedback();
        let topic_character = (character != DEFAULT_CHARACTER).then(|| character.to_string());
        for fb in &mut feedback {
            if let Feedback::Warning(w) = fb {
                w.character_id = w.character_id.take().or_else(|| topic_character.clone());
            }
        }
        self.send(feedback, Some(character));
    }

    /// A stream message (a payload that is a JSON object): on a character's topic it is that
    /// character's stream; its warnings go to the lane's character.
    fn stream_message(&mut self, lane: &Lane, text: &str) {
        let character = lane.character().to_string();
        let source = self.args.dialect.source(&character);
        let _ = match lane {
            Lane::Shared(_) => self.realizer.stream_message(&source, text),
            Lane::Topic(c) => {
                let own = (c != DEFAULT_CHARACTER).then_some(c.as_str());
                self.realizer.stream_message_on(&source, text, own)
            }
        };
        self.answer(&character);
    }

    fn refuse(&mut self, character: &str, text: String, request: Option<String>) {
        let text = format!("{}: {text}", self.args.dialect.source(character));
        if let Some(uid) = request {
            let answer = self.args.dialect.answer_request(&uid, None, Some(&text));
            self.send_raw(answer);
        }
        let warning = Feedback::Warning(WarningFeedback {
            id: NO_ID.into(),
            kind: KnownWarning::ParsingFailure.into(),
            character_id: (character != DEFAULT_CHARACTER).then(|| character.to_string()),
            text,
        });
        self.send(vec![warning], Some(character));
    }

    /// Publishes each message on its character's feedback topic (one without a character on
    /// `fallback`'s, or the default character's).
    fn send(&mut self, feedback: Vec<Feedback>, fallback: Option<&str>) {
        let mut out = Vec::new();
        for fb in feedback {
            let character = fb
                .character_id()
                .or(fallback)
                .unwrap_or(DEFAULT_CHARACTER)
                .to_string();
            let posix = self.posix_zero();
            out.extend(
                self.args
                    .dialect
                    .feedback(&character, &fb, self.args.format, posix),
            );
        }
        self.send_raw(out);
    }

    /// The POSIX time (s) of the realizer's time 0.
    fn posix_zero(&self) -> f64 {
        crate::live_frames::posix_zero(&self.clock)
    }

    /// Sends messages as they are (topics made STOMP destinations where needed).
    pub(crate) fn send_raw(&mut self, out: impl IntoIterator<Item = Out>) {
        for (topic, payload, headers) in out {
            let topic = self.destination(topic);
            self.args.wire.send(&topic, payload, &headers);
        }
        self.args.wire.flush();
    }

    /// A topic as the link names it (a STOMP destination under `/topic/`).
    pub(crate) fn destination(&self, topic: String) -> String {
        match self.args.stomp && !topic.starts_with('/') {
            true => format!("/topic/{topic}"),
            false => topic,
        }
    }
}
