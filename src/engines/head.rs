//! The head engine: `head` NOD, SHAKE and TILT as real motion of the neck and skull. A nod pitches
//! the head forward (about +x), a shake turns it (about +y, alternating sides), a tilt rolls it
//! (about +z); each of the `repetition` cycles rises smoothly to its peak — the first one exactly
//! at `stroke` — and falls back, so the head is at rest again at `relax` and stays there until
//! `end`. The amplitude is `amount` × the lexeme's full amplitude; 70 % of the rotation is at the
//! skull base and 30 % at the neck (vc4). Head motions add up with other rotations of those joints.
//! Other lexemes are played with their timing only (no motion).

use glam::{Quat, Vec3};

use crate::bml::{Behaviour, BehaviourKind};
use crate::body::{Pose, Skeleton};
use crate::engine::timing::{DefaultTimingModels, TimingModel, TimingModels};
use crate::engine::{Engine, EngineError, Steering, Unit, Units};
use crate::schedule::SyncName;
use crate::world::World;

/// Full amplitude (amount 1) of a nod, degrees.
pub const NOD_DEGREES: f64 = 30.0;
/// Full amplitude of a shake, degrees.
pub const SHAKE_DEGREES: f64 = 45.0;
/// Full amplitude of a tilt, degrees.
pub const TILT_DEGREES: f64 = 25.0;
/// Amount when the behaviour gives none.
pub const DEFAULT_AMOUNT: f64 = 0.5;
/// Share of the rotation at the skull base (the rest is at the neck).
pub const SKULL_SHARE: f32 = 0.7;

/// The head motions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Motion {
    /// Pitch forward and back.
    Nod,
    /// Turn to one side and the other.
    Shake,
    /// Roll to the side.
    Tilt,
}

impl Motion {
    /// The motion of a head lexeme, if this engine knows it.
    pub fn of(lexeme: &str) -> Option<Motion> {
        match lexeme {
            "NOD" => Some(Motion::Nod),
            "SHAKE" => Some(Motion::Shake),
            "TILT" => Some(Motion::Tilt),
            _ => None,
        }
    }

    fn axis(self) -> Vec3 {
        match self {
            Motion::Nod => Vec3::X,
            Motion::Shake => Vec3::Y,
            Motion::Tilt => Vec3::Z,
        }
    }

    fn full(self) -> f64 {
        match self {
            Motion::Nod => NOD_DEGREES,
            Motion::Shake => SHAKE_DEGREES,
            Motion::Tilt => TILT_DEGREES,
        }
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

/// The rotation angle (radians) of a head unit at global time `t`.
fn angle(u: &HeadUnit, syncs: &[(SyncName, f64)], t: f64) -> f64 {
    let (Some(start), Some(stroke), Some(relax)) = (
        sync(syncs, "start"),
        sync(syncs, "stroke"),
        sync(syncs, "relax"),
    ) else {
        return 0.0;
    };
    if !(t > start && t < relax) || relax <= start {
        return 0.0;
    }
    let cycle = (relax - start) / f64::from(u.cycles.max(1));
    let k = ((t - start) / cycle).floor();
    let v = (t - start) / cycle - k; // position in the cycle, 0..1
    let peak = ((stroke - start) / cycle).clamp(0.05, 0.95);
    let shape = if v <= peak {
        (1.0 - (std::f64::consts::PI * v / peak).cos()) / 2.0
    } else {
        (1.0 + (std::f64::consts::PI * (v - peak) / (1.0 - peak)).cos()) / 2.0
    };
    // a shake alternates sides, a nod and a tilt repeat
    let sign = if u.motion == Some(Motion::Shake) && (k as u64) % 2 == 1 {
        -1.0
    } else {
        1.0
    };
    sign * u.amplitude * shape
}

/// The head engine (see the module documentation).
#[derive(Debug, Default)]
pub struct HeadEngine {
    models: DefaultTimingModels,
    units: Units<HeadUnit>,
}

fn head(b: &Behaviour) -> Option<(Option<Motion>, f64, u32)> {
    match &b.kind {
        BehaviourKind::Head(h) => {
            let amount = h.amount.unwrap_or(DEFAULT_AMOUNT).clamp(0.0, 1.0);
            Some((
                Motion::of(&h.lexeme),
                amount,
                h.repetition.unwrap_or(1).max(1),
            ))
        }
        _ => None,
    }
}

impl Engine for HeadEngine {
    crate::units_remove!();
    crate::units_retime_len!();
    crate::units_play!("head");
    crate::units_interrupt!(crate::engine::relax_now);

    fn name(&self) -> &'static str {
        "head"
    }

    fn steers(&self, behaviour: &Behaviour, skeleton: &Skeleton) -> Option<Steering> {
        matches!(behaviour.kind, BehaviourKind::Head(_))
            .then(|| Steering::kinematic(skeleton, ["vc4", "skullbase"], true))
    }

    fn timing(&self, behaviour: &Behaviour) -> Option<TimingModel> {
        head(behaviour)?;
        self.models.model(behaviour)
    }

    fn resources(&self, _behaviour: &Behaviour) -> &'static [&'static str] {
        &["head"]
    }

    fn add(&mut self, unit: Unit<'_>) -> Result<(), EngineError> {
        let (motion, amount, cycles) = head(unit.behaviour)
            .ok_or_else(|| EngineError("the head engine realizes <head> only".into()))?;
        self.units.add(
            unit,
            HeadUnit {
                motion,
                amplitude: motion.map_or(0.0, |m| (amount * m.full()).to_radians()),
                cycles,
            },
        );
        Ok(())
    }

    fn animate(&mut self, now: f64, skeleton: &Skeleton, _world: &World, pose: &mut Pose) {
        let (Some(skull), Some(neck)) = (skeleton.joint("skullbase"), skeleton.joint("vc4")) else {
            return;
        };
        for (syncs, u) in self.units.all() {
            let a = angle(u, syncs, now) as f32;
            if let (true, Some(m)) = (a != 0.0, u.motion) {
                let axis = m.axis();
                pose.rotate(neck, Quat::from_axis_angle(axis, a * (1.0 - SKULL_SHARE)));
                pose.rotate(skull, Quat::from_axis_angle(axis, a * SKULL_SHARE));
            }
        }
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
        .map(|&(n, t)| (crate::bml::Id::new_static(n), t))
        .collect()
    }

    #[test]
    fn a_nod_peaks_at_its_stroke_and_rests_from_relax() {
        let u = HeadUnit {
            motion: Some(Motion::Nod),
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

    #[test]
    fn a_shake_alternates_sides() {
        let u = HeadUnit {
            motion: Some(Motion::Shake),
            amplitude: 0.3,
            cycles: 2,
        };
        let s = nod_syncs(); // two cycles of 0.25 s from 1.0 to 1.5
        let first: f64 = (0..250)
            .map(|i| angle(&u, &s, 1.0 + f64::from(i) / 1000.0))
            .sum();
        let second: f64 = (250..500)
            .map(|i| angle(&u, &s, 1.0 + f64::from(i) / 1000.0))
            .sum();
        assert!(first > 0.0 && second < 0.0);
    }
}
