//! A walker's footstep mode (`bmlt:planner="footsteps"`): instead of steering, the walk is a
//! sequence of footsteps chosen one at a time by [`crate::world::locomotion::footsteps`]. At each
//! footfall the next placement is chosen from where the feet are; the body then moves to
//! stand midway between the feet at the walk's speed (a longer step takes longer), turning
//! with it, and the gait plays the steps. When the trailing foot can close within
//! [`ARRIVE`] of the goal, the walk closes its feet there; when no step lowers the energy, it
//! stops where it is (a local minimum: stuck). Under load the fan is thinned: all walkers
//! share a budget of [`BUDGET`] samples a 60 Hz frame, counting those of the crowd that plan
//! in one frame on average; and a walk among others sets off staggered by its place in the
//! crowd over one step, so that walks started together do not all plan in the same frames.

use glam::Vec2;

use crate::world::locomotion::footsteps::{self, Fan, Feet, Footstep};
use crate::world::locomotion::gait;
use crate::world::nets::behaviour::{BehaviourNet, Surroundings};
use crate::world::space::{path, Obstacles};

/// Samples the walkers of a crowd may take together in one 60 Hz frame.
pub const BUDGET: usize = 1500;

/// A footstep walk arrives when its body can stand within this of the goal (m).
pub const ARRIVE: f32 = 0.3;

/// How far from obstacles the walk keeps (m), beyond the body's radius.
pub const CLEAR: f32 = 1.0;

/// How far from other walkers (m).
pub const PERSONAL: f32 = 1.0;

/// The fastest the body moves, as a multiple of the walk's speed.
pub const TOP_SPEED: f32 = 1.25;

/// How fast the body's velocity changes at most (m/s²), as a walker's steering lets it.
pub const ACCELERATION: f32 = 2.5;

/// Most turn of one step (rad).
pub const MAX_TURN: f32 = 0.8;

/// Where a walk whose route bends round obstacles aims: this far (m) along the route ahead of
/// the body, so that it starts turning before a corner and spreads the turn over steps.
pub const LOOKAHEAD: f32 = 2.0;

/// A footstep walk under way.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Plan {
    feet: Feet,
    net: BehaviourNet,
    walk_node: usize,
    fan: Fan,
    goal: Vec2,
    /// The route round the obstacles and the segment of it the body has reached.
    route: Vec<Vec2>,
    progress: usize,
    /// Where the body is headed now, its heading there, and when it gets there.
    next: Option<(Vec2, f32, f64)>,
    /// Where the body stood after the last step, and its heading.
    last: (Vec2, f32),
    step_time: f64,
    /// Whether the last step closed the feet at the goal.
    closing: bool,
    /// The fastest the body moves (m/s).
    top_speed: f32,
    /// The walk's speed (m/s).
    speed: f32,
    /// Whether the walk stopped short of its goal: no step led anywhere better.
    pub stuck: bool,
    /// When it sets off (staggered among others), once its first call has said.
    sets_off: Option<f64>,
    /// Samples its last plan took.
    pub samples: usize,
}

/// A walker's place in its crowd: its index and how many there are.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(super) struct Place {
    pub index: usize,
    pub count: usize,
}

impl Plan {
    /// A walk from `body` facing `facing` to `goal` at `speed`, keeping its distance from
    /// `obstacles` (a goal no route reaches is aimed at straight).
    pub fn new(
        body: Vec2,
        facing: f32,
        goal: Vec2,
        speed: f32,
        running: bool,
        radius: f32,
        obstacles: &Obstacles,
    ) -> Plan {
        let (net, walk_node) = footsteps::walking_net(goal, ARRIVE, radius + CLEAR, PERSONAL);
        let step = gait::step_length(speed, running).max(0.2);
        Plan {
            feet: Feet::standing(body, facing),
            net,
            walk_node,
            fan: Fan::new(step, MAX_TURN, 9),
            goal,
            route: path::plan(obstacles, body, goal, radius + CLEAR)
                .unwrap_or_else(|_| vec![body, goal]),
            progress: 0,
            next: None,
            last: (body, facing),
            step_time: 60.0 / gait::cadence(speed, running) as f64,
            closing: false,
            top_speed: speed * TOP_SPEED,
            speed,
            stuck: false,
            sets_off: None,
            samples: 0,
        }
    }

