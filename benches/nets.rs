//! The cost of PaT-Nets: 1 000 pedestrians, each with a net of three states waiting for the
//! light (a world variable), then for its walk's end (a sync guard) and for sight of a friend
//! (`all` of `sees`, `near` and `not`), beside one world light net; one step is one frame. It
//! must stay under 1 ms a frame.

use std::collections::BTreeMap;
use std::hint::black_box;

use bml_realizer::world::nets::{file, Nets, Senses};
use criterion::{criterion_group, criterion_main, Criterion};

/// A world where nobody sees anyone, everyone is 5 m from everything and nothing was reached.
struct Quiet;

impl Senses for Quiet {
    fn sees(&self, _: &str, _: &str) -> bool {
        false
    }
    fn distance(&self, _: &str, _: &str) -> Option<f32> {
        Some(5.0)
    }
    fn reached(&self, _: Option<&str>, _: &str) -> bool {
        false
    }
}

fn nets_file(n: usize) -> String {
    let mut nets = serde_json::Map::new();
    nets.insert(
        "light".into(),
        serde_json::json!({"states": ["DONT_WALK", "WALK"], "transitions": [
            {"from": "DONT_WALK", "to": "WALK", "when": {"after": 30}, "do": [{"set": ["light", "WALK"]}]},
            {"from": "WALK", "to": "DONT_WALK", "when": {"after": 30}, "do": [{"set": ["light", "DONT_WALK"]}]}]}),
    );
    for k in 0..n {
        let me = format!("p{k:04}");
        let friend = format!("p{:04}", (k + 1) % n);
        nets.insert(
            me.clone(),
            serde_json::json!({"character": me, "states": ["curb", "crossing", "across"], "transitions": [
                {"from": "curb", "to": "crossing", "when": {"all": [{"var": ["light", "WALK"]}, {"not": {"sees": friend}}]}},
                {"from": "curb", "to": "across", "when": {"all": [{"sees": friend}, {"near": [friend, 1.0]}]}},
                {"from": "crossing", "to": "across", "when": {"any": [{"sync": "cross:end"}, {"after": 60}]}}]}),
        );
    }
    serde_json::json!({ "nets": nets }).to_string()
}

fn step(c: &mut Criterion) {
    let text = nets_file(1000);
    let list = file::read(&text, &Default::default()).unwrap();
    let mut vars = BTreeMap::new();
    vars.insert(
        "light".to_string(),
        bml_realizer::language::feedback::world::VarValue::Text("DONT_WALK".into()),
    );
    let mut nets = Nets::new(list, vars);
    // (the first step starts them; each pedestrian then tries both transitions of its curb
    // every frame: the light is red, nobody sees anyone)
    nets.step(0.0, &Quiet);
    c.bench_function("nets: 1000 pedestrians waiting + a light, one frame", |b| {
        b.iter(|| black_box(nets.step(1.0, &Quiet).feedback.len()))
    });
    assert_eq!(nets.state("p0000"), Some("curb"));
}

criterion_group!(benches, step);
criterion_main!(benches);
