//! The eyelids of a living face: idle blinks at irregular intervals (deterministic per character:
//! the same character blinks at the same moments in every run), a blink with every large, fast
//! gaze shift (people blink with most gaze shifts of more than about 30°; Evinger et al., 1994),
//! and upper lids that follow the eyes' pitch: looking down lowers them, looking up raises them.
//! Blinks are AU45 on both sides; lowered lids AU43, raised lids AU5. This is part of the idle
//! layer: off with it.

use glam::Vec3;

use crate::bml::Side;
use crate::face::model::{Face, FaceModel};

/// Seconds to close, stay closed, and open again.
pub const BLINK: (f64, f64, f64) = (0.06, 0.03, 0.12);
/// Idle blinks come every 2.5 to 6 seconds.
pub const INTERVAL: (f64, f64) = (2.5, 6.0);
/// A gaze shift of more than this (radians of eye turn within [`SHIFT_WINDOW`]) comes with a
/// blink.
pub const SHIFT_ANGLE: f32 = 0.44; // 25°
/// The time over which a gaze shift's angle is measured (seconds).
pub const SHIFT_WINDOW: f64 = 0.15;
/// How much the lids follow the eyes: AU intensity per radian of pitch.
pub const LID_FOLLOW: f32 = 1.5;

/// Where the eyes look, in the head's frame (from the body: `assemble::eyes`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Eyes {
    /// Their mean pitch (radians, up positive).
    pub pitch: f32,
    /// Their mean direction.
    pub direction: Vec3,
}

impl Default for Eyes {
    /// Straight ahead.
    fn default() -> Eyes {
        Eyes {
            pitch: 0.0,
            direction: Vec3::Z,
        }
    }
}

/// The blinks of one character.
#[derive(Debug, Clone)]
pub struct Blinker {
    seed: u64,
    /// The next idle blink, and how many came before it.
    next: f64,
    count: u64,
    /// Blinks that began (their start times, the latest last).
    started: Vec<f64>,
    /// Recent eye directions (time, direction in the head's frame).
    eyes: Vec<(f64, Vec3)>,
    /// The face slots of AU45 (blink), AU43 (lids lowered) and AU5 (lids raised), both sides.
    lids: [Vec<usize>; 3],
}

/// A number in 0..1 from `seed` and `k` (splitmix64).
fn unit(seed: u64, k: u64) -> f64 {
    let mut z = seed.wrapping_add(k.wrapping_mul(0x9E37_79B9_7F4A_7C15));
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 53) as f64
}

/// How closed a blink that began at `start` is at `t` (0–1).
fn closure(t: f64, start: f64) -> f64 {
    let (close, hold, open) = BLINK;
    let x = t - start;
    if x <= 0.0 || x >= close + hold + open {
        0.0
    } else if x < close {
        crate::face::mixer::ease(x / close)
    } else if x <= close + hold {
        1.0
    } else {
        1.0 - crate::face::mixer::ease((x - close - hold) / open)
    }
}

impl Blinker {
    /// The blinks of character `id`.
    pub fn new(id: &str) -> Blinker {
        // FNV-1a of the id: a fixed, platform-independent phase per character
        let seed = (id.bytes()).fold(0xcbf2_9ce4_8422_2325u64, |h, b| {
            (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
        });
        let mut b = Blinker {
            seed,
            next: 0.0,
            count: 0,
            started: Vec::new(),
            eyes: Vec::new(),
            lids: [45, 43, 5]
                .map(|au| (FaceModel::default_model().slots(au, Side::Both)).unwrap_or_default()),
        };
        b.next = b.interval(0) * unit(seed, u64::MAX);
        b
    }

    fn interval(&self, k: u64) -> f64 {
        INTERVAL.0 + (INTERVAL.1 - INTERVAL.0) * unit(self.seed, k)
    }

    /// Closes and opens the lids of `face` at `now`, for `eyes` looking where they do.
    pub fn apply(&mut self, now: f64, eyes: Eyes, face: &mut Face) {
        while self.next <= now {
            self.started.push(self.next);
            self.count += 1;
            self.next += self.interval(self.count);
        }
        let Eyes { pitch, direction } = eyes;
        self.gaze_blink(now, direction);
        let gone = now - (BLINK.0 + BLINK.1 + BLINK.2);
        self.started.retain(|&s| s > gone);
        let closed = (self.started.iter())
            .map(|&s| closure(now, s))
            .fold(0.0, f64::max) as f32;
        let [blink, lowered, raised] = &self.lids;
        let raise = |face: &mut Face, slots: &[usize], v: f32| {
            for &s in slots {
                face.raise(s, v);
            }
        };
        raise(face, blink, closed);
        if pitch < 0.0 {
            raise(face, lowered, (-pitch * LID_FOLLOW).min(0.6));
        } else {
            raise(face, raised, (pitch * LID_FOLLOW).min(0.6));
        }
    }

    /// Starts a blink when the eyes turned more than [`SHIFT_ANGLE`] within [`SHIFT_WINDOW`]
    /// and no blink is running.
    fn gaze_blink(&mut self, now: f64, direction: Vec3) {
        self.eyes.retain(|(t, _)| *t >= now - SHIFT_WINDOW);
        let turned = (self.eyes.iter())
            .map(|(_, d)| d.angle_between(direction))
            .fold(0.0, f32::max);
        let blinking =
            (self.started.last()).is_some_and(|&s| now - s < BLINK.0 + BLINK.1 + BLINK.2);
        if turned > SHIFT_ANGLE && !blinking {
            self.started.push(now);
            self.eyes.clear();
        }
        self.eyes.push((now, direction));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn blinks(id: &str, seconds: f64) -> Vec<f64> {
        let mut b = Blinker::new(id);
        let m = FaceModel::default_model();
        let slot = m.slots(45, Side::Left).unwrap()[0];
        let mut closed_at = Vec::new();
        let mut was = 0.0;
        for k in 0..(seconds * 60.0) as usize {
            let t = k as f64 / 60.0;
            let mut face = Face::neutral(m);
            b.apply(t, Eyes::default(), &mut face);
            let w = face.aus.0[slot];
            if w >= 0.99 && was < 0.99 {
                closed_at.push(t);
            }
            was = w;
        }
        closed_at
    }

    #[test]
    fn idle_blinks_come_every_few_seconds_the_same_for_the_same_character() {
        let a = blinks("anna", 60.0);
        assert_eq!(a, blinks("anna", 60.0));
        assert_ne!(a, blinks("bob", 60.0));
        assert!(
            (10..=24).contains(&a.len()),
            "{} blinks a minute: {a:?}",
            a.len()
        );
        for w in a.windows(2) {
            assert!(w[1] - w[0] >= INTERVAL.0 - 0.05 && w[1] - w[0] <= INTERVAL.1 + 0.05);
        }
    }
}
