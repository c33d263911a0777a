//! glTF 2.0 export (`bmlr run --gltf OUT.glb`): the skinned mannequin of [`mannequin`] — a box
//! along every bone, a box head, two materials (skin for the head and hands, cloth for the
//! rest) — and the realized motion as animation channels (every joint's rotation, the root's
//! translation), in one binary `.glb` file for Blender, three.js or a game engine. Each vertex
//! follows one joint (the one whose bone it belongs to), so the mannequin moves rigidly per bone.

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

/// The binary buffer and the accessors into it.
#[derive(Default)]
struct Buffer {
    bytes: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
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

    fn floats(&mut self, values: &[f32], kind: &str, count: usize, target: Option<u32>) -> usize {
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
    let joints = skeleton.joints();
    let rest = Pose::rest(skeleton).world(skeleton).positions;
    let mut mesh = Mesh::default();
    for part in mannequin::segments(skeleton) {
        let (a, b) = (Vec3::from(part.from), Vec3::from(part.to));
        mesh.bone(a, b, part.width, part.joint as u16, part.skin);
    }
    let mut buf = Buffer::default();
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
    let primitives: Vec<Value> = (mesh.triangles.iter().enumerate())
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
        .collect();
    // the skin: every joint, bound at its rest position
    let inverse_bind: Vec<f32> = (rest.iter())
        .flat_map(|&p| Mat4::from_translation(-p).to_cols_array())
        .collect();
    let ibm = buf.floats(&inverse_bind, "MAT4", joints.len(), None);
    let animation = animation(skeleton, frames, &mut buf);
    let nodes: Vec<Value> = joints
        .iter()
        .enumerate()
        .map(|(i, j)| {
            let children: Vec<usize> = (joints.iter().enumerate())
                .filter(|(_, c)| c.parent == Some(i))
                .map(|(k, _)| k)
                .collect();
            let mut node = json!({"name": j.name, "translation": j.offset.to_array()});
            if !children.is_empty() {
                node["children"] = json!(children);
            }
            node
        })
        .chain([json!({"name": "mannequin", "mesh": 0, "skin": 0})])
        .collect();
    let gltf = json!({
        "asset": {"version": "2.0", "generator": concat!("bml-realizer ", env!("CARGO_PKG_VERSION"))},
        "scene": 0,
        "scenes": [{"nodes": [0, joints.len()]}],
        "nodes": nodes,
        "meshes": [{"name": "mannequin", "primitives": primitives}],
        "materials": [
            {"name": "cloth", "pbrMetallicRoughness": {"baseColorFactor": [0.25, 0.33, 0.45, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.8}},
            {"name": "skin", "pbrMetallicRoughness": {"baseColorFactor": [0.86, 0.67, 0.55, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.6}},
        ],
        "skins": [{"joints": (0..joints.len()).collect::<Vec<_>>(), "inverseBindMatrices": ibm, "skeleton": 0}],
        "animations": animation.into_iter().collect::<Vec<_>>(),
        "accessors": buf.accessors,
        "bufferViews": buf.views,
        "buffers": [{"byteLength": buf.bytes.len()}],
    });
    glb(
        &serde_json::to_vec(&gltf).expect("glTF JSON always encodes"),
        buf.bytes,
    )
}

/// The animation of `frames`: one rotation channel per joint and the root's translation; `None`
/// without frames.
fn animation(skeleton: &Skeleton, frames: &[(f64, &Pose)], buf: &mut Buffer) -> Option<Value> {
    let (first, last) = (frames.first()?.0, frames.last()?.0);
    let times: Vec<f32> = frames.iter().map(|(t, _)| (*t - first) as f32).collect();
    let input = buf.floats(&times, "SCALAR", times.len(), None);
    buf.accessors[input]["min"] = json!([0.0]);
    buf.accessors[input]["max"] = json!([(last - first) as f32]);
    let mut samplers = Vec::new();
    let mut channels = Vec::new();
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
        samplers.push(json!({"input": input, "output": output, "interpolation": "LINEAR"}));
        channels.push(
            json!({"sampler": samplers.len() - 1, "target": {"node": j, "path": "rotation"}}),
        );
    }
    let root: Vec<Vec3> = frames.iter().map(|(_, p)| p.root).collect();
    let output = buf.vec3s(&root, None, false);
    samplers.push(json!({"input": input, "output": output, "interpolation": "LINEAR"}));
    channels
        .push(json!({"sampler": samplers.len() - 1, "target": {"node": 0, "path": "translation"}}));
    Some(json!({"name": "realized", "samplers": samplers, "channels": channels}))
}

/// The GLB container: header, JSON chunk (padded with spaces), binary chunk (padded with zeros).
fn glb(json: &[u8], mut bin: Vec<u8>) -> Vec<u8> {
    let mut json = json.to_vec();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&bin);
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
}
