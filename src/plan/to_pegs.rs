//! From a schedule to pegs (thesis §7.3.3) and back to validity after run-time
//! changes.
//!
//! - Sync points joined by `at` constraints share one time peg, and so do the named syncs of a rigid
//!   behaviour; a fixed nonzero offset becomes an offset peg.
//! - A sync `at`-linked to an anticipator hangs on the anticipator's peg on the global block peg.
//! - A sync that no constraint names and that lies between two named syncs of its behaviour is not
//!   a peg. It is placed proportionally between them, the way an engine stretches a motion between
//!   its constrained keys.
//! - Unnamed syncs before the first or after the last named sync are offset pegs on it. A
//!   behaviour that no constraint names gets a time peg for its start.
//! - `before`/`after` constraints become order links, which push or drag when a peg moves.
//!
//! Moving an anticipator peg then retimes everything linked to it without rescheduling. `invalid`
//! lists the behaviours whose timing broke (sync order, block start).

use std::collections::HashMap;

use crate::bml::{extract, Anchor, Block, Id, Relation, SyncPoint};
use crate::plan::pegs::{BlockPegId, PegBoard, PegId, SyncAddr};
use crate::schedule::offsets::Offsets;
use crate::schedule::{BlockSchedule, ExternalTimes};
use crate::timing::SyncName;

/// Where a planned sync's time comes from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Placement {
    /// Its own peg (shared, offset or time peg).
    Peg(PegId),
    /// A fixed fraction of the way from one peg to another.
    Between {
        /// The earlier named sync's peg.
        from: PegId,
        /// The later named sync's peg.
        to: PegId,
        /// 0 at `from`, 1 at `to`.
        fraction: f64,
    },
}

/// A scheduled block on the board: its block peg and where every sync of every behaviour is.
#[derive(Debug, Clone, PartialEq)]
pub struct PlannedBlock {
    /// The block's peg.
    pub block: BlockPegId,
    /// Behaviours in schedule order: (id, [(sync, placement)]).
    pub behaviours: Vec<(Id, Vec<(SyncName, Placement)>)>,
}

impl PlannedBlock {
    /// Global times of a behaviour's syncs, in sync order.
    pub fn times(&self, board: &PegBoard, behaviour: &str) -> Option<Vec<f64>> {
        let (_, syncs) = self.behaviours.iter().find(|(id, _)| id == behaviour)?;
        Some(syncs.iter().map(|(_, p)| place(board, *p)).collect())
    }

    /// Global time of `behaviour:sync`.
    pub fn time(&self, board: &PegBoard, behaviour: &str, sync: &str) -> Option<f64> {
        let (_, syncs) = self.behaviours.iter().find(|(id, _)| id == behaviour)?;
        syncs
            .iter()
            .find(|(s, _)| s == sync)
            .map(|(_, p)| place(board, *p))
    }
}

fn place(board: &PegBoard, p: Placement) -> f64 {
    match p {
        Placement::Peg(p) => board.global(p),
        Placement::Between { from, to, fraction } => {
            let (a, b) = (board.global(from), board.global(to));
            a + fraction * (b - a)
        }
    }
}

/// Anticipator pegs on the global block peg, by (anticipator, sync).
#[derive(Debug, Clone, Default)]
pub struct Anticipators {
    pegs: HashMap<(String, String), PegId>,
}

impl Anticipators {
    /// The peg of `anticipator:sync`, created at global time `t` if it does not exist yet.
    pub fn peg(&mut self, board: &mut PegBoard, anticipator: &str, sync: &str, t: f64) -> PegId {
        *self
            .pegs
            .entry((anticipator.to_string(), sync.to_string()))
            .or_insert_with(|| board.time_peg(BlockPegId::GLOBAL, t))
    }

    /// Every anticipator peg: (anticipator, sync, peg).
    pub fn iter(&self) -> impl Iterator<Item = (&str, &str, PegId)> {
        self.pegs
            .iter()
            .map(|((a, s), p)| (a.as_str(), s.as_str(), *p))
    }

    /// The peg of `anticipator:sync`, if it exists.
    pub fn get(&self, anticipator: &str, sync: &str) -> Option<PegId> {
        self.pegs
            .get(&(anticipator.to_string(), sync.to_string()))
            .copied()
    }
}

/// Block-local times of anticipator syncs as currently predicted on the board, for scheduling a
/// block that will start at `block_start`.
pub struct BoardTimes<'a> {
    /// The board.
    pub board: &'a PegBoard,
    /// The anticipator pegs.
    pub anticipators: &'a Anticipators,
    /// Global start of the block being scheduled.
    pub block_start: f64,
}

impl ExternalTimes for BoardTimes<'_> {
    fn time(&self, point: &SyncPoint) -> Option<f64> {
        match point {
            SyncPoint::Anticipator { anticipator, sync } => self
                .anticipators
                .get(anticipator, sync)
                .map(|p| self.board.global(p) - self.block_start),
            _ => None,
        }
    }
}

