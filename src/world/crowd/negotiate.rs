//! Negotiating space with people who stand in the way ("Social Path Following", §5.2.3,
//! "Negotiation of space"). A walker whose way is shut by someone standing — no room for its
//! body on either side of them, between walls and other standing people — looks at that person
//! steadily (the thesis' alertHumanObstacle: a passer-by asking for room gazes at the one in its
//! way). A standing person so looked at steps aside once the walker is near (its
//! clearHumanObstacle: not earlier, as an early move can close the space again) to the nearest
//! free spot that opens the way, and goes back when nobody asks any more. Only people standing
//! still and walls are weighed, as in the thesis: walkers make way for each other by avoidance,
//! except one stuck still (held back until fully impatient), whom others may ask like someone
//! standing, and who asks whoever stands on its line whether there is room beside them or not.

use glam::Vec2;

use super::{Agent, Crowd};
use crate::world::space::Obstacles;

/// How far ahead along its way a walker looks for someone standing in it (m).
pub const LOOKAHEAD: f32 = 2.0;
/// A standing person steps aside for a walker that asks within this of it (m).
pub const TRIGGER: f32 = 1.5;
/// Room kept beyond the bodies when fitting a body into a gap (m).
pub const ROOM: f32 = 0.05;
/// How fast a standing person steps aside or back (m/s).
pub const STEP_SPEED: f32 = 0.8;

/// Someone standing: where, how wide.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Standing {
    /// Its index in the crowd.
    pub index: usize,
    /// Where it stands.
    pub at: Vec2,
    /// Its body radius (m).
    pub radius: f32,
}

/// The standing person who shuts the way of a walker at `at` of radius `radius` going along
/// `way` (a unit vector), among `standing`, if there is one: the nearest ahead within
/// [`LOOKAHEAD`] whose body is on the walker's line, beside whom the walker fits on neither side
/// (or, when it `insist`s, whether it fits or not: a walker stuck behind someone asks them).
pub fn blocker(
    at: Vec2,
    way: Vec2,
    radius: f32,
    standing: &[Standing],
    walls: &Obstacles,
    insist: bool,
) -> Option<usize> {
    let side = way.perp();
    let ahead = (standing.iter())
        .map(|s| (s, (s.at - at).dot(way), (s.at - at).dot(side)))
        .filter(|&(s, along, across)| {
            along > 0.0 && along <= LOOKAHEAD && across.abs() < radius + s.radius + ROOM
        })
        .min_by(|a, b| a.1.total_cmp(&b.1))?;
    let (s, _, _) = ahead;
    if insist {
        return Some(s.index);
    }
    let others: Vec<(Vec2, f32)> = (standing.iter())
        .filter(|o| o.index != s.index)
        .map(|o| (o.at, o.radius))
        .collect();
    let beside = s.radius + radius + ROOM;
    let open = [1.0, -1.0]
        .iter()
        .any(|&sign| free(s.at + side * sign * beside, radius, ROOM, &others, walls));
    (!open).then_some(s.index)
}

/// Where a person standing at `home` (radius `radius`) steps to open the way of a walker at
/// `walker` (radius `walker_radius`) going along `way`: the nearest spot, away from `others`
/// (standing or walking) and walls, from which the walker passes beside it; `None` when there
/// is none within a metre.
pub fn aside(
    home: Vec2,
    radius: f32,
    walker: Vec2,
    way: Vec2,
    walker_radius: f32,
    others: &[(Vec2, f32)],
    walls: &Obstacles,
) -> Option<Vec2> {
    let side = way.perp();
    let across = (home - walker).dot(side);
    // its own side of the walker's line first (on the line: the walker's left, so that the
    // walker keeps to its right)
    let first = if across < -0.01 { -1.0 } else { 1.0 };
    let clear = radius + walker_radius + ROOM;
    let mut spots: Vec<Vec2> = Vec::new();
    for sign in [first, -first] {
        let shift = (clear - across * sign).max(0.0);
        for back in [0.0, 0.3, 0.6] {
            spots.push(home + side * sign * shift + way * back);
        }
    }
    spots.sort_by(|a, b| a.distance(home).total_cmp(&b.distance(home)));
    (spots.into_iter())
        .find(|&spot| spot.distance(home) <= 1.0 && free(spot, radius, 0.02, others, walls))
}

