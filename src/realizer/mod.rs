//! The realizer facade a host embeds: submit BML text, call [`Realizer::tick`] each frame, read
//! frames and feedback. Blocks are routed to characters by `characterId`; each character has its
//! own engines and [`BlockManager`]. Also the [`RealizerPort`] trait, the string-level port that
//! the CLI and test harnesses drive.
//!
//! It is the realizer floor, above the engines: blocks at run time for one character
//! ([`blocks`]: lifecycle, composition, the event loop) and the clocks that drive a run
//! ([`clock`]) sit in it with the facade and its stages (sensing, nets, crowding, streaming).

use std::collections::BTreeMap;
use std::time::{SystemTime, UNIX_EPOCH};

pub mod blocks;
pub mod clock;

mod crowding;
mod netting;
pub use crowding::CROWD_PERIOD;
use crowding::{grid_index, grid_time};
mod options;
mod remote;
mod sensing;
mod streaming;
pub use netting::NET_RATE;
pub use options::from_options;

use crate::character::body::Skeleton;
use crate::engines::default_registry;
use crate::engines::interface::{Frame, Registry};
use crate::language::bml::{self, BmlError, Diagnostic};
use crate::language::feedback::{Feedback, FeedbackListener, KnownWarning, WarningFeedback};
use crate::planning::plan::anticipator::Anticipator;
use crate::planning::schedule::{Optimal, SchedulingStrategy};
use crate::planning::timing::DefaultTimingModels;
use crate::realizer::blocks::BlockManager;
use crate::world::World;

/// The id used in warnings about a block whose id could not be read.
pub const NO_ID: &str = "<no id>";

/// On the wall clock, a tick that comes this much later than a sync point it passes (seconds)
/// reports that the realizer fell behind.
pub const LATE: f64 = 0.25;

/// The string-level realizer port (BML in, feedback out), as in RealizerTester and AsapRealizer.
pub trait RealizerPort {
    /// Submits one `<bml>` block as text. Problems are reported as warning feedback.
    fn perform_bml(&mut self, bml: &str);
    /// Adds a listener that receives every feedback message from now on.
    fn add_listener(&mut self, listener: Box<dyn FeedbackListener>);
}

type RegistryFactory = Box<dyn Fn() -> Registry + Send>;
type StrategyFactory = Box<dyn Fn() -> Box<dyn SchedulingStrategy> + Send>;

/// A BML realizer for one or more characters.
pub struct Realizer {
    characters: BTreeMap<String, BlockManager>,
    default_character: Option<String>,
    engines: RegistryFactory,
    strategy: StrategyFactory,
    listeners: Vec<Box<dyn FeedbackListener>>,
    posix_time: bool,
    /// What one block may hold (see [`bml::Limits`]).
    limits: bml::Limits,
    skeleton: Skeleton,
    /// Whether characters breathe and shift their weight while standing (`body::idle`).
    idle: bool,
    world: std::sync::Arc<World>,
    now: f64,
    unframed: Vec<Feedback>,
    /// Whether characters are stepped on several threads.
    parallel: bool,
    /// Characters another realizer moves (`remote.rs`): placed here, never made characters.
    remote: std::collections::BTreeSet<String>,
    /// Whom remote characters ask to make room (asking → asked).
    remote_asks: std::collections::BTreeMap<String, String>,
    /// Synthetic vision, when on (`sensing.rs`).
    sensing: Option<Box<sensing::Sensing>>,
    /// PaT-Nets, when given (`netting.rs`).
    netting: Option<Box<netting::Netting>>,
    /// The audio streams the host opened, by name (`streaming.rs`).
    streams: BTreeMap<String, crate::character::voice::stream::AudioStream>,
}

impl Default for Realizer {
    fn default() -> Self {
        Self::new()
    }
}

impl Realizer {
    /// A realizer with the built-in engines and the `Optimal` scheduler, at time 0.
    pub fn new() -> Self {
        Realizer {
            characters: BTreeMap::new(),
            default_character: None,
            engines: Box::new(|| default_registry(DefaultTimingModels::default())),
            strategy: Box::new(|| Box::new(Optimal)),
            listeners: Vec::new(),
            posix_time: false,
            limits: bml::Limits::default(),
            skeleton: Skeleton::adult(),
            idle: true,
            world: std::sync::Arc::new(World::default()),
            remote: Default::default(),
            remote_asks: Default::default(),
            sensing: None,
            netting: None,
            streams: BTreeMap::new(),
            parallel: true,
            now: 0.0,
            unframed: Vec::new(),
        }
    }

