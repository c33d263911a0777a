//! The `SortedGreedy` baseline reproduces the thesis' account of Elckerlyc's scheduler: sorting fixes
//! Ex. 27b but not 28b or 29b (thesis §7.3.5); it rejects before/after. Side by side
//! with `Optimal`, which schedules all of them.

use bml_realizer::language::bml;
use bml_realizer::language::feedback::KnownWarning;
use bml_realizer::planning::schedule::{
    BlockSchedule, NoExternal, Optimal, SchedulingStrategy, SortedGreedy,
};
use bml_realizer::planning::timing::DefaultTimingModels;

fn run(strategy: &dyn SchedulingStrategy, file: &str) -> BlockSchedule {
    let src =
        std::fs::read_to_string(format!("{}/fixtures/{file}", env!("CARGO_MANIFEST_DIR"))).unwrap();
    let block = bml::load(&src).unwrap().block;
    strategy
        .schedule(&block, &DefaultTimingModels::default(), &NoExternal)
        .unwrap()
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() < 1e-6
}

#[test]
fn sorting_schedules_ex27b_like_ex27a() {
    let a = run(&SortedGreedy, "thesis/ex27a.xml");
    let b = run(&SortedGreedy, "thesis/ex27b.xml");
    assert!(
        a.dropped.is_empty() && b.dropped.is_empty(),
        "{:?} {:?}",
        a.dropped,
        b.dropped
    );
    for beh in &a.behaviours {
        assert_eq!(Some(beh), b.behaviour(&beh.id));
    }
    assert!(close(
        a.time("nod1", "start").unwrap(),
        a.time("speech1", "start").unwrap()
    ));
    assert!(close(
        a.time("nod1", "end").unwrap(),
        a.time("speech1", "sync1").unwrap()
    ));
}

#[test]
fn ex28a_schedules_but_ex28b_drops_the_nod() {
    let a = run(&SortedGreedy, "thesis/ex28a.xml");
    assert!(a.dropped.is_empty());
    assert!(
        close(a.time("nod1", "start").unwrap(), 3.0) && close(a.time("nod1", "end").unwrap(), 5.0)
    );
    assert!(close(
        a.time("beat1", "stroke").unwrap(),
        a.time("nod1", "stroke").unwrap()
    ));
    // Optimal gives the same answer here
    let o = run(&Optimal, "thesis/ex28a.xml");
    for beh in &a.behaviours {
        let other = o.behaviour(&beh.id).unwrap();
        for ((n, t), (m, u)) in beh.syncs.iter().zip(&other.syncs) {
            assert!(
                n == m && close(*t, *u),
                "{}:{n} greedy {t} optimal {u}",
                beh.id
            );
        }
    }
    let b = run(&SortedGreedy, "thesis/ex28b.xml");
    assert_eq!(b.dropped.len(), 1, "{:?}", b.behaviours);
    assert_eq!(b.dropped[0].behaviour, "nod1");
    assert_eq!(b.dropped[0].warning, KnownWarning::CannotSatisfyConstraints);
    assert!(run(&Optimal, "thesis/ex28b.xml").dropped.is_empty());
}

#[test]
fn ex29a_schedules_after_normalisation_but_ex29b_fails() {
    let a = run(&SortedGreedy, "thesis/ex29a.xml");
    assert!(a.dropped.is_empty(), "{:?}", a.dropped);
    // nod1 starts 2 s before g1 and ends 3 s after g2; the block was shifted so nod1 starts at 0
    assert!(close(a.time("nod1", "start").unwrap(), 0.0));
    assert!(close(a.time("g1", "start").unwrap(), 2.0));
    assert!(close(
        a.time("nod1", "end").unwrap(),
        a.time("g2", "end").unwrap() + 3.0
    ));
    let b = run(&SortedGreedy, "thesis/ex29b.xml");
    assert!(
        !b.dropped.is_empty(),
        "the nod scheduled first leaves g2 no valid timing"
    );
    assert!(run(&Optimal, "thesis/ex29b.xml").dropped.is_empty());
}

#[test]
fn before_and_after_are_rejected() {
    let src = r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="b"><gesture id="g" lexeme="BEAT"/>
        <constraint><after ref="2"><sync ref="g:start"/></after></constraint></bml>"#;
    let block = bml::load(src).unwrap().block;
    let e = SortedGreedy
        .schedule(&block, &DefaultTimingModels::default(), &NoExternal)
        .unwrap_err();
    assert!(e.reason.contains("only at-constraints"), "{}", e.reason);
    assert!(Optimal
        .schedule(&block, &DefaultTimingModels::default(), &NoExternal)
        .is_ok());
}

#[test]
fn realizertester_core_files_match_optimal_where_greedy_succeeds() {
    for file in [
        "core/testspeechgestures.xml",
        "core/testspeechandnod_synctimed.xml",
        "core/testnodlong.xml",
        "core/testspeech2.xml",
    ] {
        let path = format!("realizertester/bml-1/{file}");
        // synctimed uses <synchronize>: at-only, so greedy applies
        let g = run(&SortedGreedy, &path);
        let o = run(&Optimal, &path);
        assert!(g.dropped.is_empty(), "{file}: {:?}", g.dropped);
        for beh in &g.behaviours {
            let other = o.behaviour(&beh.id).unwrap();
            for ((n, t), (_, u)) in beh.syncs.iter().zip(&other.syncs) {
                assert!(
                    close(*t, *u),
                    "{file} {}:{n} greedy {t} optimal {u}",
                    beh.id
                );
            }
        }
    }
}
