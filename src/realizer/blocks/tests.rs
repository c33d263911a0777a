//! Unit tests of the block manager's internals.

use super::*;

fn live(id: &str, seq: u64) -> LiveBlock {
    let text = format!(r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="{id}"/>"#);
    let block = bml::load(&text).unwrap().block;
    LiveBlock::new(block, seq, 0.0, Vec::new(), Vec::new())
}

/// A block's handle keeps finding it while blocks before and after it leave; a gone block's
/// handle finds nothing, also after a block of the same id arrives again; order is arrival order.
#[test]
fn handles_stay_valid_while_other_blocks_come_and_go() {
    let mut blocks = Blocks::default();
    let keys: Vec<BlockKey> = ["a", "b", "c", "d"]
        .iter()
        .enumerate()
        .map(|(i, id)| blocks.insert(live(id, i as u64)))
        .collect();
    assert!(blocks.remove(keys[0]).is_some());
    assert!(blocks.remove(keys[2]).is_some());
    assert_eq!(blocks[keys[1]].id, "b");
    assert_eq!(blocks[keys[3]].id, "d");
    assert!(blocks.get(keys[2]).is_none());
    assert!(
        blocks.remove(keys[2]).is_none(),
        "removing twice does nothing"
    );
    let again = blocks.insert(live("c", 9));
    assert!(
        blocks.get(keys[2]).is_none(),
        "the old handle does not find the new 'c'"
    );
    assert_eq!(blocks.find("c"), Some(again));
    assert_eq!(blocks.find("a"), None);
    let order: Vec<&str> = blocks.iter().map(|b| b.id.as_str()).collect();
    assert_eq!(order, ["b", "d", "c"]);
    assert_eq!(blocks.len(), 3);
}
