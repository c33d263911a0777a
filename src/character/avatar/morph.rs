//! The face on an avatar's morph targets, by name. A target named as one of the 52 ARKit
//! blendshapes takes the frame's weight of it; a target named `viseme_X` (Ready Player Me, the
//! Oculus set) takes the frame's weight of viseme X (coarticulated: one blends into the next);
//! VRM expressions (1.0 `expressions`, 0.x
//! `blendShapeMaster`) are weighed from the face (visemes aa ih ou ee oh, blinks from the
//! blink weights, happy/angry/sad/surprised from the smile, brow and frown weights) and spread
//! onto the morph targets they bind, scaled by each bind's weight. An avatar whose eyes look by
//! expressions (VRM 1.0 `lookAt.type` `expression`, 0.x `lookAtTypeName` `BlendShape`) has its
//! lookLeft/Right/Up/Down weighed from where the realizer's eyes look ([`Look`]) through the
//! file's range maps (the angle at which the weight is full, and the weight then).

use glam::Vec3;
use serde_json::Value;

use super::file::Model;
use crate::character::body::pose::Pose;
use crate::character::face::model::{morph_index, Face, VISEMES};

/// Where the eyes look, in the head's frame: yaw (degrees, + to the character's left) and
/// pitch (degrees, + up).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Look {
    /// Degrees to the left (negative: to the right).
    pub yaw: f32,
    /// Degrees up (negative: down).
    pub pitch: f32,
}

impl Look {
    /// Where the eyes look in `pose`: the mean direction of the two eyeball joints (`eyes`,
    /// their indices) turned from rest, where they look ahead (+z). Ahead without eyes.
    pub fn of(pose: &Pose, eyes: Option<(usize, usize)>) -> Look {
        let Some((l, r)) = eyes else {
            return Look::default();
        };
        let (Some(ql), Some(qr)) = (pose.rotations.get(l), pose.rotations.get(r)) else {
            return Look::default();
        };
        let d = (*ql * Vec3::Z + *qr * Vec3::Z).normalize_or(Vec3::Z);
        Look {
            yaw: d.x.atan2(d.z).to_degrees(),
            pitch: d.y.atan2(d.x.hypot(d.z)).to_degrees(),
        }
    }
}

/// The range maps of looking by expressions: per direction (left, right, up, down) the angle
/// (degrees) at which the weight is full, and that weight.
#[derive(Debug, Clone, Copy, PartialEq)]
struct LookRanges([(f32, f32); 4]);

impl LookRanges {
    /// The ranges of `json` if its eyes look by expressions.
    fn of(json: &Value) -> Option<LookRanges> {
        // VRM 1.0 and 0.x name the same four maps and their two numbers differently
        let versions = [
            (
                &json["extensions"]["VRMC_vrm"]["lookAt"],
                ("type", "expression"),
                [
                    "rangeMapHorizontalOuter",
                    "rangeMapVerticalUp",
                    "rangeMapVerticalDown",
                ],
                ("inputMaxValue", "outputScale"),
            ),
            (
                &json["extensions"]["VRM"]["firstPerson"],
                ("lookAtTypeName", "BlendShape"),
                [
                    "lookAtHorizontalOuter",
                    "lookAtVerticalUp",
                    "lookAtVerticalDown",
                ],
                ("xRange", "yRange"),
            ),
        ];
        let (look, _, [side, up, down], (max, scale)) =
            (versions.into_iter()).find(|(look, (key, value), _, _)| look[*key] == *value)?;
        let range = |k: &str| {
            let m = &look[k];
            (
                (m[max].as_f64().unwrap_or(90.0) as f32).max(1e-3),
                m[scale].as_f64().map_or(1.0, |s| s as f32),
            )
        };
        let side = range(side);
        Some(LookRanges([side, side, range(up), range(down)]))
    }

