//! The face model: which FACS action units a face has, what each drives among the ARKit
//! blendshapes, the BML face lexemes as action units, and the visemes as blendshapes. All of it is
//! data (`fixtures/face/au-arkit.json`, `lexemes.json`, `visemes.json`, embedded); the face state
//! of a character is one intensity (0–1) per action unit and side.

use std::sync::LazyLock;

use crate::language::bml::Side;

/// The 52 ARKit blendshape names, in Apple's order (the morph targets of VRM, Ready Player Me
/// and most face rigs).
pub const ARKIT: [&str; 52] = [
    "eyeBlinkLeft",
    "eyeLookDownLeft",
    "eyeLookInLeft",
    "eyeLookOutLeft",
    "eyeLookUpLeft",
    "eyeSquintLeft",
    "eyeWideLeft",
    "eyeBlinkRight",
    "eyeLookDownRight",
    "eyeLookInRight",
    "eyeLookOutRight",
    "eyeLookUpRight",
    "eyeSquintRight",
    "eyeWideRight",
    "jawForward",
    "jawLeft",
    "jawRight",
    "jawOpen",
    "mouthClose",
    "mouthFunnel",
    "mouthPucker",
    "mouthLeft",
    "mouthRight",
    "mouthSmileLeft",
    "mouthSmileRight",
    "mouthFrownLeft",
    "mouthFrownRight",
    "mouthDimpleLeft",
    "mouthDimpleRight",
    "mouthStretchLeft",
    "mouthStretchRight",
    "mouthRollLower",
    "mouthRollUpper",
    "mouthShrugLower",
    "mouthShrugUpper",
    "mouthPressLeft",
    "mouthPressRight",
    "mouthLowerDownLeft",
    "mouthLowerDownRight",
    "mouthUpperUpLeft",
    "mouthUpperUpRight",
    "browDownLeft",
    "browDownRight",
    "browInnerUp",
    "browOuterUpLeft",
    "browOuterUpRight",
    "cheekPuff",
    "cheekSquintLeft",
    "cheekSquintRight",
    "noseSneerLeft",
    "noseSneerRight",
    "tongueOut",
];

/// The 15 visemes (the Oculus/Meta lip-sync set).
pub const VISEMES: [&str; 15] = [
    "sil", "PP", "FF", "TH", "DD", "kk", "CH", "SS", "nn", "RR", "aa", "E", "ih", "oh", "ou",
];

/// The index of blendshape `name` in [`ARKIT`].
pub fn morph_index(name: &str) -> Option<usize> {
    ARKIT.iter().position(|m| *m == name)
}

/// Morph target weights (0–1), one per [`ARKIT`] name.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Morphs(pub [f32; 52]);

impl Default for Morphs {
    fn default() -> Self {
        Morphs([0.0; 52])
    }
}

impl Morphs {
    /// The weight of blendshape `name` (0 for a name that is not an ARKit one).
    pub fn get(&self, name: &str) -> f32 {
        morph_index(name).map_or(0.0, |i| self.0[i])
    }
}

/// Intensity (0–1) per action unit and side: slot `2 k` is the left side of the model's `k`-th
/// AU, `2 k + 1` its right side.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct FaceState(pub Vec<f32>);

/// What a character's face shows in a frame: the action units, the blendshape weights they and
/// the direct morph targets (visemes, `bmlt:facemorph`) make, and the current viseme.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Face {
    /// Action unit intensities (see [`FaceState`]).
    pub aus: FaceState,
    /// Blendshape weights. Before [`FaceModel::finish`], only the direct targets.
    pub morphs: Morphs,
    /// The viseme being articulated (an index into [`VISEMES`]), while speaking.
    pub viseme: Option<usize>,
    /// Each viseme's weight (0–1, in the order of [`VISEMES`]) while speaking: coarticulated,
    /// so that one blends into the next (for avatars with a target per viseme).
    pub visemes: [f32; VISEMES.len()],
}

impl Face {
    /// A neutral face of `model`.
    pub fn neutral(model: &FaceModel) -> Face {
        Face {
            aus: FaceState(vec![0.0; 2 * model.aus.len()]),
            morphs: Morphs::default(),
            viseme: None,
            visemes: [0.0; VISEMES.len()],
        }
    }

