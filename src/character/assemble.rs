//! The last steps of a character's frame, after its engines have moved the body and played the
//! face: the lids blink and follow the eyes' pitch (with the idle layer), the face's derived
//! blendshapes are made from its action units, the jaw joint opens as far as the mouth's
//! `jawOpen` says, the joints are clamped into their limits, and the body is placed where the
//! character stands in the world. The body and the face meet here and nowhere below.

use glam::{Quat, Vec3};

use super::blink::{Blinker, Eyes};
use crate::character::body::Placement;
use crate::character::body::{Pose, Skeleton};
use crate::character::face::{Face, FaceModel};

/// How far the jaw joint (temporomandibular) opens at `jawOpen` = 1 (radians, about +x).
pub const JAW_OPEN: f32 = 0.35; // 20°

/// What one character adds to its engines' pose and face to make its frame.
#[derive(Debug, Clone)]
pub struct Assembler {
    /// The lids' idle life (blinks, lids following the eyes), with the idle layer.
    blinks: Option<Blinker>,
}

impl Assembler {
    /// The assembly of character `id`'s frames (`""`: the default character), its lids alive
    /// when `idle`.
    pub fn new(id: &str, idle: bool) -> Assembler {
        Assembler {
            blinks: idle.then(|| Blinker::new(id)),
        }
    }

    /// Turns the lids' idle life on or off (with the idle layer).
    pub fn set_idle(&mut self, id: &str, on: bool) {
        self.blinks = on.then(|| Blinker::new(id));
    }

    /// Finishes the frame at `now` of a character with `skeleton` standing at `placement`:
    /// `pose` and `face` as its engines left them. Returns the joints that were clamped into
    /// their limits.
    pub fn finish(
        &mut self,
        now: f64,
        skeleton: &Skeleton,
        placement: &Placement,
        pose: &mut Pose,
        face: &mut Face,
    ) -> Vec<usize> {
        if let Some(b) = self.blinks.as_mut() {
            b.apply(now, eyes(skeleton, pose), face);
        }
        FaceModel::default_model().finish(face);
        if let Some(jaw) = skeleton.joint("temporomandibular") {
            let open = face.morphs.get("jawOpen") * JAW_OPEN;
            pose.rotate(jaw, Quat::from_rotation_x(open));
        }
        let clamped = skeleton.limits().clamp(pose);
        // from the character's own frame to where it stands in the world
        if !placement.is_origin() {
            pose.root = placement.to_world(pose.root);
            pose.rotations[0] = placement.rotation() * pose.rotations[0];
        }
        clamped
    }
}

/// Where the eyes of `pose` look, in the head's frame.
pub fn eyes(skeleton: &Skeleton, pose: &Pose) -> Eyes {
    let turn = |name: &str| {
        (skeleton.joint(name))
            .and_then(|j| pose.rotations.get(j).copied())
            .unwrap_or(Quat::IDENTITY)
    };
    let d = (turn("l_eyeball_joint") * Vec3::Z + turn("r_eyeball_joint") * Vec3::Z)
        .normalize_or(Vec3::Z);
    Eyes {
        pitch: d.y.clamp(-1.0, 1.0).asin(),
        direction: d,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_jaw_opens_with_the_mouth_and_eyes_looking_down_lower_the_lids() {
        let s = Skeleton::adult();
        let model = FaceModel::default_model();
        let mut face = Face::neutral(model);
        let open = crate::character::face::model::morph_index("jawOpen").unwrap();
        face.morphs.0[open] = 1.0;
        let mut pose = Pose::rest(&s);
        let down = Quat::from_rotation_x(0.3); // +x turns +z towards −y: down
        for eye in ["l_eyeball_joint", "r_eyeball_joint"] {
            pose.rotate(s.joint(eye).unwrap(), down);
        }
        assert!((eyes(&s, &pose).pitch + 0.3).abs() < 1e-5);
        let mut a = Assembler::new("anna", true);
        a.finish(0.0, &s, &Placement::default(), &mut pose, &mut face);
        let jaw = pose.rotations[s.joint("temporomandibular").unwrap()];
        assert!((jaw.angle_between(Quat::IDENTITY) - JAW_OPEN).abs() < 1e-4);
        let lowered = model.slots(43, crate::language::bml::Side::Left).unwrap()[0];
        assert!(
            face.aus.0[lowered] > 0.4,
            "lids lowered: {}",
            face.aus.0[lowered]
        );
    }
}
