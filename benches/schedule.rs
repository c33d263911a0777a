//! Criterion bench `schedule`: the difference-constraint solver under the scheduler on chained
//! behaviours — N behaviours with 7 ordered sync points each, every behaviour's start tied to the
//! previous one's end (the shape of a long appended speech/gesture sequence).
//!
//! Run: `cargo bench --bench schedule`

mod common;

use std::hint::black_box;

use bml_realizer::language::bml;
use bml_realizer::planning::schedule::diff::DiffSystem;
use bml_realizer::planning::schedule::{NoExternal, Optimal, SchedulingStrategy, SortedGreedy};
use bml_realizer::planning::timing::DefaultTimingModels;
use criterion::{criterion_group, criterion_main, BatchSize, BenchmarkId, Criterion};

fn chain(n: usize) -> DiffSystem {
    let mut s = DiffSystem::new();
    let block = s.var(0.0);
    let mut prev_end = block;
    for b in 0..n {
        let keys: Vec<usize> = (0..7).map(|_| s.var(0.0)).collect();
        for k in 1..7 {
            s.at_least(keys[k], keys[k - 1], 0.1, b); // sync order with a minimum phase length
        }
        s.at_least(keys[0], block, 0.0, b); // not before block start
        s.equal(keys[0], prev_end, 0.0, b); // start = previous end
        prev_end = keys[6];
    }
    s
}

fn solve(c: &mut Criterion) {
    let mut g = c.benchmark_group("schedule/diff-chain");
    for n in [10usize, 100, 1000, 10_000] {
        let system = chain(n);
        g.bench_with_input(BenchmarkId::from_parameter(n), &system, |b, s| {
            b.iter(|| black_box(s.solve().unwrap()))
        });
    }
    g.finish();
}

fn optimal(c: &mut Criterion) {
    let mut g = c.benchmark_group("schedule/optimal");
    let models = DefaultTimingModels::default();
    for (name, text) in [
        // needs stretching: the LP path
        (
            "testspeechgestures",
            include_str!("../fixtures/realizertester/bml-1/core/testspeechgestures.xml"),
        ),
        // preferred timing fits: the fast path
        (
            "testspeechandnod_synctimed",
            include_str!("../fixtures/realizertester/bml-1/core/testspeechandnod_synctimed.xml"),
        ),
        (
            "testnodlong",
            include_str!("../fixtures/realizertester/bml-1/core/testnodlong.xml"),
        ),
    ] {
        let block = bml::load(text).unwrap().block;
        g.bench_function(format!("{name}/schedule"), |b| {
            b.iter(|| {
                black_box(
                    Optimal
                        .schedule(black_box(&block), &models, &NoExternal)
                        .unwrap(),
                )
            })
        });
        g.bench_function(format!("{name}/schedule-sorted-greedy"), |b| {
            b.iter(|| {
                black_box(
                    SortedGreedy
                        .schedule(black_box(&block), &models, &NoExternal)
                        .unwrap(),
                )
            })
        });
        g.bench_function(format!("{name}/parse+schedule"), |b| {
            b.iter(|| {
                let block = bml::load(black_box(text)).unwrap().block;
                black_box(Optimal.schedule(&block, &models, &NoExternal).unwrap())
            })
        });
    }
    g.finish();
}

fn anticipator_move(c: &mut Criterion) {
    use bml_realizer::planning::plan::pegs::PegBoard;
    use bml_realizer::planning::plan::to_pegs::{invalid, plan_block, Anticipators, BoardTimes};
    let src = r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="bml1">
        <head id="nod1" lexeme="NOD" start="anticipators:beat:b1"/>
        <gesture id="g1" lexeme="BEAT" stroke="anticipators:beat:b1+0.5"/>
        <speech id="s1" start="nod1:end"><text>Right on the beat.</text></speech></bml>"#;
    let block = bml::load(src).unwrap().block;
    let (mut board, mut ants) = (PegBoard::new(), Anticipators::default());
    let beat = ants.peg(&mut board, "beat", "b1", 2.0);
    let schedule = {
        let times = BoardTimes {
            board: &board,
            anticipators: &ants,
            block_start: 0.0,
        };
        Optimal
            .schedule(&block, &DefaultTimingModels::default(), &times)
            .unwrap()
    };
    let plan = plan_block(&mut board, &mut ants, &block, &schedule, 0.0);
    let mut t = 2.0;
    c.bench_function("schedule/anticipator-move+revalidate", |b| {
        b.iter(|| {
            t = if t > 2.05 { 2.0 } else { t + 0.001 };
            board.move_to(beat, t).unwrap();
            black_box(invalid(&board, &plan))
        })
    });
}

/// N blocks sent at once, each tied to the one before by an external reference (its speech
/// starts when the previous block's speech ends, a beat gesture on its end): parse + schedule +
/// plan of every block through the runtime, the shape of AsapRealizer's chained-block bench.
fn chained_blocks(c: &mut Criterion) {
    use bml_realizer::realizer::Realizer;
    let mut g = c.benchmark_group("schedule/chained-blocks");
    g.sample_size(10);
    for n in [10usize, 100, 1000, 10_000] {
        let blocks = common::chain_texts(n);
        // a fresh realizer per iteration (built outside the timing: it loads the skeleton and
        // the gesture lexicon); dropping it afterwards is not timed either
        g.bench_function(BenchmarkId::from_parameter(n), |b| {
            b.iter_batched(
                Realizer::new,
                |mut r| {
                    for text in &blocks {
                        r.perform_bml(text).unwrap();
                    }
                    r
                },
                BatchSize::PerIteration,
            )
        });
    }
    g.finish();
}

