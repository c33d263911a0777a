//! The geometry of space, below everything that moves or looks in it: obstacles on the ground
//! plane (circles, boxes and walls, with a bucket index), routes round them (A* on a grid,
//! pulled tight), the distances between points and segments they are measured with, and the gaps
//! between obstacles too narrow for two people to pass each other in (narrows). The
//! world holds the obstacles; walkers, crowds, sight and the behaviour nets read them from here.
//! It uses nothing of the realizer but `glam` and `serde`.

pub mod distance;
pub mod narrows;
pub mod obstacles;
pub mod path;

pub use obstacles::{Obstacle, Obstacles, Shape};

/// Largest coordinate a world file may give (metres): far beyond any scene, and far enough from
/// `f32::MAX` that turning a point into a character's frame stays finite.
pub const MAX_COORDINATE: f64 = 1e9;
