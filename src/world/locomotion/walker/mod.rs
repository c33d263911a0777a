//! One walking character: a steered vehicle (seek along the route, arrive at its end, avoid
//! obstacles, combined by priority), a facing that turns toward the direction of travel at a
//! human rate (on the spot first when the goal is behind), the gait, and the moments a walk's
//! sync points happen. It steps at its own fixed rate ([`STEP`]), so where it is at a time does
//! not depend on how often the host asks. Obstacles are a hard limit too: after each step the
//! body is pushed out of any obstacle it came nearer than its radius to (steering cuts corners
//! a little; the push keeps the radius exactly).

use glam::{Vec2, Vec3};

use super::among::neighbours;
pub use super::among::Others;
use super::gait::{angle_diff, Body, Gait};
use super::steering::{ArriveParams, Behaviour, Combine, Part, Steering, Vehicle};
use crate::world::crowd::doorway::Passing;
use crate::world::crowd::{Avoider, Profile};
use crate::world::space::path::{self, PathError};
use crate::world::space::Obstacles;

pub use super::STEP;
/// How often a walker among others checks that the point its route seeks is still in sight
/// (steps: once a second).
pub const REPLAN_EVERY: i64 = 240;
/// How fast the body turns toward its direction of travel (rad/s).
pub const TURN_RATE: f32 = 2.0;
/// How fast the body turns on the spot (rad/s): about 45° a step, the most a planted foot lets
/// the leg twist.
pub const TURN_ON_THE_SPOT: f32 = 1.0;
/// How long the rate the landing feet are turned ahead for takes to follow the body's (s).
const TURN_EASE: f32 = 0.2;

/// A goal more than this off the facing (rad) is turned to on the spot before walking.
pub const TURN_FIRST: f32 = 0.8;
/// How hard a halted walk brakes (m/s²).
pub const HALT_DECELERATION: f32 = 1.6;
/// Within this distance of its goal (m) a walk has arrived: it brakes to a stop there.
pub const STOP_RADIUS: f32 = 0.04;
/// Held still this near its goal, a walker has arrived (m).
pub const NEAR_ENOUGH: f32 = 0.1;
/// A walk comes nearer its goal when it comes this much (m) nearer than it had been: who
/// drives the walk may give it more time while it does.
pub const NEARER: f32 = 0.5;
/// Margin kept from obstacles beyond the body's radius when planning (m).
pub const PLAN_MARGIN: f32 = 0.08;

/// A walk: where to, how fast, what to face at the end.
#[derive(Debug, Clone, PartialEq)]
pub struct Walk {
    /// The goal (x, z).
    pub goal: Vec2,
    /// Cruising speed (m/s).
    pub speed: f32,
    /// Running (flight phase, other cadence).
    pub running: bool,
    /// A point to turn to once arrived.
    pub face: Option<Vec2>,
    /// A few steps to one side or back, keeping the facing (making room: `locomotion::room`),
    /// rather than turning to walk the way.
    pub stepping: bool,
    /// Walks by footsteps chosen one at a time (`locomotion::footsteps`) instead of steering.
    pub footsteps: bool,
}

/// When a walk's sync points happened (global times).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Moments {
    /// First weight shift.
    pub start: Option<f64>,
    /// Cruising speed reached.
    pub ready: Option<f64>,
    /// Final deceleration began.
    pub relax: Option<f64>,
    /// Standing still, both feet planted.
    pub end: Option<f64>,
}

#[derive(Debug, Clone, PartialEq)]
struct Active {
    walk: Walk,
    route: Vec<Vec2>,
    steering: Steering,
    moments: Moments,
    /// Whether the vehicle has stopped (the feet may still be closing).
    stopped: bool,
    /// Whether it is halting where it is (interrupted, or braking at its goal).
    halting: bool,
    /// The footsteps of a footstep walk.
    plan: Option<Box<footstep_mode::Plan>>,
}

