//! The unit tests of `timeline`.

use super::*;
use crate::language::feedback::{BlockProgress, SyncPointProgress, WarningFeedback};

fn sync(b: &str, beh: &str, s: &str, t: f64) -> Feedback {
    Feedback::SyncPointProgress(SyncPointProgress {
        block: b.into(),
        behaviour: beh.into(),
        sync: s.into(),
        time: t,
        global_time: t,
        character_id: None,
        posix_time: None,
        skipped: false,
    })
}

#[test]
fn a_block_revoked_before_it_started_is_drawn_without_lanes() {
    let progress = |block: &str, sync: &str, t: f64, status| {
        Feedback::BlockProgress(BlockProgress {
            block: block.into(),
            sync: sync.into(),
            global_time: t,
            character_id: None,
            status: Some(status),
            posix_time: None,
        })
    };
    let fb = vec![
        progress("a", "start", 0.0, BlockStatus::InExec),
        sync("a", "s", "start", 0.0),
        progress("a", "end", 1.0, BlockStatus::Interrupted),
        progress("b", "end", 1.0, BlockStatus::Revoked),
    ];
    let t = Timeline::from_feedback(&fb);
    let b = &t.blocks[1];
    assert_eq!((b.start, b.end, b.lanes.len()), (Some(1.0), Some(1.0), 0));
    assert_eq!(t.blocks[0].lanes.len(), 1);
    assert!(t.to_svg().contains("REVOKED"));
}

#[test]
fn a_log_becomes_lanes_with_coincidence_links_and_warnings() {
    let fb = vec![
        Feedback::BlockProgress(BlockProgress {
            block: "b".into(),
            sync: "start".into(),
            global_time: 0.0,
            character_id: None,
            status: Some(BlockStatus::InExec),
            posix_time: None,
        }),
        sync("b", "s", "start", 0.0),
        sync("b", "g", "start", 0.5),
        sync("b", "s", "w", 1.0),
        sync("b", "g", "stroke", 1.0),
        Feedback::Warning(WarningFeedback {
            id: "b:g".into(),
            kind: crate::language::feedback::KnownWarning::InvalidTiming.into(),
            character_id: None,
            text: "late <&>".into(),
        }),
    ];
    let t = Timeline::from_feedback(&fb);
    assert_eq!(t.blocks.len(), 1);
    assert_eq!(t.blocks[0].lanes.len(), 2);
    assert!(t.blocks[0].lanes[1].warned);
    assert_eq!(t.links.len(), 1);
    assert_eq!(t.links[0].label, "≈");
    let svg = t.to_svg();
    assert!(svg.starts_with("<svg "));
    assert!(svg.contains("late &lt;&amp;&gt;"));
    // well-formed
    let mut r = quick_xml::Reader::from_str(&svg);
    loop {
        match r.read_event() {
            Ok(quick_xml::events::Event::Eof) => break,
            Ok(_) => {}
            Err(e) => panic!("{e}"),
        }
    }
}
