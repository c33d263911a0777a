//! The head engine: `head` lexemes as real motion of the neck and skull, defined as data in
//! `fixtures/bindings/heads.json` (the default [`HeadLexicon`]: NOD pitches the head forward
//! about +x, SHAKE turns it about +y alternating sides, TILT rolls it about +z, TOSS pitches it
//! back). Each of the `repetition` cycles rises smoothly to its peak exactly at its stroke
//! (`stroke`, then `stroke:1` …, the sync points a repeated head has, so that other behaviours
//! can be tied to any of them) and falls back, so the head is at rest again at `relax` and
//! stays there until `end`. The amplitude is `amount` × the lexeme's full amplitude; 70 % of the rotation is at the
//! skull base and 30 % at the neck (vc4). Head motions add up with other rotations of those joints.
//! Lexemes the lexicon lacks are played with their timing only (no motion).

use glam::{Quat, Vec3};

use crate::character::body::{Pose, Skeleton};
use crate::engines::interface::{Engine, EngineError, Steering, Unit, Units};
use crate::language::bml::{Behaviour, BehaviourKind};
use crate::planning::timing::SyncName;
use crate::planning::timing::{DefaultTimingModels, TimingModel, TimingModels};
use crate::world::World;

/// The embedded default head lexicon.
const HEADS: &str = include_str!("../../fixtures/bindings/heads.json");

/// Full amplitude (amount 1) of a nod in the default lexicon, degrees.
pub const NOD_DEGREES: f64 = 30.0;
/// Full amplitude of a shake in the default lexicon, degrees.
pub const SHAKE_DEGREES: f64 = 45.0;
/// Full amplitude of a tilt in the default lexicon, degrees.
pub const TILT_DEGREES: f64 = 25.0;
/// Amount when the behaviour gives none.
pub const DEFAULT_AMOUNT: f64 = 0.5;
/// Share of the rotation at the skull base (the rest is at the neck).
pub const SKULL_SHARE: f32 = 0.7;

/// A head motion: about one axis, by a full amplitude, alternating sides or not.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Motion {
    /// The axis (in the joints' frames).
    pub axis: Vec3,
    /// Full amplitude (amount 1), degrees; negative turns the other way.
    pub degrees: f64,
    /// Whether every other repetition goes to the other side (a shake).
    pub alternate: bool,
}

/// Head lexemes bound to motions.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct HeadLexicon {
    motions: Vec<(String, Motion)>,
}

impl HeadLexicon {
    /// The default lexicon (`fixtures/bindings/heads.json`: NOD, SHAKE, TILT, TOSS).
    pub fn default_lexicon() -> HeadLexicon {
        static LEXICON: std::sync::LazyLock<HeadLexicon> = std::sync::LazyLock::new(|| {
            HeadLexicon::from_json(HEADS).expect("the embedded head lexicon is valid")
        });
        LEXICON.clone()
    }

    /// Reads `{"heads": [{"lexeme", "axis": x|y|z, "degrees", "alternate"?}]}`.
    pub fn from_json(text: &str) -> Result<HeadLexicon, String> {
        #[derive(serde::Deserialize)]
        #[serde(deny_unknown_fields)]
        struct File {
            #[serde(default, rename = "description")]
            _description: crate::data::Note,
            heads: Vec<Head>,
        }
        #[derive(serde::Deserialize)]
        #[serde(deny_unknown_fields)]
        struct Head {
            lexeme: String,
            axis: Axis,
            degrees: f64,
            #[serde(default)]
            alternate: bool,
        }
        #[derive(serde::Deserialize)]
        #[serde(rename_all = "lowercase")]
        enum Axis {
            X,
            Y,
            Z,
        }
        let file: File = crate::data::from_json(text)?;
        let motions = file
            .heads
            .into_iter()
            .map(|h| {
                let axis = match h.axis {
                    Axis::X => Vec3::X,
                    Axis::Y => Vec3::Y,
                    Axis::Z => Vec3::Z,
                };
                let motion = Motion {
                    axis,
                    degrees: h.degrees,
                    alternate: h.alternate,
                };
                (h.lexeme, motion)
            })
            .collect();
        Ok(HeadLexicon { motions })
    }

