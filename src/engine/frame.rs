//! What a frame holds: the engines' outputs, each character's pose and the feedback sent since
//! the previous frame.

use std::sync::Arc;

use super::UnitKey;
use crate::body::Pose;
use crate::feedback::Feedback;

/// What one engine shows of one running unit in a frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Output {
    /// The unit (shared with the engine: no copy per frame).
    pub key: Arc<UnitKey>,
    /// The engine's name.
    pub engine: &'static str,
    /// Progress through the unit, 0 at start and 1 at end.
    pub progress: f64,
    /// Current parameter values (e.g. `volume` of a speech).
    pub params: Vec<(&'static str, f64)>,
}

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
    pub face: crate::face::Face,
    /// The sounds it makes in this frame.
    pub sounds: Vec<crate::sound::Playing>,
    /// Sounds that started or stopped since the previous frame.
    pub events: Vec<crate::sound::SoundEvent>,
    /// Whether each foot (left, right) is on the ground, once the character has walked.
    pub contacts: Option<[bool; 2]>,
}

/// Everything the realizer produced for one moment: engine output, each character's pose, and the
/// feedback sent since the previous frame.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Frame {
    /// Global time of the frame.
    pub time: f64,
    /// One entry per running unit that shows something.
    pub outputs: Vec<Output>,
    /// The pose of every character, in character order.
    pub poses: Vec<CharacterPose>,
    /// Feedback sent since the previous frame, in order.
    pub feedback: Vec<Feedback>,
}

impl Frame {
    /// Character `id`'s body in this frame (`""` the default character).
    pub fn character(&self, id: &str) -> Option<&CharacterPose> {
        (self.poses.iter()).find(|p| p.character.as_deref().unwrap_or("") == id)
    }
}
