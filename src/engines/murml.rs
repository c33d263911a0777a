//! MURML behaviours (`murmlgesture`, `murmlface` in the namespace
//! `http://www.techfak.uni-bielefeld.de/ags/soa/murml`). The `<murml-description>` is read for its
//! timing — a `<keyframing>` lasts until its last `<frame ftime>`, a `<dynamic>` movement or a
//! `<static>` posture gets the default second — and the behaviour is played with gesture syncs
//! (`murmlgesture`) or face syncs (`murmlface`, as the conformance suite expects).
//!
//! The keyframe subset moves the body: in a `murmlgesture`, each `<frame>`'s
//! `<posture>Humanoid (JOINT 3 X Y Z) …</posture>` sets joint rotations (Euler angles in degrees,
//! x then y then z; `(JOINT 1 A)` turns about x), the frames are laid linearly from `start` to
//! `end` (the last frame's time is the preferred length) and slerped, each frame exact at its
//! time; a joint a frame leaves out keeps its previous rotation, names the skeleton lacks are
//! skipped. The keyframing's `easescale`/`easeturningpoint` are not applied (linear time), the
//! procedural MURML parts (hand location, palm orientation, `<static>`) are timing only. In a
//! keyframed `murmlface`, each frame's `(NAME 1 PERCENT)` groups are morph-target weights: those
//! named as ARKit blendshapes (`jawOpen`, `browInnerUp`, …) move the face, linear between frames
//! laid from `start` to `end`; other names (a rig's own targets, as in RealizerTester's file) play
//! their timing only, without a warning (the conformance suite runs that file expecting none).

use quick_xml::events::Event;
use quick_xml::Reader;

use glam::{EulerRot, Quat, Vec3};

use crate::character::body::{Pose, Skeleton};
use crate::engines::interface::{Engine, EngineError, Steering, Unit, Units};
use crate::engines::keyframe::{play, Interpolation, Keys};
use crate::language::bml::{Behaviour, BehaviourKind};
use crate::planning::timing::TimingModel;
use crate::world::World;

/// The MURML namespace.
pub const NS_MURML: &str = "http://www.techfak.uni-bielefeld.de/ags/soa/murml";

/// Duration of a MURML description without keyframes.
pub const DEFAULT_DURATION: f64 = 1.0;

/// How long a MURML description lasts: its last keyframe time, or [`DEFAULT_DURATION`]. `Err` if
/// the content is not well-formed XML.
pub fn duration(content: &str) -> Result<f64, String> {
    let mut reader = Reader::from_str(content);
    let mut last: Option<f64> = None;
    loop {
        match reader.read_event() {
            Ok(Event::Start(e)) | Ok(Event::Empty(e)) if e.local_name().as_ref() == b"frame" => {
                let t = e
                    .attributes()
                    .flatten()
                    .find(|a| a.key.local_name().as_ref() == b"ftime")
                    .and_then(|a| a.unescape_value().ok()?.trim().parse::<f64>().ok());
                match t {
                    Some(t) if t.is_finite() && t >= 0.0 => {
                        last = Some(last.map_or(t, |l: f64| l.max(t)))
                    }
                    _ => return Err("a MURML <frame> needs a time ftime >= 0".into()),
                }
            }
            Ok(Event::Eof) => break,
            Err(e) => return Err(format!("the MURML description is not well-formed: {e}")),
            Ok(_) => {}
        }
    }
    Ok(last.filter(|&d| d > 0.0).unwrap_or(DEFAULT_DURATION))
}

/// Every `<frame ftime>`'s `<posture>` text, with the frame's time, in document order.
fn postures(content: &str) -> Result<Vec<(f64, String)>, String> {
    let mut reader = Reader::from_str(content);
    let mut out = Vec::new();
    let (mut time, mut in_posture, mut text) = (None, false, String::new());
    loop {
        match reader.read_event() {
            Ok(Event::Start(e)) | Ok(Event::Empty(e)) if e.local_name().as_ref() == b"frame" => {
                time = e
                    .attributes()
                    .flatten()
                    .find(|a| a.key.local_name().as_ref() == b"ftime")
                    .and_then(|a| a.unescape_value().ok()?.trim().parse::<f64>().ok())
                    .filter(|t| t.is_finite() && *t >= 0.0);
                if time.is_none() {
                    return Err("a MURML <frame> needs a time ftime >= 0".into());
                }
            }
            Ok(Event::Start(e)) if e.local_name().as_ref() == b"posture" => {
                in_posture = true;
                text.clear();
            }
            Ok(Event::Text(t)) if in_posture => text.push_str(&String::from_utf8_lossy(&t)),
            Ok(Event::End(e)) if e.local_name().as_ref() == b"posture" => {
                in_posture = false;
                let t = time.ok_or("a MURML <posture> outside a <frame>")?;
                out.push((t, std::mem::take(&mut text)));
            }
            Ok(Event::Eof) => break,
            Err(e) => return Err(format!("the MURML description is not well-formed: {e}")),
            Ok(_) => {}
        }
    }
    Ok(out)
}

