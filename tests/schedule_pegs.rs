//! Schedules on the peg board: shared pegs for `at`-linked syncs, offset pegs, unnamed
//! syncs following their behaviour, anticipator moves without rescheduling and the
//! validity check after them, and before/after as pushing order links.

use bml_realizer::language::bml;
use bml_realizer::planning::plan::pegs::{PegBoard, SyncAddr};
use bml_realizer::planning::plan::to_pegs::{
    invalid, plan_block, Anticipators, BoardTimes, PlannedBlock,
};
use bml_realizer::planning::schedule::{Optimal, SchedulingStrategy};
use bml_realizer::planning::timing::DefaultTimingModels;

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() < 1e-9
}

fn addr(beh: &str, sync: &str) -> SyncAddr {
    SyncAddr::new("bml1", beh, sync)
}

fn planned(
    src: &str,
    board: &mut PegBoard,
    anticipators: &mut Anticipators,
    start: f64,
) -> PlannedBlock {
    let block = bml::load(src).unwrap().block;
    let schedule = {
        let times = BoardTimes {
            board,
            anticipators,
            block_start: start,
        };
        Optimal
            .schedule(&block, &DefaultTimingModels::syllable_timed(), &times)
            .unwrap()
    };
    assert!(schedule.dropped.is_empty(), "{:?}", schedule.dropped);
    let p = plan_block(board, anticipators, &block, &schedule, start);
    // the plan reproduces the schedule
    for b in &schedule.behaviours {
        for (sync, t) in b.syncs.iter().filter(|(_, t)| t.is_finite()) {
            let on_board = p.time(board, &b.id, sync).unwrap();
            assert!(
                close(on_board, start + t),
                "{}:{sync} board {on_board} schedule {}",
                b.id,
                start + t
            );
        }
    }
    p
}

#[test]
fn thesis_example_30_on_pegs() {
    let src = std::fs::read_to_string(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/fixtures/thesis/ex30.xml"
    ))
    .unwrap();
    let (mut board, mut ants) = (PegBoard::new(), Anticipators::default());
    planned(&src, &mut board, &mut ants, 10.0);
    let peg = |b: &str, s: &str| board.peg_of(&addr(b, s)).unwrap();
    // speech1:s1 = nod1:stroke share a peg; point1:start = walk1:end share another
    assert_eq!(peg("speech1", "s1"), peg("nod1", "stroke"));
    assert_eq!(peg("point1", "start"), peg("walk1", "end"));
    // point1:stroke = speech1:s1 + 0.5 is an offset peg
    assert_ne!(peg("point1", "stroke"), peg("speech1", "s1"));
    let s1 = board.time_of(&addr("speech1", "s1")).unwrap();
    // moving the s1 peg moves everything linked to it and the unnamed syncs of its behaviours
    let speech_start = board.time_of(&addr("speech1", "start")).unwrap();
    let nod_end = board.time_of(&addr("nod1", "end")).unwrap();
    board.move_to(peg("speech1", "s1"), s1 + 1.0).unwrap();
    assert!(close(
        board.time_of(&addr("nod1", "stroke")).unwrap(),
        s1 + 1.0
    ));
    assert!(close(
        board.time_of(&addr("point1", "stroke")).unwrap(),
        s1 + 1.5
    ));
    assert!(close(
        board.time_of(&addr("speech1", "start")).unwrap(),
        speech_start + 1.0
    ));
    assert!(close(
        board.time_of(&addr("nod1", "end")).unwrap(),
        nod_end + 1.0
    ));
}

#[test]
fn a_behaviour_no_constraint_names_gets_its_own_peg() {
    let src = r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="bml1"><head id="nod1" lexeme="NOD"/><gesture id="g1" lexeme="BEAT"/></bml>"#;
    let (mut board, mut ants) = (PegBoard::new(), Anticipators::default());
    planned(src, &mut board, &mut ants, 0.0);
    let (n, g) = (
        board.peg_of(&addr("nod1", "start")).unwrap(),
        board.peg_of(&addr("g1", "start")).unwrap(),
    );
    assert_ne!(n, g);
    board.move_to(n, 1.0).unwrap();
    assert!(
        close(board.time_of(&addr("nod1", "end")).unwrap(), 1.6),
        "the nod moves as a whole"
    );
    assert!(
        close(board.time_of(&addr("g1", "start")).unwrap(), 0.0),
        "the gesture stays"
    );
}

#[test]
fn anticipator_moves_retime_without_rescheduling_and_invalidate() {
    let src = r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="bml1">
        <head id="nod1" lexeme="NOD" start="anticipators:beat:b1"/>
        <gesture id="g1" lexeme="BEAT" start="nod1:end"/></bml>"#;
    let (mut board, mut ants) = (PegBoard::new(), Anticipators::default());
    let beat = ants.peg(&mut board, "beat", "b1", 2.0);
    let plan = planned(src, &mut board, &mut ants, 0.0);
    assert!(close(board.time_of(&addr("nod1", "start")).unwrap(), 2.0));
    assert!(close(board.time_of(&addr("g1", "start")).unwrap(), 2.6));
    // a small update: the nod's start follows the prediction, nothing else is rescheduled
    board.move_to(beat, 2.2).unwrap();
    assert!(close(board.time_of(&addr("nod1", "start")).unwrap(), 2.2));
    assert!(close(board.time_of(&addr("g1", "start")).unwrap(), 2.6));
    assert!(invalid(&board, &plan).is_empty());
    // a large one puts the nod's start after its end: the behaviour is reported invalid
    board.move_to(beat, 3.0).unwrap();
    assert_eq!(invalid(&board, &plan), ["nod1"]);
}

#[test]
fn after_constraints_become_order_links_that_push() {
    let src = r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="bml1">
        <gesture id="g1" lexeme="BEAT" start="1"/><speech id="s1"><text>Hi there</text></speech>
        <constraint><after ref="g1:end"><sync ref="s1:start"/></after></constraint></bml>"#;
    let (mut board, mut ants) = (PegBoard::new(), Anticipators::default());
    let plan = planned(src, &mut board, &mut ants, 0.0);
    let g_end = board.peg_of(&addr("g1", "end")).unwrap();
    let s_end = board.time_of(&addr("s1", "end")).unwrap();
    board.move_to(g_end, 2.5).unwrap();
    assert!(
        close(board.time_of(&addr("s1", "start")).unwrap(), 2.5),
        "pushed by the after link"
    );
    assert!(
        close(board.time_of(&addr("s1", "end")).unwrap(), s_end + 0.5),
        "the speech moves whole"
    );
    assert!(invalid(&board, &plan).is_empty());
}

#[test]
fn cluster_constraint_violations_after_moves_are_tolerated() {
    // the gesture's cluster starts at block start; after the anticipator moves the speech later,
    // the gesture no longer starts "as early as possible", which is accepted, not reported
    let src = r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="bml1">
        <speech id="s1" start="anticipators:turn:t"><text>Go <sync id="w"/>now</text></speech>
        <gesture id="g1" lexeme="BEAT" stroke="s1:w"/></bml>"#;
    let (mut board, mut ants) = (PegBoard::new(), Anticipators::default());
    let turn = ants.peg(&mut board, "turn", "t", 0.0);
    let plan = planned(src, &mut board, &mut ants, 0.0);
    board.move_to(turn, 4.0).unwrap();
    assert!(close(plan.time(&board, "g1", "stroke").unwrap(), 4.2));
    assert!(invalid(&board, &plan).is_empty());
}
