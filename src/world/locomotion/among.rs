//! A walker among others: the crowd as it sees it (its neighbours, moved on to its step's time)
//! and the force toward the velocity it chooses among them with the crowd's avoider, regularly
//! ten times a second and at once when its course is about to touch someone. The walls are left
//! to its route and obstacle steering; a choice that would meet one is dropped.

use glam::{Vec2, Vec3};

use super::steering::{flat, Vehicle};
use super::STEP;
use crate::world::crowd::avoid::{NEIGHBOUR_RADIUS, STANDING_SPEED};
use crate::world::crowd::negotiate::{self, Standing};
use crate::world::crowd::{Agent, Avoider, Crowd, Profile};
use crate::world::space::Obstacles;

/// The others a walker shares the ground with: the frame's crowd and its own place in it.
#[derive(Debug, Clone, Copy)]
pub struct Others<'a> {
    /// The crowd (places as of its time, moved on by their velocities).
    pub crowd: &'a Crowd,
    /// The walker's own index in it.
    pub me: Option<usize>,
    /// Those it knows of (indices in the crowd, sorted), when it avoids only those it has
    /// seen or remembers; everyone when `None`.
    pub known: Option<&'a [usize]>,
}

/// How often a walker among others chooses its velocity again (steps): every
/// [`DECIDE_PERIOD`](crate::world::crowd::avoid::DECIDE_PERIOD).
pub const DECIDE_EVERY: i64 = (crate::world::crowd::avoid::DECIDE_PERIOD / STEP + 0.5) as i64;
/// How often a walker checks that its course does not touch someone within
/// [`URGENT_HORIZON`](crate::world::crowd::avoid::URGENT_HORIZON) (steps: 40 times a second).
pub const WATCH_EVERY: i64 = 6;

/// In the last this much of its way (m), a walker weighs no contact that would come only after
/// it stopped at its goal (`Avoider::set_way_left`). Only there: weighed over the whole way,
/// walkers went on toward people standing beyond their goals and more were stranded in random
/// squares of 300 (34 in 32 scenes against 20).
pub const LAST_STRETCH: f32 = 0.5;

/// What a walker among others needs to steer round them.
pub(super) struct Near<'a, 'b> {
    pub(super) others: Others<'b>,
    pub(super) time: f64,
    pub(super) radius: f32,
    pub(super) profile: &'a Profile,
    pub(super) obstacles: &'a Obstacles,
    /// Where its walk ends.
    pub(super) goal: Vec2,
    /// How far its way still goes (m).
    pub(super) left: f32,
    /// Whether it waits its turn at a door (`crowd::doorway`).
    pub(super) waiting: bool,
}

impl Near<'_, '_> {
    /// The force toward the velocity chosen among the others ([`DECIDE_EVERY`] steps), or
    /// `None` when nobody is in the way (or the choice would lead into an obstacle); with each
    /// regular choice, whom it asks for room (`asking`, see [`Near::asks`]).
    pub(super) fn steer(
        &self,
        avoider: &mut Avoider,
        (chosen, asking): (&mut Option<Vec2>, &mut Option<Vec2>),
        vehicle: &Vehicle,
        facing: f32,
        desired: Vec2,
        pref: f32,
    ) -> Option<Vec3> {
        let here = Vec2::new(vehicle.position.x, vehicle.position.z);
        let velocity = Vec2::new(vehicle.velocity.x, vehicle.velocity.z);
        let tick = (self.time / STEP).round() as i64;
        let regular = tick % DECIDE_EVERY == 0;
        if regular && self.waiting {
            // (waiting its turn at a door, it is held back by no one: it neither grows
            // impatient nor asks)
            avoider.calm(DECIDE_EVERY as f32 * STEP as f32);
            *asking = None;
        } else if regular {
            avoider.wait(DECIDE_EVERY as f32 * STEP as f32, velocity, desired, pref);
            // stuck (fully impatient), it asks whoever stands on its line, room beside them or
            // not: its avoidance found no way round them (wedged between two people standing,
            // room beside the one ahead but none to get there, a walker stood for 20 s)
            let insist = avoider.impatience() >= 1.0;
            *asking = self.asks(here, velocity, desired, pref, insist);
        }
        // between the regular choices, a course about to touch someone is chosen again at once
        let me = Agent {
            at: here,
            velocity,
            radius: self.radius,
        };
        let urgent = !regular
            && tick % WATCH_EVERY == 0
            && crate::world::crowd::avoid::about_to_touch(
                me,
                neighbours(self.others, self.time, here, 2.0).into_iter(),
            );
        if regular || urgent {
            let near = neighbours(self.others, self.time, here, NEIGHBOUR_RADIUS);
            avoider.set_way_left(if self.left < LAST_STRETCH {
                self.left
            } else {
                f32::INFINITY
            });
            // the walls are left to the route and the obstacle steering: a walker going round a
            // group's space at its clearance found every forward candidate "into a wall" and
            // stood (seen in the plaza); a choice that would meet a wall is dropped below
            let v = avoider.choose(
                me,
                desired,
                facing,
                pref,
                near.into_iter(),
                &Obstacles::default(),
                self.profile,
            );
            let clear = self
                .obstacles
                .segment_clear(here, here + v * 0.6, self.radius);
            *chosen = (avoider.avoiding && clear).then_some(v);
        }
        chosen.map(|v| Vec3::new(v.x, 0.0, v.y) - flat(vehicle.velocity))
    }
}

