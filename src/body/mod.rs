//! The body: an H-Anim skeleton ([`skeleton`]), poses with forward kinematics ([`pose`]) and BVH
//! export ([`bvh`]), and two-link inverse kinematics ([`ik`]).
//! Right-handed coordinates, y up, the character facing +z (its left is +x), metres and radians.

pub mod bvh;
pub mod ik;
pub mod pose;
pub mod skeleton;

pub use pose::{Pose, WorldPose};
pub use skeleton::{Joint, Skeleton, SkeletonError};
