//! Steering behaviours on Reynolds' vehicle model, as the IViHumans platform thesis (Ch. 2.1 and
//! 3, "steering behaviours") describes them for walking characters: a point mass whose steering
//! force is truncated to `max_force`, accelerates by a = F/m and has its speed truncated to
//! `max_speed`. Every behaviour here is two-dimensional: its force has no vertical component and
//! the vehicle's vertical velocity never changes. Behaviours: seek, flee, arrive (linear
//! deceleration down to a floor speed, then a stop inside a small radius), pursue and evade
//! (targets that move), wander, walk-to-velocity, stop, follow a list of points and obstacle
//! avoidance; combiners: the truncated weighted sum, the prioritised running sum and prioritised
//! dithering. The module is a library a host can use on its own; the realizer's walkers use it.

pub use crate::rng::Rng;
use glam::{Vec2, Vec3};

use crate::world::space::Obstacles;

/// The horizontal part of `v` (y = 0).
pub fn flat(v: Vec3) -> Vec3 {
    Vec3::new(v.x, 0.0, v.z)
}

/// `v` shortened to length `max` if it is longer.
pub fn truncate(v: Vec3, max: f32) -> Vec3 {
    let l = v.length();
    if l > max && l > 0.0 {
        v * (max / l)
    } else {
        v
    }
}

/// A point mass steered by forces (Reynolds' simple vehicle).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Vehicle {
    /// Position (metres).
    pub position: Vec3,
    /// Velocity (m/s).
    pub velocity: Vec3,
    /// Mass (kg).
    pub mass: f32,
    /// Largest steering force (N).
    pub max_force: f32,
    /// Largest speed (m/s).
    pub max_speed: f32,
}

impl Vehicle {
    /// A vehicle at rest at `position`.
    pub fn new(position: Vec3, mass: f32, max_force: f32, max_speed: f32) -> Vehicle {
        Vehicle {
            position,
            velocity: Vec3::ZERO,
            mass,
            max_force,
            max_speed,
        }
    }

    /// Horizontal speed.
    pub fn speed(&self) -> f32 {
        flat(self.velocity).length()
    }

    /// One step of `dt` seconds: the force truncated to `max_force`, a = F/m, the velocity
    /// truncated to `max_speed`, x += v dt.
    pub fn step(&mut self, force: Vec3, dt: f32) {
        let f = truncate(force, self.max_force);
        let a = f / self.mass.max(1e-6);
        self.velocity = truncate(self.velocity + a * dt, self.max_speed);
        self.position += self.velocity * dt;
    }
}

/// Arrive's deceleration (the thesis' `arriveDecDist`, `arriveStopDist`, `arriveSpeed`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArriveParams {
    /// Inside this distance the desired speed falls linearly with the distance (m).
    pub slow_radius: f32,
    /// Inside this distance the vehicle stops at once and the behaviour is done (m).
    pub stop_radius: f32,
    /// The desired speed never falls below this while slowing down (m/s).
    pub floor_speed: f32,
}

/// Reynolds' wander: a target on a circle ahead of the vehicle that drifts at random.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Wander {
    /// Distance of the circle's centre ahead (m).
    pub distance: f32,
    /// The circle's radius (m).
    pub radius: f32,
    /// Largest change of the angle on the circle per step (rad).
    pub jitter: f32,
    /// The current angle on the circle (rad).
    pub angle: f32,
}

/// One steering behaviour.
#[derive(Debug, Clone, PartialEq)]
pub enum Behaviour {
    /// Toward a point at full speed (orbits it once there).
    Seek(Vec3),
    /// Away from a point at full speed, while nearer than `panic` metres.
    Flee {
        /// The point fled from.
        from: Vec3,
        /// Beyond this distance the force is zero.
        panic: f32,
    },
    /// Toward a point, slowing down near it and stopping inside the stop radius.
    Arrive {
        /// The point.
        target: Vec3,
        /// How it slows and stops.
        params: ArriveParams,
    },
    /// Seek where a moving target will be when the vehicle could reach it.
    Pursue {
        /// The target's position now.
        position: Vec3,
        /// Its velocity.
        velocity: Vec3,
    },
    /// Flee from where a moving target will be.
    Evade {
        /// The target's position now.
        position: Vec3,
        /// Its velocity.
        velocity: Vec3,
    },
    /// Wander about.
    Wander(Wander),
    /// Take this horizontal velocity (the force is (V − v) × 1 kg/s).
    WalkTo(Vec3),
    /// Come to rest (walk-to-velocity zero); done below [`STOP_EPSILON`].
    Stop,
    /// Seek each point in turn, arrive at the last.
    FollowPoints {
        /// The points.
        points: Vec<Vec3>,
        /// The point sought now.
        next: usize,
        /// Within this distance of a point the next one is sought (m).
        reach: f32,
        /// How it arrives at the last one.
        params: ArriveParams,
    },
    /// Steer away from obstacles ahead, within `lookahead` seconds at the current speed.
    AvoidObstacles {
        /// The body's radius (m).
        radius: f32,
        /// How far ahead to look, in seconds of travel.
        lookahead: f32,
    },
}

