//! Test avatars built here, as small GLBs without meshes: a Mixamo-named T-pose in centimetres
//! under a turned armature, a VRM 1.0 in an A-pose with every bone's axes turned at random, no
//! upper chest and forearm twist bones, a VRM 0.x in a T-pose facing −z. Shared by `tests/avatar.rs` and
//! `tests/avatar_cli.rs`.

#![allow(dead_code)]

use std::f32::consts::{FRAC_PI_2, FRAC_PI_4, PI};

use bml_realizer::character::avatar::{Model, Retarget};
use bml_realizer::character::body::pose::Pose;
use bml_realizer::character::body::skeleton::Skeleton;
use bml_realizer::rng::Rng;
use glam::{Mat4, Quat, Vec3};
use serde_json::{json, Value};

/// A test avatar's bones: (bone as VRM 1.0 names it, where it sits: a realizer joint, its
/// parent bone, its Mixamo name).
pub const BONES: &[(&str, &str, &str, &str)] = &[
    ("hips", "sacroiliac", "", "Hips"),
    ("spine", "vl5", "hips", "Spine"),
    ("chest", "vt12", "spine", "Spine1"),
    ("upperChest", "vt6", "chest", "Spine2"),
    ("neck", "vc7", "upperChest", "Neck"),
    ("head", "skullbase", "neck", "Head"),
    (
        "leftShoulder",
        "l_sternoclavicular",
        "upperChest",
        "LeftShoulder",
    ),
    ("leftUpperArm", "l_shoulder", "leftShoulder", "LeftArm"),
    ("leftLowerArm", "l_elbow", "leftUpperArm", "LeftForeArm"),
    ("leftHand", "l_wrist", "leftLowerArm", "LeftHand"),
    (
        "leftThumbMetacarpal",
        "l_thumb1",
        "leftHand",
        "LeftHandThumb1",
    ),
    (
        "leftThumbProximal",
        "l_thumb2",
        "leftThumbMetacarpal",
        "LeftHandThumb2",
    ),
    (
        "leftThumbDistal",
        "l_thumb3",
        "leftThumbProximal",
        "LeftHandThumb3",
    ),
    (
        "leftIndexProximal",
        "l_index1",
        "leftHand",
        "LeftHandIndex1",
    ),
    (
        "leftIndexIntermediate",
        "l_index2",
        "leftIndexProximal",
        "LeftHandIndex2",
    ),
    (
        "leftIndexDistal",
        "l_index3",
        "leftIndexIntermediate",
        "LeftHandIndex3",
    ),
    (
        "leftMiddleProximal",
        "l_middle1",
        "leftHand",
        "LeftHandMiddle1",
    ),
    (
        "leftMiddleIntermediate",
        "l_middle2",
        "leftMiddleProximal",
        "LeftHandMiddle2",
    ),
    (
        "rightShoulder",
        "r_sternoclavicular",
        "upperChest",
        "RightShoulder",
    ),
    ("rightUpperArm", "r_shoulder", "rightShoulder", "RightArm"),
    ("rightLowerArm", "r_elbow", "rightUpperArm", "RightForeArm"),
    ("rightHand", "r_wrist", "rightLowerArm", "RightHand"),
    (
        "rightMiddleProximal",
        "r_middle1",
        "rightHand",
        "RightHandMiddle1",
    ),
    (
        "rightMiddleIntermediate",
        "r_middle2",
        "rightMiddleProximal",
        "RightHandMiddle2",
    ),
    ("leftUpperLeg", "l_hip", "hips", "LeftUpLeg"),
    ("leftLowerLeg", "l_knee", "leftUpperLeg", "LeftLeg"),
    ("leftFoot", "l_talocrural", "leftLowerLeg", "LeftFoot"),
    ("leftToes", "l_metatarsal", "leftFoot", "LeftToeBase"),
    ("rightUpperLeg", "r_hip", "hips", "RightUpLeg"),
    ("rightLowerLeg", "r_knee", "rightUpperLeg", "RightLeg"),
    ("rightFoot", "r_talocrural", "rightLowerLeg", "RightFoot"),
    ("rightToes", "r_metatarsal", "rightFoot", "RightToeBase"),
];