/// A walking character (see the module documentation).
#[derive(Debug, Clone, PartialEq)]
pub struct Walker {
    /// The steered body.
    pub vehicle: Vehicle,
    /// Where it faces (rad about +y from +z).
    pub facing: f32,
    /// Its gait.
    pub gait: Gait,
    /// Its body radius (m).
    pub radius: f32,
    /// The time of its last step: `origin` + `steps` × [`STEP`], counted rather than summed so
    /// that it is the same however the steps were grouped into frames.
    pub time: f64,
    origin: f64,
    steps: u64,
    /// How its steering behaviours combine (prioritised by default).
    pub combine: Combine,
    /// How it avoids other people.
    pub profile: Profile,
    /// Its avoidance state, and the velocity it chose among others (none when nobody is in
    /// its way).
    avoider: Avoider,
    chosen: Option<Vec2>,
    /// Where the person standing in its way stands, whom it asks for room by looking at them
    /// (`crowd::negotiate`), while they shut its way.
    pub asking: Option<Vec2>,
    /// The narrow door its route goes through next, if one is near (`crowd::doorway`).
    pub passing: Option<Passing>,
    /// Where it waits for its turn at that door, when it is not its turn.
    pub waiting: Option<Vec2>,
    /// The way its walk goes (unit), while it walks among others.
    pub heading: Option<Vec2>,
    /// The way it takes to keep to the right half of a passage with people coming the other
    /// way (`crowd::lanes`), when it does.
    pub lane: Option<Vec2>,
    /// How long the walk under way has waited for its turn at doors (s): a person in a queue
    /// does not give up for the time the queue takes.
    pub queued: f64,
    /// The nearest the walk under way has come to its goal (m), and when it came [`NEARER`]
    /// than before.
    pub nearest: (f32, f64),
    /// Where the walker stands for whom it makes room (`locomotion::room`), whom it watches.
    pub watching: Option<Vec2>,
    /// How much it attends to the one it asks (0 to 1, eased in and out over a quarter of a
    /// second), and where that one last stood.
    attention: f32,
    asked_at: Vec2,
    active: Option<Active>,
    /// How far short of its goal the last footstep walk stopped, when no step led anywhere
    /// better (taken by whoever reports it).
    pub stuck: Option<f32>,
    /// Where the body came to a stop on its last walk, before anyone pressed it on (its place
    /// when the walk has ended: the walk ends only once the feet have closed).
    pub stopped_at: Option<Vec2>,
}

/// How far the one it looks at may have moved between two steps for it to be followed (m).
const FOLLOW: f32 = 0.2;

impl Walker {
    /// Standing at `at` facing `facing`, at time `time`.
    pub fn new(at: Vec2, facing: f32, radius: f32, time: f64) -> Walker {
        let body = Body { at, facing };
        Walker {
            vehicle: Vehicle::new(Vec3::new(at.x, 0.0, at.y), 0.2, 0.5, 1.3),
            facing,
            gait: Gait::standing(body),
            radius,
            time,
            origin: time,
            steps: 0,
            combine: Combine::Prioritised,
            profile: Profile::default(),
            avoider: Avoider::starting_at(at),
            chosen: None,
            asking: None,
            passing: None,
            waiting: None,
            heading: None,
            lane: None,
            queued: 0.0,
            nearest: (f32::INFINITY, time),
            watching: None,
            attention: 0.0,
            asked_at: at,
            active: None,
            stuck: None,
            stopped_at: None,
        }
    }

    /// Where the body is now.
    pub fn body(&self) -> Body {
        Body {
            at: Vec2::new(self.vehicle.position.x, self.vehicle.position.z),
            facing: self.facing,
        }
    }

    /// Velocity (x, z).
    pub fn velocity(&self) -> Vec2 {
        Vec2::new(self.vehicle.velocity.x, self.vehicle.velocity.z)
    }

    /// The moments of the walk under way.
    pub fn moments(&self) -> Option<Moments> {
        self.active.as_ref().map(|a| a.moments)
    }

