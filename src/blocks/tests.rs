//! Unit tests of the block manager's internals.

use super::*;

/// A block is found where it is, whether or not blocks before or after it have left (the guess
/// from the newest block's seq, then the binary search), and an unknown or gone block is not.
#[test]
fn position_finds_blocks_with_and_without_gaps() {
    let ids = ["a", "b", "c", "d", "e", "f"];
    let index: HashMap<bml::Id, u64> = ids
        .iter()
        .enumerate()
        .map(|(i, id)| (bml::Id::new(id), i as u64 + 10))
        .collect();
    for live in [
        vec![10u64, 11, 12, 13, 14, 15], // none left
        vec![12, 13, 14, 15],            // the first two left
        vec![10, 12, 15],                // gaps inside
        vec![11, 12, 13],                // the newest left
    ] {
        for (i, id) in ids.iter().enumerate() {
            let seq = i as u64 + 10;
            assert_eq!(
                position(&live, &index, id),
                live.iter().position(|&s| s == seq),
                "{id} in {live:?}"
            );
        }
        assert_eq!(position(&live, &index, "z"), None);
    }
    assert_eq!(position(&[], &index, "a"), None);
}
