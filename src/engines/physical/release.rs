//! The hand-back from the simulated body to the kinematic pose when the last controller ends:
//! how far the body is from that pose ([`Offset`]) and the way back ([`Release`]), which keeps
//! the pose and the speed the body had and stays under a peak speed.

use glam::Quat;

use crate::character::body::Pose;

/// The shortest hand-back to the kinematic pose when the last controller ends (s); a body far
/// from that pose takes longer, so that the way back keeps under [`RELEASE_SPEED`].
const RELEASE: f64 = 0.3;

/// The peak speeds of the way back: of the root (m/s) and of any joint (rad/s).
const RELEASE_SPEED: (f64, f64) = (1.0, 3.0);

/// How far past where it was handed back the way back may carry the body on, as a share of
/// its distance from the kinematic pose (see `overshoot_capped`).
const RELEASE_OVERSHOOT: f64 = 0.15;

/// How far a pose is from the kinematic one at a moment: the root's displacement and each
/// joint's turn (rotation vectors, kinematic⁻¹ · pose).
#[derive(Debug, Clone)]
pub(super) struct Offset {
    pub(super) time: f64,
    pub(super) root: glam::Vec3,
    pub(super) turns: Vec<glam::Vec3>,
}

impl Offset {
    pub(super) fn between(time: f64, kinematic: &Pose, pose: &Pose) -> Offset {
        let turns = (kinematic.rotations.iter().zip(&pose.rotations))
            .map(|(k, p)| {
                let d = k.inverse() * *p;
                if d.w < 0.0 { -d } else { d }.to_scaled_axis()
            })
            .collect();
        Offset {
            time,
            root: pose.root - kinematic.root,
            turns,
        }
    }
}

/// The way back from the simulated pose to the kinematic one: the offset eases to nothing along
/// a cubic Hermite curve, starting at the last simulated offset with its rate of change, so the
/// body keeps its pose and its speed at the hand-over. It lasts [`RELEASE`] seconds, or longer
/// for a large offset: the curve's peak rate is 1.5 times the offset over the duration, kept
/// under [`RELEASE_SPEED`] (a body lying on the floor takes about 1.3 s to stand again).
#[derive(Debug, Clone)]
pub(super) struct Release {
    pub(super) from: Offset,
    /// How long it takes (s).
    pub(super) duration: f64,
    /// The offset's rate of change (per second) at the hand-over.
    pub(super) rate: Offset,
}

impl Release {
    pub(super) fn new(last: &Offset, before: Option<&Offset>) -> Release {
        let dt = before.map_or(0.0, |b| last.time - b.time);
        let rate = |a: glam::Vec3, b: glam::Vec3| {
            if dt > 0.0 {
                (a - b) / dt as f32
            } else {
                glam::Vec3::ZERO
            }
        };
        let rate = match before {
            Some(b) if dt > 0.0 => Offset {
                time: last.time,
                root: rate(last.root, b.root),
                turns: (last.turns.iter().zip(&b.turns))
                    .map(|(a, b)| rate(*a, *b))
                    .collect(),
            },
            _ => Offset {
                time: last.time,
                root: glam::Vec3::ZERO,
                turns: vec![glam::Vec3::ZERO; last.turns.len()],
            },
        };
        let turn = last
            .turns
            .iter()
            .map(|t| f64::from(t.length()))
            .fold(0.0, f64::max);
        let duration = RELEASE
            .max(1.5 * f64::from(last.root.length()) / RELEASE_SPEED.0)
            .max(1.5 * turn / RELEASE_SPEED.1);
        let mut rate = rate;
        rate.root = overshoot_capped(last.root, rate.root, duration, 0.05);
        for (r, t) in rate.turns.iter_mut().zip(&last.turns) {
            *r = overshoot_capped(*t, *r, duration, 0.1);
        }
        Release {
            from: last.clone(),
            duration,
            rate,
        }
    }

    /// Puts the eased offset on `pose` (the kinematic pose) at `now`; false once it is over.
    pub(super) fn apply(&self, now: f64, pose: &mut Pose) -> bool {
        let s = ((now - self.from.time) / self.duration).clamp(0.0, 1.0);
        if s >= 1.0 {
            return false;
        }
        // cubic Hermite weights of the start value and the start tangent (the end is zero)
        let h00 = (2.0 * s * s * s - 3.0 * s * s + 1.0) as f32;
        let h10 = ((s * s * s - 2.0 * s * s + s) * self.duration) as f32;
        pose.root += self.from.root * h00 + self.rate.root * h10;
        for (q, (r, dr)) in pose
            .rotations
            .iter_mut()
            .zip(self.from.turns.iter().zip(&self.rate.turns))
        {
            *q = (*q * Quat::from_scaled_axis(*r * h00 + *dr * h10)).normalize();
        }
        true
    }
}

/// The start rate of a way back from `offset` over `duration`, scaled down so that the curve
/// goes on past the offset by at most [`RELEASE_OVERSHOOT`] of it, or `least` (m or rad) if
/// that is more (a body handed back early keeps its speed): a body handed back while it
/// falls fast would otherwise keep falling, into the floor (from a 3 m/s fall the pelvis went
/// 0.45 m under it). The Hermite tangent weight peaks at 4/27 (a third of the way).
fn overshoot_capped(offset: glam::Vec3, rate: glam::Vec3, duration: f64, least: f64) -> glam::Vec3 {
    let away = rate.dot(offset).max(0.0) / offset.length().max(1e-6);
    let overshoot = f64::from(away) * duration * 4.0 / 27.0;
    let allowed = (RELEASE_OVERSHOOT * f64::from(offset.length())).max(least);
    if overshoot > allowed {
        rate * (allowed / overshoot) as f32
    } else {
        rate
    }
}
