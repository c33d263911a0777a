//! The frames file (`bmlr run --frames OUT.jsonl`): the realized motion for tools and tests, as
//! JSON lines. Line 1 is a header with the frame rate, the skeleton (each joint's name, parent and
//! rest translation from the parent, metres) and the characters; then one line per frame with
//! each character's root (HumanoidRoot's world position and rotation) and every joint's local
//! rotation relative to the rest pose (quaternion `[x, y, z, w]`; the rest pose is identity),
//! and its face: the action units that are not 0 (`AU1` when both sides are equal, else `AU1L`
//! and `AU1R`), the ARKit blendshapes that are not 0, and the viseme while speaking.
//! Numbers are rounded to 6 decimals so that files diff well and stay deterministic.

use indexmap::IndexMap;
use serde::Serialize;

use super::CharacterPose;
use crate::character::body::Skeleton;
use crate::character::face::{Face, FaceModel, ARKIT, VISEMES};

/// Feet on the ground, as a frame writes them.
#[derive(Serialize)]
struct Contacts {
    l: bool,
    r: bool,
}

#[derive(Serialize)]
struct EventLine<'a> {
    kind: &'static str,
    id: &'a str,
    offset: f64,
}

/// Line 1.
#[derive(Serialize)]
struct Header<'a> {
    fps: f64,
    skeleton: SkeletonLine<'a>,
    /// Character ids in the order of the frames' `characters` (the default character is `""`).
    characters: &'a [&'a str],
    /// Present (true) when the frames carry only where each character stands.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    roots_only: bool,
    /// The POSIX time (s) of the frames' time 0, where they were taken on a real-time clock
    /// (a served realizer's), so that frames of several realizers can be put on one clock.
    #[serde(skip_serializing_if = "Option::is_none")]
    posix_zero: Option<f64>,
}

#[derive(Serialize)]
struct SkeletonLine<'a> {
    joints: Vec<JointLine<'a>>,
}

#[derive(Serialize)]
struct JointLine<'a> {
    name: &'a str,
    parent: Option<&'a str>,
    offset: [f64; 3],
}

#[derive(Serialize)]
struct CharacterLine<'a> {
    root: [f64; 3],
    rotation: [f64; 4],
    joints: IndexMap<&'a str, [f64; 4]>,
    /// The joints the engines turned beyond their limits in this frame (clamped back).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    clamped: Vec<&'a str>,
    #[serde(skip_serializing_if = "IndexMap::is_empty")]
    face: IndexMap<String, f64>,
    #[serde(skip_serializing_if = "IndexMap::is_empty")]
    morphs: IndexMap<&'static str, f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    viseme: Option<&'static str>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    events: Vec<EventLine<'a>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    contacts: Option<Contacts>,
}

/// The action units of `face` that are not 0, one entry for both sides where they are equal.
fn action_units(face: &Face) -> IndexMap<String, f64> {
    let model = FaceModel::default_model();
    let mut out = IndexMap::new();
    for (k, pair) in face.aus.0.chunks(2).enumerate() {
        let (l, r) = (round(pair[0]), round(pair.get(1).copied().unwrap_or(0.0)));
        let number = model.aus.get(k).map_or(0, |a| a.number);
        if l == r && l != 0.0 {
            out.insert(format!("AU{number}"), l);
        } else {
            for (v, side) in [(l, 'L'), (r, 'R')] {
                if v != 0.0 {
                    out.insert(format!("AU{number}{side}"), v);
                }
            }
        }
    }
    out
}

/// The blendshapes of `face` that are not 0.
fn morphs(face: &Face) -> IndexMap<&'static str, f64> {
    (ARKIT.iter().zip(face.morphs.0))
        .map(|(&name, w)| (name, round(w)))
        .filter(|(_, w)| *w != 0.0)
        .collect()
}

fn round(v: f32) -> f64 {
    (f64::from(v) * 1e6).round() / 1e6 + 0.0 // + 0.0: no negative zero in the file
}

fn quat(q: glam::Quat) -> [f64; 4] {
    let q = q.normalize();
    [round(q.x), round(q.y), round(q.z), round(q.w)]
}

/// The header line (without a newline) for frames at `fps` of `characters` on `skeleton`, whose
/// lines carry `detail`.
pub fn header(skeleton: &Skeleton, fps: f64, characters: &[&str], detail: Detail) -> String {
    header_on_clock(skeleton, fps, characters, detail, None)
}

/// The header line of frames taken on a real-time clock whose time 0 was `posix_zero` (POSIX
/// seconds; `None`: not on one).
pub fn header_on_clock(
    skeleton: &Skeleton,
    fps: f64,
    characters: &[&str],
    detail: Detail,
    posix_zero: Option<f64>,
) -> String {
    let joints = skeleton.joints();
    let header = Header {
        fps,
        skeleton: SkeletonLine {
            joints: (joints.iter())
                .map(|j| JointLine {
                    name: &j.name,
                    parent: j.parent.map(|p| joints[p].name.as_str()),
                    offset: [round(j.offset.x), round(j.offset.y), round(j.offset.z)],
                })
                .collect(),
        },
        characters,
        roots_only: detail == Detail::Roots,
        posix_zero,
    };
    serde_json::to_string(&header).expect("a header always encodes")
}

/// What a frame line carries of each character.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Detail {
    /// Pose, clamped joints, face, sound events and foot contacts.
    #[default]
    Full,
    /// Only where each character stands (its root's position and rotation) and, once it has
    /// walked, its foot contacts: for crowds too large to keep every joint.
    Roots,
}

