//! Which node of an avatar is which human bone. Bones are named here as VRM 1.0 names them
//! (`hips`, `leftUpperArm`, …): the one vocabulary every scheme maps into. An avatar's skeleton
//! is recognised from VRM 1.0's or VRM 0.x's humanoid extension, from a JSON bone map the user
//! gives, or by its node names: the realizer's own H-Anim names, Mixamo's (`mixamorig:LeftArm`),
//! or Unreal's (`upperarm_l`). Each human bone has a realizer joint as its source: the avatar
//! bone takes the world rotation of that joint. Where the realizer has more vertebrae than the
//! avatar has spine bones, the avatar's spine bones take the joints at the top of the spans
//! they stand for (so that the chest and the head end up turned as the realizer's).

use std::collections::BTreeMap;

use serde_json::Value;

use super::file::{AvatarError, Model};

/// The human bones in parents-first order, each with its parent bone (`""` for the hips).
pub const BONES: &[(&str, &str)] = &[
    ("hips", ""),
    ("spine", "hips"),
    ("chest", "spine"),
    ("upperChest", "chest"),
    ("neck", "upperChest"),
    ("head", "neck"),
    ("leftEye", "head"),
    ("rightEye", "head"),
    ("jaw", "head"),
    ("leftUpperLeg", "hips"),
    ("leftLowerLeg", "leftUpperLeg"),
    ("leftFoot", "leftLowerLeg"),
    ("leftToes", "leftFoot"),
    ("rightUpperLeg", "hips"),
    ("rightLowerLeg", "rightUpperLeg"),
    ("rightFoot", "rightLowerLeg"),
    ("rightToes", "rightFoot"),
    ("leftShoulder", "upperChest"),
    ("leftUpperArm", "leftShoulder"),
    ("leftLowerArm", "leftUpperArm"),
    ("leftHand", "leftLowerArm"),
    ("rightShoulder", "upperChest"),
    ("rightUpperArm", "rightShoulder"),
    ("rightLowerArm", "rightUpperArm"),
    ("rightHand", "rightLowerArm"),
    ("leftThumbMetacarpal", "leftHand"),
    ("leftThumbProximal", "leftThumbMetacarpal"),
    ("leftThumbDistal", "leftThumbProximal"),
    ("leftIndexProximal", "leftHand"),
    ("leftIndexIntermediate", "leftIndexProximal"),
    ("leftIndexDistal", "leftIndexIntermediate"),
    ("leftMiddleProximal", "leftHand"),
    ("leftMiddleIntermediate", "leftMiddleProximal"),
    ("leftMiddleDistal", "leftMiddleIntermediate"),
    ("leftRingProximal", "leftHand"),
    ("leftRingIntermediate", "leftRingProximal"),
    ("leftRingDistal", "leftRingIntermediate"),
    ("leftLittleProximal", "leftHand"),
    ("leftLittleIntermediate", "leftLittleProximal"),
    ("leftLittleDistal", "leftLittleIntermediate"),
    ("rightThumbMetacarpal", "rightHand"),
    ("rightThumbProximal", "rightThumbMetacarpal"),
    ("rightThumbDistal", "rightThumbProximal"),
    ("rightIndexProximal", "rightHand"),
    ("rightIndexIntermediate", "rightIndexProximal"),
    ("rightIndexDistal", "rightIndexIntermediate"),
    ("rightMiddleProximal", "rightHand"),
    ("rightMiddleIntermediate", "rightMiddleProximal"),
    ("rightMiddleDistal", "rightMiddleIntermediate"),
    ("rightRingProximal", "rightHand"),
    ("rightRingIntermediate", "rightRingProximal"),
    ("rightRingDistal", "rightRingIntermediate"),
    ("rightLittleProximal", "rightHand"),
    ("rightLittleIntermediate", "rightLittleProximal"),
    ("rightLittleDistal", "rightLittleIntermediate"),
];

