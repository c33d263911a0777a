//! Eyes alive: the small saccades a person's eyes make while nothing steers them — at rest,
//! listening, speaking — so that a standing character does not stare. Part of the idle layer
//! (it starts every frame's pose; a BML gaze, or a look the crowd asks for, sets the eyes over
//! it). The eyes hold a fixation, then jump to the next, at irregular moments (a mean of
//! [`MEAN_INTERVAL`] apart, each within ±40 % of its slot) to fixations spread around straight
//! ahead (normal, [`SPREAD`] degrees sideways and up or down, held within [`FIELD`]), as Lee,
//! Badler and Badler's "Eyes Alive" (SIGGRAPH 2002) made eyes live from the statistics of
//! people's gaze in conversation: mostly small jumps, about one a second. Each jump follows the
//! main sequence (Carpenter, "Movements of the Eyes", 1988): it lasts 2.2 ms per degree plus
//! 21 ms, with a minimum-jerk profile, so its peak speed (1.875 × amplitude / duration) rises
//! with its amplitude and levels off. Deterministic: the same character (by id) at the same time
//! looks the same way; no state, so any frame can be made on its own.

use glam::Quat;

use super::pose::Pose;
use super::skeleton::Skeleton;
use crate::rng::{fnv1a, normals, unit};

/// The salts of the saccades' streams of numbers: when they start, where they aim.
const JITTER: u64 = 0xA5A5_A5A5;
const AIM: u64 = 0x5A5A_5A5A;

/// The mean time between saccades (seconds).
pub const MEAN_INTERVAL: f64 = 1.1;
/// How widely fixations spread about straight ahead: one standard deviation sideways and up or
/// down (degrees).
pub const SPREAD: (f64, f64) = (4.0, 2.5);
/// Fixations stay within this far of straight ahead, sideways and up or down (degrees).
pub const FIELD: (f64, f64) = (10.0, 6.0);
/// The main sequence: a saccade of amplitude A degrees lasts `A × .0 + .1` seconds.
pub const MAIN_SEQUENCE: (f64, f64) = (0.0022, 0.021);
/// The longest idle saccade (seconds): across the whole field (its diagonal, 2·√(10² + 6²)
/// degrees).
pub const LONGEST: f64 = MAIN_SEQUENCE.0 * 2.0 * 11.67 + MAIN_SEQUENCE.1;
/// At most this many saccades in a row are left out (`Saccades::look_without`).
pub const SKIPPED: usize = 8;

/// The saccades of one character.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Saccades {
    seed: u64,
    /// The eyeball joints (left, right).
    eyes: Option<(usize, usize)>,
}

/// Minimum jerk from 0 to 1 over 0..1.
pub(super) fn minimum_jerk(x: f64) -> f64 {
    let x = x.clamp(0.0, 1.0);
    x * x * x * (10.0 - 15.0 * x + 6.0 * x * x)
}

impl Saccades {
    /// The saccades of character `id` on `skeleton` (none without eyeball joints).
    pub fn new(id: &str, skeleton: &Skeleton) -> Saccades {
        // (a stream of its own, apart from the blinks')
        let seed = fnv1a(id) ^ 0x6a09_e667_f3bc_c908;
        let eyes = skeleton
            .joint("l_eyeball_joint")
            .zip(skeleton.joint("r_eyeball_joint"));
        Saccades { seed, eyes }
    }

    /// When saccade `k` starts (seconds; saccade 0 at the start, to the first fixation).
    pub fn start(&self, k: i64) -> f64 {
        let jitter = unit(self.seed ^ JITTER, k as u64) - 0.5;
        (k as f64 + 0.8 * jitter) * MEAN_INTERVAL
    }

    /// Fixation `k` (yaw left, pitch up; degrees): where saccade `k` lands.
    pub fn fixation(&self, k: i64) -> (f64, f64) {
        let (a, b) = normals(unit(self.seed, k as u64), unit(self.seed ^ AIM, k as u64));
        let yaw = (a * SPREAD.0).clamp(-FIELD.0, FIELD.0);
        let pitch = (b * SPREAD.1).clamp(-FIELD.1, FIELD.1);
        (yaw, pitch)
    }

    /// How long a saccade from `from` to `to` (yaw, pitch; degrees) lasts (seconds): the main
    /// sequence for its amplitude.
    pub fn main_sequence(from: (f64, f64), to: (f64, f64)) -> f64 {
        MAIN_SEQUENCE.0 * (to.0 - from.0).hypot(to.1 - from.1) + MAIN_SEQUENCE.1
    }

