//! How a kinematic chain's inverse dynamics reaches the simulated body it hangs from, split so
//! that no part of it lags a step: the chain as a rigid body in its current configuration
//! ([`Composite`], added to the connector's mass properties: it then moves with the connector
//! and carries its weight within the step) and the wrench of its motion relative to the
//! connector ([`relative_wrench`]). The two sum to the chain's inverse dynamics on the
//! connector's motion (docs/physics.md, "Coupling").

use glam::{DQuat, DVec3};
use rapier3d::prelude as rp;

use super::rnea::{inverse_dynamics, BaseMotion, JointMotion, Link};

fn v(x: DVec3) -> rp::Vector {
    rp::Vector::new(x.x as f32, x.y as f32, x.z as f32)
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
            let shift = glam::DMat3::from_diagonal(DVec3::splat(c.length_squared()))
                - glam::DMat3::from_cols(c * c.x, c * c.y, c * c.z);
            self.mass += l.mass;
            self.moment += l.mass * c;
            self.inertia += r * l.inertia * r.transpose() + shift * l.mass;
        }
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
        let c = self.moment / self.mass;
        let shift = glam::DMat3::from_diagonal(DVec3::splat(c.length_squared()))
            - glam::DMat3::from_cols(c * c.x, c * c.y, c * c.z);
        let about = self.inertia - shift * self.mass;
        let m = |col: DVec3| rp::Vector::new(col.x as f32, col.y as f32, col.z as f32);
        let matrix = rp::Matrix::from_cols(m(about.x_axis), m(about.y_axis), m(about.z_axis));
        rp::MassProperties::with_inertia_matrix(v(c), self.mass as f32, matrix)
    }
}

/// What a chain's motion relative to its connector adds to the wrench on it: the inverse
/// dynamics with the connector turning at `omega` (connector frame) and no acceleration or
/// gravity, less the same with every joint still (the rigid chain's own share, which rapier
/// applies to the added mass).
pub fn relative_wrench(links: &[Link], motions: &[JointMotion], omega: DVec3) -> (DVec3, DVec3) {
    let base = BaseMotion {
        velocity: omega,
        ..BaseMotion::default()
    };
    let moving = inverse_dynamics(links, motions, base);
    let still: Vec<JointMotion> = (motions.iter())
        .map(|m| JointMotion {
            velocity: DVec3::ZERO,
            acceleration: DVec3::ZERO,
            ..*m
        })
        .collect();
    let rigid = inverse_dynamics(links, &still, base);
    (
        moving.base_force - rigid.base_force,
        moving.base_moment - rigid.base_moment,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DMat3;

    /// The split is exact: for a moving three-link chain on a base that turns and accelerates,
    /// the chain's full inverse dynamics equals the rigid composite's Newton–Euler wrench for the
    /// base's motion plus the relative wrench.
    #[test]
    fn the_rigid_composite_and_the_relative_wrench_add_up_to_the_inverse_dynamics() {
        let link = |parent, offset: DVec3, mass, com: DVec3, d: DVec3| Link {
            parent,
            offset,
            mass,
            com,
            inertia: DMat3::from_diagonal(d),
        };
        let links = [
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
        ];
        let motions = [
            JointMotion {
                rotation: DQuat::from_euler(glam::EulerRot::ZXY, 0.3, -0.7, 0.2),
                velocity: DVec3::new(1.0, -0.5, 2.0),
                acceleration: DVec3::new(-3.0, 4.0, 1.0),
            },
            JointMotion {
                rotation: DQuat::from_rotation_x(-1.1),
                velocity: DVec3::new(-2.0, 0.0, 0.3),
                acceleration: DVec3::new(5.0, 0.0, -2.0),
            },
            JointMotion {
                rotation: DQuat::from_rotation_z(0.4),
                velocity: DVec3::new(0.0, 1.5, 0.0),
                acceleration: DVec3::new(0.5, -1.0, 0.0),
            },
        ];
        let base = BaseMotion {
            velocity: DVec3::new(0.4, -0.3, 0.8),
            acceleration: DVec3::new(-1.5, 2.0, 0.7),
            linear: DVec3::new(0.5, 9.81, -1.2),
        };
        let full = inverse_dynamics(&links, &motions, base);
        let mut c = Composite::default();
        c.add(&links, &motions);
        let (w, dw, a) = (base.velocity, base.acceleration, base.linear);
        let com = c.moment / c.mass;
        let force = c.mass * (a + dw.cross(com) + w.cross(w.cross(com)));
        let moment = c.inertia * dw + w.cross(c.inertia * w) + c.moment.cross(a);
        let (rf, rm) = relative_wrench(&links, &motions, w);
        let scale = full.base_force.length() + full.base_moment.length();
        assert!(
            (force + rf - full.base_force).length() < 1e-12 * scale,
            "{} vs {}",
            force + rf,
            full.base_force
        );
        assert!(
            (moment + rm - full.base_moment).length() < 1e-12 * scale,
            "{} vs {}",
            moment + rm,
            full.base_moment
        );
    }
}
