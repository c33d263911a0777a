//! Fuzz target `avatar`: arbitrary bytes as an avatar file (GLB container, glTF JSON, VRM
//! extensions, skins, node hierarchies) are read, recognised and retargeted; an error is fine,
//! a panic or a hang is not.

#![no_main]

use bml_realizer::avatar::{Model, Retarget};
use bml_realizer::character::body::{Pose, Skeleton};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(model) = Model::from_glb("fuzz.glb", data) else {
        return;
    };
    let skeleton = Skeleton::adult();
    if let Ok(retarget) = Retarget::new(&model, &skeleton, None) {
        let _ = retarget.pose(&Pose::rest(&skeleton));
    }
});
