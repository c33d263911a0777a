//! glTF 2.0 export (`bmlr run --gltf OUT.glb`): the skinned mannequin of [`mannequin`] — a box
//! along every bone, a box head, two materials (skin for the head and hands, cloth for the
//! rest) — and the realized motion as animation channels (every joint's rotation, the root's
//! translation), in one binary `.glb` file for Blender, three.js or a game engine; several
//! characters make one scene, each a mannequin of its own. Each vertex follows one joint (the one
//! whose bone it belongs to), so the mannequin moves rigidly per bone.

use glam::{Mat4, Quat, Vec3};
use serde_json::{json, Value};

use super::mannequin;
use super::pose::Pose;
use super::skeleton::Skeleton;

/// glTF component types and buffer targets.
const FLOAT: u32 = 5126;
const UNSIGNED_SHORT: u32 = 5123;
const UNSIGNED_INT: u32 = 5125;
const ARRAY_BUFFER: u32 = 34962;
const ELEMENT_ARRAY_BUFFER: u32 = 34963;

/// The mesh being built: positions, normals, the joint of each vertex, and the triangles of the
/// two materials.
#[derive(Default)]
struct Mesh {
    positions: Vec<Vec3>,
    normals: Vec<Vec3>,
    joints: Vec<u16>,
    triangles: [Vec<u32>; 2],
}

impl Mesh {
    /// A box from `a` to `b` (rest positions), `width` across, following joint `joint`.
    fn bone(&mut self, a: Vec3, b: Vec3, width: f32, joint: u16, skin: bool) {
        let axis = (b - a).normalize_or(Vec3::Y);
        let rotation = Quat::from_rotation_arc(Vec3::Y, axis);
        let (half, length) = (width / 2.0, a.distance(b).max(0.01));
        // six faces, four corners each (so each face has its own normal)
        for (n, u, v) in [
            (Vec3::X, Vec3::Y, Vec3::Z),
            (Vec3::NEG_X, Vec3::Z, Vec3::Y),
            (Vec3::Z, Vec3::X, Vec3::Y),
            (Vec3::NEG_Z, Vec3::Y, Vec3::X),
            (Vec3::Y, Vec3::Z, Vec3::X),
            (Vec3::NEG_Y, Vec3::X, Vec3::Z),
        ] {
            let base = self.positions.len() as u32;
            for (su, sv) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
                // the box spans y in [0, length] and x, z in [-half, half] before it is turned
                let local = n * half + u * su * half + v * sv * half;
                let local = Vec3::new(local.x, (local.y + half) / (2.0 * half) * length, local.z);
                self.positions.push(a + rotation * local);
                self.normals.push(rotation * n);
                self.joints.push(joint);
            }
            // the corners go round u then v: counter-clockwise seen from outside when u × v = n
            let quad = if u.cross(v).dot(n) > 0.0 {
                [0, 1, 2, 0, 2, 3]
            } else {
                [0, 2, 1, 0, 3, 2]
            };
            self.triangles[usize::from(skin)].extend(quad.map(|k| base + k));
        }
    }
}

/// The binary buffer and the accessors into it (also used to add an animation to an avatar's
/// own buffer, `avatar::animated_glb`).
#[derive(Default)]
pub(crate) struct Buffer {
    pub(crate) bytes: Vec<u8>,
    pub(crate) views: Vec<Value>,
    pub(crate) accessors: Vec<Value>,
}

impl Buffer {
    /// Appends `data` as a buffer view and an accessor; returns the accessor's index.
    fn add(&mut self, data: &[u8], target: Option<u32>, accessor: Value) -> usize {
        while !self.bytes.len().is_multiple_of(4) {
            self.bytes.push(0);
        }
        let mut view =
            json!({"buffer": 0, "byteOffset": self.bytes.len(), "byteLength": data.len()});
        if let Some(t) = target {
            view["target"] = json!(t);
        }
        self.bytes.extend_from_slice(data);
        self.views.push(view);
        let mut accessor = accessor;
        accessor["bufferView"] = json!(self.views.len() - 1);
        self.accessors.push(accessor);
        self.accessors.len() - 1
    }

