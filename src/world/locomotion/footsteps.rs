//! Footstep planning (after Granieri, Becket, Reich, Crabtree and Badler, §2.3.1 and §4.4):
//! at each footfall the next placement of the swinging foot is chosen once, by sampling a fan
//! of places in front of the planted foot — three step lengths (short, medium, long: the
//! steps a recorded gait would have) × a spread of turns — and taking the one where the
//! behaviour net's energy is least, the agent pretending to stand at each (midway between its
//! feet, facing the new heading). Sampling the field instead of following its gradient from
//! where the agent stands steps over the thresholds' discontinuities smoothly: no sawtooth
//! along a wall. The agent turns about its planted foot. When many agents plan in one frame,
//! a budget of samples a frame lowers the turns each samples ([`allot`]), and agents start
//! their steps staggered over a step's time ([`stagger`]) so that they do not all plan at once.

use glam::Vec2;

use super::gait::HALF_WIDTH;
use crate::world::nets::behaviour::{BehaviourNet, Node, Sensor, Surroundings};

/// The fan of candidate steps.
#[derive(Debug, Clone, PartialEq)]
pub struct Fan {
    /// Step lengths (m): how far ahead of the planted foot the swinging one lands.
    pub lengths: [f32; 3],
    /// Turns (rad) of the heading a step may take, tried from straight on outwards (right
    /// first).
    pub turns: Vec<f32>,
}

impl Fan {
    /// Steps of 0.6, 1 and 1.4 × `step` m, turning up to ±`max_turn` rad in `turns` (odd)
    /// evenly spaced turns.
    pub fn new(step: f32, max_turn: f32, turns: usize) -> Fan {
        let half = turns.max(1) / 2;
        let mut list = vec![0.0];
        for k in 1..=half {
            let a = max_turn * k as f32 / half as f32;
            list.extend([-a, a]);
        }
        Fan {
            lengths: [0.6 * step, step, 1.4 * step],
            turns: list,
        }
    }

    /// How many places the whole fan samples.
    pub fn len(&self) -> usize {
        self.lengths.len() * self.turns.len()
    }

    /// Whether it samples none (never).
    pub fn is_empty(&self) -> bool {
        self.turns.is_empty()
    }
}

/// Where an agent's feet are between steps: one planted, the other about to swing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Feet {
    /// The planted foot (x, z).
    pub planted: Vec2,
    /// Whether the planted foot is the left one.
    pub planted_left: bool,
    /// The agent's heading (rad about +y from +z).
    pub heading: f32,
}

/// A chosen step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Footstep {
    /// Where the swinging foot lands (x, z).
    pub at: Vec2,
    /// The heading after the step.
    pub heading: f32,
    /// Where the agent stands after it: midway between its feet.
    pub body: Vec2,
    /// The energy there.
    pub energy: f32,
}

/// The agent's forward and left directions at `heading`.
pub fn axes(heading: f32) -> (Vec2, Vec2) {
    let (s, c) = heading.sin_cos();
    (Vec2::new(s, c), Vec2::new(c, -s))
}

impl Feet {
    /// Standing at `body` facing `heading`, the left foot planted.
    pub fn standing(body: Vec2, heading: f32) -> Feet {
        let (_, left) = axes(heading);
        Feet {
            planted: body + left * HALF_WIDTH,
            planted_left: true,
            heading,
        }
    }

    /// Where the agent stands now: midway between the planted foot and where the other foot
    /// stands beside it.
    pub fn body(&self) -> Vec2 {
        let (_, left) = axes(self.heading);
        let side = if self.planted_left { -1.0 } else { 1.0 };
        self.planted + left * side * HALF_WIDTH
    }

    /// The candidate of `length` and `turn`: the swinging foot lands `length` ahead of the
    /// planted one and a hip width beside it, along the turned heading.
    pub fn candidate(&self, length: f32, turn: f32) -> (Vec2, f32) {
        let heading = self.heading + turn;
        let (ahead, left) = axes(heading);
        let side = if self.planted_left { -2.0 } else { 2.0 };
        (
            self.planted + ahead * length + left * side * HALF_WIDTH,
            heading,
        )
    }

