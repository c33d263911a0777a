//! Reading an avatar file: a binary glTF (`.glb`, and VRM 0.x/1.0 `.vrm`, which are GLB) or a
//! JSON glTF (`.gltf`) whose buffers are `data:` URIs or files beside it. Out of the document
//! (`document`: read as the specification says, every index it uses checked) come the nodes
//! (names, parents, rest transforms), the largest skin's joints and every mesh's morph target
//! names. The file's own JSON is kept as it is (VRM's extensions included) with its buffers
//! gathered into one (`buffers`), so that an export can write the avatar back unchanged with
//! the animation added. An FBX file is refused saying how to convert it.

use std::path::Path;

use glam::Mat4;
use serde_json::Value;

use super::{buffers, document};

/// The largest avatar file read (bytes).
pub const MAX_AVATAR_BYTES: u64 = 256 << 20;

/// Something wrong with an avatar file: the file and what is wrong or missing.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{file}: {what}")]
pub struct AvatarError {
    /// The file (or the name the avatar was given).
    pub file: String,
    /// What is wrong or missing, in a sentence.
    pub what: String,
}

impl AvatarError {
    pub(crate) fn new(file: &str, what: impl Into<String>) -> AvatarError {
        AvatarError {
            file: file.to_string(),
            what: what.into(),
        }
    }
}

pub use super::document::Node;

/// An avatar file read: its nodes, skin and morph targets, and the file's JSON and binary
/// buffer as they were.
#[derive(Debug, Clone)]
pub struct Model {
    /// The file's name, for messages.
    pub file: String,
    /// Every node, in the file's order.
    pub nodes: Vec<Node>,
    /// The nodes of the first skin's joints.
    pub joints: Vec<usize>,
    /// Per mesh (by index) the names of its morph targets (empty when it has none or they are
    /// unnamed).
    pub morphs: Vec<Vec<String>>,
    /// The file's glTF JSON.
    pub json: Value,
    /// The binary buffer (the GLB's BIN chunk, or a `.gltf`'s single buffer).
    pub bin: Vec<u8>,
}

const GLB_MAGIC: u32 = 0x4654_6C67;
const CHUNK_JSON: u32 = 0x4E4F_534A;
const CHUNK_BIN: u32 = 0x004E_4942;

impl Model {
    /// Reads the avatar at `path` (`.glb`, `.vrm` or `.gltf`).
    pub fn read(path: &Path) -> Result<Model, AvatarError> {
        let file = path.display().to_string();
        let size = std::fs::metadata(path)
            .map_err(|e| AvatarError::new(&file, format!("cannot read it: {e}")))?
            .len();
        if size > MAX_AVATAR_BYTES {
            return Err(AvatarError::new(
                &file,
                format!("{size} bytes, more than the {MAX_AVATAR_BYTES} an avatar may have"),
            ));
        }
        let bytes = std::fs::read(path)
            .map_err(|e| AvatarError::new(&file, format!("cannot read it: {e}")))?;
        if bytes.starts_with(b"glTF") {
            return Model::from_glb(&file, &bytes);
        }
        if bytes.starts_with(b"Kaydara FBX Binary") || bytes.starts_with(b"; FBX") {
            return Err(AvatarError::new(
                &file,
                "an FBX file, which this realizer does not read: convert it to glTF binary (.glb), \
                 e.g. in Blender (File > Import > FBX, then File > Export > glTF 2.0, format GLB) \
                 or with FBX2glTF (`FBX2glTF --binary --input X.fbx --output X`)",
            ));
        }
        let mut json: Value = serde_json::from_slice(&bytes)
            .map_err(|e| AvatarError::new(&file, format!("neither GLB nor glTF JSON: {e}")))?;
        let dir = path.parent().unwrap_or(Path::new(".")).to_path_buf();
        let bin = buffers::gather(&mut json, buffers::First::Beside(dir))
            .map_err(|e| AvatarError::new(&file, e))?;
        Model::from_parts(&file, json, bin)
    }

