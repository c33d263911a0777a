//! Analytic two-link inverse kinematics: where to put the middle joint (elbow, knee) so that
//! the end of the second link (wrist, ankle) reaches a target, bending toward a pole direction.

use glam::{Quat, Vec3};

use super::pose::Pose;

use super::skeleton::Skeleton;

/// Where elbows bend: down and back.
pub const ARM_POLE: Vec3 = Vec3::new(0.0, -1.0, -0.4);
/// Where knees bend: forward.
pub const LEG_POLE: Vec3 = Vec3::new(0.0, 0.0, 1.0);
/// The elbow's hinge, in its local frame: a positive turn about it bends the forearm forward.
pub const ARM_HINGE: Vec3 = Vec3::NEG_X;
/// The knee's hinge, in its local frame: a positive turn about it bends the shin backward.
pub const LEG_HINGE: Vec3 = Vec3::X;

/// The rotation taking direction `from` to direction `to` (shortest arc).
pub fn arc(from: Vec3, to: Vec3) -> Quat {
    Quat::from_rotation_arc(from.normalize_or(Vec3::X), to.normalize_or(Vec3::X))
}

/// The world frame of a limb's root joint: its position, its orientation and its parent's
/// orientation ([`LimbRoot::chain`]).
#[derive(Debug, Clone, Copy)]
pub struct LimbRoot {
    /// Position of the root joint.
    pub position: Vec3,
    /// Orientation of the root joint.
    pub orientation: Quat,
    /// Orientation of its parent.
    pub parent: Quat,
}

impl LimbRoot {
    /// The frame of joint `root` by forward kinematics along its ancestors only.
    pub fn chain(skeleton: &Skeleton, pose: &Pose, root: usize) -> Option<LimbRoot> {
        skeleton.joints()[root].parent?;
        let (position, orientation) = pose.joint_world(skeleton, root);
        Some(LimbRoot {
            position,
            orientation,
            parent: orientation * pose.rotations[root].inverse(),
        })
    }
}

/// The local rotations of a limb's `root` and `mid` joints (shoulder and elbow, hip and knee) that
/// put its `end` joint (wrist, ankle) at `goal` (the space of `frame`), the middle joint bending
/// toward `pole`; `frame` is the root joint's world frame in `pose`. The middle joint is a hinge:
/// it turns only about `hinge` (its local axis, [`ARM_HINGE`] or [`LEG_HINGE`]), as far as the
/// distance to the goal needs; the root turns the limb so that its bend lies in the plane toward
/// the pole (which also sets the upper link's twist).
pub fn place_limb(
    skeleton: &Skeleton,
    frame: LimbRoot,
    [_root, mid, end]: [usize; 3],
    goal: Vec3,
    pole: Vec3,
    hinge: Vec3,
) -> Option<(Quat, Quat)> {
    let joints = skeleton.joints();
    let (upper, lower) = (joints[mid].offset, joints[end].offset);
    let s = frame.position;
    let e = two_link(s, upper.length(), lower.length(), goal, pole);
    // the middle joint: bent by the angle between the links' directions
    let bend = (e - s).angle_between(goal - e);
    let local_e = Quat::from_axis_angle(hinge.normalize_or(Vec3::X), bend);
    // the root: the limb as bent, in the root's frame, onto the elbow and the goal
    let reach = upper + local_e * lower;
    let onto = align(reach, upper, goal - s, e - s)?;
    let local_s = frame.parent.inverse() * onto;
    Some((local_s, local_e))
}

/// The rotation taking direction `a1` onto `a2` and the plane of `a1` and `b1` onto that of `a2`
/// and `b2` (`b1` to the side of `b2`).
fn align(a1: Vec3, b1: Vec3, a2: Vec3, b2: Vec3) -> Option<Quat> {
    let frame = |a: Vec3, b: Vec3| {
        let x = a.normalize_or_zero();
        let y = (b - x * b.dot(x)).normalize_or_zero();
        (x != Vec3::ZERO && y != Vec3::ZERO).then(|| glam::Mat3::from_cols(x, y, x.cross(y)))
    };
    let (m1, m2) = (frame(a1, b1)?, frame(a2, b2)?);
    Some(Quat::from_mat3(&(m2 * m1.transpose())).normalize())
}

/// The middle joint's position for links of lengths `upper` and `lower` from `root` to reach
/// `target`, bending toward `pole`. A target out of reach is approached along the same line (the
/// limb stretches out or folds as far as it can).
pub fn two_link(root: Vec3, upper: f32, lower: f32, target: Vec3, pole: Vec3) -> Vec3 {
    let to = target - root;
    let n = to.normalize_or(Vec3::X);
    let min = (upper - lower).abs() + 1e-4;
    let max = upper + lower - 1e-4;
    let d = to.length().clamp(min, max);
    // law of cosines: the angle at the root between the target line and the upper link
    let cos_a = ((upper * upper + d * d - lower * lower) / (2.0 * upper * d)).clamp(-1.0, 1.0);
    let sin_a = (1.0 - cos_a * cos_a).sqrt();
    let m = (pole - n * pole.dot(n)).normalize_or(n.any_orthonormal_vector());
    root + upper * (cos_a * n + sin_a * m)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reachable_targets_are_reached_within_a_millimetre() {
        let (upper, lower) = (0.29f32, 0.25f32);
        let root = Vec3::new(0.2, 1.4, 0.0);
        let mut seed = 7u32;
        let mut next = || {
            seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (seed >> 8) as f32 / (1u32 << 24) as f32
        };
        for _ in 0..1000 {
            let dir = Vec3::new(next() - 0.5, next() - 0.5, next() - 0.5).normalize_or(Vec3::X);
            let dist = 0.06 + next() * (upper + lower - 0.07);
            let target = root + dir * dist;
            let elbow = two_link(root, upper, lower, target, Vec3::new(0.0, -1.0, -0.3));
            assert!(((elbow - root).length() - upper).abs() < 1e-5);
            let wrist = elbow + (target - elbow).normalize() * lower;
            assert!(
                (wrist - target).length() < 1e-3,
                "{}",
                (wrist - target).length()
            );
        }
        // out of reach: straight toward the target
        let far = root + Vec3::new(0.0, 0.0, 2.0);
        let elbow = two_link(root, upper, lower, far, Vec3::NEG_Y);
        assert!((elbow - root).normalize().dot(Vec3::Z) > 0.99);
    }
}