    /// Appends `values` as an accessor of `count` elements of `kind` (`SCALAR`, `VEC3`, …).
    pub(crate) fn floats(
        &mut self,
        values: &[f32],
        kind: &str,
        count: usize,
        target: Option<u32>,
    ) -> usize {
        let data: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        self.add(
            data.as_slice(),
            target,
            json!({"componentType": FLOAT, "count": count, "type": kind}),
        )
    }

    fn vec3s(&mut self, values: &[Vec3], target: Option<u32>, bounds: bool) -> usize {
        let flat: Vec<f32> = values.iter().flat_map(|v| v.to_array()).collect();
        let i = self.floats(&flat, "VEC3", values.len(), target);
        if bounds {
            let min = values
                .iter()
                .fold(Vec3::splat(f32::INFINITY), |a, &b| a.min(b));
            let max = values
                .iter()
                .fold(Vec3::splat(f32::NEG_INFINITY), |a, &b| a.max(b));
            self.accessors[i]["min"] = json!(min.to_array());
            self.accessors[i]["max"] = json!(max.to_array());
        }
        i
    }
}

/// The `.glb` of the mannequin on `skeleton` playing `frames` ((time, pose) in time order).
pub fn write(skeleton: &Skeleton, frames: &[(f64, &Pose)]) -> Vec<u8> {
    write_scene(skeleton, &[("", frames)])
}