/// The bones an avatar must have to be driven.
pub const REQUIRED: &[&str] = &[
    "hips",
    "spine",
    "head",
    "leftUpperArm",
    "leftLowerArm",
    "leftHand",
    "rightUpperArm",
    "rightLowerArm",
    "rightHand",
    "leftUpperLeg",
    "leftLowerLeg",
    "leftFoot",
    "rightUpperLeg",
    "rightLowerLeg",
    "rightFoot",
];

/// The realizer (H-Anim) joint whose world rotation a bone takes, for bones other than the
/// spine's (which depend on how many the avatar has, see [`spine_sources`]).
pub fn source(bone: &str) -> Option<String> {
    let (side, rest) = split_side(bone);
    if side.is_empty() {
        let joint = match rest {
            "hips" => "sacroiliac",
            "neck" => "vc4",
            "head" => "skullbase",
            "jaw" => "temporomandibular",
            _ => return None,
        };
        return Some(joint.to_string());
    }
    let joint = match rest {
        "Eye" => "eyeball_joint",
        "Shoulder" => "sternoclavicular",
        "UpperArm" => "shoulder",
        "LowerArm" => "elbow",
        "Hand" => "wrist",
        "UpperLeg" => "hip",
        "LowerLeg" => "knee",
        "Foot" => "talocrural",
        "Toes" => "metatarsal",
        finger => {
            let (f, k) = digit(finger)?;
            let f = if f == "Little" { "pinky" } else { f };
            return Some(format!("{side}_{}{k}", f.to_ascii_lowercase()));
        }
    };
    Some(format!("{side}_{joint}"))
}

/// The realizer's joints that an avatar's spine bones (`spine`, `chest`, `upperChest`, those
/// it has, bottom up) take their rotations from.
pub fn spine_sources(count: usize) -> &'static [&'static str] {
    match count {
        0 => &[],
        1 => &["vt6"],
        2 => &["vt12", "vt6"],
        _ => &["vl5", "vt12", "vt6"],
    }
}

/// Which node each human bone is (bone name → node), as found in `model`: by the bone map
/// given (keys: bone names or realizer joint names; values: node names, or `#N` for node N),
/// else by VRM's
/// humanoid extension, else by the node names.
pub fn recognise(
    model: &Model,
    map: Option<&BTreeMap<String, String>>,
) -> Result<BTreeMap<&'static str, usize>, AvatarError> {
    let found = if let Some(map) = map {
        from_map(model, map)?
    } else if let Some(bones) = vrm_bones(&model.json) {
        bones
            .into_iter()
            .filter(|&(_, n)| n < model.nodes.len())
            .collect()
    } else {
        by_names(model)
    };
    let missing: Vec<&str> = REQUIRED
        .iter()
        .copied()
        .filter(|b| !found.contains_key(b))
        .collect();
    if missing.is_empty() {
        return Ok(found);
    }
    let why = if missing.len() == REQUIRED.len() {
        "its skeleton's names match no known scheme (H-Anim, Mixamo, VRM, Unreal): none of the humanoid bones".to_string()
    } else {
        "its skeleton is not a whole humanoid: no bone".to_string()
    };
    Err(AvatarError::new(
        &model.file,
        format!(
            "{why} {} was found. Give a bone map (--bone-map MAP.json) naming the node of each: {}",
            missing.join(", "),
            bone_map_form(model, &missing)
        ),
    ))
}

/// The form of a bone map for the `missing` bones, and the names of the skin's joints to fill
/// it with (the first 40; a node without a name is given by its index, a number in the map).
fn bone_map_form(model: &Model, missing: &[&str]) -> String {
    let items: Vec<String> = missing
        .iter()
        .map(|b| format!("\"{b}\": \"NODE\""))
        .collect();
    // (a joint without a name by its index, as a bone map may give it: a number)
    let names: Vec<String> = (model.joints.iter())
        .map(|&j| match model.nodes[j].name.as_str() {
            "" => format!("{j} (no name)"),
            name => name.to_string(),
        })
        .take(40)
        .collect();
    let more = model.joints.len().saturating_sub(names.len());
    format!(
        "{{{}}}; the skin's joints are {}{}",
        items.join(", "),
        names.join(", "),
        if more > 0 {
            format!(" and {more} more")
        } else {
            String::new()
        }
    )
}