    /// `first`'s lexemes, then these: for a lexeme both bind, `first`'s wins.
    pub fn extended_by(mut self, first: HeadLexicon) -> HeadLexicon {
        let mut motions = first.motions;
        motions.append(&mut self.motions);
        HeadLexicon { motions }
    }

    /// The motion of `lexeme`, if bound.
    pub fn get(&self, lexeme: &str) -> Option<Motion> {
        self.motions.iter().find(|m| m.0 == lexeme).map(|m| m.1)
    }

    /// The bound lexemes, in order.
    pub fn lexemes(&self) -> Vec<&str> {
        self.motions.iter().map(|m| m.0.as_str()).collect()
    }
}

/// One head unit: its motion (none for a lexeme this engine does not know: timing only),
/// amplitude (radians) and cycles.
#[derive(Debug, Clone)]
struct HeadUnit {
    motion: Option<Motion>,
    amplitude: f64,
    cycles: u32,
}

fn sync(syncs: &[(SyncName, f64)], name: &str) -> Option<f64> {
    syncs.iter().find(|s| s.0 == name).map(|s| s.1)
}

/// The rotation angle (radians) of a head unit at global time `t`: cycle `k` rises from the
/// middle between strokes `k-1` and `k` (from `start` for the first) to its peak at stroke `k`
/// and falls to the middle before the next (to `relax` after the last).
fn angle(u: &HeadUnit, syncs: &[(SyncName, f64)], t: f64) -> f64 {
    let (Some(start), Some(relax)) = (sync(syncs, "start"), sync(syncs, "relax")) else {
        return 0.0;
    };
    if !(t > start && t < relax) || relax <= start {
        return 0.0;
    }
    // (in key order: stroke, stroke:1, …)
    let peaks: Vec<f64> = (syncs.iter())
        .filter(|(name, _)| crate::language::bml::stroke_iteration_of(name).is_some())
        .map(|s| s.1)
        .take(u.cycles.max(1) as usize)
        .collect();
    // the cycle holding t: its bounds and peak
    let k = peaks.partition_point(|&p| p < t);
    let k = if k > 0 && k < peaks.len() && t - peaks[k - 1] < peaks[k] - t {
        k - 1
    } else {
        k.min(peaks.len().saturating_sub(1))
    };
    let Some(&peak) = peaks.get(k) else {
        return 0.0;
    };
    let from = if k == 0 {
        start
    } else {
        (peaks[k - 1] + peak) / 2.0
    };
    let to = peaks.get(k + 1).map_or(relax, |next| (peak + next) / 2.0);
    let shape = if t <= peak {
        (1.0 - (std::f64::consts::PI * (t - from) / (peak - from).max(1e-9)).cos()) / 2.0
    } else {
        (1.0 + (std::f64::consts::PI * (t - peak) / (to - peak).max(1e-9)).cos()) / 2.0
    };
    // a shake alternates sides, a nod and a tilt repeat
    let sign = if u.motion.is_some_and(|m| m.alternate) && k % 2 == 1 {
        -1.0
    } else {
        1.0
    };
    sign * u.amplitude * shape.clamp(0.0, 1.0)
}

/// The head engine (see the module documentation).
#[derive(Debug)]
pub struct HeadEngine {
    models: DefaultTimingModels,
    lexicon: HeadLexicon,
    units: Units<HeadUnit>,
}

impl Default for HeadEngine {
    fn default() -> Self {
        HeadEngine::new(HeadLexicon::default_lexicon())
    }
}

impl HeadEngine {
    /// A head engine with `lexicon`.
    pub fn new(lexicon: HeadLexicon) -> Self {
        HeadEngine {
            models: DefaultTimingModels::default(),
            lexicon,
            units: Units::new(),
        }
    }

