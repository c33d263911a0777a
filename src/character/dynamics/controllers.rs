//! Physical controllers: what turns the simulated joints. Each adds to a [`Drive`]: joint
//! torques (per part, the world torque of its joint on it; the parent gets the opposite) and PD
//! pulls toward target rotations, so that several controllers on one joint sum — torques add,
//! PD pulls add their gains (their targets weighted by stiffness: the sum of linear springs).
//! The simulation realizes the PD pulls with rapier's joint motors, which solve the spring and
//! damper implicitly with the joints: applied as explicit torques, PD on a light part (a foot,
//! 0.01 kg m², or the pelvis between three joints) diverges once the damping per step exceeds
//! the part's inertia, which standing gains do. A PD pose controller pulls joints toward target
//! rotations; the balance controller keeps the centre of mass over the feet with a virtual
//! force carried by the standing legs (virtual model control), the pelvis upright through the
//! hips and the legs and spine in a standing pose, all gains scaled by one stiffness
//! multiplier; the rag doll applies nothing.

use glam::{DQuat, DVec2, DVec3};

use super::sim::Simulation;

/// A physical controller (see the module documentation).
pub trait Controller {
    /// Adds its torques and PD pulls for the simulation's current state to `drive`.
    fn drive(&self, sim: &Simulation, drive: &mut Drive);
}

/// A PD pull on one joint: toward `target` (the part's rotation relative to its parent part)
/// with stiffness `kp` (N m/rad) and damping `kd` (N m s/rad).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pull {
    /// Target rotation relative to the parent part.
    pub target: DQuat,
    /// Stiffness.
    pub kp: f64,
    /// Damping.
    pub kd: f64,
}

/// What the controllers ask of the joints in one step (see the module documentation).
#[derive(Debug, Clone, PartialEq)]
pub struct Drive {
    /// Per part, the world torque of its joint on it (the parent gets the opposite).
    pub torques: Vec<DVec3>,
    /// Per part, the sum of the PD pulls on its joint (`None`: the joint is free).
    pub pulls: Vec<Option<Pull>>,
}

impl Drive {
    /// Nothing asked of `n` parts.
    pub fn new(n: usize) -> Drive {
        Drive {
            torques: vec![DVec3::ZERO; n],
            pulls: vec![None; n],
        }
    }

    /// Adds a PD pull on part `i`'s joint: stiffnesses and dampings add, and the target is the
    /// stiffness-weighted mean of the targets (the rest point of the summed springs).
    pub fn pull(&mut self, i: usize, target: DQuat, kp: f64, kd: f64) {
        let Some(slot) = self.pulls.get_mut(i) else {
            return;
        };
        *slot = Some(match *slot {
            None => Pull { target, kp, kd },
            Some(p) => {
                let q = if p.target.dot(target) < 0.0 {
                    -target
                } else {
                    target
                };
                let sum = p.kp + kp;
                let mean = if sum > 0.0 {
                    (p.target * (p.kp / sum) + q * (kp / sum)).normalize()
                } else {
                    p.target
                };
                Pull {
                    target: mean,
                    kp: sum,
                    kd: p.kd + kd,
                }
            }
        });
    }
}

/// A PD law: `kp (x_d − x) + kd (v_d − v)`.
pub fn pd(kp: f64, kd: f64, x_d: f64, x: f64, v_d: f64, v: f64) -> f64 {
    kp * (x_d - x) + kd * (v_d - v)
}

