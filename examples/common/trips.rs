//! Trips for whole-body walkers, the scenes of the `crowd_random` example and of
//! `tests/crowd_press.rs`: N walkers start and end at random spots of a square (starts
//! [`APART`] from each other, goals too), or cross through a door or along a corridor
//! ([`passage`]), each sent `<locomotion target="x,z"/>` at t = 0.
//! Needs the crate root to hold `mod lcg` (`common/lcg.rs`).

use bml_realizer::realizer::Realizer;
use bml_realizer::world::World;
use glam::{Vec2, Vec3};

use crate::lcg::Lcg;

/// How far apart starts (and goals) are at least (m).
pub const APART: f32 = 0.8;

/// How long a scene goes on after every walk has ended (s): one who stepped aside for a late
/// walker goes back to its place before the walkers are judged.
pub const SETTLE: f64 = 3.0;

/// Who did not arrive: every walker whose `last` root is more than 0.3 m from its goal, or
/// whose walk has not `ended`, with how far off it stands (m).
#[allow(dead_code)] // (the tests'; the example says more of each)
pub fn stranded(last: &[Option<Vec3>], goals: &[Vec2], ended: &[bool]) -> Vec<String> {
    (0..goals.len())
        .filter_map(|k| {
            let off = last[k].map_or(f32::MAX, |p| Vec2::new(p.x, p.z).distance(goals[k]));
            (off > 0.3 || !ended[k]).then(|| format!("{} {off:.2} m off", id(k)))
        })
        .collect()
}

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
    let mut rng = Lcg(seed);
    let starts = spots(&mut rng, n, side);
    let goals = spots(&mut rng, n, side);
    (walking(&starts, &goals, &[]), goals)
}

/// A realizer with walkers `w0000`, `w0001`, … standing at `starts`, facing their `goals`,
/// among `walls` (segments [x1, z1, x2, z2]), each sent `<locomotion target="x,z"/>`.
pub fn walking(starts: &[Vec2], goals: &[Vec2], walls: &[[f32; 4]]) -> Realizer {
    const NS: &str = r#"xmlns="http://www.bml-initiative.org/bml/bml-1.0""#;
    let chars: Vec<String> = (starts.iter().zip(goals).enumerate())
        .map(|(k, (&s, &g))| {
            let facing = (g - s).x.atan2((g - s).y).to_degrees();
            format!(
                r#""{}": {{"position": [{}, 0, {}], "facing": {facing}}}"#,
                id(k),
                s.x,
                s.y
            )
        })
        .collect();
    let walls: Vec<String> = (walls.iter())
        .map(|[a, b, c, d]| format!(r#"{{"segment": [{a}, {b}, {c}, {d}]}}"#))
        .collect();
    let json = format!(
        r#"{{"characters": {{{}}}, "obstacles": [{}]}}"#,
        chars.join(", "),
        walls.join(", ")
    );
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
    r
}

/// A scene of walls and walkers crossing.
#[allow(dead_code)] // (the example's; the proptest's scenes are random squares)
pub struct Passage {
    /// Where the walkers start.
    pub starts: Vec<Vec2>,
    /// Where they go.
    pub goals: Vec<Vec2>,
    /// The walls: segments [x1, z1, x2, z2].
    pub walls: Vec<[f32; 4]>,
}

/// A passage scene: `door`, a 0.9 m door in a wall with 30 walkers on each side crossing
/// (`door10`: 10 a side); `corridor15`, 15 walking each way through a 4 m corridor;
/// `corridor`, a 4 m wide corridor with 100 walking each way. `None` for another name.
#[allow(dead_code)] // (the example's; the proptest's scenes are random squares)
pub fn passage(name: &str) -> Option<Passage> {
    match name {
        // the wall along x = 0, its door from z = -0.45 to 0.45; each crosses to 4 m beyond
        // where the other side started
        "door" => Some(crossing(
            (-5.2, 2.0, 5),
            (-2.0, 6),
            11.2,
            vec![[0.0, -12.0, 0.0, -0.45], [0.0, 0.45, 0.0, 12.0]],
        )),
        // the same door, 10 a side (the press test's)
        "door10" => Some(crossing(
            (-2.8, 2.0, 2),
            (-1.6, 5),
            9.6,
            vec![[0.0, -12.0, 0.0, -0.45], [0.0, 0.45, 0.0, 12.0]],
        )),
        // a shorter corridor, 15 each way (the press test's)
        "corridor15" => Some(crossing(
            (-10.4, 8.8, 3),
            (-1.6, 5),
            20.8,
            vec![[-20.0, -2.0, 20.0, -2.0], [-20.0, 2.0, 20.0, 2.0]],
        )),
        // each side ends where the other started
        "corridor" => Some(crossing(
            (-36.0, 20.8, 20),
            (-1.6, 5),
            56.8,
            vec![[-45.0, -2.0, 45.0, -2.0], [-45.0, 2.0, 45.0, 2.0]],
        )),
        _ => None,
    }
}

/// Two groups crossing along x among `walls`: grids of `cols` × `rows` places [`APART`] apart,
/// the west one from x = `west`, the east one from x = `east`, both from z = `z0`; each walker
/// goes `shift` m east (west group) or west (east group).
#[allow(dead_code)] // (the example's and the door test's; the proptest's scenes are random squares)
fn crossing(
    (west, east, cols): (f32, f32, usize),
    (z0, rows): (f32, usize),
    shift: f32,
    walls: Vec<[f32; 4]>,
) -> Passage {
    let grid = |x0: f32| {
        (0..cols).flat_map(move |i| {
            (0..rows).map(move |j| Vec2::new(x0 + APART * i as f32, z0 + APART * j as f32))
        })
    };
    let starts: Vec<Vec2> = grid(west).chain(grid(east)).collect();
    let goals = (grid(west).map(|p| p + Vec2::X * shift))
        .chain(grid(east).map(|p| p - Vec2::X * shift))
        .collect();
    Passage {
        starts,
        goals,
        walls,
    }
}
