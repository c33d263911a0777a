//! The parts of a glTF 2.0 document an avatar needs, read from its JSON as the specification
//! says: the nodes (names, children, rest transforms as a matrix or as translation, rotation
//! and scale), the skins' joints and the extensions the file requires. Every index used is
//! checked (in range, each node one parent at most, no cycle), naming the field.
//!
//! Read here rather than through the `gltf` crate's document: its validation refuses files
//! the specification and the Khronos validator allow — accessors without a `bufferView`, which
//! are zeros (gltf-rs issue 346 on GitHub), as exporters write them for morph targets that do not move a
//! primitive — and an avatar needs none of what it would check beyond these few arrays (vertex
//! data is read by the viewer's three.js and checked by the validator on export).

use glam::{Mat4, Quat, Vec3};
use serde_json::Value;

/// One node of the avatar's scene graph at rest.
#[derive(Debug, Clone, PartialEq)]
pub struct Node {
    /// Its name (`""` when it has none).
    pub name: String,
    /// Its parent node.
    pub parent: Option<usize>,
    /// Its rest translation, relative to its parent.
    pub translation: Vec3,
    /// Its rest rotation, relative to its parent.
    pub rotation: Quat,
    /// Its rest scale.
    pub scale: Vec3,
}

impl Node {
    /// Its rest transform relative to its parent.
    pub fn local(&self) -> Mat4 {
        Mat4::from_scale_rotation_translation(self.scale, self.rotation, self.translation)
    }
}

/// Extensions an avatar may require: the ones that change nothing the realizer reads, and that
/// the viewer's three.js and the Khronos validator understand.
pub const UNDERSTOOD_EXTENSIONS: &[&str] = &[
    "KHR_mesh_quantization",
    "KHR_texture_transform",
    "KHR_materials_unlit",
    "KHR_materials_emissive_strength",
    "KHR_materials_ior",
    "KHR_materials_specular",
    "KHR_materials_transmission",
    "KHR_materials_volume",
    "KHR_materials_clearcoat",
    "KHR_materials_sheen",
    "KHR_texture_basisu",
    "EXT_texture_webp",
];

/// Refuses a document that requires an extension not in [`UNDERSTOOD_EXTENSIONS`]: the
/// sentence names it and says what to do.
pub fn check_required(json: &Value) -> Result<(), String> {
    let required = json["extensionsRequired"].as_array().map(Vec::as_slice);
    for e in required.unwrap_or_default() {
        let name = e.as_str().unwrap_or("(not a name)");
        if UNDERSTOOD_EXTENSIONS.contains(&name) {
            continue;
        }
        let how = match name {
            "EXT_meshopt_compression" | "KHR_meshopt_compression" => {
                "its meshes are compressed with meshopt; write it without compression (gltfpack without -c, or Blender's glTF export)"
            }
            "KHR_draco_mesh_compression" => {
                "its meshes are Draco-compressed; export it again without Draco compression (Blender's glTF export: Compression off)"
            }
            _ => "export it again without that extension",
        };
        return Err(format!(
            "it requires the glTF extension {name}, which this realizer does not read; {how}"
        ));
    }
    Ok(())
}

/// The array `key` of the document (empty when absent); an error when it is not an array.
fn array<'a>(json: &'a Value, key: &str) -> Result<&'a [Value], String> {
    match &json[key] {
        Value::Null => Ok(&[]),
        Value::Array(a) => Ok(a),
        _ => Err(format!("'{key}' is not an array")),
    }
}

/// An index at `at` (`what` says where, for the error) below `len`.
fn index(v: &Value, len: usize, what: &str) -> Result<usize, String> {
    v.as_u64()
        .map(|i| i as usize)
        .filter(|&i| i < len)
        .ok_or_else(|| format!("{what}: {v} is not the index of one of the {len}"))
}

/// The `N` numbers at `key` of node `i` (the default when absent).
fn numbers<const N: usize>(
    node: &Value,
    key: &str,
    i: usize,
    default: [f32; N],
) -> Result<[f32; N], String> {
    let Some(v) = node.get(key) else {
        return Ok(default);
    };
    let a = v.as_array().filter(|a| a.len() == N);
    let a = a.ok_or_else(|| format!("nodes[{i}].{key}: not {N} numbers"))?;
    let mut out = default;
    for (o, x) in out.iter_mut().zip(a) {
        *o = (x.as_f64())
            .filter(|f| f.is_finite())
            .ok_or_else(|| format!("nodes[{i}].{key}: {x} is not a number"))? as f32;
    }
    Ok(out)
}

/// The nodes at rest, each with its parent.
pub fn nodes(json: &Value) -> Result<Vec<Node>, String> {
    let raw = array(json, "nodes")?;
    let mut nodes = Vec::with_capacity(raw.len());
    for (i, n) in raw.iter().enumerate() {
        let (scale, rotation, translation) = if n.get("matrix").is_some() {
            let m = Mat4::from_cols_array(&numbers(n, "matrix", i, [0.0; 16])?);
            m.to_scale_rotation_translation()
        } else {
            let t = numbers(n, "translation", i, [0.0; 3])?;
            let r = numbers(n, "rotation", i, [0.0, 0.0, 0.0, 1.0])?;
            let s = numbers(n, "scale", i, [1.0; 3])?;
            (Vec3::from(s), Quat::from_array(r), Vec3::from(t))
        };
        let rotation = if rotation.length_squared() > 0.0 {
            rotation.normalize()
        } else {
            Quat::IDENTITY
        };
        nodes.push(Node {
            name: n["name"].as_str().unwrap_or("").to_string(),
            parent: None,
            translation,
            rotation,
            scale,
        });
    }
    for (i, n) in raw.iter().enumerate() {
        let children = array(n, "children").map_err(|e| format!("nodes[{i}]: {e}"))?;
        for (k, c) in children.iter().enumerate() {
            let c = index(c, raw.len(), &format!("nodes[{i}].children[{k}]"))?;
            if c == i || nodes[c].parent.is_some() {
                return Err(format!(
                    "nodes[{i}].children[{k}]: node {c} has a parent already (a node has one at most)"
                ));
            }
            nodes[c].parent = Some(i);
        }
    }
    // (one parent each: a cycle is a chain that never reaches a root)
    for i in 0..nodes.len() {
        let (mut at, mut steps) = (nodes[i].parent, 0);
        while let Some(p) = at {
            steps += 1;
            if steps > nodes.len() {
                return Err(format!("nodes: node {i} is its own ancestor"));
            }
            at = nodes[p].parent;
        }
    }
    Ok(nodes)
}

/// The joints (node indices) of each skin.
pub fn skins(json: &Value, nodes: usize) -> Result<Vec<Vec<usize>>, String> {
    let raw = array(json, "skins")?;
    (raw.iter().enumerate())
        .map(|(s, skin)| {
            let joints = array(skin, "joints").map_err(|e| format!("skins[{s}]: {e}"))?;
            (joints.iter().enumerate())
                .map(|(k, j)| index(j, nodes, &format!("skins[{s}].joints[{k}]")))
                .collect()
        })
        .collect()
}
