//! A whole-body character standing in someone's way makes room when asked ("Social Path
//! Following" §5.2.3, the clearHumanObstacle half of the negotiation of space; the walker's half,
//! looking at the one in its way, is `crowd::negotiate::blocker` and [`Walker::asking`]). The
//! crowd snapshot says who asks whom; a character standing (no walk of its own under way) that
//! is asked by a walker within [`TRIGGER`] walks, at the negotiation's stepping speed, to the
//! nearest free spot that opens the walker's way (`crowd::negotiate::aside`), turned as it
//! stood, and walks back to its place, turned as before, once nobody asks any more. These walks
//! are the character's own: they send no feedback.
//!
//! [`Walker::asking`]: super::Walker::asking

use glam::Vec2;

use super::gait::{forward, Body};
use super::{Obstacles, Walk};
use crate::world::crowd::negotiate::{self, STEP_SPEED, TRIGGER};
use crate::world::crowd::{Agent, Crowd};

/// How long after the last ask one who stepped aside stays there at least (s): a walker's ask
/// comes and goes as it judges its way, and one that went back at each lapse never got aside.
pub const HOLD: f64 = 1.0;

/// Where a character that made room stood, whether it is aside now, for whom.
#[derive(Debug, Clone, PartialEq)]
pub struct Room {
    /// Its place (and facing) before it was first asked.
    pub home: Body,
    /// Whether it stands (or walks) aside; false once it walks back.
    pub aside: bool,
    /// The walker it made room for (its id; `None` when it was pressed off its place).
    pub walker: Option<String>,
    /// When it was last asked (s).
    pub asked: f64,
}

/// The walk a standing character at `body` (index `me` in `crowd`, radius `radius`, among
/// `obstacles`) sets off on at `now` to make room or to go back, given what it did so far
/// (`room`, updated); `None` when it keeps doing what it does. It goes back once nobody has
/// asked it for [`HOLD`] (or only another walker asks, whose way it now shuts) and the walker
/// it made room for has passed: more than [`TRIGGER`] from its place, or come to a stop clear
/// of it (a walker that stops near, at its own goal, would otherwise keep it away from its
/// place for good).
pub fn make_room(
    room: &mut Option<Room>,
    now: f64,
    (me, body, radius): (usize, Body, f32),
    crowd: &Crowd,
    obstacles: &Obstacles,
) -> Option<Walk> {
    let near = (crowd.askers(me)).find(|&i| crowd.agent(i).at.distance(body.at) <= TRIGGER);
    if let Some(r) = room.as_mut() {
        if crowd.askers(me).next().is_some() {
            r.asked = now;
        }
        if r.aside {
            let passing = (r.walker.as_deref().and_then(|w| crowd.index(w)))
                .is_some_and(|i| in_the_way(crowd.agent(i), r.home.at, radius));
            // (asked by another, whose way it now shuts, it goes back: one that stood aside
            // on a walker's goal, asked by that walker, stayed there until the walk gave up)
            let (mut theirs, mut another) = (false, false);
            for i in crowd.askers(me) {
                match r.walker.as_deref() == Some(crowd.id(i)) {
                    true => theirs = true,
                    false => another = true,
                }
            }
            let held = now - r.asked < HOLD && (theirs || !another);
            if held || passing {
                return None;
            }
            r.aside = false;
            return Some(walk_to(r.home.at, r.home));
        }
    }
    let walker = crowd.agent(near?);
    let home = room.as_ref().map_or(body, |r| r.home);
    let spot = negotiate::aside_in(crowd, (me, body.at, radius), walker, obstacles)?;
    *room = Some(Room {
        home,
        aside: true,
        walker: Some(crowd.id(near?).to_string()),
        asked: now,
    });
    Some(walk_to(spot, home))
}

/// Pressed further than this (m) off the place its last walk arrived at, a character standing
/// steps back to it ([`back_to`]); the pelvis sways about 2 cm to each side.
pub const PRESSED: f32 = 0.1;

/// A character standing at `body` pressed off `place`, where its last walk arrived (walkers
/// squeezing past push bodies apart): the way back to it at the stepping speed, turned as it
/// stood, and the room that says it is going back; `None` within [`PRESSED`] of it. (Whole-body
/// characters pressed off their places stood there for good: half of those counted as not
/// arrived in a random square of 300 had arrived, and stood 0.3 to 0.8 m off.)
pub fn back_to(place: Body, body: Body) -> Option<(Room, Walk)> {
    (body.at.distance(place.at) > PRESSED).then(|| {
        let room = Room {
            home: place,
            aside: false,
            walker: None,
            asked: f64::NEG_INFINITY,
        };
        (room, walk_to(place.at, place))
    })
}

/// Faster than this a walker still passes (m/s).
const MOVING: f32 = 0.05;

/// Whether `walker` still keeps one who made room from its place `home` (its radius `radius`):
/// within [`TRIGGER`] of it and moving, or standing where the two would touch.
fn in_the_way(walker: Agent, home: Vec2, radius: f32) -> bool {
    let d = walker.at.distance(home);
    d <= TRIGGER && (walker.velocity.length() > MOVING || d < walker.radius + radius)
}

/// A walk at the stepping speed to `spot`, ending turned as `home` faced.
fn walk_to(spot: Vec2, home: Body) -> Walk {
    Walk {
        goal: spot,
        speed: STEP_SPEED,
        running: false,
        face: Some(spot + forward(home.facing)),
        stepping: true,
        footsteps: false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_pressed_off_its_place_steps_back_to_it_turned_as_it_stood() {
        let place = Body {
            at: Vec2::new(1.0, 2.0),
            facing: 0.5,
        };
        let nudged = Body {
            at: Vec2::new(1.08, 2.0),
            facing: 0.9,
        };
        assert_eq!(back_to(place, nudged), None);
        let pressed = Body {
            at: Vec2::new(1.0, 2.4),
            facing: 0.9,
        };
        let (room, walk) = back_to(place, pressed).expect("a way back");
        assert_eq!((room.home, room.aside), (place, false));
        assert_eq!((walk.goal, walk.speed), (place.at, STEP_SPEED));
        assert!(walk.stepping && !walk.running);
        let face = walk.face.expect("turned") - place.at;
        assert!((face.x.atan2(face.y) - 0.5).abs() < 1e-5, "{face}");
    }
}
