//! Forearm twist bones. Turning the hand about the forearm (pronation, supination) turns the
//! skin along the whole forearm, most near the wrist; rigs made for games carry that with
//! twist bones under the lower arm (Unreal's `lowerarm_twist_01_l`, Blender's
//! `forearm_twist.L`, a `…Roll` bone). The realizer's skeleton has none: the twist is in its
//! wrist. An avatar node is taken for a forearm twist bone when it follows no joint, its name
//! holds `twist` or `roll` (any case), it hangs from the lower arm (directly or under another
//! twist bone) and nothing below it follows a joint. It turns about the forearm by the wrist's
//! twist times its share: how far along the forearm it sits at rest (0 at the elbow, 1 at the
//! wrist), less its twist parent's share.

use glam::{Mat4, Quat, Vec3};

use super::file::Model;
use super::retarget::Drive;
use crate::body::skeleton::Skeleton;

/// The twist drives of `model`'s forearm twist bones (node, drive).
pub(super) fn drives(
    model: &Model,
    skeleton: &Skeleton,
    source: &[Option<usize>],
    pre: &[Quat],
    rest: &[Vec3],
    world: &[Mat4],
) -> Vec<(usize, Drive)> {
    let node_of = |j: usize| source.iter().position(|&s| s == Some(j));
    let place = |i: usize| world[i].w_axis.truncate();
    let named = |i: usize| {
        let name = model.nodes[i].name.to_lowercase();
        source[i].is_none() && (name.contains("twist") || name.contains("roll"))
    };
    // nodes with a follower at or below them: each follower and its ancestors, up to the
    // first one already marked
    let mut carries = vec![false; model.nodes.len()];
    for i in (0..model.nodes.len()).filter(|&i| source[i].is_some()) {
        carries[i] = true;
        let mut at = model.nodes[i].parent;
        while let Some(k) = at.filter(|&k| !carries[k]) {
            carries[k] = true;
            at = model.nodes[k].parent;
        }
    }
    let mut out = Vec::new();
    for side in ["l_", "r_"] {
        let joint = |name: &str| skeleton.joint(&format!("{side}{name}"));
        let Some((elbow, wrist)) = joint("elbow").zip(joint("wrist")) else {
            continue;
        };
        let Some((lower, hand)) = node_of(elbow).zip(node_of(wrist)) else {
            continue;
        };
        let forearm = (rest[wrist] - rest[elbow]).normalize_or_zero();
        let along = place(hand) - place(lower);
        if forearm == Vec3::ZERO || along.length_squared() < 1e-12 {
            continue;
        }
        let share = |i: usize| {
            ((place(i) - place(lower)).dot(along) / along.length_squared()).clamp(0.0, 1.0)
        };
        // the twist bones under the lower arm, parents first, with the forearm in their
        // parent's frame and their parent's share
        let mut stack = vec![(lower, pre[lower].inverse() * forearm, 0.0)];
        while let Some((parent, axis, given)) = stack.pop() {
            for child in (0..model.nodes.len()).filter(|&c| model.nodes[c].parent == Some(parent)) {
                if !named(child) || carries[child] {
                    continue;
                }
                let s = share(child);
                out.push((
                    child,
                    Drive::Twist {
                        wrist,
                        forearm,
                        axis,
                        share: s - given,
                    },
                ));
                let rest_rotation = model.nodes[child].rotation;
                stack.push((child, rest_rotation.inverse() * axis, s));
            }
        }
    }
    out
}

/// The angle of `q`'s twist about the unit `axis` (rad, in (−π, π]).
pub(super) fn angle(q: Quat, axis: Vec3) -> f32 {
    let along = Vec3::new(q.x, q.y, q.z).dot(axis);
    let a = 2.0 * along.atan2(q.w);
    if a > std::f32::consts::PI {
        a - std::f32::consts::TAU
    } else if a <= -std::f32::consts::PI {
        a + std::f32::consts::TAU
    } else {
        a
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_twist_of_a_rotation_about_an_axis() {
        let axis = Vec3::new(1.0, 0.0, 0.0);
        let twist = Quat::from_axis_angle(axis, 0.7);
        let swing = Quat::from_axis_angle(Vec3::Z, 0.4);
        assert!((angle(twist, axis) - 0.7).abs() < 1e-5);
        assert!((angle(swing * twist, axis) - 0.7).abs() < 0.1);
        assert!((angle(Quat::from_axis_angle(axis, -2.5), axis) + 2.5).abs() < 1e-5);
        assert!(angle(swing, axis).abs() < 1e-5);
        // a quaternion and its negation are one rotation
        assert!((angle(-twist, axis) - 0.7).abs() < 1e-5);
    }
}
