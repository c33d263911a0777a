//! Criterion bench `tick`: the per-frame cost of the runtime. 100 characters, each running one
//! block of 20 units (gestures, nods, gaze, a speech) that last long enough to stay active; each
//! iteration advances the clock by one 60 Hz frame.
//!
//! Run: `cargo bench --bench tick`

use std::hint::black_box;

use bml_realizer::realizer::Realizer;
use criterion::{criterion_group, criterion_main, Criterion};

fn block(character: usize) -> String {
    let mut body = String::new();
    for i in 0..16 {
        body.push_str(&format!(
            r#"<gesture id="g{i}" lexeme="BEAT" start="{}" end="100000"/>"#,
            i as f64 * 0.01
        ));
    }
    for i in 0..2 {
        body.push_str(&format!(
            r#"<head id="h{i}" lexeme="NOD" start="0" end="100000"/>"#
        ));
    }
    body.push_str(r#"<gaze id="look" target="user" start="0" end="100000"/>"#);
    let words = "la ".repeat(1000);
    body.push_str(&format!(r#"<speech id="s"><text>{words}</text></speech>"#));
    format!(
        r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="b" characterId="c{character}">{body}</bml>"#
    )
}

fn tick(c: &mut Criterion) {
    let mut r = Realizer::new();
    for ch in 0..100 {
        r.perform_bml(&block(ch)).unwrap();
    }
    let mut t = 0.5;
    r.tick(t);
    let active: usize = r.tick(t).outputs.len();
    assert_eq!(active, 100 * 20, "every unit is active");
    c.bench_function("tick/100-characters-x-20-units", |b| {
        b.iter(|| {
            t += 1.0 / 60.0;
            black_box(r.tick(t))
        })
    });
}

criterion_group!(benches, tick);
criterion_main!(benches);