/// The bone of a VRM 1.0 name, as a `'static` name from [`BONES`].
fn bone(name: &str) -> Option<&'static str> {
    BONES.iter().map(|b| b.0).find(|b| *b == name)
}

/// The human bones of VRM 1.0 (`VRMC_vrm.humanoid.humanBones`) or VRM 0.x
/// (`VRM.humanoid.humanBones`, whose thumb bones are named one step further out).
fn vrm_bones(json: &Value) -> Option<BTreeMap<&'static str, usize>> {
    let ext = &json["extensions"];
    if let Some(bones) = ext["VRMC_vrm"]["humanoid"]["humanBones"].as_object() {
        return Some(
            bones
                .iter()
                .filter_map(|(k, v)| Some((bone(k)?, v["node"].as_u64()? as usize)))
                .collect(),
        );
    }
    let bones = ext["VRM"]["humanoid"]["humanBones"].as_array()?;
    Some(
        bones
            .iter()
            .filter_map(|b| {
                let name = b["bone"].as_str()?;
                let name = match name {
                    n if n.ends_with("ThumbProximal") => n.replace("Proximal", "Metacarpal"),
                    n if n.ends_with("ThumbIntermediate") => n.replace("Intermediate", "Proximal"),
                    n => n.to_string(),
                };
                Some((bone(&name)?, b["node"].as_u64()? as usize))
            })
            .collect(),
    )
}

/// A bone map as a user writes it: a JSON object of bone names (or realizer joint names) to
/// node names, or to node indices (numbers, for nodes without names), which the map holds as
/// `#N` (what [`recognise`] takes).
pub fn bone_map_from_json(text: &str) -> Result<BTreeMap<String, String>, String> {
    let raw: BTreeMap<String, Value> = serde_json::from_str(text).map_err(|e| e.to_string())?;
    raw.into_iter()
        .map(|(bone, node)| match node {
            Value::String(n) => Ok((bone, n)),
            Value::Number(n) if n.is_u64() => Ok((bone, format!("#{n}"))),
            other => Err(format!("{bone}: {other} is neither a name nor an index")),
        })
        .collect()
}

/// The bones of a user's map (bone or realizer joint → node name).
fn from_map(
    model: &Model,
    map: &BTreeMap<String, String>,
) -> Result<BTreeMap<&'static str, usize>, AvatarError> {
    let mut found = BTreeMap::new();
    for (key, node) in map {
        let b = bone(key)
            .or_else(|| {
                BONES
                    .iter()
                    .map(|b| b.0)
                    .find(|b| hanim(b).as_deref() == Some(key.as_str()))
            })
            .ok_or_else(|| {
                AvatarError::new(&model.file, format!("bone map: unknown bone '{key}'"))
            })?;
        // (`#N`: node N, for nodes without names)
        let index = (node.strip_prefix('#'))
            .and_then(|n| n.parse::<usize>().ok())
            .filter(|&n| n < model.nodes.len());
        let n = model.node(node).or(index).ok_or_else(|| {
            AvatarError::new(
                &model.file,
                format!("bone map: {key}: no node named '{node}'"),
            )
        })?;
        found.insert(b, n);
    }
    Ok(found)
}

/// The realizer's own name of a bone when an avatar uses H-Anim names.
fn hanim(bone: &str) -> Option<String> {
    match bone {
        "spine" => Some("vl5".into()),
        "chest" => Some("vt12".into()),
        "upperChest" => Some("vt6".into()),
        b => source(b),
    }
}

/// A naming scheme: the node name it gives a bone.
type NameScheme = fn(&str) -> Option<String>;

