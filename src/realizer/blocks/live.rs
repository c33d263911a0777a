//! One block in the running plan and its behaviours: block-local sync times from the schedule,
//! how far each behaviour has got, and the derived block predictions (end, subsiding time).

use smallvec::SmallVec;

use crate::engines::interface::Registry;
use crate::language::bml::{self, ConstraintItem, SyncPoint, SyncRef};
use crate::language::feedback::BlockStatus;
use crate::planning::plan::to_pegs::BlockPegs;
use crate::planning::schedule::{BlockSchedule, SyncName};

/// Where a behaviour is in its life.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Phase {
    /// Scheduled; its block has not started.
    Planned,
    /// Handed to its engine; no sync passed yet.
    Added,
    /// At least one sync passed.
    Running,
    /// Its end passed.
    Ended,
    /// Left the plan before it started (dropped, interrupted, refused by its engine).
    Removed,
}

/// A scheduled behaviour at run time.
#[derive(Debug, Clone)]
pub(crate) struct LiveBehaviour {
    pub(crate) id: bml::Id,
    /// Index in the block's `behaviours` (document order).
    pub(crate) index: usize,
    /// Registry index of its engine.
    pub(crate) engine: crate::engines::interface::EngineId,
    /// (sync, block-local time) in sync order.
    pub(crate) syncs: Vec<(SyncName, f64)>,
    /// The next sync to pass.
    pub(crate) next: usize,
    pub(crate) phase: Phase,
    /// Internal timing fixed (speech): once started, it no longer follows its pegs.
    pub(crate) rigid: bool,
    /// Syncs before this index that are still ahead were cut by an interrupt: they are reported
    /// as skipped when their (moved) time comes.
    pub(crate) skip_before: usize,
}

impl LiveBehaviour {
    /// (sync, global time) for a block that starts at `start`.
    pub(crate) fn global(&self, start: f64) -> Vec<(SyncName, f64)> {
        self.syncs
            .iter()
            .map(|(n, l)| (n.clone(), start + l))
            .collect()
    }

    /// Block-local time of `sync`.
    pub(crate) fn time(&self, sync: &str) -> Option<f64> {
        self.syncs.iter().find(|(n, _)| n == sync).map(|s| s.1)
    }

    /// New global `times` from the engine (interrupt or a timing parameter): syncs not yet passed
    /// take them, never earlier than `now` nor than the sync before.
    pub(crate) fn retime(&mut self, times: &[f64], start: f64, now: f64) {
        let mut floor = now - start;
        for (k, s) in self.syncs.iter_mut().enumerate() {
            if k < self.next {
                continue;
            }
            if let Some(&t) = times.get(k) {
                let local = (t - start).max(floor);
                s.1 = local;
                floor = local;
            }
        }
    }

    /// After an interrupt moved the syncs still ahead: those before the retraction (`relax`, or
    /// `end` for a behaviour without one) will never be reached as planned.
    pub(crate) fn cut_before_retraction(&mut self) {
        let relax = self.syncs.iter().position(|(n, _)| n == "relax");
        self.skip_before = match relax {
            Some(r) if r >= self.next => r,
            Some(_) => self.next,
            None => self.syncs.len().saturating_sub(1),
        };
    }

    fn passed_relax(&self) -> bool {
        match self.syncs.iter().position(|(n, _)| n == "relax") {
            Some(r) => self.next > r,
            None => self.phase == Phase::Ended,
        }
    }
}

/// Whether every behaviour satisfies `done`, a property that once true stays true (a phase that
/// ended, a sync that passed): the behaviours before `*checked` are known to, and the check goes
/// on from there, so that asking once per sync of a block stays linear in the block.
fn all_from(
    behaviours: &[LiveBehaviour],
    checked: &std::cell::Cell<usize>,
    done: impl Fn(&LiveBehaviour) -> bool,
) -> bool {
    let from = checked.get().min(behaviours.len());
    let first_open = behaviours[from..].iter().position(|b| !done(b));
    checked.set(first_open.map_or(behaviours.len(), |i| from + i));
    first_open.is_none()
}

