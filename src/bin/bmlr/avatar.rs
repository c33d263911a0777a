//! `--avatar FILE` and `--bone-map FILE` of `bmlr run` (and the viewer): the avatar a glTF
//! export shows, read and recognised before anything runs, so that a bad one stops the command
//! with exit 2 and a sentence naming the file.

use std::collections::BTreeMap;
use std::path::PathBuf;

use bml_realizer::avatar::{self, Model, Retarget};
use bml_realizer::body::Skeleton;
use clap::Args;

/// The avatar options.
#[derive(Args, Clone, Default)]
pub struct AvatarArgs {
    /// The avatar --gltf shows (.glb, .gltf, or VRM 0.x/1.0 .vrm): the realized motion
    /// retargeted onto its skeleton, the face onto its morph targets by name. Without it, the
    /// default avatar (docs/avatars.md).
    #[arg(long, value_name = "FILE")]
    pub avatar: Option<PathBuf>,
    /// Which node of --avatar is which bone, as JSON: {"leftUpperArm": "Arm.L", ...} (VRM 1.0
    /// bone names or the realizer's joint names as keys), for skeletons named in no known
    /// scheme.
    #[arg(long, value_name = "MAP.json", requires = "avatar")]
    pub bone_map: Option<PathBuf>,
}

/// An avatar read and recognised.
pub struct Avatar {
    pub model: Model,
    pub retarget: Retarget,
}

impl AvatarArgs {
    /// The avatar asked for (the default one when none is), or what is wrong with it.
    pub fn load(&self) -> Result<Avatar, String> {
        let model = match &self.avatar {
            Some(path) => Model::read(path).map_err(|e| e.to_string())?,
            None => avatar::default_model(),
        };
        let map = match &self.bone_map {
            Some(path) => Some(read_map(path)?),
            None => None,
        };
        let retarget =
            Retarget::new(&model, &Skeleton::adult(), map.as_ref()).map_err(|e| e.to_string())?;
        Ok(Avatar { model, retarget })
    }
}

fn read_map(path: &PathBuf) -> Result<BTreeMap<String, String>, String> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| format!("{}: cannot read it: {e}", path.display()))?;
    serde_json::from_str(&text).map_err(|e| {
        format!(
            "{}: a bone map is a JSON object of bone names to node names: {e}",
            path.display()
        )
    })
}
