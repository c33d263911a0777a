//! Walking: how a character gets from one place to another. [`steering`] is Reynolds' vehicle
//! model with the steering behaviours and combiners of the IViHumans platform (usable on its
//! own), round the obstacles and along the routes of [`crate::world::space`]; [`gait`] a
//! procedural human gait driven by the distance walked, with planted feet, and [`knee`] its
//! knees' least bend; [`posing`] that gait as a pose of the skeleton; [`walker`] one walking
//! character that puts them together at a fixed step.
//! The locomotion engine (`engines::locomotion`, which also resolves where a walk goes) realizes
//! BML `<locomotion>` with them; `docs/locomotion.md` explains the whole.

/// The walker's fixed step (s), which the crowd around a walker is also moved on by.
pub const STEP: f64 = 1.0 / 240.0;

pub mod among;
pub mod footsteps;
pub mod gait;
pub mod knee;
pub mod posing;
pub mod room;
pub mod steering;
pub mod walker;

/// Obstacles and routes moved to [`crate::world::space`], below locomotion; these keep the old paths
/// compiling for one release.
pub use crate::world::space::{obstacles, path, Obstacle, Obstacles, Shape};
pub use walker::{Moments, Walk, Walker};

/// Where a walk goes moved to the locomotion engine, the one user that reads the world; this
/// keeps the old path compiling for one release.
#[doc(hidden)]
pub use crate::engines::locomotion::targets;
