//! A walker's step, in the order its stages run: the walk under way drives the body (braking
//! to a halt at its goal, a footstep walk's next velocity, a turn on the spot before setting
//! off, or steering along the route among others) and marks its moments; then the body is kept
//! out of other bodies and obstacles, turns to face its way of travel, attends to the one it
//! asks or watches, and its feet step; the walk ends when the body stands, faces where it
//! should and has its feet together.

use glam::{Vec2, Vec3};

use super::{
    footstep_mode, turn_toward, Active, Moments, Others, Walker, HALT_DECELERATION, NEARER,
    NEAR_ENOUGH, REPLAN_EVERY, STEP, STOP_RADIUS, TURN_EASE, TURN_FIRST, TURN_ON_THE_SPOT,
    TURN_RATE,
};
use crate::world::crowd::doorway::{self, Passing};
use crate::world::crowd::lanes;
use crate::world::locomotion::among::{neighbours, Near, DECIDE_EVERY};
use crate::world::locomotion::gait::{angle_diff, forward};
use crate::world::locomotion::steering::{flat, Behaviour, Context};
use crate::world::space::obstacles::Obstacles;
use crate::world::space::path;

/// Fastest a body left overlapping another (both moved at once) is moved apart (m/s), on top
/// of its walk: a quick side step, so that a press never throws a person (uncapped, roots were
/// shoved at up to 10 m/s between frames; at 0.6 m/s a walker in the plaza, held back longer,
/// set off later across its feet and dragged one 1.5 cm).
pub const PRESSED_APART: f32 = 1.0;

impl Walker {
    /// One step; the moments when the walk ends in it.
    pub(super) fn step(
        &mut self,
        dt: f32,
        obstacles: &Obstacles,
        others: Option<Others<'_>>,
    ) -> Option<Moments> {
        let time = self.time;
        if others.is_none() || self.active.as_ref().is_none_or(|a| a.stopped) {
            self.asking = None;
        }
        // among others, who may press it behind an obstacle: once a second on the global grid
        if others.is_some() && (time / STEP).round() as i64 % REPLAN_EVERY == 0 {
            self.replan_if_lost(obstacles);
        }
        let facing_before = self.facing;
        let before = self.body().at;
        if let Some(mut a) = self.active.take() {
            self.drive(&mut a, dt, obstacles, others);
            self.active = Some(a);
        }
        self.keep_apart(dt, before, obstacles, others);
        self.face_the_way(dt);
        self.attend(dt, others);
        self.step_the_feet(dt, facing_before)
    }

    /// The walk under way moves the body one step.
    fn drive(
        &mut self,
        a: &mut Active,
        dt: f32,
        obstacles: &Obstacles,
        others: Option<Others<'_>>,
    ) {
        let time = self.time;
        let here = self.body().at;
        let to_goal = a.walk.goal - here;
        // the point sought now (not the route's first: one pushed past it and slowed down
        // turned back to it on the spot)
        let ahead = a.route_from(here);
        let next = ahead.get(1).copied().unwrap_or(a.walk.goal);
        let wanted = (next - here).normalize_or_zero();
        // (one going round someone as its avoidance chose does not turn first toward its
        // goal: a walker that did, turning straight at one standing and then steering round
        // them again, swung between the two and crept 5 cm/s for 17 s)
        let round = self.chosen.is_some_and(|v| v.length() > 0.1) || self.waiting.is_some();
        let behind = wanted != Vec2::ZERO
            && !round
            && !a.walk.stepping
            && angle_diff(wanted.x.atan2(wanted.y), self.facing).abs() > TURN_FIRST;
        // arriving, the floor speed is braked away where the arrival would stop dead (a
        // person does not stop from 0.12 m/s in a step; this takes about 0.1 s and 5 mm)
        let speed = self.vehicle.speed();
        let braking = speed * speed / (2.0 * HALT_DECELERATION);
        // (held still within a hand of its goal, it has arrived: a walker 7 cm from its
        // place, stopped for someone standing a metre beyond it, stood there for half a
        // minute)
        let held_near = speed < 0.05 && to_goal.length() < NEAR_ENOUGH;
        if !a.halting && ((speed < 0.3 && to_goal.length() <= STOP_RADIUS + braking) || held_near) {
            a.halting = ahead.len() <= 2;
        }
        if a.halting && !a.stopped {
            self.brake(a, dt);
        } else if !a.stopped {
            let route = ahead;
            // (a footstep walk keeps only loosely to a route: what is left is the way to the goal)
            let left = match a.plan {
                Some(_) => to_goal.length(),
                None => path::length(&route),
            };
            if a.plan.is_some() {
                self.follow_footsteps(a, dt, obstacles, others, here);
            } else if behind && self.vehicle.speed() < 0.3 && to_goal.length() > 0.3 {
                self.turn_first(a, wanted, dt);
            } else {
                self.steer(a, dt, obstacles, others, &route, left);
            }
            self.mark_moments(a, here, left);
        }
        if a.stopped {
            self.stopped_at.get_or_insert(self.body().at);
            // the feet close where the body stopped
            self.gait.stop_at = None;
            a.moments.ready.get_or_insert(time);
            a.moments.relax.get_or_insert(time);
            if let Some(p) = a.walk.face {
                let d = p - here;
                if d.length() > 1e-3 {
                    turn_toward(&mut self.facing, d.x.atan2(d.y), TURN_ON_THE_SPOT * dt);
                }
            }
        }
    }