    /// The weight of look expression `name` at `look`.
    fn weigh(&self, name: &str, look: Look) -> f32 {
        let (angle, (max, scale)) = match name {
            "lookLeft" => (look.yaw, self.0[0]),
            "lookRight" => (-look.yaw, self.0[1]),
            "lookUp" => (look.pitch, self.0[2]),
            "lookDown" => (-look.pitch, self.0[3]),
            _ => return 0.0,
        };
        (angle / max).clamp(0.0, 1.0) * scale
    }
}

/// What drives one morph target.
#[derive(Debug, Clone, PartialEq)]
enum Source {
    /// An ARKit blendshape (index into `ARKIT`).
    Arkit(usize),
    /// A viseme (index into `VISEMES`).
    Viseme(usize),
    /// A VRM expression by its VRM 1.0 preset name, and the bind's weight (0–1).
    Expression(&'static str, f32),
}

/// Every animated mesh node of an avatar and what drives each of its morph targets.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MorphMap {
    /// (node, per morph target the sources that add up to its weight).
    nodes: Vec<(usize, Vec<Vec<Source>>)>,
    /// How far the eyes look for full weight, when they look by expressions.
    look: Option<LookRanges>,
}

impl MorphMap {
    /// The morph targets of `model` that the face drives.
    pub fn new(model: &Model) -> MorphMap {
        let look = LookRanges::of(&model.json);
        let mut nodes = Vec::new();
        for (i, node) in model.json["nodes"]
            .as_array()
            .into_iter()
            .flatten()
            .enumerate()
        {
            let Some(mesh) = node["mesh"].as_u64().map(|m| m as usize) else {
                continue;
            };
            let Some(names) = model.morphs.get(mesh) else {
                continue;
            };
            let mut sources: Vec<Vec<Source>> = names.iter().map(|n| by_name(n)).collect();
            for (expression, target, weight) in expression_binds(&model.json, i, mesh) {
                if expression.starts_with("look") && look.is_none() {
                    continue; // (the eyes look by bones: these expressions are not used)
                }
                if let Some(s) = sources.get_mut(target) {
                    s.push(Source::Expression(expression, weight));
                }
            }
            if sources.iter().any(|s| !s.is_empty()) {
                nodes.push((i, sources));
            }
        }
        MorphMap { nodes, look }
    }

    /// The animated mesh nodes and how many morph targets each has.
    pub fn nodes(&self) -> impl Iterator<Item = (usize, usize)> + '_ {
        self.nodes.iter().map(|(n, t)| (*n, t.len()))
    }

    /// Whether nothing of the face shows on the avatar.
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// The weights of the `k`-th node's (of [`MorphMap::nodes`]) morph targets for `face` with
    /// the eyes at `look`, into `out`.
    pub fn weights(&self, k: usize, face: &Face, look: Look, out: &mut Vec<f32>) {
        out.clear();
        for sources in &self.nodes[k].1 {
            let w: f32 = sources.iter().map(|s| self.weigh(s, face, look)).sum();
            out.push(w.clamp(0.0, 1.0));
        }
    }

    fn weigh(&self, source: &Source, face: &Face, look: Look) -> f32 {
        match *source {
            Source::Arkit(i) => face.morphs.0[i],
            Source::Viseme(v) => face.visemes.get(v).copied().unwrap_or(0.0),
            Source::Expression(name, weight) if name.starts_with("look") => {
                self.look.map_or(0.0, |r| r.weigh(name, look)) * weight
            }
            Source::Expression(name, weight) => expression(name, face) * weight,
        }
    }
}

fn by_name(name: &str) -> Vec<Source> {
    if let Some(i) = morph_index(name) {
        return vec![Source::Arkit(i)];
    }
    let viseme = name
        .strip_prefix("viseme_")
        .and_then(|v| VISEMES.iter().position(|x| *x == v));
    viseme.map(Source::Viseme).into_iter().collect()
}

