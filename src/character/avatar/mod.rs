//! Avatars: a skinned human the realizer's motion is shown on. An avatar is a glTF 2.0 file
//! (GLB, or VRM 0.x/1.0) read by [`Model`]; its skeleton is recognised by [`humanoid`] (VRM's
//! humanoid map, a bone map, or H-Anim, Mixamo or Unreal names) and driven by [`Retarget`],
//! which aligns the two rest poses bone by bone and gives each avatar bone the world rotation
//! of its realizer joint. The default avatar, built by `tools/avatar.py` from CC0 MakeHuman
//! data (`assets/avatar/NOTICE.md`), is compiled in: its skeleton is the realizer's own, its
//! face has the 52 ARKit morph targets.

mod buffers;
mod document;
mod drive;
mod export;
mod file;
pub mod humanoid;
mod morph;
mod retarget;
mod scene;
mod twist;

pub use drive::Driver;
pub use export::{animated_document, animated_glb, Frame};
pub use file::{AvatarError, Model, Node, MAX_AVATAR_BYTES};
pub use morph::{Look, MorphMap};
pub use retarget::{Posed, Retarget};
pub use scene::scene_glb;

/// The default avatar's GLB (`assets/avatar/default.glb`, CC0 data; notice beside it).
pub const DEFAULT_GLB: &[u8] = include_bytes!("../../../assets/avatar/default.glb");

/// The default avatar, read.
pub fn default_model() -> Model {
    Model::from_glb("default avatar", DEFAULT_GLB).expect("the default avatar is a valid GLB")
}