fn local(a: &Anchor) -> Option<(&str, &str)> {
    match a {
        Anchor::Point(SyncPoint::Local { behaviour, sync }) => {
            Some((behaviour.as_str(), sync.as_str()))
        }
        _ => None,
    }
}

/// Puts a scheduled block on the board, starting at global time `start`. `before`/`after`
/// constraints against an anticipator become order links only if that anticipator's peg is already
/// on the board (create it with [`Anticipators::peg`] at its prediction first).
pub fn plan_block(
    board: &mut PegBoard,
    anticipators: &mut Anticipators,
    block: &Block,
    schedule: &BlockSchedule,
    start: f64,
) -> PlannedBlock {
    let block_peg = board.add_block(&block.id, start);
    // one node per scheduled (finite) sync
    let mut node: HashMap<(&str, &str), usize> = HashMap::new();
    let mut times = Vec::new();
    for b in &schedule.behaviours {
        for (sync, t) in b.syncs.iter().filter(|(_, t)| t.is_finite()) {
            node.insert((b.id.as_str(), sync.as_ref()), times.len());
            times.push(*t);
        }
    }
    let n = times.len();
    let mut joined = Offsets::default();
    joined.reset(n);
    let mut named = vec![false; n];
    let mut on_anticipator: Vec<Option<(Id, Id, f64)>> = vec![None; n];
    let mut orders = Vec::new();
    let mut ant_orders = Vec::new();
    let constraints = extract(block);
    for c in &constraints {
        let l = local(&c.left).and_then(|k| node.get(&k).copied());
        let r = local(&c.right).and_then(|k| node.get(&k).copied());
        for v in [l, r].into_iter().flatten() {
            named[v] = true;
        }
        match (c.relation, l, r, &c.right) {
            (Relation::At, Some(a), Some(b), _) => {
                // (the schedule satisfies every constraint: no conflict to report here)
                joined.join(a, b, c.offset);
            }
            (
                Relation::At,
                Some(a),
                None,
                Anchor::Point(SyncPoint::Anticipator { anticipator, sync }),
            ) => {
                on_anticipator[a] = Some((anticipator.clone(), sync.clone(), c.offset));
            }
            (Relation::Before | Relation::After, Some(a), Some(b), _) => {
                orders.push((c.relation, a, b, c.offset))
            }
            (
                Relation::Before | Relation::After,
                Some(a),
                None,
                Anchor::Point(SyncPoint::Anticipator { anticipator, sync }),
            ) => ant_orders.push((c.relation, a, anticipator, sync, c.offset)),
            _ => {}
        }
    }
    // a rigid behaviour's named syncs keep their distances: one cluster
    for b in schedule.behaviours.iter().filter(|b| b.rigid) {
        let ids: Vec<usize> = b
            .syncs
            .iter()
            .filter_map(|(s, _)| node.get(&(b.id.as_str(), s.as_ref())).copied())
            .filter(|&v| named[v])
            .collect();
        for w in ids.windows(2) {
            joined.join(w[1], w[0], times[w[1]] - times[w[0]]);
        }
    }
    // one time peg per cluster of named syncs, offset pegs for the others in it
    let mut root_peg: HashMap<usize, PegId> = HashMap::new();
    let mut peg = vec![None; n];
    for v in 0..n {
        if !named[v] {
            continue;
        }
        let (root, off) = joined.find(v);
        let tp = *root_peg.entry(root).or_insert_with(|| {
            // a cluster at-linked to an anticipator hangs on its peg
            let linked = (0..n).find(|&w| on_anticipator[w].is_some() && joined.find(w).0 == root);
            match linked.and_then(|w| on_anticipator[w].clone().map(|a| (w, a))) {
                Some((w, (anticipator, sync, o))) => {
                    let ap = anticipators.peg(board, &anticipator, &sync, start + times[w] - o);
                    let (_, wo) = joined.find(w);
                    // time(root) = time(w) - wo = anticipator + o - wo
                    board.offset_peg(ap, o - wo)
                }
                None => board.time_peg(block_peg, times[root] - joined.find(root).1),
            }
        });
        peg[v] = Some(if off == 0.0 {
            tp
        } else {
            board.offset_peg(tp, off)
        });
    }
    // unnamed syncs: between named ones proportionally, outside them as offset pegs
    let mut behaviours = Vec::new();
    for b in &schedule.behaviours {
        let ids: Vec<(SyncName, usize)> = b
            .syncs
            .iter()
            .filter_map(|(s, _)| {
                node.get(&(b.id.as_str(), s.as_ref()))
                    .map(|&v| (s.clone(), v))
            })
            .collect();
        let named_ids: Vec<(usize, PegId)> = ids
            .iter()
            .filter_map(|(_, v)| peg[*v].map(|p| (*v, p)))
            .collect();
        let mut syncs = Vec::new();
        for (name, v) in &ids {
            let v = *v;
            let placement = if let Some(p) = peg[v] {
                Placement::Peg(p)
            } else {
                let before = named_ids
                    .iter()
                    .copied()
                    .rfind(|&(w, _)| times[w] <= times[v]);
                let after = named_ids
                    .iter()
                    .copied()
                    .find(|&(w, _)| times[w] >= times[v]);
                match (before, after) {
                    (Some((a, pa)), Some((z, pz))) if a != z => Placement::Between {
                        from: pa,
                        to: pz,
                        fraction: if times[z] > times[a] {
                            (times[v] - times[a]) / (times[z] - times[a])
                        } else {
                            0.0
                        },
                    },
                    (Some((w, pw)), _) | (_, Some((w, pw))) => {
                        Placement::Peg(board.offset_peg(pw, times[v] - times[w]))
                    }
                    (None, None) => {
                        // no sync of this behaviour is named: a time peg for its first sync, the
                        // others offset from it
                        let first = ids[0].1;
                        let p = match peg[first] {
                            Some(p) => p,
                            None => {
                                let p = board.time_peg(block_peg, times[first]);
                                peg[first] = Some(p);
                                p
                            }
                        };
                        if first == v {
                            Placement::Peg(p)
                        } else {
                            Placement::Peg(board.offset_peg(p, times[v] - times[first]))
                        }
                    }
                }
            };
            if let Placement::Peg(p) = placement {
                peg[v] = Some(p);
                board.attach(SyncAddr::new(&block.id, &b.id, name), p);
            }
            syncs.push((name.clone(), placement));
        }
        behaviours.push((b.id.clone(), syncs));
    }
    for (relation, a, b, offset) in orders {
        if let (Some(pa), Some(pb)) = (peg[a], peg[b]) {
            match relation {
                // a <= b + offset: b is later by at least -offset
                Relation::Before => board.order(pa, pb, -offset),
                // a >= b + offset
                _ => board.order(pb, pa, offset),
            }
        }
    }
    // before/after an anticipator's prediction: order links with its peg, if it is on the board
    for (relation, a, anticipator, sync, offset) in ant_orders {
        if let (Some(pa), Some(ap)) = (peg[a], anticipators.get(anticipator, sync)) {
            match relation {
                Relation::Before => board.order(pa, ap, -offset),
                _ => board.order(ap, pa, offset),
            }
        }
    }
    PlannedBlock {
        block: block_peg,
        behaviours,
    }
}