/// The weight of VRM 1.0 expression `name` in `face`.
fn expression(name: &str, face: &Face) -> f32 {
    let m = |n: &str| face.morphs.get(n);
    let viseme = |v: &str| (VISEMES.iter().position(|x| *x == v)).map_or(0.0, |i| face.visemes[i]);
    match name {
        "aa" => viseme("aa"),
        "ih" => viseme("ih"),
        "ou" => viseme("ou"),
        "ee" => viseme("E"),
        "oh" => viseme("oh"),
        "blink" => m("eyeBlinkLeft").min(m("eyeBlinkRight")),
        "blinkLeft" => m("eyeBlinkLeft") - m("eyeBlinkLeft").min(m("eyeBlinkRight")),
        "blinkRight" => m("eyeBlinkRight") - m("eyeBlinkLeft").min(m("eyeBlinkRight")),
        "happy" => 0.5 * (m("mouthSmileLeft") + m("mouthSmileRight")),
        "angry" => 0.5 * (m("browDownLeft") + m("browDownRight")),
        "sad" => 0.5 * (m("mouthFrownLeft") + m("mouthFrownRight")),
        "surprised" => m("browInnerUp"),
        _ => 0.0,
    }
}

/// The VRM 1.0 preset name of a VRM 0.x blend shape preset.
fn preset_of_vrm0(name: &str) -> Option<&'static str> {
    Some(match name {
        "a" => "aa",
        "i" => "ih",
        "u" => "ou",
        "e" => "ee",
        "o" => "oh",
        "blink" => "blink",
        "blink_l" => "blinkLeft",
        "blink_r" => "blinkRight",
        "joy" => "happy",
        "angry" => "angry",
        "sorrow" => "sad",
        "fun" => "surprised",
        "lookleft" => "lookLeft",
        "lookright" => "lookRight",
        "lookup" => "lookUp",
        "lookdown" => "lookDown",
        _ => return None,
    })
}

/// The VRM 1.0 preset names the realizer weighs.
const PRESETS: [&str; 16] = [
    "aa",
    "ih",
    "ou",
    "ee",
    "oh",
    "blink",
    "blinkLeft",
    "blinkRight",
    "happy",
    "angry",
    "sad",
    "surprised",
    "lookLeft",
    "lookRight",
    "lookUp",
    "lookDown",
];