    /// Uses `factory` to make the engines of each character (register extra kinds and engines
    /// here).
    pub fn with_engines(mut self, factory: impl Fn() -> Registry + Send + 'static) -> Self {
        self.engines = Box::new(factory);
        self
    }

    /// Times speech with `speech` (the built-in TTS by default; `SpeechTiming::syllables()` for
    /// the metronome voice), with the default engines.
    pub fn with_speech_timing(self, speech: crate::planning::timing::SpeechTiming) -> Self {
        self.with_engines(move || {
            crate::engines::default_registry(crate::planning::timing::DefaultTimingModels {
                speech,
            })
        })
    }

    /// Uses another scheduling strategy.
    pub fn with_strategy(
        mut self,
        factory: impl Fn() -> Box<dyn SchedulingStrategy> + Send + 'static,
    ) -> Self {
        self.strategy = Box::new(factory);
        self
    }

    /// Every character gets `skeleton` (the default adult otherwise).
    pub fn with_skeleton(mut self, skeleton: Skeleton) -> Self {
        self.skeleton = skeleton;
        self
    }

    /// Whether characters breathe and shift their weight from foot to foot while standing (the
    /// idle layer, on by default). It changes the pose only, never the feedback.
    pub fn with_idle(mut self, on: bool) -> Self {
        self.idle = on;
        self
    }

    /// Blocks without a `characterId` go to character `id` (their feedback names it).
    pub fn with_default_character(mut self, id: Option<String>) -> Self {
        self.default_character = id;
        self
    }

    /// Stamps block and sync progress with `bmla:posixTime` (for wall-clock runs; virtual-clock
    /// runs leave it out so that logs are byte-identical). A wall-clock realizer also reports
    /// when it fell behind: a tick more than [`LATE`] after a sync point it passes gives an
    /// EXECUTION_FAILURE warning saying how late (the sync's feedback keeps its planned time).
    pub fn with_posix_time(mut self, on: bool) -> Self {
        self.posix_time = on;
        self
    }

    /// Refuses blocks that pass `limits` (nesting, attributes, size, behaviours, times) with a
    /// PARSING_FAILURE warning that names the limit.
    pub fn with_limits(mut self, limits: bml::Limits) -> Self {
        self.limits = limits;
        self
    }

    /// The world: named targets (the host moves them between ticks).
    pub fn world(&self) -> &World {
        &self.world
    }

    /// The world, to place or move targets (takes effect at the next tick, or at once for blocks
    /// submitted after the change).
    pub fn world_mut(&mut self) -> &mut World {
        std::sync::Arc::make_mut(&mut self.world)
    }

    /// The current time: the last `tick`.
    pub fn now(&self) -> f64 {
        self.now
    }

    /// The character ids with a block manager ("" is the default character).
    pub fn characters(&self) -> impl Iterator<Item = (&str, &BlockManager)> {
        self.characters.iter().map(|(k, v)| (k.as_str(), v))
    }

    /// The block manager of character `id` ("" for the default character), if it has one.
    pub fn character(&self, id: &str) -> Option<&BlockManager> {
        self.characters.get(id)
    }

    /// The time of the next scheduled event of any character, if any (see
    /// [`BlockManager::next_event`]).
    /// With sight on, a character's next look is an event too while sync points are still
    /// to come or nets run (looks alone do not keep a run going).
    /// Nets that can still change state want a step every frame ([`NET_RATE`]), and keep a
    /// run going.
    pub fn next_event(&self) -> Option<f64> {
        let (sync, nets) = (self.next_sync(), self.nets_wake());
        sync.or(nets)?;
        [sync, nets, self.next_look()]
            .into_iter()
            .flatten()
            .reduce(f64::min)
    }

    /// With sight on, the time of the next look of any character (each looks on its own grid
    /// of times); a run that goes on to a given end ticks at these so that every look falls
    /// on its grid.
    pub fn next_look(&self) -> Option<f64> {
        self.perception().and_then(|p| p.next_look_of_any())
    }

    /// The time of the next sync point of any character.
    fn next_sync(&self) -> Option<f64> {
        self.characters
            .values()
            .filter_map(BlockManager::next_event)
            .reduce(f64::min)
    }