/// The explicit PD torque (world frame) that pulls part `i` toward the rotation `target`
/// relative to its parent part (the world for the root): [`pd`] about the error's axis, the
/// relative angular velocity damped. For the root's upright, which no joint motor can hold;
/// its gains stay far below what the whole body's inertia bears.
pub fn pose_torque(sim: &Simulation, i: usize, target: DQuat, kp: f64, kd: f64) -> DVec3 {
    let parts = sim.parts();
    let s = parts[i];
    let (parent_q, parent_w) = match sim.humanoid().parts[i].parent {
        Some(p) => (parts[p].orientation, parts[p].angular),
        None => (DQuat::IDENTITY, DVec3::ZERO),
    };
    let relative = parent_q.inverse() * s.orientation;
    // the error as a rotation vector in the part's frame (shortest way round)
    let mut error = relative.inverse() * target;
    if error.w < 0.0 {
        error = -error;
    }
    let (axis, angle) = error.to_axis_angle();
    let e = s.orientation * (axis * angle);
    kp * e - kd * (s.angular - parent_w)
}

/// Pulls the listed parts toward target rotations relative to their parents.
#[derive(Debug, Clone, PartialEq)]
pub struct PoseController {
    /// (part, target rotation relative to its parent part, kp in N m/rad, kd in N m s/rad).
    pub targets: Vec<(usize, DQuat, f64, f64)>,
}

impl Controller for PoseController {
    fn drive(&self, sim: &Simulation, drive: &mut Drive) {
        for &(i, target, kp, kd) in &self.targets {
            if sim.is_physical(i) {
                drive.pull(i, target, kp, kd);
            }
        }
    }
}

/// No torque at all: the simulated parts fall as they will.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct RagDoll;

impl Controller for RagDoll {
    fn drive(&self, _sim: &Simulation, _drive: &mut Drive) {}
}

/// Keeps the body standing (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Balance {
    /// The pelvis' height to hold, relative to the leg's length (hip to sole at rest).
    pub pelvis_height: f64,
    /// Scales every gain.
    pub stiffness: f64,
}

impl Default for Balance {
    fn default() -> Self {
        Balance {
            pelvis_height: 0.98,
            stiffness: 1.0,
        }
    }
}

/// The balance controller's gains at stiffness 1.
mod gains {
    /// Centre of mass over the feet, horizontally (N/m, N s/m).
    pub const COM: (f64, f64) = (1200.0, 500.0);
    /// Pelvis height (N/m, N s/m).
    pub const HEIGHT: (f64, f64) = (4000.0, 600.0);
    /// Pelvis upright (N m/rad, N m s/rad): no damping, as an explicit torque it would turn
    /// the light pelvis (0.06 kg m²) against the joints' motors and diverge; the legs' motors
    /// damp it.
    pub const UPRIGHT: (f64, f64) = (1500.0, 0.0);
    /// Spine toward straight, relative to the pelvis.
    pub const SPINE: (f64, f64) = (800.0, 60.0);
    /// Legs' joints toward the standing pose (hip, knee, ankle).
    pub const LEG: (f64, f64) = (150.0, 15.0);
}

/// The parts of each leg, hip to foot, by name.
const LEGS: [[&str; 3]; 2] = [
    ["l_thigh", "l_shank", "l_foot"],
    ["r_thigh", "r_shank", "r_foot"],
];

fn part(sim: &Simulation, name: &str) -> Option<usize> {
    sim.humanoid().parts.iter().position(|p| p.name == name)
}

impl Balance {
    /// The pelvis height it holds (m): at rest less the rest leg length (hip joint to sole)
    /// times one minus [`pelvis_height`](Self::pelvis_height).
    pub fn target_height(&self, sim: &Simulation) -> f64 {
        let h = sim.humanoid();
        let hip = part(sim, "l_thigh").map_or(0.9, |t| f64::from(h.rest[t].y));
        f64::from(h.rest[0].y) - (1.0 - self.pelvis_height) * hip
    }