/// The same chain through the scheduler core alone, the scope of AsapRealizer's number: parse
/// and `Optimal` schedule of each block with the default timing models, the previous blocks'
/// times known to the next (all blocks at start 0, so block-local times are global). No block
/// lifecycle, engines or feedback.
fn chained_core(c: &mut Criterion) {
    use bml_realizer::language::bml::SyncPoint;
    use bml_realizer::planning::schedule::{BlockSchedule, ExternalTimes};
    use std::collections::HashMap;

    /// The schedules so far, by block id.
    struct Known(HashMap<bml::Id, BlockSchedule>);
    impl ExternalTimes for Known {
        fn time(&self, point: &SyncPoint) -> Option<f64> {
            let SyncPoint::External {
                block,
                behaviour,
                sync,
            } = point
            else {
                return None;
            };
            let schedule = self.0.get(block)?;
            schedule
                .behaviours
                .iter()
                .find(|b| b.id == *behaviour)?
                .time(sync)
        }
    }

    let models = DefaultTimingModels::default();
    let mut g = c.benchmark_group("schedule/chained-core");
    g.sample_size(10);
    for n in [10usize, 100, 1000, 10_000] {
        let blocks = common::chain_texts(n);
        let run = |mut known: Known| {
            for text in &blocks {
                let block = bml::load(text).unwrap().block;
                let schedule = Optimal.schedule(&block, &models, &known).unwrap();
                known.0.insert(block.id, schedule);
            }
            known
        };
        // each block really follows the one before (a missed reference would drop its speech)
        let known = run(Known(HashMap::new()));
        let last = &known.0[format!("b{}", n - 1).as_str()];
        assert_eq!(last.behaviours.len(), 2);
        assert!(last.behaviours.iter().all(|b| b.syncs[0].1 > 0.0));
        g.bench_function(BenchmarkId::from_parameter(n), |b| {
            b.iter_batched(
                || Known(HashMap::with_capacity(n)),
                run,
                BatchSize::PerIteration,
            )
        });
    }
    g.finish();
}

/// Twenty small blocks (testspeechgestures) submitted to a realizer that is empty, and to one
/// that already runs a large block of 1000 behaviours: the second should cost the same.
fn after_large_block(c: &mut Criterion) {
    use bml_realizer::realizer::Realizer;
    // 20 small blocks per iteration (a one-off cost, such as an engine's unit list growing,
    // is shared by them as it is in a real stream)
    let smalls: Vec<String> = (0..20)
        .map(|i| {
            include_str!("../fixtures/realizertester/bml-1/core/testspeechgestures.xml")
                .replace(r#"id="bml1""#, &format!(r#"id="small{i}""#))
        })
        .collect();
    let mut body = String::new();
    for i in 0..1000 {
        body.push_str(&format!(
            r#"<gesture id="g{i}" lexeme="BEAT" start="{}"/>"#,
            f64::from(i) * 0.5
        ));
    }
    let large = format!(
        r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="large">{body}</bml>"#
    );
    let warm = r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="warm"><wait id="w" start="0" end="0.5"/></bml>"#.to_string();
    let mut g = c.benchmark_group("schedule/small-block");
    for (name, with_large) in [
        ("into-an-empty-realizer", false),
        ("after-a-1000-behaviour-block", true),
    ] {
        g.bench_function(name, |b| {
            b.iter_batched(
                || {
                    let mut r = Realizer::new();
                    // the character's block manager exists in both cases
                    r.perform_bml(if with_large { &large } else { &warm })
                        .unwrap();
                    r.tick(1.0);
                    r
                },
                |mut r| {
                    for text in &smalls {
                        r.perform_bml(black_box(text)).unwrap();
                    }
                    r
                },
                BatchSize::PerIteration,
            )
        });
    }
    g.finish();
}

/// Every RealizerTester core file (the issue's per-file bar: AsapRealizer's scheduler core
/// took 21–40 µs for each single-behaviour file): parse + `Optimal` schedule with the default
/// timing models, file by file (the valid blocks among them).
fn core_files(c: &mut Criterion) {
    let models = DefaultTimingModels::default();
    let mut g = c.benchmark_group("schedule/core-file");
    g.warm_up_time(std::time::Duration::from_millis(300));
    g.measurement_time(std::time::Duration::from_secs(1));
    for (name, text) in common::core_files() {
        g.bench_function(name, |b| {
            b.iter(|| {
                let block = bml::load(black_box(&text)).unwrap().block;
                black_box(Optimal.schedule(&block, &models, &NoExternal).unwrap())
            })
        });
    }
    g.finish();
}

criterion_group!(
    benches,
    solve,
    optimal,
    core_files,
    anticipator_move,
    chained_blocks,
    chained_core,
    after_large_block
);
criterion_main!(benches);