/// The (expression, morph target, weight 0–1) binds of VRM expressions onto node `node`
/// (VRM 1.0 binds name nodes) or mesh `mesh` (VRM 0.x binds name meshes).
fn expression_binds(json: &Value, node: usize, mesh: usize) -> Vec<(&'static str, usize, f32)> {
    let mut out = Vec::new();
    let vrm1 = &json["extensions"]["VRMC_vrm"]["expressions"]["preset"];
    for preset in PRESETS {
        for b in vrm1[preset]["morphTargetBinds"]
            .as_array()
            .into_iter()
            .flatten()
        {
            if b["node"].as_u64() == Some(node as u64) {
                if let Some(index) = b["index"].as_u64() {
                    let w = b["weight"].as_f64().unwrap_or(1.0) as f32;
                    out.push((preset, index as usize, w));
                }
            }
        }
    }
    let groups = &json["extensions"]["VRM"]["blendShapeMaster"]["blendShapeGroups"];
    for g in groups.as_array().into_iter().flatten() {
        let Some(preset) = g["presetName"].as_str().and_then(preset_of_vrm0) else {
            continue;
        };
        for b in g["binds"].as_array().into_iter().flatten() {
            if b["mesh"].as_u64() == Some(mesh as u64) {
                if let Some(index) = b["index"].as_u64() {
                    // VRM 0.x weighs binds 0–100
                    let w = b["weight"].as_f64().unwrap_or(100.0) as f32 / 100.0;
                    out.push((preset, index as usize, w));
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use serde_json::json;

    use super::*;
    use crate::character::face::model::{morph_index, Morphs};

    fn model(json: Value) -> Model {
        Model {
            file: "face.vrm".into(),
            nodes: Vec::new(),
            joints: Vec::new(),
            morphs: vec![vec![
                "jawOpen".into(),
                "viseme_aa".into(),
                "Fcl_MTH_A".into(),
                "Fcl_EYE_Close".into(),
                "unrelated".into(),
            ]],
            json,
            bin: Vec::new(),
        }
    }

    fn speaking() -> Face {
        let mut morphs = Morphs::default();
        for (name, w) in [
            ("jawOpen", 0.4),
            ("eyeBlinkLeft", 1.0),
            ("eyeBlinkRight", 0.8),
        ] {
            morphs.0[morph_index(name).unwrap()] = w;
        }
        let aa = VISEMES.iter().position(|v| *v == "aa").unwrap();
        let mut visemes = [0.0; VISEMES.len()];
        visemes[aa] = 1.0;
        visemes[aa + 1] = 0.25; // coarticulation: the next one coming
        Face {
            morphs,
            viseme: Some(aa),
            visemes,
            ..Face::default()
        }
    }

    #[test]
    fn arkit_names_visemes_and_vrm_expressions_drive_their_targets() {
        // VRM 1.0: expressions bind nodes
        let vrm1 = model(json!({
            "nodes": [{"mesh": 0}],
            "extensions": {"VRMC_vrm": {"expressions": {"preset": {
                "aa": {"morphTargetBinds": [{"node": 0, "index": 2, "weight": 1.0}]},
                "blink": {"morphTargetBinds": [{"node": 0, "index": 3, "weight": 0.5}]}
            }}}}
        }));
        // VRM 0.x: blend shape groups bind meshes, weights 0-100
        let vrm0 = model(json!({
            "nodes": [{"mesh": 0}],
            "extensions": {"VRM": {"blendShapeMaster": {"blendShapeGroups": [
                {"presetName": "a", "binds": [{"mesh": 0, "index": 2, "weight": 100}]},
                {"presetName": "blink", "binds": [{"mesh": 0, "index": 3, "weight": 50}]}
            ]}}}
        }));
        for m in [vrm1, vrm0] {
            let map = MorphMap::new(&m);
            assert_eq!(map.nodes().collect::<Vec<_>>(), vec![(0, 5)]);
            let mut w = Vec::new();
            map.weights(0, &speaking(), Look::default(), &mut w);
            // jawOpen as is, the viseme on, the expression aa on, blink (the lesser eye) × 0.5
            assert_eq!(w, vec![0.4, 1.0, 1.0, 0.4, 0.0]);
            map.weights(0, &Face::default(), Look::default(), &mut w);
            assert_eq!(w, vec![0.0; 5]);
        }
        // nothing the face drives: nothing animated
        let mut plain = model(json!({"nodes": [{"mesh": 0}]}));
        plain.morphs = vec![vec!["Key 1".into()]];
        assert!(MorphMap::new(&plain).is_empty());
    }

    #[test]
    fn eyes_that_look_by_expressions_weigh_them_from_where_the_realizer_looks() {
        let binds =
            |i: usize| json!({"morphTargetBinds": [{"node": 0, "index": i, "weight": 1.0}]});
        let vrm1 = |kind: &str| {
            model(json!({
                "nodes": [{"mesh": 0}],
                "extensions": {"VRMC_vrm": {
                    "lookAt": {"type": kind,
                               "rangeMapHorizontalOuter": {"inputMaxValue": 20.0, "outputScale": 1.0},
                               "rangeMapVerticalUp": {"inputMaxValue": 10.0, "outputScale": 0.5}},
                    "expressions": {"preset": {"lookLeft": binds(0), "lookUp": binds(2)}}}}
            }))
        };
        let look = Look {
            yaw: 10.0,
            pitch: 15.0,
        };
        let mut w = Vec::new();
        let map = MorphMap::new(&vrm1("expression"));
        map.weights(0, &Face::default(), look, &mut w);
        // half way to the 20° of a full lookLeft; up past its 10°, at its scale 0.5
        assert_eq!(w, vec![0.5, 0.0, 0.5, 0.0, 0.0]);
        map.weights(
            0,
            &Face::default(),
            Look {
                yaw: -10.0,
                pitch: -5.0,
            },
            &mut w,
        );
        assert_eq!(w, vec![0.0; 5]);
        // eyes that look by bones leave the expressions alone
        MorphMap::new(&vrm1("bone")).weights(0, &Face::default(), look, &mut w);
        assert_eq!(w, vec![0.0; 5]);
        // VRM 0.x: lookAtTypeName BlendShape, presets lookleft …, ranges in degrees
        let vrm0 = model(json!({
            "nodes": [{"mesh": 0}],
            "extensions": {"VRM": {
                "firstPerson": {"lookAtTypeName": "BlendShape",
                                "lookAtHorizontalOuter": {"xRange": 40.0, "yRange": 1.0}},
                "blendShapeMaster": {"blendShapeGroups": [
                    {"presetName": "lookleft", "binds": [{"mesh": 0, "index": 1, "weight": 100}]}]}}}
        }));
        MorphMap::new(&vrm0).weights(0, &Face::default(), look, &mut w);
        assert_eq!(w, vec![0.0, 0.25, 0.0, 0.0, 0.0]);
    }

    /// A gaze to the character's left turns its eyes left: `Look` says so from the pose.
    #[test]
    fn look_follows_the_realizer_s_eyes() {
        let skeleton = crate::character::body::Skeleton::adult();
        let eyes = skeleton
            .joint("l_eyeball_joint")
            .zip(skeleton.joint("r_eyeball_joint"));
        let mut r = crate::realizer::Realizer::new().with_idle(false);
        r.world_mut().set("left", glam::Vec3::new(2.0, 1.6, 1.0));
        r.perform_bml(
            r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="b"><gaze id="g" target="left" influence="EYES" start="0" ready="0.3" end="2"/></bml>"#,
        )
        .unwrap();
        let mut look = Look::default();
        for k in 0..60 {
            look = Look::of(&r.tick(f64::from(k) / 60.0).poses[0].pose, eyes);
        }
        assert!(look.yaw > 10.0, "the eyes look {look:?}");
        assert_eq!(Look::of(&r.tick(1.0).poses[0].pose, None), Look::default());
    }

    /// Visemes blend into each other: over a spoken sentence at 60 frames a second, a
    /// `viseme_*` target never jumps by more than half its range from one frame to the next,
    /// and spends frames between off and on (a target that followed the strongest viseme alone
    /// would jump from 0 to 1).
    #[test]
    fn viseme_targets_blend_from_frame_to_frame() {
        let map = MorphMap::new(&model(json!({"nodes": [{"mesh": 0}]})));
        let mut r = crate::realizer::Realizer::new().with_idle(false);
        r.perform_bml(
            r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="b"><speech id="s">
               <text>Hello and welcome to the realizer, a talking head.</text></speech></bml>"#,
        )
        .unwrap();
        let (mut jump, mut between, mut w, mut was) = (0.0f32, 0, Vec::new(), None::<Vec<f32>>);
        for k in 0..240 {
            let frame = r.tick(f64::from(k) / 60.0);
            map.weights(0, &frame.poses[0].face, Look::default(), &mut w);
            let aa = w[1];
            if aa > 0.05 && aa < 0.95 {
                between += 1;
            }
            if let Some(p) = &was {
                jump = jump.max((aa - p[1]).abs());
            }
            was = Some(w.clone());
        }
        assert!(
            between >= 4,
            "viseme_aa between off and on in {between} frames"
        );
        assert!(jump <= 0.5, "viseme_aa jumped {jump} in one frame");
    }
}