    /// How far the walk under way has still to go along its route (m).
    pub fn remaining(&self) -> f32 {
        self.active
            .as_ref()
            .map_or(0.0, |a| path::length(&a.route_from(self.body().at)))
    }

    /// How far off its facing the way goes 1.5 m ahead along the route (0 when not walking;
    /// rad, positive to the left): where the head leads the turn.
    pub fn look_ahead(&self) -> f32 {
        let walking = self.active.as_ref().is_some_and(|a| !a.stopped);
        if walking {
            self.route_ahead(self.body().at)
        } else {
            0.0
        }
    }

    /// Whom it attends to: where the one it asks for room, or the walker it makes room for,
    /// stands (world x, z), and how much (0 to 1, eased in and out over a quarter of a
    /// second). The gaze engine looks there (`engine::Attend`).
    pub fn attending(&self) -> Option<(Vec2, f32)> {
        (self.attention > 1e-3).then_some((self.asked_at, self.attention))
    }

    /// Where the one it asked for room stands now, while it is still held back (below half its
    /// speed) after it stopped asking (they began to make room): it keeps looking at them,
    /// following them as they step aside, until its way is clear (the seed's walker gazes at the
    /// one in its way for as long as the way lacks clearance).
    fn held_back_by(&self, others: Option<Others<'_>>) -> Option<Vec2> {
        let o = others?;
        let a = self.active.as_ref().filter(|a| !a.stopped)?;
        if self.attention < 1e-3 || self.velocity().length() >= 0.5 * a.walk.speed {
            return None;
        }
        let near = neighbours(o, self.time, self.asked_at, FOLLOW);
        (near.iter())
            .map(|n| n.at)
            .min_by(|p, q| (p.distance(self.asked_at)).total_cmp(&q.distance(self.asked_at)))
    }

    /// How far off its facing the way goes 1.5 m ahead along the route from `here` (rad).
    fn route_ahead(&self, here: Vec2) -> f32 {
        let Some(a) = self.active.as_ref() else {
            return 0.0;
        };
        let (mut left, mut at) = (1.5f32, here);
        for p in a.route_from(here).into_iter().skip(1) {
            let d = at.distance(p);
            if d >= left {
                at += (p - at) * (left / d);
                break;
            }
            left -= d;
            at = p;
        }
        let to = at - here;
        if to.length() < 0.2 {
            return 0.0;
        }
        angle_diff(to.x.atan2(to.y), self.facing)
    }

    /// Whether a route for `walk` from where it stands goes round `obstacles`.
    pub fn can_route(&self, walk: &Walk, obstacles: &Obstacles) -> bool {
        path::plan(
            obstacles,
            self.body().at,
            walk.goal,
            self.radius + PLAN_MARGIN,
        )
        .is_ok()
    }

    /// Starts `walk` now, along a route around `obstacles`.
    pub fn start(&mut self, walk: Walk, obstacles: &Obstacles) -> Result<(), PathError> {
        let clearance = self.radius + PLAN_MARGIN;
        let route = path::plan(obstacles, self.body().at, walk.goal, clearance)?;
        let mut steering = Steering::new(self.combine, 0x5eed);
        let reach = 0.45;
        let params = ArriveParams {
            slow_radius: slow_radius(walk.speed),
            stop_radius: STOP_RADIUS,
            floor_speed: 0.12,
        };
        // the start leads the points (already passed), so that the first point sought is
        // passed like the others when the walker is pushed past it
        let points = route.iter().map(|p| Vec3::new(p.x, 0.0, p.y)).collect();
        let mut avoid = Part::new(Behaviour::AvoidObstacles {
            radius: self.radius,
            lookahead: 0.6,
        });
        avoid.priority = 1;
        steering.add(avoid);
        steering.add(Part::new(Behaviour::FollowPoints {
            points,
            next: 1,
            reach,
            params,
        }));
        self.vehicle.max_speed = walk.speed;
        self.stopped_at = None;
        self.queued = 0.0;
        self.nearest = (f32::INFINITY, self.time);
        // the velocity follows the steering within about 0.2 s, speeding up and braking at up
        // to about 2.3 m/s² walking, more running
        self.vehicle.max_force = self.vehicle.mass * (1.6 + 0.6 * walk.speed);
        self.gait.running = walk.running;
        let body = self.body();
        let plan = walk.footsteps.then(|| {
            let p = footstep_mode::Plan::new(
                body.at,
                self.facing,
                walk.goal,
                walk.speed,
                walk.running,
                self.radius,
                obstacles,
            );
            Box::new(p)
        });
        let moments = Moments {
            start: Some(self.time),
            ..Moments::default()
        };
        self.active = Some(Active {
            walk,
            route,
            steering,
            moments,
            stopped: false,
            halting: false,
            plan,
        });
        Ok(())
    }

