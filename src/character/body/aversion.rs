//! Looking away as one begins to speak. People who take the floor mostly look away from their
//! listener as an utterance begins and back at them as it goes on: Kendon ("Some functions of
//! gaze-direction in social interaction", Acta Psychologica 26, 1967) found speakers looking
//! away at the start of long utterances and back towards their end; Cassell, Torres and Prevost
//! ("Turn taking vs. discourse structure", 1999) counted a look away at the start of about seven
//! in ten utterances' first part, and Andrist, Mutlu and Gleicher ("Conversational gaze aversion
//! for virtual agents", IVA 2013) gave agents such aversions, which listeners then read as
//! thinking. Here, at the start of most utterances ([`CHANCE`]) the eyes jump away — sideways
//! and up or down, [`AMPLITUDE`] degrees — hold there for half the utterance, at least
//! [`HOLD`].0 and at most [`HOLD`].1 seconds, and jump back to where the idle saccades look. Both
//! jumps are saccades on the main sequence (as in `saccades`). The idle saccades go on while the
//! eyes are away (the look away adds to them), but not during a jump: an idle saccade under way
//! as the utterance begins ends first, and those that would start during a jump are left out,
//! so each jump is one saccade. A BML gaze sets the eyes over all of it.
//! Deterministic: the same character and utterance start give the same aversion, and any frame
//! can be made on its own.

use super::saccades::{minimum_jerk, Saccades, LONGEST};
use crate::rng::{fnv1a, unit};

/// The share of utterances that begin with a look away.
pub const CHANCE: f64 = 0.7;
/// How far the eyes look away (degrees, least and most).
pub const AMPLITUDE: (f64, f64) = (10.0, 18.0);
/// How long the eyes stay away (seconds, least and most): half the utterance within these.
pub const HOLD: (f64, f64) = (0.6, 2.0);
/// The share of aversions that look up (the others look down).
pub const UP: f64 = 0.6;

/// An utterance being said: when it began and when it ends (global seconds).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Utterance {
    /// Its start.
    pub start: f64,
    /// Its end (as planned now).
    pub end: f64,
}

/// The aversions of one character.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Aversion {
    seed: u64,
}

impl Aversion {
    /// The aversions of character `id`.
    pub fn new(id: &str) -> Aversion {
        // (a stream of its own, apart from the saccades' and the blinks')
        Aversion {
            seed: fnv1a(id) ^ 0xbb67_ae85_84ca_a73b,
        }
    }

    /// Where the eyes look away to (yaw left, pitch up; degrees) at the start of an utterance
    /// that begins at `start`, if they do.
    pub fn away(&self, start: f64) -> Option<(f64, f64)> {
        // (the utterance by its start to the millisecond, as the stream's indices are meant:
        // consecutive whole numbers)
        let k = (start * 1000.0).round() as i64 as u64;
        let draw = |salt: u64| unit(self.seed ^ salt, k);
        if draw(0) >= CHANCE {
            return None;
        }
        let amplitude = AMPLITUDE.0 + (AMPLITUDE.1 - AMPLITUDE.0) * draw(1);
        // sideways to either side, 20–50° above or below the horizontal
        let side = if draw(2) < 0.5 { 1.0 } else { -1.0 };
        let up = if draw(3) < UP { 1.0 } else { -1.0 };
        let elevation = (20.0 + 30.0 * draw(4)).to_radians();
        Some((
            side * amplitude * elevation.cos(),
            up * amplitude * elevation.sin(),
        ))
    }

    /// How long the eyes stay away for `utterance` (seconds, from its start to the jump back).
    pub fn hold(utterance: &Utterance) -> f64 {
        (0.5 * (utterance.end - utterance.start)).clamp(HOLD.0, HOLD.1)
    }