/// The `.glb` of a scene of characters `(id, frames)`, each the mannequin on `skeleton` playing
/// its frames (every character's at the same times, in time order) in one animation. With more
/// than one, each character's nodes are named `ID/joint` and its mesh node `ID`.
pub fn write_scene(skeleton: &Skeleton, characters: &[(&str, &[(f64, &Pose)])]) -> Vec<u8> {
    let mut buf = Buffer::default();
    let primitives = mannequin_primitives(skeleton, &mut buf);
    // the skins: every joint, bound at its rest position
    let rest = Pose::rest(skeleton).world(skeleton).positions;
    let inverse_bind: Vec<f32> = (rest.iter())
        .flat_map(|&p| Mat4::from_translation(-p).to_cols_array())
        .collect();
    let ibm = buf.floats(&inverse_bind, "MAT4", skeleton.len(), None);
    let (mut nodes, mut roots, mut skins) = (Vec::new(), Vec::new(), Vec::new());
    let mut animation = Animation::default();
    for (k, (id, frames)) in characters.iter().enumerate() {
        let base = nodes.len();
        let prefix = if characters.len() > 1 {
            format!("{id}/")
        } else {
            String::new()
        };
        nodes.extend(joint_nodes(skeleton, base, &prefix));
        let name = if prefix.is_empty() { "mannequin" } else { id };
        nodes.push(json!({"name": name, "mesh": 0, "skin": k}));
        roots.extend([base, base + skeleton.len()]);
        skins.push(json!({
            "joints": (base..base + skeleton.len()).collect::<Vec<_>>(),
            "inverseBindMatrices": ibm,
            "skeleton": base,
        }));
        animation.add(skeleton, frames, base, &mut buf);
    }
    let gltf = json!({
        "asset": {"version": "2.0", "generator": concat!("bml-realizer ", env!("CARGO_PKG_VERSION"))},
        "scene": 0,
        "scenes": [{"nodes": roots}],
        "nodes": nodes,
        "meshes": [{"name": "mannequin", "primitives": primitives}],
        "materials": [
            {"name": "cloth", "pbrMetallicRoughness": {"baseColorFactor": [0.25, 0.33, 0.45, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.8}},
            {"name": "skin", "pbrMetallicRoughness": {"baseColorFactor": [0.86, 0.67, 0.55, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.6}},
        ],
        "skins": skins,
        "animations": animation.finish().into_iter().collect::<Vec<_>>(),
        "accessors": buf.accessors,
        "bufferViews": buf.views,
        "buffers": [{"byteLength": buf.bytes.len()}],
    });
    glb(
        &serde_json::to_vec(&gltf).expect("glTF JSON always encodes"),
        buf.bytes,
    )
}

/// The mannequin's mesh (a box along every bone, each vertex following its bone's joint) into
/// `buf`: its primitives, one per material.
fn mannequin_primitives(skeleton: &Skeleton, buf: &mut Buffer) -> Vec<Value> {
    let mut mesh = Mesh::default();
    for part in mannequin::segments(skeleton) {
        let (a, b) = (Vec3::from(part.from), Vec3::from(part.to));
        mesh.bone(a, b, part.width, part.joint as u16, part.skin);
    }
    let position = buf.vec3s(&mesh.positions, Some(ARRAY_BUFFER), true);
    let normal = buf.vec3s(&mesh.normals, Some(ARRAY_BUFFER), false);
    let joint_data: Vec<u8> = (mesh.joints.iter())
        .flat_map(|&j| [j, 0, 0, 0])
        .flat_map(|j| j.to_le_bytes())
        .collect();
    let count = mesh.joints.len();
    let joint_acc = buf.add(
        &joint_data,
        Some(ARRAY_BUFFER),
        json!({"componentType": UNSIGNED_SHORT, "count": count, "type": "VEC4"}),
    );
    let weights: Vec<f32> = (0..count).flat_map(|_| [1.0, 0.0, 0.0, 0.0]).collect();
    let weight_acc = buf.floats(&weights, "VEC4", count, Some(ARRAY_BUFFER));
    (mesh.triangles.iter().enumerate())
        .filter(|(_, t)| !t.is_empty())
        .map(|(material, t)| {
            let data: Vec<u8> = t.iter().flat_map(|i| i.to_le_bytes()).collect();
            let indices = buf.add(
                &data,
                Some(ELEMENT_ARRAY_BUFFER),
                json!({"componentType": UNSIGNED_INT, "count": t.len(), "type": "SCALAR"}),
            );
            json!({
                "attributes": {"POSITION": position, "NORMAL": normal, "JOINTS_0": joint_acc, "WEIGHTS_0": weight_acc},
                "indices": indices,
                "material": material,
            })
        })
        .collect()
}

/// The joint nodes of one character, numbered from `base`, named with `prefix`.
fn joint_nodes(skeleton: &Skeleton, base: usize, prefix: &str) -> Vec<Value> {
    let joints = skeleton.joints();
    (joints.iter().enumerate())
        .map(|(i, j)| {
            let children: Vec<usize> = (joints.iter().enumerate())
                .filter(|(_, c)| c.parent == Some(i))
                .map(|(k, _)| base + k)
                .collect();
            let name = format!("{prefix}{}", j.name);
            let mut node = json!({"name": name, "translation": j.offset.to_array()});
            if !children.is_empty() {
                node["children"] = json!(children);
            }
            node
        })
        .collect()
}

/// The one animation of a scene, built a character at a time.
#[derive(Default)]
struct Animation {
    /// The key times' accessor, shared by every character (all are keyed at the same times).
    input: Option<usize>,
    samplers: Vec<Value>,
    channels: Vec<Value>,
}

impl Animation {
    /// One rotation channel per joint and the root's translation of the character whose nodes
    /// start at `base`; nothing without frames.
    fn add(&mut self, skeleton: &Skeleton, frames: &[(f64, &Pose)], base: usize, buf: &mut Buffer) {
        let (Some(first), Some(last)) = (frames.first(), frames.last()) else {
            return;
        };
        let input = *self.input.get_or_insert_with(|| {
            let times: Vec<f32> = frames.iter().map(|(t, _)| (*t - first.0) as f32).collect();
            let input = buf.floats(&times, "SCALAR", times.len(), None);
            buf.accessors[input]["min"] = json!([0.0]);
            buf.accessors[input]["max"] = json!([(last.0 - first.0) as f32]);
            input
        });
        for j in 0..skeleton.len() {
            // the shorter way between neighbouring keys (q and -q are one rotation)
            let mut prev = Quat::IDENTITY;
            let rotations: Vec<f32> = (frames.iter())
                .flat_map(|(_, p)| {
                    let q = p.rotations[j].normalize();
                    let q = if q.dot(prev) < 0.0 { -q } else { q };
                    prev = q;
                    q.to_array()
                })
                .collect();
            let output = buf.floats(&rotations, "VEC4", frames.len(), None);
            self.channel(input, output, base + j, "rotation");
        }
        let root: Vec<Vec3> = frames.iter().map(|(_, p)| p.root).collect();
        let output = buf.vec3s(&root, None, false);
        self.channel(input, output, base, "translation");
    }

    fn channel(&mut self, input: usize, output: usize, node: usize, path: &str) {
        self.samplers
            .push(json!({"input": input, "output": output, "interpolation": "LINEAR"}));
        self.channels.push(
            json!({"sampler": self.samplers.len() - 1, "target": {"node": node, "path": path}}),
        );
    }

    /// The animation, if any character had frames.
    fn finish(self) -> Option<Value> {
        (!self.channels.is_empty()).then(
            || json!({"name": "realized", "samplers": self.samplers, "channels": self.channels}),
        )
    }
}

/// The GLB container: header, JSON chunk (padded with spaces), binary chunk (padded with zeros;
/// left out when there is no binary data).
pub(crate) fn glb(json: &[u8], mut bin: Vec<u8>) -> Vec<u8> {
    let mut json = json.to_vec();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let bin_chunk = if bin.is_empty() { 0 } else { 8 + bin.len() };
    let total = 12 + 8 + json.len() + bin_chunk;
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json);
    if !bin.is_empty() {
        out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
        out.extend_from_slice(b"BIN\0");
        out.extend_from_slice(&bin);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_glb_has_its_header_chunks_and_one_channel_per_joint() {
        let s = Skeleton::adult();
        let rest = Pose::rest(&s);
        let glb = write(&s, &[(0.0, &rest), (0.5, &rest)]);
        assert_eq!(&glb[0..4], b"glTF");
        assert_eq!(
            u32::from_le_bytes(glb[8..12].try_into().unwrap()) as usize,
            glb.len()
        );
        let json_len = u32::from_le_bytes(glb[12..16].try_into().unwrap()) as usize;
        let gltf: Value = serde_json::from_slice(&glb[20..20 + json_len]).unwrap();
        assert_eq!(gltf["nodes"].as_array().unwrap().len(), s.len() + 1);
        let channels = gltf["animations"][0]["channels"].as_array().unwrap();
        assert_eq!(channels.len(), s.len() + 1);
        assert_eq!(gltf["materials"].as_array().unwrap().len(), 2);
    }

    #[test]
    fn a_scene_has_each_character_s_nodes_skin_and_channels() {
        let s = Skeleton::adult();
        let rest = Pose::rest(&s);
        let frames = [(0.0, &rest), (0.5, &rest)];
        let glb = write_scene(&s, &[("Alice", &frames), ("Bob", &frames)]);
        let json_len = u32::from_le_bytes(glb[12..16].try_into().unwrap()) as usize;
        let gltf: Value = serde_json::from_slice(&glb[20..20 + json_len]).unwrap();
        let n = s.len();
        assert_eq!(gltf["nodes"].as_array().unwrap().len(), 2 * (n + 1));
        assert_eq!(
            gltf["nodes"][n + 1]["name"],
            format!("Bob/{}", s.joints()[0].name)
        );
        assert_eq!(gltf["nodes"][2 * n + 1]["skin"], 1);
        assert_eq!(gltf["skins"][1]["joints"][0], n + 1);
        assert_eq!(gltf["scenes"][0]["nodes"], json!([0, n, n + 1, 2 * n + 1]));
        let channels = gltf["animations"][0]["channels"].as_array().unwrap();
        assert_eq!(channels.len(), 2 * (n + 1));
        assert_eq!(channels[n + 1]["target"]["node"], n + 1);
        // one set of key times for both
        let samplers = gltf["animations"][0]["samplers"].as_array().unwrap();
        assert_eq!(samplers[0]["input"], samplers[n + 1]["input"]);
    }
}
