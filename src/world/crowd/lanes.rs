//! Keeping right in a passage: a walker in a corridor (walls on both sides, at most
//! [`PASSAGE`] apart, and wide enough for two to pass each other) who sees people coming the other way ahead of it steers toward the
//! middle of the right half of the passage, so that the two ways form lanes instead of meeting
//! face to face across the whole width (two blocks of a hundred did, and stood pressed against
//! each other). In the open the avoidance's own preference for the right is enough.

use glam::Vec2;

use super::snapshot::Crowd;
use crate::world::space::narrows::WIDEST;
use crate::world::space::Obstacles;

/// Walls on both sides at most this far apart (m) make a passage.
pub const PASSAGE: f32 = 6.0;
/// Someone coming the other way within this far ahead (m) …
pub const AHEAD: f32 = 10.0;
/// … and this far to either side of one's line (m) is oncoming.
pub const BESIDE: f32 = 2.0;
/// Someone coming toward one faster than this (m/s, along one's way) is coming the other way.
pub const TOWARD: f32 = 0.2;
/// Someone coming the other way on one's line this near (m) is face to face with one: one
/// steps to the right.
pub const FACE_TO_FACE: f32 = 1.5;
/// How much more a walker face to face with someone coming the other way turns right (as
/// [`GAIN`] for a metre off its lane): a side step.
pub const SIDESTEP: f32 = 1.5;
/// Within this of its goal (m along its way) a walker keeps to no lane: it makes for its
/// place, which may lie on the other side.
pub const RELEASE: f32 = 2.0;
/// The half-width of the probe that looks for the walls beside (m).
const PROBE: f32 = 0.05;
/// How steeply a walker makes for its lane: its way turns right by this much per metre it is
/// off the lane's middle (at most one metre's worth).
pub const GAIN: f32 = 0.6;

/// How far (m, up to `max`) a body of `radius` at `here` could go in direction `dir` before it
/// met an obstacle, in steps of 0.2 m.
fn free(obstacles: &Obstacles, here: Vec2, dir: Vec2, radius: f32, max: f32) -> f32 {
    let mut d = 0.0;
    while d < max {
        let next = (d + 0.2).min(max);
        if !obstacles.segment_clear(here + dir * d, here + dir * next, radius) {
            return d;
        }
        d = next;
    }
    max
}

/// How near (m ahead) the nearest of the `crowd` coming the other way is, ahead of walker `me`
/// at `here` going `way` (unit) within [`AHEAD`] and [`BESIDE`] of its line: walking toward
/// it, or standing (held in a press) on a walk the other way. With it, whether one of them is
/// face to face with it: on its line (within a body's width) and within [`FACE_TO_FACE`].
pub fn oncoming(crowd: &Crowd, me: Option<usize>, here: Vec2, way: Vec2) -> Option<(f32, bool)> {
    let right = Vec2::new(-way.y, way.x);
    let mut near = Vec::new();
    crowd.near(here, AHEAD, &mut near);
    let coming = (near.into_iter().filter(|&i| Some(i) != me)).filter_map(|i| {
        let a = crowd.agent(i);
        let d = a.at - here;
        let (ahead, aside) = (d.dot(way), d.dot(right).abs());
        let against =
            a.velocity.dot(way) < -TOWARD || crowd.way(i).is_some_and(|w| w.dot(way) < -0.5);
        (ahead > 0.0 && ahead < AHEAD && aside < BESIDE && against).then_some((ahead, aside))
    });
    coming.fold(None, |found, (ahead, aside)| {
        let facing = aside < 0.5 && ahead < FACE_TO_FACE;
        Some(match found {
            None => (ahead, facing),
            Some((d, f)) => (d.min(ahead), f || facing),
        })
    })
}

