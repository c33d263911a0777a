//! A character at a moment as the realizer hands it out in each frame: its body's pose inside
//! the joint limits (and which joints were clamped), its face, its sounds and its feet's contact
//! with the ground.

use crate::character::body::Pose;

/// A character's body at a moment.
#[derive(Debug, Clone, PartialEq)]
pub struct CharacterPose {
    /// The character (`None`: the default character).
    pub character: Option<String>,
    /// Its pose (joint order of the character's skeleton), inside the joint limits.
    pub pose: Pose,
    /// The joints (indices) the engines turned beyond their limits in this frame, which were
    /// clamped back into them.
    pub clamped: Vec<usize>,
    /// Its face: action units, blendshape weights, the viseme.
    pub face: crate::character::face::Face,
    /// The sounds it makes in this frame.
    pub sounds: Vec<crate::character::sound::Playing>,
    /// Sounds that started or stopped since the previous frame.
    pub events: Vec<crate::character::sound::SoundEvent>,
    /// Whether each foot (left, right) is on the ground, once the character has walked.
    pub contacts: Option<[bool; 2]>,
}