    fn manager(&mut self, character: Option<String>) -> &mut BlockManager {
        self.manager_at(character, self.now)
    }

    /// [`manager`](Self::manager), a new one made as of time `now`.
    fn manager_at(&mut self, character: Option<String>, now: f64) -> &mut BlockManager {
        let character = character.or_else(|| self.default_character.clone());
        let key = character.clone().unwrap_or_default();
        if self.characters.contains_key(&key) {
            // the usual case: no entry to build
            return self.characters.get_mut(&key).expect("just found");
        }
        let (engines, strategy, skeleton, world, idle) = (
            &self.engines,
            &self.strategy,
            &self.skeleton,
            &self.world,
            self.idle,
        );
        self.characters.entry(key).or_insert_with(|| {
            let mut m = BlockManager::new(engines(), strategy(), character);
            m.set_skeleton(skeleton.clone());
            m.set_idle(idle);
            m.advance(now, world, &mut Frame::default());
            m
        })
    }

    /// Pushes the simulated body of `character` ("" for the default character): `impulse`
    /// (N s, world frame: +y up, the character facing +z) on body part `part` (a part of the
    /// physical humanoid, `sacroiliac`, `upper-body`, `l_thigh`, …, or a skeleton joint,
    /// meaning the part it moves with). The body is simulated while a `bmlt:controller` runs;
    /// `Err` says why nothing was pushed (no such character, nothing simulated, an unknown
    /// part).
    pub fn push(&mut self, character: &str, part: &str, impulse: [f64; 3]) -> Result<(), String> {
        let Some(m) = self.characters.get_mut(character) else {
            return Err(format!("no character '{character}'"));
        };
        let mut why = String::from("no engine simulates the body");
        for e in m.registry_mut().engines_mut() {
            if let Some(p) = e.as_physics() {
                match p.push(part, impulse) {
                    Ok(()) => return Ok(()),
                    Err(e) => why = e,
                }
            }
        }
        Err(why)
    }

    /// How the simulated body of `character` ("" for the default character) stands now: its
    /// centre of mass, zero-moment point, support polygon, and how many physics steps the
    /// zero-moment point lay outside the feet (`dynamics::zmp`). `Err` says why there is no
    /// reading (no such character, no body simulated now: no `bmlt:controller` runs).
    pub fn balance(
        &mut self,
        character: &str,
    ) -> Result<crate::engines::interface::BalanceReading, String> {
        let Some(m) = self.characters.get_mut(character) else {
            return Err(format!("no character '{character}'"));
        };
        let mut why = String::from("no engine simulates the body");
        for e in m.registry_mut().engines_mut() {
            if let Some(p) = e.as_physics() {
                match p.balance() {
                    Ok(reading) => return Ok(reading),
                    Err(e) => why = e,
                }
            }
        }
        Err(why)
    }

    /// Registers an anticipator for `character` (None: blocks without a characterId). Blocks
    /// can then refer to its predictions as `anticipators:ID:SYNC`; when they change, what hangs
    /// on them moves without rescheduling.
    pub fn add_anticipator(&mut self, character: Option<&str>, anticipator: Box<dyn Anticipator>) {
        self.manager(character.map(str::to_string))
            .add_anticipator(anticipator);
    }

    /// Submits one `<bml>` block at the current time. Invalid BML yields a PARSING_FAILURE
    /// warning (and the error, for callers that want it); the stream keeps working.
    pub fn perform_bml(&mut self, text: &str) -> Result<(), BmlError> {
        self.perform_bml_from(text, None)
    }

    /// [`perform_bml`](Self::perform_bml) for a block read from `source` (a file name, say):
    /// a PARSING_FAILURE warning then names it before each position (`FILE:LINE:COL: ...`).
    pub fn perform_bml_from(&mut self, text: &str, source: Option<&str>) -> Result<(), BmlError> {
        let checked = bml::Checked::new(text, &self.limits);
        self.perform_checked(checked, source)
    }