/// The limb bones checked, each with the bone it points at.
pub const LIMBS: &[(&str, &str)] = &[
    ("leftUpperArm", "leftLowerArm"),
    ("leftLowerArm", "leftHand"),
    ("leftHand", "leftMiddleProximal"),
    ("leftIndexProximal", "leftIndexIntermediate"),
    ("leftIndexIntermediate", "leftIndexDistal"),
    ("leftThumbMetacarpal", "leftThumbProximal"),
    ("leftMiddleProximal", "leftMiddleIntermediate"),
    ("rightUpperArm", "rightLowerArm"),
    ("rightLowerArm", "rightHand"),
    ("rightHand", "rightMiddleProximal"),
    ("leftUpperLeg", "leftLowerLeg"),
    ("leftLowerLeg", "leftFoot"),
    ("leftFoot", "leftToes"),
    ("rightUpperLeg", "rightLowerLeg"),
    ("rightLowerLeg", "rightFoot"),
    ("rightFoot", "rightToes"),
];

/// The VRM 1.0 avatar's arm twist bones: (name, parent node, the limb segment's bone, share of
/// the way along the segment).
pub const TWISTS: &[(&str, &str, &str, f32)] = &[
    ("J_leftLowerArmTwist1", "leftLowerArm", "leftLowerArm", 0.5),
    (
        "J_leftLowerArmTwist2",
        "J_leftLowerArmTwist1",
        "leftLowerArm",
        0.9,
    ),
    ("lowerarm_twist_01_r", "rightLowerArm", "rightLowerArm", 0.3),
    ("upperarm_twist_01_l", "leftUpperArm", "leftUpperArm", 0.0),
    (
        "upperarm_twist_02_l",
        "upperarm_twist_01_l",
        "leftUpperArm",
        0.5,
    ),
    ("J_rightUpperArmRoll", "rightUpperArm", "rightUpperArm", 0.6),
];

/// A twisting limb segment of [`TWISTS`]: the bone at its end, the realizer's joints at its
/// start and end (without side), the joint whose twist its twist bones share and the share its
/// own bone keeps (the forearm none of the wrist's, the upper arm all of the shoulder's).
pub fn twist_segment(bone: &str) -> (String, &'static str, &'static str, &'static str, f32) {
    if bone.contains("LowerArm") {
        (
            bone.replace("LowerArm", "Hand"),
            "elbow",
            "wrist",
            "wrist",
            0.0,
        )
    } else {
        let end = bone.replace("UpperArm", "LowerArm");
        (end, "shoulder", "elbow", "shoulder", 1.0)
    }
}

#[derive(Clone, Copy, PartialEq)]
pub enum Kind {
    /// Mixamo names, T-pose, centimetres under an armature turned a quarter about x.
    Mixamo,
    /// VRM 1.0, A-pose, bones' axes turned at random, no upper chest.
    Vrm1,
    /// VRM 0.x, T-pose, facing −z.
    Vrm0,
}

/// A GLB holding `json` alone.
pub fn glb(json: &Value) -> Vec<u8> {
    glb_with(json, &[])
}

/// A GLB of `json` and its binary buffer.
pub fn glb_with(json: &Value, bin: &[u8]) -> Vec<u8> {
    let mut text = serde_json::to_vec(json).unwrap();
    while !text.len().is_multiple_of(4) {
        text.push(b' ');
    }
    let mut bin = bin.to_vec();
    bin.resize(bin.len().next_multiple_of(4), 0);
    let total = 12 + 8 + text.len() + if bin.is_empty() { 0 } else { 8 + bin.len() };
    let mut out = Vec::new();
    for word in [
        0x4654_6C67u32,
        2,
        total as u32,
        text.len() as u32,
        0x4E4F_534A,
    ] {
        out.extend(word.to_le_bytes());
    }
    out.extend(text);
    if !bin.is_empty() {
        out.extend((bin.len() as u32).to_le_bytes());
        out.extend(0x004E_4942u32.to_le_bytes());
        out.extend(bin);
    }
    out
}

