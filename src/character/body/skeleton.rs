//! Skeletons: joints with H-Anim names in a tree, each with its rest translation from its parent.
//! The default adult is embedded (`fixtures/skeletons/adult.json`); others load from the same JSON
//! format: `{"name": …, "joints": [{"name": …, "parent": … | null, "offset": [x, y, z]}, …]}`,
//! parents before children.

use glam::Vec3;
use rustc_hash::FxHashMap;

use super::limits::Limits;

/// The embedded default adult.
const ADULT: &str = include_str!("../../../fixtures/skeletons/adult.json");

/// The default adult's spine from the lower back to the skull, in order: the joints between
/// the pelvis (`sacroiliac`) and the head.
pub const ADULT_SPINE: [&str; 6] = ["vl5", "vt12", "vt6", "vc7", "vc4", "skullbase"];

/// The other side's joint name: `l_…` ↔ `r_…`; other joints are their own mirror image.
pub fn mirror_name(joint: &str) -> String {
    if let Some(rest) = joint.strip_prefix("r_") {
        format!("l_{rest}")
    } else if let Some(rest) = joint.strip_prefix("l_") {
        format!("r_{rest}")
    } else {
        joint.to_string()
    }
}

/// One joint.
#[derive(Debug, Clone, PartialEq)]
pub struct Joint {
    /// H-Anim name, e.g. `skullbase`.
    pub name: String,
    /// Index of the parent joint (`None` for the root).
    pub parent: Option<usize>,
    /// Rest translation from the parent joint (metres, parent frame).
    pub offset: Vec3,
}

/// A joint tree; joints are stored parents first.
#[derive(Debug, Clone, PartialEq)]
pub struct Skeleton {
    /// Its name.
    pub name: String,
    joints: Vec<Joint>,
    /// Joint indices by name. Engines look joints up by name every frame (a procedural unit's
    /// rotations are data): with the std hasher this was a tenth of a mixed 100-character frame.
    index: FxHashMap<String, usize>,
    /// Each joint's mirror image (`l_…` ↔ `r_…`, others themselves), if the skeleton has it.
    mirror: Vec<Option<usize>>,
    limits: Limits,
}

/// Why a skeleton file was refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("skeleton: {0}")]
pub struct SkeletonError(pub String);

/// A skeleton file as written.
#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct SkeletonFile {
    #[serde(default = "unnamed")]
    name: String,
    #[serde(default, rename = "units")]
    _units: crate::data::Note,
    /// For people reading the file.
    #[serde(default, rename = "description")]
    _description: crate::data::Note,
    joints: Vec<JointFile>,
}

