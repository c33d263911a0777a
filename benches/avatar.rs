//! Criterion bench `avatar`: what showing a character on an avatar costs beside its tick, in one
//! run. One character speaking with a beat, a wave, a nod and a gaze at 60 Hz: the realizer's
//! tick, and the retargeting of the pose that tick made onto the default avatar (its skeleton is
//! the realizer's: each bone takes its joint's rotation) and onto a Mixamo one (every bone
//! aligned and turned) and onto CesiumMan (published, driven by a bone map) and the Cryptovoxels
//! VRM 0.x (published, its humanoid map, facing −z), as the glTF export
//! and the viewer use them. The target: retargeting costs under 10 % of the tick. Also the
//! loading of each avatar (read, skeleton recognised, rest poses aligned).
//!
//! Run: `cargo bench --bench avatar`

#[path = "../tests/common/avatars.rs"]
mod avatars;

use std::hint::black_box;

use bml_realizer::character::avatar::{default_model, Model, Retarget};
use bml_realizer::character::body::Skeleton;
use bml_realizer::realizer::Realizer;
use criterion::{criterion_group, criterion_main, Criterion};

const BLOCK: &str = r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="b">
    <gesture id="beat" lexeme="BEAT" mode="RIGHT_HAND" start="0" end="100000"/>
    <gesture id="wave" lexeme="WAVE" mode="LEFT_HAND" start="0" end="100000"/>
    <head id="nod" lexeme="NOD" start="0" end="100000"/>
    <gaze id="look" target="user" start="0" end="100000"/>
    <speech id="s"><text>WORDS</text></speech></bml>"#;

fn avatar(c: &mut Criterion) {
    let mut r = Realizer::new();
    r.perform_bml(&BLOCK.replace("WORDS", &"la ".repeat(100_000)))
        .unwrap();
    let mut t = 1.0;
    let frame = r.tick(t);
    let pose = frame.poses[0].pose.clone();
    let mut g = c.benchmark_group("one character at 60 Hz");
    g.bench_function("tick (speech, beat, wave, nod, gaze)", |b| {
        b.iter(|| {
            t += 1.0 / 60.0;
            black_box(r.tick(t))
        })
    });
    let model = default_model();
    let skeleton = Skeleton::adult();
    let retarget = Retarget::new(&model, &skeleton, None).unwrap();
    g.bench_function("retarget onto the default avatar", |b| {
        b.iter(|| black_box(retarget.pose(&pose)))
    });
    // a Mixamo T-pose in centimetres under a turned armature: every bone aligned and turned
    let mixamo = Model::from_glb("mixamo", &avatars::test_avatar(avatars::Kind::Mixamo)).unwrap();
    let retarget = Retarget::new(&mixamo, &skeleton, None).unwrap();
    g.bench_function("retarget onto a Mixamo avatar", |b| {
        b.iter(|| black_box(retarget.pose(&pose)))
    });
    // CesiumMan as published (unnamed joints, a bone map by index; 22 nodes)
    let cesium = Model::read(std::path::Path::new(CESIUM_MAN)).unwrap();
    let map = cesium_map();
    let retarget = Retarget::new(&cesium, &skeleton, Some(&map)).unwrap();
    g.bench_function("retarget onto CesiumMan", |b| {
        b.iter(|| black_box(retarget.pose(&pose)))
    });
    // the Cryptovoxels VRM 0.x as published (74 nodes, 57 joints, fingers)
    let vrm = Model::read(std::path::Path::new(CRYPTOVOXELS)).unwrap();
    let retarget = Retarget::new(&vrm, &skeleton, None).unwrap();
    g.bench_function("retarget onto the Cryptovoxels VRM 0.x", |b| {
        b.iter(|| black_box(retarget.pose(&pose)))
    });
    g.finish();
    // reading each avatar file and recognising its skeleton (what `--avatar` does once)
    let mut g = c.benchmark_group("loading an avatar");
    g.sample_size(20);
    g.bench_function("the default avatar (1.6 MB GLB, 52 face targets)", |b| {
        b.iter(|| {
            let m = default_model();
            black_box(Retarget::new(&m, &skeleton, None).unwrap())
        })
    });
    g.bench_function("CesiumMan (.gltf, .bin and texture beside it)", |b| {
        b.iter(|| {
            let m = Model::read(std::path::Path::new(CESIUM_MAN)).unwrap();
            black_box(Retarget::new(&m, &skeleton, Some(&map)).unwrap())
        })
    });
    g.bench_function("the Cryptovoxels VRM 0.x (238 kB)", |b| {
        b.iter(|| {
            let m = Model::read(std::path::Path::new(CRYPTOVOXELS)).unwrap();
            black_box(Retarget::new(&m, &skeleton, None).unwrap())
        })
    });
    g.bench_function("a Mixamo-named GLB (no mesh)", |b| {
        let bytes = avatars::test_avatar(avatars::Kind::Mixamo);
        b.iter(|| {
            let m = Model::from_glb("mixamo", &bytes).unwrap();
            black_box(Retarget::new(&m, &skeleton, None).unwrap())
        })
    });
    g.finish();
}

const CESIUM_MAN: &str = "fixtures/avatars/cesium-man/CesiumMan.gltf";
const CRYPTOVOXELS: &str = "fixtures/avatars/cryptovoxels/cryptovoxels.vrm";

/// CesiumMan's bone map (node indices), as `--bone-map` reads it.
fn cesium_map() -> std::collections::BTreeMap<String, String> {
    let text = std::fs::read_to_string("fixtures/avatars/cesium-man/bone-map.json").unwrap();
    bml_realizer::character::avatar::humanoid::bone_map_from_json(&text).unwrap()
}

criterion_group!(benches, avatar);
criterion_main!(benches);
