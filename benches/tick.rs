//! Criterion bench `tick`: the per-frame cost of the runtime. 100 characters, each running one
//! block of 20 units (gestures, nods, gaze, a speech) that last long enough to stay active; and
//! one or 100 characters each running 10 units of every motion engine (keyed and procedural
//! gestures, a procanimation with IK, a keyframe, a nod, a gaze, noise, a posture with a pose, a
//! speech); and 100 characters each with 20 units of which half move the face (face lexemes,
//! FACS units, a faceShift) and a speech moves the lips. Each iteration advances the clock by one
//! 60 Hz frame.
//!
//! Run: `cargo bench --bench tick`

use std::hint::black_box;

use bml_realizer::language::feedback::Feedback;
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

/// Ten units of every motion engine, all lasting past the end of the bench.
fn mixed(character: usize) -> String {
    let body = r#"
        <gesture id="g1" lexeme="BEAT" start="0" end="1000000"/>
        <gesture id="g2" lexeme="WAVE" mode="LEFT_HAND" start="0" end="1000000"/>
        <bmlt:procanimation id="p" name="sway" start="0" end="1000000"/>
        <bmlt:keyframe id="kf" start="0" end="1000000"><SkeletonInterpolator rotationEncoding="quaternions" parts="l_elbow vt12" encoding="R">
            0 1 0 0 0 1 0 0 0
            1 0.9239 0 0.3827 0 0.9962 0.0872 0 0
        </SkeletonInterpolator></bmlt:keyframe>
        <head id="h" lexeme="NOD" start="0" end="1000000"/>
        <gaze id="look" target="user" start="0" end="1000000"/>
        <pointing id="pt" target="bluebox" mode="RIGHT_HAND" start="0" end="1000000"/>
        <bmlt:noise id="n" type="perlin" joint="skullbase" start="0" end="1000000"/>
        <posture id="po" start="0" end="1000000"><stance type="STANDING"/><pose part="ARMS" lexeme="AKIMBO"/><pose part="LEGS" lexeme="SPREAD"/></posture>"#;
    let words = "la ".repeat(100_000);
    format!(
        r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" xmlns:bmlt="http://hmi.ewi.utwente.nl/bmlt" id="b" characterId="c{character}">{body}<speech id="s"><text>{words}</text></speech></bml>"#
    )
}

fn tick_mixed(c: &mut Criterion) {
    for n in [1usize, 100] {
        let mut r = Realizer::new();
        for ch in 0..n {
            r.perform_bml(&mixed(ch)).unwrap();
        }
        let mut t = 1.0;
        let first = r.tick(t);
        let warnings: Vec<String> = first
            .feedback
            .iter()
            .filter(|f| matches!(f, Feedback::Warning(_)))
            .map(|f| format!("{f:?}"))
            .collect();
        assert!(warnings.is_empty(), "{warnings:?}");
        let active: usize = r.tick(t).outputs.len();
        assert_eq!(active, n * 10, "every unit is active");
        c.bench_function(&format!("tick/{n}-characters-x-10-mixed-units"), |b| {
            b.iter(|| {
                t += 1.0 / 60.0;
                black_box(r.tick(t))
            })
        });
    }
}

/// A frame with many live blocks whose behaviours lie in the future (N chained blocks, each
/// speech starting when the previous one ends): the frame's cost should not grow with N.
fn tick_many_live_blocks(c: &mut Criterion) {
    for n in [10usize, 1000] {
        let mut r = Realizer::new();
        for i in 0..n {
            let start = if i == 0 {
                String::new()
            } else {
                format!(r#" start="b{}:s:end""#, i - 1)
            };
            // the first speech lasts long enough for the whole bench (20 000 s)
            let words = if i == 0 {
                "la ".repeat(100_000)
            } else {
                "One two three.".to_string()
            };
            r.perform_bml(&format!(
                r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="b{i}"><speech id="s"{start}><text>{words}</text></speech><gesture id="g" lexeme="BEAT" stroke="s:end"/></bml>"#
            ))
            .unwrap();
        }
        let mut t = 0.0;
        r.tick(t);
        c.bench_function(&format!("tick/{n}-live-chained-blocks"), |b| {
            b.iter(|| {
                // frames inside the first speech: no block starts or ends
                t += 1.0 / 60.0;
                black_box(r.tick(t))
            })
        });
    }
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

/// 20 units per character, half of them on the face, and a speech whose lips move.
fn face_block(character: usize) -> String {
    let mut body = String::new();
    for i in 0..8 {
        body.push_str(&format!(
            r#"<gesture id="g{i}" lexeme="BEAT" start="{}" end="100000"/>"#,
            i as f64 * 0.01
        ));
    }
    body.push_str(r#"<head id="h" lexeme="NOD" start="0" end="100000"/>"#);
    for (i, l) in [
        "RAISE_BROWS",
        "SMILE",
        "WIDEN_EYES",
        "LOWER_LEFT_BROW",
        "OPEN_LIPS",
        "RAISE_LEFT_MOUTH_CORNER",
    ]
    .iter()
    .enumerate()
    {
        body.push_str(&format!(
            r#"<faceLexeme id="f{i}" lexeme="{l}" amount="0.5" start="0" end="100000"/>"#
        ));
    }
    for (i, au) in [9, 14].iter().enumerate() {
        body.push_str(&format!(
            r#"<faceFacs id="a{i}" au="{au}" side="LEFT" start="0" end="100000"/>"#
        ));
    }
    body.push_str(
        r#"<faceShift id="fs" lexeme="RAISE_MOUTH_CORNERS" amount="0.3" start="0" end="0.2"/>"#,
    );
    body.push_str(r#"<gaze id="look" target="user" start="0" end="100000"/>"#);
    let words = "papa bought the map and made my bomb ".repeat(200);
    body.push_str(&format!(r#"<speech id="s"><text>{words}</text></speech>"#));
    format!(
        r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="b" characterId="c{character}">{body}</bml>"#
    )
}

fn tick_face(c: &mut Criterion) {
    let mut r = Realizer::new();
    for ch in 0..100 {
        r.perform_bml(&face_block(ch)).unwrap();
    }
    let mut t = 0.5;
    r.tick(t);
    let frame = r.tick(t);
    assert_eq!(
        frame.outputs.len(),
        100 * 19,
        "every unit is active (the faceShift has ended)"
    );
    assert!(
        frame.poses.iter().all(|p| p.face.viseme.is_some()),
        "the lips move"
    );
    c.bench_function("tick/100-characters-x-20-units-face-and-lips", |b| {
        b.iter(|| {
            t += 1.0 / 60.0;
            black_box(r.tick(t))
        })
    });
}

criterion_group!(benches, tick, tick_mixed, tick_many_live_blocks, tick_face);
criterion_main!(benches);