/// The bones found by node names, trying each scheme and keeping the one that finds most.
fn by_names(model: &Model) -> BTreeMap<&'static str, usize> {
    let schemes: [NameScheme; 3] = [hanim, mixamo, unreal];
    let mut best = BTreeMap::new();
    for name_of in schemes {
        let mut found = BTreeMap::new();
        for (b, _) in BONES {
            let Some(want) = name_of(b) else { continue };
            if let Some(n) = model.nodes.iter().position(|n| same(&n.name, &want)) {
                found.insert(*b, n);
            }
        }
        if found.len() > best.len() {
            best = found;
        }
    }
    best
}

/// Whether node name `node` is `want`, ignoring case and a `mixamorig:`-like prefix.
fn same(node: &str, want: &str) -> bool {
    let bare = node.rsplit([':', '|']).next().unwrap_or(node);
    let bare = bare.strip_prefix("mixamorig").unwrap_or(bare);
    let bare = bare.trim_start_matches('_');
    bare.eq_ignore_ascii_case(want)
}

fn mixamo(bone: &str) -> Option<String> {
    let (side, rest) = split_side(bone);
    let side = match side {
        "l" => "Left",
        "r" => "Right",
        _ => "",
    };
    let name = match rest {
        "hips" => "Hips",
        "spine" => "Spine",
        "chest" => "Spine1",
        "upperChest" => "Spine2",
        "neck" => "Neck",
        "head" => "Head",
        "Eye" => "Eye",
        "Shoulder" => "Shoulder",
        "UpperArm" => "Arm",
        "LowerArm" => "ForeArm",
        "Hand" => "Hand",
        "UpperLeg" => "UpLeg",
        "LowerLeg" => "Leg",
        "Foot" => "Foot",
        "Toes" => "ToeBase",
        finger => return digit(finger).map(|(f, k)| format!("{side}Hand{}{k}", mixamo_finger(f))),
    };
    Some(format!("{side}{name}"))
}

fn mixamo_finger(f: &str) -> &str {
    if f == "Little" {
        "Pinky"
    } else {
        f
    }
}

fn unreal(bone: &str) -> Option<String> {
    let (side, rest) = split_side(bone);
    let name = match rest {
        "hips" => "pelvis",
        "spine" => "spine_01",
        "chest" => "spine_02",
        "upperChest" => "spine_03",
        "neck" => "neck_01",
        "head" => "head",
        "Eye" => "eye",
        "Shoulder" => "clavicle",
        "UpperArm" => "upperarm",
        "LowerArm" => "lowerarm",
        "Hand" => "hand",
        "UpperLeg" => "thigh",
        "LowerLeg" => "calf",
        "Foot" => "foot",
        "Toes" => "ball",
        finger => {
            let (f, k) = digit(finger)?;
            let f = if f == "Little" { "pinky" } else { f };
            return Some(format!("{}_0{k}_{side}", f.to_ascii_lowercase()));
        }
    };
    Some(if side.is_empty() {
        name.to_string()
    } else {
        format!("{name}_{side}")
    })
}

/// A bone's side (`l`, `r` or none) and the rest of its name.
fn split_side(bone: &str) -> (&str, &str) {
    if let Some(r) = bone.strip_prefix("left") {
        ("l", r)
    } else if let Some(r) = bone.strip_prefix("right") {
        ("r", r)
    } else {
        ("", bone)
    }
}

/// A finger bone's finger (`Thumb`, `Index`, … `Little`) and its number from the hand (1–3).
fn digit(rest: &str) -> Option<(&str, usize)> {
    let finger = ["Thumb", "Index", "Middle", "Ring", "Little"]
        .into_iter()
        .find(|f| rest.starts_with(f))?;
    let part = &rest[finger.len()..];
    let order: &[&str] = if finger == "Thumb" {
        &["Metacarpal", "Proximal", "Distal"]
    } else {
        &["Proximal", "Intermediate", "Distal"]
    };
    Some((finger, order.iter().position(|p| *p == part)? + 1))
}