    /// After stepping `step`: its foot planted, the other about to swing.
    pub fn after(&self, step: &Footstep) -> Feet {
        Feet {
            planted: step.at,
            planted_left: !self.planted_left,
            heading: step.heading,
        }
    }
}

/// A behaviour net for walking to `goal` (arriving within `arrive` m), avoiding obstacles
/// within `clear` m and other walkers within `personal` m; returns it and its walk node.
pub fn walking_net(goal: Vec2, arrive: f32, clear: f32, personal: f32) -> (BehaviourNet, usize) {
    let half = 100f32.to_radians();
    let nodes = vec![
        Node::Sense(Sensor::Location(goal)),
        Node::Sense(Sensor::Obstacles {
            range: 3.0,
            half_field: half,
        }),
        Node::Sense(Sensor::Walkers {
            range: 3.0,
            half_field: half,
        }),
        Node::Attract {
            input: 0,
            t_theta: 0.05,
            t_d: arrive,
            k_theta: 1.0,
            k_d: 1.0,
        },
        Node::Avoid {
            input: 1,
            t_d: clear,
            k_theta: 0.4,
            k_d: 6.0,
        },
        Node::Avoid {
            input: 2,
            t_d: personal,
            k_theta: 0.4,
            k_d: 4.0,
        },
        Node::Walk {
            inputs: vec![3, 4, 5],
        },
    ];
    (BehaviourNet::new(nodes).expect("a well-formed net"), 6)
}

/// The node of [`walking_net`] that senses where the walk goes (what a walker following a route
/// moves along it with [`BehaviourNet::aim`]).
pub const GOAL_SENSOR: usize = 0;

/// Chooses the next step from `feet` by sampling `samples` places of `fan` (at least its
/// three lengths straight on; the turns thinned evenly when fewer than the whole fan): the
/// least energy of `net`'s walk node `walk`, among places that keep `radius` from every
/// obstacle of `here` — where the body stands now, which the step must improve on: `None`
/// when no place has less energy than standing still (arrived, or stuck). Ties go to the
/// first sampled.
pub fn choose(
    net: &mut BehaviourNet,
    walk: usize,
    feet: &Feet,
    fan: &Fan,
    samples: usize,
    here: &Surroundings,
    radius: f32,
) -> Option<Footstep> {
    let standing = net.energy(walk, here);
    let turns = (samples / fan.lengths.len()).clamp(1, fan.turns.len());
    // every k-th turn of the list (straight on first, then outwards in pairs)
    let stride = fan.turns.len().div_ceil(turns);
    let mut best: Option<Footstep> = None;
    for &turn in fan.turns.iter().step_by(stride.max(1)) {
        for &length in &fan.lengths {
            let (at, heading) = feet.candidate(length, turn);
            let body = (feet.planted + at) / 2.0;
            if here.obstacles.clearance(body, radius + 0.5) < radius
                || !here.obstacles.segment_clear(feet.planted, at, 0.02)
            {
                continue;
            }
            let env = Surroundings {
                at: body,
                heading,
                ..*here
            };
            let energy = net.energy(walk, &env);
            if best.is_none_or(|b| energy < b.energy) {
                best = Some(Footstep {
                    at,
                    heading,
                    body,
                    energy,
                });
            }
        }
    }
    best.filter(|b| b.energy < standing - 1e-6)
}

/// How many places each of `due` agents planning in one frame samples under a budget of
/// `budget` places a frame: the whole fan (`full`) when it fits, fewer when not, never fewer
/// than its three lengths.
pub fn allot(budget: usize, due: usize, full: usize) -> usize {
    if due == 0 {
        return full;
    }
    (budget / due).clamp(3, full)
}

/// When agent `index` of `count` takes its first step: staggered evenly over one step of
/// `step_time` s, so that their plans spread over the frames.
pub fn stagger(index: usize, count: usize, step_time: f64) -> f64 {
    if count == 0 {
        return 0.0;
    }
    step_time * (index % count) as f64 / count as f64
}

#[cfg(test)]
mod tests;