    /// Raises slot `slot` to at least `v` (the AUs of several sources combine by maximum).
    pub fn raise(&mut self, slot: usize, v: f32) {
        if let Some(w) = self.aus.0.get_mut(slot) {
            *w = w.max(v.clamp(0.0, 1.0));
        }
    }

    /// Raises blendshape `index` to at least `v`.
    pub fn raise_morph(&mut self, index: usize, v: f32) {
        if let Some(w) = self.morphs.0.get_mut(index) {
            *w = w.max(v.clamp(0.0, 1.0));
        }
    }
}

/// An action unit of the model: its FACS number and name, and the blendshapes (index, weight at
/// full intensity) each of its sides drives.
#[derive(Debug, Clone, PartialEq)]
pub struct ActionUnit {
    /// FACS number (1 = inner brow raiser, …).
    pub number: u32,
    /// FACS name.
    pub name: String,
    /// Left side, right side.
    pub drives: [Vec<(usize, f32)>; 2],
}

/// The face model (see the module documentation).
#[derive(Debug, Clone, PartialEq)]
pub struct FaceModel {
    /// The action units, by increasing number.
    pub aus: Vec<ActionUnit>,
    lexemes: Vec<(String, Vec<(usize, f32)>)>,
    visemes: Vec<Vec<(usize, f32)>>,
}

