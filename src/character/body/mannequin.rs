//! The mannequin: the simple body drawn around a skeleton, shared by the glTF export and the web
//! viewer so that both show the same figure. Every bone (parent joint to child joint) is a box
//! of a thickness that depends on the body part; the head is a box above the skull base, the
//! jaw a box that hangs from the jaw joint, and each eye a small dark box that shows where it
//! looks. Each part follows one joint rigidly, and is either skin (head, neck, hands) or cloth.

use glam::Vec3;
use serde::Serialize;

use super::pose::Pose;
use super::skeleton::Skeleton;

/// One box of the mannequin, in rest-pose world coordinates (metres).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Segment {
    /// The joint the box moves with (an index into the skeleton).
    pub joint: usize,
    /// Where the box starts along its length.
    pub from: [f32; 3],
    /// Where it ends.
    pub to: [f32; 3],
    /// Its width and depth.
    pub width: f32,
    /// Skin (head, neck, hands) rather than cloth.
    pub skin: bool,
}

/// Height of the head box above the skull base, its width, and how far its centre is in front of
/// the skull base.
const HEAD: (f32, f32, f32) = (0.22, 0.17, 0.03);
/// The jaw box: from the jaw joint down to the chin (behind the face's front, so the mouth
/// shows), and its width.
const JAW: ([f32; 3], f32) = ([0.0, -0.04, 0.0], 0.085);
/// The eye boxes: how far each reaches forward from the eyeball joint, and their width.
const EYE: (f32, f32) = (0.03, 0.025);

/// A body part's thickness (metres) and whether it shows skin, by the names of the joints its
/// bone starts and ends at.
fn part(name: &str, child: &str) -> (f32, bool) {
    let finger = ["thumb", "index", "middle", "ring", "pinky"];
    if child.ends_with("_hip") {
        (0.12, false) // the pelvis, from the sacrum out to each hip
    } else if finger.iter().any(|f| name.contains(f)) {
        (0.016, true)
    } else if name.contains("wrist") {
        (0.045, true)
    } else if name.starts_with("vl") || name.starts_with("vt") || name == "sacroiliac" {
        (0.2, false)
    } else if name.starts_with("vc") || name == "skullbase" {
        (0.09, true)
    } else if name.contains("sternoclavicular") || name.contains("hip") {
        (0.09, false)
    } else {
        (0.075, false)
    }
}

/// The boxes of the mannequin on `skeleton`: one per bone (the eyes and the jaw drawn as
/// themselves), then the head.
pub fn segments(skeleton: &Skeleton) -> Vec<Segment> {
    let joints = skeleton.joints();
    let rest = Pose::rest(skeleton).world(skeleton).positions;
    let along = |joint: usize, from: Vec3, to: Vec3, width: f32, skin: bool| Segment {
        joint,
        from: from.to_array(),
        to: to.to_array(),
        width,
        skin,
    };
    let mut out: Vec<Segment> = (joints.iter().enumerate())
        .filter_map(|(i, j)| {
            let p = j.parent?;
            let at = rest[i];
            Some(if j.name.contains("eyeball") {
                along(i, at, at + Vec3::Z * EYE.0, EYE.1, false)
            } else if j.name == "temporomandibular" {
                along(i, at, at + Vec3::from(JAW.0), JAW.1, true)
            } else {
                let (width, skin) = part(&joints[p].name, &j.name);
                along(p, rest[p], at, width, skin)
            })
        })
        .collect();
    if let Some(head) = skeleton.joint("skullbase") {
        let base = rest[head] + Vec3::Z * HEAD.2;
        out.push(along(head, base, base + Vec3::Y * HEAD.0, HEAD.1, true));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_bone_and_the_head_is_a_box() {
        let s = Skeleton::adult();
        let parts = segments(&s);
        assert_eq!(
            parts.len(),
            s.len() - 1 + 1,
            "one per bone (all but the root) + head"
        );
        let head = parts.last().unwrap();
        assert_eq!(head.joint, s.joint("skullbase").unwrap());
        assert!(
            head.to[1] > 1.7 && head.to[1] < 1.9,
            "the head's top at {:?}",
            head.to
        );
        let wrist = s.joint("r_wrist").unwrap();
        assert!(parts.iter().any(|p| p.joint == wrist && p.skin));
    }
}
