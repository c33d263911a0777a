//! Recursive Newton–Euler inverse dynamics of a tree of rigid links joined by 3-DoF ball joints
//! (motion subspace S = [I₃; 0]), on a base (the connector) that moves: given each joint's
//! rotation, relative angular velocity and acceleration, the torque each joint must make and the
//! wrench the chain puts on its base. An outward pass carries velocities and accelerations from
//! the base to the leaves, each link in its own frame; an inward pass sums forces and moments
//! back. Gravity enters as an upward acceleration of the base (a₀ = a_connector − g), which is
//! the same as applying m·g at every centre of mass.

use glam::{DMat3, DQuat, DVec3};

/// A link of the chain, in its own frame (whose origin is the joint that attaches it).
#[derive(Debug, Clone, PartialEq)]
pub struct Link {
    /// The link it hangs from (`None`: the base).
    pub parent: Option<usize>,
    /// Where its joint is, in the parent's frame (m).
    pub offset: DVec3,
    /// Mass (kg).
    pub mass: f64,
    /// Centre of mass, in its frame (m).
    pub com: DVec3,
    /// Inertia about the centre of mass, in its frame (kg m²).
    pub inertia: DMat3,
}

/// A joint's motion: its rotation (child frame to parent frame), and its angular velocity and
/// acceleration relative to the parent, in the child's frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointMotion {
    /// Rotation from the link's frame to its parent's.
    pub rotation: DQuat,
    /// Angular velocity relative to the parent (rad/s, link frame).
    pub velocity: DVec3,
    /// Its time derivative (rad/s², link frame).
    pub acceleration: DVec3,
}

/// The base's motion, in its own frame: angular velocity and acceleration, and the linear
/// acceleration of its origin (add −g here for gravity: see [`with_gravity`]).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BaseMotion {
    /// Angular velocity (rad/s).
    pub velocity: DVec3,
    /// Angular acceleration (rad/s²).
    pub acceleration: DVec3,
    /// Linear acceleration of the origin (m/s²).
    pub linear: DVec3,
}

/// `base` with gravity as an upward acceleration of the base: `linear − g` (g in the base's
/// frame, whose orientation in the world is `orientation`).
pub fn with_gravity(base: BaseMotion, orientation: DQuat) -> BaseMotion {
    BaseMotion {
        linear: base.linear - orientation.inverse() * super::GRAVITY,
        ..base
    }
}

/// What the chain needs: each joint's torque (link frame) and the force and moment the base
/// exerts on the chain at its origin (base frame); the chain pushes back with the opposite.
#[derive(Debug, Clone, PartialEq)]
pub struct Dynamics {
    /// Joint torques (N m), one per link, in the link's frame.
    pub torques: Vec<DVec3>,
    /// Force on the chain at the base (N, base frame).
    pub base_force: DVec3,
    /// Moment on the chain about the base's origin (N m, base frame).
    pub base_moment: DVec3,
}

/// The inverse dynamics of `links` (parents before children) moving with `joints` on `base`.
pub fn inverse_dynamics(links: &[Link], joints: &[JointMotion], base: BaseMotion) -> Dynamics {
    let n = links.len();
    let (mut w, mut dw, mut a) = (
        vec![DVec3::ZERO; n],
        vec![DVec3::ZERO; n],
        vec![DVec3::ZERO; n],
    );
    let mut rot = vec![DMat3::IDENTITY; n];
    let (mut f, mut m) = (vec![DVec3::ZERO; n], vec![DVec3::ZERO; n]);
    // outward: velocities and accelerations, each in its link's frame
    for (i, l) in links.iter().enumerate() {
        let (wp, dwp, ap) = match l.parent {
            Some(p) => (w[p], dw[p], a[p]),
            None => (base.velocity, base.acceleration, base.linear),
        };
        let j = joints[i];
        rot[i] = DMat3::from_quat(j.rotation);
        let back = rot[i].transpose();
        let wp_here = back * wp;
        w[i] = wp_here + j.velocity;
        dw[i] = back * dwp + wp_here.cross(j.velocity) + j.acceleration;
        a[i] = back * (ap + dwp.cross(l.offset) + wp.cross(wp.cross(l.offset)));
        let ac = a[i] + dw[i].cross(l.com) + w[i].cross(w[i].cross(l.com));
        f[i] = l.mass * ac;
        m[i] = l.inertia * dw[i] + w[i].cross(l.inertia * w[i]) + l.com.cross(f[i]);
    }
    // inward: each link passes its force and moment to its parent
    let (mut base_force, mut base_moment) = (DVec3::ZERO, DVec3::ZERO);
    for i in (0..n).rev() {
        let (fi, mi) = (rot[i] * f[i], rot[i] * m[i]);
        let moment = mi + links[i].offset.cross(fi);
        match links[i].parent {
            Some(p) => {
                f[p] += fi;
                m[p] += moment;
            }
            None => {
                base_force += fi;
                base_moment += moment;
            }
        }
    }
    Dynamics {
        torques: m,
        base_force,
        base_moment,
    }
}

