//! Blocks at run time for one character: the lifecycle state machine (IN_PREP → PENDING | LURKING →
//! IN_EXEC → SUBSIDING → DONE, ending INTERRUPTED or REVOKED), composition (MERGE, APPEND,
//! REPLACE, APPEND-AFTER) and the BMLA block attributes (interrupt, onStart, preplan, appendAfter,
//! chunkAfter, chunkBefore, prependBefore), the event loop that passes sync points at their exact
//! times, the control actions of engines, and the feedback of docs/cli.md.
//!
//! Time is the host's: [`BlockManager::submit`] happens at the manager's current time and
//! [`BlockManager::advance`] moves it forward, processing every event up to the new time in time
//! order (ties: earlier block first, then document order, then sync order). Feedback carries the
//! exact scheduled times, so a run is deterministic whatever the frame rate.
//!
//! One `impl BlockManager` spread over the phases: `submit.rs` (composition → schedule → start or
//! wait), `lifecycle.rs` (starting, activation, ending), `event_loop.rs` (syncs in time order,
//! control actions, parameter changes), `interrupt.rs`, `anticipation.rs` (blocks on pegs),
//! `feedback.rs`; `live.rs` is a block in the plan, `store.rs` the live blocks by stable handle.

mod anticipation;
mod dependencies;
mod event_loop;
mod feedback;
mod interrupt;
mod lifecycle;
mod live;
mod moving;
mod store;
mod submit;

use std::cmp::Reverse;
use std::collections::{BinaryHeap, VecDeque};

// block ids come from the host: a fast hash (rustc's) instead of SipHash
use rustc_hash::FxHashSet as HashSet;

use crate::character::body::{Pose, Skeleton};
use crate::engines::interface::{
    Action, CharacterPose, Frame, ParameterChange, Registry, Unit, UnitKey,
};
use crate::language::bml::{self, Diagnostic, SyncPoint};
use crate::language::feedback::{
    BehaviourPrediction, BlockPrediction, BlockProgress, BlockStatus, Feedback, KnownWarning,
    PredictionFeedback, SyncPointProgress, WarningFeedback,
};
use crate::planning::plan::anticipator::Anticipator;
use crate::planning::plan::pegs::PegBoard;
use crate::planning::plan::to_pegs::BlockPegs;
use crate::planning::plan::to_pegs::{self, Anticipators};
use crate::planning::schedule::{ExternalTimes, SchedulingStrategy};
use crate::planning::timing::TimingModels;
use crate::world::World;
use event_loop::Due;
use live::{anticipator_refs, referenced_points, LiveBlock, Phase};
use store::{BlockKey, Blocks};

/// How late a block may start so that its references to other blocks' sync points that have just
/// passed still hold exactly (a block sent a frame after the moment it refers to): it starts that
/// much in the past instead of failing those constraints.
pub const LATE_START: f64 = 0.25;

/// How many ids of finished blocks are remembered (so that late references to them are quiet
/// no-ops rather than NO_SUCH_TARGET warnings).
pub const FINISHED_HISTORY: usize = 4096;

/// Counts of what the manager holds (bounded-memory checks).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Sizes {
    /// Blocks not yet finished.
    pub blocks: usize,
    /// Units held by all engines.
    pub engine_units: usize,
    /// Running parameter changes.
    pub parameter_changes: usize,
    /// Remembered ids of finished blocks.
    pub finished_ids: usize,
}

/// The blocks of one character and the engines that realize them.
pub struct BlockManager {
    /// The next sync of every live behaviour, earliest first (see [`Self::next_sync`]).
    due: std::cell::RefCell<BinaryHeap<Reverse<Due>>>,
    /// The plan changed since `due` was built.
    due_stale: std::cell::Cell<bool>,
    registry: Registry,
    strategy: Box<dyn SchedulingStrategy>,
    character: Option<String>,
    /// Live blocks in arrival order, by handle and by id.
    blocks: Blocks,
    /// How many blocks are LURKING (nothing to check when none is).
    lurking: usize,
    finished: VecDeque<bml::Id>,
    finished_set: HashSet<bml::Id>,
    changes: Vec<ParameterChange>,
    anticipators: Vec<Box<dyn Anticipator>>,
    /// Units whose end passed during this advance: engines drop them after the frame, so that
    /// the frame at their end still shows their last moment.
    retiring: Vec<(crate::engines::interface::EngineId, UnitKey)>,
    skeleton: Skeleton,
    /// The idle layer every frame's pose starts from (`None`: the rest pose).
    idle: Option<crate::character::body::idle::Idle>,
    /// What the character adds to its engines' pose and face (lids, jaw, limits, placement).
    assembler: crate::character::Assembler,
    /// The sounds that played in the last frame (ids).
    playing: Vec<String>,
    /// The utterance the character began last (the idle layer's eyes look away as it begins;
    /// kept after it ends, so that the look back completes).
    utterance: Option<crate::character::body::aversion::Utterance>,
    /// The world as of the last advance (shared with the realizer).
    shared: std::sync::Arc<World>,
    /// That world as this character sees it, from where it stands (what its engines get).
    world: std::sync::Arc<World>,
    /// Where it stands in the world: its frames' root is placed there.
    placement: crate::world::Placement,
    /// Whether an engine has moved the character from where it was first placed.
    moved: bool,
    now: f64,
    seq: u64,
    out: Vec<Feedback>,
}

