//! Where a walk goes: a locomotion target read against the world. A target is `x,z` in world
//! metres, a placed character (the walk stops [`SOCIAL_DISTANCE`] from them, on the walker's
//! side, turned to face them), or a point of the world (one moving along a path is where the
//! path has it now).

use glam::Vec2;

use crate::world::World;

/// How far from another character a walk to them stops (m).
pub const SOCIAL_DISTANCE: f32 = 1.2;

/// `x,z` in metres, if `target` is written so.
pub fn coordinates(target: &str) -> Option<Vec2> {
    let (x, z) = target.split_once(',')?;
    let (x, z) = (x.trim().parse::<f32>().ok()?, z.trim().parse::<f32>().ok()?);
    let limit = crate::world::MAX_COORDINATE as f32;
    (x.is_finite() && z.is_finite() && x.abs() <= limit && z.abs() <= limit)
        .then(|| Vec2::new(x, z))
}

/// Where a walk to `target` goes in `world` for walker `me` standing at `from`, and what it
/// faces there; `None` for a target the world does not have.
pub fn resolve(world: &World, me: &str, target: &str, from: Vec2) -> Option<(Vec2, Option<Vec2>)> {
    if let Some(p) = coordinates(target) {
        return Some((p, None));
    }
    let is_character = target != me && world.is_placed(target) && !world.has_point(target);
    if is_character {
        let p = world.placement(target).position;
        let them = Vec2::new(p.x, p.z);
        let away = (from - them).normalize_or(Vec2::Y);
        return Some((them + away * SOCIAL_DISTANCE, Some(them)));
    }
    let p = world.get(target)?;
    Some((Vec2::new(p.x, p.z), None))
}

/// Longest lead a pursuit takes (s): a target seen moving is aimed at where it will be in the
/// time the walker needs to reach it, at most this.
pub const MAX_LEAD: f32 = 3.0;
/// A target seen moving faster than this (m/s) between two looks has jumped (a host placing
/// it, a path's jump): it is aimed at where it is, not led.
pub const MAX_TARGET_SPEED: f32 = 12.0;
/// How long the estimate of a target's velocity takes to follow a change (s): frame-to-frame
/// differences are noisy (a path's corners, a host's jumps), the low-pass keeps the aim steady.
pub const VELOCITY_SMOOTHING: f64 = 0.3;

/// Reynolds' pursuit of a moving target: its velocity estimated from where it is seen, frame
/// by frame, and the point a pursuer aims at (where the target will be when the pursuer could
/// reach it). A target that stops is aimed at where it stands.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Pursuit {
    last: Option<(f64, Vec2)>,
    velocity: Vec2,
}

impl Pursuit {
    /// The target is at `at` at time `t`.
    pub fn observe(&mut self, t: f64, at: Vec2) {
        if let Some((t0, p0)) = self.last {
            let dt = t - t0;
            if dt <= 0.0 {
                return;
            }
            let seen = (at - p0) / dt as f32;
            if !seen.is_finite() || seen.length() > MAX_TARGET_SPEED {
                self.velocity = Vec2::ZERO;
                self.last = Some((t, at));
                return;
            }
            let k = 1.0 - (-dt / VELOCITY_SMOOTHING).exp();
            self.velocity += (seen - self.velocity) * k as f32;
            if !self.velocity.is_finite() {
                self.velocity = Vec2::ZERO;
            }
        }
        self.last = Some((t, at));
    }

    /// The target's estimated velocity (m/s).
    pub fn velocity(&self) -> Vec2 {
        self.velocity
    }

    /// Where a pursuer at `from` going at `speed` aims for a target whose goal is `goal`: the
    /// goal moved on by the target's velocity over the time to reach it (at most
    /// [`MAX_LEAD`]); the goal itself when the target is about still.
    pub fn aim(&self, goal: Vec2, from: Vec2, speed: f32) -> Vec2 {
        if self.velocity.length() < 0.05 {
            return goal;
        }
        let lead = (from.distance(goal) / speed.max(0.1)).min(MAX_LEAD);
        goal + self.velocity * lead
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pursuit_learns_a_steady_velocity_and_leads_by_the_time_to_reach() {
        let mut p = Pursuit::default();
        for k in 0..120 {
            let t = k as f64 / 60.0;
            p.observe(t, Vec2::new(t as f32, 5.0));
        }
        assert!(p.velocity().distance(Vec2::X) < 0.02, "{}", p.velocity());
        // 5 m away at 1 m/s: 5 s, capped at the longest lead
        let aim = p.aim(Vec2::new(2.0, 5.0), Vec2::new(2.0, 0.0), 1.0);
        assert!(aim.distance(Vec2::new(2.0 + MAX_LEAD, 5.0)) < 0.1, "{aim}");
        // 1 m away at 2 m/s: half a second ahead
        let aim = p.aim(Vec2::new(2.0, 5.0), Vec2::new(2.0, 4.0), 2.0);
        assert!(aim.distance(Vec2::new(2.5, 5.0)) < 0.02, "{aim}");
        // it stops: the aim comes back to where it stands
        for k in 120..300 {
            p.observe(k as f64 / 60.0, Vec2::new(2.0, 5.0));
        }
        assert_eq!(
            p.aim(Vec2::new(2.0, 5.0), Vec2::ZERO, 1.0),
            Vec2::new(2.0, 5.0)
        );
    }
}
