//! What a frame holds: the engines' outputs, each character's pose and the feedback sent since
//! the previous frame.

use std::sync::Arc;

use super::UnitKey;
use crate::language::feedback::Feedback;

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

pub use crate::character::CharacterPose;

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
