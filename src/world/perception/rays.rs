//! The rays of synthetic vision (after IViHumans, thesis §3.1.7): a square matrix of viewport
//! points, symmetric about the viewport's centre and denser towards it, kept a margin `k` inside
//! the viewport's edges; at each pass every point is moved by the same displacement, and the
//! displacements of successive passes walk out along a spiral (a Vogel spiral: the golden angle
//! between passes, the radius growing with the square root of the pass within a turn-out), so
//! that over a few passes every ray sweeps the gaps around it. The thesis cites the matrix's
//! construction without giving it; here the matrix's coordinates are `s·|s|^(γ−1)` of evenly
//! spaced `s` in (−1, 1), γ = 1.6: their spacing grows from the centre outwards.

use glam::{Vec2, Vec3};

/// How much denser the rays are at the centre: the exponent γ of the matrix's coordinates.
pub const CENTRE_WEIGHT: f32 = 1.6;

/// The margin `k` kept from the viewport's edges (in viewport units, the viewport being
/// [0, 1]²): the largest displacement, so that no ray leaves the field of view.
pub const MARGIN: f32 = 0.02;

/// Passes in one turn-out of the spiral (then it starts again from the centre).
pub const SPIRAL_PASSES: u64 = 16;

/// The golden angle (radians): successive displacements turn by it.
const GOLDEN_ANGLE: f32 = 2.399_963;

/// A viewer's rays: the base matrix and the field of view.
#[derive(Debug, Clone, PartialEq)]
pub struct RaySet {
    /// The base matrix: viewport points in [k, 1 − k]², row by row.
    base: Vec<Vec2>,
    /// tan of half the horizontal and vertical field of view.
    half_tan: Vec2,
}

impl RaySet {
    /// `side × side` rays over a field of view of `horizontal × vertical` degrees (each
    /// clamped to [1, 170]°; `side` to [1, 256]).
    pub fn new(side: usize, horizontal: f32, vertical: f32) -> RaySet {
        let side = side.clamp(1, 256);
        let coordinate = |i: usize| {
            let s = -1.0 + (2 * i + 1) as f32 / side as f32;
            0.5 + (0.5 - MARGIN) * s.signum() * s.abs().powf(CENTRE_WEIGHT)
        };
        let base = (0..side)
            .flat_map(|r| (0..side).map(move |c| Vec2::new(coordinate(c), coordinate(r))))
            .collect();
        let half = |deg: f32| (deg.clamp(1.0, 170.0).to_radians() / 2.0).tan();
        RaySet {
            base,
            half_tan: Vec2::new(half(horizontal), half(vertical)),
        }
    }

    /// How many rays a pass casts.
    pub fn len(&self) -> usize {
        self.base.len()
    }

    /// Whether it casts none (never: a ray set has at least one ray).
    pub fn is_empty(&self) -> bool {
        self.base.is_empty()
    }

    /// The base matrix (viewport points).
    pub fn base(&self) -> &[Vec2] {
        &self.base
    }

    /// The displacement of pass `pass` for a viewer whose spiral is turned by `turn` radians.
    pub fn displacement(pass: u64, turn: f32) -> Vec2 {
        let within = (pass % SPIRAL_PASSES) as f32;
        let radius = MARGIN * ((within + 0.5) / SPIRAL_PASSES as f32).sqrt();
        let angle = turn + GOLDEN_ANGLE * pass as f32;
        Vec2::new(angle.cos(), angle.sin()) * radius
    }

