//! Where a body stands in the world: a place on the ground and the way it faces, which turns
//! the character's own frame (the origin facing +z, y up, metres) into the world's.

use glam::{Quat, Vec3};

/// Where a character stands: a place on the ground and the way it faces.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Placement {
    /// Where its root stands (metres, world).
    pub position: Vec3,
    /// Its heading: radians about +y from facing +z (π/2 faces +x).
    pub facing: f32,
}

impl Placement {
    /// Standing at `position`, turned `degrees` about +y from facing +z.
    pub fn new(position: Vec3, degrees: f32) -> Placement {
        Placement {
            position,
            facing: degrees.to_radians(),
        }
    }

    /// Its turn from facing +z.
    pub fn rotation(&self) -> Quat {
        Quat::from_rotation_y(self.facing)
    }

    /// A point of the character's own frame (the origin facing +z) in the world.
    pub fn to_world(&self, local: Vec3) -> Vec3 {
        self.position + self.rotation() * local
    }

    /// A point of the world in the character's own frame.
    pub fn to_local(&self, world: Vec3) -> Vec3 {
        self.rotation().inverse() * (world - self.position)
    }

    /// Whether it is the origin facing +z (the character's frame is the world's).
    pub fn is_origin(&self) -> bool {
        *self == Placement::default()
    }
}
