//! The face on an avatar's morph targets, by name. A target named as one of the 52 ARKit
//! blendshapes takes the frame's weight of it; a target named `viseme_X` (Ready Player Me, the
//! Oculus set) takes the frame's weight of viseme X (coarticulated: one blends into the next);
//! VRM expressions (1.0 `expressions`, 0.x
//! `blendShapeMaster`) are weighed from the face (visemes aa ih ou ee oh, blinks from the
//! blink weights, happy/angry/sad/surprised from the smile, brow and frown weights) and spread
//! onto the morph targets they bind, scaled by each bind's weight.

use serde_json::Value;

use super::file::Model;
use crate::face::model::{morph_index, Face, VISEMES};

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
}

impl MorphMap {
    /// The morph targets of `model` that the face drives.
    pub fn new(model: &Model) -> MorphMap {
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
                if let Some(s) = sources.get_mut(target) {
                    s.push(Source::Expression(expression, weight));
                }
            }
            if sources.iter().any(|s| !s.is_empty()) {
                nodes.push((i, sources));
            }
        }
        MorphMap { nodes }
    }

    /// The animated mesh nodes and how many morph targets each has.
    pub fn nodes(&self) -> impl Iterator<Item = (usize, usize)> + '_ {
        self.nodes.iter().map(|(n, t)| (*n, t.len()))
    }

    /// Whether nothing of the face shows on the avatar.
    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// The weights of the `k`-th node's (of [`MorphMap::nodes`]) morph targets for `face`, into `out`.
    pub fn weights(&self, k: usize, face: &Face, out: &mut Vec<f32>) {
        out.clear();
        for sources in &self.nodes[k].1 {
            let w: f32 = sources.iter().map(|s| weigh(s, face)).sum();
            out.push(w.clamp(0.0, 1.0));
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

fn weigh(source: &Source, face: &Face) -> f32 {
    match *source {
        Source::Arkit(i) => face.morphs.0[i],
        Source::Viseme(v) => face.visemes.get(v).copied().unwrap_or(0.0),
        Source::Expression(name, weight) => expression(name, face) * weight,
    }
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
        _ => return None,
    })
}

/// The VRM 1.0 preset names the realizer weighs.
const PRESETS: [&str; 12] = [
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
    use crate::face::model::{morph_index, Morphs};

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
            map.weights(0, &speaking(), &mut w);
            // jawOpen as is, the viseme on, the expression aa on, blink (the lesser eye) × 0.5
            assert_eq!(w, vec![0.4, 1.0, 1.0, 0.4, 0.0]);
            map.weights(0, &Face::default(), &mut w);
            assert_eq!(w, vec![0.0; 5]);
        }
        // nothing the face drives: nothing animated
        let mut plain = model(json!({"nodes": [{"mesh": 0}]}));
        plain.morphs = vec![vec!["Key 1".into()]];
        assert!(MorphMap::new(&plain).is_empty());
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
            map.weights(0, &frame.poses[0].face, &mut w);
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