    /// The last saccade started by `t` (the one under way then, if any is).
    pub fn last(&self, t: f64) -> i64 {
        // the last one started is the one of t's slot or its neighbour (starts keep their
        // order: each within ±40 % of its slot)
        let slot = (t / MEAN_INTERVAL).floor() as i64;
        (slot - 1..=slot + 1)
            .rev()
            .find(|&k| self.start(k) <= t)
            .unwrap_or(slot - 1)
    }

    /// Where the eyes look at `t` (yaw left, pitch up; degrees).
    pub fn look(&self, t: f64) -> (f64, f64) {
        self.look_without(t, |_| false)
    }

    /// Where the eyes look at `t` (yaw left, pitch up; degrees) when the saccades `skip` names
    /// are left out (the eyes stay where they were instead; at most [`SKIPPED`] in a row).
    pub fn look_without(&self, t: f64, skip: impl Fn(i64) -> bool) -> (f64, f64) {
        let made = |mut k: i64| {
            for _ in 0..SKIPPED {
                if !skip(k) {
                    break;
                }
                k -= 1;
            }
            k
        };
        let k = made(self.last(t));
        let (from, to) = (self.fixation(made(k - 1)), self.fixation(k));
        let f = minimum_jerk((t - self.start(k)) / Saccades::main_sequence(from, to));
        (from.0 + (to.0 - from.0) * f, from.1 + (to.1 - from.1) * f)
    }

    /// Turns the eyes of `pose` to `look` (yaw left, pitch up; degrees).
    pub fn apply(&self, look: (f64, f64), pose: &mut Pose) {
        let Some((l, r)) = self.eyes else {
            return;
        };
        let (yaw, pitch) = look;
        let turn = Quat::from_rotation_y(yaw.to_radians() as f32)
            * Quat::from_rotation_x(-pitch.to_radians() as f32);
        for e in [l, r] {
            pose.rotations[e] = turn * pose.rotations[e];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The saccades in `seconds` sampled at 1 kHz: (start, duration, amplitude in degrees,
    /// peak speed in degrees a second), found from the eyes' speed alone.
    fn measured(s: &Saccades, seconds: f64) -> Vec<(f64, f64, f64, f64)> {
        let dt = 0.001;
        let (mut out, mut moving, mut from, mut at, mut peak) =
            (Vec::new(), false, (0.0, 0.0), 0.0, 0.0f64);
        let mut was = s.look(0.0);
        for i in 1..(seconds / dt) as usize {
            let t = i as f64 * dt;
            let now = s.look(t);
            let speed = (now.0 - was.0).hypot(now.1 - was.1) / dt;
            if speed > 1.0 && !moving {
                (moving, from, at, peak) = (true, was, t - dt, 0.0);
            }
            if moving {
                peak = peak.max(speed);
                if speed < 1e-9 {
                    moving = false;
                    let amplitude = (now.0 - from.0).hypot(now.1 - from.1);
                    out.push((at, t - at, amplitude, peak));
                }
            }
            was = now;
        }
        out
    }

    #[test]
    fn the_eyes_jump_about_once_a_second_on_the_main_sequence() {
        let skeleton = Skeleton::adult();
        for id in ["", "anna", "bob"] {
            let s = Saccades::new(id, &skeleton);
            let all = measured(&s, 60.0);
            // at least 12 a minute (here about 55)
            assert!(
                (40..=70).contains(&all.len()),
                "{id}: {} saccades a minute",
                all.len()
            );
            for &(at, duration, amplitude, peak) in &all {
                if amplitude < 0.5 {
                    continue;
                }
                let main = MAIN_SEQUENCE.0 * amplitude + MAIN_SEQUENCE.1;
                assert!(
                    duration >= 0.8 * main - 0.002 && duration <= 1.6 * main + 0.002,
                    "{id}: at {at:.3} s a {amplitude:.1}° saccade lasts {duration:.3} s"
                );
                // the peak speed rises with amplitude and stays below 600°/s (people: about
                // 300°/s at 10°, levelling off at 500–700°/s)
                assert!(
                    peak > 20.0 * amplitude.min(10.0) && peak < 600.0,
                    "{id}: {amplitude:.1}° at {peak:.0}°/s"
                );
            }
            // held within the field
            for (y, p) in (0..60_000).map(|i| s.look(i as f64 / 1000.0)) {
                assert!(y.abs() <= FIELD.0 + 1e-9 && p.abs() <= FIELD.1 + 1e-9);
            }
        }
        // characters look about on their own
        let (a, b) = (
            Saccades::new("anna", &skeleton),
            Saccades::new("bob", &skeleton),
        );
        assert_ne!(a.look(5.0), b.look(5.0));
        assert_eq!(a.look(5.0), Saccades::new("anna", &skeleton).look(5.0));
    }
}
