//! ORCA (`dodgy_2d`) driven on the same movers as the realizer's roots-only crowd
//! (`crowd::sim::Mover`: the same preferred velocity, slowing in the last metre, the same
//! arrival), through its per-agent API: every step each agent's neighbours within the same
//! radius by the same grid search (`dodgy_2d`'s own `Simulator` filters neighbours wrongly),
//! the avoiding velocity taken at once (as ORCA assumes). Walls and the groups' spaces are
//! given to ORCA as its obstacles (a wall as a sliver 2 cm thick, a circle as a 16-gon around
//! it), and the movers follow the same routes round them. Shared by
//! `examples/crowd_quality.rs` and `benches/crowd.rs`.
#![allow(dead_code)] // each user takes what it needs

use std::borrow::Cow;
use std::sync::Arc;

use bml_realizer::world::crowd::avoid::NEIGHBOUR_RADIUS;
use bml_realizer::world::crowd::sim::Mover;
use bml_realizer::world::crowd::{Agent, Crowd};
use bml_realizer::world::space::{Obstacles, Shape};
use glam::Vec2;

/// ORCA's look-ahead for other agents (s).
pub const TIME_HORIZON: f32 = 3.0;

/// Everyone, stepped together from one snapshot.
pub struct Orca {
    pub time: f64,
    pub movers: Vec<Mover>,
    walls: Arc<Obstacles>,
    obstacles: Vec<dodgy_2d::Obstacle>,
}

/// ORCA's form of an obstacle: a closed polygon, counter-clockwise.
fn polygon(shape: &Shape) -> dodgy_2d::Obstacle {
    let vertices = match *shape {
        Shape::Circle { centre, radius } => {
            let r = radius / (std::f32::consts::PI / 16.0).cos();
            (0..16)
                .map(|k| centre + Vec2::from_angle(k as f32 * std::f32::consts::TAU / 16.0) * r)
                .collect()
        }
        Shape::Box { min, max } => vec![min, Vec2::new(max.x, min.y), max, Vec2::new(min.x, max.y)],
        Shape::Segment { a, b } => {
            let side = (b - a).perp().normalize_or_zero() * 0.01;
            vec![a - side, b - side, b + side, a + side]
        }
    };
    dodgy_2d::Obstacle::Closed {
        vertices: vertices.into_iter().map(d2).collect(),
    }
}

fn d2(v: Vec2) -> dodgy_2d::Vec2 {
    dodgy_2d::Vec2::new(v.x, v.y)
}

fn as_dodgy(m: &Mover) -> dodgy_2d::Agent {
    dodgy_2d::Agent {
        position: d2(m.at),
        velocity: d2(m.velocity),
        radius: m.radius,
        avoidance_responsibility: 1.0,
    }
}

impl Orca {
    pub fn new(movers: Vec<Mover>) -> Orca {
        Orca::among(movers, Arc::default())
    }

    /// The movers among `walls`, each with its route round them (as `Sim::among`).
    pub fn among(mut movers: Vec<Mover>, walls: Arc<Obstacles>) -> Orca {
        for m in &mut movers {
            let _ = m.route_round(&walls);
        }
        let obstacles = walls.all().iter().map(|o| polygon(&o.shape)).collect();
        Orca {
            time: 0.0,
            movers,
            walls,
            obstacles,
        }
    }

    /// The velocity each agent takes now (the avoidance step alone).
    pub fn choose(&self, dt: f32) -> Vec<Vec2> {
        let crowd = Crowd::unnamed(
            self.time,
            (self.movers.iter())
                .map(|m| Agent {
                    at: m.at,
                    velocity: m.velocity,
                    radius: m.radius,
                })
                .collect(),
        );
        let options = dodgy_2d::AvoidanceOptions {
            obstacle_margin: 0.0,
            time_horizon: TIME_HORIZON,
            obstacle_time_horizon: 1.0,
        };
        let mut near = Vec::new();
        let obstacles: Vec<Cow<'_, dodgy_2d::Obstacle>> =
            self.obstacles.iter().map(Cow::Borrowed).collect();
        (self.movers.iter().enumerate())
            .map(|(i, m)| {
                if m.arrived.is_some() {
                    return Vec2::ZERO;
                }
                crowd.near(m.at, NEIGHBOUR_RADIUS, &mut near);
                let neighbours: Vec<Cow<'_, dodgy_2d::Agent>> = (near.iter())
                    .filter(|&&j| j != i)
                    .map(|&j| Cow::Owned(as_dodgy(&self.movers[j])))
                    .collect();
                // as RVO2's examples do, a tiny perturbation (here fixed per agent and step)
                // breaks the perfect symmetry that stalls ORCA head-on
                let turn =
                    ((i as f32 * 12.9898 + self.time as f32 * 78.233).sin() * 43758.547).fract();
                let preferred = m.desired() + Vec2::from_angle(turn * std::f32::consts::TAU) * 1e-3;
                let v = as_dodgy(m).compute_avoiding_velocity(
                    &neighbours,
                    &obstacles,
                    d2(preferred),
                    m.speed,
                    dt,
                    &options,
                );
                Vec2::new(v.x, v.y)
            })
            .collect()
    }

    pub fn step(&mut self, dt: f32) {
        for m in &mut self.movers {
            m.follow(&self.walls, self.time);
        }
        let chosen = self.choose(dt);
        self.time += f64::from(dt);
        for (m, v) in self.movers.iter_mut().zip(chosen) {
            if m.arrived.is_none() {
                m.velocity = v;
                m.at += v * dt;
                m.arrive_if_there(self.time);
            }
        }
    }
}
