//! The zero-moment point (thesis §2.2, after Vukobratović): the point on the ground about which
//! gravity and the body's inertial forces have no horizontal moment. Of a body standing still
//! it is its centre of mass' ground projection; when the body accelerates it moves away from it
//! (behind the centre of mass when that accelerates forward). Feet on the ground can only push
//! within the support polygon, so a zero-moment point outside it means the feet would roll
//! over an edge: a measure of how hard a motion is to balance.

use glam::{DMat3, DVec3};

/// One rigid part's mass and motion, in the world.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Segment {
    /// Mass (kg).
    pub mass: f64,
    /// Centre of mass (m).
    pub com: DVec3,
    /// The centre of mass' acceleration (m/s²).
    pub acceleration: DVec3,
    /// Inertia about the centre of mass (kg m², world axes).
    pub inertia: DMat3,
    /// Angular velocity (rad/s).
    pub spin: DVec3,
    /// Angular acceleration (rad/s²).
    pub spin_rate: DVec3,
}

/// The zero-moment point of `segments` on the level ground at height `ground` (y up) under
/// `gravity`; `None` when nothing presses on the ground (the parts fall freely, or are thrown
/// up): the vertical force is then under 1 % of the weight.
pub fn zero_moment_point(segments: &[Segment], gravity: DVec3, ground: f64) -> Option<DVec3> {
    let (mut force, mut moment, mut weight) = (DVec3::ZERO, DVec3::ZERO, 0.0);
    for s in segments {
        let f = s.mass * (gravity - s.acceleration);
        let turning = s.inertia * s.spin_rate + s.spin.cross(s.inertia * s.spin);
        force += f;
        moment += s.com.cross(f) - turning;
        weight += s.mass * gravity.length();
    }
    // the ground's reaction balances `force`; its moment about p = (x, ground, z) has no
    // horizontal part where moment − p × force has none
    if force.y.abs() < 0.01 * weight || force.y > 0.0 {
        return None;
    }
    let x = (moment.z + ground * force.x) / force.y;
    let z = (ground * force.z - moment.x) / force.y;
    Some(DVec3::new(x, ground, z))
}

#[cfg(test)]
mod tests {
    use super::*;

    const G: DVec3 = DVec3::new(0.0, -9.81, 0.0);

    fn point(mass: f64, com: DVec3, acceleration: DVec3) -> Segment {
        Segment {
            mass,
            com,
            acceleration,
            inertia: DMat3::ZERO,
            spin: DVec3::ZERO,
            spin_rate: DVec3::ZERO,
        }
    }

    /// Standing still, the zero-moment point is the centre of mass' ground projection.
    #[test]
    fn of_a_body_at_rest_it_is_below_the_centre_of_mass() {
        let parts = [
            point(30.0, DVec3::new(0.1, 1.2, -0.05), DVec3::ZERO),
            point(40.0, DVec3::new(-0.05, 0.6, 0.02), DVec3::ZERO),
        ];
        let p = zero_moment_point(&parts, G, 0.0).unwrap();
        let com = (30.0 * parts[0].com + 40.0 * parts[1].com) / 70.0;
        assert!((p - DVec3::new(com.x, 0.0, com.z)).length() < 1e-12, "{p}");
    }

    /// The cart on a table: a mass at height h accelerating by a has its zero-moment point
    /// h a / g behind it, in x and in z; on ground at height y₀ the lever is h − y₀.
    #[test]
    fn an_accelerating_mass_has_it_behind_by_h_a_over_g() {
        let (h, a) = (0.9, DVec3::new(1.5, 0.0, -2.0));
        let p = zero_moment_point(&[point(70.0, DVec3::new(0.2, h, 0.3), a)], G, 0.0).unwrap();
        let want = DVec3::new(0.2 - h * 1.5 / 9.81, 0.0, 0.3 + h * 2.0 / 9.81);
        assert!((p - want).length() < 1e-12, "{p} vs {want}");
        let p = zero_moment_point(&[point(70.0, DVec3::new(0.2, h, 0.3), a)], G, 0.1).unwrap();
        assert!((p.x - (0.2 - (h - 0.1) * 1.5 / 9.81)).abs() < 1e-12, "{p}");
    }

    /// A part turning faster about z moves the point as its moment I ω̇ would: by I ω̇_z / (m g).
    #[test]
    fn a_spinning_up_part_shifts_it_by_its_moment() {
        let mut s = point(10.0, DVec3::new(0.0, 1.0, 0.0), DVec3::ZERO);
        s.inertia = DMat3::from_diagonal(DVec3::new(0.5, 0.5, 0.5));
        s.spin_rate = DVec3::new(0.0, 0.0, 4.0);
        let p = zero_moment_point(&[s], G, 0.0).unwrap();
        assert!((p.x - 0.5 * 4.0 / (10.0 * 9.81)).abs() < 1e-12, "{p}");
    }

    /// Falling freely nothing presses on the ground.
    #[test]
    fn in_free_fall_there_is_none() {
        assert!(zero_moment_point(&[point(70.0, DVec3::Y, G)], G, 0.0).is_none());
    }
}
