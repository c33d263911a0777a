//! The blocks' waiting relation as a graph: block X → Y when X waits for Y to end (APPEND,
//! APPEND-AFTER, `appendAfter`, another block's `prependBefore`) or to subside (`chunkAfter`,
//! another block's `chunkBefore`). Waiting must stay acyclic: the blocks on a cycle would wait for
//! each other for ever and never start.

use petgraph::algo::has_path_connecting;
use petgraph::graphmap::DiGraphMap;

use super::live::LiveBlock;
use super::store::Blocks;

/// Whether `from` (a block about to join `blocks`) waits, directly or through other blocks, for
/// the block `to`: then `to` may not be made to wait for `from`.
pub(super) fn waits_on(blocks: &Blocks, from: &LiveBlock, to: &str) -> bool {
    let mut graph: DiGraphMap<&str, ()> = DiGraphMap::new();
    for b in blocks.iter().chain(std::iter::once(from)) {
        graph.add_node(b.id.as_str());
        for w in b.waits_for.iter().chain(&b.chunk_after) {
            graph.add_edge(b.id.as_str(), w.as_str(), ());
        }
    }
    graph.contains_node(to) && has_path_connecting(&graph, from.id.as_str(), to, None)
}