    /// When the eyes look away for `utterance` and back (global seconds), if they do, and
    /// where to (yaw left, pitch up; degrees, from where the idle saccades look). The look
    /// away waits for an idle saccade under way to end.
    fn plan(&self, saccades: &Saccades, utterance: &Utterance) -> Option<Plan> {
        let to = self.away(utterance.start)?;
        let out = utterance
            .start
            .max(saccades.start(saccades.last(utterance.start)) + LONGEST);
        Some(Plan {
            out,
            back: out + Aversion::hold(utterance),
            to,
        })
    }

    /// Where the eyes look at `t` (yaw left, pitch up; degrees): where `saccades` look, turned
    /// away at the start of `utterance` (the last one begun, if any). The idle saccades that
    /// would start while the eyes jump away or back are left out, so each jump is one saccade.
    pub fn look(&self, t: f64, saccades: &Saccades, utterance: Option<&Utterance>) -> (f64, f64) {
        let Some(plan) = utterance.and_then(|u| self.plan(saccades, u)) else {
            return saccades.look(t);
        };
        let jump = Saccades::main_sequence((0.0, 0.0), plan.to);
        let skip = |k: i64| {
            let s = saccades.start(k);
            (plan.out..=plan.out + jump).contains(&s)
                || (plan.back - LONGEST..=plan.back + jump).contains(&s)
        };
        let (yaw, pitch) = saccades.look_without(t, skip);
        let weight = if t < plan.back {
            minimum_jerk((t - plan.out) / jump)
        } else {
            1.0 - minimum_jerk((t - plan.back) / jump)
        };
        (yaw + plan.to.0 * weight, pitch + plan.to.1 * weight)
    }
}

/// One look away: when the eyes jump away and back (global seconds), and how far.
struct Plan {
    out: f64,
    back: f64,
    to: (f64, f64),
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn most_utterances_begin_with_a_look_away_that_comes_back() {
        let a = Aversion::new("anna");
        let starts: Vec<f64> = (0..1000).map(|i| 0.37 + 3.1 * f64::from(i)).collect();
        let away: Vec<_> = starts.iter().filter_map(|&s| a.away(s)).collect();
        let share = away.len() as f64 / starts.len() as f64;
        assert!((0.65..0.75).contains(&share), "{share}");
        let up = away.iter().filter(|(_, p)| *p > 0.0).count() as f64 / away.len() as f64;
        assert!((0.55..0.65).contains(&up), "{up}");
        for &(y, p) in &away {
            let amplitude = y.hypot(p);
            assert!((AMPLITUDE.0 - 1e-9..=AMPLITUDE.1 + 1e-9).contains(&amplitude));
            assert!(
                y.abs() > p.abs() * 0.5,
                "sideways, then up or down: {y} {p}"
            );
        }
        // one that looks away: away within the main sequence, held, back again
        let skeleton = crate::character::body::Skeleton::adult();
        let saccades = Saccades::new("anna", &skeleton);
        let s = *starts.iter().find(|&&s| a.away(s).is_some()).unwrap();
        let u = Utterance {
            start: s,
            end: s + 3.0,
        };
        let full = a.away(s).unwrap();
        let away = |t: f64| {
            let (l, i) = (a.look(t, &saccades, Some(&u)), saccades.look(t));
            (l.0 - i.0, l.1 - i.1)
        };
        assert_eq!(away(s - 0.01), (0.0, 0.0));
        for t in [s + 0.2, s + 1.0, s + 1.49] {
            let (y, p) = away(t);
            assert!((y - full.0).abs() < 20.0 && (p - full.1).abs() < 12.0);
            assert!(y.hypot(p) > 3.0, "away at {t}: {y} {p}");
        }
        // back where the idle saccades look once the next one is made
        assert_eq!(a.look(s + 4.0, &saccades, Some(&u)), saccades.look(s + 4.0));
        assert_eq!(a.look(s + 0.2, &saccades, None), saccades.look(s + 0.2));
        // a short utterance still looks away for the least hold
        let short = Utterance {
            start: s,
            end: s + 0.5,
        };
        assert_eq!(Aversion::hold(&short), HOLD.0);
    }
}
