//! Poses: a root translation and a local rotation (unit quaternion) per joint; forward kinematics
//! to world positions and orientations.

use glam::{Quat, Vec3};

use super::skeleton::Skeleton;

/// A pose of a skeleton: local joint rotations (relative to the parent's frame) and the root's
/// translation. The rest pose is all identity rotations.
#[derive(Debug, Clone, PartialEq)]
pub struct Pose {
    /// Translation of the root joint (world, metres).
    pub root: Vec3,
    /// Local rotation per joint, in the skeleton's joint order.
    pub rotations: Vec<Quat>,
}

/// World positions and orientations of every joint.
#[derive(Debug, Clone, PartialEq)]
pub struct WorldPose {
    /// Joint positions (metres).
    pub positions: Vec<Vec3>,
    /// Joint orientations.
    pub orientations: Vec<Quat>,
}

impl Pose {
    /// The rest pose of `skeleton` (root at its rest offset).
    pub fn rest(skeleton: &Skeleton) -> Pose {
        Pose {
            root: skeleton.joints()[0].offset,
            rotations: vec![Quat::IDENTITY; skeleton.len()],
        }
    }

    /// Sets joint `i`'s rotation to its current one followed by `q` (applied in the joint's
    /// frame), renormalised.
    pub fn rotate(&mut self, i: usize, q: Quat) {
        if let Some(r) = self.rotations.get_mut(i) {
            *r = (*r * q).normalize();
        }
    }

    /// Forward kinematics of one joint only (along its ancestors): its world position and
    /// orientation, as [`world`](Self::world) gives them.
    pub fn joint_world(&self, skeleton: &Skeleton, i: usize) -> (Vec3, Quat) {
        let joints = skeleton.joints();
        // the chain from the root down to i (skeletons are shallow)
        let mut chain = [0usize; 64];
        let (mut n, mut j) = (0, Some(i));
        while let Some(k) = j {
            if n == chain.len() {
                let w = self.world(skeleton);
                return (w.positions[i], w.orientations[i]);
            }
            chain[n] = k;
            n += 1;
            j = joints[k].parent;
        }
        let (mut p, mut o) = (self.root, Quat::IDENTITY);
        for (step, &k) in chain[..n].iter().rev().enumerate() {
            let local = self.rotations.get(k).copied().unwrap_or(Quat::IDENTITY);
            if step > 0 {
                p += o * joints[k].offset;
            }
            o *= local;
        }
        (p, o)
    }

    /// Forward kinematics: every joint's world position and orientation.
    pub fn world(&self, skeleton: &Skeleton) -> WorldPose {
        let n = skeleton.len();
        let mut positions = vec![Vec3::ZERO; n];
        let mut orientations = vec![Quat::IDENTITY; n];
        for (i, j) in skeleton.joints().iter().enumerate() {
            let local = self.rotations.get(i).copied().unwrap_or(Quat::IDENTITY);
            match j.parent {
                None => {
                    positions[i] = self.root;
                    orientations[i] = local;
                }
                Some(p) => {
                    positions[i] = positions[p] + orientations[p] * j.offset;
                    orientations[i] = orientations[p] * local;
                }
            }
        }
        WorldPose {
            positions,
            orientations,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f32::consts::FRAC_PI_2;

    #[test]
    fn one_joint_forward_kinematics_equals_the_full_one() {
        let s = Skeleton::adult();
        let mut pose = Pose::rest(&s);
        for (i, r) in pose.rotations.iter_mut().enumerate() {
            *r = Quat::from_euler(glam::EulerRot::ZXY, 0.1 * i as f32, -0.05 * i as f32, 0.3);
        }
        pose.root = glam::Vec3::new(0.3, 0.9, -0.2);
        let w = pose.world(&s);
        for i in 0..s.len() {
            let (p, o) = pose.joint_world(&s, i);
            assert!((p - w.positions[i]).length() < 1e-5, "{i}");
            assert!(
                1.0 - o.dot(w.orientations[i]).abs() < 1e-6,
                "{i}: {o} {}",
                w.orientations[i]
            );
        }
        assert_eq!(s.joint_mirrored("r_elbow", true), s.joint("l_elbow"));
        assert_eq!(s.joint_mirrored("r_elbow", false), s.joint("r_elbow"));
        assert_eq!(s.joint_mirrored("vl5", true), s.joint("vl5"));
        assert_eq!(s.joint_mirrored("l_nothing", true), None);
    }

    #[test]
    fn forward_kinematics_matches_a_hand_computed_arm() {
        let s = Skeleton::adult();
        let mut pose = Pose::rest(&s);
        let w = pose.world(&s);
        let (sh, el, wr) = (
            s.joint("l_shoulder").unwrap(),
            s.joint("l_elbow").unwrap(),
            s.joint("l_wrist").unwrap(),
        );
        // rest: the left arm hangs down (-y)
        assert!((w.positions[el] - w.positions[sh] - Vec3::new(0.0, -0.29, 0.0)).length() < 1e-6);
        // the elbow bent 90° about -x turns the forearm from -y to +z (forward)
        pose.rotate(el, Quat::from_rotation_x(-FRAC_PI_2));
        let w2 = pose.world(&s);
        assert!((w2.positions[wr] - w2.positions[el] - Vec3::new(0.0, 0.0, 0.25)).length() < 1e-6);
        assert_eq!(
            w2.positions[el], w.positions[el],
            "the elbow itself does not move"
        );
        // a nod of the skull base moves the eyes but not the neck
        let (skull, eye) = (
            s.joint("skullbase").unwrap(),
            s.joint("l_eyeball_joint").unwrap(),
        );
        let mut nod = Pose::rest(&s);
        nod.rotate(skull, Quat::from_rotation_x(0.3));
        let wn = nod.world(&s);
        assert_eq!(wn.positions[skull], w.positions[skull]);
        let before = w.positions[eye] - w.positions[skull];
        let after = wn.positions[eye] - wn.positions[skull];
        assert!((before.length() - after.length()).abs() < 1e-6);
        // about the x axis: the x part stays, the (y, z) part turns by 0.3 rad
        assert!((before.x - after.x).abs() < 1e-6);
        let yz = |v: Vec3| Vec3::new(0.0, v.y, v.z);
        assert!((yz(before).angle_between(yz(after)) - 0.3).abs() < 1e-5);
    }
}