/// Below this speed (m/s) `Stop` is done.
pub const STOP_EPSILON: f32 = 1e-3;

/// What a behaviour sees besides the vehicle.
#[derive(Debug, Clone, Copy, Default)]
pub struct Context<'a> {
    /// Obstacles (for [`Behaviour::AvoidObstacles`]).
    pub obstacles: Option<&'a Obstacles>,
}

impl Behaviour {
    /// The steering force on `v`, truncated to its `max_force`, horizontal; `None` when the
    /// behaviour is done (arrive stopped the vehicle, stop reached rest, the points were
    /// followed). Arrive inside its stop radius sets the vehicle's horizontal velocity to zero.
    pub fn force(&mut self, v: &mut Vehicle, ctx: Context<'_>, rng: &mut Rng) -> Option<Vec3> {
        let raw = match self {
            Behaviour::Seek(t) => seek(v, *t),
            Behaviour::Flee { from, panic } => {
                let away = flat(v.position - *from);
                if away.length() > *panic {
                    Vec3::ZERO
                } else {
                    away.normalize_or_zero() * v.max_speed - flat(v.velocity)
                }
            }
            Behaviour::Arrive { target, params } => arrive(v, *target, *params)?,
            Behaviour::Pursue { position, velocity } => seek(v, ahead(v, *position, *velocity)),
            Behaviour::Evade { position, velocity } => {
                let at = ahead(v, *position, *velocity);
                flat(v.position - at).normalize_or_zero() * v.max_speed - flat(v.velocity)
            }
            Behaviour::Wander(w) => {
                w.angle += (rng.next_f32() * 2.0 - 1.0) * w.jitter;
                let heading = flat(v.velocity).normalize_or(Vec3::Z);
                let centre = v.position + heading * w.distance;
                let on = centre + Vec3::new(w.angle.sin(), 0.0, w.angle.cos()) * w.radius;
                seek(v, on)
            }
            Behaviour::WalkTo(target) => walk_to(v, *target),
            Behaviour::Stop => {
                if v.speed() < STOP_EPSILON {
                    return None;
                }
                walk_to(v, Vec3::ZERO)
            }
            Behaviour::FollowPoints {
                points,
                next,
                reach,
                params,
            } => {
                while *next + 1 < points.len() && passed(v.position, points, *next, *reach, &ctx) {
                    *next += 1;
                }
                let p = *points.get(*next)?;
                if *next + 1 < points.len() {
                    seek(v, p)
                } else {
                    arrive(v, p, *params)?
                }
            }
            Behaviour::AvoidObstacles { radius, lookahead } => {
                avoid(v, ctx.obstacles, *radius, *lookahead)
            }
        };
        Some(truncate(flat(raw), v.max_force))
    }
}

/// Whether a follower at `at` is done with point `i` of `points` (not the last): within `reach`
/// of it, or past the line through it square to the way it came from the point before, with the
/// next point in sight (a follower pushed aside by others does not turn back for a point it
/// went round).
fn passed(at: Vec3, points: &[Vec3], i: usize, reach: f32, ctx: &Context) -> bool {
    let (p, q) = (flat(points[i]), flat(points[i + 1]));
    let at = flat(at);
    if (p - at).length() <= reach {
        return true;
    }
    let Some(before) = i.checked_sub(1).map(|k| flat(points[k])) else {
        return false;
    };
    let beyond = (at - p).dot(p - before) > 0.0;
    let xz = |v: Vec3| glam::Vec2::new(v.x, v.z);
    beyond
        && ctx
            .obstacles
            .is_none_or(|o| o.segment_clear(xz(at), xz(q), 0.05))
}

/// Reynolds' seek: the desired velocity toward `t` at full speed, less the current velocity.
fn seek(v: &Vehicle, t: Vec3) -> Vec3 {
    flat(t - v.position).normalize_or_zero() * v.max_speed - flat(v.velocity)
}

/// The thesis' walk-to-velocity: (V_h − v) × 1 kg/s, V_h taking the current vertical velocity.
fn walk_to(v: &Vehicle, target: Vec3) -> Vec3 {
    let wanted = Vec3::new(target.x, v.velocity.y, target.z);
    (wanted - v.velocity) * 1.0
}

/// Where a target at `p` moving at `vel` will be when `v` could reach it at full speed.
fn ahead(v: &Vehicle, p: Vec3, vel: Vec3) -> Vec3 {
    let t = flat(p - v.position).length() / v.max_speed.max(1e-3);
    p + flat(vel) * t
}

/// The thesis' modified arrive: seek far away; inside the slow radius the desired speed falls
/// linearly with the distance, but not below the floor speed; inside the stop radius the
/// vehicle stops at once (`None`: done).
fn arrive(v: &mut Vehicle, t: Vec3, p: ArriveParams) -> Option<Vec3> {
    let to = flat(t - v.position);
    let d = to.length();
    if d <= p.stop_radius {
        v.velocity = Vec3::new(0.0, v.velocity.y, 0.0);
        return None;
    }
    let speed = if d < p.slow_radius {
        (v.max_speed * d / p.slow_radius).max(p.floor_speed)
    } else {
        v.max_speed
    };
    Some(to / d * speed - flat(v.velocity))
}