    /// The viewport points of pass `pass`.
    pub fn points(&self, pass: u64, turn: f32) -> impl Iterator<Item = Vec2> + '_ {
        let d = Self::displacement(pass, turn);
        self.base.iter().map(move |p| *p + d)
    }

    /// The direction (unit, in the eye's frame: +z ahead, +y up, +x to the left) through a
    /// viewport point (u to the right, v downwards, as on a screen).
    pub fn direction(&self, p: Vec2) -> Vec3 {
        let x = (0.5 - p.x) * 2.0 * self.half_tan.x;
        let y = (0.5 - p.y) * 2.0 * self.half_tan.y;
        Vec3::new(x, y, 1.0).normalize()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_matrix_is_symmetric_and_denser_at_the_centre() {
        let r = RaySet::new(20, 120.0, 90.0);
        assert_eq!(r.len(), 400);
        // symmetric about (0.5, 0.5): every point has its mirror
        for p in r.base() {
            let m = Vec2::ONE - *p;
            assert!(r.base().iter().any(|q| (*q - m).length() < 1e-5), "{p}");
        }
        // inside the margin
        assert!(r
            .base()
            .iter()
            .all(|p| p.min_element() >= MARGIN && p.max_element() <= 1.0 - MARGIN));
        // the central quarter of the viewport's area holds far more than a quarter of the rays
        let central = (r.base().iter())
            .filter(|p| (p.x - 0.5).abs() < 0.25 && (p.y - 0.5).abs() < 0.25)
            .count();
        assert!(central as f32 > 0.4 * r.len() as f32, "{central} of 400");
        // spacing grows outwards along a row
        let row: Vec<f32> = r.base()[..20].iter().map(|p| p.x).collect();
        let gaps: Vec<f32> = row.windows(2).map(|w| w[1] - w[0]).collect();
        assert!(gaps[9] < gaps[5] && gaps[5] < gaps[0], "{gaps:?}");
    }

    #[test]
    fn each_pass_moves_every_ray_and_successive_passes_spiral_within_the_margin() {
        let r = RaySet::new(10, 100.0, 60.0);
        let mut last = Vec2::ZERO;
        for pass in 0..3 * SPIRAL_PASSES {
            let d = RaySet::displacement(pass, 0.3);
            assert!(d.length() <= MARGIN + 1e-6);
            assert!(
                (d - last).length() > 1e-3,
                "pass {pass} repeats the one before"
            );
            last = d;
            for p in r.points(pass, 0.3) {
                assert!(p.min_element() >= -1e-6 && p.max_element() <= 1.0 + 1e-6);
            }
        }
        // a spiral: within a turn-out the radius grows, the angle turns by the golden angle
        let radii: Vec<f32> = (0..SPIRAL_PASSES)
            .map(|k| RaySet::displacement(k, 0.0).length())
            .collect();
        assert!(radii.windows(2).all(|w| w[1] > w[0]), "{radii:?}");
    }

    #[test]
    fn directions_span_the_field_of_view() {
        let r = RaySet::new(2, 90.0, 90.0);
        let left = r.direction(Vec2::new(0.0, 0.5));
        assert!((left.x.atan2(left.z).to_degrees() - 45.0).abs() < 1e-3);
        let up = r.direction(Vec2::new(0.5, 0.0));
        assert!((up.y.atan2(up.z).to_degrees() - 45.0).abs() < 1e-3);
        assert_eq!(r.direction(Vec2::splat(0.5)), Vec3::Z);
    }
}

#[cfg(test)]
mod coverage {
    use super::*;

    /// The largest angle (degrees) from any direction through the viewport's `[lo, 1 − lo]²`
    /// to its nearest ray, over `passes` looks.
    pub(super) fn worst_gap(r: &RaySet, lo: f32, passes: u64) -> f32 {
        let mut worst = 0.0f32;
        for pass in 0..passes {
            let rays: Vec<Vec3> = r.points(pass, 0.7).map(|p| r.direction(p)).collect();
            for i in 0..=40 {
                for j in 0..=40 {
                    let at = |k: i32| lo + (1.0 - 2.0 * lo) * k as f32 / 40.0;
                    let d = r.direction(Vec2::new(at(i), at(j)));
                    let near = rays.iter().map(|q| q.dot(d)).fold(-1.0f32, f32::max);
                    worst = worst.max(near.clamp(-1.0, 1.0).acos().to_degrees());
                }
            }
        }
        worst
    }

    #[test]
    fn with_the_default_rays_a_thing_wider_than_7_2_degrees_is_met_at_every_look() {
        let r = RaySet::new(24, 120.0, 90.0);
        let gap = worst_gap(&r, 0.05, 2 * SPIRAL_PASSES);
        assert!(gap <= 3.6, "a direction {gap}° from the nearest ray");
    }
}
