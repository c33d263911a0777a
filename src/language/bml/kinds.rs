//! Facts about each behaviour kind: its element name and namespace, its sync points,
//! and whether its sync points are open (defined by animation data rather than by BML).

use super::model::{Behaviour, BehaviourKind, NS_BML, NS_BMLA, NS_BMLT, NS_CORE_EXT};
use std::borrow::Cow;

/// gesture, pointing, head (and BMLT procanimationgesture).
pub const GESTURE_SYNCS: &[&str] = &[
    "start",
    "ready",
    "strokeStart",
    "stroke",
    "strokeEnd",
    "relax",
    "end",
];
/// gaze, posture, locomotion.
pub const GAZE_SYNCS: &[&str] = &["start", "ready", "relax", "end"];
/// face, faceLexeme, faceFacs (and BMLT facemorph).
pub const FACE_SYNCS: &[&str] = &["start", "attackPeak", "relax", "end"];
/// Everything else: start and end only.
pub const START_END: &[&str] = &["start", "end"];
/// Every standard sync point name, used as the sync attributes of unknown extension behaviours.
pub const ALL_STANDARD_SYNCS: &[&str] = &[
    "start",
    "ready",
    "strokeStart",
    "stroke",
    "strokeEnd",
    "attackPeak",
    "relax",
    "end",
];

/// The 15 BML 1.0 core behaviour elements (`faceFacs` is also accepted in the core-extensions
/// namespace).
pub const CORE_BEHAVIOURS: &[&str] = &[
    "speech",
    "gesture",
    "pointing",
    "head",
    "headDirectionShift",
    "gaze",
    "gazeShift",
    "face",
    "faceLexeme",
    "faceFacs",
    "faceShift",
    "posture",
    "postureShift",
    "locomotion",
    "wait",
];
/// The control behaviours, accepted in both the BMLA and the BMLT namespace.
pub const CONTROL_BEHAVIOURS: &[&str] = &["interrupt", "activate", "parametervaluechange"];
/// The BMLT behaviour elements.
pub const BMLT_BEHAVIOURS: &[&str] = &[
    "procanimation",
    "procanimationgesture",
    "keyframe",
    "controller",
    "audiofile",
    "noise",
    "facemorph",
    "transition",
    "text",
];

/// Every built-in kind's element name and the namespace it is written in, in the order of
/// [`BehaviourKind::builtin_slot`] (the control behaviours are also read in BMLT).
pub const BUILTIN_KINDS: [(&str, &str); 27] = [
    ("speech", NS_BML),
    ("gesture", NS_BML),
    ("pointing", NS_BML),
    ("head", NS_BML),
    ("headDirectionShift", NS_BML),
    ("gaze", NS_BML),
    ("gazeShift", NS_BML),
    ("face", NS_BML),
    ("faceLexeme", NS_BML),
    ("faceFacs", NS_CORE_EXT),
    ("faceShift", NS_BML),
    ("posture", NS_BML),
    ("postureShift", NS_BML),
    ("locomotion", NS_BML),
    ("wait", NS_BML),
    ("interrupt", NS_BMLA),
    ("activate", NS_BMLA),
    ("parametervaluechange", NS_BMLA),
    ("procanimation", NS_BMLT),
    ("procanimationgesture", NS_BMLT),
    ("keyframe", NS_BMLT),
    ("controller", NS_BMLT),
    ("audiofile", NS_BMLT),
    ("noise", NS_BMLT),
    ("facemorph", NS_BMLT),
    ("transition", NS_BMLT),
    ("text", NS_BMLT),
];

impl BehaviourKind {
    /// The element's local name.
    pub fn element_name(&self) -> &str {
        match self {
            BehaviourKind::Unknown(u) => &u.name,
            k => k.builtin_name(),
        }
    }

    /// [`Self::element_name`] as an id: static for the built-in kinds (nothing copied).
    pub fn element_id(&self) -> super::Id {
        match self {
            BehaviourKind::Unknown(u) => super::Id::new(&u.name),
            k => super::Id::new_static(k.builtin_name()),
        }
    }

    /// The position of a built-in kind in [`BUILTIN_KINDS`] (`None` for an unknown extension):
    /// a number that registries can index by.
    pub fn builtin_slot(&self) -> Option<usize> {
        Some(match self {
            BehaviourKind::Speech(_) => 0,
            BehaviourKind::Gesture(_) => 1,
            BehaviourKind::Pointing(_) => 2,
            BehaviourKind::Head(_) => 3,
            BehaviourKind::HeadDirectionShift { .. } => 4,
            BehaviourKind::Gaze(_) => 5,
            BehaviourKind::GazeShift(_) => 6,
            BehaviourKind::Face(_) => 7,
            BehaviourKind::FaceLexeme(_) => 8,
            BehaviourKind::FaceFacs(_) => 9,
            BehaviourKind::FaceShift(_) => 10,
            BehaviourKind::Posture(_) => 11,
            BehaviourKind::PostureShift(_) => 12,
            BehaviourKind::Locomotion(_) => 13,
            BehaviourKind::Wait(_) => 14,
            BehaviourKind::Interrupt(_) => 15,
            BehaviourKind::Activate(_) => 16,
            BehaviourKind::ParameterValueChange(_) => 17,
            BehaviourKind::ProcAnimation(_) => 18,
            BehaviourKind::ProcAnimationGesture(_) => 19,
            BehaviourKind::Keyframe(_) => 20,
            BehaviourKind::Controller(_) => 21,
            BehaviourKind::AudioFile { .. } => 22,
            BehaviourKind::Noise(_) => 23,
            BehaviourKind::FaceMorph(_) => 24,
            BehaviourKind::Transition(_) => 25,
            BehaviourKind::Text(_) => 26,
            BehaviourKind::Unknown(_) => return None,
        })
    }