/// The way (unit) a walker of `radius` at `here` going `way` (unit) takes to keep to the right
/// half of the passage it is in (stepping aside to the right when `face_to_face` with someone
/// coming the other way), or `None` in the open (walls on both sides further than [`PASSAGE`]
/// apart).
pub fn keep_right(
    obstacles: &Obstacles,
    here: Vec2,
    way: Vec2,
    radius: f32,
    face_to_face: bool,
) -> Option<Vec2> {
    // (facing +z the right hand is −x)
    let right = Vec2::new(-way.y, way.x);
    // (measured with a thin probe, then less the body: one beside the end of a wall across its
    // way, at a door's mouth, is in no passage)
    let to_right = (free(obstacles, here, right, PROBE, PASSAGE) - (radius - PROBE)).max(0.0);
    let to_left = (free(obstacles, here, -right, PROBE, PASSAGE) - (radius - PROBE)).max(0.0);
    // (too narrow for two to pass each other, it is a narrow: they take turns there)
    let width = to_right + to_left + radius * 2.0;
    if width >= PASSAGE || width <= WIDEST {
        return None;
    }
    // the middle of the right half, measured to the right of here
    let off = (to_right - to_left) / 2.0 + (to_right + to_left) / 4.0;
    let step = if face_to_face && to_right > 0.2 {
        SIDESTEP
    } else {
        0.0
    };
    Some((way + right * (off.clamp(-1.0, 1.0) * GAIN + step)).normalize())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::world::space::Obstacle;

    /// A corridor 4 m wide along x.
    fn corridor() -> Obstacles {
        Obstacles::new(vec![
            Obstacle::wall(Vec2::new(-20.0, -2.0), Vec2::new(20.0, -2.0)),
            Obstacle::wall(Vec2::new(-20.0, 2.0), Vec2::new(20.0, 2.0)),
        ])
    }

    #[test]
    fn in_a_corridor_each_way_makes_for_its_right_half() {
        // going +x the right hand is +z (facing +z it is −x): the lane's middle is at
        // z = 0.8, halfway between the middle and where a body touches the wall
        let east =
            keep_right(&corridor(), Vec2::new(0.0, 0.0), Vec2::X, 0.25, false).expect("a lane");
        assert!(east.y > 0.3 && east.x > 0.5, "{east}");
        let west =
            keep_right(&corridor(), Vec2::new(0.0, 0.0), -Vec2::X, 0.25, false).expect("a lane");
        assert!(west.y < -0.3 && west.x < -0.5, "{west}");
        // in its lane, it goes straight on (to the 0.2 m the sides are measured in)
        let lane =
            keep_right(&corridor(), Vec2::new(0.0, 0.8), Vec2::X, 0.25, false).expect("a lane");
        assert!(lane.y.abs() < 0.1, "{lane}");
    }

    #[test]
    fn in_the_open_there_is_no_lane() {
        let open = Obstacles::default();
        assert!(keep_right(&open, Vec2::ZERO, Vec2::X, 0.25, false).is_none());
        // across the corridor, its walls are ahead and behind: no passage either
        assert!(keep_right(&corridor(), Vec2::ZERO, Vec2::Y, 0.25, false).is_none());
        // in a door, too narrow for two, they take turns instead
        let door = Obstacles::new(vec![
            Obstacle::wall(Vec2::new(-0.45, 0.0), Vec2::new(-0.45, 0.2)),
            Obstacle::wall(Vec2::new(0.45, 0.0), Vec2::new(0.45, 0.2)),
        ]);
        assert!(keep_right(&door, Vec2::new(0.0, 0.1), Vec2::Y, 0.25, false).is_none());
    }

    #[test]
    fn only_those_ahead_coming_toward_one_are_oncoming() {
        let crowd = |x: f32, z: f32, vx: f32, way: Option<Vec2>| {
            let a = |at: Vec2, vx: f32| crate::world::crowd::Agent {
                at,
                velocity: Vec2::new(vx, 0.0),
                radius: 0.25,
            };
            let mut c = Crowd::unnamed(0.0, vec![a(Vec2::ZERO, 1.2), a(Vec2::new(x, z), vx)]);
            c.set_ways(way.map(|w| (1, w)));
            c
        };
        let on = |c: Crowd| oncoming(&c, Some(0), Vec2::ZERO, Vec2::X).is_some();
        assert!(on(crowd(5.0, 1.0, -1.2, None)));
        assert!(!on(crowd(5.0, 1.0, 1.2, None)), "going the same way");
        assert!(!on(crowd(-3.0, 0.0, -1.2, None)), "behind");
        assert!(!on(crowd(5.0, 3.0, -1.2, None)), "well aside");
        assert!(!on(crowd(5.0, 0.0, 0.0, None)), "standing, going nowhere");
        assert!(
            on(crowd(5.0, 0.0, 0.0, Some(-Vec2::X))),
            "held in a press the other way"
        );
    }
}
