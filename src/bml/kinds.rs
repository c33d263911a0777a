//! Facts about each behaviour kind: its element name and namespace, its sync points (DESIGN §3),
//! and whether its sync points are open (defined by animation data rather than by BML).

use super::model::{Behaviour, BehaviourKind, NS_BML, NS_BMLA, NS_BMLT, NS_CORE_EXT};

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
/// gaze, posture.
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

    /// The local name of a built-in kind (`""` for an unknown extension).
    fn builtin_name(&self) -> &'static str {
        match self {
            BehaviourKind::Speech(_) => "speech",
            BehaviourKind::Gesture(_) => "gesture",
            BehaviourKind::Pointing(_) => "pointing",
            BehaviourKind::Head(_) => "head",
            BehaviourKind::HeadDirectionShift { .. } => "headDirectionShift",
            BehaviourKind::Gaze(_) => "gaze",
            BehaviourKind::GazeShift(_) => "gazeShift",
            BehaviourKind::Face(_) => "face",
            BehaviourKind::FaceLexeme(_) => "faceLexeme",
            BehaviourKind::FaceFacs(_) => "faceFacs",
            BehaviourKind::FaceShift(_) => "faceShift",
            BehaviourKind::Posture(_) => "posture",
            BehaviourKind::PostureShift(_) => "postureShift",
            BehaviourKind::Locomotion(_) => "locomotion",
            BehaviourKind::Wait(_) => "wait",
            BehaviourKind::Interrupt(_) => "interrupt",
            BehaviourKind::Activate(_) => "activate",
            BehaviourKind::ParameterValueChange(_) => "parametervaluechange",
            BehaviourKind::ProcAnimation(_) => "procanimation",
            BehaviourKind::ProcAnimationGesture(_) => "procanimationgesture",
            BehaviourKind::Keyframe(_) => "keyframe",
            BehaviourKind::Controller(_) => "controller",
            BehaviourKind::AudioFile { .. } => "audiofile",
            BehaviourKind::Noise(_) => "noise",
            BehaviourKind::FaceMorph(_) => "facemorph",
            BehaviourKind::Transition(_) => "transition",
            BehaviourKind::Text(_) => "text",
            BehaviourKind::Unknown(_) => "",
        }
    }

    /// The namespace the writer puts the element in.
    pub fn namespace(&self) -> &str {
        match self {
            BehaviourKind::FaceFacs(_) => NS_CORE_EXT,
            BehaviourKind::Interrupt(_)
            | BehaviourKind::Activate(_)
            | BehaviourKind::ParameterValueChange(_) => NS_BMLA,
            BehaviourKind::ProcAnimation(_)
            | BehaviourKind::ProcAnimationGesture(_)
            | BehaviourKind::Keyframe(_)
            | BehaviourKind::Controller(_)
            | BehaviourKind::AudioFile { .. }
            | BehaviourKind::Noise(_)
            | BehaviourKind::FaceMorph(_)
            | BehaviourKind::Transition(_)
            | BehaviourKind::Text(_) => NS_BMLT,
            BehaviourKind::Unknown(u) => &u.ns,
            _ => NS_BML,
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
            BehaviourKind::Gaze(_) | BehaviourKind::Posture(_) => GAZE_SYNCS,
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
    /// sync points between `start` and `end`.
    pub fn sync_points(&self) -> Vec<&str> {
        match &self.kind {
            BehaviourKind::Speech(s) | BehaviourKind::Text(s) => {
                let mut v = vec!["start"];
                v.extend(s.sync_ids());
                v.push("end");
                v
            }
            k => k.standard_syncs().to_vec(),
        }
    }

    /// Whether `sync` is a known sync point of the behaviour (always true for open kinds).
    pub fn has_sync(&self, sync: &str) -> bool {
        match &self.kind {
            BehaviourKind::Speech(s) | BehaviourKind::Text(s) => {
                sync == "start" || sync == "end" || s.sync_ids().any(|id| id == sync)
            }
            k => k.has_open_syncs() || k.standard_syncs().contains(&sync),
        }
    }
}