impl BlockManager {
    /// A manager for `character` (None: the default character) with these engines and strategy.
    pub fn new(
        registry: Registry,
        strategy: Box<dyn SchedulingStrategy>,
        character: Option<String>,
    ) -> Self {
        let skeleton = Skeleton::adult();
        let idle =
            crate::character::body::idle::Idle::new(character.as_deref().unwrap_or(""), &skeleton);
        let assembler = crate::character::Assembler::new(character.as_deref().unwrap_or(""), true);
        BlockManager {
            due: std::cell::RefCell::new(BinaryHeap::new()),
            due_stale: std::cell::Cell::new(true),
            registry,
            strategy,
            character,
            blocks: Blocks::default(),
            lurking: 0,
            finished: VecDeque::new(),
            finished_set: HashSet::default(),
            changes: Vec::new(),
            anticipators: Vec::new(),
            retiring: Vec::new(),
            skeleton,
            idle: Some(idle),
            assembler,
            playing: Vec::new(),
            utterance: None,
            shared: std::sync::Arc::new(World::default()),
            world: std::sync::Arc::new(World::default()),
            placement: crate::world::Placement::default(),
            moved: false,
            now: 0.0,
            seq: 0,
            out: Vec::new(),
        }
    }

    /// Uses `skeleton` for this character's body (the default adult otherwise). Set it before the
    /// character acts: engines may keep measurements of the skeleton.
    pub fn set_skeleton(&mut self, skeleton: Skeleton) {
        self.skeleton = skeleton;
        let on = self.idle.is_some();
        self.set_idle(on);
    }

    /// Uses `world` for targets and for where the character stands from now on (the realizer
    /// shares its world this way). The engines get it as seen from the character.
    pub fn set_world(&mut self, world: &std::sync::Arc<World>) {
        if std::sync::Arc::ptr_eq(&self.shared, world) {
            return;
        }
        self.shared = world.clone();
        let id = self.character.as_deref().unwrap_or("");
        self.placement = world.placement(id);
        self.world = if self.placement.is_origin() {
            world.clone()
        } else {
            std::sync::Arc::new(world.seen_from(id))
        };
    }

    /// Turns the idle layer (breathing, a slow weight shift, blinks) on or off; it is on by
    /// default. It never changes the feedback.
    pub fn set_idle(&mut self, on: bool) {
        let id = self.character.as_deref().unwrap_or("");
        self.idle = on.then(|| crate::character::body::idle::Idle::new(id, &self.skeleton));
        self.assembler.set_idle(id, on);
    }

    /// Notes the utterance being said at `now` that began last, if the engines say one (the
    /// last one noted stays until another begins).
    fn hear_utterance(&mut self, now: f64) {
        let said = (self.registry.engines())
            .filter_map(|e| e.as_speaking()?.utterance(now))
            .max_by(|a, b| a.start.total_cmp(&b.start));
        if said.is_some() {
            self.utterance = said;
        }
    }

    /// The pose a frame at `t` starts from: the idle layer's, or the rest pose.
    fn base_pose(&self, t: f64) -> Pose {
        match &self.idle {
            Some(idle) => idle.pose(&self.skeleton, t, self.utterance.as_ref()),
            None => Pose::rest(&self.skeleton),
        }
    }

    /// The character's skeleton.
    pub fn skeleton(&self) -> &Skeleton {
        &self.skeleton
    }

    /// The current time (the last time advanced to).
    pub fn now(&self) -> f64 {
        self.now
    }

    /// The engines, to change (a host pushing a simulated body).
    pub fn registry_mut(&mut self) -> &mut Registry {
        &mut self.registry
    }

    /// The engines.
    pub fn registry(&self) -> &Registry {
        &self.registry
    }

    /// Moves the feedback produced so far to the end of `to`; the manager keeps its list's
    /// capacity for the next messages.
    pub fn move_feedback(&mut self, to: &mut Vec<Feedback>) {
        to.append(&mut self.out);
    }

    /// What the manager holds.
    pub fn sizes(&self) -> Sizes {
        Sizes {
            blocks: self.blocks.len(),
            engine_units: self.registry.engines().map(|e| e.len()).sum(),
            parameter_changes: self.changes.len(),
            finished_ids: self.finished.len(),
        }
    }

    /// Status of block `id`: its live status, DONE if it finished recently, `None` if unknown.
    pub fn status(&self, id: &str) -> Option<BlockStatus> {
        match self.blocks.named(id) {
            Some(b) => Some(b.status),
            None => self.finished_set.contains(id).then_some(BlockStatus::Done),
        }
    }

    /// Whether any block has been accepted for this character (a block refused for a duplicate
    /// id does not count).
    pub fn received_blocks(&self) -> bool {
        self.seq > 0
    }

    /// Whether an engine has moved the character about (it walked, or stepped aside for
    /// someone without a block of its own).
    pub fn moved(&self) -> bool {
        self.moved
    }

    /// Ids and statuses of the blocks not yet finished, in arrival order.
    pub fn live_blocks(&self) -> Vec<(String, BlockStatus)> {
        self.blocks
            .iter()
            .map(|b| (b.id.to_string(), b.status))
            .collect()
    }

    /// The time of the next event (a sync point of a running block), if any. `None` when nothing
    /// will happen without outside input (all done, only persistent behaviour, or blocks waiting
    /// for an activation).
    pub fn next_event(&self) -> Option<f64> {
        let sync = self
            .next_sync()
            .map(|(t, _, _)| t)
            .filter(|t| t.is_finite());
        match (sync, self.next_prediction_change()) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        }
    }
}

#[cfg(test)]
mod tests;