/// A block in the plan.
#[derive(Debug, Clone)]
pub(crate) struct LiveBlock {
    pub(crate) id: bml::Id,
    /// Arrival number: ties between blocks go to the earlier one.
    pub(crate) seq: u64,
    pub(crate) status: BlockStatus,
    /// Global start: predicted until the block starts, then fixed.
    pub(crate) start: f64,
    /// The block as written.
    pub(crate) source: bml::Block,
    pub(crate) behaviours: Vec<LiveBehaviour>,
    /// Blocks that must end before this one starts.
    pub(crate) waits_for: Vec<bml::Id>,
    /// Blocks that must be subsiding before this one starts.
    pub(crate) chunk_after: Vec<bml::Id>,
    /// Waiting for an activation.
    pub(crate) preplan: bool,
    /// The block's own peg board, for blocks tied to anticipators: moving an anticipator's peg
    /// retimes what hangs on it. Boxed: few blocks have one, and every block is kept.
    pub(crate) pegs: Option<Box<BlockPegs>>,
    /// An interrupt behaviour cut some of its behaviours: it ends INTERRUPTED, not DONE.
    pub(crate) cut: bool,
    /// The behaviours before this index have all ended (see [`all_from`]).
    ended_before: std::cell::Cell<usize>,
    /// The behaviours before this index have all passed `relax`.
    relaxed_before: std::cell::Cell<usize>,
}

/// Every sync point outside the block (of another block, or of an anticipator) that a sync
/// reference of `block` names (attributes and `<constraint>`s), each once, sorted.
pub(crate) fn referenced_points(block: &bml::Block) -> SmallVec<[&SyncPoint; 8]> {
    let mut out: SmallVec<[&SyncPoint; 8]> = SmallVec::new();
    let refs = block
        .behaviours
        .iter()
        .flat_map(|b| b.syncs.iter().map(|s| &s.value))
        .chain(block.constraints.iter().flat_map(|c| {
            c.items.iter().flat_map(|item| {
                let (reference, syncs) = match item {
                    ConstraintItem::Synchronize {
                        reference, syncs, ..
                    } => (reference.as_ref(), syncs),
                    ConstraintItem::Before {
                        reference, syncs, ..
                    }
                    | ConstraintItem::After {
                        reference, syncs, ..
                    } => (Some(reference), syncs),
                };
                reference
                    .into_iter()
                    .chain(syncs.iter().map(|s| &s.reference))
            })
        }));
    // only references that leave the block matter here; sorted, once each
    out.extend(refs.filter_map(|r| match r {
        SyncRef::Point { point, .. } if !matches!(point, SyncPoint::Local { .. }) => Some(point),
        _ => None,
    }));
    out.sort_unstable();
    out.dedup();
    out
}

/// The anticipator syncs (anticipator, sync) that sync references of `block` name.
pub(crate) fn anticipator_refs(block: &bml::Block) -> Vec<(&str, &str)> {
    referenced_points(block)
        .into_iter()
        .filter_map(|p| match p {
            SyncPoint::Anticipator { anticipator, sync } => {
                Some((anticipator.as_str(), sync.as_str()))
            }
            _ => None,
        })
        .collect()
}

impl LiveBlock {
    pub(crate) fn new(
        source: bml::Block,
        seq: u64,
        start: f64,
        waits_for: Vec<bml::Id>,
        chunk_after: Vec<bml::Id>,
    ) -> Self {
        LiveBlock {
            id: source.id.clone(),
            seq,
            status: BlockStatus::InPrep,
            start,
            source,
            behaviours: Vec::new(),
            waits_for,
            chunk_after,
            preplan: false,
            pegs: None,
            cut: false,
            ended_before: std::cell::Cell::new(0),
            relaxed_before: std::cell::Cell::new(0),
        }
    }

