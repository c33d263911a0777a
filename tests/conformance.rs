//! The RealizerTester conformance suite (`realizer-tests`), all 41 tests, in process on the virtual
//! clock; and the same suite against a deliberately broken realizer, to show that it catches
//! timing regressions.

use bml_realizer::ports::conformance::InProcess;
use realizer_tests::{run, TESTS};

#[test]
fn all_41_conformance_tests_pass() {
    let mut port = InProcess::new();
    let outcomes = run(&mut port, "", |_, _, _| {});
    assert_eq!(outcomes.len(), TESTS.len());
    let failed: Vec<String> = outcomes
        .iter()
        .filter_map(|o| o.failure.as_ref().map(|f| format!("{}: {f}", o.name)))
        .collect();
    assert!(
        failed.is_empty(),
        "{} failed:\n{}",
        failed.len(),
        failed.join("\n\n")
    );
}

#[test]
fn a_realizer_that_reports_block_ends_late_fails_the_timing_tests() {
    let mut port = InProcess::new().with_late_block_ends(0.2);
    let outcomes = run(&mut port, "", |_, _, _| {});
    let failed: Vec<&str> = outcomes
        .iter()
        .filter(|o| o.failure.is_some())
        .map(|o| o.name)
        .collect();
    // the tests that tie a block's start to another block's end
    for name in ["testAppend", "testInterrupt"] {
        assert!(failed.contains(&name), "{name} should fail: {failed:?}");
    }
    let append = outcomes.iter().find(|o| o.name == "testAppend").unwrap();
    assert!(
        append
            .failure
            .as_deref()
            .unwrap()
            .contains("bml2 starts at"),
        "{:?}",
        append.failure
    );
}