    /// The velocity to walk at `time` from `here`, or `None` when the walk is over (arrived,
    /// or no step leads anywhere better).
    pub fn velocity(
        &mut self,
        time: f64,
        here: Vec2,
        obstacles: &Obstacles,
        walkers: &[Vec2],
        radius: f32,
        place: Place,
    ) -> Option<Vec2> {
        let sets_off = *self.sets_off.get_or_insert_with(|| {
            time + footsteps::stagger(place.index, place.count, self.step_time)
        });
        if time < sets_off - 1e-9 {
            return Some(Vec2::ZERO);
        }
        if self.next.is_none_or(|(_, _, due)| time >= due - 1e-9) {
            if self.closing {
                // the body stands midway between the closed feet
                let (target, ..) = self.next?;
                if here.distance(target) <= 0.02 {
                    return None;
                }
                // braking to stand there (not creeping up on it)
                let d = here.distance(target);
                let pace = (2.0 * ACCELERATION * d).sqrt().min(self.speed);
                return Some((target - here) / d * pace);
            }
            // those of the crowd that plan in one frame, on average
            let planning = (place.count as f64 / 60.0 / self.step_time).ceil().max(1.0);
            self.samples = footsteps::allot(BUDGET, planning as usize, self.fan.len());
            let Some(step) = self.choose(obstacles, walkers, radius) else {
                self.stuck = true;
                return None;
            };
            self.feet = self.feet.after(&step);
            self.last = (step.body, step.heading);
            let (target, heading) = if self.feet.body().distance(self.goal) <= ARRIVE {
                // the trailing foot closes beside the one just planted
                self.closing = true;
                (self.feet.body(), step.heading)
            } else {
                (step.body, step.heading)
            };
            // the step takes as long as the body needs at the walk's speed (longer steps at a
            // slower cadence: the walk keeps its speed), within a cadence of 75 to 170 a minute
            let span = (here.distance(target) / self.speed) as f64;
            let step_time = span.clamp(60.0 / 170.0, 60.0 / 75.0);
            self.next = Some((target, heading, time + step_time));
        }
        let (target, _, due) = self.next?;
        let left = (due - time).max(1e-3) as f32;
        // (never faster than a brisk version of the walk: a foot left behind would drag)
        Some(((target - here) / left).clamp_length_max(self.top_speed))
    }

    /// The next step: the least energy of the fan, if it is less than standing where the
    /// last step left the body.
    fn choose(&mut self, obstacles: &Obstacles, walkers: &[Vec2], radius: f32) -> Option<Footstep> {
        self.aim();
        let here = Surroundings {
            at: self.last.0,
            heading: self.last.1,
            obstacles,
            walkers,
        };
        let (net, walk) = (&mut self.net, self.walk_node);
        footsteps::choose(
            net,
            walk,
            &self.feet,
            &self.fan,
            self.samples,
            &here,
            radius,
        )
    }

    /// Points the net's goal sensor where the walk goes next: along a route that bends round
    /// obstacles, [`LOOKAHEAD`] ahead on it until the body has passed its last bend; else the
    /// goal itself. (Aimed at the goal across a wall, the walk slid along the wall and swung
    /// round its end in one step.)
    fn aim(&mut self) {
        let (carrot, segment) = path::carrot(&self.route, self.last.0, self.progress, LOOKAHEAD);
        self.progress = segment;
        let bends_ahead = segment + 2 < self.route.len();
        let at = if bends_ahead { carrot } else { self.goal };
        self.net.aim(footsteps::GOAL_SENSOR, at);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn among_many_the_fan_is_thinned_and_walks_set_off_staggered() {
        let obstacles = Obstacles::default();
        let go = |place: Place| {
            let goal = Vec2::new(0.0, 10.0);
            let mut p = Plan::new(Vec2::ZERO, 0.0, goal, 1.3, false, 0.25, &obstacles);
            let moving = (0..240).map(|k| k as f64 / 240.0).find(|&t| {
                p.velocity(t, Vec2::ZERO, &obstacles, &[], 0.25, place)
                    .is_some_and(|v| v.length() > 0.0)
            });
            (moving.unwrap(), p.samples)
        };
        let full = Fan::new(0.69, MAX_TURN, 9).len();
        // alone: at once, the whole fan
        assert_eq!(go(Place { index: 0, count: 1 }), (0.0, full));
        // third of four: a half step later (0.53 s a step at 1.3 m/s)
        let (t, _) = go(Place { index: 2, count: 4 });
        assert!(
            (t - 0.5 * 60.0 / gait::cadence(1.3, false) as f64).abs() < 1.0 / 240.0,
            "{t}"
        );
        // among 20 000: fewer samples, never fewer than the three lengths
        let (_, n) = go(Place {
            index: 0,
            count: 20_000,
        });
        assert!((3..full).contains(&n), "{n} of {full}");
    }
}