/// The floats of accessor `a` of a GLB whose JSON is `json` (tightly packed, as the export
/// writes them): count × the components of its type.
pub fn floats_of(bytes: &[u8], json: &Value, a: usize) -> Vec<f32> {
    let length = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    let bin = &bytes[20 + length + 8..];
    let acc = &json["accessors"][a];
    let view = &json["bufferViews"][acc["bufferView"].as_u64().unwrap() as usize];
    let at = |key: &str, v: &Value| v[key].as_u64().unwrap_or(0) as usize;
    let start = at("byteOffset", view) + at("byteOffset", acc);
    let components = match acc["type"].as_str().unwrap() {
        "SCALAR" => 1,
        "VEC2" => 2,
        "VEC3" => 3,
        _ => 4,
    };
    (0..at("count", acc) * components)
        .map(|k| f32::from_le_bytes(bin[start + 4 * k..start + 4 * k + 4].try_into().unwrap()))
        .collect()
}

/// The JSON chunk of a GLB.
pub fn glb_json(bytes: &[u8]) -> Value {
    let length = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    serde_json::from_slice(&bytes[20..20 + length]).unwrap()
}

pub fn random_rotation(rng: &mut Rng, most: f32) -> Quat {
    let axis = Vec3::new(
        rng.next_f32() - 0.5,
        rng.next_f32() - 0.5,
        rng.next_f32() - 0.5,
    )
    .normalize_or(Vec3::Y);
    Quat::from_axis_angle(axis, (rng.next_f32() * 2.0 - 1.0) * most)
}

/// A test avatar of `kind`: its GLB bytes.
pub fn test_avatar(kind: Kind) -> Vec<u8> {
    let skeleton = Skeleton::adult();
    let mut pose = Pose::rest(&skeleton);
    let arms = if kind == Kind::Vrm1 {
        FRAC_PI_4
    } else {
        FRAC_PI_2
    };
    pose.rotate(
        skeleton.joint("l_shoulder").unwrap(),
        Quat::from_rotation_z(arms),
    );
    pose.rotate(
        skeleton.joint("r_shoulder").unwrap(),
        Quat::from_rotation_z(-arms),
    );
    let places = pose.world(&skeleton).positions;
    let facing = if kind == Kind::Vrm0 {
        Quat::from_rotation_y(PI)
    } else {
        Quat::IDENTITY
    };
    // the armature: its world rotation and scale
    let (armature, scale) = match kind {
        Kind::Mixamo => (Quat::from_rotation_x(FRAC_PI_2), 0.01),
        _ => (Quat::IDENTITY, 1.0),
    };
    let mut rng = Rng(17);
    let bones: Vec<_> = BONES
        .iter()
        .filter(|b| !(kind == Kind::Vrm1 && b.0 == "chest"))
        .map(|&(bone, at, parent, mixamo)| {
            let parent = if kind == Kind::Vrm1 && parent == "chest" {
                "spine"
            } else {
                parent
            };
            (bone, at, parent, mixamo)
        })
        .collect();
    let index = |bone: &str| 1 + bones.iter().position(|b| b.0 == bone).unwrap();
    let mut world_rotation = vec![armature];
    let mut world_place = vec![Vec3::ZERO];
    let mut nodes = vec![json!({
        "name": "Armature",
        "rotation": armature.to_array(),
        "scale": [scale, scale, scale],
        "children": [1],
    })];
    for &(bone, at, parent, mixamo) in &bones {
        let w = facing * places[skeleton.joint(at).unwrap()];
        let g = match kind {
            Kind::Vrm1 => random_rotation(&mut rng, PI),
            _ => armature,
        };
        let p = if parent.is_empty() { 0 } else { index(parent) };
        let (gp, wp) = (world_rotation[p], world_place[p]);
        let s = if p == 0 { scale } else { 1.0 };
        let t = gp.inverse() * (w - wp) / s;
        let name = match kind {
            Kind::Mixamo => format!("mixamorig:{mixamo}"),
            _ => format!("J_{bone}"),
        };
        let children: Vec<usize> = bones
            .iter()
            .filter(|b| b.2 == bone)
            .map(|b| index(b.0))
            .collect();
        let mut node = json!({
            "name": name,
            "translation": t.to_array(),
            "rotation": (gp.inverse() * g).normalize().to_array(),
        });
        if !children.is_empty() {
            node["children"] = json!(children);
        }
        nodes.push(node);
        world_rotation.push(g);
        world_place.push(w);
    }
    if kind == Kind::Vrm1 {
        // arm twist bones: two chained on the left, one on the right, of each segment
        for &(name, parent, bone, share) in TWISTS {
            let p = match bones.iter().position(|b| b.0 == parent) {
                Some(k) => 1 + k,
                None => nodes.iter().position(|n| n["name"] == parent).unwrap(),
            };
            let (start, end) = (index(bone), index(&twist_segment(bone).0));
            let w = world_place[start].lerp(world_place[end], share);
            let g = random_rotation(&mut rng, PI);
            let (gp, wp) = (world_rotation[p], world_place[p]);
            let k = nodes.len();
            let mut children = nodes[p]["children"].as_array().cloned().unwrap_or_default();
            children.push(json!(k));
            nodes[p]["children"] = json!(children);
            nodes.push(json!({
                "name": name,
                "translation": (gp.inverse() * (w - wp)).to_array(),
                "rotation": (gp.inverse() * g).normalize().to_array(),
            }));
            world_rotation.push(g);
            world_place.push(w);
        }
    }
    let joints: Vec<usize> = (1..nodes.len()).collect();
    let mut doc = json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": nodes,
        "skins": [{"joints": joints}],
    });
    match kind {
        Kind::Vrm1 => {
            let map: serde_json::Map<String, Value> = bones
                .iter()
                .map(|b| (b.0.to_string(), json!({"node": index(b.0)})))
                .collect();
            doc["extensionsUsed"] = json!(["VRMC_vrm"]);
            doc["extensions"] = json!({"VRMC_vrm": {"specVersion": "1.0",
                                        "humanoid": {"humanBones": map}}});
        }
        Kind::Vrm0 => {
            let list: Vec<Value> = bones
                .iter()
                .map(|b| {
                    let name =
                        b.0.replace("ThumbProximal", "ThumbIntermediate")
                            .replace("ThumbMetacarpal", "ThumbProximal");
                    json!({"bone": name, "node": index(b.0)})
                })
                .collect();
            doc["extensionsUsed"] = json!(["VRM"]);
            doc["extensions"] = json!({"VRM": {"humanoid": {"humanBones": list}}});
        }
        Kind::Mixamo => {}
    }
    glb(&doc)
}

