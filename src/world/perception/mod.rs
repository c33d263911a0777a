//! Synthetic vision with memory (after IViHumans, thesis §3.1.7): each character looks
//! periodically — at its own rate, from a random phase in [0, 1/rate) so that a crowd's looks
//! spread over the frames — by casting rays from its eyes along its gaze ([`rays`]). A thing is
//! seen when it is the first that at least one ray meets; obstacles (to their height) and other
//! characters' bodies hide what is behind them ([`scene`]). What a look sees replaces what the
//! one before saw, and goes into a bounded memory ([`memory`]). Sensing only reads the scene;
//! it changes nothing in it.

pub mod memory;
pub mod rays;
pub mod scene;

use std::collections::BTreeMap;

use serde::Deserialize;

use crate::language::feedback::world::{PerceptionFeedback, WorldFeedback};
pub use memory::{Memory, MemoryLimits, Remembered};
pub use rays::RaySet;
pub use scene::{Eyes, Scene, Sieve, Thing};

/// How characters see (all optional in the world file's `"vision"`).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, rename_all = "camelCase", default)]
pub struct Vision {
    /// Looks per second (Hz).
    pub rate: f64,
    /// The side of the ray matrix: `side × side` rays a look.
    pub side: usize,
    /// The field of view: horizontal and vertical (degrees).
    pub field: [f32; 2],
    /// How far a character sees (m).
    pub range: f32,
    /// What its memory keeps.
    pub memory: MemoryLimits,
    /// The seed of the phases and of the spirals' turns.
    pub seed: u64,
}

impl Default for Vision {
    fn default() -> Self {
        Vision {
            rate: 10.0,
            side: 24,
            field: [120.0, 90.0],
            range: 30.0,
            memory: MemoryLimits::default(),
            seed: 1,
        }
    }
}

impl Vision {
    /// Why these settings cannot be used, naming the field.
    pub fn check(&self) -> Result<(), String> {
        if !(self.rate > 0.0 && self.rate <= 120.0) {
            return Err(format!("vision.rate: {} is not in (0, 120] Hz", self.rate));
        }
        if !(1..=64).contains(&self.side) {
            return Err(format!("vision.side: {} is not in 1..=64", self.side));
        }
        for (k, f) in self.field.iter().enumerate() {
            if !(*f >= 1.0 && *f <= 170.0) {
                return Err(format!("vision.field[{k}]: {f} is not in [1, 170] degrees"));
            }
        }
        if !(self.range > 0.0 && self.range <= 1000.0) {
            return Err(format!(
                "vision.range: {} is not in (0, 1000] m",
                self.range
            ));
        }
        if let Some(ms) = self.memory.millis.filter(|m| !(*m >= 0.0 && m.is_finite())) {
            return Err(format!("vision.memory.millis: {ms} is not a duration"));
        }
        Ok(())
    }
}

/// One character's sight.
#[derive(Debug, Clone)]
struct Viewer {
    /// When it looks next.
    next: f64,
    /// Looks so far.
    passes: u64,
    /// The turn of its spiral (radians).
    turn: f32,
    /// What its last look saw, sorted.
    seen: Vec<String>,
    memory: Memory,
}

/// Every character's sight.
#[derive(Debug, Clone)]
pub struct Perception {
    vision: Vision,
    rays: RaySet,
    viewers: BTreeMap<String, Viewer>,
}

/// A number in [0, 1) from `id` and `seed` alone (FNV-1a, then the project's xorshift).
fn draw(id: &str, seed: u64, salt: u64) -> f32 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325 ^ seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) ^ salt;
    for b in id.bytes() {
        h = (h ^ b as u64).wrapping_mul(0x0100_0000_01b3);
    }
    let mut r = crate::rng::Rng(h);
    r.skip(2);
    r.next_f32()
}

impl Perception {
    /// Sight as `vision` says (checked by [`Vision::check`]).
    pub fn new(vision: Vision) -> Perception {
        Perception {
            rays: RaySet::new(vision.side, vision.field[0], vision.field[1]),
            vision,
            viewers: BTreeMap::new(),
        }
    }

    /// Its settings.
    pub fn vision(&self) -> &Vision {
        &self.vision
    }

    /// What character `id` saw at its last look (sorted; empty before its first).
    pub fn seen(&self, id: &str) -> &[String] {
        self.viewers.get(id).map_or(&[], |v| v.seen.as_slice())
    }

