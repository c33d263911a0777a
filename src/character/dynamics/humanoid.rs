//! The physical humanoid: the 15 rigid bodies and 14 joints of the thesis' model (§3.3, Fig.
//! 3.5) laid over a skeleton. Each body is a box (its collision shape and its mass geometry) of
//! one body part, with the part's density from the biomechanics literature, and follows one
//! skeleton joint (its *joint*); the skeleton joints between it and the next body move with it
//! rigidly. Masses, centres of mass and inertia follow from the boxes (`dynamics::mass`).

use glam::{DVec3, Vec3};

use super::mass::{cuboid, MassProperties};
use crate::character::body::{Pose, Skeleton};

/// One body part: the skeleton joint it follows, the body it hangs from, and its box.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PartSpec {
    /// The body part's name (as in the thesis' Fig. 3.5).
    pub name: &'static str,
    /// The skeleton joint it follows (its origin is the joint's position).
    pub joint: &'static str,
    /// The part it hangs from (an index into [`PARTS`]; `None` for the sacroiliac, the root).
    pub parent: Option<usize>,
    /// The box's size (x, y, z; metres) in the rest pose.
    pub size: [f64; 3],
    /// The box's centre relative to the joint, in the rest pose (metres).
    pub centre: [f64; 3],
    /// Density (kg/l; ×1000 for kg/m³).
    pub density: f64,
    /// Whether its joint is a hinge about the x axis (knees, elbows) rather than a ball.
    pub hinge: bool,
}

/// The 15 parts of the default adult (densities from the thesis' Fig. 3.5; boxes from the adult
/// skeleton's proportions). Parents come before their children.
pub const PARTS: [PartSpec; 15] = [
    part(
        "sacroiliac",
        "sacroiliac",
        None,
        [0.30, 0.16, 0.20],
        [0.0, 0.0, 0.0],
        1.03,
    ),
    part(
        "upper-body",
        "vl5",
        Some(0),
        [0.30, 0.42, 0.20],
        [0.0, 0.21, 0.0],
        1.03,
    ),
    part(
        "head&neck",
        "vc7",
        Some(1),
        [0.12, 0.28, 0.15],
        [0.0, 0.14, 0.02],
        1.11,
    ),
    part(
        "l_upperarm",
        "l_shoulder",
        Some(1),
        [0.10, 0.29, 0.09],
        [0.0, -0.145, 0.0],
        1.07,
    ),
    part(
        "l_forearm",
        "l_elbow",
        Some(3),
        [0.075, 0.25, 0.075],
        [0.0, -0.125, 0.0],
        1.13,
    )
    .hinge(),
    part(
        "l_hand",
        "l_wrist",
        Some(4),
        [0.035, 0.18, 0.09],
        [0.0, -0.09, 0.0],
        1.16,
    ),
    part(
        "r_upperarm",
        "r_shoulder",
        Some(1),
        [0.10, 0.29, 0.09],
        [0.0, -0.145, 0.0],
        1.07,
    ),
    part(
        "r_forearm",
        "r_elbow",
        Some(6),
        [0.075, 0.25, 0.075],
        [0.0, -0.125, 0.0],
        1.13,
    )
    .hinge(),
    part(
        "r_hand",
        "r_wrist",
        Some(7),
        [0.035, 0.18, 0.09],
        [0.0, -0.09, 0.0],
        1.16,
    ),
    part(
        "l_thigh",
        "l_hip",
        Some(0),
        [0.14, 0.43, 0.14],
        [0.0, -0.215, 0.0],
        1.05,
    ),
    part(
        "l_shank",
        "l_knee",
        Some(9),
        [0.09, 0.42, 0.09],
        [0.0, -0.21, 0.0],
        1.09,
    )
    .hinge(),
    part(
        "l_foot",
        "l_talocrural",
        Some(10),
        [0.10, 0.05, 0.24],
        [0.0, -0.025, 0.06],
        1.10,
    ),
    part(
        "r_thigh",
        "r_hip",
        Some(0),
        [0.14, 0.43, 0.14],
        [0.0, -0.215, 0.0],
        1.05,
    ),
    part(
        "r_shank",
        "r_knee",
        Some(12),
        [0.09, 0.42, 0.09],
        [0.0, -0.21, 0.0],
        1.09,
    )
    .hinge(),
    part(
        "r_foot",
        "r_talocrural",
        Some(13),
        [0.10, 0.05, 0.24],
        [0.0, -0.025, 0.06],
        1.10,
    ),
];

const fn part(
    name: &'static str,
    joint: &'static str,
    parent: Option<usize>,
    size: [f64; 3],
    centre: [f64; 3],
    density: f64,
) -> PartSpec {
    PartSpec {
        name,
        joint,
        parent,
        size,
        centre,
        density,
        hinge: false,
    }
}

impl PartSpec {
    const fn hinge(mut self) -> Self {
        self.hinge = true;
        self
    }

    /// Whether it is a foot (its box's underside is a sole).
    pub fn is_foot(&self) -> bool {
        self.name.ends_with("_foot")
    }

    /// The middle of its box's underside, in its joint's frame.
    pub fn underside(&self) -> DVec3 {
        DVec3::from_array(self.centre) - DVec3::new(0.0, self.size[1] / 2.0, 0.0)
    }