    /// Reads an avatar from the bytes of a GLB (or VRM) file named `file`.
    pub fn from_glb(file: &str, bytes: &[u8]) -> Result<Model, AvatarError> {
        let bad = |what: &str| AvatarError::new(file, format!("not a valid GLB: {what}"));
        let word = |at: usize| -> Result<u32, AvatarError> {
            let b = bytes.get(at..at + 4).ok_or_else(|| bad("it ends early"))?;
            Ok(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
        };
        if word(0)? != GLB_MAGIC || word(4)? != 2 {
            return Err(bad("not glTF 2.0"));
        }
        let total = (word(8)? as usize).min(bytes.len());
        let (mut at, mut json, mut bin) = (12, None, Vec::new());
        while at + 8 <= total {
            let (length, kind) = (word(at)? as usize, word(at + 4)?);
            let chunk = bytes
                .get(at + 8..at + 8 + length)
                .ok_or_else(|| bad("a chunk runs past the end"))?;
            match kind {
                CHUNK_JSON if json.is_none() => json = Some(chunk),
                CHUNK_BIN if bin.is_empty() => bin = chunk.to_vec(),
                _ => {}
            }
            at += 8 + length.next_multiple_of(4);
        }
        let json = json.ok_or_else(|| bad("no JSON chunk"))?;
        let mut json: Value = serde_json::from_slice(json)
            .map_err(|e| AvatarError::new(file, format!("its JSON: {e}")))?;
        let bin = buffers::gather(&mut json, buffers::First::Glb(bin))
            .map_err(|e| AvatarError::new(file, e))?;
        Model::from_parts(file, json, bin)
    }

    /// The avatar of glTF `json` with its one binary buffer `bin`.
    fn from_parts(file: &str, json: Value, bin: Vec<u8>) -> Result<Model, AvatarError> {
        let invalid = |e: String| AvatarError::new(file, format!("not valid glTF: {e}"));
        if !json.is_object() {
            return Err(invalid("the document is not a JSON object".into()));
        }
        let version = json["asset"]["version"].as_str().unwrap_or("");
        if !version.starts_with("2.") {
            return Err(invalid(format!(
                "asset.version is '{version}', not 2.x (glTF 1.0 files must be converted)"
            )));
        }
        document::check_required(&json).map_err(|e| AvatarError::new(file, e))?;
        let nodes = document::nodes(&json).map_err(invalid)?;
        let skins = document::skins(&json, nodes.len()).map_err(invalid)?;
        // (the skin with most joints: a figure's body, not an accessory's)
        let joints = skins.into_iter().max_by_key(Vec::len).unwrap_or_default();
        if joints.is_empty() {
            return Err(AvatarError::new(file, "it has no skin (no skinned mesh)"));
        }
        let meshes = json["meshes"].as_array().map_or(0, Vec::len);
        let morphs = (0..meshes)
            .map(|m| target_names(&json["meshes"][m]))
            .collect();
        Ok(Model {
            file: file.to_string(),
            nodes,
            joints,
            morphs,
            json,
            bin,
        })
    }

    /// The rest transform of node `i` in the scene (its parents' transforms applied).
    pub fn rest_world(&self, i: usize) -> Mat4 {
        let mut m = self.nodes[i].local();
        let mut at = self.nodes[i].parent;
        // (a cycle is refused by the glTF check; the count bounds the walk all the same)
        for _ in 0..self.nodes.len() {
            let Some(p) = at else { break };
            m = self.nodes[p].local() * m;
            at = self.nodes[p].parent;
        }
        m
    }

    /// The node named `name`.
    pub fn node(&self, name: &str) -> Option<usize> {
        self.nodes.iter().position(|n| n.name == name)
    }
}

/// The morph target names of a glTF mesh: `extras.targetNames` of the mesh or of its first
/// primitive (exporters use either).
fn target_names(mesh: &Value) -> Vec<String> {
    let names = mesh["extras"]["targetNames"]
        .as_array()
        .or_else(|| mesh["primitives"][0]["extras"]["targetNames"].as_array());
    names
        .map(|a| {
            a.iter()
                .map(|v| v.as_str().unwrap_or("").to_string())
                .collect()
        })
        .unwrap_or_default()
}
