//! The eyelids of a living face: idle blinks at irregular intervals (deterministic per character:
//! the same character blinks at the same moments in every run), more often while it speaks — the
//! spontaneous blink rates Bentivoglio et al. (1997, Movement Disorders 12(6)) measured in 150
//! adults: 17 ± 13 a minute at rest, 26 ± 15 in conversation — with intervals as irregular as
//! people's (log-normal, coefficient of variation 0.7; a uniform spread of a few seconds gave
//! 0.28, a metronome), a blink with every large, fast
//! gaze shift (people blink with most gaze shifts of more than about 30°; Evinger et al., 1994),
//! and upper lids that follow the eyes' pitch: looking down lowers them, looking up raises them.
//! Blinks are AU45 on both sides; lowered lids AU43, raised lids AU5. This is part of the idle
//! layer: off with it.

use glam::Vec3;

use crate::character::face::model::{Face, FaceModel};
use crate::language::bml::Side;
use crate::rng::{fnv1a, normals, unit};

/// Seconds to close, stay closed, and open again.
pub const BLINK: (f64, f64, f64) = (0.06, 0.03, 0.12);
/// The mean interval between idle blinks at rest and while speaking (seconds): 60 s over 17
/// and over 26 blinks a minute (Bentivoglio et al., 1997).
pub const MEAN_INTERVAL: (f64, f64) = (60.0 / 17.0, 60.0 / 26.0);
/// The intervals' coefficient of variation (standard deviation over mean).
pub const INTERVAL_CV: f64 = 0.7;
/// The shortest and longest interval between idle blinks (seconds).
pub const INTERVAL_BOUNDS: (f64, f64) = (0.4, 20.0);
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

/// How closed a blink that began at `start` is at `t` (0–1).
fn closure(t: f64, start: f64) -> f64 {
    let (close, hold, open) = BLINK;
    let x = t - start;
    if x <= 0.0 || x >= close + hold + open {
        0.0
    } else if x < close {
        crate::character::face::mixer::ease(x / close)
    } else if x <= close + hold {
        1.0
    } else {
        1.0 - crate::character::face::mixer::ease((x - close - hold) / open)
    }
}

impl Blinker {
    /// The blinks of character `id`.
    pub fn new(id: &str) -> Blinker {
        // a fixed, platform-independent phase per character
        let seed = fnv1a(id);
        let mut b = Blinker {
            seed,
            next: 0.0,
            count: 0,
            started: Vec::new(),
            eyes: Vec::new(),
            lids: [45, 43, 5]
                .map(|au| (FaceModel::default_model().slots(au, Side::Both)).unwrap_or_default()),
        };
        b.next = b.interval(0, false) * unit(seed, u64::MAX);
        b
    }

    /// The `k`-th interval, while speaking or not: log-normal with the mean and variation above
    /// (two of the character's uniform numbers through Box and Muller's transform).
    fn interval(&self, k: u64, speaking: bool) -> f64 {
        let mean = if speaking {
            MEAN_INTERVAL.1
        } else {
            MEAN_INTERVAL.0
        };
        let sigma = (1.0 + INTERVAL_CV * INTERVAL_CV).ln().sqrt();
        let (z, _) = normals(unit(self.seed, k), unit(self.seed ^ 0x5bd1_e995, k));
        let interval = (mean.ln() - sigma * sigma / 2.0 + sigma * z).exp();
        interval.clamp(INTERVAL_BOUNDS.0, INTERVAL_BOUNDS.1)
    }

    /// Closes and opens the lids of `face` at `now`, for `eyes` looking where they do.
    pub fn apply(&mut self, now: f64, eyes: Eyes, face: &mut Face) {
        // (speaking: the lips play a viseme)
        let speaking = face.visemes.iter().any(|&v| v > 0.0);
        while self.next <= now {
            self.started.push(self.next);
            self.count += 1;
            self.next += self.interval(self.count, speaking);
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

    /// The coefficient of variation of the intervals between `times`.
    fn cv(times: &[f64]) -> f64 {
        let d: Vec<f64> = times.windows(2).map(|w| w[1] - w[0]).collect();
        let mean = d.iter().sum::<f64>() / d.len() as f64;
        let var = d.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (d.len() - 1) as f64;
        var.sqrt() / mean
    }

    #[test]
    fn idle_blinks_come_as_irregularly_as_people_s_the_same_for_the_same_character() {
        let a = blinks("anna", 60.0);
        assert_eq!(a, blinks("anna", 60.0));
        assert_ne!(a, blinks("bob", 60.0));
        // at rest: 17 ± 13 a minute (Bentivoglio et al., 1997); over ten characters' ten
        // minutes, the mean rate near 17 and the intervals' variation at least 0.4
        let (mut count, mut cvs) = (0, Vec::new());
        for id in [
            "anna", "bob", "", "Alice", "Bob", "c1", "c2", "c3", "walker", "speaker",
        ] {
            let b = blinks(id, 600.0);
            count += b.len();
            cvs.push(cv(&b));
            assert!(b
                .windows(2)
                .all(|w| w[1] - w[0] >= INTERVAL_BOUNDS.0 - 0.05));
        }
        let rate = count as f64 / 100.0;
        assert!(
            (14.0..=20.0).contains(&rate),
            "{rate} blinks a minute at rest"
        );
        for c in cvs {
            assert!(c >= 0.4, "the intervals vary by {c}");
        }
        // each blink lasts 100-400 ms: the lids measured at 1 kHz, from moving to open again
        let m = FaceModel::default_model();
        let slot = m.slots(45, Side::Left).unwrap()[0];
        let (mut b, mut began, mut lengths) = (Blinker::new("anna"), None, Vec::new());
        for k in 0..20_000 {
            let t = f64::from(k) / 1000.0;
            let mut face = Face::neutral(m);
            b.apply(t, Eyes::default(), &mut face);
            match (face.aus.0[slot] > 0.0, began) {
                (true, None) => began = Some(t),
                (false, Some(s)) => {
                    lengths.push(t - s);
                    began = None;
                }
                _ => {}
            }
        }
        assert!(lengths.len() >= 3, "{lengths:?}");
        for l in lengths {
            assert!((0.1..=0.4).contains(&l), "a blink of {l:.3} s");
        }
    }

    #[test]
    fn a_speaking_face_blinks_more_often() {
        let m = FaceModel::default_model();
        let slot = m.slots(45, Side::Left).unwrap()[0];
        let (mut rest, mut speaking) = (0, 0);
        for id in ["anna", "bob", "c1", "c2", "c3"] {
            for talk in [false, true] {
                let mut b = Blinker::new(id);
                let mut was = 0.0;
                for k in 0..600 * 60 {
                    let mut face = Face::neutral(m);
                    if talk {
                        face.visemes[1] = 0.5;
                    }
                    b.apply(k as f64 / 60.0, Eyes::default(), &mut face);
                    let w = face.aus.0[slot];
                    if w >= 0.99 && was < 0.99 {
                        *(if talk { &mut speaking } else { &mut rest }) += 1;
                    }
                    was = w;
                }
            }
        }
        // per minute over 50 minutes each: 26 ± 15 in conversation against 17 ± 13 at rest
        let (rest, speaking) = (rest as f64 / 50.0, speaking as f64 / 50.0);
        assert!(
            (22.0..=30.0).contains(&speaking) && speaking > rest + 5.0,
            "{rest} at rest, {speaking} speaking"
        );
    }
}