/// The body keys of a keyframed description: every frame's `<posture>` joint rotations, sorted
/// by time; `None` if it has no frame with a posture.
pub fn body_keys(content: &str) -> Result<Option<Keys>, String> {
    let mut frames: Vec<(f64, Vec<(String, Quat)>)> = (postures(content)?.into_iter())
        .map(|(t, text)| Ok((t, posture(&text)?)))
        .collect::<Result<_, String>>()?;
    if frames.is_empty() {
        return Ok(None);
    }
    frames.sort_by(|a, b| a.0.total_cmp(&b.0));
    frames.dedup_by(|later, earlier| {
        let same = later.0 == earlier.0;
        if same {
            earlier.1 = std::mem::take(&mut later.1);
        }
        same
    });
    let mut parts: Vec<String> = Vec::new();
    for (_, joints) in &frames {
        for (j, _) in joints {
            if !parts.contains(j) {
                parts.push(j.clone());
            }
        }
    }
    // a joint a frame leaves out keeps its previous rotation
    let mut current = vec![Quat::IDENTITY; parts.len()];
    let keys = frames
        .into_iter()
        .map(|(t, joints)| {
            for (j, q) in joints {
                if let Some(i) = parts.iter().position(|p| *p == j) {
                    current[i] = q;
                }
            }
            (t, Vec3::ZERO, current.clone())
        })
        .collect();
    Ok(Some(Keys {
        parts,
        root_translation: false,
        keys,
    }))
}

/// Reads `Humanoid (NAME N V…) …`: each group's name and values.
fn groups(text: &str) -> Result<Vec<(String, Vec<f32>)>, String> {
    let mut out = Vec::new();
    let mut rest = text.trim();
    if let Some(r) = rest.strip_prefix("Humanoid") {
        rest = r;
    }
    while let Some(open) = rest.find('(') {
        let close = rest[open..]
            .find(')')
            .ok_or_else(|| format!("unclosed '(' in MURML posture '{}'", text.trim()))?;
        let group: Vec<&str> = rest[open + 1..open + close].split_whitespace().collect();
        rest = &rest[open + close + 1..];
        let bad = || {
            format!(
                "MURML posture group '({})' is not (JOINT N VALUES…)",
                group.join(" ")
            )
        };
        let (name, n) = match group.as_slice() {
            [name, n, ..] => (*name, n.parse::<usize>().map_err(|_| bad())?),
            _ => return Err(bad()),
        };
        let values: Vec<f32> = group[2..]
            .iter()
            .map(|v| v.parse::<f32>().ok().filter(|v| v.is_finite()))
            .collect::<Option<_>>()
            .ok_or_else(bad)?;
        if values.len() != n {
            return Err(bad());
        }
        out.push((name.to_string(), values));
    }
    Ok(out)
}

/// Reads `Humanoid (JOINT N V…) …`: joints with 3 Euler angles (x, y, z degrees) or 1 (about x).
fn posture(text: &str) -> Result<Vec<(String, Quat)>, String> {
    Ok(groups(text)?
        .into_iter()
        .filter_map(|(name, values)| {
            let q = match values.as_slice() {
                [x, y, z] => Quat::from_euler(
                    EulerRot::XYZ,
                    x.to_radians(),
                    y.to_radians(),
                    z.to_radians(),
                ),
                [a] => Quat::from_rotation_x(a.to_radians()),
                // other channels do not turn a joint
                _ => return None,
            };
            Some((name, q))
        })
        .collect())
}

/// Blendshape keys: (time, [(blendshape index, weight)]) per frame, in time order.
pub type MorphKeys = Vec<(f64, Vec<(usize, f32)>)>;

/// The morph keys of a keyframed `murmlface`: for each frame (time, in order), the weight (0–1;
/// MURML gives percent) of each ARKit blendshape its `(NAME 1 PERCENT)` groups name. Groups with
/// other names (a rig's own morph targets) are left out.
pub fn morph_keys(content: &str) -> Result<MorphKeys, String> {
    let mut frames: MorphKeys = Vec::new();
    for (t, text) in postures(content)? {
        let morphs = (groups(&text)?.into_iter())
            .filter_map(|(name, v)| match v.as_slice() {
                [percent] => Some((
                    crate::character::face::model::morph_index(&name)?,
                    (percent / 100.0).clamp(0.0, 1.0),
                )),
                _ => None,
            })
            .collect();
        frames.push((t, morphs));
    }
    frames.sort_by(|a, b| a.0.total_cmp(&b.0));
    Ok(frames)
}