    fn head(&self, b: &Behaviour) -> Option<(Option<Motion>, f64, u32)> {
        match &b.kind {
            BehaviourKind::Head(h) => {
                let amount = h.amount.unwrap_or(DEFAULT_AMOUNT).clamp(0.0, 1.0);
                Some((
                    self.lexicon.get(&h.lexeme),
                    amount,
                    h.repetition.unwrap_or(1).max(1),
                ))
            }
            _ => None,
        }
    }
}

impl Engine for HeadEngine {
    crate::units_remove!();
    crate::units_retime_len!();
    crate::units_play!("head");
    crate::units_interrupt!(crate::engines::interface::relax_now);

    fn name(&self) -> &'static str {
        "head"
    }

    fn timing(&self, behaviour: &Behaviour) -> Option<TimingModel> {
        self.head(behaviour)?;
        self.models.model(behaviour)
    }

    fn unanimated(&self, behaviour: &Behaviour) -> Option<String> {
        let BehaviourKind::Head(h) = &behaviour.kind else {
            return None;
        };
        self.lexicon.get(&h.lexeme).is_none().then(|| {
            format!(
                "head '{}': no binding moves lexeme '{}'; it plays its timing only (bound: {})",
                behaviour.id,
                h.lexeme,
                self.lexicon.lexemes().join(", ")
            )
        })
    }

    fn add(&mut self, unit: Unit<'_>) -> Result<(), EngineError> {
        let (motion, amount, cycles) = self
            .head(unit.behaviour)
            .ok_or_else(|| EngineError("the head engine realizes <head> only".into()))?;
        self.units.add(
            unit,
            HeadUnit {
                motion,
                amplitude: motion.map_or(0.0, |m| (amount * m.degrees).to_radians()),
                cycles,
            },
        );
        Ok(())
    }

    fn as_motion(&mut self) -> Option<&mut dyn crate::engines::interface::Motion> {
        Some(self)
    }

    fn as_resources(&self) -> Option<&dyn crate::engines::interface::Resources> {
        Some(self)
    }
}

impl crate::engines::interface::Motion for HeadEngine {
    fn steers(&self, behaviour: &Behaviour, skeleton: &Skeleton) -> Option<Steering> {
        matches!(behaviour.kind, BehaviourKind::Head(_))
            .then(|| Steering::kinematic(skeleton, ["vc4", "skullbase"], true))
    }

    fn animate(&mut self, now: f64, skeleton: &Skeleton, _world: &World, pose: &mut Pose) {
        let (Some(skull), Some(neck)) = (skeleton.joint("skullbase"), skeleton.joint("vc4")) else {
            return;
        };
        for (syncs, u) in self.units.all() {
            let a = angle(u, syncs, now) as f32;
            if let (true, Some(m)) = (a != 0.0, u.motion) {
                let axis = m.axis;
                pose.rotate(neck, Quat::from_axis_angle(axis, a * (1.0 - SKULL_SHARE)));
                pose.rotate(skull, Quat::from_axis_angle(axis, a * SKULL_SHARE));
            }
        }
    }
}

