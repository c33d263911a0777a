//! The live blocks of one character: stable handles ([`BlockKey`]) that stay valid while other
//! blocks come and go, arrival order, and lookup by id.

use std::collections::BTreeMap;
use std::ops::{Index, IndexMut};

// block ids come from the host: a fast hash (rustc's) instead of SipHash for the id index
use rustc_hash::FxHashMap as HashMap;
use slotmap::{new_key_type, SlotMap};

use super::live::LiveBlock;
use crate::language::bml;

new_key_type! {
    /// A live block's handle. It stays valid until that block leaves the plan; after that it
    /// finds nothing (it is never reused for another block).
    pub(crate) struct BlockKey;
}

/// The live blocks, in arrival order.
#[derive(Default)]
pub(super) struct Blocks {
    slots: SlotMap<BlockKey, LiveBlock>,
    /// Handles by arrival (the block's `seq`): blocks leave from anywhere, most often the front,
    /// so a map rather than a list that would shift.
    order: BTreeMap<u64, BlockKey>,
    by_id: HashMap<bml::Id, BlockKey>,
}

impl Blocks {
    /// Adds a block (its id is not in use); returns its handle.
    pub(super) fn insert(&mut self, block: LiveBlock) -> BlockKey {
        let (id, seq) = (block.id.clone(), block.seq);
        let key = self.slots.insert(block);
        self.order.insert(seq, key);
        self.by_id.insert(id, key);
        key
    }

    /// Takes block `key` out.
    pub(super) fn remove(&mut self, key: BlockKey) -> Option<LiveBlock> {
        let block = self.slots.remove(key)?;
        self.order.remove(&block.seq);
        self.by_id.remove(&block.id);
        Some(block)
    }

    /// The live block named `id`.
    pub(super) fn find(&self, id: &str) -> Option<BlockKey> {
        self.by_id.get(id).copied()
    }

    /// Block `key`, if it is still live.
    pub(super) fn get(&self, key: BlockKey) -> Option<&LiveBlock> {
        self.slots.get(key)
    }

    /// The live block named `id`.
    pub(super) fn named(&self, id: &str) -> Option<&LiveBlock> {
        self.slots.get(self.find(id)?)
    }

    /// How many blocks are live.
    pub(super) fn len(&self) -> usize {
        self.order.len()
    }

    /// Handles in arrival order.
    pub(super) fn keys(&self) -> impl Iterator<Item = BlockKey> + '_ {
        self.order.values().copied()
    }

    /// Blocks in arrival order.
    pub(super) fn iter(&self) -> impl Iterator<Item = &LiveBlock> + '_ {
        self.order.values().map(|&k| &self.slots[k])
    }

    /// (handle, block) in arrival order.
    pub(super) fn with_keys(&self) -> impl Iterator<Item = (BlockKey, &LiveBlock)> + '_ {
        self.order.values().map(|&k| (k, &self.slots[k]))
    }
}

impl Index<BlockKey> for Blocks {
    type Output = LiveBlock;
    fn index(&self, key: BlockKey) -> &LiveBlock {
        &self.slots[key]
    }
}

impl IndexMut<BlockKey> for Blocks {
    fn index_mut(&mut self, key: BlockKey) -> &mut LiveBlock {
        &mut self.slots[key]
    }
}
