//! Criterion bench `tick` of bmlr-c: what the C ABI adds to a tick, side by side in one run.
//! One character speaking with a beat, a wave, a nod and a gaze, ticked at 60 Hz: the library's
//! `Realizer::tick`, and `bmlr_tick` with the feedback polled after it (as a C host does), each
//! over the same two seconds of a fresh realizer. The target: the C tick under 1.05 × the Rust
//! one.
//!
//! Run: `cargo bench -p bmlr-c --bench tick`

use std::ffi::{c_char, CString};
use std::hint::black_box;
use std::ptr::{null, null_mut};
use std::time::{Duration, Instant};

use bml_realizer::realizer::Realizer;
use bmlr::*;
use criterion::{criterion_group, criterion_main, Criterion};

const BLOCK: &str = r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="b">
    <gesture id="beat" lexeme="BEAT" mode="RIGHT_HAND" start="0" end="100000"/>
    <gesture id="wave" lexeme="WAVE" mode="LEFT_HAND" start="0" end="100000"/>
    <head id="nod" lexeme="NOD" start="0" end="100000"/>
    <gaze id="look" target="user" start="0" end="100000"/>
    <speech id="s"><text>WORDS</text></speech></bml>"#;

fn block() -> String {
    BLOCK.replace("WORDS", &"la ".repeat(2_000))
}

/// Ticks per measured run: two seconds at 60 Hz, from one second in.
const TICKS: usize = 120;

fn at(k: usize) -> f64 {
    1.0 + k as f64 / 60.0
}

/// Both variants tick a fresh realizer over the same two seconds of the same block (made
/// outside the timing), so that they do the same work.
fn tick(c: &mut Criterion) {
    let mut g = c.benchmark_group("one character at 60 Hz");
    g.sample_size(30);
    g.bench_function("Rust: Realizer::tick", |b| {
        b.iter_custom(|iters| {
            let mut total = Duration::ZERO;
            for _ in 0..iters {
                let mut r = Realizer::new();
                r.perform_bml(&block()).unwrap();
                r.tick(0.0);
                let clock = Instant::now();
                for k in 0..TICKS {
                    black_box(r.tick(at(k)));
                }
                total += clock.elapsed();
            }
            total / TICKS as u32
        })
    });
    let text = CString::new(block()).unwrap();
    let mut buf = vec![0 as c_char; 1 << 16];
    g.bench_function("C: bmlr_tick + bmlr_next_feedback", |b| {
        b.iter_custom(|iters| {
            let mut total = Duration::ZERO;
            for _ in 0..iters {
                let mut h = null_mut();
                // SAFETY: valid arguments; the realizer is freed below
                unsafe {
                    assert_eq!(bmlr_new(null(), &mut h), bmlr_status::BMLR_OK);
                    assert_eq!(bmlr_perform(h, text.as_ptr()), bmlr_status::BMLR_OK);
                    bmlr_tick(h, 0.0);
                    let clock = Instant::now();
                    for k in 0..TICKS {
                        black_box(bmlr_tick(h, at(k)));
                        let mut len = 1;
                        while len > 0 {
                            bmlr_next_feedback(h, buf.as_mut_ptr(), buf.len(), &mut len);
                        }
                    }
                    total += clock.elapsed();
                    bmlr_free(h);
                }
            }
            total / TICKS as u32
        })
    });
    g.finish();
}

criterion_group!(benches, tick);
criterion_main!(benches);