    /// Halting: the body slows at a person's deceleration until it stands.
    fn brake(&mut self, a: &mut Active, dt: f32) {
        let v = self.vehicle.velocity;
        let speed = flat(v).length();
        let slower = (speed - HALT_DECELERATION * dt).max(0.0);
        self.vehicle.velocity = if speed > 0.0 { v * (slower / speed) } else { v };
        self.vehicle.position += self.vehicle.velocity * dt;
        if slower == 0.0 {
            a.stopped = true;
        }
    }

    /// A footstep walk from `here`: the velocity its steps ask for, or standing when it has
    /// closed its feet at the goal or no step leads anywhere better.
    fn follow_footsteps(
        &mut self,
        a: &mut Active,
        dt: f32,
        obstacles: &Obstacles,
        others: Option<Others<'_>>,
        here: Vec2,
    ) {
        let time = self.time;
        let to_goal = a.walk.goal - here;
        let Some(plan) = a.plan.as_mut() else {
            return;
        };
        let walkers: Vec<Vec2> = others
            .map(|o| {
                neighbours(o, time, here, 3.0)
                    .iter()
                    .map(|n| n.at)
                    .collect()
            })
            .unwrap_or_default();
        let place = others.map_or(footstep_mode::Place::default(), |o| footstep_mode::Place {
            index: o.me.unwrap_or(0),
            count: o.crowd.len(),
        });
        match plan.velocity(time, here, obstacles, &walkers, self.radius, place) {
            Some(v) => {
                // speeding up and braking as a person does
                let now = Vec2::new(self.vehicle.velocity.x, self.vehicle.velocity.z);
                let v = now + (v - now).clamp_length_max(footstep_mode::ACCELERATION * dt);
                self.vehicle.velocity = Vec3::new(v.x, 0.0, v.y);
                self.vehicle.position += self.vehicle.velocity * dt;
            }
            // arrived (the last step closed the feet) or stuck: it stands
            None => {
                if plan.stuck {
                    self.stuck = Some(to_goal.length());
                }
                a.halting = true;
                a.stopped = true;
                self.vehicle.velocity = Vec3::ZERO;
            }
        }
    }

    /// The way is behind: it brakes and turns on the spot before setting off.
    fn turn_first(&mut self, a: &mut Active, wanted: Vec2, dt: f32) {
        let brake =
            Behaviour::Stop.force(&mut self.vehicle, Context::default(), &mut a.steering.rng);
        self.vehicle.step(brake.unwrap_or(Vec3::ZERO), dt);
        turn_toward(
            &mut self.facing,
            wanted.x.atan2(wanted.y),
            TURN_ON_THE_SPOT * dt,
        );
    }