/// Where a character stands, for [`Detail::Roots`].
#[derive(Serialize)]
struct RootLine {
    root: [f64; 3],
    rotation: [f64; 4],
    #[serde(skip_serializing_if = "Option::is_none")]
    contacts: Option<Contacts>,
}

/// One frame's line (without a newline): the time and each character (its id, `""` the default
/// one) in order: its pose, the joints that were clamped into their limits, its face, the
/// sounds that started or stopped since the last frame and, once it has walked, which feet are
/// on the ground.
pub fn line(skeleton: &Skeleton, time: f64, characters: &[(&str, &CharacterPose)]) -> String {
    let parts: Vec<(&str, String)> = (characters.iter())
        .map(|&(id, c)| (id, character(skeleton, c, Detail::Full)))
        .collect();
    let parts: Vec<(&str, &str)> = parts.iter().map(|(id, p)| (*id, p.as_str())).collect();
    line_of(time, &parts)
}

/// One frame's line (without a newline) from each character's id and its JSON object made by
/// [`character`], in order. The same bytes as [`line()`] for the same characters.
pub fn line_of(time: f64, characters: &[(&str, &str)]) -> String {
    let time = (time * 1e6).round() / 1e6;
    let mut out = format!("{{\"time\":{},\"characters\":{{", json(&time));
    for (k, (id, part)) in characters.iter().enumerate() {
        if k > 0 {
            out.push(',');
        }
        out.push_str(&json(id));
        out.push(':');
        out.push_str(part);
    }
    out.push_str("}}");
    out
}

fn json<T: Serialize + ?Sized>(value: &T) -> String {
    serde_json::to_string(value).expect("numbers and strings always encode")
}

/// One character's JSON object in a frame line (see [`line()`]), with the `detail` asked for.
pub fn character(skeleton: &Skeleton, c: &CharacterPose, detail: Detail) -> String {
    let CharacterPose {
        pose,
        clamped,
        face,
        events,
        contacts,
        ..
    } = c;
    let world = pose.world(skeleton);
    let (root, rotation) = (world.positions[0], world.orientations[0]);
    let root = [round(root.x), round(root.y), round(root.z)];
    let contacts = contacts.map(|[l, r]| Contacts { l, r });
    if detail == Detail::Roots {
        return json(&RootLine {
            root,
            rotation: quat(rotation),
            contacts,
        });
    }
    let joints = (skeleton.joints().iter().zip(&pose.rotations))
        .map(|(j, &q)| (j.name.as_str(), quat(q)))
        .collect();
    json(&CharacterLine {
        root,
        rotation: quat(rotation),
        joints,
        clamped: (clamped.iter())
            .map(|&j| skeleton.joints()[j].name.as_str())
            .collect(),
        face: action_units(face),
        morphs: morphs(face),
        viseme: face.viseme.and_then(|v| VISEMES.get(v).copied()),
        events: (events.iter())
            .map(|e| EventLine {
                kind: if e.start { "audio-start" } else { "audio-stop" },
                id: &e.id,
                offset: (e.offset * 1e6).round() / 1e6,
            })
            .collect(),
        contacts,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::character::body::Pose;

    fn at_rest(pose: Pose, clamped: Vec<usize>, contacts: Option<[bool; 2]>) -> CharacterPose {
        CharacterPose {
            character: None,
            pose,
            clamped,
            face: Face::neutral(FaceModel::default_model()),
            sounds: Vec::new(),
            events: Vec::new(),
            contacts,
        }
    }

    #[test]
    fn the_header_names_every_joint_and_a_frame_every_rotation() {
        let s = Skeleton::adult();
        let h: serde_json::Value =
            serde_json::from_str(&header(&s, 60.0, &["", "anna"], Detail::Full)).unwrap();
        assert_eq!(h["fps"], 60.0);
        assert_eq!(h["characters"], serde_json::json!(["", "anna"]));
        let joints = h["skeleton"]["joints"].as_array().unwrap();
        assert_eq!(joints.len(), s.len());
        assert_eq!(joints[0]["parent"], serde_json::Value::Null);
        assert_eq!(joints[0]["offset"], serde_json::json!([0.0, 0.95, 0.0]));
        let mut pose = Pose::rest(&s);
        let elbow = s.joint("l_elbow").unwrap();
        pose.rotate(
            elbow,
            glam::Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2),
        );
        let f: serde_json::Value = serde_json::from_str(&line(
            &s,
            0.5,
            &[("", &at_rest(pose.clone(), vec![], None))],
        ))
        .unwrap();
        assert_eq!(f["time"], 0.5);
        let c = &f["characters"][""];
        assert_eq!(c["root"], serde_json::json!([0.0, 0.95, 0.0]));
        assert_eq!(c["rotation"], serde_json::json!([0.0, 0.0, 0.0, 1.0]));
        assert_eq!(c["joints"].as_object().unwrap().len(), s.len());
        let h = std::f64::consts::FRAC_1_SQRT_2;
        let q = c["joints"]["l_elbow"].as_array().unwrap();
        assert!(
            (q[0].as_f64().unwrap() + h).abs() < 1e-6 && (q[3].as_f64().unwrap() - h).abs() < 1e-6
        );
        assert!(c.get("clamped").is_none(), "only when a joint was clamped");
        let f: serde_json::Value = serde_json::from_str(&line(
            &s,
            0.5,
            &[("", &at_rest(pose, vec![elbow], Some([true, false])))],
        ))
        .unwrap();
        assert_eq!(
            f["characters"][""]["clamped"],
            serde_json::json!(["l_elbow"])
        );
        assert_eq!(
            f["characters"][""]["contacts"],
            serde_json::json!({"l": true, "r": false})
        );
        assert!(
            c.get("contacts").is_none(),
            "only for characters that walked"
        );
    }
}