    /// Submits a block already read and checked (by [`bml::Checked::new`], on any thread) at the
    /// current time: what [`perform_bml_from`](Self::perform_bml_from) does after reading.
    pub fn perform_checked(
        &mut self,
        checked: bml::Checked,
        source: Option<&str>,
    ) -> Result<(), BmlError> {
        let valid = checked.is_valid();
        let bml::Checked {
            block,
            diagnostics,
            id_hint,
        } = checked;
        match block {
            Some(block) if valid => {
                let world = self.world.clone();
                // the manager's feedback moves straight into the frame's list (no list per block)
                let mut unframed = std::mem::take(&mut self.unframed);
                let from = unframed.len();
                let m = self.manager(block.character_id.clone());
                m.set_world(&world);
                m.submit(block, &diagnostics);
                m.move_feedback(&mut unframed);
                self.unframed = unframed;
                self.deliver(from);
                Ok(())
            }
            block => {
                let character_id = block
                    .and_then(|b| b.character_id)
                    .or_else(|| self.default_character.clone());
                let mut errors = diagnostics;
                errors.retain(Diagnostic::is_error);
                self.refuse_block(id_hint, character_id, &errors, source);
                Err(BmlError(errors))
            }
        }
    }

    /// Reports a block that cannot be performed: a PARSING_FAILURE warning with its id (as far
    /// as it could be read) and its errors, each at `SOURCE:LINE:COL`.
    fn refuse_block(
        &mut self,
        id: Option<String>,
        character_id: Option<String>,
        errors: &[Diagnostic],
        source: Option<&str>,
    ) {
        let id = id
            .filter(|id| !id.is_empty())
            .unwrap_or_else(|| NO_ID.to_string());
        let at = source.map_or(String::new(), |s| format!("{s}:"));
        let text = errors
            .iter()
            .map(|d| format!("{at}{}:{}: {}", d.pos.line, d.pos.col, d.message))
            .collect::<Vec<_>>()
            .join("; ");
        let text = if text.is_empty() {
            format!("{at} the block could not be read")
                .trim_start()
                .to_string()
        } else {
            text
        };
        self.unframed.push(Feedback::Warning(WarningFeedback {
            id,
            kind: KnownWarning::ParsingFailure.into(),
            character_id,
            text,
        }));
        self.deliver(self.unframed.len() - 1);
    }

    /// Reports input that could not even be read as text (a line that is not UTF-8, or too
    /// long): a PARSING_FAILURE warning with `<no id>` whose text is `SOURCE:LINE: reason`.
    pub fn refuse_line(&mut self, source: &str, bad: &bml::BadLine) {
        let text = format!("{source}:{}: {}", bad.line, bad.reason);
        self.warn_input(KnownWarning::ParsingFailure, text);
    }

    /// Sends a warning of `kind` about input that belongs to no block (`<no id>`), for the
    /// default character.
    fn warn_input(&mut self, kind: KnownWarning, text: String) {
        self.unframed.push(Feedback::Warning(WarningFeedback {
            id: NO_ID.into(),
            kind: kind.into(),
            character_id: self.default_character.clone(),
            text,
        }));
        self.deliver(self.unframed.len() - 1);
    }

    /// What one block may hold.
    pub fn limits(&self) -> &bml::Limits {
        &self.limits
    }

    /// Adds a listener that receives every feedback message from now on, in order.
    pub fn add_listener(&mut self, listener: Box<dyn FeedbackListener>) {
        self.listeners.push(listener);
    }

    /// Stamps and hands to the listeners the feedback from `unframed[from..]`, which is new.
    fn deliver(&mut self, from: usize) {
        let feedback = &mut self.unframed[from..];
        if self.posix_time {
            let ms = SystemTime::now()
                .duration_since(UNIX_EPOCH)
                .map_or(0, |d| d.as_millis() as u64);
            for fb in feedback.iter_mut() {
                match fb {
                    Feedback::BlockProgress(p) => p.posix_time = Some(ms),
                    Feedback::SyncPointProgress(p) => p.posix_time = Some(ms),
                    _ => {}
                }
            }
        }
        for fb in feedback.iter() {
            for l in &mut self.listeners {
                l.feedback(fb);
            }
        }
    }

    /// The feedback sent since the last frame (what performing a block or a message said at
    /// once), taken without moving time: the next frame does not hold it again. A server
    /// answers each block with it, instead of a whole frame per block.
    pub fn take_feedback(&mut self) -> Vec<Feedback> {
        let feedback = std::mem::take(&mut self.unframed);
        self.note_progress(&feedback);
        feedback
    }