/// The wrench to apply to the physical body at the connector: −k times what the chain needs
/// (k = 1 exact, between 0 and 1 damped, above 1 exaggerated).
pub fn reaction(d: &Dynamics, k: f64) -> (DVec3, DVec3) {
    (-k * d.base_force, -k * d.base_moment)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A rod of mass m and length l hanging down from its joint, its centre of mass at l/2.
    fn rod(parent: Option<usize>, offset: DVec3, mass: f64, l: f64) -> Link {
        let i = mass * l * l / 12.0;
        Link {
            parent,
            offset,
            mass,
            com: DVec3::new(0.0, -l / 2.0, 0.0),
            inertia: DMat3::from_diagonal(DVec3::new(i, 1e-4, i)),
        }
    }

    #[test]
    fn a_pendulum_needs_its_inertia_times_acceleration_plus_gravity_torque() {
        // θ(t) = A sin(Ωt) about z, hanging down at θ = 0
        let (m, l, amp, om) = (2.0, 0.8, 0.7, 3.0);
        let link = rod(None, DVec3::ZERO, m, l);
        let pivot = m * l * l / 12.0 + m * (l / 2.0) * (l / 2.0);
        for k in 0..50 {
            let t = k as f64 * 0.037;
            let th = amp * (om * t).sin();
            let (dth, ddth) = (amp * om * (om * t).cos(), -amp * om * om * (om * t).sin());
            let joint = JointMotion {
                rotation: DQuat::from_rotation_z(th),
                velocity: DVec3::Z * dth,
                acceleration: DVec3::Z * ddth,
            };
            let base = with_gravity(BaseMotion::default(), DQuat::IDENTITY);
            let d = inverse_dynamics(std::slice::from_ref(&link), &[joint], base);
            let want = pivot * ddth + m * 9.81 * (l / 2.0) * th.sin();
            assert!(
                (d.torques[0].z - want).abs() <= 1e-9 * want.abs().max(1.0),
                "{} vs {want}",
                d.torques[0].z
            );
        }
    }

    #[test]
    fn the_reaction_is_minus_k_times_the_base_wrench() {
        let link = rod(None, DVec3::ZERO, 1.0, 0.5);
        let joint = JointMotion {
            rotation: DQuat::from_rotation_x(0.3),
            velocity: DVec3::X,
            acceleration: DVec3::Y,
        };
        let d = inverse_dynamics(
            &[link],
            &[joint],
            with_gravity(BaseMotion::default(), DQuat::IDENTITY),
        );
        let (f1, m1) = reaction(&d, 1.0);
        let (f06, m06) = reaction(&d, 0.6);
        assert!((f1 + d.base_force).length() < 1e-12 && (m1 + d.base_moment).length() < 1e-12);
        assert!((f06 - 0.6 * f1).length() < 1e-12 && (m06 - 0.6 * m1).length() < 1e-12);
        // hanging still, the base holds the rod's weight
        let still = JointMotion {
            rotation: DQuat::IDENTITY,
            velocity: DVec3::ZERO,
            acceleration: DVec3::ZERO,
        };
        let d = inverse_dynamics(
            &[rod(None, DVec3::ZERO, 1.0, 0.5)],
            &[still],
            with_gravity(BaseMotion::default(), DQuat::IDENTITY),
        );
        assert!((d.base_force - DVec3::new(0.0, 9.81, 0.0)).length() < 1e-12);
    }
}
