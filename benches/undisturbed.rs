//! Bench `undisturbed`: the cost of scheduling when nothing else on the machine interferes. The
//! shared VM this project is measured on changes speed by 20–30 % within minutes, and criterion's
//! medians take that in; this bench reports the **minimum** over many short batches instead (a
//! batch that ran undisturbed), which repeats within a few per cent. It complements the criterion
//! benches in `schedule.rs`, which stay the reference for typical times.
//!
//! Measured, one line each: parse + `Optimal` of every RealizerTester core file (per iteration,
//! the best of 100 batches of 2000, the files taking turns), and N chained blocks through the
//! whole runtime as in
//! `schedule/chained-blocks` (per run, the best of 200 runs at N = 1000 and of 20 at N = 10 000;
//! building and dropping the realizer are not timed), with the allocator's default settings (what a
//! host gets).
//!
//! Run: `cargo bench --bench undisturbed` (an argument filters by name).

mod common;

use std::hint::black_box;
use std::time::{Duration, Instant};

use bml_realizer::language::bml;
use bml_realizer::planning::schedule::{NoExternal, Optimal, SchedulingStrategy};
use bml_realizer::planning::timing::DefaultTimingModels;
use bml_realizer::realizer::Realizer;

/// The shortest of `batches` timings of `run`.
fn best(batches: usize, mut run: impl FnMut() -> Duration) -> Duration {
    (0..batches).map(|_| run()).min().unwrap_or_default()
}

fn main() {
    // `cargo bench` passes `--bench`; any other argument filters the lines by name
    let filter: Option<String> = std::env::args().skip(1).find(|a| !a.starts_with("--"));
    let wanted = |name: &str| filter.as_deref().is_none_or(|f| name.contains(f));

    let models = DefaultTimingModels::default();
    let mut core: Vec<(String, String, Duration)> = common::core_files()
        .into_iter()
        .map(|(stem, text)| (format!("core-file/{stem}"), text, Duration::MAX))
        .filter(|(name, _, _)| wanted(name))
        .collect();
    // the files take turns, five rounds of 20 batches each: a slow spell of the machine (it can
    // last seconds) then costs a file some of its batches, not all of them
    const ITERATIONS: u32 = 2000;
    for _round in 0..5 {
        for (_, text, fastest) in &mut core {
            let t = best(20, || {
                let start = Instant::now();
                for _ in 0..ITERATIONS {
                    let block = bml::load(black_box(text.as_str()))
                        .expect("core_files keeps valid blocks only")
                        .block;
                    black_box(
                        Optimal
                            .schedule(&block, &models, &NoExternal)
                            .expect("schedulable"),
                    );
                }
                start.elapsed()
            });
            *fastest = (*fastest).min(t);
        }
    }
    for (name, _, fastest) in &core {
        let t = *fastest / ITERATIONS;
        println!("{name:<48} {:>9.3} µs", t.as_secs_f64() * 1e6);
    }

    for (n, runs) in [(1000usize, 200usize), (10_000, 20)] {
        let name = format!("chained-blocks/{n}");
        if !wanted(&name) {
            continue;
        }
        let blocks = common::chain_texts(n);
        let t = best(runs, || {
            let mut r = Realizer::new();
            let start = Instant::now();
            for text in &blocks {
                r.perform_bml(text).expect("a valid block");
            }
            let took = start.elapsed();
            drop(black_box(r));
            took
        });
        println!("{name:<48} {:>9.3} ms", t.as_secs_f64() * 1e3);
    }
}
