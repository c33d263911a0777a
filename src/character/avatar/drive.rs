//! An avatar driven frame by frame, for a host that has loaded a copy of the avatar itself and
//! sets its nodes (the live viewer; an engine through the bindings): per frame, the local
//! rotation of every node that moves, the travelling node's translation and the weights of the
//! morph targets the face drives, flat, in a fixed order the host learns once.

use super::file::Model;
use super::morph::Look;
use super::morph::MorphMap;
use super::retarget::Retarget;
use crate::character::body::pose::Pose;
use crate::character::face::model::Face;

/// What moves in one avatar, and its values for a frame.
#[derive(Debug, Clone)]
pub struct Driver {
    retarget: Retarget,
    morphs: MorphMap,
    moving: Vec<usize>,
}

impl Driver {
    /// The driving of `model` by `retarget` (made for it).
    pub fn new(model: &Model, retarget: Retarget) -> Driver {
        let moving = (0..model.nodes.len())
            .filter(|&i| retarget.moves(i))
            .collect();
        Driver {
            morphs: MorphMap::new(model),
            retarget,
            moving,
        }
    }

    /// The nodes whose rotation moves, in the order of [`Driver::frame`]'s rotations.
    pub fn moving(&self) -> &[usize] {
        &self.moving
    }

    /// How the host turns the avatar's whole scene so that it stands in the realizer's world
    /// (the identity for an avatar made facing the realizer's way; a VRM 0.x is turned half
    /// round). The frames' rotations and travel are in the avatar's own frame.
    pub fn stand(&self) -> glam::Quat {
        self.retarget.stand()
    }

    /// The node whose translation carries the character's travel.
    pub fn hips(&self) -> usize {
        self.retarget.hips()
    }

    /// The mesh nodes whose morph targets the face drives, each with its number of targets,
    /// in the order of [`Driver::frame`]'s weights.
    pub fn morph_nodes(&self) -> Vec<(usize, usize)> {
        self.morphs.nodes().collect()
    }

    /// The avatar at `pose` with `face`: into `rotations`, each moving node's local rotation
    /// (x, y, z, w), then the travelling node's translation (x, y, z); into `weights`, each
    /// morph node's target weights one after the other.
    pub fn frame(
        &self,
        pose: &Pose,
        face: &Face,
        rotations: &mut Vec<f32>,
        weights: &mut Vec<f32>,
    ) {
        let posed = self.retarget.pose(pose);
        rotations.clear();
        for &i in &self.moving {
            rotations.extend(posed.rotations[i].to_array());
        }
        rotations.extend(posed.hips.1.to_array());
        weights.clear();
        let mut one = Vec::new();
        let look = Look::of(pose, self.retarget.eyes());
        for k in 0..self.morphs.nodes().count() {
            self.morphs.weights(k, face, look, &mut one);
            weights.extend_from_slice(&one);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::character::body::Skeleton;
    use crate::character::face::FaceModel;

    #[test]
    fn the_default_avatar_s_moving_nodes_turn_as_their_joints() {
        let model = crate::character::avatar::default_model();
        let skeleton = Skeleton::adult();
        let driver = Driver::new(&model, Retarget::new(&model, &skeleton, None).unwrap());
        let mut pose = Pose::rest(&skeleton);
        let elbow = skeleton.joint("l_elbow").unwrap();
        pose.rotate(elbow, glam::Quat::from_rotation_x(-1.0));
        let mut face = Face::neutral(FaceModel::default_model());
        let smile = crate::character::face::model::morph_index("mouthSmileLeft").unwrap();
        face.morphs.0[smile] = 0.75;
        let (mut r, mut w) = (Vec::new(), Vec::new());
        driver.frame(&pose, &face, &mut r, &mut w);
        assert_eq!(r.len(), 4 * driver.moving().len() + 3);
        let k = (driver.moving().iter())
            .position(|&i| model.nodes[i].name == "l_elbow")
            .unwrap();
        let q = glam::Quat::from_slice(&r[4 * k..4 * k + 4]);
        assert!(q.angle_between(glam::Quat::from_rotation_x(-1.0)) < 1e-5);
        let targets: usize = driver.morph_nodes().iter().map(|n| n.1).sum();
        assert_eq!(w.len(), targets);
        assert!(
            w.contains(&0.75),
            "the smile's weight is among the avatar's"
        );
    }
}
