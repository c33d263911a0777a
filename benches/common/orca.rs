//! ORCA (`dodgy_2d`) driven on the same scenes as the realizer's crowd, through its per-agent
//! API: every step each agent's neighbours within 8 m (the same grid search the realizer's
//! crowd uses; `dodgy_2d`'s own `Simulator` filters neighbours wrongly), its preferred velocity
//! toward its goal slowing in the last metre, the avoiding velocity taken at once (as ORCA
//! assumes), and arrival within 5 cm. Shared by `examples/crowd_quality.rs` and
//! `benches/crowd.rs`.
#![allow(dead_code)] // each user takes what it needs

use std::borrow::Cow;

use bml_realizer::crowd::{sim, Agent, Crowd};
use glam::Vec2;

/// ORCA's look-ahead for other agents (s).
pub const TIME_HORIZON: f32 = 3.0;

/// One ORCA agent and its goal.
#[derive(Debug, Clone)]
pub struct OrcaAgent {
    pub at: Vec2,
    pub velocity: Vec2,
    pub goal: Vec2,
    pub radius: f32,
    pub speed: f32,
    pub arrived: Option<f64>,
}

/// Everyone, stepped together from one snapshot.
pub struct Orca {
    pub time: f64,
    pub agents: Vec<OrcaAgent>,
}

fn d2(v: Vec2) -> dodgy_2d::Vec2 {
    dodgy_2d::Vec2::new(v.x, v.y)
}

impl Orca {
    pub fn new(agents: Vec<OrcaAgent>) -> Orca {
        Orca { time: 0.0, agents }
    }

    pub fn all_arrived(&self) -> bool {
        self.agents.iter().all(|a| a.arrived.is_some())
    }

    /// The velocity each agent takes now (the avoidance step alone).
    pub fn choose(&self, dt: f32) -> Vec<Vec2> {
        let crowd = Crowd::unnamed(
            self.time,
            (self.agents.iter())
                .map(|a| Agent {
                    at: a.at,
                    velocity: a.velocity,
                    radius: a.radius,
                })
                .collect(),
        );
        let options = dodgy_2d::AvoidanceOptions {
            obstacle_margin: 0.0,
            time_horizon: TIME_HORIZON,
            obstacle_time_horizon: 1.0,
        };
        let as_dodgy = |a: &OrcaAgent| dodgy_2d::Agent {
            position: d2(a.at),
            velocity: d2(a.velocity),
            radius: a.radius,
            avoidance_responsibility: 1.0,
        };
        let mut near = Vec::new();
        (self.agents.iter().enumerate())
            .map(|(i, a)| {
                if a.arrived.is_some() {
                    return Vec2::ZERO;
                }
                crowd.near(a.at, sim::NEIGHBOUR_RADIUS, &mut near);
                let neighbours: Vec<Cow<'_, dodgy_2d::Agent>> = (near.iter())
                    .filter(|&&j| j != i)
                    .map(|&j| Cow::Owned(as_dodgy(&self.agents[j])))
                    .collect();
                let d = a.goal - a.at;
                let l = d.length();
                let preferred = if l > 1e-6 {
                    d / l * a.speed * (l / sim::SLOW_RADIUS).min(1.0)
                } else {
                    Vec2::ZERO
                };
                // as RVO2's examples do, a tiny perturbation (here fixed per agent and step)
                // breaks the perfect symmetry that stalls ORCA head-on
                let turn =
                    ((i as f32 * 12.9898 + self.time as f32 * 78.233).sin() * 43758.547).fract();
                let preferred = preferred + Vec2::from_angle(turn * std::f32::consts::TAU) * 1e-3;
                let v = as_dodgy(a).compute_avoiding_velocity(
                    &neighbours,
                    &[],
                    d2(preferred),
                    a.speed,
                    dt,
                    &options,
                );
                Vec2::new(v.x, v.y)
            })
            .collect()
    }

    pub fn step(&mut self, dt: f32) {
        let chosen = self.choose(dt);
        for (a, v) in self.agents.iter_mut().zip(chosen) {
            if a.arrived.is_some() {
                continue;
            }
            a.velocity = v;
            a.at += v * dt;
            if a.at.distance(a.goal) < sim::ARRIVED {
                a.arrived = Some(self.time + f64::from(dt));
                a.velocity = Vec2::ZERO;
            }
        }
        self.time += f64::from(dt);
    }
}