impl Near<'_, '_> {
    /// Where the person standing (not moving) in the way of a walker at `here`, held back
    /// below half its preferred speed `pref`, stands, when they shut its way (or whenever
    /// they stand on its line, when it `insist`s: [`negotiate::blocker`]).
    fn asks(
        &self,
        here: Vec2,
        velocity: Vec2,
        desired: Vec2,
        pref: f32,
        insist: bool,
    ) -> Option<Vec2> {
        if velocity.length() >= 0.5 * pref || desired.length() < 1e-3 {
            return None;
        }
        let near = neighbours(self.others, self.time, here, negotiate::LOOKAHEAD + 1.0);
        let standing: Vec<Standing> = (near.iter().enumerate())
            .filter(|(_, a)| a.velocity.length() < STANDING_SPEED)
            .map(|(index, a)| Standing {
                index,
                at: a.at,
                radius: a.radius,
            })
            .collect();
        let way = desired.normalize();
        negotiate::blocker(here, way, self.radius, &standing, self.obstacles, insist)
            .map(|i| near[i].at)
            .or_else(|| self.aside_on_goal(here))
    }

    /// Where one who stands aside for someone else (and will go back) stands on this walker's
    /// goal, if anyone does and the walker is near it: asked, they go back to their place.
    /// (One aside there, beyond the goal rather than on the walker's line, was never asked,
    /// and the walk gave up 0.37 m short.)
    fn aside_on_goal(&self, here: Vec2) -> Option<Vec2> {
        let crowd = self.others.crowd;
        if here.distance(self.goal) > negotiate::LOOKAHEAD {
            return None;
        }
        let mut found = Vec::new();
        crowd.near(self.goal, self.radius + 1.0, &mut found);

        (found.into_iter())
            .filter(|&i| Some(i) != self.others.me && crowd.is_aside(i))
            .map(|i| crowd.agent(i))
            .filter(|a| a.at.distance(self.goal) < self.radius + a.radius)
            .min_by(|a, b| {
                let (da, db) = (a.at.distance(here), b.at.distance(here));
                da.total_cmp(&db)
            })
            .map(|a| a.at)
    }
}

/// The others within `r` of `here` at `time` (their places moved on by their velocities).
pub(super) fn neighbours(o: Others<'_>, time: f64, here: Vec2, r: f32) -> Vec<Agent> {
    let mut found = Vec::new();
    o.crowd.near(here, r, &mut found);
    let ahead = (time - o.crowd.time) as f32;
    (found.into_iter())
        .filter(|&i| Some(i) != o.me)
        .filter(|i| o.known.is_none_or(|k| k.binary_search(i).is_ok()))
        .map(|i| {
            let a = o.crowd.agent(i);
            Agent {
                at: a.at + a.velocity * ahead,
                ..a
            }
        })
        .collect()
}