/// The weight of blendshape `m` at time `t` of morph keys `keys` (linear between frames; a frame
/// that leaves `m` out has it at 0).
fn morph_at(keys: &[(f64, Vec<(usize, f32)>)], m: usize, t: f64) -> f32 {
    let w = |k: &(f64, Vec<(usize, f32)>)| k.1.iter().find(|x| x.0 == m).map_or(0.0, |x| x.1);
    let i = keys.partition_point(|k| k.0 <= t);
    match (i.checked_sub(1).map(|j| &keys[j]), keys.get(i)) {
        (Some(a), Some(b)) if b.0 > a.0 => w(a) + (w(b) - w(a)) * ((t - a.0) / (b.0 - a.0)) as f32,
        (Some(a), _) => w(a),
        (None, Some(b)) => w(b),
        (None, None) => 0.0,
    }
}

/// The two MURML kinds.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Kind {
    Gesture,
    Face,
}

fn kind(b: &Behaviour) -> Option<(Kind, &str)> {
    match &b.kind {
        BehaviourKind::Unknown(u) if u.ns == NS_MURML && u.name == "murmlgesture" => {
            Some((Kind::Gesture, &u.content))
        }
        BehaviourKind::Unknown(u) if u.ns == NS_MURML && u.name == "murmlface" => {
            Some((Kind::Face, &u.content))
        }
        _ => None,
    }
}

#[derive(Debug, Clone)]
struct MurmlUnit {
    /// Body keys of a keyframed `murmlgesture`.
    keys: Option<Keys>,
    /// Blendshape keys of a keyframed `murmlface`, and the length they were written for.
    morphs: MorphKeys,
    length: f64,
    /// The blendshapes its keys name, each once.
    shapes: Vec<usize>,
    /// The skeleton joint of each part, resolved on first use.
    joints: Option<Vec<Option<usize>>>,
}

/// The MURML engine (see the module documentation).
#[derive(Debug, Default)]
pub struct MurmlEngine {
    units: Units<MurmlUnit>,
}

impl Engine for MurmlEngine {
    crate::units_remove!();
    crate::units_retime_len!();
    crate::units_play!("murml");
    crate::units_interrupt!(crate::engines::interface::relax_now);

    fn name(&self) -> &'static str {
        "murml"
    }

    fn timing(&self, behaviour: &Behaviour) -> Option<TimingModel> {
        let (k, content) = kind(behaviour)?;
        // a malformed description is refused when the unit is added, with the reason
        let d = duration(content).unwrap_or(DEFAULT_DURATION);
        Some(match k {
            Kind::Gesture => TimingModel::gesture(d),
            Kind::Face => TimingModel::face(d),
        })
    }

    fn add(&mut self, unit: Unit<'_>) -> Result<(), EngineError> {
        let (k, content) = kind(unit.behaviour).ok_or_else(|| {
            EngineError("the MURML engine realizes murmlgesture and murmlface".into())
        })?;
        let length = duration(content).map_err(EngineError)?;
        let fail = |e: String| EngineError(format!("{}: {e}", unit.key));
        let (keys, morphs) = match k {
            Kind::Gesture => (body_keys(content).map_err(fail)?, Vec::new()),
            Kind::Face => (None, morph_keys(content).map_err(fail)?),
        };
        let mut shapes: Vec<usize> = (morphs.iter())
            .flat_map(|k| k.1.iter().map(|x| x.0))
            .collect();
        shapes.sort_unstable();
        shapes.dedup();
        let data = MurmlUnit {
            keys,
            morphs,
            length,
            shapes,
            joints: None,
        };
        self.units.add(unit, data);
        Ok(())
    }

    fn as_motion(&mut self) -> Option<&mut dyn crate::engines::interface::Motion> {
        Some(self)
    }

    fn as_resources(&self) -> Option<&dyn crate::engines::interface::Resources> {
        Some(self)
    }

    fn as_expression(&mut self) -> Option<&mut dyn crate::engines::interface::Expression> {
        Some(self)
    }
}

