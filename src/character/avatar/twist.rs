//! Twist bones of the arms. Turning the hand about the forearm (pronation, supination) turns
//! the skin along the whole forearm, most near the wrist; turning the arm about itself at the
//! shoulder turns the skin of the upper arm, most near the elbow and hardly at the shoulder.
//! Rigs made for games carry that with twist bones (Unreal's `lowerarm_twist_01_l` and
//! `upperarm_twist_01_l`, Blender's `forearm_twist.L`, a `…Roll` bone). The realizer's
//! skeleton has none: the twists are in its wrist and shoulder joints. An avatar node is taken
//! for a twist bone of a limb segment when it follows no joint, its name holds `twist` or
//! `roll` (any case), it hangs from the segment's bone (directly or under another twist bone)
//! and nothing below it follows a joint. It keeps, of the twisting joint's twist about the
//! segment, its share: how far along the segment it sits at rest (0 at the segment's start, 1
//! at its end). The forearm's bone itself keeps none of the wrist's twist; the upper arm's bone
//! keeps all of the shoulder's, so an upper-arm twist bone turns back by what it does not keep.

use glam::{Mat4, Quat, Vec3};

use super::file::Model;
use crate::character::body::skeleton::Skeleton;

/// An arm twist bone: it turns about `axis` (in its parent's frame) by `share` of the realizer
/// joint `joint`'s twist about the realizer's limb segment (`about`, in the joint's parent's
/// frame).
#[derive(Debug, Clone, Copy)]
pub(super) struct TwistBone {
    pub joint: usize,
    pub about: Vec3,
    pub axis: Vec3,
    pub share: f32,
}

/// A limb segment with twist bones: the joints at its start and end, the joint whose twist
/// about the segment the twist bones share, and the share its own bone keeps.
struct Segment {
    start: &'static str,
    end: &'static str,
    twisting: &'static str,
    kept: f32,
}

const SEGMENTS: [Segment; 2] = [
    Segment {
        start: "elbow",
        end: "wrist",
        twisting: "wrist",
        kept: 0.0,
    },
    Segment {
        start: "shoulder",
        end: "elbow",
        twisting: "shoulder",
        kept: 1.0,
    },
];

/// The twist bones of `model`'s arms, each with its node.
pub(super) fn bones(
    model: &Model,
    skeleton: &Skeleton,
    source: &[Option<usize>],
    pre: &[Quat],
    rest: &[Vec3],
    world: &[Mat4],
) -> Vec<(usize, TwistBone)> {
    let node_of = |j: usize| source.iter().position(|&s| s == Some(j));
    let place = |i: usize| world[i].w_axis.truncate();
    let named = |i: usize| {
        let name = model.nodes[i].name.to_lowercase();
        source[i].is_none() && (name.contains("twist") || name.contains("roll"))
    };
    let carries = carrying(model, source);
    let mut out = Vec::new();
    for side in ["l_", "r_"] {
        for segment in &SEGMENTS {
            let joint = |name: &str| skeleton.joint(&format!("{side}{name}"));
            let (Some(start), Some(end), Some(twisting)) = (
                joint(segment.start),
                joint(segment.end),
                joint(segment.twisting),
            ) else {
                continue;
            };
            let Some((bone, far)) = node_of(start).zip(node_of(end)) else {
                continue;
            };
            let about = (rest[end] - rest[start]).normalize_or_zero();
            let along = place(far) - place(bone);
            if about == Vec3::ZERO || along.length_squared() < 1e-12 {
                continue;
            }
            let share = |i: usize| {
                ((place(i) - place(bone)).dot(along) / along.length_squared()).clamp(0.0, 1.0)
            };
            // the twist bones under the segment's bone, parents first, with the segment's axis
            // in their parent's frame and their parent's share
            let mut stack = vec![(bone, pre[bone].inverse() * about, segment.kept)];
            while let Some((parent, axis, given)) = stack.pop() {
                for child in
                    (0..model.nodes.len()).filter(|&c| model.nodes[c].parent == Some(parent))
                {
                    if !named(child) || carries[child] {
                        continue;
                    }
                    let s = share(child);
                    out.push((
                        child,
                        TwistBone {
                            joint: twisting,
                            about,
                            axis,
                            share: s - given,
                        },
                    ));
                    let rest_rotation = model.nodes[child].rotation;
                    stack.push((child, rest_rotation.inverse() * axis, s));
                }
            }
        }
    }
    out
}

/// Per node, whether a node following a joint is at or below it: each follower and its
/// ancestors, up to the first one already marked.
fn carrying(model: &Model, source: &[Option<usize>]) -> Vec<bool> {
    let mut carries = vec![false; model.nodes.len()];
    for i in (0..model.nodes.len()).filter(|&i| source[i].is_some()) {
        carries[i] = true;
        let mut at = model.nodes[i].parent;
        while let Some(k) = at.filter(|&k| !carries[k]) {
            carries[k] = true;
            at = model.nodes[k].parent;
        }
    }
    carries
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
