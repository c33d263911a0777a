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
