//! Behaviour nets (after Granieri, Becket, Reich, Crabtree and Badler, §2 of their real-time
//! pedestrians paper): a fixed network of nodes across whose links only floating-point values
//! travel, from sensors (the bearing θ and distance d of a goal, a wall, the nearest obstacle
//! or walker) through control nodes — *attract* and *avoid*, proportional servos with
//! thresholds — to a *walk* motor node that sums what they urge. The network is stepped
//! synchronously in two phases: every node first loads its inputs from what the others emitted
//! at the previous step, then all emit together, so that the result never depends on the
//! order nodes are evaluated in (each node could run on a processor of its own). [`settle`]
//! steps a network as many times as it is deep, from rest, so that its output is a function of
//! the surroundings alone: what the footstep planner samples.
//!
//! [`settle`]: BehaviourNet::settle

use glam::Vec2;

use crate::world::space::Obstacles;

/// Where an agent is and what is around it, as sensors read it.
#[derive(Debug, Clone, Copy)]
pub struct Surroundings<'a> {
    /// Where the agent stands (x, z).
    pub at: Vec2,
    /// Its heading (rad about +y from +z).
    pub heading: f32,
    /// The world's obstacles.
    pub obstacles: &'a Obstacles,
    /// The other walkers (x, z).
    pub walkers: &'a [Vec2],
}

/// What a sensor senses: its output is (θ, d), the bearing (rad, relative to the heading,
/// positive to the left) and distance (m) of what it senses; d is infinite when it senses
/// nothing.
#[derive(Debug, Clone, PartialEq)]
pub enum Sensor {
    /// A fixed point.
    Location(Vec2),
    /// A wall segment: its nearest point.
    Line(Vec2, Vec2),
    /// The nearest obstacle within `range` m and `half_field` rad of the heading.
    Obstacles {
        /// How far it senses (m).
        range: f32,
        /// Half its field (rad).
        half_field: f32,
    },
    /// The nearest other walker within `range` m and `half_field` rad of the heading.
    Walkers {
        /// How far it senses (m).
        range: f32,
        /// Half its field (rad).
        half_field: f32,
    },
}

/// A node: where its input comes from (indices of other nodes) and what it computes.
#[derive(Debug, Clone, PartialEq)]
pub enum Node {
    /// A perceptual node.
    Sense(Sensor),
    /// Brings θ within ±`t_theta` and d within `t_d`: emits (Δθ, Δd).
    Attract {
        /// The sensor node it reads.
        input: usize,
        /// Angular threshold (rad).
        t_theta: f32,
        /// Distance threshold (m).
        t_d: f32,
        /// Angular weight.
        k_theta: f32,
        /// Distance weight.
        k_d: f32,
    },
    /// Keeps d beyond `t_d`, steering away: emits (Δθ, Δd).
    Avoid {
        /// The sensor node it reads.
        input: usize,
        /// Distance threshold (m).
        t_d: f32,
        /// Angular weight.
        k_theta: f32,
        /// Distance weight.
        k_d: f32,
    },
    /// The walking motor: emits the sums of its inputs' Δθ and Δd, and the energy of the
    /// situation — the sum of their squares, zero when every control is content.
    Walk {
        /// The control nodes it reads, summed in this order.
        inputs: Vec<usize>,
    },
}

/// A node's output: three floats (sensors: θ, d, 0; controls: Δθ, Δd, 0; walk: ΣΔθ, ΣΔd,
/// energy).
pub type Signal = [f32; 3];

/// The angle `a` wrapped into (−π, π].
pub fn wrap(a: f32) -> f32 {
    let t = std::f32::consts::TAU;
    let w = a - t * (a / t).round();
    if w <= -std::f32::consts::PI {
        w + t
    } else {
        w
    }
}

/// The attract law: (Δθ, Δd) for bearing `theta` and distance `d`.
pub fn attract(theta: f32, d: f32, t_theta: f32, t_d: f32, k_theta: f32, k_d: f32) -> (f32, f32) {
    let dt = if (-t_theta..=t_theta).contains(&theta) {
        0.0
    } else if theta > t_theta {
        k_theta * (theta - t_theta)
    } else {
        k_theta * (theta + t_theta)
    };
    let dd = if d <= t_d { 0.0 } else { k_d * (d - t_d) };
    (dt, dd)
}

/// The avoid law: (Δθ, Δd) for bearing `theta` and distance `d` (the seed prints the distance
/// law under the angle's name; it is Δd = k_d (t_d − d)).
pub fn avoid(theta: f32, d: f32, t_d: f32, k_theta: f32, k_d: f32) -> (f32, f32) {
    if d > t_d {
        return (0.0, 0.0);
    }
    let pi = std::f32::consts::PI;
    let dt = if theta >= 0.0 {
        k_theta * (pi - theta)
    } else {
        k_theta * (-pi - theta)
    };
    (dt, k_d * (t_d - d))
}

/// Steps that carry a sensor's reading to the motor: a net is sensors, then controls reading
/// them, then walk nodes reading the controls ([`BehaviourNet::new`] refuses any other shape).
const DEPTH: usize = 3;

/// A behaviour net.
#[derive(Debug, Clone, PartialEq)]
pub struct BehaviourNet {
    nodes: Vec<Node>,
    /// What each node emitted at the last step.
    out: Vec<Signal>,
}