    /// The leg's standing pose at the pelvis height it holds (hip, knee, ankle rotations): the
    /// hip-to-ankle distance that height leaves, the knee bent to make it (law of cosines), the
    /// pelvis upright and the foot flat. Hips flex about −x, knees bend about +x.
    pub fn crouch(&self, sim: &Simulation) -> [DQuat; 3] {
        let h = sim.humanoid();
        let (Some(thigh), Some(shank), Some(foot)) = (
            part(sim, "l_thigh"),
            part(sim, "l_shank"),
            part(sim, "l_foot"),
        ) else {
            return [DQuat::IDENTITY; 3];
        };
        let y = |i: usize| f64::from(h.rest[i].y);
        let (a, b) = (y(thigh) - y(shank), y(shank) - y(foot));
        let drop = y(0) - self.target_height(sim);
        let d = (a + b - drop).clamp((a - b).abs() + 0.05, a + b);
        let angle = |x: f64, y: f64, opposite: f64| {
            ((x * x + y * y - opposite * opposite) / (2.0 * x * y))
                .clamp(-1.0, 1.0)
                .acos()
        };
        let (hip, ankle) = (angle(a, d, b), angle(b, d, a));
        [
            DQuat::from_rotation_x(-hip),
            DQuat::from_rotation_x(hip + ankle),
            DQuat::from_rotation_x(-ankle),
        ]
    }

    /// Whether the body has fallen: the centre of mass more than 5 cm outside the support
    /// polygon, no foot on the ground, or the pelvis down to half its standing height.
    pub fn fallen(&self, sim: &Simulation) -> bool {
        let (c, _) = sim.centre_of_mass();
        let feet = sim.contacts();
        let pelvis = sim.parts()[0].position.y;
        feet.is_empty()
            || pelvis < 0.5 * self.target_height(sim)
            || outside(&support_polygon(&feet), DVec2::new(c.x, c.z)) > 0.05
    }
}

impl Controller for Balance {
    fn drive(&self, sim: &Simulation, drive: &mut Drive) {
        let k = self.stiffness;
        let parts = sim.parts();
        let (c, cv) = sim.centre_of_mass();
        let mass: f64 = parts.iter().map(|p| p.mass).sum();
        // over the middle of the soles (not of the touching corners: a heel that lifts would
        // move the target toward the other foot and lift it further)
        let soles: Vec<DVec3> = (LEGS.iter())
            .filter_map(|l| part(sim, l[2]))
            .map(|f| sim.sole_centre(f))
            .collect();
        let centre = if soles.is_empty() {
            DVec3::new(c.x, 0.0, c.z)
        } else {
            soles.iter().sum::<DVec3>() / soles.len() as f64
        };
        let pelvis = parts[0];
        let height = self.target_height(sim);
        // the virtual force on the centre of mass: its weight, over the feet, at the height
        let force = DVec3::new(
            gains::COM.0 * k * (centre.x - c.x) - gains::COM.1 * k * cv.x,
            mass * 9.81 + gains::HEIGHT.0 * k * (height - pelvis.position.y)
                - gains::HEIGHT.1 * k * pelvis.velocity.y,
            gains::COM.0 * k * (centre.z - c.z) - gains::COM.1 * k * cv.z,
        );
        // the pelvis upright, in the world
        let upright = pose_torque(
            sim,
            0,
            DQuat::IDENTITY,
            gains::UPRIGHT.0 * k,
            gains::UPRIGHT.1 * k,
        );
        let standing: Vec<[usize; 3]> = (LEGS.iter())
            .filter_map(|names| {
                let leg = [
                    part(sim, names[0])?,
                    part(sim, names[1])?,
                    part(sim, names[2])?,
                ];
                leg.iter().all(|&i| sim.is_physical(i)).then_some(leg)
            })
            .collect();
        let shares = weight_shares(sim, &standing, c);
        let crouch = self.crouch(sim);
        for (leg, &share) in standing.iter().zip(&shares) {
            for (&i, &target) in leg.iter().zip(&crouch) {
                // the part above this joint (toward the pelvis) carries its share of the virtual
                // wrench: the force at the centre of mass and the pelvis' upright torque
                let wrench = (c - parts[i].position).cross(force) + upright;
                drive.torques[i] -= wrench * share;
                drive.pull(i, target, gains::LEG.0 * k, gains::LEG.1 * k);
            }
            // a foot can only turn the body as far as its sole pushes on the ground: the ankle's
            // torque about the ground's axes stays within what keeps the centre of pressure
            // inside the sole (80 % of its half length for pitch, of its half width for roll)
            let foot = &sim.humanoid().parts[leg[2]];
            let weight = mass * 9.81 * share;
            let t = &mut drive.torques[leg[2]];
            let (pitch, roll) = (
                0.8 * weight * foot.size[2] / 2.0,
                0.8 * weight * foot.size[0] / 2.0,
            );
            t.x = t.x.clamp(-pitch, pitch);
            t.z = t.z.clamp(-roll, roll);
        }
        if let Some(spine) = part(sim, "upper-body").filter(|&i| sim.is_physical(i)) {
            drive.pull(
                spine,
                DQuat::IDENTITY,
                gains::SPINE.0 * k,
                gains::SPINE.1 * k,
            );
        }
    }
}