const AU_ARKIT: &str = include_str!("../../../fixtures/face/au-arkit.json");
const LEXEMES: &str = include_str!("../../../fixtures/face/lexemes.json");
const VISEME_SHAPES: &str = include_str!("../../../fixtures/face/visemes.json");

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct AuFile {
    #[serde(default, rename = "description")]
    _description: crate::data::Note,
    aus: indexmap::IndexMap<String, AuEntry>,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct AuEntry {
    name: String,
    left: Vec<(String, f32)>,
    right: Vec<(String, f32)>,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct LexemeFile {
    #[serde(default, rename = "description")]
    _description: crate::data::Note,
    lexemes: indexmap::IndexMap<String, Vec<(String, f32)>>,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct VisemeFile {
    #[serde(default, rename = "description")]
    _description: crate::data::Note,
    visemes: indexmap::IndexMap<String, Vec<(String, f32)>>,
}

/// `(blendshape, weight)` pairs by index; the error names an unknown blendshape.
fn shapes(pairs: Vec<(String, f32)>, what: &str) -> Result<Vec<(usize, f32)>, String> {
    (pairs.into_iter())
        .map(|(m, w)| {
            morph_index(&m)
                .map(|i| (i, w))
                .ok_or_else(|| format!("{what}: '{m}' is not an ARKit blendshape"))
        })
        .collect()
}

impl FaceModel {
    /// The embedded model.
    pub fn default_model() -> &'static FaceModel {
        static MODEL: LazyLock<FaceModel> = LazyLock::new(|| {
            FaceModel::from_json(AU_ARKIT, LEXEMES, VISEME_SHAPES)
                .expect("the embedded face model is valid")
        });
        &MODEL
    }

    /// Reads the three data files; the error says which entry is wrong.
    pub fn from_json(aus: &str, lexemes: &str, visemes: &str) -> Result<FaceModel, String> {
        let file: AuFile = crate::data::from_json(aus)?;
        let mut units = Vec::new();
        for (number, e) in file.aus {
            let n: u32 =
                (number.parse()).map_err(|_| format!("action unit '{number}' is not a number"))?;
            let what = format!("AU{n}");
            units.push(ActionUnit {
                number: n,
                name: e.name,
                drives: [shapes(e.left, &what)?, shapes(e.right, &what)?],
            });
        }
        units.sort_by_key(|a| a.number);
        let mut model = FaceModel {
            aus: units,
            lexemes: Vec::new(),
            visemes: Vec::new(),
        };
        let file: LexemeFile = crate::data::from_json(lexemes)?;
        for (name, list) in file.lexemes {
            let mut slots = Vec::new();
            for (au, w) in list {
                let found = (model.parse_au(&au))
                    .ok_or_else(|| format!("lexeme {name}: '{au}' is not an AU of the model"))?;
                slots.extend(found.into_iter().map(|s| (s, w)));
            }
            model.lexemes.push((name, slots));
        }
        let file: VisemeFile = crate::data::from_json(visemes)?;
        for (k, v) in VISEMES.iter().enumerate() {
            let list = (file.visemes.get(*v))
                .ok_or_else(|| format!("viseme '{v}' is missing"))?
                .clone();
            model
                .visemes
                .push(shapes(list, &format!("viseme {}", VISEMES[k]))?);
        }
        Ok(model)
    }

    /// The slots of `AU12` (both sides), `AU12L` or `AU12R`.
    fn parse_au(&self, name: &str) -> Option<Vec<usize>> {
        let rest = name.strip_prefix("AU")?;
        let (digits, side) = match rest.strip_suffix('L') {
            Some(d) => (d, Side::Left),
            None => match rest.strip_suffix('R') {
                Some(d) => (d, Side::Right),
                None => (rest, Side::Both),
            },
        };
        self.slots(digits.parse().ok()?, side)
    }

    /// The slots of action unit `au` on `side`; `None` if the model has no such AU.
    pub fn slots(&self, au: u32, side: Side) -> Option<Vec<usize>> {
        let k = self.aus.iter().position(|a| a.number == au)?;
        Some(match side {
            Side::Left => vec![2 * k],
            Side::Right => vec![2 * k + 1],
            Side::Both => vec![2 * k, 2 * k + 1],
        })
    }

    /// The name of a slot: `AU12L` or `AU12R`.
    pub fn slot_name(&self, slot: usize) -> String {
        let side = if slot.is_multiple_of(2) { 'L' } else { 'R' };
        format!("AU{}{side}", self.aus[slot / 2].number)
    }

    /// The AU slots and weights of face lexeme `name`.
    pub fn lexeme(&self, name: &str) -> Option<&[(usize, f32)]> {
        (self.lexemes.iter())
            .find(|(n, _)| n == name)
            .map(|(_, s)| s.as_slice())
    }

    /// The lexemes the model binds, in order.
    pub fn lexemes(&self) -> impl Iterator<Item = &str> {
        self.lexemes.iter().map(|(n, _)| n.as_str())
    }

    /// The blendshapes of viseme `k` (an index into [`VISEMES`]).
    pub fn viseme(&self, k: usize) -> &[(usize, f32)] {
        self.visemes.get(k).map_or(&[], |v| v.as_slice())
    }

    /// Completes `face.morphs`: the blendshapes the action units drive (contributions add up,
    /// clamped to 1), combined by maximum with the direct targets already there.
    pub fn finish(&self, face: &mut Face) {
        let mut driven = [0.0f32; 52];
        for (slot, &w) in face.aus.0.iter().enumerate() {
            if w <= 0.0 {
                continue;
            }
            for &(m, weight) in &self.aus[slot / 2].drives[slot % 2] {
                driven[m] += w * weight;
            }
        }
        for (out, d) in face.morphs.0.iter_mut().zip(driven) {
            *out = out.max(d.min(1.0));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_model_has_every_bml_lexeme_and_the_15_visemes() {
        let m = FaceModel::default_model();
        for l in crate::language::bml::FACE_LEXEMES {
            assert!(m.lexeme(l).is_some(), "{l}");
        }
        assert_eq!(m.visemes.len(), 15);
        assert!(m.viseme(0).is_empty(), "sil moves nothing");
        let brows = m.lexeme("RAISE_LEFT_BROW").unwrap();
        assert!(
            brows.iter().all(|(s, _)| s.is_multiple_of(2)),
            "the left side only"
        );
        assert_eq!(m.slot_name(brows[0].0), "AU1L");
    }

    #[test]
    fn action_units_drive_blendshapes_and_both_sides_make_the_full_weight() {
        let m = FaceModel::default_model();
        let mut face = Face::neutral(m);
        for s in m.slots(1, Side::Both).unwrap() {
            face.raise(s, 1.0);
        }
        face.raise(m.slots(12, Side::Left).unwrap()[0], 0.5);
        m.finish(&mut face);
        assert_eq!(face.morphs.get("browInnerUp"), 1.0);
        assert_eq!(face.morphs.get("mouthSmileLeft"), 0.5);
        assert_eq!(face.morphs.get("mouthSmileRight"), 0.0);
        let bad = FaceModel::from_json(
            r#"{"aus": {"1": {"name": "x", "left": [["browUp", 1]], "right": []}}}"#,
            LEXEMES,
            VISEME_SHAPES,
        );
        assert!(bad
            .unwrap_err()
            .contains("'browUp' is not an ARKit blendshape"));
    }
}