impl BehaviourNet {
    /// A net of `nodes`; `Err` names a node whose input is not a node of the right kind.
    pub fn new(nodes: Vec<Node>) -> Result<BehaviourNet, String> {
        let n = nodes.len();
        for (i, node) in nodes.iter().enumerate() {
            let ok = |j: usize, sense: bool| j < n && matches!(nodes[j], Node::Sense(_)) == sense;
            let good = match node {
                Node::Sense(_) => true,
                Node::Attract { input, .. } | Node::Avoid { input, .. } => ok(*input, true),
                Node::Walk { inputs } => inputs
                    .iter()
                    .all(|&j| ok(j, false) && !matches!(nodes[j], Node::Walk { .. })),
            };
            if !good {
                return Err(format!(
                    "node {i}: its input is not a node of the kind it reads"
                ));
            }
        }
        Ok(BehaviourNet {
            out: vec![[0.0; 3]; n],
            nodes,
        })
    }

    /// Every node back at rest (all outputs zero).
    pub fn rest(&mut self) {
        self.out.iter_mut().for_each(|o| *o = [0.0; 3]);
    }

    /// Moves the fixed point that sensor node `i` senses to `at`; `false` (and nothing
    /// changes) when node `i` is not a [`Sensor::Location`].
    pub fn aim(&mut self, i: usize, at: Vec2) -> bool {
        match self.nodes.get_mut(i) {
            Some(Node::Sense(Sensor::Location(p))) => {
                *p = at;
                true
            }
            _ => false,
        }
    }

    /// Its nodes.
    pub fn nodes(&self) -> &[Node] {
        &self.nodes
    }

    /// What node `i` emitted at the last step.
    pub fn output(&self, i: usize) -> Signal {
        self.out[i]
    }

    /// One synchronous step: every node (in `order`, which changes nothing) loads from the
    /// previous outputs; then all emit.
    pub fn step(&mut self, order: &[usize], env: &Surroundings) {
        let mut next = vec![[0.0; 3]; self.nodes.len()];
        for &i in order {
            next[i] = self.load(i, env);
        }
        self.out = next;
    }

    /// Steps from rest until every sensor's reading has reached the motor; returns what each
    /// node emits then.
    pub fn settle(&mut self, env: &Surroundings) -> &[Signal] {
        let order: Vec<usize> = (0..self.nodes.len()).collect();
        self.settle_in(&order, env)
    }

    /// [`settle`](Self::settle) evaluating nodes in `order`.
    pub fn settle_in(&mut self, order: &[usize], env: &Surroundings) -> &[Signal] {
        self.rest();
        for _ in 0..DEPTH {
            self.step(order, env);
        }
        &self.out
    }

    /// The energy the walk motor node `walk` reports for `env` (0 if it is not a walk node).
    pub fn energy(&mut self, walk: usize, env: &Surroundings) -> f32 {
        self.settle(env)[walk][2]
    }

    fn load(&self, i: usize, env: &Surroundings) -> Signal {
        match &self.nodes[i] {
            Node::Sense(s) => {
                let (theta, d) = sense(s, env);
                [theta, d, 0.0]
            }
            &Node::Attract {
                input,
                t_theta,
                t_d,
                k_theta,
                k_d,
            } => {
                let [theta, d, _] = self.out[input];
                let (a, b) = attract(theta, d, t_theta, t_d, k_theta, k_d);
                [a, b, 0.0]
            }
            &Node::Avoid {
                input,
                t_d,
                k_theta,
                k_d,
            } => {
                let [theta, d, _] = self.out[input];
                let (a, b) = avoid(theta, d, t_d, k_theta, k_d);
                [a, b, 0.0]
            }
            Node::Walk { inputs } => {
                let mut s = [0.0; 3];
                for &j in inputs {
                    let [a, b, _] = self.out[j];
                    s[0] += a;
                    s[1] += b;
                    s[2] += a * a + b * b;
                }
                s
            }
        }
    }
}

/// (θ, d) of a point `p` seen from `env`.
fn bearing(env: &Surroundings, p: Vec2) -> (f32, f32) {
    let r = p - env.at;
    (wrap(r.x.atan2(r.y) - env.heading), r.length())
}

fn sense(s: &Sensor, env: &Surroundings) -> (f32, f32) {
    let nothing = (0.0, f32::INFINITY);
    match s {
        Sensor::Location(p) => bearing(env, *p),
        Sensor::Line(a, b) => {
            let (_, p) = crate::world::space::distance::point_segment(env.at, *a, *b);
            bearing(env, p)
        }
        Sensor::Obstacles { range, half_field } => {
            let lo = env.at - Vec2::splat(*range);
            let hi = env.at + Vec2::splat(*range);
            (env.obstacles.near_box(lo, hi, 0.0).into_iter())
                .map(|k| {
                    let (d, away) = env.obstacles.all()[k as usize].shape.distance(env.at);
                    bearing(env, env.at - away * d.max(0.0))
                })
                .filter(|(t, d)| *d <= *range && t.abs() <= *half_field)
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .unwrap_or(nothing)
        }
        Sensor::Walkers { range, half_field } => (env.walkers.iter())
            .map(|w| bearing(env, *w))
            .filter(|(t, d)| *d > 1e-6 && *d <= *range && t.abs() <= *half_field)
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .unwrap_or(nothing),
    }
}

#[cfg(test)]
#[path = "behaviour/tests.rs"]
mod tests;