    /// Moves time to `now` (never backwards): every character passes the sync points up to then
    /// (characters in id order), engines play, and the frame holds their output and the feedback
    /// sent since the previous frame.
    pub fn tick(&mut self, now: f64) -> Frame {
        let now = if now.is_finite() {
            now.max(self.now)
        } else {
            self.now
        };
        // on the wall clock, the realizer may fall behind (a stalled host, a paused process)
        let due = self
            .next_sync()
            .filter(|t| self.posix_time && now - t > LATE);
        self.now = now;
        // (the world is shared with every character: copied only when a point moves)
        if self.world.moves_at(now) {
            self.world_mut().move_to(now);
        }
        let mut frame = Frame {
            time: now,
            ..Frame::default()
        };
        // sensing reads the world as the previous frame left it; then the nets act on it
        self.sense(now);
        self.run_nets(now);
        let from = self.unframed.len();
        // walkers among others see the crowd on a fixed grid of times, whatever the frames:
        // the characters are stepped to each grid time passed since the last frame
        while self.among_others_moving() {
            let next = grid_time(grid_index(self.world.crowd().time) + 1);
            if next >= now - 1e-9 {
                break;
            }
            self.step_characters(next, &mut Frame::default());
            self.update_crowd(next);
        }
        self.step_characters(now, &mut frame);
        let at = grid_time(grid_index(now));
        if (now - at).abs() < 1e-9 || !self.among_others_moving() {
            self.update_crowd(at);
        }
        if let Some(due) = due {
            self.unframed.push(Feedback::Warning(WarningFeedback {
                id: NO_ID.into(),
                kind: KnownWarning::ExecutionFailure.into(),
                character_id: self.default_character.clone(),
                text: format!(
                    "the realizer fell behind its clock: sync points due from {due:.3} s were reported at {now:.3} s, up to {:.3} s late (their feedback keeps the planned globalTime)",
                    now - due
                ),
            }));
        }
        self.deliver(from);
        // (its feedback is delivered as it is performed)
        self.perform_nets_bml();
        frame.feedback = std::mem::take(&mut self.unframed);
        self.keep_poses(&frame);
        self.note_progress(&frame.feedback);
        frame
    }
}

/// Fewest characters stepped in parallel (below it, threads cost more than they save).
pub const PARALLEL_CHARACTERS: usize = 4;

impl Realizer {
    /// Every character passes its sync points up to `now` (in id order) and plays into
    /// `frame`; where the ones that walked now stand is written to the world (all at once: no
    /// character sees another's move of this step).
    fn step_characters(&mut self, now: f64, frame: &mut Frame) {
        let world = &self.world;
        let step = |m: &mut BlockManager| {
            let mut own = Frame {
                time: frame.time,
                ..Frame::default()
            };
            let mut feedback = Vec::new();
            m.advance(now, world, &mut own);
            m.move_feedback(&mut feedback);
            (own, feedback)
        };
        let mut managers: Vec<&mut BlockManager> = self.characters.values_mut().collect();
        // each character reads only the shared world: they are stepped on all cores and their
        // output is merged in id order, exactly as one thread would produce it
        let parts: Vec<(Frame, Vec<Feedback>)> =
            if self.parallel && managers.len() >= PARALLEL_CHARACTERS {
                use rayon::prelude::*;
                managers.par_iter_mut().map(|m| step(m)).collect()
            } else {
                managers.iter_mut().map(|m| step(m)).collect()
            };
        for (own, feedback) in parts {
            frame.outputs.extend(own.outputs);
            frame.poses.extend(own.poses);
            frame.feedback.extend(own.feedback);
            self.unframed.extend(feedback);
        }
        let moved: Vec<(&str, crate::world::Placement)> = (self.characters.iter())
            .map(|(id, m)| (id.as_str(), m.placement()))
            .filter(|(id, at)| *at != self.world.placement(id))
            .collect();
        if !moved.is_empty() {
            let world = std::sync::Arc::make_mut(&mut self.world);
            for (id, at) in moved {
                let _ = world.place(id, at);
            }
        }
    }

    /// Whether characters are stepped on several threads when there are at least
    /// [`PARALLEL_CHARACTERS`] of them (the default; the output is the same either way).
    pub fn set_parallel(&mut self, on: bool) {
        self.parallel = on;
    }
}

impl RealizerPort for Realizer {
    fn perform_bml(&mut self, bml: &str) {
        // the error is also reported as warning feedback
        let _ = Realizer::perform_bml(self, bml);
    }

    fn add_listener(&mut self, listener: Box<dyn FeedbackListener>) {
        Realizer::add_listener(self, listener);
    }
}
