//! The unit tests of `optimal`.

use super::fast::{at_preferred_timing, pinned_apart};
use super::*;
use crate::language::bml;
use crate::planning::schedule::links::resolve;
use crate::planning::schedule::strategy::NoExternal;
use crate::planning::timing::{DefaultTimingModels, TimingModel};

fn prepared(src: &str) -> (Vec<TimingModel>, Block) {
    let block = bml::load(src).unwrap().block;
    let models = block
        .behaviours
        .iter()
        .map(|b| DefaultTimingModels::default().model(b).unwrap())
        .collect();
    (models, block)
}

/// Items and links of a one-block source, as `Optimal` prepares them.
fn linked(block: &Block, models: Vec<TimingModel>) -> (Vec<Item<'_>>, Vec<Link>) {
    let items: Vec<Item> = block
        .behaviours
        .iter()
        .zip(models)
        .map(|(beh, model)| Item {
            beh,
            len: model.keys.len(),
            model,
        })
        .collect();
    let (links, unusable) = resolve(block, &items, &extract(block), &NoExternal);
    assert!(unusable.is_none());
    (items, links)
}

/// The shortcut says "must stretch" exactly when two fixed times disagree with the preferred
/// timing, and then the preferred-timing system has no solution either.
#[test]
fn pinned_apart_only_when_fixed_times_disagree_with_preferred_timing() {
    let ns = r#"xmlns="http://www.bml-initiative.org/bml/bml-1.0""#;
    let head =
        |syncs: &str| format!(r#"<bml {ns} id="b"><head id="h" lexeme="NOD" {syncs}/></bml>"#);
    let (models, _) = prepared(&head(""));
    let d = models[0].preferred_duration();
    let stroke = models[0].keys[models[0].key("stroke").unwrap()].at;
    for (syncs, apart) in [
        (String::from(r#"start="0" end="5""#), true),
        (format!(r#"start="1" end="{}""#, 1.0 + d), false),
        (format!(r#"start="1" stroke="{}""#, 1.0 + stroke), false),
        (format!(r#"start="1" stroke="{}""#, 1.5 + stroke), true),
        (String::from(r#"start="1""#), false),
        (String::from(r#"end="2""#), false),
    ] {
        let (models, block) = prepared(&head(&syncs));
        let (items, links) = linked(&block, models);
        assert_eq!(pinned_apart(&items, &links), apart, "{syncs}");
        // the shortcut never hides a preferred-timing answer
        if apart {
            assert_eq!(at_preferred_timing(&items, &links), None, "{syncs}");
        }
    }
}

/// Where both apply, the uniform-stretch fast path and the LP agree.
#[test]
fn uniform_fast_path_matches_the_linear_program() {
    let dir = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/fixtures/realizertester/bml-1/core/"
    );
    for file in [
        "testspeechgestures.xml",
        "testnodlong.xml",
        "testspeech_nodtimedtosync.xml",
        "testshortbeh.xml",
    ] {
        let (models, block) = prepared(&std::fs::read_to_string(format!("{dir}{file}")).unwrap());
        let (items, links) = linked(&block, models);
        assert!(
            preferred(&items, &links).is_none(),
            "{file} needs stretching"
        );
        let fast = separable(&items, &links).unwrap_or_else(|| panic!("{file}: no fast path"));
        let lp = optimise(&items, &links);
        assert_eq!(fast.len(), lp.len(), "{file}");
        for (a, b) in fast.iter().zip(&lp) {
            assert!((a - b).abs() < 1e-6, "{file}: {fast:?} vs {lp:?}");
        }
    }
}