fn unnamed() -> String {
    "unnamed".into()
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct JointFile {
    name: String,
    parent: Option<String>,
    offset: [f32; 3],
}

impl Skeleton {
    /// The default adult (read from its embedded JSON once per process, then copied).
    pub fn adult() -> Skeleton {
        static ADULT_SKELETON: std::sync::LazyLock<Skeleton> = std::sync::LazyLock::new(|| {
            let s = Skeleton::from_json(ADULT).expect("the embedded adult skeleton is valid");
            let limits = Limits::from_json(super::limits::ADULT_LIMITS, &s)
                .expect("the embedded adult limits are valid");
            s.with_limits(limits)
        });
        ADULT_SKELETON.clone()
    }

    /// Reads a skeleton from JSON (see the module documentation).
    pub fn from_json(text: &str) -> Result<Skeleton, SkeletonError> {
        let e = |m: String| SkeletonError(m);
        let file: SkeletonFile = crate::data::from_json(text).map_err(e)?;
        let mut s = Skeleton {
            name: file.name,
            joints: Vec::new(),
            index: FxHashMap::default(),
            mirror: Vec::new(),
            limits: Limits::default(),
        };
        for (i, j) in file.joints.into_iter().enumerate() {
            if j.name.is_empty() {
                return Err(e(format!("joint {i} has no name")));
            }
            let parent = match &j.parent {
                None => None,
                Some(p) => Some(*s.index.get(p).ok_or_else(|| {
                    e(format!(
                        "joint '{}': parent '{p}' is not defined before it",
                        j.name
                    ))
                })?),
            };
            if parent.is_none() && !s.joints.is_empty() {
                return Err(e(format!("joint '{}' is a second root", j.name)));
            }
            if !j.offset.iter().all(|v| v.is_finite()) {
                return Err(e(format!(
                    "joint '{}': offset must be three numbers",
                    j.name
                )));
            }
            if s.index.insert(j.name.clone(), s.joints.len()).is_some() {
                return Err(e(format!("joint '{}' is defined twice", j.name)));
            }
            s.joints.push(Joint {
                name: j.name,
                parent,
                offset: Vec3::from_array(j.offset),
            });
        }
        if s.joints.is_empty() {
            return Err(e("no joints".into()));
        }
        s.mirror = (s.joints.iter())
            .map(|j| s.joint(&mirror_name(&j.name)))
            .collect();
        Ok(s)
    }

    /// This skeleton with joint limits (read for it with [`Limits::from_json`]).
    pub fn with_limits(mut self, limits: Limits) -> Skeleton {
        self.limits = limits;
        self
    }

    /// Its joint limits (the default adult's are embedded; a skeleton read from a file has none,
    /// every joint free, until [`with_limits`](Self::with_limits)).
    pub fn limits(&self) -> &Limits {
        &self.limits
    }

    /// The joints, parents before children.
    pub fn joints(&self) -> &[Joint] {
        &self.joints
    }

    /// Number of joints.
    pub fn len(&self) -> usize {
        self.joints.len()
    }

    /// Whether there are no joints (never true for a loaded skeleton).
    pub fn is_empty(&self) -> bool {
        self.joints.is_empty()
    }

    /// The index of joint `name`.
    pub fn joint(&self, name: &str) -> Option<usize> {
        self.index.get(name).copied()
    }

    /// The index of joint `name`, or of its mirror image (`l_…` ↔ `r_…`) when `mirrored`.
    pub fn joint_mirrored(&self, name: &str, mirrored: bool) -> Option<usize> {
        match self.joint(name) {
            Some(i) if mirrored => self.mirror[i],
            Some(i) => Some(i),
            // a joint this skeleton lacks may still have its mirror image here
            None if mirrored => self.joint(&mirror_name(name)),
            None => None,
        }
    }

    /// The children of joint `i`.
    pub fn children(&self, i: usize) -> impl Iterator<Item = usize> + '_ {
        self.joints
            .iter()
            .enumerate()
            .filter(move |(_, j)| j.parent == Some(i))
            .map(|(k, _)| k)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_adult_has_the_h_anim_joints_a_realizer_needs() {
        let s = Skeleton::adult();
        for name in [
            "HumanoidRoot",
            "sacroiliac",
            "l_eyeball_joint",
            "r_eyeball_joint",
            "l_shoulder",
            "l_elbow",
            "l_wrist",
            "l_index1",
            "l_index3",
            "r_shoulder",
            "r_wrist",
            "r_index1",
            "l_hip",
            "l_knee",
            "l_talocrural",
            "r_talocrural",
        ]
        .into_iter()
        .chain(ADULT_SPINE)
        {
            assert!(s.joint(name).is_some(), "{name}");
        }
        assert_eq!(s.joints()[0].name, "HumanoidRoot");
        let skull = s.joint("skullbase").unwrap();
        assert_eq!(s.joints()[skull].parent, s.joint("vc4"));
        assert_eq!(s.children(s.joint("vt6").unwrap()).count(), 3); // neck and both clavicles
    }

    #[test]
    fn bad_skeleton_files_are_refused_with_a_reason() {
        let bad = |t: &str| Skeleton::from_json(t).unwrap_err().0;
        assert!(bad("{").contains("EOF while parsing"), "{}", bad("{"));
        assert_eq!(bad(r#"{"joints": []}"#), "no joints");
        assert!(
            bad(r#"{"joints": [{"name": "a", "parent": "b", "offset": [0,0,0]}]}"#)
                .contains("not defined before it")
        );
        assert!(
            bad(r#"{"joints": [{"name": "a", "parent": null, "offset": [0,0]}]}"#)
                .starts_with("joints[0].offset: invalid length 2")
        );
        assert!(bad(
            r#"{"joints": [{"name": "a", "parent": null, "offset": [0,0,0]},
                                    {"name": "a", "parent": "a", "offset": [0,0,0]}]}"#
        )
        .contains("twice"));
        assert!(bad(
            r#"{"joints": [{"name": "a", "parent": null, "offset": [0,0,0]},
                                    {"name": "b", "parent": null, "offset": [0,0,0]}]}"#
        )
        .contains("second root"));
        // a misspelled field is named, not ignored
        assert!(
            bad(r#"{"joints": [{"name": "a", "parnet": null, "offset": [0,0,0]}]}"#)
                .starts_with("joints[0].parnet: unknown field `parnet`")
        );
    }
}
