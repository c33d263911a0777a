//! The body: an H-Anim skeleton ([`skeleton`]), poses with forward kinematics ([`pose`]), BVH
//! export ([`bvh`]), glTF export ([`gltf`]) of the mannequin ([`mannequin`]), the frames file ([`crate::character::frames`]), joint limits ([`limits`]), the idle layer
//! ([`idle`], with the eyes' [`saccades`] and [`aversion`]), stick-figure pictures ([`sketch`]) and two-link inverse kinematics ([`ik`]).
//! Right-handed coordinates, y up, the character facing +z (its left is +x), metres and radians.

pub mod aversion;
pub mod bvh;
pub mod gltf;
pub mod idle;
pub mod ik;
pub mod limits;
pub mod mannequin;
pub mod placement;
pub mod pose;
pub mod saccades;
pub mod skeleton;
pub mod sketch;

pub use placement::Placement;
pub use pose::{Pose, WorldPose};
pub use skeleton::{Joint, Skeleton, SkeletonError};
