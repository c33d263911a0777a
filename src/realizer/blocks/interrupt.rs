//! Interrupts: of whole blocks (the block attribute, REPLACE, `bmla:interrupt` naming a block)
//! and of single behaviours through their engines' interrupt timing.

use super::*;

impl BlockManager {
    /// The live block `target` of an interrupt by `by`. A block that finished a moment ago is a
    /// quiet no-op; one that never existed gets a NO_SUCH_TARGET warning.
    pub(super) fn interrupt_target(&mut self, target: &str, by: &str) -> Option<BlockKey> {
        let i = self.blocks.find(target);
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
    pub(super) fn interrupt_block_by_id(&mut self, target: &str, t: f64, by: &str) {
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
    pub(super) fn interrupt_unit(&mut self, bi: BlockKey, xi: usize, t: f64) {
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
    pub(super) fn interrupt_behaviours(
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

    // the event loop
}