/// Behaviours of a planned block whose timing is no longer valid: syncs out of order, before the
/// block start, or an end not after the start.
pub fn invalid(board: &PegBoard, planned: &PlannedBlock) -> Vec<Id> {
    let start = board.block_start(planned.block);
    planned
        .behaviours
        .iter()
        .filter(|(id, _)| {
            let t = planned.times(board, id).unwrap_or_default();
            let ordered = t.windows(2).all(|w| w[1] >= w[0] - 1e-9);
            let after_start = t.iter().all(|x| *x >= start - 1e-9);
            let lasts = t.len() < 2 || t[t.len() - 1] > t[0];
            !(ordered && after_start && lasts)
        })
        .map(|(id, _)| id.clone())
        .collect()
}

/// A block on its own peg board (only blocks that refer to anticipators have one): moving an
/// anticipator's peg retimes what hangs on it.
#[derive(Debug, Clone)]
pub(crate) struct BlockPegs {
    pub(crate) board: PegBoard,
    pub(crate) anticipators: Anticipators,
    pub(crate) plan: PlannedBlock,
}

impl BlockPegs {
    /// Moves the pegs of the syncs of the anticipators in `changed` to their new predictions
    /// (`predict(anticipator, sync)`; a missing or infinite one leaves its peg): whether a peg
    /// moved, and why the last move the board refused was refused.
    pub(crate) fn follow(
        &mut self,
        changed: &[String],
        predict: impl Fn(&str, &str) -> Option<f64>,
    ) -> (bool, Option<String>) {
        let pegs: Vec<(String, String, PegId)> = self
            .anticipators
            .iter()
            .filter(|(a, _, _)| changed.iter().any(|c| c == a))
            .map(|(a, s, peg)| (a.to_string(), s.to_string(), peg))
            .collect();
        let (mut moved, mut refused) = (false, None);
        for (a, sync, peg) in pegs {
            let Some(prediction) = predict(&a, &sync).filter(|p| p.is_finite()) else {
                continue;
            };
            if (self.board.global(peg) - prediction).abs() > 1e-12 {
                match self.board.move_to(peg, prediction) {
                    Ok(_) => moved = true,
                    Err(e) => refused = Some(format!("anticipators:{a}:{sync}: {e}")),
                }
            }
        }
        (moved, refused)
    }
}
