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

use crate::language::bml::{extract, Anchor, Block, Id, Relation, SyncPoint};
use crate::planning::plan::pegs::{BlockPegId, PegBoard, PegId, SyncAddr};
use crate::planning::schedule::offsets::Offsets;
use crate::planning::schedule::{BlockSchedule, ExternalTimes};
use crate::planning::timing::SyncName;

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
    plan_block_with(board, anticipators, block, schedule, start, &[])
}

/// [`plan_block`], with every sync of the behaviours `own_pegs` on a peg of its own (joined
/// only by `at` constraints): behaviours whose engine revises their times while they run.
pub fn plan_block_with(
    board: &mut PegBoard,
    anticipators: &mut Anticipators,
    block: &Block,
    schedule: &BlockSchedule,
    start: f64,
    own_pegs: &[&str],
) -> PlannedBlock {
    let block_peg = board.add_block(&block.id, start);
    let mut p = Planner::new(board, anticipators, schedule, block_peg, start);
    let constraints = extract(block);
    let orders = p.read_constraints(&constraints);
    for b in schedule
        .behaviours
        .iter()
        .filter(|b| own_pegs.contains(&b.id.as_str()))
    {
        for (sync, _) in &b.syncs {
            if let Some(&v) = p.node.get(&(b.id.as_str(), sync.as_ref())) {
                p.named[v] = true;
            }
        }
    }
    p.join_rigid();
    p.cluster_pegs();
    let behaviours: Vec<_> = (schedule.behaviours.iter())
        .map(|b| (b.id.clone(), p.place_behaviour(&block.id, b)))
        .collect();
    p.link_orders(orders);
    keep_in_order(p.board, &behaviours, own_pegs);
    PlannedBlock {
        block: block_peg,
        behaviours,
    }
}

/// The syncs of each behaviour of `own` (on pegs of their own) stay in their order when an
/// anticipator moves some of them: a peg that would pass its neighbour pushes or drags it
/// along, until the behaviour's engine gives their times.
fn keep_in_order(
    board: &mut PegBoard,
    behaviours: &[(Id, Vec<(SyncName, Placement)>)],
    own: &[&str],
) {
    for (_, syncs) in behaviours
        .iter()
        .filter(|(id, _)| own.contains(&id.as_str()))
    {
        let pegs: Vec<PegId> = (syncs.iter())
            .filter_map(|(_, p)| match p {
                Placement::Peg(p) => Some(*p),
                Placement::Between { .. } => None,
            })
            .collect();
        for w in pegs.windows(2) {
            board.order(w[0], w[1], 0.0);
        }
    }
}

/// A before/after constraint between two syncs of the block (by node), or between a sync and an
/// anticipator's prediction.
enum Order<'c> {
    Local(Relation, usize, usize, f64),
    Anticipator(Relation, usize, &'c Id, &'c Id, f64),
}

/// The state of [`plan_block`]: one node per scheduled (finite) sync, the clusters `at`
/// constraints and rigid behaviours join them into, and each node's peg once it has one.
struct Planner<'a> {
    board: &'a mut PegBoard,
    anticipators: &'a mut Anticipators,
    schedule: &'a BlockSchedule,
    block_peg: BlockPegId,
    start: f64,
    /// (behaviour, sync) → node.
    node: HashMap<(&'a str, &'a str), usize>,
    /// Each node's block-local time in the schedule.
    times: Vec<f64>,
    /// Clusters of nodes with fixed offsets between them.
    joined: Offsets,
    /// Whether a constraint names the node.
    named: Vec<bool>,
    /// The anticipator sync a node is `at`-linked to (with the constraint's offset).
    on_anticipator: Vec<Option<(Id, Id, f64)>>,
    /// Each node's peg, once placed.
    peg: Vec<Option<PegId>>,
}

impl<'a> Planner<'a> {
    fn new(
        board: &'a mut PegBoard,
        anticipators: &'a mut Anticipators,
        schedule: &'a BlockSchedule,
        block_peg: BlockPegId,
        start: f64,
    ) -> Self {
        let mut node = HashMap::new();
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
        Planner {
            board,
            anticipators,
            schedule,
            block_peg,
            start,
            node,
            times,
            joined,
            named: vec![false; n],
            on_anticipator: vec![None; n],
            peg: vec![None; n],
        }
    }

    fn node_of(&self, a: &Anchor) -> Option<usize> {
        local(a).and_then(|k| self.node.get(&k).copied())
    }

