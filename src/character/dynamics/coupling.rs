//! How kinematic chains reach the simulated body they hang from (mixed dynamics, thesis §3.4),
//! with nothing lagging a step and the momentum of the whole kept: each chain counts as a rigid
//! body in its current configuration ([`Composite`]), added to its connector's mass properties
//! (rapier then moves it with the connector within the step, its weight included), plus the
//! momentum of its motion relative to the connector ([`relative_momentum`]). A [`Carrier`]
//! gives the connector, over each step, the opposite of how much that relative momentum
//! changed, and of how much rapier's own momentum jumped when the composite changed (rapier
//! keeps a body's velocities, not its momentum, when its mass properties change). Summed over
//! the steps these impulses are exactly the chain's momentum change, which is what its inverse
//! dynamics integrates to (docs/physics.md, "Coupling").

use glam::{DQuat, DVec3};
use rapier3d::prelude as rp;

use super::mass::MassProperties;
use super::rnea::{JointMotion, Link};
use super::{drot, dv, v};

/// What a unit mass at `c` adds to an inertia about the origin: |c|² 1 − c cᵀ.
fn parallel_axis(c: DVec3) -> glam::DMat3 {
    glam::DMat3::from_diagonal(DVec3::splat(c.length_squared()))
        - glam::DMat3::from_cols(c * c.x, c * c.y, c * c.z)
}

/// A rigid body made of links: mass, centre of mass and inertia about it (connector frame).
/// Empty by default (glam's default matrix is the identity, not zero).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Composite {
    /// Mass (kg).
    pub mass: f64,
    /// Σ m c: the first moment about the connector's origin (kg m).
    pub moment: DVec3,
    /// Σ (R I Rᵀ + m (|c|² 1 − c cᵀ)) about the connector's origin (kg m²).
    pub inertia: glam::DMat3,
}

impl Default for Composite {
    fn default() -> Self {
        Composite {
            mass: 0.0,
            moment: DVec3::ZERO,
            inertia: glam::DMat3::ZERO,
        }
    }
}

impl Composite {
    /// Adds the links of a chain, placed by `motions` (connector frame).
    pub fn add(&mut self, links: &[Link], motions: &[JointMotion]) {
        let mut frames: Vec<(DVec3, DQuat)> = Vec::with_capacity(links.len());
        for (l, m) in links.iter().zip(motions) {
            let (p, q) = l
                .parent
                .map_or((DVec3::ZERO, DQuat::IDENTITY), |i| frames[i]);
            let (at, turn) = (p + q * l.offset, q * m.rotation);
            frames.push((at, turn));
            let c = at + turn * l.com;
            let r = glam::DMat3::from_quat(turn);
            self.mass += l.mass;
            self.moment += l.mass * c;
            self.inertia += r * l.inertia * r.transpose() + parallel_axis(c) * l.mass;
        }
    }

    /// One rigid body (its frame is the composite's).
    pub fn of(body: &MassProperties) -> Composite {
        Composite {
            mass: body.mass,
            moment: body.mass * body.com,
            inertia: body.inertia + parallel_axis(body.com) * body.mass,
        }
    }

    /// The sum of two composites (both in the same frame).
    pub fn plus(&self, other: &Composite) -> Composite {
        Composite {
            mass: self.mass + other.mass,
            moment: self.moment + other.moment,
            inertia: self.inertia + other.inertia,
        }
    }

    /// Its centre of mass (frame origin when empty).
    pub fn centre(&self) -> DVec3 {
        if self.mass <= 1e-12 {
            DVec3::ZERO
        } else {
            self.moment / self.mass
        }
    }

    /// Its angular momentum about the world's origin when it moves as one rigid body placed at
    /// `at`, turned by `turn`, its centre of mass moving at `velocity` and turning at `spin`
    /// (world frame): I_c ω + m c × v.
    pub fn angular_momentum(&self, at: DVec3, turn: DQuat, velocity: DVec3, spin: DVec3) -> DVec3 {
        let c = self.centre();
        let r = glam::DMat3::from_quat(turn);
        let about = r * (self.inertia - parallel_axis(c) * self.mass) * r.transpose();
        about * spin + self.mass * (at + turn * c).cross(velocity)
    }

    /// Every quantity times `k`.
    pub fn scaled(&self, k: f64) -> Composite {
        Composite {
            mass: self.mass * k,
            moment: self.moment * k,
            inertia: self.inertia * k,
        }
    }

    /// As rapier's mass properties (inertia about the centre of mass).
    pub fn rapier(&self) -> rp::MassProperties {
        if self.mass <= 1e-12 {
            return rp::MassProperties::default();
        }
        let c = self.centre();
        let about = self.inertia - parallel_axis(c) * self.mass;
        let m = |col: DVec3| rp::Vector::new(col.x as f32, col.y as f32, col.z as f32);
        let matrix = rp::Matrix::from_cols(m(about.x_axis), m(about.y_axis), m(about.z_axis));
        rp::MassProperties::with_inertia_matrix(v(c), self.mass as f32, matrix)
    }
}