    /// Slows down and stands within a step or two (an interrupted walk): it brakes along its
    /// way at [`HALT_DECELERATION`] (not the arrive law, whose linear slowing ends in a long
    /// creep).
    pub fn halt(&mut self) {
        if let Some(a) = self.active.as_mut() {
            a.halting = true;
            a.walk.face = None;
            self.gait.stop_at = None;
            a.moments.relax.get_or_insert(self.time);
            a.moments.ready.get_or_insert(self.time);
            a.steering.clear();
        }
    }

    /// Gives up the walk under way at once: the body stands where it is (its feet may still
    /// close).
    pub fn stand(&mut self) {
        self.active = None;
        self.gait.stop_at = None;
        self.vehicle.velocity = Vec3::ZERO;
    }

    /// Moves the goal of the walk under way (a moving target), planning a new route when it
    /// moved more than 0.1 m. Moments that happened stay.
    pub fn retarget(&mut self, goal: Vec2, face: Option<Vec2>, obstacles: &Obstacles) {
        let Some(a) = self.active.as_ref() else {
            return;
        };
        if a.halting || a.stopped || a.walk.goal.distance(goal) < 0.1 {
            if let Some(a) = self.active.as_mut() {
                a.walk.face = face.or(a.walk.face);
            }
            return;
        }
        let mut walk = a.walk.clone();
        walk.goal = goal;
        walk.face = face;
        self.restart(walk, obstacles);
    }

    /// Plans the walk under way again among `obstacles` (the world's changed: a group that
    /// stood walked off, or one formed); false if none is under way or it cannot be planned
    /// there (it then goes on as it was).
    pub fn reroute(&mut self, obstacles: &Obstacles) -> bool {
        let Some(a) = self.active.as_ref() else {
            return false;
        };
        if a.halting || a.stopped || a.walk.stepping || !self.can_route(&a.walk, obstacles) {
            return false;
        }
        let walk = a.walk.clone();
        self.restart(walk, obstacles)
    }

    /// The walk under way, if any.
    pub fn walk(&self) -> Option<&Walk> {
        self.active.as_ref().map(|a| &a.walk)
    }

    /// Plans the walk under way again from where the body stands when the point its route
    /// seeks is out of sight within its radius (others pressed it behind an obstacle's
    /// clearance, where seeking that point only pushes it along the obstacle); true if it did.
    fn replan_if_lost(&mut self, obstacles: &Obstacles) -> bool {
        let Some(a) = self.active.as_ref() else {
            return false;
        };
        let here = self.body().at;
        let route = a.route_from(here);
        let aim = route.get(1).copied().unwrap_or(a.walk.goal);
        if a.halting || a.stopped || obstacles.segment_clear(here, aim, 0.5 * self.radius) {
            return false;
        }
        let walk = a.walk.clone();
        self.restart(walk, obstacles)
    }

    /// Starts `walk` again from here, keeping the moments that happened.
    fn restart(&mut self, walk: Walk, obstacles: &Obstacles) -> bool {
        let Some(moments) = self.active.as_ref().map(|a| a.moments) else {
            return false;
        };
        let (queued, nearest) = (self.queued, self.nearest);
        let ok = self.start(walk, obstacles).is_ok();
        (self.queued, self.nearest) = (queued, nearest);
        if let (true, Some(a)) = (ok, self.active.as_mut()) {
            // (a relax that happened stays: it has been reported)
            a.moments = Moments {
                end: None,
                ..moments
            };
        }
        ok
    }