impl crate::engines::interface::Resources for HeadEngine {
    fn resources(&self, _behaviour: &Behaviour) -> &'static [&'static str] {
        &["head"]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn nod_syncs() -> Vec<(SyncName, f64)> {
        [
            ("start", 1.0),
            ("ready", 1.1),
            ("strokeStart", 1.15),
            ("stroke", 1.3),
            ("strokeEnd", 1.45),
            ("relax", 1.5),
            ("end", 1.6),
        ]
        .iter()
        .map(|&(n, t)| (crate::language::bml::Id::new_static(n), t))
        .collect()
    }

    #[test]
    fn the_default_head_lexicon_binds_nod_shake_tilt_as_documented() {
        let l = HeadLexicon::default_lexicon();
        let m = |x: &str| l.get(x).unwrap();
        assert_eq!(
            (m("NOD").axis, m("NOD").degrees, m("NOD").alternate),
            (Vec3::X, NOD_DEGREES, false)
        );
        assert_eq!(
            (m("SHAKE").axis, m("SHAKE").degrees, m("SHAKE").alternate),
            (Vec3::Y, SHAKE_DEGREES, true)
        );
        assert_eq!((m("TILT").axis, m("TILT").degrees), (Vec3::Z, TILT_DEGREES));
        assert!(l.get("WOBBLE").is_none());
        assert!(HeadLexicon::from_json(
            r#"{"heads": [{"lexeme": "X", "axis": "w", "degrees": 1}]}"#
        )
        .unwrap_err()
        .contains("axis"));
    }

    #[test]
    fn a_nod_peaks_at_its_stroke_and_rests_from_relax() {
        let u = HeadUnit {
            motion: HeadLexicon::default_lexicon().get("NOD"),
            amplitude: 0.2,
            cycles: 1,
        };
        let s = nod_syncs();
        assert_eq!(angle(&u, &s, 1.0), 0.0);
        assert!((angle(&u, &s, 1.3) - 0.2).abs() < 1e-12);
        assert!(angle(&u, &s, 1.2) < 0.2 && angle(&u, &s, 1.4) < 0.2);
        assert_eq!(angle(&u, &s, 1.5), 0.0);
        assert_eq!(angle(&u, &s, 1.55), 0.0);
        // the curve rises and falls smoothly: no value above the peak
        let max = (0..=600)
            .map(|i| angle(&u, &s, 1.0 + f64::from(i) / 1000.0))
            .fold(0.0, f64::max);
        assert!((max - 0.2).abs() < 1e-9);
    }

    /// A head's syncs with strokes at `strokes`, from `start` 1.0 to `relax` 2.0.
    fn repeated_syncs(strokes: &[f64]) -> Vec<(SyncName, f64)> {
        let mut s = vec![(crate::language::bml::Id::new_static("start"), 1.0)];
        s.extend(
            (0..)
                .zip(strokes)
                .map(|(n, &t)| (crate::language::bml::stroke_name(n), t)),
        );
        s.push((crate::language::bml::Id::new_static("relax"), 2.0));
        s
    }

    #[test]
    fn a_shake_alternates_sides() {
        let u = HeadUnit {
            motion: HeadLexicon::default_lexicon().get("SHAKE"),
            amplitude: 0.3,
            cycles: 2,
        };
        let s = repeated_syncs(&[1.25, 1.75]);
        let first: f64 = (0..500)
            .map(|i| angle(&u, &s, 1.0 + f64::from(i) / 1000.0))
            .sum();
        let second: f64 = (500..1000)
            .map(|i| angle(&u, &s, 1.0 + f64::from(i) / 1000.0))
            .sum();
        assert!(first > 0.0 && second < 0.0);
    }

    #[test]
    fn a_repeated_nod_peaks_at_each_of_its_strokes_wherever_they_are() {
        let u = HeadUnit {
            motion: HeadLexicon::default_lexicon().get("NOD"),
            amplitude: 0.2,
            cycles: 3,
        };
        // the second stroke pulled late (tied to something else)
        let strokes = [1.2, 1.7, 1.85];
        let s = repeated_syncs(&strokes);
        let at = |t: f64| angle(&u, &s, t);
        for p in strokes {
            assert!((at(p) - 0.2).abs() < 1e-9, "no peak at {p}: {}", at(p));
        }
        // down between the strokes: at rest at the middles, lower on either side of a peak
        assert!(at(1.45).abs() < 1e-9 && at(1.775).abs() < 1e-9);
        for p in strokes {
            assert!(at(p - 0.02) < at(p) && at(p + 0.02) < at(p));
        }
        let max = (0..=1000)
            .map(|i| at(1.0 + f64::from(i) / 1000.0))
            .fold(0.0, f64::max);
        assert!((max - 0.2).abs() < 1e-9);
        assert_eq!(at(2.0), 0.0);
    }
}