/// The momentum of a chain's motion relative to its connector, in the connector's frame: linear,
/// and angular about the connector's origin. Each link's velocity is what its joints' rates
/// (`motions`' velocities) give it with the connector held still.
pub fn relative_momentum(links: &[Link], motions: &[JointMotion]) -> (DVec3, DVec3) {
    // per link: joint position, orientation, origin velocity, angular velocity (connector frame)
    let mut frames: Vec<(DVec3, DQuat, DVec3, DVec3)> = Vec::with_capacity(links.len());
    let (mut linear, mut angular) = (DVec3::ZERO, DVec3::ZERO);
    for (l, m) in links.iter().zip(motions) {
        let (p, q, v, w) = l.parent.map_or(
            (DVec3::ZERO, DQuat::IDENTITY, DVec3::ZERO, DVec3::ZERO),
            |i| frames[i],
        );
        let arm = q * l.offset;
        let (at, turn) = (p + arm, q * m.rotation);
        let (vel, spin) = (v + w.cross(arm), w + turn * m.velocity);
        frames.push((at, turn, vel, spin));
        let reach = turn * l.com;
        let (c, dc) = (at + reach, vel + spin.cross(reach));
        let r = glam::DMat3::from_quat(turn);
        linear += l.mass * dc;
        angular += l.mass * c.cross(dc) + r * l.inertia * r.transpose() * spin;
    }
    (linear, angular)
}

/// A connector carrying kinematic chains from step to step (see the module documentation): what
/// its chains were at the step before.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Carrier {
    before: Option<Carried>,
}

/// The chains carried at one step: their composite (connector frame) and the momentum of their
/// relative motion (world frame; angular about the world's origin).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Carried {
    composite: Composite,
    linear: DVec3,
    angular: DVec3,
}

