//! Random trips for whole-body walkers, the scenes of the `crowd_random` example and of
//! `tests/crowd_press.rs`: N walkers start and end at random spots of a square (starts
//! [`APART`] from each other, goals too), each sent `<locomotion target="x,z"/>` at t = 0.
//! Needs the crate root to hold `mod lcg` (`common/lcg.rs`).

use bml_realizer::realizer::Realizer;
use bml_realizer::world::World;
use glam::Vec2;

use crate::lcg::Lcg;

/// How far apart starts (and goals) are at least (m).
pub const APART: f32 = 0.8;

/// How long a scene goes on after every walk has ended (s): one who stepped aside for a late
/// walker goes back to its place before the walkers are judged.
pub const SETTLE: f64 = 3.0;

/// Walker `k`'s id; its block is `b{k}`.
pub fn id(k: usize) -> String {
    format!("w{k:04}")
}

/// `n` spots in a square of `side` m centred on the origin, [`APART`] from each other.
fn spots(rng: &mut Lcg, n: usize, side: f32) -> Vec<Vec2> {
    let mut out: Vec<Vec2> = Vec::with_capacity(n);
    let mut tries = 0;
    while out.len() < n {
        tries += 1;
        assert!(
            tries < 1000 * n,
            "{n} spots {APART} m apart do not fit {side} m"
        );
        let p = Vec2::new(rng.unit() - 0.5, rng.unit() - 0.5) * side;
        if out.iter().all(|q| q.distance(p) >= APART) {
            out.push(p);
        }
    }
    out
}

/// A realizer with `n` walkers on random trips in a `side` m square (generator `seed`), every
/// walk sent; and the goals.
pub fn trips(n: usize, side: f32, seed: u64) -> (Realizer, Vec<Vec2>) {
    const NS: &str = r#"xmlns="http://www.bml-initiative.org/bml/bml-1.0""#;
    let mut rng = Lcg(seed);
    let starts = spots(&mut rng, n, side);
    let goals = spots(&mut rng, n, side);
    let chars: Vec<String> = (0..n)
        .map(|k| {
            let (s, g) = (starts[k], goals[k]);
            let facing = (g - s).x.atan2((g - s).y).to_degrees();
            format!(
                r#""{}": {{"position": [{}, 0, {}], "facing": {facing}}}"#,
                id(k),
                s.x,
                s.y
            )
        })
        .collect();
    let json = format!(r#"{{"characters": {{{}}}}}"#, chars.join(", "));
    let mut r = Realizer::new();
    *r.world_mut() = World::from_json(&json).expect("a world").0;
    for (k, g) in goals.iter().enumerate() {
        let bml = format!(
            r#"<bml {NS} id="b{k}" characterId="{}"><locomotion id="w" target="{},{}"/></bml>"#,
            id(k),
            g.x,
            g.y
        );
        r.perform_bml(&bml).expect("a block");
    }
    (r, goals)
}
