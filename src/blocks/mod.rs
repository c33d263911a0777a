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

mod anticipation;
mod live;

use std::cmp::Reverse;
use std::collections::{BinaryHeap, VecDeque};

// block ids come from the host: a fast hash (rustc's) instead of SipHash for the block index
use rustc_hash::{FxHashMap as HashMap, FxHashSet as HashSet};

use crate::bml::{self, Diagnostic, SyncPoint};
use crate::body::{Pose, Skeleton};
use crate::engine::{Action, CharacterPose, Frame, ParameterChange, Registry, Unit, UnitKey};
use crate::feedback::{
    BehaviourPrediction, BlockPrediction, BlockProgress, BlockStatus, Feedback, KnownWarning,
    PredictionFeedback, SyncPointProgress, WarningFeedback,
};
use crate::plan::anticipator::Anticipator;
use crate::plan::pegs::PegBoard;
use crate::plan::to_pegs::BlockPegs;
use crate::plan::to_pegs::{self, Anticipators};
use crate::schedule::{ExternalTimes, SchedulingStrategy};
use crate::timing::TimingModels;
use crate::world::World;
use live::{anticipator_refs, referenced_points, LiveBlock, Phase};

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

/// A behaviour's next sync in the heap of [`BlockManager::next_sync`], ordered by time (in whole
/// nanoseconds, so that float noise makes ties), then block arrival, then document order.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
struct Due {
    ns: i64,
    seq: u64,
    index: usize,
    /// The behaviour's position in its block, and the sync's position in the behaviour.
    xi: usize,
    k: usize,
}

/// A global time in whole nanoseconds.
fn due_ns(t: f64) -> i64 {
    (t * 1e9).round() as i64
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
    /// Live blocks in arrival order (so sorted by `seq`).
    blocks: Vec<LiveBlock>,
    /// The blocks' `seq`s, in the same order: searched instead of the large blocks themselves.
    seqs: Vec<u64>,
    /// Block id → seq, to find a block without scanning.
    index: HashMap<bml::Id, u64>,
    /// How many blocks are LURKING (nothing to check when none is).
    lurking: usize,
    finished: VecDeque<bml::Id>,
    finished_set: HashSet<bml::Id>,
    changes: Vec<ParameterChange>,
    anticipators: Vec<Box<dyn Anticipator>>,
    /// Units whose end passed during this advance: engines drop them after the frame, so that
    /// the frame at their end still shows their last moment.
    retiring: Vec<(usize, UnitKey)>,
    skeleton: Skeleton,
    /// The world as of the last advance (shared with the realizer).
    world: std::sync::Arc<World>,
    now: f64,
    seq: u64,
    out: Vec<Feedback>,
}

/// Times of other blocks' syncs relative to the start of a block being scheduled.
struct OtherBlocks<'a> {
    blocks: &'a [LiveBlock],
    seqs: &'a [u64],
    index: &'a HashMap<bml::Id, u64>,
    anticipators: &'a [Box<dyn Anticipator>],
    start: f64,
}

/// Where block `id` is among the blocks whose `seq`s are `seqs` (increasing).
fn position(seqs: &[u64], index: &HashMap<bml::Id, u64>, id: &str) -> Option<usize> {
    let seq = *index.get(id)?;
    // where it is if no block after it has left (the usual case: blocks mostly end in order,
    // and references go to recent blocks), else a binary search
    let guess = seqs
        .len()
        .checked_sub(1 + usize::try_from(seqs.last()?.checked_sub(seq)?).ok()?);
    match guess {
        Some(i) if seqs[i] == seq => Some(i),
        _ => seqs.binary_search(&seq).ok(),
    }
}

impl ExternalTimes for OtherBlocks<'_> {
    fn time(&self, point: &SyncPoint) -> Option<f64> {
        match point {
            SyncPoint::External {
                block,
                behaviour,
                sync,
            } => {
                let b = &self.blocks[position(self.seqs, self.index, block)?];
                let local = b.behaviour(behaviour)?.time(sync)?;
                Some(b.start + local - self.start)
            }
            SyncPoint::Anticipator { anticipator, sync } => {
                let a = self.anticipators.iter().find(|a| a.id() == anticipator)?;
                Some(a.predict(sync)? - self.start)
            }
            SyncPoint::Local { .. } => None,
        }
    }
}

impl BlockManager {
    /// A manager for `character` (None: the default character) with these engines and strategy.
    pub fn new(
        registry: Registry,
        strategy: Box<dyn SchedulingStrategy>,
        character: Option<String>,
    ) -> Self {
        BlockManager {
            due: std::cell::RefCell::new(BinaryHeap::new()),
            due_stale: std::cell::Cell::new(true),
            registry,
            strategy,
            character,
            blocks: Vec::new(),
            seqs: Vec::new(),
            index: HashMap::default(),
            lurking: 0,
            finished: VecDeque::new(),
            finished_set: HashSet::default(),
            changes: Vec::new(),
            anticipators: Vec::new(),
            retiring: Vec::new(),
            skeleton: Skeleton::adult(),
            world: std::sync::Arc::new(World::default()),
            now: 0.0,
            seq: 0,
            out: Vec::new(),
        }
    }

