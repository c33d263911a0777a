//! `--avatar FILE` and `--bone-map FILE` of `bmlr run`, `view` and `serve --view`: the avatar a
//! glTF export, the viewer and the live view show, read and recognised before anything runs, so that a bad one stops the command
//! with exit 2 and a sentence naming the file.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use bml_realizer::character::avatar::{self, Model, Retarget};
use bml_realizer::character::body::Skeleton;
use bml_realizer::world::{Placement, World};
use clap::Args;

/// The avatar options.
#[derive(Args, Clone, Default)]
pub struct AvatarArgs {
    /// The avatar the characters are shown as (in --gltf, the viewer, the live view) when the
    /// world file gives them none (.glb, .gltf, or VRM 0.x/1.0 .vrm): the realized motion
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

impl Avatar {
    /// The avatar at `path` (the default one for none), its bones by `map` or recognised.
    fn read(path: Option<&Path>, map: Option<&BTreeMap<String, String>>) -> Result<Avatar, String> {
        let model = match path {
            Some(path) => Model::read(path).map_err(|e| e.to_string())?,
            None => avatar::default_model(),
        };
        let retarget = Retarget::new(&model, &Skeleton::adult(), map).map_err(|e| e.to_string())?;
        Ok(Avatar { model, retarget })
    }

    /// Its driving for a character that stood `at` when its motion began (its place kept,
    /// its travel from there scaled by leg length).
    pub fn placed(&self, at: Placement) -> Retarget {
        let mut retarget = self.retarget.clone();
        retarget.place_at(at);
        retarget
    }
}

/// The avatar of every character: the world file's for those it gives one, else the one of
/// the command line (or the default one).
pub struct Avatars {
    /// For characters the world file gives none.
    pub common: Avatar,
    /// By character id, from the world file.
    pub own: BTreeMap<String, Avatar>,
}

impl Avatars {
    /// Character `id`'s avatar.
    pub fn of(&self, id: &str) -> &Avatar {
        self.own.get(id).unwrap_or(&self.common)
    }
}

impl AvatarArgs {
    /// The avatars of `world`'s characters (read from `world_file`'s directory when relative)
    /// and the one asked for on the command line (the default one when none is), or what is
    /// wrong with one of them.
    pub fn load(&self, world: &World, world_file: Option<&Path>) -> Result<Avatars, String> {
        let map = match &self.bone_map {
            Some(path) => Some(read_map(path)?),
            None => None,
        };
        let common = Avatar::read(self.avatar.as_deref(), map.as_ref())?;
        let dir = world_file.and_then(Path::parent).unwrap_or(Path::new(""));
        let mut own = BTreeMap::new();
        for (id, _) in world.placements() {
            if let Some(file) = world.avatar(id) {
                let path = dir.join(file);
                let avatar = Avatar::read(Some(&path), None)
                    .map_err(|e| format!("world file: character '{id}': {e}"))?;
                own.insert(id.to_string(), avatar);
            }
        }
        Ok(Avatars { common, own })
    }
}

/// A bone map file: bone names to node names or node indices.
fn read_map(path: &Path) -> Result<BTreeMap<String, String>, String> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| format!("{}: cannot read it: {e}", path.display()))?;
    bml_realizer::character::avatar::humanoid::bone_map_from_json(&text).map_err(|e| {
        format!(
            "{}: a bone map is a JSON object of bone names to node names or node indices: {e}",
            path.display()
        )
    })
}
