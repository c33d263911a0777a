//! The peg board, the flexible plan's representation of time (thesis §7.3):
//! - every sync point of every planned behaviour hangs on a peg;
//! - sync points joined by `at` share one peg, so moving the peg keeps the constraint;
//! - a `TimePeg` holds block-local time on a `BlockPeg`, so moving a block moves all of its pegs;
//! - an `OffsetPeg` stays at a fixed offset from its `TimePeg`;
//! - order links (the thesis' Before/AfterPegs) push or drag their partner when a peg moves past
//!   them, which keeps before/after constraints through run-time changes.
//!
//! Anticipator pegs live on the immovable global block peg at time 0.

use std::collections::HashMap;
use std::fmt;

/// A block peg: the global start time of one block (or of the global, anticipator, peg).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct BlockPegId(usize);

impl BlockPegId {
    /// The immovable global block peg at 0 that anticipator pegs hang on.
    pub const GLOBAL: BlockPegId = BlockPegId(0);
}

/// A time or offset peg.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct PegId(usize);

/// Addresses a sync point of a planned behaviour: (block id, behaviour id, sync id).
#[derive(Debug, Clone, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct SyncAddr {
    /// Block id.
    pub block: String,
    /// Behaviour id.
    pub behaviour: String,
    /// Sync point id.
    pub sync: String,
}

impl SyncAddr {
    /// `block:behaviour:sync`.
    pub fn new(block: &str, behaviour: &str, sync: &str) -> Self {
        SyncAddr {
            block: block.into(),
            behaviour: behaviour.into(),
            sync: sync.into(),
        }
    }
}

impl fmt::Display for SyncAddr {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}:{}", self.block, self.behaviour, self.sync)
    }
}

#[derive(Debug, Clone)]
struct BlockPeg {
    id: String,
    start: f64,
}

#[derive(Debug, Clone, Copy)]
enum Peg {
    /// Block-local time on a block peg.
    Time { block: BlockPegId, local: f64 },
    /// A fixed offset from a time peg (always a `Time` peg: offsets of offsets are flattened).
    Offset { link: PegId, offset: f64 },
}

/// `global(late) >= global(early) + gap`, kept when either peg moves.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Order {
    early: PegId,
    late: PegId,
    gap: f64,
}

/// Why a change to the board was refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PegError {
    /// The global block peg cannot move.
    #[error("the global block peg is immovable")]
    ImmovableGlobal,
    /// Order links that contradict each other (a cycle demanding more time than it has).
    #[error("order links between pegs contradict each other; the move cannot keep them")]
    ContradictoryOrder,
    /// A time that is not finite.
    #[error("peg times must be finite, got {0}")]
    NotFinite(f64),
}

/// All pegs of the plan.
#[derive(Debug, Clone)]
pub struct PegBoard {
    blocks: Vec<BlockPeg>,
    pegs: Vec<Peg>,
    orders: Vec<Order>,
    syncs: HashMap<SyncAddr, PegId>,
}

impl Default for PegBoard {
    fn default() -> Self {
        Self::new()
    }
}

impl PegBoard {
    /// A board with only the global block peg.
    pub fn new() -> Self {
        PegBoard {
            blocks: vec![BlockPeg {
                id: "anticipators".into(),
                start: 0.0,
            }],
            pegs: Vec::new(),
            orders: Vec::new(),
            syncs: HashMap::new(),
        }
    }

    /// Adds the block peg of block `id` starting at global time `start`.
    pub fn add_block(&mut self, id: &str, start: f64) -> BlockPegId {
        self.blocks.push(BlockPeg {
            id: id.into(),
            start,
        });
        BlockPegId(self.blocks.len() - 1)
    }

    /// The block id a block peg belongs to (`anticipators` for the global peg).
    pub fn block_id(&self, b: BlockPegId) -> &str {
        &self.blocks[b.0].id
    }

    /// Global start time of a block peg.
    pub fn block_start(&self, b: BlockPegId) -> f64 {
        self.blocks[b.0].start
    }

    /// Moves a block peg; all its pegs move with it, their local times unchanged.
    pub fn set_block_start(&mut self, b: BlockPegId, start: f64) -> Result<(), PegError> {
        if b == BlockPegId::GLOBAL {
            return Err(PegError::ImmovableGlobal);
        }
        if !start.is_finite() {
            return Err(PegError::NotFinite(start));
        }
        self.blocks[b.0].start = start;
        Ok(())
    }

    /// A new time peg at block-local time `local` on block `b`.
    pub fn time_peg(&mut self, b: BlockPegId, local: f64) -> PegId {
        self.pegs.push(Peg::Time { block: b, local });
        PegId(self.pegs.len() - 1)
    }

    /// A new offset peg, `offset` seconds after `link`. Linking to an offset peg links to
    /// its time peg with the offsets added.
    pub fn offset_peg(&mut self, link: PegId, offset: f64) -> PegId {
        let (root, base) = self.root(link);
        self.pegs.push(Peg::Offset {
            link: root,
            offset: base + offset,
        });
        PegId(self.pegs.len() - 1)
    }