    /// Steps until `t` (whole steps of [`STEP`]); returns the walk's moments if it ended in
    /// that time (the walker then stands).
    /// A walker that stands with its feet together has nothing to step: its clock jumps.
    pub fn advance(&mut self, t: f64, obstacles: &Obstacles) -> Option<Moments> {
        self.advance_among(t, obstacles, None)
    }

    /// [`advance`](Self::advance) among `others`, avoiding them.
    pub fn advance_among(
        &mut self,
        t: f64,
        obstacles: &Obstacles,
        others: Option<Others<'_>>,
    ) -> Option<Moments> {
        let mut ended = None;
        while self.time + STEP <= t + 1e-9 {
            let attending = self.watching.is_some() || self.attention > 1e-3;
            if self.active.is_none()
                && self.gait.at_rest(self.body())
                && self.gait.amount < 1e-3
                && !attending
            {
                self.count(((t + 1e-9 - self.time) / STEP).floor() as u64);
                self.gait.amount = 0.0;
                break;
            }
            self.count(1);
            if let Some(m) = self.step(STEP as f32, obstacles, others) {
                ended = Some(m);
            }
        }
        ended
    }

    /// Moves its clock on by `n` steps.
    fn count(&mut self, n: u64) {
        self.steps += n;
        self.time = self.origin + self.steps as f64 * STEP;
    }

    /// A copy that walks `walk` from here to its end: its moments, or why it cannot. At most
    /// `limit` seconds are simulated; a longer walk has no `end`, and its `relax` is predicted
    /// from the rest of its route at cruising speed.
    pub fn rehearse(
        &self,
        walk: Walk,
        obstacles: &Obstacles,
        limit: f64,
    ) -> Result<Moments, PathError> {
        let mut w = self.clone();
        w.start(walk, obstacles)?;
        let stop = w.time + limit;
        // (whole steps only: a remainder shorter than a step would never be stepped)
        while w.time + STEP <= stop + 1e-9 {
            let t = (w.time + 1.0).min(stop);
            if let Some(m) = w.advance(t, obstacles) {
                return Ok(m);
            }
        }
        // longer than the rehearsal: the rest at cruising speed, then the usual slowing down
        let mut m = w.moments().unwrap_or_default();
        let speed = f64::from(w.vehicle.max_speed.max(0.05));
        let slow = f64::from(slow_radius(w.vehicle.max_speed));
        let relax = w.time + (f64::from(w.remaining()) - slow).max(0.0) / speed;
        m.relax.get_or_insert(relax);
        m.end = None;
        m.ready.get_or_insert(relax);
        Ok(m)
    }
}

impl Active {
    /// The route still ahead from `here`: the points not yet sought past.
    fn route_from(&self, here: Vec2) -> Vec<Vec2> {
        let next = self
            .steering
            .parts()
            .iter()
            .find_map(|p| match &p.behaviour {
                Behaviour::FollowPoints { next, .. } => Some(*next),
                _ => None,
            })
            .unwrap_or(self.route.len() - 1);
        let mut v = vec![here];
        v.extend(self.route.iter().skip(next));
        v
    }

    fn slow_radius(&self) -> f32 {
        slow_radius(self.walk.speed)
    }
}

/// Where the final deceleration at `speed` begins, from the goal (m): about two steps at a walk.
fn slow_radius(speed: f32) -> f32 {
    (0.75 * speed).max(0.5)
}

/// Turns `facing` toward `to` by at most `max` radians.
fn turn_toward(facing: &mut f32, to: f32, max: f32) {
    let d = angle_diff(to, *facing);
    *facing = (*facing + d.clamp(-max, max)).rem_euclid(std::f32::consts::TAU);
}

mod footstep_mode;
mod stages;

#[cfg(test)]
mod tests;