    /// Steering along the route (`left` metres of it), avoiding the others in a crowd; the walk
    /// stops when its steering has nothing left to follow.
    fn steer(
        &mut self,
        a: &mut Active,
        dt: f32,
        obstacles: &Obstacles,
        others: Option<Others<'_>>,
        route: &[Vec2],
        left: f32,
    ) {
        let here = self.body().at;
        let f = a.steering.force(
            &mut self.vehicle,
            Context {
                obstacles: Some(obstacles),
            },
        );
        let f = match others {
            // (stepping aside for someone, it does not avoid them)
            Some(o) if o.crowd.len() > 1 && !a.walk.stepping => {
                let desired = self.desired_among(a, o, obstacles, route, left);
                let near = Near {
                    others: o,
                    time: self.time,
                    radius: self.radius,
                    profile: &self.profile,
                    obstacles,
                    goal: a.walk.goal,
                    left,
                    waiting: self.waiting.is_some(),
                };
                let steered = near.steer(
                    &mut self.avoider,
                    (&mut self.chosen, &mut self.asking),
                    &self.vehicle,
                    self.facing,
                    desired,
                    a.walk.speed,
                );
                // (waiting, or keeping to its lane, with nobody in its way: it goes to its
                // place in the queue, or along its lane, not on along its route)
                let to_desired = Vec3::new(desired.x, 0.0, desired.y) - flat(self.vehicle.velocity);
                let own = self.waiting.is_some() || self.lane.is_some();
                steered.unwrap_or(if own { to_desired } else { f })
            }
            _ => {
                self.passing = None;
                self.waiting = None;
                self.lane = None;
                self.heading = None;
                f
            }
        };
        self.note_progress(a, here, dt);
        self.vehicle.step(f, dt);
        if a.steering.parts().iter().all(|p| {
            !matches!(
                p.behaviour,
                Behaviour::FollowPoints { .. } | Behaviour::Stop
            )
        }) {
            a.stopped = true;
            self.vehicle.velocity = Vec3::ZERO;
        }
    }

    /// The velocity a walker among `o`thers wants along its `route` (`left` metres of it):
    /// toward the route's next point, slowing at the end; along its lane in a passage with
    /// people coming the other way (`crowd::lanes`, decided with its regular choices); or to
    /// its place in the queue when it is not its turn at a narrow door (`crowd::doorway`).
    fn desired_among(
        &mut self,
        a: &Active,
        o: Others<'_>,
        obstacles: &Obstacles,
        route: &[Vec2],
        left: f32,
    ) -> Vec2 {
        let here = self.body().at;
        let toward = (route.get(1).copied().unwrap_or(a.walk.goal) - here).normalize_or_zero();
        self.heading = Some(toward).filter(|t| *t != Vec2::ZERO);
        let narrows = obstacles.narrows();
        self.passing = (!narrows.is_empty())
            .then(|| Passing::on(route, narrows))
            .flatten();
        self.waiting = (self.passing)
            .filter(|p| !p.may_go(o.crowd.turn(p.narrow)))
            .map(|p| {
                let rank = o.me.map_or(0, |me| doorway::rank(o.crowd, me, p));
                p.waiting_spot(&narrows[p.narrow as usize], rank)
            });
        if (self.time / STEP).round() as i64 % DECIDE_EVERY == 0 {
            let coming = lanes::oncoming(o.crowd, o.me, here, toward);
            self.lane = (coming.filter(|_| left > lanes::RELEASE)).and_then(|(_, facing)| {
                lanes::keep_right(obstacles, here, toward, self.radius, facing)
            });
        }
        match self.waiting {
            Some(spot) => doorway_arrival(spot - here, a.walk.speed),
            None => {
                let slowing = (left / a.slow_radius()).clamp(0.1, 1.0);
                self.lane.unwrap_or(toward) * a.walk.speed * slowing
            }
        }
    }

    /// Notes how near the walk has come to its goal, and how long it has queued for a narrow
    /// door (waiting its turn, or held back in the press before it): who drives the walk gives
    /// it more time for both.
    fn note_progress(&mut self, a: &Active, here: Vec2, dt: f32) {
        let off = here.distance(a.walk.goal);
        if off < self.nearest.0 - NEARER {
            self.nearest = (off, self.time);
        }
        let slow = self.vehicle.speed() < 0.5 * a.walk.speed;
        if self.waiting.is_some() || (self.passing.is_some() && slow) {
            self.queued += f64::from(dt);
        }
    }

    /// The walk's moments: `ready` at cruising speed, `relax` where the final slowing begins
    /// (`left` metres of the way from `here`, where the body was at the step's start), and
    /// where the feet will stop.
    fn mark_moments(&mut self, a: &mut Active, here: Vec2, left: f32) {
        let time = self.time;
        let speed = self.vehicle.speed();
        if a.moments.ready.is_none() && speed >= 0.95 * a.walk.speed {
            a.moments.ready = Some(time);
        }
        if a.moments.relax.is_none() && left < a.slow_radius() && speed > 0.0 {
            a.moments.relax = Some(time);
            a.moments.ready.get_or_insert(time);
        }
        if a.moments.relax.is_some() && a.plan.is_none() {
            // where the body will stand: arrived, STOP_RADIUS short of the goal
            let back = (a.walk.goal - here).normalize_or_zero() * STOP_RADIUS;
            self.gait.stop_at = Some(a.walk.goal - back);
        }
    }

