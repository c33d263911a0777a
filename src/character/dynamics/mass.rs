//! Mass properties of body segments from their shape: a box of uniform density (the segments of
//! the physical body are boxes, like the mannequin's), and the 6×6 spatial inertia of a body at
//! its own origin built from its mass, centre of mass and inertia about the centre (the
//! parallel-axis theorem in spatial form), which the inverse dynamics' wrenches are expressed with.

use glam::{DMat3, DVec3};

/// Mass, centre of mass and inertia about the centre of mass.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MassProperties {
    /// Mass (kg).
    pub mass: f64,
    /// Centre of mass (m, body frame).
    pub com: DVec3,
    /// Inertia about the centre of mass (kg m², body frame).
    pub inertia: DMat3,
}

/// A box of side lengths `size` (m) and density `density` (kg/m³) centred at `centre`:
/// m = ρabc, I_xx = m(b² + c²)/12 and so on.
pub fn cuboid(size: DVec3, density: f64, centre: DVec3) -> MassProperties {
    let mass = density * size.x * size.y * size.z;
    let sq = size * size;
    MassProperties {
        mass,
        com: centre,
        inertia: DMat3::from_diagonal(
            DVec3::new(sq.y + sq.z, sq.x + sq.z, sq.x + sq.y) * (mass / 12.0),
        ),
    }
}

/// The skew matrix of `v` (`skew(v) * w = v × w`).
fn skew(v: DVec3) -> DMat3 {
    DMat3::from_cols(
        DVec3::new(0.0, v.z, -v.y),
        DVec3::new(-v.z, 0.0, v.x),
        DVec3::new(v.y, -v.x, 0.0),
    )
}

/// The spatial inertia at the body's origin, as a 6×6 row-major matrix acting on (ω, v):
/// [[I_c + m c̃ c̃ᵀ, m c̃], [m c̃ᵀ, m 1]].
pub fn spatial(p: &MassProperties) -> [[f64; 6]; 6] {
    let c = skew(p.com);
    let top_left = p.inertia + c * c.transpose() * p.mass;
    let top_right = c * p.mass;
    let mut out = [[0.0; 6]; 6];
    for r in 0..3 {
        for k in 0..3 {
            out[r][k] = top_left.col(k)[r];
            out[r][k + 3] = top_right.col(k)[r];
            out[r + 3][k] = top_right.col(r)[k];
            out[r + 3][k + 3] = if r == k { p.mass } else { 0.0 };
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_box_has_the_closed_form_mass_and_inertia() {
        let (a, b, c, rho) = (0.3, 0.12, 0.5, 1070.0);
        let p = cuboid(DVec3::new(a, b, c), rho, DVec3::ZERO);
        let m = rho * a * b * c;
        let close = |x: f64, y: f64| (x - y).abs() <= 1e-9 * y.abs();
        assert!(close(p.mass, m));
        assert!(close(p.inertia.x_axis.x, m * (b * b + c * c) / 12.0));
        assert!(close(p.inertia.y_axis.y, m * (a * a + c * c) / 12.0));
        assert!(close(p.inertia.z_axis.z, m * (a * a + b * b) / 12.0));
    }

    #[test]
    fn the_spatial_inertia_is_symmetric_positive_definite_with_the_parallel_axis_result() {
        let p = cuboid(
            DVec3::new(0.1, 0.4, 0.12),
            1000.0,
            DVec3::new(0.02, -0.2, 0.01),
        );
        let s = spatial(&p);
        let entries = (0..6).flat_map(|r| (0..6).map(move |k| (r, k)));
        assert!(
            entries
                .clone()
                .all(|(r, k)| (s[r][k] - s[k][r]).abs() < 1e-12),
            "symmetric"
        );
        // positive definite: Cholesky succeeds
        let mut l = [[0.0f64; 6]; 6];
        for i in 0..6 {
            for j in 0..=i {
                let sum: f64 = (0..j).map(|k| l[i][k] * l[j][k]).sum();
                if i == j {
                    let d = s[i][i] - sum;
                    assert!(d > 0.0, "positive definite");
                    l[i][j] = d.sqrt();
                } else {
                    l[i][j] = (s[i][j] - sum) / l[j][j];
                }
            }
        }
        // the rotational block at the origin is the parallel-axis inertia: I_c + m(|c|²1 − c cᵀ)
        let c = p.com;
        let want = p.inertia
            + (DMat3::IDENTITY * c.length_squared() - DMat3::from_cols(c * c.x, c * c.y, c * c.z))
                * p.mass;
        let block = entries.filter(|&(r, k)| r < 3 && k < 3);
        assert!(block
            .clone()
            .all(|(r, k)| (s[r][k] - want.col(k)[r]).abs() < 1e-12));
    }
}