/// Obstacle avoidance: of the obstacles the body would come within its radius of along its
/// course in the next `lookahead` seconds, the nearest pushes the vehicle sideways, away from
/// its nearest point, harder the nearer it is.
fn avoid(v: &Vehicle, obstacles: Option<&Obstacles>, radius: f32, lookahead: f32) -> Vec3 {
    let (Some(obstacles), speed) = (obstacles, v.speed()) else {
        return Vec3::ZERO;
    };
    if speed < 1e-3 {
        return Vec3::ZERO;
    }
    let at = Vec2::new(v.position.x, v.position.z);
    let heading = Vec2::new(v.velocity.x, v.velocity.z) / speed;
    let reach = speed * lookahead;
    let mut nearest: Option<(f32, Vec2)> = None;
    let steps = 8;
    for k in 1..=steps {
        let p = at + heading * (reach * k as f32 / steps as f32);
        if let Some((d, away)) = obstacles.nearest(p, radius + 0.5) {
            if d < radius && nearest.is_none_or(|n| k as f32 / steps as f32 * reach < n.0) {
                nearest = Some((reach * k as f32 / steps as f32, away));
            }
        }
    }
    let Some((distance, away)) = nearest else {
        return Vec3::ZERO;
    };
    // sideways (perpendicular to the heading) on the side away from the obstacle
    let side = Vec2::new(-heading.y, heading.x);
    let sign = if side.dot(away) >= 0.0 { 1.0 } else { -1.0 };
    let urgency = 1.0 - (distance / reach.max(1e-3)).clamp(0.0, 1.0);
    let f = side * sign * v.max_force * (0.3 + 0.7 * urgency);
    Vec3::new(f.x, 0.0, f.y)
}

/// How several behaviours' forces make one.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Combine {
    /// Σ wᵢ Fᵢ, truncated to `max_force` (weights 1: the plain truncated sum).
    WeightedSum,
    /// In priority order, add wᵢ Fᵢ while the running sum's magnitude is under `max_force`;
    /// the one that would pass it adds only the part that fits.
    Prioritised,
    /// In priority order, evaluate each with its probability; the first non-zero force wins.
    Dithering,
}

/// A behaviour in a combination.
#[derive(Debug, Clone, PartialEq)]
pub struct Part {
    /// The behaviour.
    pub behaviour: Behaviour,
    /// Its weight (sums).
    pub weight: f32,
    /// Its priority (higher first).
    pub priority: i32,
    /// The probability it is evaluated in a step (dithering).
    pub probability: f32,
}

impl Part {
    /// `behaviour` with weight 1, priority 0 and probability 1.
    pub fn new(behaviour: Behaviour) -> Part {
        Part {
            behaviour,
            weight: 1.0,
            priority: 0,
            probability: 1.0,
        }
    }
}

/// Several behaviours and how they combine: a character's steering.
#[derive(Debug, Clone, PartialEq)]
pub struct Steering {
    /// The combiner (selectable at any time).
    pub combine: Combine,
    /// The behaviours, kept in priority order (highest first; ties keep their order).
    parts: Vec<Part>,
    /// The generator of wander and dithering.
    pub rng: Rng,
}

impl Steering {
    /// No behaviours yet.
    pub fn new(combine: Combine, seed: u64) -> Steering {
        Steering {
            combine,
            parts: Vec::new(),
            rng: Rng(seed.max(1)),
        }
    }

    /// Adds a behaviour (kept in priority order).
    pub fn add(&mut self, part: Part) {
        let at = self.parts.partition_point(|p| p.priority >= part.priority);
        self.parts.insert(at, part);
    }

    /// The behaviours, highest priority first.
    pub fn parts(&self) -> &[Part] {
        &self.parts
    }

    /// Removes every behaviour.
    pub fn clear(&mut self) {
        self.parts.clear();
    }

    /// The combined force on `v` this step. Behaviours that are done leave the combination.
    pub fn force(&mut self, v: &mut Vehicle, ctx: Context<'_>) -> Vec3 {
        let mut done = Vec::new();
        let budget = v.max_force;
        let mut sum = Vec3::ZERO;
        for (i, part) in self.parts.iter_mut().enumerate() {
            if self.combine == Combine::Dithering && self.rng.next_f32() >= part.probability {
                continue;
            }
            let Some(f) = part.behaviour.force(v, ctx, &mut self.rng) else {
                done.push(i);
                continue;
            };
            match self.combine {
                Combine::WeightedSum => sum += f * part.weight,
                Combine::Prioritised => {
                    let f = f * part.weight;
                    let left = budget - sum.length();
                    if left <= 0.0 {
                        break;
                    }
                    if f.length() <= left {
                        sum += f;
                    } else {
                        sum += f.normalize_or_zero() * left;
                        break;
                    }
                }
                Combine::Dithering => {
                    if f != Vec3::ZERO {
                        sum = f;
                        break;
                    }
                }
            }
        }
        for i in done.into_iter().rev() {
            self.parts.remove(i);
        }
        truncate(flat(sum), budget)
    }
}
