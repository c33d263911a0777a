//! Walking: how a character gets from one place to another. [`steering`] is Reynolds' vehicle
//! model with the steering behaviours and combiners of the IViHumans platform (usable on its
//! own); [`obstacles`] the world's circles, boxes and walls; [`path`] routes around them (A* on
//! a grid, pulled tight); [`gait`] a procedural human gait driven by the distance walked, with
//! planted feet; [`posing`] that gait as a pose of the skeleton; [`targets`] where a walk goes;
//! [`walker`] one walking
//! character that puts them together at a fixed step. The locomotion engine
//! (`engines::locomotion`) realizes BML `<locomotion>` with them; `docs/locomotion.md` explains
//! the whole.

pub mod among;
pub mod footsteps;
pub mod gait;
pub mod obstacles;
pub mod path;
pub mod posing;
pub mod room;
pub mod steering;
pub mod targets;
pub mod walker;

pub use obstacles::{Obstacle, Obstacles, Shape};
pub use walker::{Moments, Walk, Walker};