    /// Uses `skeleton` for this character's body (the default adult otherwise). Set it before the
    /// character acts: engines may keep measurements of the skeleton.
    pub fn set_skeleton(&mut self, skeleton: Skeleton) {
        self.skeleton = skeleton;
    }

    /// Uses `world` for targets from now on (the realizer shares its world this way).
    pub fn set_world(&mut self, world: &std::sync::Arc<World>) {
        if !std::sync::Arc::ptr_eq(&self.world, world) {
            self.world = world.clone();
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
        match self.pos(id) {
            Some(i) => Some(self.blocks[i].status),
            None => self.finished_set.contains(id).then_some(BlockStatus::Done),
        }
    }

    /// Whether any block has been accepted for this character (a block refused for a duplicate
    /// id does not count).
    pub fn received_blocks(&self) -> bool {
        self.seq > 0
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

    // ---------------------------------------------------------------------------------------
    // feedback helpers

    fn emit(&mut self, fb: Feedback) {
        self.out.push(fb);
    }

    fn warn(&mut self, id: impl Into<String>, kind: KnownWarning, text: String) {
        let character_id = self.character.clone();
        self.emit(Feedback::Warning(WarningFeedback {
            id: id.into(),
            kind: kind.into(),
            character_id,
            text,
        }));
    }

    fn predict(&mut self, i: usize, with_behaviours: bool) {
        let fb = self.prediction(&self.blocks[i], with_behaviours);
        self.emit(fb);
    }

    fn prediction(&self, b: &LiveBlock, with_behaviours: bool) -> Feedback {
        let end = b.predicted_end();
        // the feedback is kept until the host takes it: every list gets its exact size
        let behaviours = if with_behaviours {
            let live = || b.behaviours.iter().filter(|x| x.phase != Phase::Removed);
            let mut v = Vec::with_capacity(live().count());
            v.extend(live().map(|x| {
                // (a persistent behaviour's end is infinite: not a prediction)
                let syncs = if x.syncs.iter().all(|s| s.1.is_finite()) {
                    x.syncs.clone()
                } else {
                    x.syncs
                        .iter()
                        .filter(|s| s.1.is_finite())
                        .cloned()
                        .collect()
                };
                BehaviourPrediction {
                    kind: b.source.behaviours[x.index].kind.element_id(),
                    block: b.id.clone(),
                    behaviour: x.id.clone(),
                    syncs,
                }
            }));
            v
        } else {
            Vec::new()
        };
        let fb = PredictionFeedback {
            character_id: self.character.clone(),
            blocks: vec![BlockPrediction {
                id: b.id.clone(),
                global_start: Some(b.start),
                // unknown while scheduling (the harness waits for a known end)
                global_end: end.filter(|e| e.is_finite() && b.status != BlockStatus::InPrep),
                status: Some(b.status),
            }],
            behaviours,
        };
        Feedback::Prediction(fb)
    }

    fn progress(&mut self, block: &bml::Id, sync: &'static str, t: f64, status: BlockStatus) {
        let character_id = self.character.clone();
        self.emit(Feedback::BlockProgress(BlockProgress {
            block: block.clone(),
            sync: bml::Id::new_static(sync),
            global_time: t,
            character_id,
            status: Some(status),
            posix_time: None,
        }));
    }

    // ---------------------------------------------------------------------------------------
    // submitting a block

    /// Reports what of an accepted block will not be interpreted: extension attributes that no
    /// engine reads (CUSTOM_ATTRIBUTE_NOT_SUPPORTED) and extension content the parser ignored.
    /// Unknown behaviour kinds are reported when scheduling finds no engine for them; lexemes when
    /// an engine cannot realize them.
    fn parse_warnings(&mut self, block: &bml::Block, warnings: &[Diagnostic]) {
        for a in &block.foreign_attrs {
            self.warn(
                block.id.to_string(),
                KnownWarning::CustomAttributeNotSupported,
                format!(
                    "attribute '{}' (namespace {}) on <bml id=\"{}\"> is not interpreted and is ignored",
                    a.name, a.ns, block.id
                ),
            );
        }
        for b in &block.behaviours {
            let Some(engine) = self.registry.engine_for(b) else {
                continue;
            };
            for a in &b.foreign_attrs {
                if !self.registry.engine(engine).interprets(&a.ns, &a.name) {
                    self.warn(
                        format!("{}:{}", block.id, b.id),
                        KnownWarning::CustomAttributeNotSupported,
                        format!(
                            "attribute '{}' (namespace {}) on <{} id=\"{}\"> is not interpreted and is ignored",
                            a.name,
                            a.ns,
                            b.kind.element_name(),
                            b.id
                        ),
                    );
                }
            }
        }
        for d in warnings {
            let ignored_content = d.code == bml::Code::UnsupportedExtension
                && !block
                    .behaviours
                    .iter()
                    .any(|b| (b.pos.line, b.pos.col) == (d.pos.line, d.pos.col));
            if ignored_content {
                self.warn(
                    block.id.to_string(),
                    KnownWarning::BehaviorTypeNotSupported,
                    format!("{}:{}: {}", d.pos.line, d.pos.col, d.message),
                );
            }
        }
    }

    /// Plans `block` at the current time: interrupts, composition, scheduling, and its start if
    /// nothing holds it back. Every problem becomes a warning; the block is rejected only if its
    /// id is in use or its required behaviours cannot be scheduled.
    pub fn submit(&mut self, block: bml::Block, warnings: &[Diagnostic]) {
        self.touch();
        let now = self.now;
        if let Some(i) = self.pos(&block.id) {
            let status = self.blocks[i].status;
            self.warn(
                block.id.to_string(),
                KnownWarning::ImpossibleToSchedule,
                format!(
                    "block id '{}' is still in use (status {status}); the new block is ignored",
                    block.id
                ),
            );
            return;
        }
        self.parse_warnings(&block, warnings);
        // blocks named in bmla:interrupt leave the plan first, then REPLACE removes everything;
        // what waited for them starts only once all of them are gone
        for target in &block.ext.interrupt {
            self.interrupt_block_by_id(target, now, &block.id);
        }
        if block.composition == bml::Composition::Replace {
            let ids: Vec<bml::Id> = self.blocks.iter().map(|b| b.id.clone()).collect();
            for id in ids {
                self.interrupt_block_by_id(&id, now, &block.id);
            }
        }
        self.start_ready(now);
        // blocks this one waits for
        let mut waits_for: Vec<bml::Id> = match &block.composition {
            bml::Composition::Append => self
                .blocks
                .iter()
                .filter(|b| b.status != BlockStatus::Pending)
                .map(|b| b.id.clone())
                .collect(),
            bml::Composition::AppendAfter(ids) => self.existing(ids, &block.id),
            _ => Vec::new(),
        };
        for id in self.existing(&block.ext.append_after, &block.id) {
            if !waits_for.contains(&id) {
                waits_for.push(id);
            }
        }
        let chunk_after = self.existing(&block.ext.chunk_after, &block.id);
        let mut start = self.predicted_start(now, &waits_for, &chunk_after);
        // a block tied to another block's sync point that passed a moment ago starts then
        let mut on_anticipators = false;
        for p in referenced_points(&block) {
            on_anticipators |= matches!(p, SyncPoint::Anticipator { .. });
            if let SyncPoint::External {
                block: b,
                behaviour,
                sync,
            } = p
            {
                let t = self.pos(b).and_then(|i| {
                    let other = &self.blocks[i];
                    Some(other.start + other.behaviour(behaviour)?.time(sync)?)
                });
                if let Some(t) = t.filter(|t| *t < start && start - *t <= LATE_START) {
                    start = t;
                }
            }
        }

        // scheduling starts
        self.seq += 1;
        let mut live = LiveBlock::new(block, self.seq, start, waits_for, chunk_after);
        let fb = self.prediction(&live, false);
        self.emit(fb);

        let schedule = {
            let external = OtherBlocks {
                blocks: &self.blocks,
                seqs: &self.seqs,
                index: &self.index,
                anticipators: &self.anticipators,
                start,
            };
            self.strategy
                .schedule(&live.source, &self.registry, &external)
        };
        let schedule = match schedule {
            Ok(mut s) => {
                // (asked only of a behaviour whose end is infinite)
                s.drop_unreachable(|id| {
                    let b = live.source.behaviours.iter().find(|b| b.id == *id);
                    b.and_then(|b| TimingModels::model(&self.registry, b))
                        .is_some_and(|m| m.persistent)
                });
                s
            }
            Err(e) => {
                let id = live.id.clone();
                self.warn(id, KnownWarning::CannotSatisfyConstraints, e.to_string());
                return;
            }
        };
        for d in &schedule.dropped {
            self.warn(
                format!("{}:{}", live.id, d.behaviour),
                d.warning,
                d.reason.clone(),
            );
        }
        let refs = if on_anticipators {
            anticipator_refs(&live.source)
        } else {
            Vec::new()
        };
        if !refs.is_empty() {
            // its own peg board: anticipator moves retime it without rescheduling
            let (mut board, mut anticipators) = (PegBoard::new(), Anticipators::default());
            for (a, sync) in refs {
                let predicted = self
                    .anticipators
                    .iter()
                    .find(|x| x.id() == a)
                    .and_then(|x| x.predict(sync));
                if let Some(t) = predicted.filter(|t| t.is_finite()) {
                    anticipators.peg(&mut board, a, sync, t);
                }
            }
            let plan = to_pegs::plan_block(
                &mut board,
                &mut anticipators,
                &live.source,
                &schedule,
                start,
            );
            live.pegs = Some(Box::new(BlockPegs {
                board,
                anticipators,
                plan,
            }));
        }
        live.set_schedule(schedule, &self.registry);
        for (beh, reason) in live.resolve_exclusive_ties(&self.registry) {
            self.warn(
                format!("{}:{beh}", live.id),
                KnownWarning::ImpossibleToSchedule,
                reason,
            );
        }
        // chunkBefore / prependBefore: make other blocks wait for this one
        let id = live.id.clone();
        let ext = &live.source.ext;
        for (targets, chunk) in [(&ext.chunk_before, true), (&ext.prepend_before, false)] {
            for t in targets {
                match self.pos(t).map(|i| &mut self.blocks[i]) {
                    Some(b) if !b.started() => {
                        let list = if chunk {
                            &mut b.chunk_after
                        } else {
                            &mut b.waits_for
                        };
                        list.push(id.clone());
                    }
                    Some(_) => self.warn(
                        id.clone(),
                        KnownWarning::ImpossibleToSchedule,
                        format!("block '{t}' has already started; '{id}' cannot go before it"),
                    ),
                    None => self.warn(
                        id.clone(),
                        KnownWarning::NoSuchTarget,
                        format!("no block '{t}' to go before"),
                    ),
                }
            }
        }
        // scheduled: PENDING, and pre-planned blocks wait for an activation
        let preplan = ext.preplan;
        live.status = BlockStatus::Pending;
        live.preplan = preplan;
        self.index.insert(live.id.clone(), live.seq);
        self.seqs.push(live.seq);
        self.blocks.push(live);
        let i = self.blocks.len() - 1;
        self.predict(i, true);
        if !preplan {
            if self.ready(i) {
                // at its planned start: now, or a moment ago (LATE_START)
                let t = self.blocks[i].start.min(now);
                self.start_block(i, t);
            } else {
                self.release(i, now);
            }
        }
        self.start_ready(now);
    }

    /// The ids of `ids` that name live blocks. Unknown ids that never existed get a warning.
    fn existing(&mut self, ids: &[String], by: &str) -> Vec<bml::Id> {
        let mut v = Vec::new();
        for id in ids {
            if self.pos(id).is_some() {
                v.push(bml::Id::new(id));
            } else if !self.finished_set.contains(id.as_str()) {
                self.warn(
                    by.to_string(),
                    KnownWarning::NoSuchTarget,
                    format!("block '{by}' refers to block '{id}', which does not exist"),
                );
            }
        }
        v
    }

    fn predicted_start(&self, now: f64, waits_for: &[bml::Id], chunk_after: &[bml::Id]) -> f64 {
        let mut start = now;
        for (ids, subsiding) in [(waits_for, false), (chunk_after, true)] {
            for b in ids
                .iter()
                .filter_map(|id| self.pos(id))
                .map(|i| &self.blocks[i])
            {
                let t = if subsiding {
                    b.predicted_subsiding()
                } else {
                    b.predicted_end()
                };
                start = start.max(t.unwrap_or(now));
            }
        }
        if start.is_finite() {
            start
        } else {
            now
        }
    }

    /// Where block `id` is in `self.blocks`.
    fn pos(&self, id: &str) -> Option<usize> {
        position(&self.seqs, &self.index, id)
    }

    /// A PENDING block that may run: it starts now if nothing holds it back, else it is LURKING
    /// (with its prediction) until [`start_ready`](Self::start_ready) starts it. Block indices may
    /// change (a block that starts can end at once).
    fn release(&mut self, i: usize, now: f64) {
        self.blocks[i].preplan = false;
        if self.blocks[i].status == BlockStatus::Lurking {
            return;
        }
        if self.ready(i) {
            self.start_block(i, now);
            return;
        }
        let (w, c) = (
            self.blocks[i].waits_for.clone(),
            self.blocks[i].chunk_after.clone(),
        );
        self.blocks[i].start = self.predicted_start(now, &w, &c);
        self.blocks[i].status = BlockStatus::Lurking;
        self.lurking += 1;
        self.predict(i, false);
    }

    /// every append target is done and every chunk target subsiding or done.
    fn ready(&self, i: usize) -> bool {
        let b = &self.blocks[i];
        let live = |id: &bml::Id| self.pos(id).map(|i| &self.blocks[i]);
        b.waits_for.iter().all(|id| live(id).is_none())
            && b.chunk_after.iter().all(|id| {
                live(id)
                    .is_none_or(|x| matches!(x.status, BlockStatus::Subsiding | BlockStatus::Done))
            })
    }

    /// Starts every LURKING block that is ready, at `t`, until none is left (a start can end a
    /// block at once, which can make others ready).
    fn start_ready(&mut self, t: f64) {
        while self.lurking > 0 {
            let next = (0..self.blocks.len())
                .find(|&i| self.blocks[i].status == BlockStatus::Lurking && self.ready(i));
            match next {
                Some(i) => self.start_block(i, t),
                None => return,
            }
        }
    }

    /// the block peg moves to `t`, start feedback, onStart activations, units to engines.
    fn start_block(&mut self, i: usize, t: f64) {
        if self.blocks[i].status == BlockStatus::Lurking {
            self.lurking -= 1;
        }
        let moved = self.blocks[i].start != t;
        if let Some(p) = self.blocks[i].pegs.as_mut() {
            // the block peg moves to now; syncs hanging on anticipators stay where they are
            let block = p.plan.block;
            let _ = p.board.set_block_start(block, t);
        }
        self.blocks[i].start = t;
        if moved && self.blocks[i].pegs.is_some() {
            self.follow_pegs(i, t);
        }
        let b = &mut self.blocks[i];
        b.start = t;
        b.status = BlockStatus::InExec;
        let id = b.id.clone();
        self.progress(&id, "start", t, BlockStatus::InExec);
        // hand every unit to its engine
        let (mut failed, mut moves_nothing) = (Vec::new(), Vec::new());
        {
            let b = &mut self.blocks[i];
            for x in b
                .behaviours
                .iter_mut()
                .filter(|x| x.phase == Phase::Planned)
            {
                let key = UnitKey::new(b.id.clone(), x.id.clone());
                let unit = Unit {
                    key: &key,
                    behaviour: &b.source.behaviours[x.index],
                    syncs: x.global(t),
                    world: &self.world,
                };
                let unanimated = self.registry.engine(x.engine).unanimated(unit.behaviour);
                match self.registry.engine_mut(x.engine).add(unit) {
                    Ok(()) => {
                        x.phase = Phase::Added;
                        if let Some(why) = unanimated {
                            moves_nothing.push((x.id.clone(), why));
                        }
                    }
                    Err(e) => {
                        x.phase = Phase::Removed;
                        failed.push((x.id.clone(), e.to_string()));
                    }
                }
            }
        }
        for (beh, reason) in failed {
            self.warn(
                format!("{id}:{beh}"),
                KnownWarning::ExecutionFailure,
                reason,
            );
        }
        for (beh, reason) in moves_nothing {
            self.warn(
                format!("{id}:{beh}"),
                KnownWarning::LexemeNotSupported,
                reason,
            );
        }
        self.coarticulate(i, t);
        if !self.blocks[i].all_ended() {
            self.predict(i, false);
        }
        // activations may start (and end) other blocks: find this one again by id afterwards
        let on_start = self.blocks[i].source.ext.on_start.clone();
        for target in on_start {
            self.activate(&target, t, &id);
        }
        if let Some(i) = self.pos(&id) {
            self.finish_if_done(i, t);
        }
    }

    /// A chunked block starting at `t` takes over from the blocks it is chunked after: their
    /// behaviours that are retracting (past `relax`) on a body resource this block uses (a hand,
    /// the voice) skip the rest of the retraction and end now.
    fn coarticulate(&mut self, i: usize, t: f64) {
        if self.blocks[i].chunk_after.is_empty() {
            return;
        }
        let mut used: Vec<&'static str> = Vec::new();
        for x in self.blocks[i]
            .behaviours
            .iter()
            .filter(|x| x.phase != Phase::Removed)
        {
            let b = &self.blocks[i].source.behaviours[x.index];
            used.extend(self.registry.engine(x.engine).resources(b));
        }
        if used.is_empty() {
            return;
        }
        for target in self.blocks[i].chunk_after.clone() {
            let Some(j) = self.pos(&target) else { continue };
            for xi in 0..self.blocks[j].behaviours.len() {
                let x = &self.blocks[j].behaviours[xi];
                let relax = x.syncs.iter().position(|(n, _)| n == "relax");
                let retracting = x.phase == Phase::Running && relax.is_some_and(|r| x.next > r);
                let b = &self.blocks[j].source.behaviours[x.index];
                let shares = self
                    .registry
                    .engine(x.engine)
                    .resources(b)
                    .iter()
                    .any(|r| used.contains(r));
                if !(retracting && shares) {
                    continue;
                }
                self.interrupt_unit(j, xi, t);
            }
        }
    }

    /// Activates pre-planned block `target` (by `activate` or onStart).
    fn activate(&mut self, target: &str, t: f64, by: &str) {
        match self.pos(target) {
            Some(j) if self.blocks[j].status == BlockStatus::Pending => {
                self.release(j, t);
                self.start_ready(t);
            }
            Some(_) => {} // already on its way: activating twice is a no-op
            None if self.finished_set.contains(target) => {}
            None => self.warn(
                by.to_string(),
                KnownWarning::NoSuchTarget,
                format!("cannot activate block '{target}': no such block"),
            ),
        }
    }

    /// Ends block `i` with DONE (INTERRUPTED if an interrupt cut it) if every behaviour still in
    /// its plan has ended, and starts what waited for it.
    fn finish_if_done(&mut self, i: usize, t: f64) -> bool {
        if !self.blocks[i].all_ended() {
            return false;
        }
        let status = if self.blocks[i].cut {
            BlockStatus::Interrupted
        } else {
            BlockStatus::Done
        };
        self.end_block(i, t, status);
        self.start_ready(t);
        true
    }

    /// Removes block `i` from the plan with end feedback of `status`. What waited for it is
    /// started by the caller, once it has removed all it removes (a queued block that REPLACE is
    /// about to remove must not start first).
    fn end_block(&mut self, i: usize, t: f64, status: BlockStatus) {
        let b = self.blocks.remove(i);
        self.seqs.remove(i);
        self.index.remove(&b.id);
        if b.status == BlockStatus::Lurking {
            self.lurking -= 1;
        }
        for x in &b.behaviours {
            let key = UnitKey::new(b.id.clone(), x.id.clone());
            match x.phase {
                // it reached its end: it shows its last moment in this frame, then goes
                Phase::Ended => self.retiring.push((x.engine, key)),
                Phase::Added | Phase::Running => self.registry.engine_mut(x.engine).remove(&key),
                Phase::Planned | Phase::Removed => {}
            }
        }
        self.changes.retain(|c| c.target.block != b.id);
        self.progress(&b.id, "end", t, status);
        self.remember(b.id);
    }

    fn remember(&mut self, id: bml::Id) {
        if self.finished_set.insert(id.clone()) {
            self.finished.push_back(id);
            if self.finished.len() > FINISHED_HISTORY {
                if let Some(old) = self.finished.pop_front() {
                    self.finished_set.remove(&old);
                }
            }
        }
    }

    // ---------------------------------------------------------------------------------------
    // interruption

    /// The live block `target` of an interrupt by `by`. A block that finished a moment ago is a
    /// quiet no-op; one that never existed gets a NO_SUCH_TARGET warning.
    fn interrupt_target(&mut self, target: &str, by: &str) -> Option<usize> {
        let i = self.pos(target);
        if i.is_none() && !self.finished_set.contains(target) {
            self.warn(
                by.to_string(),
                KnownWarning::NoSuchTarget,
                format!("cannot interrupt block '{target}': no such block"),
            );
        }
        i
    }

    /// Interrupts a whole block: before its start it is revoked; while running, every behaviour
    /// that started reports its remaining syncs now, the others are dropped, and it ends
    /// INTERRUPTED.
    fn interrupt_block_by_id(&mut self, target: &str, t: f64, by: &str) {
        let Some(i) = self.interrupt_target(target, by) else {
            return;
        };
        if !self.blocks[i].started() {
            self.end_block(i, t, BlockStatus::Revoked);
            return;
        }
        let id = self.blocks[i].id.clone();
        let start = self.blocks[i].start;
        let mut reports = Vec::new();
        for x in &mut self.blocks[i].behaviours {
            if x.phase == Phase::Running {
                for (name, _) in &x.syncs[x.next..] {
                    reports.push((x.id.clone(), name.clone()));
                }
                x.next = x.syncs.len();
                x.phase = Phase::Ended;
            }
        }
        // every sync still ahead is cut; the behaviour ends now
        for (beh, sync) in reports {
            let skipped = sync != "end";
            self.sync_feedback(&id, &beh, &sync, t - start, t, skipped);
        }
        self.end_block(i, t, BlockStatus::Interrupted);
    }

    /// Ends running behaviour `xi` of block `bi` at `t` the way its engine ends interrupted units
    /// (speech stops, motion retracts from now); its remaining syncs take the engine's times.
    fn interrupt_unit(&mut self, bi: usize, xi: usize, t: f64) {
        let b = &self.blocks[bi];
        let (start, x) = (b.start, &b.behaviours[xi]);
        let key = UnitKey::new(b.id.clone(), x.id.clone());
        let times = self
            .registry
            .engine_mut(x.engine)
            .interrupt(&key, t, &x.global(start));
        let x = &mut self.blocks[bi].behaviours[xi];
        x.retime(&times, start, t);
        x.cut_before_retraction();
    }

    /// Interrupts behaviours of block `target` at `t` (a BMLA interrupt behaviour): a behaviour
    /// not yet started leaves the plan; a running one ends the way its engine says (speech stops,
    /// motion retracts from now).
    fn interrupt_behaviours(
        &mut self,
        by: &UnitKey,
        target: &str,
        include: &[String],
        exclude: &[String],
        t: f64,
    ) {
        let Some(i) = self.interrupt_target(target, &by.to_string()) else {
            return;
        };
        for id in include.iter().chain(exclude) {
            if self.blocks[i].behaviour(id).is_none() {
                self.warn(
                    by.to_string(),
                    KnownWarning::NoSuchTarget,
                    format!("block '{target}' has no behaviour '{id}'"),
                );
            }
        }
        for xi in 0..self.blocks[i].behaviours.len() {
            let x = &self.blocks[i].behaviours[xi];
            let selected = (include.is_empty() || include.iter().any(|s| *s == x.id))
                && !exclude.iter().any(|s| *s == x.id);
            if !selected {
                continue;
            }
            // a running block that loses behaviours this way was cut short
            let cut = matches!(x.phase, Phase::Planned | Phase::Added | Phase::Running);
            if cut && self.blocks[i].started() {
                self.blocks[i].cut = true;
            }
            let x = &self.blocks[i].behaviours[xi];
            match x.phase {
                Phase::Planned => self.blocks[i].behaviours[xi].phase = Phase::Removed,
                Phase::Added => {
                    let key = UnitKey::new(self.blocks[i].id.clone(), x.id.clone());
                    self.registry.engine_mut(x.engine).remove(&key);
                    self.blocks[i].behaviours[xi].phase = Phase::Removed;
                }
                Phase::Running => self.interrupt_unit(i, xi, t),
                Phase::Ended | Phase::Removed => {}
            }
        }
        if self.blocks[i].started() {
            self.finish_if_done(i, t);
        }
    }

    // ---------------------------------------------------------------------------------------
    // the event loop

    /// The next sync point due: (global time, block index, behaviour index). Ties (times within
    /// a nanosecond: float noise of the solver) go to the earlier block, then document order.
    ///
    /// Every live behaviour's next sync waits in a heap. It is rebuilt after a change of the plan
    /// ([`touch`](Self::touch)); a sync that passes without consequences for other behaviours
    /// only queues the behaviour's next one ([`queue_next`](Self::queue_next)). An entry whose
    /// behaviour has moved on is dropped when it comes up. So an event costs a heap operation,
    /// not a scan of every live behaviour (a chain of 10 000 behaviours passes 70 000 syncs).
    fn next_sync(&self) -> Option<(f64, usize, usize)> {
        if self.due_stale.get() {
            self.rebuild_due();
        }
        let mut due = self.due.borrow_mut();
        while let Some(&Reverse(d)) = due.peek() {
            if let Some((t, bi)) = self.still_due(d) {
                return Some((t, bi, d.xi));
            }
            due.pop();
        }
        None
    }

    /// The plan changed (blocks, phases or sync times): the heap of next syncs is rebuilt.
    fn touch(&self) {
        self.due_stale.set(true);
    }

    /// The entry of behaviour `xi` of block `bi`'s next sync, if it has one to report.
    fn due_of(&self, bi: usize, xi: usize) -> Option<Due> {
        let b = &self.blocks[bi];
        let x = &b.behaviours[xi];
        let live = b.started() && matches!(x.phase, Phase::Added | Phase::Running);
        let local = x.syncs.get(x.next).filter(|_| live)?.1;
        Some(Due {
            ns: due_ns(b.start + local),
            seq: b.seq,
            index: x.index,
            xi,
            k: x.next,
        })
    }

    /// Queues the next sync of behaviour `xi` of block `bi` (after one of its syncs passed).
    fn queue_next(&self, bi: usize, xi: usize) {
        if let Some(d) = self.due_of(bi, xi) {
            self.due.borrow_mut().push(Reverse(d));
        }
    }

    fn rebuild_due(&self) {
        let mut all = Vec::new();
        for (bi, b) in self.blocks.iter().enumerate() {
            if b.started() {
                all.extend((0..b.behaviours.len()).filter_map(|xi| self.due_of(bi, xi)));
            }
        }
        *self.due.borrow_mut() = BinaryHeap::from(all.into_iter().map(Reverse).collect::<Vec<_>>());
        self.due_stale.set(false);
    }

    /// Whether an entry still stands for its behaviour's next sync: its global time and its
    /// block's index then.
    fn still_due(&self, d: Due) -> Option<(f64, usize)> {
        let bi = self.seqs.binary_search(&d.seq).ok()?;
        let now = self.due_of(bi, d.xi)?;
        (now == d).then(|| {
            let b = &self.blocks[bi];
            (b.start + b.behaviours[d.xi].syncs[d.k].1, bi)
        })
    }

    fn sync_feedback(
        &mut self,
        block: &bml::Id,
        behaviour: &bml::Id,
        sync: &bml::Id,
        local: f64,
        t: f64,
        skipped: bool,
    ) {
        let character_id = self.character.clone();
        self.emit(Feedback::SyncPointProgress(SyncPointProgress {
            block: block.clone(),
            behaviour: behaviour.clone(),
            sync: sync.clone(),
            time: local,
            global_time: t,
            character_id,
            posix_time: None,
            skipped,
        }));
    }

    /// Moves time to `to`: every sync point up to then passes in time order with its feedback and
    /// consequences (control actions, block ends, blocks that were waiting), then parameter
    /// changes apply, every engine plays into `frame` and moves the body, whose pose joins the
    /// frame.
    pub fn advance(&mut self, to: f64, world: &std::sync::Arc<World>, frame: &mut Frame) {
        self.set_world(world);
        let to = to.max(self.now);
        // changes made from outside since the last frame (e.g. a new tempo)
        self.update_anticipators(self.now);
        let mut last_change = f64::NEG_INFINITY;
        loop {
            let sync = self.next_sync().filter(|s| s.0 <= to);
            // an anticipator that keeps announcing the same change is not asked again
            let change = self
                .next_prediction_change()
                .filter(|&c| c <= to && c > last_change);
            if let Some(c) = change {
                last_change = c;
            }
            match (sync, change) {
                // a prediction changing at the same moment as a sync applies first
                (Some((ts, _, _)), Some(tc)) if tc <= ts => {
                    self.now = self.now.max(tc);
                    self.update_anticipators(tc);
                }
                (None, Some(tc)) => {
                    self.now = self.now.max(tc);
                    self.update_anticipators(tc);
                }
                (Some((t, bi, xi)), _) => {
                    self.now = t;
                    let seq = self.blocks[bi].seq;
                    if self.pass_sync(bi, xi, t) {
                        self.touch();
                    } else if let Ok(bi) = self.seqs.binary_search(&seq) {
                        self.queue_next(bi, xi);
                    }
                }
                (None, None) => break,
            }
        }
        self.now = to;
        self.update_anticipators(to);
        self.apply_changes(to);
        self.predict_poses(to);
        let mut pose = Pose::rest(&self.skeleton);
        for e in self.registry.engines_mut() {
            e.play(to, frame);
            e.animate(to, &self.skeleton, &self.world, &mut pose);
        }
        frame.poses.push(CharacterPose {
            character: self.character.clone(),
            pose,
        });
        for (engine, key) in std::mem::take(&mut self.retiring) {
            self.registry.engine_mut(engine).remove(&key);
        }
    }

    /// Gives every engine that asks for them the poses the predictable units will have at the
    /// times it names.
    fn predict_poses(&mut self, now: f64) {
        for i in 0..self.registry.len() {
            let times = self.registry.engine(i).prediction_times(now);
            if times.is_empty() {
                continue;
            }
            let poses = times
                .into_iter()
                .map(|t| {
                    let mut pose = Pose::rest(&self.skeleton);
                    for e in self.registry.engines() {
                        e.predict(t, &self.skeleton, &self.world, &mut pose);
                    }
                    (t, pose)
                })
                .collect();
            self.registry.engine_mut(i).predicted(poses);
        }
    }

    /// Reports the next sync of behaviour `xi` of block `bi`, passed at `t`, and what follows
    /// from it. Returns whether the plan changed beyond that behaviour (an action, a block that
    /// ended or started).
    fn pass_sync(&mut self, bi: usize, xi: usize, t: f64) -> bool {
        let (block_id, beh_id, sync, local, engine, last, skipped) = {
            let b = &mut self.blocks[bi];
            let x = &mut b.behaviours[xi];
            let (name, local) = x.syncs[x.next].clone();
            let skipped = x.next < x.skip_before;
            x.next += 1;
            x.phase = Phase::Running;
            (
                b.id.clone(),
                x.id.clone(),
                name,
                local,
                x.engine,
                x.next == x.syncs.len(),
                skipped,
            )
        };
        self.sync_feedback(&block_id, &beh_id, &sync, local, t, skipped);
        let key = UnitKey::new(block_id.clone(), beh_id.clone());
        let mut actions = Vec::new();
        self.registry
            .engine_mut(engine)
            .sync_passed(&key, &sync, t, &mut actions);
        if last {
            self.blocks[bi].behaviours[xi].phase = Phase::Ended;
            self.retiring.push((engine, key.clone()));
        }
        let mut changed = !actions.is_empty();
        if self.blocks[bi].update_subsiding() {
            self.start_ready(t);
            changed = true;
        }
        for a in actions {
            self.act(a, t);
        }
        if let Some(bi) = self.pos(&block_id) {
            changed |= self.finish_if_done(bi, t);
        }
        changed
    }

    fn act(&mut self, action: Action, t: f64) {
        match action {
            Action::Interrupt {
                by,
                target,
                include,
                exclude,
            } => self.interrupt_behaviours(&by, &target, &include, &exclude, t),
            Action::Activate { by, target } => self.activate(&target, t, &by.to_string()),
            Action::ChangeParameter(mut c) => {
                let engine = self
                    .pos(&c.target.block)
                    .and_then(|i| self.blocks[i].behaviour(&c.target.behaviour))
                    .filter(|x| matches!(x.phase, Phase::Added | Phase::Running))
                    .map(|x| x.engine);
                let Some(engine) = engine else {
                    self.warn(
                        c.by.to_string(),
                        KnownWarning::NoSuchTarget,
                        format!(
                            "cannot change '{}' of {}: it is not in the running plan",
                            c.param, c.target
                        ),
                    );
                    return;
                };
                if c.initial.is_none() {
                    // start from the target's current value
                    c.initial = self.registry.engine(engine).parameter(&c.target, &c.param);
                    if c.initial.is_none() {
                        self.warn(
                            c.by.to_string(),
                            KnownWarning::ExecutionFailure,
                            format!("{} has no parameter '{}'", c.target, c.param),
                        );
                        return;
                    }
                }
                self.changes.push(c);
                self.apply_changes(t);
            }
        }
    }

    /// Sets every running parameter change's value at `t`; changes past their end are done (the
    /// value stays).
    fn apply_changes(&mut self, t: f64) {
        if !self.changes.is_empty() {
            self.touch(); // a change may retime its target
        }
        let changes = std::mem::take(&mut self.changes);
        for c in changes {
            let found = self.pos(&c.target.block).and_then(|bi| {
                let xi = self.blocks[bi]
                    .behaviours
                    .iter()
                    .position(|x| x.id == c.target.behaviour)?;
                Some((bi, xi))
            });
            let Some((bi, xi)) = found else { continue };
            let x = &self.blocks[bi].behaviours[xi];
            if !matches!(x.phase, Phase::Added | Phase::Running) {
                continue; // the target ended: nothing to change any more
            }
            let value = c.value_at(c.initial.unwrap_or(c.target_value), t.max(c.start));
            let engine = x.engine;
            match self
                .registry
                .engine_mut(engine)
                .set_parameter(&c.target, &c.param, value, t)
            {
                Ok(retimed) => {
                    if let Some(times) = retimed {
                        let start = self.blocks[bi].start;
                        self.blocks[bi].behaviours[xi].retime(&times, start, t);
                    }
                    if t < c.end {
                        self.changes.push(c);
                    }
                }
                Err(e) => self.warn(c.by.to_string(), KnownWarning::ExecutionFailure, e.0),
            }
        }
    }
}

#[cfg(test)]
mod tests;