    /// For a foot, the corners of its sole, in its joint's frame.
    pub fn sole(&self) -> Option<[DVec3; 4]> {
        let (mid, h) = (self.underside(), DVec3::from_array(self.size) / 2.0);
        self.is_foot().then(|| {
            [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
                .map(|(x, z)| mid + DVec3::new(x * h.x, 0.0, z * h.z))
        })
    }

    /// Its mass properties, in a frame at its joint aligned with the world in the rest pose.
    pub fn mass(&self) -> MassProperties {
        cuboid(
            DVec3::from_array(self.size),
            self.density * 1000.0,
            DVec3::from_array(self.centre),
        )
    }
}

/// The parts laid over a skeleton: per part, its skeleton joint, and per skeleton joint, the part
/// it moves with (the part of its nearest ancestor that is a part's joint).
#[derive(Debug, Clone, PartialEq)]
pub struct Humanoid {
    /// The parts ([`PARTS`]).
    pub parts: Vec<PartSpec>,
    /// Per part, its skeleton joint.
    pub joints: Vec<usize>,
    /// Per skeleton joint, the part it moves with (`None` above the sacroiliac: the root).
    pub part_of: Vec<Option<usize>>,
    /// Per part, where its joint is in the rest pose (m).
    pub rest: Vec<Vec3>,
}

impl Humanoid {
    /// The default parts over `skeleton`, or why they do not fit it (a joint it lacks).
    pub fn new(skeleton: &Skeleton) -> Result<Humanoid, String> {
        let parts = PARTS.to_vec();
        let joints = (parts.iter())
            .map(|p| {
                skeleton.joint(p.joint).ok_or_else(|| {
                    format!("the skeleton has no joint '{}' for {}", p.joint, p.name)
                })
            })
            .collect::<Result<Vec<_>, _>>()?;
        let mut part_of = vec![None; skeleton.len()];
        for (i, j) in skeleton.joints().iter().enumerate() {
            part_of[i] = match joints.iter().position(|&k| k == i) {
                Some(p) => Some(p),
                None => j.parent.and_then(|p| part_of[p]),
            };
        }
        // the root's other children (the spine hangs from HumanoidRoot) join the sacroiliac's part
        for (i, j) in skeleton.joints().iter().enumerate() {
            if part_of[i].is_none() && j.parent.is_some() {
                part_of[i] = Some(0);
            }
        }
        let world = Pose::rest(skeleton).world(skeleton);
        let rest = joints.iter().map(|&j| world.positions[j]).collect();
        Ok(Humanoid {
            parts,
            joints,
            part_of,
            rest,
        })
    }

    /// The total mass (kg).
    pub fn mass(&self) -> f64 {
        self.parts.iter().map(|p| p.mass().mass).sum()
    }

    /// Each part's world position (of its joint) and orientation in `pose`.
    pub fn frames(&self, skeleton: &Skeleton, pose: &Pose) -> Vec<(Vec3, glam::Quat)> {
        let world = pose.world(skeleton);
        (self.joints.iter())
            .map(|&j| (world.positions[j], world.orientations[j]))
            .collect()
    }

    /// The world centre of mass of the parts in `pose` (m).
    pub fn centre_of_mass(&self, skeleton: &Skeleton, pose: &Pose) -> DVec3 {
        let (mut sum, mut mass) = (DVec3::ZERO, 0.0);
        for (p, (at, q)) in self.parts.iter().zip(self.frames(skeleton, pose)) {
            let m = p.mass();
            let c = at.as_dvec3() + q.as_dquat() * m.com;
            sum += m.mass * c;
            mass += m.mass;
        }
        sum / mass
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fifteen_parts_fourteen_joints_and_the_mass_of_an_adult() {
        let s = Skeleton::adult();
        let h = Humanoid::new(&s).unwrap();
        assert_eq!(h.parts.len(), 15);
        assert_eq!(h.parts.iter().filter(|p| p.parent.is_some()).count(), 14);
        // parents first
        for (i, p) in h.parts.iter().enumerate() {
            assert!(p.parent.is_none_or(|q| q < i), "{}", p.name);
        }
        // the thesis' parts sum to 78.9 kg (its printed total, 94.21, does not add up)
        let m = h.mass();
        assert!((75.0..83.0).contains(&m), "{m} kg");
        // each part near the thesis' mass (Fig. 3.5), within 25 %
        let thesis = [
            10.56, 25.2, 4.8, 2.95, 1.59, 0.7, 2.95, 1.59, 0.7, 8.79, 3.73, 1.41,
        ];
        for (p, t) in h.parts.iter().zip(thesis.iter().chain(&thesis[9..])) {
            let m = p.mass().mass;
            assert!((m - t).abs() < 0.25 * t + 0.5, "{}: {m} kg vs {t}", p.name);
        }
        // every joint of the skeleton moves with some part; the fingers with the hands
        let hand = |side: &str| {
            h.parts
                .iter()
                .position(|p| p.name == format!("{side}_hand"))
        };
        assert_eq!(h.part_of[s.joint("r_index3").unwrap()], hand("r"));
        assert_eq!(h.part_of[s.joint("vt6").unwrap()], Some(1));
        assert_eq!(h.part_of[s.joint("skullbase").unwrap()], Some(2));
        assert_eq!(h.part_of[s.joint("HumanoidRoot").unwrap()], None);
    }

    #[test]
    fn standing_at_rest_the_centre_of_mass_is_over_the_feet_at_hip_height() {
        let s = Skeleton::adult();
        let h = Humanoid::new(&s).unwrap();
        let c = h.centre_of_mass(&s, &Pose::rest(&s));
        assert!(c.x.abs() < 1e-9, "{c}");
        // a person's centre of mass is at about 55 % of their height (1.75 m): near 0.95 m
        assert!((0.85..1.05).contains(&c.y), "{c}");
        // between the heels (z = -0.06) and the toes (z = 0.18)
        assert!((-0.06..0.18).contains(&c.z), "{c}");
    }
}
