//! Criterion bench `parse`: parsing + validation + constraint extraction of RealizerTester's
//! core/testspeechgestures.xml (the reference input), and the pieces separately.
//!
//! Run: `cargo bench --bench parse`

use bml_realizer::language::bml;
use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};

const FILE: &str = include_str!("../fixtures/realizertester/bml-1/core/testspeechgestures.xml");

fn parse(c: &mut Criterion) {
    let mut g = c.benchmark_group("parse");
    g.bench_function("testspeechgestures/parse+validate+extract", |b| {
        b.iter(|| {
            let parsed = bml::load(black_box(FILE)).unwrap();
            black_box(bml::extract(&parsed.block))
        })
    });
    g.bench_function("testspeechgestures/parse", |b| {
        b.iter(|| black_box(bml::parse(black_box(FILE)).unwrap()))
    });
    let block = bml::load(FILE).unwrap().block;
    g.bench_function("testspeechgestures/extract", |b| {
        b.iter(|| black_box(bml::extract(black_box(&block))))
    });
    g.bench_function("testspeechgestures/write", |b| {
        b.iter(|| black_box(bml::write(black_box(&block))))
    });
    g.finish();
}

criterion_group!(benches, parse);
criterion_main!(benches);
