//! The one identifier type of the language, below the model and the sync references that both
//! name blocks, behaviours and sync points with it.

/// An id (of a block, behaviour, sync point or anticipator): immutable, cheap to clone, stored
/// inline without allocation up to 23 bytes.
pub type Id = smol_str::SmolStr;