/// A random pose of the realizer: every joint turned up to `most` radians, the root moved and
/// turned.
pub fn random_pose(skeleton: &Skeleton, rng: &mut Rng, most: f32) -> Pose {
    let mut pose = Pose::rest(skeleton);
    for r in &mut pose.rotations {
        *r = random_rotation(rng, most);
    }
    pose.root += Vec3::new(
        rng.next_f32() * 4.0 - 2.0,
        rng.next_f32() * 0.3,
        rng.next_f32() * 4.0 - 2.0,
    );
    pose
}

/// The angles (degrees) between every limb bone of the posed avatar and its realizer bone.
pub fn limb_errors(
    model: &Model,
    retarget: &Retarget,
    skeleton: &Skeleton,
    pose: &Pose,
) -> Vec<f32> {
    let node_of = |bone: &str| {
        model.nodes.iter().position(|n| {
            n.name.ends_with(&format!("J_{bone}")) || {
                let m = BONES.iter().find(|b| b.0 == bone).unwrap().3;
                n.name == format!("mixamorig:{m}")
            }
        })
    };
    limb_errors_by(retarget, skeleton, pose, node_of)
}

/// The angles (degrees) between every limb bone (of [`LIMBS`], where `node_of` finds both
/// ends) of the posed avatar and its realizer bone.
pub fn limb_errors_by(
    retarget: &Retarget,
    skeleton: &Skeleton,
    pose: &Pose,
    node_of: impl Fn(&str) -> Option<usize>,
) -> Vec<f32> {
    let posed = retarget.world(&retarget.pose(pose));
    let realizer = pose.world(skeleton);
    let place = |m: &Mat4| m.w_axis.truncate();
    LIMBS
        .iter()
        .filter_map(|&(a, b)| {
            let (na, nb) = (node_of(a)?, node_of(b)?);
            let ours = place(&posed[nb]) - place(&posed[na]);
            let (ja, jb) = (retarget.source(na)?, retarget.source(nb)?);
            let theirs = retarget.frame() * (realizer.positions[jb] - realizer.positions[ja]);
            Some(ours.angle_between(theirs).to_degrees())
        })
        .collect()
}
