//! Criterion bench `runtime`: one large block run end to end on the virtual clock, the way
//! `bmlr run` does (a tick at every event until nothing more will happen). `chain/N` is a chain
//! of N gestures, each starting at the previous one's end: N behaviours, 7 N sync points.
//!
//! Run: `cargo bench --bench runtime`

use std::hint::black_box;

use bml_realizer::realizer::Realizer;
use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion};

fn chain(n: usize) -> String {
    let mut body = String::with_capacity(n * 64);
    for i in 0..n {
        let start = if i == 0 {
            String::new()
        } else {
            format!(r#" start="g{}:end""#, i - 1)
        };
        body.push_str(&format!(r#"<gesture id="g{i}" lexeme="BEAT"{start}/>"#));
    }
    format!(r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="chain">{body}</bml>"#)
}

/// Submits `text` and ticks from event to event until nothing more will happen; the number of
/// feedback messages.
fn run(text: &str) -> usize {
    let mut r = Realizer::new();
    r.perform_bml(text).expect("a valid block");
    let mut messages = r.tick(0.0).feedback.len();
    while let Some(t) = r.next_event() {
        messages += r.tick(t).feedback.len();
    }
    messages
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("runtime");
    g.sample_size(10);
    for n in [1_000, 10_000] {
        let text = chain(n);
        g.bench_with_input(BenchmarkId::new("chain", n), &text, |b, text| {
            b.iter(|| black_box(run(text)))
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
