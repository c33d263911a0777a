//! An avatar with the realizer's motion, as one binary glTF: the avatar's own file (its JSON
//! and binary buffer as read, node names and extensions kept) with one animation added — the
//! local rotation of every bone that follows a realizer joint, the translation of the node that
//! carries the root's travel, and the weights of every morph target the face drives — sampled
//! at the frames' times (linear interpolation between them).

use serde_json::{json, Value};

use super::file::Model;
use super::morph::MorphMap;
use super::retarget::Retarget;
use crate::body::pose::Pose;
use crate::body::skeleton::Skeleton;
use crate::face::model::Face;

const FLOAT: u32 = 5126;

/// One frame of a character: when, its pose, its face.
#[derive(Debug, Clone, Copy)]
pub struct Frame<'a> {
    /// The frame's time (s).
    pub time: f64,
    /// The character's pose.
    pub pose: &'a Pose,
    /// The character's face.
    pub face: &'a Face,
}

/// The file's JSON and binary buffer, growing.
struct Out {
    json: Value,
    bin: Vec<u8>,
}

impl Out {
    /// Appends `data` as a buffer view and `accessor` into it; the accessor's index.
    fn push(&mut self, data: &[u8], mut accessor: Value) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let view = json!({"buffer": 0, "byteOffset": self.bin.len(), "byteLength": data.len()});
        self.bin.extend_from_slice(data);
        accessor["bufferView"] = json!(push(&mut self.json, "bufferViews", view));
        push(&mut self.json, "accessors", accessor)
    }

    /// Appends the floats `values` as an accessor of `kind` (`SCALAR`, `VEC3`, `VEC4`).
    fn floats(&mut self, values: &[f32], kind: &str, count: usize, bounds: bool) -> usize {
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        let mut accessor = json!({"componentType": FLOAT, "count": count, "type": kind});
        if bounds {
            let (lo, hi) = values
                .iter()
                .fold((f32::MAX, f32::MIN), |(l, h), &v| (l.min(v), h.max(v)));
            accessor["min"] = json!([lo]);
            accessor["max"] = json!([hi]);
        }
        self.push(&bytes, accessor)
    }
}

/// Appends `item` to the array `key` of `json` (made when absent); its index.
fn push(json: &mut Value, key: &str, item: Value) -> usize {
    if !json[key].is_array() {
        json[key] = json!([]);
    }
    let list = json[key].as_array_mut().expect("made an array above");
    list.push(item);
    list.len() - 1
}

/// The avatar `model` moving as `frames` of `skeleton` say, as GLB bytes; the animation is
/// named `name`.
pub fn animated_glb(
    model: &Model,
    retarget: &Retarget,
    skeleton: &Skeleton,
    frames: &[Frame<'_>],
    name: &str,
) -> Vec<u8> {
    let mut out = Out {
        json: model.json.clone(),
        bin: model.bin.clone(),
    };
    if !frames.is_empty() {
        animate(&mut out, model, retarget, skeleton, frames, name);
    }
    glb(out)
}

fn animate(
    out: &mut Out,
    model: &Model,
    retarget: &Retarget,
    skeleton: &Skeleton,
    frames: &[Frame<'_>],
    name: &str,
) {
    let bones: Vec<usize> = (0..model.nodes.len())
        .filter(|&i| retarget.source(i).is_some())
        .collect();
    let mut turns: Vec<Vec<f32>> = vec![Vec::with_capacity(4 * frames.len()); bones.len()];
    let mut travel = Vec::with_capacity(3 * frames.len());
    let mut hips = 0;
    for f in frames {
        let posed = retarget.pose(skeleton, f.pose);
        for (k, &b) in bones.iter().enumerate() {
            turns[k].extend(posed.rotations[b].to_array());
        }
        hips = posed.hips.0;
        travel.extend(posed.hips.1.to_array());
    }
    let times: Vec<f32> = frames.iter().map(|f| f.time as f32).collect();
    let input = out.floats(&times, "SCALAR", times.len(), true);
    let (mut samplers, mut channels) = (Vec::new(), Vec::new());
    let mut channel = |node: usize, path: &str, output: usize| {
        samplers.push(json!({"input": input, "output": output, "interpolation": "LINEAR"}));
        channels.push(json!({"sampler": samplers.len() - 1,
                             "target": {"node": node, "path": path}}));
    };
    for (k, &b) in bones.iter().enumerate() {
        let output = out.floats(&turns[k], "VEC4", frames.len(), false);
        channel(b, "rotation", output);
    }
    let output = out.floats(&travel, "VEC3", frames.len(), false);
    channel(hips, "translation", output);
    let morphs = MorphMap::new(model);
    let mut weights = Vec::new();
    for (k, (node, targets)) in morphs.nodes().enumerate() {
        let mut all = Vec::with_capacity(targets * frames.len());
        for f in frames {
            morphs.weights(k, f.face, &mut weights);
            all.extend_from_slice(&weights);
        }
        let output = out.floats(&all, "SCALAR", all.len(), false);
        channel(node, "weights", output);
    }
    push(
        &mut out.json,
        "animations",
        json!({"name": name, "samplers": samplers, "channels": channels}),
    );
}

/// The GLB container of `out`.
fn glb(mut out: Out) -> Vec<u8> {
    while !out.bin.len().is_multiple_of(4) {
        out.bin.push(0);
    }
    if !out.bin.is_empty() {
        if !out.json["buffers"].is_array()
            || out.json["buffers"].as_array().is_some_and(Vec::is_empty)
        {
            out.json["buffers"] = json!([{}]);
        }
        let buffer = &mut out.json["buffers"][0];
        if let Some(b) = buffer.as_object_mut() {
            b.remove("uri");
        }
        buffer["byteLength"] = json!(out.bin.len());
    }
    let mut text = serde_json::to_vec(&out.json).expect("a JSON value serialises");
    while !text.len().is_multiple_of(4) {
        text.push(b' ');
    }
    let bin_chunk = if out.bin.is_empty() {
        0
    } else {
        8 + out.bin.len()
    };
    let total = 12 + 8 + text.len() + bin_chunk;
    let mut bytes = Vec::with_capacity(total);
    for word in [
        0x4654_6C67u32,
        2,
        total as u32,
        text.len() as u32,
        0x4E4F_534A,
    ] {
        bytes.extend(word.to_le_bytes());
    }
    bytes.extend(text);
    if !out.bin.is_empty() {
        bytes.extend((out.bin.len() as u32).to_le_bytes());
        bytes.extend(0x004E_4942u32.to_le_bytes());
        bytes.extend(out.bin);
    }
    bytes
}