    /// Takes the scheduled behaviours (in document order) and their engines.
    pub(crate) fn set_schedule(&mut self, schedule: BlockSchedule, registry: &Registry) {
        self.behaviours.reserve_exact(schedule.behaviours.len());
        // both lists are in document order: each search goes on from where the last one ended
        let mut from = 0;
        for s in schedule.behaviours {
            let source = &self.source.behaviours;
            let found = source[from..].iter().position(|b| b.id == s.id);
            let Some(index) = found.map(|i| from + i) else {
                continue;
            };
            from = index + 1;
            let Some(engine) = registry.engine_for(&self.source.behaviours[index]) else {
                continue;
            };
            self.behaviours.push(LiveBehaviour {
                id: s.id,
                index,
                engine,
                syncs: s.syncs,
                next: 0,
                phase: Phase::Planned,
                rigid: s.rigid,
                skip_before: 0,
            });
        }
    }

    /// behaviours of one exclusive group (gaze, posture) with the same start and end cannot
    /// both run; all but the first in document order leave the plan. Returns (id, reason) of each.
    pub(crate) fn resolve_exclusive_ties(&mut self, registry: &Registry) -> Vec<(bml::Id, String)> {
        let mut dropped = Vec::new();
        for i in 0..self.behaviours.len() {
            let a = &self.behaviours[i];
            let b = &self.source.behaviours[a.index];
            let Some(group) = registry.exclusive_group(a.engine, b) else {
                continue;
            };
            let span =
                |x: &LiveBehaviour| (x.syncs.first().map(|s| s.1), x.syncs.last().map(|s| s.1));
            let tie = self.behaviours[..i].iter().find(|p| {
                p.phase != Phase::Removed
                    && registry.exclusive_group(p.engine, &self.source.behaviours[p.index])
                        == Some(group)
                    && span(p) == span(a)
            });
            if let Some(p) = tie {
                dropped.push((
                    a.id.clone(),
                    format!(
                        "'{}' and '{}' are both {group} behaviours with the same start and end; only '{}' runs",
                        p.id, a.id, p.id
                    ),
                ));
                self.behaviours[i].phase = Phase::Removed;
            }
        }
        dropped
    }

    pub(crate) fn behaviour(&self, id: &str) -> Option<&LiveBehaviour> {
        self.behaviours.iter().find(|b| b.id == id)
    }

    /// Whether the block has started (IN_EXEC or SUBSIDING).
    pub(crate) fn started(&self) -> bool {
        matches!(self.status, BlockStatus::InExec | BlockStatus::Subsiding)
    }

    fn live(&self) -> impl Iterator<Item = &LiveBehaviour> {
        self.behaviours.iter().filter(|b| b.phase != Phase::Removed)
    }

    /// Predicted global end: the latest end of its behaviours (infinite with a persistent one).
    pub(crate) fn predicted_end(&self) -> Option<f64> {
        let end = self
            .live()
            .filter_map(|b| b.syncs.last().map(|s| s.1))
            .fold(0.0_f64, f64::max);
        Some(self.start + end)
    }

    /// Predicted global time at which every behaviour has passed `relax` (or `end`).
    pub(crate) fn predicted_subsiding(&self) -> Option<f64> {
        let t = self
            .live()
            .filter_map(|b| b.time("relax").or_else(|| b.syncs.last().map(|s| s.1)))
            .fold(0.0_f64, f64::max);
        Some(self.start + t)
    }

    /// Every behaviour still in the plan has ended.
    pub(crate) fn all_ended(&self) -> bool {
        let ended = |b: &LiveBehaviour| matches!(b.phase, Phase::Ended | Phase::Removed);
        all_from(&self.behaviours, &self.ended_before, ended)
    }

    /// IN_EXEC → SUBSIDING once every behaviour passed `relax` (or `end`); true if it changed.
    pub(crate) fn update_subsiding(&mut self) -> bool {
        let passed = |b: &LiveBehaviour| b.phase == Phase::Removed || b.passed_relax();
        if self.status == BlockStatus::InExec
            && all_from(&self.behaviours, &self.relaxed_before, passed)
        {
            self.status = BlockStatus::Subsiding;
            return true;
        }
        false
    }
}