/// [`aside`] for the one at index `me` of `crowd` (standing at `home`, radius `radius`) and the
/// `walker` asking it, among everyone else of the crowd within 2 m.
pub fn aside_in(
    crowd: &Crowd,
    (me, home, radius): (usize, Vec2, f32),
    walker: Agent,
    walls: &Obstacles,
) -> Option<Vec2> {
    let way = (home - walker.at).normalize_or_zero();
    let mut near = Vec::new();
    crowd.near(home, 2.0, &mut near);
    let others: Vec<(Vec2, f32)> = (near.into_iter())
        .filter(|&i| i != me)
        .map(|i| crowd.agent(i))
        .map(|a| (a.at, a.radius))
        .collect();
    aside(home, radius, walker.at, way, walker.radius, &others, walls)
}

/// Whether a body of `radius` at `spot` keeps `room` from each of `others` (place, radius) and
/// does not touch a wall.
fn free(spot: Vec2, radius: f32, room: f32, others: &[(Vec2, f32)], walls: &Obstacles) -> bool {
    (others.iter()).all(|&(o, r)| o.distance(spot) >= radius + r + room)
        && walls.clearance(spot, radius + 0.01) >= radius
}

#[cfg(test)]
mod tests {
    use super::*;

    fn standing(list: &[(f32, f32)]) -> Vec<Standing> {
        (list.iter().enumerate())
            .map(|(index, &(x, z))| Standing {
                index,
                at: Vec2::new(x, z),
                radius: 0.25,
            })
            .collect()
    }

    #[test]
    fn one_person_in_the_open_leaves_room_two_shoulder_to_shoulder_do_not() {
        let walls = Obstacles::default();
        let (at, way) = (Vec2::ZERO, Vec2::Y);
        let one = standing(&[(0.1, 1.5)]);
        assert_eq!(blocker(at, way, 0.25, &one, &walls, false), None);
        // … unless the walker is stuck behind them: it asks all the same
        assert_eq!(blocker(at, way, 0.25, &one, &walls, true), Some(0));
        // a gap of 0.3 m on either side of the middle one: too narrow for a body 0.5 m wide
        let row = standing(&[(-0.8, 1.5), (0.0, 1.5), (0.8, 1.5)]);
        assert_eq!(blocker(at, way, 0.25, &row, &walls, false), Some(1));
        // beyond the lookahead, or off the line: nobody
        let far = standing(&[(-0.8, 2.5), (0.0, 2.5), (0.8, 2.5)]);
        assert_eq!(blocker(at, way, 0.25, &far, &walls, false), None);
        // a wall beside one person shuts the way too
        let wall = Obstacles::new(vec![crate::world::space::Obstacle {
            shape: crate::world::space::Shape::Box {
                min: Vec2::new(0.3, 0.0),
                max: Vec2::new(3.0, 3.0),
            },
            height: 1.0,
        }]);
        let lone = standing(&[(-0.7, 1.5)]);
        assert_eq!(blocker(at, way, 0.25, &lone, &wall, false), None);
        let middle = standing(&[(-0.2, 1.5), (-1.0, 1.5)]);
        assert_eq!(blocker(at, way, 0.25, &middle, &wall, false), Some(0));
    }

    #[test]
    fn the_one_in_the_way_steps_to_a_free_spot_that_opens_it() {
        let walls = Obstacles::default();
        let (walker, way) = (Vec2::ZERO, Vec2::Y);
        let home = Vec2::new(0.1, 1.5);
        // its neighbour on the right (x < 0) is close: it steps to the left (x > 0), its side
        let others = [(Vec2::new(-0.7, 1.5), 0.25)];
        let spot = aside(home, 0.25, walker, way, 0.25, &others, &walls).unwrap();
        assert!((spot.x - 0.55).abs() < 1e-5 && spot.y == 1.5, "{spot}");
        // hemmed in on its side: the other side, or back along the way
        let others = [(Vec2::new(0.9, 1.5), 0.25), (Vec2::new(-0.7, 1.5), 0.25)];
        let spot = aside(home, 0.25, walker, way, 0.25, &others, &walls).unwrap();
        for (o, r) in others {
            assert!(o.distance(spot) >= 0.25 + r, "{spot}");
        }
        assert!(
            (spot - walker).dot(way.perp()).abs() >= 0.55 - 1e-5,
            "{spot}"
        );
        // nowhere to go
        let ring: Vec<(Vec2, f32)> = (0..12)
            .map(|k| {
                let a = std::f32::consts::TAU * k as f32 / 12.0;
                (home + Vec2::new(a.sin(), a.cos()) * 0.55, 0.25)
            })
            .collect();
        assert_eq!(aside(home, 0.25, walker, way, 0.25, &ring, &walls), None);
    }
}