    /// The local name of a built-in kind (`""` for an unknown extension).
    fn builtin_name(&self) -> &'static str {
        self.builtin_slot().map_or("", |s| BUILTIN_KINDS[s].0)
    }

    /// The namespace the writer puts the element in.
    pub fn namespace(&self) -> &str {
        match self {
            BehaviourKind::Unknown(u) => &u.ns,
            k => k.builtin_slot().map_or("", |s| BUILTIN_KINDS[s].1),
        }
    }

    /// The standard sync points of this kind, in their required time order (speech's inline sync
    /// points come on top, see [`Behaviour::sync_points`]). These are also the names of the
    /// shorthand sync attributes the element accepts.
    pub fn standard_syncs(&self) -> &'static [&'static str] {
        match self {
            BehaviourKind::Gesture(_)
            | BehaviourKind::Pointing(_)
            | BehaviourKind::Head(_)
            | BehaviourKind::ProcAnimationGesture(_) => GESTURE_SYNCS,
            BehaviourKind::Gaze(_) | BehaviourKind::Posture(_) | BehaviourKind::Locomotion(_) => {
                GAZE_SYNCS
            }
            BehaviourKind::Face(_)
            | BehaviourKind::FaceLexeme(_)
            | BehaviourKind::FaceFacs(_)
            | BehaviourKind::FaceMorph(_) => FACE_SYNCS,
            BehaviourKind::Unknown(_) => ALL_STANDARD_SYNCS,
            _ => START_END,
        }
    }

    /// Whether the kind may have sync points beyond its standard ones that only its animation data
    /// defines (BMLT procanimation, keyframe, controller; unknown extensions). References to such
    /// sync points cannot be checked statically.
    pub fn has_open_syncs(&self) -> bool {
        matches!(
            self,
            BehaviourKind::ProcAnimation(_)
                | BehaviourKind::ProcAnimationGesture(_)
                | BehaviourKind::Keyframe(_)
                | BehaviourKind::Controller(_)
                | BehaviourKind::Unknown(_)
        )
    }

    /// Whether this is one of the 15 BML 1.0 core behaviours.
    pub fn is_core(&self) -> bool {
        self.namespace() == NS_BML || matches!(self, BehaviourKind::FaceFacs(_))
    }
}

impl Behaviour {
    /// All sync points of the behaviour in time order: the standard ones, with speech's inline
    /// sync points between `start` and `end` and a repeated head's later strokes (`stroke:1` …
    /// `stroke:N-1`, as OpenBMLParser numbers them) after `stroke`.
    pub fn sync_points(&self) -> Vec<Cow<'_, str>> {
        match &self.kind {
            BehaviourKind::Speech(s) | BehaviourKind::Text(s) => {
                let inline = s.sync_ids().map(Cow::Borrowed);
                let mut v = vec![Cow::Borrowed("start")];
                v.extend(inline);
                v.push(Cow::Borrowed("end"));
                v
            }
            k => {
                let mut v: Vec<Cow<str>> = k.standard_syncs().iter().map(|&s| s.into()).collect();
                if let Some(at) = v.iter().position(|s| s == "stroke") {
                    let later =
                        (1..self.strokes()).map(|n| Cow::Owned(super::stroke_name(n).into()));
                    v.splice(at + 1..at + 1, later);
                }
                v
            }
        }
    }

    /// How many strokes the behaviour has: `repetition` for a head, 1 for others with a stroke.
    pub fn strokes(&self) -> u32 {
        match &self.kind {
            BehaviourKind::Head(h) => h.repetition.unwrap_or(1).max(1),
            _ => 1,
        }
    }

    /// Whether `sync` is a known sync point of the behaviour (always true for open kinds).
    pub fn has_sync(&self, sync: &str) -> bool {
        match &self.kind {
            BehaviourKind::Speech(s) | BehaviourKind::Text(s) => {
                sync == "start" || sync == "end" || s.sync_ids().any(|id| id == sync)
            }
            k if k.has_open_syncs() || k.standard_syncs().contains(&sync) => true,
            k => {
                k.standard_syncs().contains(&"stroke")
                    && super::stroke_iteration_of(sync).is_some_and(|n| n < self.strokes())
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The slot table names exactly the elements the parser accepts, each in the namespace the
    /// writer uses for it.
    #[test]
    fn builtin_kinds_are_the_accepted_elements_in_their_namespaces() {
        let mut expected: Vec<(&str, &str)> = CORE_BEHAVIOURS
            .iter()
            .map(|&n| (n, if n == "faceFacs" { NS_CORE_EXT } else { NS_BML }))
            .chain(CONTROL_BEHAVIOURS.iter().map(|&n| (n, NS_BMLA)))
            .chain(BMLT_BEHAVIOURS.iter().map(|&n| (n, NS_BMLT)))
            .collect();
        let mut table = BUILTIN_KINDS.to_vec();
        expected.sort();
        table.sort();
        assert_eq!(table, expected);
    }
}
