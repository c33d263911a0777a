//! A block's life after submission: when it may start, starting it (its units to the engines),
//! activation of pre-planned blocks, and its end (DONE, INTERRUPTED or REVOKED), after which the
//! blocks that waited for it start.

use super::*;

impl BlockManager {
    /// A PENDING block that may run: it starts now if nothing holds it back, else it is LURKING
    /// (with its prediction) until [`start_ready`](Self::start_ready) starts it. A block that
    /// starts can end at once (its handle then finds nothing).
    pub(super) fn release(&mut self, i: BlockKey, now: f64) {
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
    pub(super) fn ready(&self, i: BlockKey) -> bool {
        let b = &self.blocks[i];
        let live = |id: &bml::Id| self.blocks.named(id);
        b.waits_for.iter().all(|id| live(id).is_none())
            && b.chunk_after.iter().all(|id| {
                live(id)
                    .is_none_or(|x| matches!(x.status, BlockStatus::Subsiding | BlockStatus::Done))
            })
    }

    /// Starts every LURKING block that is ready, at `t`, until none is left (a start can end a
    /// block at once, which can make others ready).
    pub(super) fn start_ready(&mut self, t: f64) {
        while self.lurking > 0 {
            let next = (self.blocks.keys())
                .find(|&i| self.blocks[i].status == BlockStatus::Lurking && self.ready(i));
            match next {
                Some(i) => self.start_block(i, t),
                None => return,
            }
        }
    }

    /// the block peg moves to `t`, start feedback, onStart activations, units to engines.
    pub(super) fn start_block(&mut self, i: BlockKey, t: f64) {
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
                        let kind = self.registry.engine(x.engine).refusal(&e);
                        failed.push((x.id.clone(), e.to_string(), kind));
                    }
                }
            }
        }
        for (beh, reason, kind) in failed {
            self.warn(format!("{id}:{beh}"), kind, reason);
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
        // activations may start (and end) other blocks, this one among them
        let on_start = self.blocks[i].source.ext.on_start.clone();
        for target in on_start {
            self.activate(&target, t, &id);
        }
        if self.blocks.get(i).is_some() {
            self.finish_if_done(i, t);
        }
    }

    /// A chunked block starting at `t` takes over from the blocks it is chunked after: their
    /// behaviours that are retracting (past `relax`) on a body resource this block uses (a hand,
    /// the voice) skip the rest of the retraction and end now.
    pub(super) fn coarticulate(&mut self, i: BlockKey, t: f64) {
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
            used.extend(self.registry.resources(x.engine, b));
        }
        if used.is_empty() {
            return;
        }
        for target in self.blocks[i].chunk_after.clone() {
            let Some(j) = self.blocks.find(&target) else {
                continue;
            };
            for xi in 0..self.blocks[j].behaviours.len() {
                let x = &self.blocks[j].behaviours[xi];
                let relax = x.syncs.iter().position(|(n, _)| n == "relax");
                let retracting = x.phase == Phase::Running && relax.is_some_and(|r| x.next > r);
                let b = &self.blocks[j].source.behaviours[x.index];
                let shares = self
                    .registry
                    .resources(x.engine, b)
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
    pub(super) fn activate(&mut self, target: &str, t: f64, by: &str) {
        match self.blocks.find(target) {
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
    pub(super) fn finish_if_done(&mut self, i: BlockKey, t: f64) -> bool {
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
    pub(super) fn end_block(&mut self, i: BlockKey, t: f64, status: BlockStatus) {
        let Some(b) = self.blocks.remove(i) else {
            return; // it has left the plan already
        };
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

    pub(super) fn remember(&mut self, id: bml::Id) {
        if self.finished_set.insert(id.clone()) {
            self.finished.push_back(id);
            if self.finished.len() > FINISHED_HISTORY {
                if let Some(old) = self.finished.pop_front() {
                    self.finished_set.remove(&old);
                }
            }
        }
    }

    // interruption
}