    /// The time peg a peg is attached to and its offset from it.
    fn root(&self, p: PegId) -> (PegId, f64) {
        match self.pegs[p.0] {
            Peg::Time { .. } => (p, 0.0),
            Peg::Offset { link, offset } => (link, offset),
        }
    }

    /// The block peg a peg belongs to.
    pub fn block_of(&self, p: PegId) -> BlockPegId {
        match self.pegs[self.root(p).0 .0] {
            Peg::Time { block, .. } => block,
            Peg::Offset { .. } => unreachable!("offset pegs link to time pegs"),
        }
    }

    /// Global time of a peg: its block's start plus its local time.
    pub fn global(&self, p: PegId) -> f64 {
        let (root, offset) = self.root(p);
        match self.pegs[root.0] {
            Peg::Time { block, local } => self.blocks[block.0].start + local + offset,
            Peg::Offset { .. } => unreachable!("offset pegs link to time pegs"),
        }
    }

    /// Block-local time of a peg.
    pub fn local(&self, p: PegId) -> f64 {
        self.global(p) - self.block_start(self.block_of(p))
    }

    /// Requires `global(late) >= global(early) + gap` from now on: a Before/AfterPeg pair.
    pub fn order(&mut self, early: PegId, late: PegId, gap: f64) {
        self.orders.push(Order { early, late, gap });
    }

    /// Hangs a sync point on a peg (several sync points may share one).
    pub fn attach(&mut self, sync: SyncAddr, p: PegId) {
        self.syncs.insert(sync, p);
    }

    /// The peg a sync point hangs on.
    pub fn peg_of(&self, sync: &SyncAddr) -> Option<PegId> {
        self.syncs.get(sync).copied()
    }

    /// Global time of a sync point.
    pub fn time_of(&self, sync: &SyncAddr) -> Option<f64> {
        self.peg_of(sync).map(|p| self.global(p))
    }

    /// Sync points hanging on a peg or on any peg sharing its time peg.
    pub fn syncs_on(&self, p: PegId) -> Vec<&SyncAddr> {
        let root = self.root(p).0;
        let mut v: Vec<&SyncAddr> = self
            .syncs
            .iter()
            .filter(|(_, q)| self.root(**q).0 == root)
            .map(|(s, _)| s)
            .collect();
        v.sort();
        v
    }

    fn set_root_global(&mut self, root: PegId, t: f64) {
        if let Peg::Time { block, local } = &mut self.pegs[root.0] {
            *local = t - self.blocks[block.0].start;
        }
    }

