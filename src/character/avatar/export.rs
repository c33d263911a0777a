//! An avatar with the realizer's motion, as one binary glTF: the avatar's own file (its JSON
//! and binary buffer as read, node names and extensions kept) with one animation added before
//! the file's own (viewers play the first) — the
//! local rotation of every bone that follows a realizer joint, the translation of the node that
//! carries the root's travel, and the weights of every morph target the face drives — sampled
//! at the frames' times (linear interpolation between them). An avatar made facing another way
//! than the realizer's characters (a VRM 0.x faces −z, CesiumMan +x) stands in the realizer's
//! world under one node more that turns it (see [`stand`]).

use serde_json::{json, Value};

use super::file::Model;
use super::morph::{Look, MorphMap};
use super::retarget::Retarget;
use crate::character::body::gltf::{glb, Buffer};
use crate::character::body::pose::Pose;
use crate::character::face::model::Face;

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

/// The avatar `model` moving as `frames` say, as GLB bytes; the animation is
/// named `name`.
pub fn animated_glb(
    model: &Model,
    retarget: &Retarget,
    frames: &[Frame<'_>],
    name: &str,
) -> Vec<u8> {
    let (json, bin) = animated_document(model, retarget, frames, name);
    let text = serde_json::to_vec(&json).expect("a JSON value serialises");
    glb(&text, bin)
}

/// The avatar `model` moving as `frames` say: its glTF JSON and binary buffer (buffer 0).
pub fn animated_document(
    model: &Model,
    retarget: &Retarget,
    frames: &[Frame<'_>],
    name: &str,
) -> (Value, Vec<u8>) {
    let mut json = model.json.clone();
    // the file's own buffer, views and accessors, the animation's appended to them
    let mut take = |key: &str| match json.as_object_mut().and_then(|o| o.remove(key)) {
        Some(Value::Array(a)) => a,
        _ => Vec::new(),
    };
    let mut buf = Buffer {
        bytes: model.bin.clone(),
        views: take("bufferViews"),
        accessors: take("accessors"),
    };
    stand(&mut json, retarget.stand());
    if !frames.is_empty() {
        let animation = animation(&mut buf, model, retarget, frames, name);
        // first, before the file's own: what viewers play unless told otherwise
        match json["animations"].as_array_mut() {
            Some(list) => list.insert(0, animation),
            None => json["animations"] = json!([animation]),
        }
    }
    if !buf.bytes.is_empty() {
        while !buf.bytes.len().is_multiple_of(4) {
            buf.bytes.push(0);
        }
        // the GLB's binary chunk is buffer 0 (a .gltf's file buffer becomes it)
        if json["buffers"].as_array().is_none_or(Vec::is_empty) {
            json["buffers"] = json!([{}]);
        }
        let buffer = &mut json["buffers"][0];
        if let Some(b) = buffer.as_object_mut() {
            b.remove("uri");
        }
        buffer["byteLength"] = json!(buf.bytes.len());
    }
    if !buf.views.is_empty() {
        json["bufferViews"] = Value::Array(buf.views);
        json["accessors"] = Value::Array(buf.accessors);
    }
    (json, buf.bytes)
}

/// Turns the avatar of document `json` by `turn` into the realizer's world: a node named
/// `realizer frame` with that rotation over the default scene's roots (see [`hang_roots`]).
/// Nothing changes when the avatar already faces the realizer's way.
fn stand(json: &mut Value, turn: glam::Quat) {
    if turn.angle_between(glam::Quat::IDENTITY) < 1e-4 {
        return;
    }
    let scene = json["scene"].as_u64().unwrap_or(0) as usize;
    let roots: Vec<usize> = (json["scenes"][scene]["nodes"]
        .as_array()
        .into_iter()
        .flatten())
    .filter_map(|n| Some(n.as_u64()? as usize))
    .collect();
    let Some(nodes) = json["nodes"].as_array_mut() else {
        return;
    };
    let node = json!({"name": "realizer frame", "rotation": turn.to_array()});
    let roots = hang_roots(nodes, &roots, node);
    json["scenes"][scene]["nodes"] = json!(roots);
}

/// Appends `node` to `nodes` as the parent of the scene's `roots`, but for skinned meshes,
/// which glTF wants at the root (a skinned mesh ignores its parents' transforms: its joints
/// carry them); returns the scene's new roots: the skinned meshes, then `node`. Every node
/// keeps its index.
pub(super) fn hang_roots(nodes: &mut Vec<Value>, roots: &[usize], mut node: Value) -> Vec<usize> {
    let (mut skinned, children): (Vec<usize>, Vec<usize>) =
        (roots.iter()).partition(|&&n| nodes.get(n).is_some_and(|node| node.get("skin").is_some()));
    node["children"] = json!(children);
    skinned.push(nodes.len());
    nodes.push(node);
    skinned
}

/// The animation of `frames` on `model`, its keys appended to `buf`.
fn animation(
    buf: &mut Buffer,
    model: &Model,
    retarget: &Retarget,
    frames: &[Frame<'_>],
    name: &str,
) -> Value {
    let bones: Vec<usize> = (0..model.nodes.len())
        .filter(|&i| retarget.moves(i))
        .collect();
    let mut turns: Vec<Vec<f32>> = vec![Vec::with_capacity(4 * frames.len()); bones.len()];
    let mut travel = Vec::with_capacity(3 * frames.len());
    for f in frames {
        let posed = retarget.pose(f.pose);
        for (k, &b) in bones.iter().enumerate() {
            turns[k].extend(posed.rotations[b].to_array());
        }
        travel.extend(posed.hips.1.to_array());
    }
    let times: Vec<f32> = frames.iter().map(|f| f.time as f32).collect();
    let input = buf.floats(&times, "SCALAR", times.len(), None);
    let (first, last) = (times[0], times[times.len() - 1]);
    buf.accessors[input]["min"] = json!([first]);
    buf.accessors[input]["max"] = json!([last]);
    let (mut samplers, mut channels) = (Vec::new(), Vec::new());
    let mut channel = |node: usize, path: &str, output: usize| {
        samplers.push(json!({"input": input, "output": output, "interpolation": "LINEAR"}));
        channels.push(json!({"sampler": samplers.len() - 1,
                             "target": {"node": node, "path": path}}));
    };
    for (k, &b) in bones.iter().enumerate() {
        let output = buf.floats(&turns[k], "VEC4", frames.len(), None);
        channel(b, "rotation", output);
    }
    let output = buf.floats(&travel, "VEC3", frames.len(), None);
    channel(retarget.hips(), "translation", output);
    let morphs = MorphMap::new(model);
    let mut weights = Vec::new();
    for (k, (node, targets)) in morphs.nodes().enumerate() {
        let mut all = Vec::with_capacity(targets * frames.len());
        for f in frames {
            let look = Look::of(f.pose, retarget.eyes());
            morphs.weights(k, f.face, look, &mut weights);
            all.extend_from_slice(&weights);
        }
        let output = buf.floats(&all, "SCALAR", all.len(), None);
        channel(node, "weights", output);
    }
    json!({"name": name, "samplers": samplers, "channels": channels})
}

#[cfg(test)]
mod tests {
    use super::*;

    fn document() -> Value {
        json!({
            "scene": 0,
            "scenes": [{"nodes": [0, 1]}],
            "nodes": [{"name": "hips", "children": [2]}, {"name": "body", "mesh": 0, "skin": 0},
                      {"name": "spine"}],
        })
    }

    #[test]
    fn an_avatar_facing_another_way_stands_under_one_turned_node() {
        let mut json = document();
        let half = glam::Quat::from_rotation_y(std::f32::consts::PI);
        stand(&mut json, half);
        // appended, so that every node keeps its index; the skinned mesh stays at the root
        assert_eq!(json["nodes"][3]["name"], "realizer frame");
        assert_eq!(json["nodes"][3]["children"], json!([0]));
        assert_eq!(json["scenes"][0]["nodes"], json!([1, 3]));
        let turn: Vec<f32> = (json["nodes"][3]["rotation"].as_array().unwrap().iter())
            .map(|x| x.as_f64().unwrap() as f32)
            .collect();
        let turn = glam::Quat::from_slice(&turn);
        assert!(turn.angle_between(half) < 1e-6, "{turn:?}");
        // one already facing the realizer's way is left as it is
        let mut same = document();
        stand(&mut same, glam::Quat::IDENTITY);
        assert_eq!(same, document());
    }
}