impl Carrier {
    /// Loads `body` (the connector, whose own mass properties are `own`) for the coming step of
    /// `h` seconds with its chains as they are now: their `composite` and the momentum of their
    /// relative motion (`moving`: linear, and angular about the connector's origin; both in the
    /// connector's frame). Sets the body's additional mass properties and adds the force and
    /// torque that keep the momentum of the whole; returns them (world frame; the torque about
    /// the new centre of mass). The first step after a carrier starts adds no force: the body
    /// moved with its chains before.
    pub fn load(
        &mut self,
        body: &mut rp::RigidBody,
        own: &Composite,
        composite: Composite,
        moving: (DVec3, DVec3),
        h: f64,
    ) -> (DVec3, DVec3) {
        let (at, turn) = (dv(body.translation()), drot(body.rotation()));
        let linear = turn * moving.0;
        let angular = turn * moving.1 + at.cross(linear);
        // rapier's velocities: of its centre of mass (with what was carried before), turning
        let (velocity, spin) = (dv(body.linvel()), dv(body.angvel()));
        let whole = own.plus(&composite);
        let (force, torque) = match self.before {
            Some(b) => {
                let jump = whole.angular_momentum(at, turn, velocity, spin)
                    - (own.plus(&b.composite)).angular_momentum(at, turn, velocity, spin);
                let impulse = b.linear - linear;
                let about_origin = b.angular - angular - jump;
                let centre = at + turn * whole.centre();
                (impulse / h, (about_origin - centre.cross(impulse)) / h)
            }
            None => (DVec3::ZERO, DVec3::ZERO),
        };
        body.set_additional_mass_properties(composite.rapier(), true);
        body.add_force(v(force), true);
        body.add_torque(v(torque), true);
        self.before = Some(Carried {
            composite,
            linear,
            angular,
        });
        (force, torque)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::character::dynamics::rnea::{inverse_dynamics, BaseMotion};
    use glam::DMat3;

    /// An arm-like chain of three links.
    fn chain() -> [Link; 3] {
        let link = |parent, offset: DVec3, mass, com: DVec3, d: DVec3| Link {
            parent,
            offset,
            mass,
            com,
            inertia: DMat3::from_diagonal(d),
        };
        [
            link(
                None,
                DVec3::new(0.1, 0.3, 0.0),
                2.5,
                DVec3::new(0.0, -0.14, 0.01),
                DVec3::new(0.02, 0.003, 0.02),
            ),
            link(
                Some(0),
                DVec3::new(0.0, -0.29, 0.0),
                1.6,
                DVec3::new(0.0, -0.12, 0.0),
                DVec3::new(0.01, 0.002, 0.01),
            ),
            link(
                Some(1),
                DVec3::new(0.0, -0.25, 0.0),
                0.7,
                DVec3::new(0.01, -0.09, 0.0),
                DVec3::new(0.002, 0.001, 0.002),
            ),
        ]
    }

    /// Each joint turning about its own fixed axis by a sine: rotation, rate and acceleration
    /// at time `t`.
    fn motions(t: f64) -> [JointMotion; 3] {
        let axes = [
            DVec3::new(1.0, 0.2, -0.4).normalize(),
            DVec3::X,
            DVec3::new(0.0, 0.6, 0.8),
        ];
        let waves = [(0.9, 5.0, 0.3), (1.2, 7.0, -1.0), (0.5, 11.0, 2.0)];
        std::array::from_fn(|i| {
            let (a, w, phase) = waves[i];
            let th = a * (w * t + phase).sin();
            let dth = a * w * (w * t + phase).cos();
            JointMotion {
                rotation: DQuat::from_axis_angle(axes[i], th),
                velocity: axes[i] * dth,
                acceleration: axes[i] * (-w * w * th),
            }
        })
    }

    /// Held still on a base that turns and accelerates (gravity included), the chain needs what
    /// its composite, as one rigid body, needs by Newton–Euler.
    #[test]
    fn the_composite_is_the_chain_held_rigid() {
        let links = chain();
        let still = motions(0.37).map(|m| JointMotion {
            velocity: DVec3::ZERO,
            acceleration: DVec3::ZERO,
            ..m
        });
        let base = BaseMotion {
            velocity: DVec3::new(0.4, -0.3, 0.8),
            acceleration: DVec3::new(-1.5, 2.0, 0.7),
            linear: DVec3::new(0.5, 9.81, -1.2),
        };
        let d = inverse_dynamics(&links, &still, base);
        let mut c = Composite::default();
        c.add(&links, &still);
        let (w, dw, a) = (base.velocity, base.acceleration, base.linear);
        let force = c.mass * (a + dw.cross(c.centre()) + w.cross(w.cross(c.centre())));
        let moment = c.inertia * dw + w.cross(c.inertia * w) + c.moment.cross(a);
        let scale = d.base_force.length() + d.base_moment.length();
        assert!(
            (force - d.base_force).length() < 1e-12 * scale,
            "{force} vs {}",
            d.base_force
        );
        assert!(
            (moment - d.base_moment).length() < 1e-12 * scale,
            "{moment} vs {}",
            d.base_moment
        );
    }

    /// On a base held still (no gravity), what the chain needs from it is the rate of change of
    /// its momentum: the inverse dynamics' base wrench equals the central difference of the
    /// relative momentum.
    #[test]
    fn the_relative_momentum_changes_as_the_inverse_dynamics_says() {
        let links = chain();
        let dt = 1e-5;
        let mut worst: f64 = 0.0;
        for k in 0..20 {
            let t = 0.05 * k as f64;
            let d = inverse_dynamics(&links, &motions(t), BaseMotion::default());
            let (p0, h0) = relative_momentum(&links, &motions(t - dt));
            let (p1, h1) = relative_momentum(&links, &motions(t + dt));
            let (dp, dh) = ((p1 - p0) / (2.0 * dt), (h1 - h0) / (2.0 * dt));
            let scale = d.base_force.length() + d.base_moment.length();
            worst =
                worst.max(((dp - d.base_force).length() + (dh - d.base_moment).length()) / scale);
        }
        assert!(worst < 1e-6, "relative difference {worst}");
        // and the linear momentum is the rate of the composite's first moment
        let moment = |t: f64| {
            let mut c = Composite::default();
            c.add(&links, &motions(t));
            c.moment
        };
        let (p, _) = relative_momentum(&links, &motions(0.4));
        let rate = (moment(0.4 + dt) - moment(0.4 - dt)) / (2.0 * dt);
        assert!((p - rate).length() < 1e-6 * p.length(), "{p} vs {rate}");
    }

    /// A box spinning about its centre has I ω; one moving without turning, m c × v.
    #[test]
    fn a_composite_s_angular_momentum_about_the_world_origin() {
        let body = crate::character::dynamics::mass::cuboid(
            DVec3::new(0.3, 0.2, 0.1),
            1000.0,
            DVec3::new(0.0, 0.5, 0.0),
        );
        let c = Composite::of(&body);
        let turn = DQuat::from_rotation_z(0.7);
        let at = DVec3::new(1.0, 2.0, 3.0);
        let spin = DVec3::new(0.0, 0.0, 2.0);
        let got = c.angular_momentum(at, turn, DVec3::ZERO, spin);
        assert!((got - body.inertia * spin).length() < 1e-12, "{got}");
        let velocity = DVec3::new(0.5, 0.0, -1.0);
        let centre = at + turn * body.com;
        let got = c.angular_momentum(at, turn, velocity, DVec3::ZERO);
        assert!(
            (got - body.mass * centre.cross(velocity)).length() < 1e-12,
            "{got}"
        );
    }
}