/// How the standing legs share the body's weight: in proportion to how near the centre of mass
/// is to each sole along the line between them (all on one when it is over that sole or
/// beyond; evenly for one leg or feet at one place). A body that leans over one foot carries
/// itself on that leg, which an even split would not let it do.
fn weight_shares(sim: &Simulation, legs: &[[usize; 3]], c: DVec3) -> Vec<f64> {
    if legs.len() != 2 {
        return vec![1.0 / legs.len().max(1) as f64; legs.len()];
    }
    let (a, b) = (sim.sole_centre(legs[0][2]), sim.sole_centre(legs[1][2]));
    let (a, b, c) = (
        DVec2::new(a.x, a.z),
        DVec2::new(b.x, b.z),
        DVec2::new(c.x, c.z),
    );
    let line = b - a;
    if line.length_squared() < 1e-6 {
        return vec![0.5, 0.5];
    }
    let toward_b = ((c - a).dot(line) / line.length_squared()).clamp(0.0, 1.0);
    vec![1.0 - toward_b, toward_b]
}

/// The convex hull of points on the ground (x, z), counter-clockwise.
pub fn support_polygon(points: &[DVec3]) -> Vec<DVec2> {
    let mut p: Vec<DVec2> = points.iter().map(|q| DVec2::new(q.x, q.z)).collect();
    p.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    p.dedup_by(|a, b| a.distance(*b) < 1e-9);
    if p.len() < 3 {
        return p;
    }
    let cross = |o: DVec2, a: DVec2, b: DVec2| (a - o).perp_dot(b - o);
    let mut hull: Vec<DVec2> = Vec::with_capacity(2 * p.len());
    for pass in 0..2 {
        let start = hull.len();
        let points: Box<dyn Iterator<Item = &DVec2>> = if pass == 0 {
            Box::new(p.iter())
        } else {
            Box::new(p.iter().rev())
        };
        for &q in points {
            while hull.len() >= start + 2
                && cross(hull[hull.len() - 2], hull[hull.len() - 1], q) <= 0.0
            {
                hull.pop();
            }
            hull.push(q);
        }
        hull.pop();
    }
    hull
}

/// How far `q` lies outside the convex polygon (0 inside; for fewer than three corners, the
/// distance to them).
pub fn outside(polygon: &[DVec2], q: DVec2) -> f64 {
    if polygon.len() < 3 {
        return polygon
            .iter()
            .map(|p| p.distance(q))
            .fold(f64::INFINITY, f64::min);
    }
    let mut worst: f64 = 0.0;
    for (i, &a) in polygon.iter().enumerate() {
        let b = polygon[(i + 1) % polygon.len()];
        let edge = b - a;
        // outward distance from the edge line (counter-clockwise: outside is to the right)
        let d = -edge.perp_dot(q - a) / edge.length();
        worst = worst.max(d);
    }
    worst
}