    /// Marks the syncs the constraints name, joins `at`-linked ones, notes links to
    /// anticipators, and returns the before/after constraints for [`link_orders`](Self::link_orders).
    fn read_constraints<'c>(
        &mut self,
        constraints: &'c [crate::language::bml::Constraint],
    ) -> Vec<Order<'c>> {
        let mut orders = Vec::new();
        for c in constraints {
            let (l, r) = (self.node_of(&c.left), self.node_of(&c.right));
            for v in [l, r].into_iter().flatten() {
                self.named[v] = true;
            }
            let anticipator = match &c.right {
                Anchor::Point(SyncPoint::Anticipator { anticipator, sync }) => {
                    Some((anticipator, sync))
                }
                _ => None,
            };
            match (c.relation, l, r, anticipator) {
                // (the schedule satisfies every constraint: no conflict to report here)
                (Relation::At, Some(a), Some(b), _) => {
                    self.joined.join(a, b, c.offset);
                }
                (Relation::At, Some(a), None, Some((ant, sync))) => {
                    self.on_anticipator[a] = Some((ant.clone(), sync.clone(), c.offset));
                }
                (Relation::Before | Relation::After, Some(a), Some(b), _) => {
                    orders.push(Order::Local(c.relation, a, b, c.offset))
                }
                (Relation::Before | Relation::After, Some(a), None, Some((ant, sync))) => {
                    orders.push(Order::Anticipator(c.relation, a, ant, sync, c.offset))
                }
                _ => {}
            }
        }
        orders
    }

    /// A rigid behaviour's named syncs keep their distances: one cluster.
    fn join_rigid(&mut self) {
        for b in self.schedule.behaviours.iter().filter(|b| b.rigid) {
            let ids: Vec<usize> = (b.syncs.iter())
                .filter_map(|(s, _)| self.node.get(&(b.id.as_str(), s.as_ref())).copied())
                .filter(|&v| self.named[v])
                .collect();
            for w in ids.windows(2) {
                let (a, z) = (w[0], w[1]);
                self.joined.join(z, a, self.times[z] - self.times[a]);
            }
        }
    }

    /// One time peg per cluster of named syncs (on an anticipator's peg if the cluster is
    /// `at`-linked to one), offset pegs for the others in it.
    fn cluster_pegs(&mut self) {
        let mut root_peg: HashMap<usize, PegId> = HashMap::new();
        for v in 0..self.times.len() {
            if !self.named[v] {
                continue;
            }
            let (root, off) = self.joined.find(v);
            let tp = match root_peg.get(&root) {
                Some(&tp) => tp,
                None => {
                    let tp = self.cluster_peg(root);
                    root_peg.insert(root, tp);
                    tp
                }
            };
            self.peg[v] = Some(if off == 0.0 {
                tp
            } else {
                self.board.offset_peg(tp, off)
            });
        }
    }

    /// The peg of the cluster whose root is `root`.
    fn cluster_peg(&mut self, root: usize) -> PegId {
        let n = self.times.len();
        let linked = (0..n)
            .find(|&w| self.on_anticipator[w].is_some() && self.joined.find(w).0 == root)
            .and_then(|w| self.on_anticipator[w].clone().map(|a| (w, a)));
        match linked {
            Some((w, (anticipator, sync, o))) => {
                let predicted = self.start + self.times[w] - o;
                let ap = (self.anticipators).peg(self.board, &anticipator, &sync, predicted);
                let (_, wo) = self.joined.find(w);
                // time(root) = time(w) - wo = anticipator + o - wo
                self.board.offset_peg(ap, o - wo)
            }
            None => {
                let t = self.times[root] - self.joined.find(root).1;
                self.board.time_peg(self.block_peg, t)
            }
        }
    }

    /// Places every sync of behaviour `b` and attaches the ones with a peg of their own.
    fn place_behaviour(
        &mut self,
        block: &Id,
        b: &crate::planning::schedule::ScheduledBehaviour,
    ) -> Vec<(SyncName, Placement)> {
        let ids: Vec<(SyncName, usize)> = (b.syncs.iter())
            .filter_map(|(s, _)| {
                let v = self.node.get(&(b.id.as_str(), s.as_ref()))?;
                Some((s.clone(), *v))
            })
            .collect();
        let named: Vec<(usize, PegId)> = (ids.iter())
            .filter_map(|(_, v)| self.peg[*v].map(|p| (*v, p)))
            .collect();
        let mut syncs = Vec::with_capacity(ids.len());
        for (name, v) in &ids {
            let placement = match self.peg[*v] {
                Some(p) => Placement::Peg(p),
                None => self.place_unnamed(*v, &named, ids[0].1),
            };
            if let Placement::Peg(p) = placement {
                self.peg[*v] = Some(p);
                self.board.attach(SyncAddr::new(block, &b.id, name), p);
            }
            syncs.push((name.clone(), placement));
        }
        syncs
    }

    /// An unnamed sync `v`: between the behaviour's `named` syncs around it proportionally,
    /// outside them an offset peg on the nearest; in a behaviour nothing names, offset from a
    /// time peg for its `first` sync.
    fn place_unnamed(&mut self, v: usize, named: &[(usize, PegId)], first: usize) -> Placement {
        let times = &self.times;
        let before = named.iter().copied().rfind(|&(w, _)| times[w] <= times[v]);
        let after = named.iter().copied().find(|&(w, _)| times[w] >= times[v]);
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
                Placement::Peg(self.board.offset_peg(pw, times[v] - times[w]))
            }
            (None, None) => {
                let p = match self.peg[first] {
                    Some(p) => p,
                    None => {
                        let p = self.board.time_peg(self.block_peg, self.times[first]);
                        self.peg[first] = Some(p);
                        p
                    }
                };
                if first == v {
                    Placement::Peg(p)
                } else {
                    let offset = self.times[v] - self.times[first];
                    Placement::Peg(self.board.offset_peg(p, offset))
                }
            }
        }
    }

    /// Before/after constraints become order links; against an anticipator's prediction only if
    /// its peg is on the board.
    fn link_orders(&mut self, orders: Vec<Order<'_>>) {
        for order in orders {
            let (relation, pa, pb, offset) = match order {
                Order::Local(relation, a, b, offset) => {
                    (relation, self.peg[a], self.peg[b], offset)
                }
                Order::Anticipator(relation, a, anticipator, sync, offset) => {
                    let ap = self.anticipators.get(anticipator, sync);
                    (relation, self.peg[a], ap, offset)
                }
            };
            let (Some(pa), Some(pb)) = (pa, pb) else {
                continue;
            };
            match relation {
                // a <= b + offset: b is later by at least -offset
                Relation::Before => self.board.order(pa, pb, -offset),
                // a >= b + offset
                _ => self.board.order(pb, pa, offset),
            }
        }
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