impl crate::engines::interface::Expression for MurmlEngine {
    /// The blendshapes of every `murmlface` playing: its frames laid linearly from `start` to
    /// `end`.
    fn express(&mut self, now: f64, face: &mut crate::character::face::Face) {
        for (syncs, u) in self.units.started(now) {
            let (Some(start), Some(end)) = (syncs.first(), syncs.last()) else {
                continue;
            };
            if u.morphs.is_empty() || now > end.1 || end.1 <= start.1 {
                continue;
            }
            let t = (now - start.1) / (end.1 - start.1) * u.length;
            for &m in &u.shapes {
                face.raise_morph(m, morph_at(&u.morphs, m, t));
            }
        }
    }
}

impl crate::engines::interface::Motion for MurmlEngine {
    fn steers(&self, behaviour: &Behaviour, skeleton: &Skeleton) -> Option<Steering> {
        let (Kind::Gesture, content) = kind(behaviour)? else {
            return None;
        };
        let keys = body_keys(content).ok()??;
        Some(Steering::kinematic(
            skeleton,
            keys.parts.iter().map(String::as_str),
            false,
        ))
    }

    fn animate(&mut self, now: f64, skeleton: &Skeleton, _world: &World, pose: &mut Pose) {
        for (syncs, u) in self.units.all_mut() {
            let Some(k) = &u.keys else { continue };
            let joints = u
                .joints
                .get_or_insert_with(|| k.parts.iter().map(|p| skeleton.joint(p)).collect());
            play((k, Interpolation::Slerp, &[]), joints, syncs, now, pose);
        }
    }
}

impl crate::engines::interface::Resources for MurmlEngine {
    fn resources(&self, behaviour: &Behaviour) -> &'static [&'static str] {
        match kind(behaviour) {
            Some((Kind::Gesture, _)) => &["left_hand", "right_hand"],
            Some((Kind::Face, _)) => &["face"],
            None => &[],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keyframe_postures_are_read_as_joint_rotations_frame_by_frame() {
        let k = body_keys(
            r#"<murml-description><dynamic><keyframing><phase>
                 <frame ftime="1"><posture>Humanoid (l_shoulder 3 90 0 0) (l_elbow 1 30)</posture></frame>
                 <frame ftime="0"><posture>Humanoid (l_shoulder 3 0 0 0)</posture></frame>
                 <frame ftime="2"><posture>Humanoid (l_elbow 1 0)</posture></frame>
               </phase></keyframing></dynamic></murml-description>"#,
        )
        .unwrap()
        .unwrap();
        assert_eq!(k.parts, ["l_shoulder", "l_elbow"]);
        let times: Vec<f64> = k.keys.iter().map(|x| x.0).collect();
        assert_eq!(times, [0.0, 1.0, 2.0]);
        let q = |deg: f32| Quat::from_rotation_x(deg.to_radians());
        let same = |a: Quat, b: Quat| 1.0 - a.dot(b).abs() < 1e-6;
        assert!(same(k.keys[1].2[0], q(90.0)));
        assert!(same(k.keys[1].2[1], q(30.0)));
        // the shoulder is left out of the last frame: it keeps 90°
        assert!(same(k.keys[2].2[0], q(90.0)));
        assert!(same(k.keys[2].2[1], q(0.0)));
        assert!(body_keys(
            r#"<frame ftime="0"><posture>Humanoid (l_elbow 3 1 2)</posture></frame>"#
        )
        .unwrap_err()
        .contains("(l_elbow 3 1 2)"));
        assert_eq!(
            body_keys("<murml-description><static/></murml-description>"),
            Ok(None)
        );
    }

    #[test]
    fn a_keyframed_description_lasts_until_its_last_frame() {
        let d = duration(
            r#"<murml-description><dynamic><keyframing><phase>
                 <frame ftime="0"><posture>Humanoid (l_shoulder 3 0 0 0)</posture></frame>
                 <frame ftime="2.5"/><frame ftime="1"/>
               </phase></keyframing></dynamic></murml-description>"#,
        );
        assert_eq!(d, Ok(2.5));
        assert_eq!(
            duration(r#"<murml-description><dynamic slot="PalmOrientation"/></murml-description>"#),
            Ok(DEFAULT_DURATION)
        );
        assert!(duration(r#"<frame ftime="soon"/>"#).is_err());
        // the keyframes' length is the gesture's, its syncs at the usual places
        let m = TimingModel::gesture(2.5);
        assert_eq!(m.preferred_duration(), 2.5);
        assert!((m.keys[m.key("stroke").unwrap()].at - 1.25).abs() < 1e-12);
        let f = TimingModel::face(3.0);
        assert!((f.keys[f.key("attackPeak").unwrap()].at - 0.6).abs() < 1e-12);
        assert!(duration(r#"<murml-description><frame></murml-description>"#).is_err());
    }
}