    /// Never into another body, nor into an obstacle: the step from `before` slides along
    /// whoever it touches, and an overlap left (the others moved too) parts no faster than
    /// [`PRESSED_APART`]; an obstacle pushes the body out, but never into another body (a
    /// group's space is kept by manners, a body by contact).
    fn keep_apart(
        &mut self,
        dt: f32,
        before: Vec2,
        obstacles: &Obstacles,
        others: Option<Others<'_>>,
    ) {
        use crate::world::crowd::contact::{pushed_out_at_most, slid_along, stepped_along};
        self.vehicle.position.y = 0.0;
        self.vehicle.velocity.y = 0.0;
        let near = match others {
            // (bodies never pass through each other, seen or not)
            Some(o) => neighbours(
                Others { known: None, ..o },
                self.time,
                before,
                self.radius + 1.0,
            ),
            None => Vec::new(),
        };
        let moved = stepped_along(before, self.radius, self.body().at - before, &near);
        let v = slid_along(before, self.radius, self.velocity(), &near);
        self.vehicle.velocity = Vec3::new(v.x, 0.0, v.y);
        let at = before + moved;
        // (pressed out of one, never into another)
        let out = pushed_out_at_most(at, self.radius, near.iter().copied(), dt, PRESSED_APART);
        let at = at + stepped_along(at, self.radius, out - at, &near);
        let out = obstacles.push_out(at, self.radius);
        let at = at + stepped_along(at, self.radius, out - at, &near);
        // (a body is never left in a wall: pressed against one by another, it stays a hand
        // nearer them rather than in the wall)
        let at = obstacles.push_out(at, self.radius);
        self.vehicle.position = Vec3::new(at.x, 0.0, at.y);
    }

    /// Faces the way of travel, never walking backwards (unless stepping aside).
    fn face_the_way(&mut self, dt: f32) {
        let v = self.velocity();
        let stepping = self.active.as_ref().is_some_and(|a| a.walk.stepping);
        if v.length() > 0.05 && !stepping {
            turn_toward(&mut self.facing, v.x.atan2(v.y), TURN_RATE * dt);
            self.facing = self.gait.within_stance_twist(self.facing);
            let f = forward(self.facing);
            if v.dot(f) < 0.0 {
                let keep = v - f * v.dot(f);
                self.vehicle.velocity = Vec3::new(keep.x, 0.0, keep.y);
            }
        }
    }

    /// Attends to the one it asks for room or watches, or to one holding it back.
    fn attend(&mut self, dt: f32, others: Option<Others<'_>>) {
        let held = match self.asking.or(self.watching) {
            Some(_) => None,
            None => self.held_back_by(others),
        };
        let attended = self.asking.or(self.watching).or(held);
        if let Some(p) = attended {
            self.asked_at = p;
        }
        let attend = if attended.is_some() { 1.0 } else { 0.0 };
        self.attention += (attend - self.attention) * (1.0 - (-dt / 0.25).exp());
    }

    /// The feet step under the body (which faced `facing_before` at the step's start); the
    /// walk's moments when it ends here.
    fn step_the_feet(&mut self, dt: f32, facing_before: f32) -> Option<Moments> {
        let body = self.body();
        // the rate the feet are turned ahead for, eased over a fifth of a second: when a turn on
        // the spot ends, the swinging foot's landing heading eases back instead of jumping (it
        // twisted the hip at 30 rad/s in one frame)
        let turning = angle_diff(self.facing, facing_before) / dt;
        self.gait.turn_rate += (turning - self.gait.turn_rate) * (1.0 - (-dt / TURN_EASE).exp());
        self.gait.step(dt, body, self.velocity());
        let a = self.active.as_mut()?;
        let facing_done = a.walk.face.is_none_or(|p| {
            let d = p - body.at;
            d.length() < 1e-3 || angle_diff(d.x.atan2(d.y), self.facing).abs() < 0.03
        });
        if a.stopped && facing_done && self.gait.at_rest(body) {
            a.moments.end = Some(self.time);
            let ended = a.moments;
            self.active = None;
            self.gait.stop_at = None;
            return Some(ended);
        }
        None
    }
}

/// The velocity toward a waiting place `to` (from here) at walking `speed`, slowing within the
/// last metre and standing within 10 cm of it.
fn doorway_arrival(to: Vec2, speed: f32) -> Vec2 {
    let d = to.length();
    if d < 0.1 {
        Vec2::ZERO
    } else {
        to / d * speed * d.min(1.0)
    }
}