    /// What character `id` remembers, oldest first.
    pub fn remembered(&self, id: &str) -> Vec<Remembered> {
        (self.viewers.get(id)).map_or_else(Vec::new, |v| v.memory.entries().cloned().collect())
    }

    /// When character `id` looks next, once it has been met.
    pub fn next_look(&self, id: &str) -> Option<f64> {
        self.viewers.get(id).map(|v| v.next)
    }

    /// Whether [`sense`](Self::sense) at `now` has anything to do for a scene of `viewers`
    /// characters: someone's look is due, or not all of them have been met.
    pub fn due(&self, now: f64, viewers: usize) -> bool {
        self.viewers.len() != viewers || self.next_look_of_any().is_some_and(|t| t <= now + 1e-9)
    }

    /// When the next look of any character met so far is due.
    pub fn next_look_of_any(&self) -> Option<f64> {
        self.viewers.values().map(|v| v.next).reduce(f64::min)
    }

    /// Every character of `scene` whose time to look has come by `now` looks (in id order;
    /// a character met for the first time starts its period now, from its random phase);
    /// changes in what a character sees are pushed to `out`.
    pub fn sense(&mut self, now: f64, scene: &Scene, out: &mut Vec<WorldFeedback>) {
        let period = 1.0 / self.vision.rate;
        let mut due = Vec::new();
        for (i, thing) in scene.things().iter().enumerate() {
            if scene.eyes(i).is_none() {
                continue;
            }
            let seed = self.vision.seed;
            let v = self
                .viewers
                .entry(thing.id.clone())
                .or_insert_with(|| Viewer {
                    next: now + period * draw(&thing.id, seed, 1) as f64,
                    passes: 0,
                    turn: std::f32::consts::TAU * draw(&thing.id, seed, 2),
                    seen: Vec::new(),
                    memory: Memory::new(self.vision.memory),
                });
            if v.next <= now + 1e-9 {
                due.push(i);
            }
        }
        let looks: Vec<Vec<usize>> = if due.len() >= 4 {
            use rayon::prelude::*;
            due.par_iter().map(|&i| self.look(scene, i)).collect()
        } else {
            due.iter().map(|&i| self.look(scene, i)).collect()
        };
        for (i, hits) in due.into_iter().zip(looks) {
            let thing = &scene.things()[i];
            let v = self.viewers.get_mut(&thing.id).expect("met above");
            let found: Vec<(String, glam::Vec3)> = (hits.iter())
                .map(|&k| (scene.things()[k].id.clone(), scene.things()[k].at))
                .collect();
            v.memory.record(v.passes, now, &found);
            v.passes += 1;
            // the next look is on the viewer's own grid of times (looks missed are skipped)
            v.next += period * ((now - v.next) / period).floor().max(0.0) + period;
            let mut seen: Vec<String> = found.into_iter().map(|(id, _)| id).collect();
            seen.sort();
            let appeared: Vec<String> = (seen.iter())
                .filter(|s| v.seen.binary_search(s).is_err())
                .cloned()
                .collect();
            let disappeared: Vec<String> = (v.seen.iter())
                .filter(|s| seen.binary_search(s).is_err())
                .cloned()
                .collect();
            v.seen = seen;
            if !appeared.is_empty() || !disappeared.is_empty() {
                out.push(WorldFeedback::Perception(PerceptionFeedback {
                    character_id: thing.id.clone(),
                    time: now,
                    seen: v.seen.clone(),
                    appeared,
                    disappeared,
                }));
            }
        }
    }

    /// One look of thing `i` of `scene`: what its rays see first, each once, in ray order.
    fn look(&self, scene: &Scene, i: usize) -> Vec<usize> {
        let eyes = scene.eyes(i).expect("a viewer has eyes");
        let v = &self.viewers[&scene.things()[i].id];
        let sieve = Sieve::new(scene, i, eyes.at, self.vision.range);
        // the eye's frame: ahead along the gaze, left and up about the world's up
        let ahead = eyes.ahead;
        let left = glam::Vec3::Y
            .cross(ahead)
            .try_normalize()
            .unwrap_or(glam::Vec3::X);
        let up = ahead.cross(left);
        let mut hits: Vec<usize> = Vec::new();
        for p in self.rays.points(v.passes, v.turn) {
            let d = self.rays.direction(p);
            let world = left * d.x + up * d.y + ahead * d.z;
            if let Some(k) = sieve.first(eyes.at, world) {
                if !hits.contains(&k) {
                    hits.push(k);
                }
            }
        }
        hits
    }
}
