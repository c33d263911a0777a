//! Submitting a block: an id in use is refused; interrupts and REPLACE take blocks out of the plan;
//! composition and the BMLA attributes decide what the block waits for; it is scheduled against
//! the other blocks' times (`OtherBlocks`), and then waits, lurks or starts.

use super::*;
use crate::planning::schedule::BlockSchedule;

/// Times of other blocks' syncs relative to the start of a block being scheduled.
pub(super) struct OtherBlocks<'a> {
    pub(super) blocks: &'a Blocks,
    pub(super) anticipators: &'a [Box<dyn Anticipator>],
    pub(super) start: f64,
}

impl ExternalTimes for OtherBlocks<'_> {
    fn time(&self, point: &SyncPoint) -> Option<f64> {
        match point {
            SyncPoint::External {
                block,
                behaviour,
                sync,
            } => {
                let b = self.blocks.named(block)?;
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

    fn why_unknown(&self, point: &SyncPoint) -> String {
        let SyncPoint::External {
            block,
            behaviour,
            sync,
        } = point
        else {
            return format!("the time of {point} is not known");
        };
        let Some(b) = self.blocks.named(block) else {
            return format!("the time of {point} is not known: block '{block}' is not in the plan");
        };
        let Some(beh) = b.behaviour(behaviour) else {
            return format!(
                "the time of {point} is not known: block '{block}' has no behaviour '{behaviour}' (now)"
            );
        };
        let names: Vec<&str> = beh.syncs.iter().map(|(n, _)| n.as_str()).collect();
        let hint = if bml::stroke_iteration_of(sync).is_some() {
            bml::STROKE_ITERATION_HINT
        } else {
            ""
        };
        format!(
            "the time of {point} is not known: '{block}:{behaviour}' has no sync point '{sync}'; its sync points are {}{hint}",
            names.join(", ")
        )
    }
}

impl BlockManager {
    /// Plans `block` at the current time: interrupts, composition, scheduling, and its start if
    /// nothing holds it back. Every problem becomes a warning; the block is rejected only if its
    /// id is in use or its required behaviours cannot be scheduled.
    pub fn submit(&mut self, block: bml::Block, warnings: &[Diagnostic]) {
        self.touch();
        let now = self.now;
        if let Some(i) = self.blocks.find(&block.id) {
            let status = self.blocks[i].status;
            let text = format!(
                "block id '{}' is still in use (status {status}); the new block is ignored",
                block.id
            );
            self.warn(
                block.id.to_string(),
                KnownWarning::ImpossibleToSchedule,
                text,
            );
            return;
        }
        self.parse_warnings(&block, warnings);
        // composition: what leaves the plan, what the block waits for, when it may start
        self.make_room_for(&block, now);
        let (waits_for, chunk_after) = self.waits_for(&block);
        let start = self.start_of(&block, now, &waits_for, &chunk_after);
        self.seq += 1;
        let mut live = LiveBlock::new(block, self.seq, start, waits_for, chunk_after);
        let fb = self.prediction(&live, false);
        self.emit(fb);
        // schedule
        let Some(schedule) = self.schedule(&live) else {
            return;
        };
        // pegs, for a block that hangs on anticipators
        live.pegs = self.pegs_for(&live, &schedule);
        live.set_schedule(schedule, &self.registry);
        for (beh, reason) in live.resolve_exclusive_ties(&self.registry) {
            let id = format!("{}:{beh}", live.id);
            self.warn(id, KnownWarning::ImpossibleToSchedule, reason);
        }
        self.go_before(&live);
        // start, or wait
        self.admit(live, now);
    }

    /// Takes out of the plan the blocks `block` interrupts (its `bmla:interrupt` list first, then
    /// every block for REPLACE); what waited for them starts once all of them are gone.
    fn make_room_for(&mut self, block: &bml::Block, now: f64) {
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
    }

    /// The blocks `block` waits for (APPEND: every block but pre-planned ones not activated;
    /// APPEND-AFTER and `appendAfter`: the ones named) and those it waits to subside
    /// (`chunkAfter`).
    fn waits_for(&mut self, block: &bml::Block) -> (Vec<bml::Id>, Vec<bml::Id>) {
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
        (waits_for, chunk_after)
    }

    /// When `block` is predicted to start: after what it waits for, or up to [`LATE_START`]
    /// earlier than now when it is tied to another block's sync point that passed a moment ago.
    fn start_of(
        &self,
        block: &bml::Block,
        now: f64,
        waits_for: &[bml::Id],
        chunk_after: &[bml::Id],
    ) -> f64 {
        let mut start = self.predicted_start(now, waits_for, chunk_after);
        for p in referenced_points(block) {
            if let SyncPoint::External {
                block: b,
                behaviour,
                sync,
            } = p
            {
                let t = self.blocks.find(b).and_then(|i| {
                    let other = &self.blocks[i];
                    Some(other.start + other.behaviour(behaviour)?.time(sync)?)
                });
                if let Some(t) = t.filter(|t| *t < start && start - *t <= LATE_START) {
                    start = t;
                }
            }
        }
        start
    }

    /// Schedules `live` against the other blocks' times: the schedule with its dropped
    /// behaviours reported, or `None` (with a warning) when the block cannot be scheduled.
    fn schedule(&mut self, live: &LiveBlock) -> Option<BlockSchedule> {
        let external = OtherBlocks {
            blocks: &self.blocks,
            anticipators: &self.anticipators,
            start: live.start,
        };
        let schedule = self
            .strategy
            .schedule(&live.source, &self.registry, &external);
        let mut schedule = match schedule {
            Ok(s) => s,
            Err(e) => {
                let id = live.id.clone();
                self.warn(id, KnownWarning::CannotSatisfyConstraints, e.to_string());
                return None;
            }
        };
        // (asked only of a behaviour whose end is infinite)
        schedule.drop_unreachable(|id| {
            let b = live.source.behaviours.iter().find(|b| b.id == *id);
            b.and_then(|b| TimingModels::model(&self.registry, b))
                .is_some_and(|m| m.persistent)
        });
        for d in &schedule.dropped {
            let id = format!("{}:{}", live.id, d.behaviour);
            self.warn(id, d.warning, d.reason.clone());
        }
        for s in crate::planning::schedule::performable::squeezed(&live.source, &schedule) {
            let id = format!("{}:{}", live.id, s.behaviour);
            self.warn(id, KnownWarning::InvalidTiming, s.sentence());
        }
        Some(schedule)
    }

    /// The peg board of a block that refers to anticipators (`None` for the others): its
    /// schedule on pegs, the anticipators' pegs at their current predictions.
    fn pegs_for(&self, live: &LiveBlock, schedule: &BlockSchedule) -> Option<Box<BlockPegs>> {
        let refs = anticipator_refs(&live.source);
        // behaviours whose engine revises their times while they run (a walk)
        let own: Vec<&str> = (live.source.behaviours.iter())
            .filter(|b| {
                self.registry
                    .engine_for(b)
                    .is_some_and(|e| self.registry.engine(e).self_timed(b))
            })
            .map(|b| b.id.as_str())
            .collect();
        if refs.is_empty() && own.is_empty() {
            return None;
        }
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
        let start = live.start;
        let plan = to_pegs::plan_block_with(
            &mut board,
            &mut anticipators,
            &live.source,
            schedule,
            start,
            &own,
        );
        Some(Box::new(BlockPegs {
            board,
            anticipators,
            plan,
        }))
    }

    /// `chunkBefore` / `prependBefore`: the blocks `live` names wait for it (to subside, or to
    /// end), unless they have started, or `live` itself waits for them (a cycle: neither would
    /// ever start).
    fn go_before(&mut self, live: &LiveBlock) {
        let id = &live.id;
        let ext = &live.source.ext;
        for (targets, chunk) in [(&ext.chunk_before, true), (&ext.prepend_before, false)] {
            for t in targets {
                if dependencies::waits_on(&self.blocks, live, t) {
                    let text = format!(
                        "'{id}' waits for block '{t}', so '{t}' cannot wait for it; the two would wait for each other for ever"
                    );
                    self.warn(id.to_string(), KnownWarning::ImpossibleToSchedule, text);
                    continue;
                }
                match self.blocks.find(t).map(|i| &mut self.blocks[i]) {
                    Some(b) if !b.started() => {
                        let list = if chunk {
                            &mut b.chunk_after
                        } else {
                            &mut b.waits_for
                        };
                        list.push(id.clone());
                    }
                    Some(_) => self.warn(
                        id.to_string(),
                        KnownWarning::ImpossibleToSchedule,
                        format!("block '{t}' has already started; '{id}' cannot go before it"),
                    ),
                    None => self.warn(
                        id.to_string(),
                        KnownWarning::NoSuchTarget,
                        format!("no block '{t}' to go before"),
                    ),
                }
            }
        }
    }

    /// A scheduled block joins the plan PENDING: a pre-planned one waits for an activation,
    /// another starts now if nothing holds it back, or lurks.
    fn admit(&mut self, mut live: LiveBlock, now: f64) {
        let preplan = live.source.ext.preplan;
        live.status = BlockStatus::Pending;
        live.preplan = preplan;
        let i = self.blocks.insert(live);
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
    pub(super) fn existing(&mut self, ids: &[String], by: &str) -> Vec<bml::Id> {
        let mut v = Vec::new();
        for id in ids {
            if self.blocks.find(id).is_some() {
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

    pub(super) fn predicted_start(
        &self,
        now: f64,
        waits_for: &[bml::Id],
        chunk_after: &[bml::Id],
    ) -> f64 {
        let mut start = now;
        for (ids, subsiding) in [(waits_for, false), (chunk_after, true)] {
            for b in ids.iter().filter_map(|id| self.blocks.named(id)) {
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
}