    /// Moves peg `p` to global time `t` (an offset peg moves its time peg by the same delta),
    /// then pushes or drags pegs linked by order links so that every link still holds. Returns the
    /// time pegs that moved, the first being `p`'s.
    pub fn move_to(&mut self, p: PegId, t: f64) -> Result<Vec<PegId>, PegError> {
        if !t.is_finite() {
            return Err(PegError::NotFinite(t));
        }
        let (root, offset) = self.root(p);
        let saved = self.pegs.clone();
        self.set_root_global(root, t - offset);
        let mut moved = vec![root];
        let mut work = vec![root];
        let mut steps = 0usize;
        let limit = (self.orders.len() + 1) * (self.pegs.len() + 1);
        while let Some(r) = work.pop() {
            for i in 0..self.orders.len() {
                let o = self.orders[i];
                let (er, lr) = (self.root(o.early).0, self.root(o.late).0);
                if er != r && lr != r {
                    continue;
                }
                let (e, l) = (self.global(o.early), self.global(o.late));
                if l + 1e-12 >= e + o.gap {
                    continue;
                }
                steps += 1;
                if steps > limit {
                    self.pegs = saved;
                    return Err(PegError::ContradictoryOrder);
                }
                // the peg that did not just move gives way
                let (target, new_t) = if er == r {
                    (o.late, e + o.gap)
                } else {
                    (o.early, l - o.gap)
                };
                let (troot, toff) = self.root(target);
                self.set_root_global(troot, new_t - toff);
                if !moved.contains(&troot) {
                    moved.push(troot);
                }
                work.push(troot);
            }
        }
        Ok(moved)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn addr(b: &str, beh: &str, s: &str) -> SyncAddr {
        SyncAddr::new(b, beh, s)
    }

    /// syncs joined by `at` share a peg; moving it moves them all and keeps the constraint.
    #[test]
    fn moving_a_peg_moves_every_sync_on_it() {
        let mut board = PegBoard::new();
        let b = board.add_block("bml1", 10.0);
        let p = board.time_peg(b, 1.0);
        board.attach(addr("bml1", "speech1", "s1"), p);
        board.attach(addr("bml1", "nod1", "stroke"), p);
        board.move_to(p, 12.5).unwrap();
        assert_eq!(board.time_of(&addr("bml1", "speech1", "s1")), Some(12.5));
        assert_eq!(board.time_of(&addr("bml1", "nod1", "stroke")), Some(12.5));
        assert_eq!(board.syncs_on(p).len(), 2);
    }

    /// An offset peg keeps its offset; moving either moves the other.
    #[test]
    fn offset_pegs_move_with_their_time_peg_and_back() {
        let mut board = PegBoard::new();
        let b = board.add_block("bml1", 0.0);
        let tp = board.time_peg(b, 2.0);
        let op = board.offset_peg(tp, 0.5);
        let op2 = board.offset_peg(op, -1.0); // flattened onto tp with offset -0.5
        assert_eq!((board.global(op), board.global(op2)), (2.5, 1.5));
        board.move_to(tp, 3.0).unwrap();
        assert_eq!((board.global(op), board.global(op2)), (3.5, 2.5));
        let moved = board.move_to(op, 5.0).unwrap();
        assert_eq!(moved, vec![tp]);
        assert_eq!((board.global(tp), board.global(op2)), (4.5, 4.0));
    }

    /// Global = block start + local; moving the block shifts its pegs, keeping relations.
    #[test]
    fn moving_a_block_peg_shifts_its_pegs_only() {
        let mut board = PegBoard::new();
        let b1 = board.add_block("bml1", 1.0);
        let b2 = board.add_block("bml2", 1.0);
        let a = board.time_peg(b1, 0.5);
        let c = board.offset_peg(a, 2.0);
        let other = board.time_peg(b2, 0.5);
        assert_eq!((board.global(a), board.local(a)), (1.5, 0.5));
        board.set_block_start(b1, 4.0).unwrap();
        assert_eq!(
            (board.global(a), board.global(c), board.local(c)),
            (4.5, 6.5, 2.5)
        );
        assert_eq!(board.global(other), 1.5);
        assert_eq!(board.block_of(c), b1);
    }

    /// anticipator pegs hang on the immovable global block peg at 0.
    #[test]
    fn global_block_peg_is_immovable_and_its_pegs_are_global_times() {
        let mut board = PegBoard::new();
        assert_eq!(board.block_id(BlockPegId::GLOBAL), "anticipators");
        let stop = board.time_peg(BlockPegId::GLOBAL, 7.25);
        assert_eq!(board.global(stop), 7.25);
        assert_eq!(
            board.set_block_start(BlockPegId::GLOBAL, 1.0),
            Err(PegError::ImmovableGlobal)
        );
        board.move_to(stop, 8.0).unwrap(); // an anticipator update
        assert_eq!(board.global(stop), 8.0);
    }

    /// a behaviour constrained to another block's or an anticipator's peg moves with it.
    #[test]
    fn external_pegs_move_referring_behaviours() {
        let mut board = PegBoard::new();
        let b = board.add_block("bml2", 3.0);
        let anticipated = board.time_peg(BlockPegId::GLOBAL, 6.0);
        let nod_start = board.offset_peg(anticipated, 1.0); // nod1:start = anticipators:a:s + 1
        board.attach(addr("bml2", "nod1", "start"), nod_start);
        board.move_to(anticipated, 6.4).unwrap();
        assert_eq!(board.time_of(&addr("bml2", "nod1", "start")), Some(7.4));
        // the behaviour belongs to bml2, its peg to the anticipator's (global) block peg
        assert_eq!(board.block_of(nod_start), BlockPegId::GLOBAL);
        assert_ne!(b, BlockPegId::GLOBAL);
    }

    /// Before/AfterPegs: moving a peg past its partner pushes (or drags) the partner along.
    #[test]
    fn order_links_push_and_drag_partners() {
        let mut board = PegBoard::new();
        let b = board.add_block("bml1", 0.0);
        let g1_end = board.time_peg(b, 2.0);
        let s1_start = board.time_peg(b, 2.5);
        let s1_end = board.offset_peg(s1_start, 1.0);
        board.order(g1_end, s1_start, 0.0); // s1:start >= g1:end
                                            // moving g1:end later pushes the speech (and its end, an offset peg) along
        let moved = board.move_to(g1_end, 3.0).unwrap();
        assert_eq!(moved, vec![g1_end, s1_start]);
        assert_eq!((board.global(s1_start), board.global(s1_end)), (3.0, 4.0));
        // moving the speech earlier drags g1:end back
        board.move_to(s1_start, 1.0).unwrap();
        assert_eq!(board.global(g1_end), 1.0);
        // moves that keep the order leave the partner alone
        board.move_to(s1_start, 5.0).unwrap();
        assert_eq!(board.global(g1_end), 1.0);
    }

    #[test]
    fn contradictory_order_links_are_refused_and_nothing_moves() {
        let mut board = PegBoard::new();
        let b = board.add_block("bml1", 0.0);
        let a = board.time_peg(b, 0.0);
        let c = board.time_peg(b, 1.0);
        board.order(a, c, 1.0);
        board.order(c, a, 0.5); // a >= c + 0.5 and c >= a + 1: impossible
        assert_eq!(board.move_to(a, 2.0), Err(PegError::ContradictoryOrder));
        assert_eq!((board.global(a), board.global(c)), (0.0, 1.0));
        assert!(matches!(
            board.move_to(a, f64::NAN),
            Err(PegError::NotFinite(_))
        ));
    }
}
