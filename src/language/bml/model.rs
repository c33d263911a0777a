//! The typed model of a BML block: block attributes (BML 1.0 + BMLA/BMLT), the 15 core behaviours,
//! the BMLA control behaviours, the BMLT behaviours, unknown extension behaviours, and `<constraint>`
//! elements as written. Normalised difference constraints live in `constraints.rs`.
//!
//! Longer than 600 lines on purpose: it declares every element of the language with its
//! attributes, one type each, and the types name each other; what is done with them lives in the
//! files that do it (parser, validation, constraints, writer).

use super::diagnostic::Pos;
use super::syncref::SyncRef;

pub use super::id::Id;

/// Namespace of BML 1.0 core elements and of feedback messages.
pub const NS_BML: &str = "http://www.bml-initiative.org/bml/bml-1.0";
/// Namespace of the BML 1.0 core extensions (e.g. `faceFacs`).
pub const NS_CORE_EXT: &str = "http://www.bml-initiative.org/bml/coreextensions-1.0";
/// Namespace of the AsapRealizer BMLA extensions.
pub const NS_BMLA: &str = "http://www.asap-project.org/bmla";
/// Namespace of the Elckerlyc BMLT extensions.
pub const NS_BMLT: &str = "http://hmi.ewi.utwente.nl/bmlt";

/// Declares a closed string enumeration with its exact BML spelling.
macro_rules! bml_enum {
    ($(#[$m:meta])* $name:ident { $($(#[$vm:meta])* $var:ident = $s:literal),+ $(,)? }) => {
        $(#[$m])*
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
        pub enum $name { $($(#[$vm])* #[doc = concat!("`", $s, "`")] $var),+ }
        impl $name {
            /// Every value, in declaration order.
            pub const ALL: &'static [$name] = &[$($name::$var),+];
            /// The BML spelling.
            pub fn as_str(self) -> &'static str { match self { $($name::$var => $s),+ } }
            /// Parses the exact BML spelling.
            pub fn parse(s: &str) -> Option<Self> {
                match s { $($s => Some($name::$var),)+ _ => None }
            }
            /// The BML spellings, comma separated (for messages).
            pub fn expected() -> String {
                Self::ALL.iter().map(|v| v.as_str()).collect::<Vec<_>>().join(", ")
            }
        }
    };
}

bml_enum!(
    /// Which hand(s) a gesture or pointing uses.
    Mode { LeftHand = "LEFT_HAND", RightHand = "RIGHT_HAND", BothHands = "BOTH_HANDS" }
);
bml_enum!(
    /// How much of the body a gaze recruits. `NECK` is accepted as in the RealizerTester files.
    Influence { Eyes = "EYES", Neck = "NECK", Head = "HEAD", Shoulder = "SHOULDER", Waist = "WAIST", Whole = "WHOLE" }
);
bml_enum!(
    /// Direction of a gaze's angular offset from its target.
    OffsetDirection {
        Right = "RIGHT", Left = "LEFT", Up = "UP", Down = "DOWN", UpRight = "UPRIGHT",
        UpLeft = "UPLEFT", DownLeft = "DOWNLEFT", DownRight = "DOWNRIGHT", Polar = "POLAR",
    }
);
bml_enum!(
    /// Side of the face of a FACS action unit.
    Side { Left = "LEFT", Right = "RIGHT", Both = "BOTH" }
);
bml_enum!(
    /// Stance of a posture.
    StanceType { Sitting = "SITTING", Crouching = "CROUCHING", Standing = "STANDING", Lying = "LYING" }
);
bml_enum!(
    /// Body part of a posture's `<pose>`.
    PosePart {
        Arms = "ARMS", LeftArm = "LEFT_ARM", RightArm = "RIGHT_ARM", LeftHand = "LEFT_HAND",
        RightHand = "RIGHT_HAND", Legs = "LEGS", LeftLeg = "LEFT_LEG", RightLeg = "RIGHT_LEG",
        Head = "HEAD", WholeBody = "WHOLEBODY",
    }
);
bml_enum!(
    /// Trajectory of a parameter value change.
    TrajectoryType { Linear = "linear", Instant = "instant" }
);

/// Head lexemes of the BML 1.0 standard (others are accepted with a warning).
pub const HEAD_LEXEMES: &[&str] = &["NOD", "SHAKE"];
/// Face lexemes of the BML 1.0 standard (others are accepted with a warning).
pub const FACE_LEXEMES: &[&str] = &[
    "OBLIQUE_BROWS",
    "RAISE_BROWS",
    "RAISE_LEFT_BROW",
    "RAISE_RIGHT_BROW",
    "LOWER_BROWS",
    "LOWER_LEFT_BROW",
    "LOWER_RIGHT_BROW",
    "LOWER_MOUTH_CORNERS",
    "LOWER_LEFT_MOUTH_CORNER",
    "LOWER_RIGHT_MOUTH_CORNER",
    "RAISE_MOUTH_CORNERS",
    "RAISE_RIGHT_MOUTH_CORNER",
    "RAISE_LEFT_MOUTH_CORNER",
    "OPEN_MOUTH",
    "OPEN_LIPS",
    "WIDEN_EYES",
    "CLOSE_EYES",
];

/// How a block combines with the current plan.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub enum Composition {
    /// Added to the plan, starting now (the default).
    #[default]
    Merge,
    /// Starts when everything in the plan has ended.
    Append,
    /// Replaces the whole plan.
    Replace,
    /// Starts when every behaviour of the listed blocks has ended.
    AppendAfter(Vec<String>),
}

impl Composition {
    /// Parses `MERGE`, `APPEND`, `REPLACE` or `APPEND-AFTER(a,b,...)`, case-insensitively.
    pub fn parse(s: &str) -> Option<Composition> {
        let t = s.trim();
        let upper = t.to_ascii_uppercase();
        match upper.as_str() {
            "MERGE" => return Some(Composition::Merge),
            "APPEND" => return Some(Composition::Append),
            "REPLACE" => return Some(Composition::Replace),
            _ => {}
        }
        let rest = upper.strip_prefix("APPEND-AFTER")?.trim_start();
        if !rest.starts_with('(') || !rest.ends_with(')') {
            return None;
        }
        // keep the original spelling of the ids
        let open = t.find('(')?;
        let inner = &t[open + 1..t.len() - 1];
        let ids = split_id_list(inner);
        if ids.is_empty()
            || ids
                .iter()
                .any(|i| i.chars().any(|c| c.is_whitespace() || c == '(' || c == ')'))
        {
            return None;
        }
        Some(Composition::AppendAfter(ids))
    }

    /// The canonical BML spelling.
    pub fn to_bml(&self) -> String {
        match self {
            Composition::Merge => "MERGE".into(),
            Composition::Append => "APPEND".into(),
            Composition::Replace => "REPLACE".into(),
            Composition::AppendAfter(ids) => format!("APPEND-AFTER({})", ids.join(",")),
        }
    }
}

/// Splits a comma (or whitespace) separated id list, dropping empty items.
pub fn split_id_list(s: &str) -> Vec<String> {
    s.split(|c: char| c == ',' || c.is_whitespace())
        .filter(|p| !p.is_empty())
        .map(str::to_string)
        .collect()
}

/// An attribute in a namespace this realizer does not interpret, kept verbatim.
#[derive(Debug, Clone, PartialEq)]
pub struct ForeignAttr {
    /// Namespace URI.
    pub ns: String,
    /// Local name.
    pub name: String,
    /// Value as written (unescaped).
    pub value: String,
}

/// The BMLA/BMLT block attributes (accepted in either namespace).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct BlockExt {
    /// `preplan="true"`: schedule, but do not start until activated.
    pub preplan: bool,
    /// `onStart`: pre-planned blocks to activate when this block starts.
    pub on_start: Vec<String>,
    /// `interrupt`: blocks to remove from the plan before this one is scheduled.
    pub interrupt: Vec<String>,
    /// `appendAfter`: blocks whose end this block waits for.
    pub append_after: Vec<String>,
    /// `chunkAfter`: blocks this block is chunked after.
    pub chunk_after: Vec<String>,
    /// `chunkBefore`: blocks chunked after this one.
    pub chunk_before: Vec<String>,
    /// `prependBefore`: blocks that must wait for this one.
    pub prepend_before: Vec<String>,
    /// `allowexternalrefs="true"`: constraints may name behaviours of other blocks.
    pub allow_external_refs: bool,
}

/// One `<bml>` block.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Block {
    /// Block id (required).
    pub id: Id,
    /// Character the block is for, if named.
    pub character_id: Option<String>,
    /// How the block combines with the plan (`composition`, or the draft alias `scheduling`).
    pub composition: Composition,
    /// BMLA/BMLT block attributes.
    pub ext: BlockExt,
    /// Behaviours in document order.
    pub behaviours: Vec<Behaviour>,
    /// `<constraint>` elements in document order.
    pub constraints: Vec<ConstraintElement>,
    /// Extension attributes on `<bml>` that are not interpreted.
    pub foreign_attrs: Vec<ForeignAttr>,
    /// Where the `<bml>` element starts.
    pub pos: Pos,
}

impl Block {
    /// The behaviour with id `id`, if any.
    pub fn behaviour(&self, id: &str) -> Option<&Behaviour> {
        self.behaviours.iter().find(|b| b.id == id)
    }
}

/// A shorthand sync attribute on a behaviour, e.g. `start="speech1:s1"`.
#[derive(Debug, Clone, PartialEq)]
pub struct SyncAttr {
    /// The sync point of this behaviour that is constrained (the attribute name).
    pub sync: &'static str,
    /// What it is synchronised to.
    pub value: SyncRef,
    /// Where the attribute is.
    pub pos: Pos,
}

/// A `<description priority type>` alternative of a behaviour; its content is kept as raw XML.
#[derive(Debug, Clone, PartialEq)]
pub struct Description {
    /// Priority: a larger number is preferred.
    pub priority: Option<i64>,
    /// Description type, e.g. `application/ssml+xml`.
    pub kind: String,
    /// The raw XML between the description tags.
    pub content: String,
    /// Namespace prefixes (prefix, URI) declared outside the content and used in it.
    pub namespaces: Vec<(String, String)>,
    /// Where the description starts.
    pub pos: Pos,
}

/// A piece of speech text: words, or an inline `<sync id>` marker.
#[derive(Debug, Clone, PartialEq)]
pub enum TextPart {
    /// Text as written (unescaped).
    Text(String),
    /// An inline sync point.
    Sync(Id),
}

/// A `name`/`value` parameter of a BMLT behaviour.
#[derive(Debug, Clone, PartialEq)]
pub struct Param {
    /// Parameter name.
    pub name: String,
    /// Parameter value.
    pub value: String,
}

/// One behaviour of a block.
#[derive(Debug, Clone, PartialEq)]
pub struct Behaviour {
    /// Behaviour id, unique within the block.
    pub id: Id,
    /// What the behaviour is, with its kind-specific attributes.
    pub kind: BehaviourKind,
    /// Shorthand sync attributes in document order.
    pub syncs: Vec<SyncAttr>,
    /// Whether it sits inside a BML 1.0 `<required>` element.
    pub required: bool,
    /// `<description>` alternatives.
    pub descriptions: Vec<Description>,
    /// Extension attributes that are not interpreted.
    pub foreign_attrs: Vec<ForeignAttr>,
    /// Where the element starts.
    pub pos: Pos,
}

/// Speech: text with inline sync points.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Speech {
    /// The `<text>` content.
    pub text: Vec<TextPart>,
}

impl Speech {
    /// Ids of the inline sync points in text order.
    pub fn sync_ids(&self) -> impl Iterator<Item = &str> {
        self.text.iter().filter_map(|p| match p {
            TextPart::Sync(id) => Some(id.as_str()),
            TextPart::Text(_) => None,
        })
    }

    /// The spoken words without sync markers.
    pub fn plain_text(&self) -> String {
        self.text
            .iter()
            .filter_map(|p| match p {
                TextPart::Text(t) => Some(t.as_str()),
                TextPart::Sync(_) => None,
            })
            .collect()
    }
}

/// `<gesture lexeme mode>`.
#[derive(Debug, Clone, PartialEq)]
pub struct Gesture {
    /// Gesture lexeme, e.g. `BEAT`.
    pub lexeme: String,
    /// Hand(s).
    pub mode: Option<Mode>,
}

/// `<pointing target mode>`.
#[derive(Debug, Clone, PartialEq)]
pub struct Pointing {
    /// What to point at.
    pub target: String,
    /// Hand(s).
    pub mode: Option<Mode>,
}

/// `<head lexeme repetition amount>`.
#[derive(Debug, Clone, PartialEq)]
pub struct Head {
    /// `NOD`, `SHAKE`, or a realizer lexeme.
    pub lexeme: String,
    /// Number of repetitions (default 1).
    pub repetition: Option<u32>,
    /// Amount in [0, 1] (default 0.5).
    pub amount: Option<f64>,
}

/// `<gaze>` / `<gazeShift>` attributes.
#[derive(Debug, Clone, PartialEq)]
pub struct Gaze {
    /// What to look at.
    pub target: String,
    /// Which body parts take part.
    pub influence: Option<Influence>,
    /// Angular offset from the target, degrees.
    pub offset_angle: Option<f64>,
    /// Direction of the offset.
    pub offset_direction: Option<OffsetDirection>,
}

/// `<face>`: a face expression given by a lexeme or by a FACS action unit.
#[derive(Debug, Clone, PartialEq)]
pub struct Face {
    /// Face lexeme, if given by lexeme.
    pub lexeme: Option<String>,
    /// FACS action unit, if given by AU.
    pub au: Option<u32>,
    /// Side for an AU.
    pub side: Option<Side>,
    /// Intensity.
    pub amount: Option<f64>,
}

/// `<faceLexeme>` / `<faceShift>` attributes.
#[derive(Debug, Clone, PartialEq)]
pub struct FaceLexeme {
    /// Face lexeme, e.g. `RAISE_BROWS`.
    pub lexeme: String,
    /// Intensity.
    pub amount: Option<f64>,
}

/// `<faceFacs au side amount>`.
#[derive(Debug, Clone, PartialEq)]
pub struct FaceFacs {
    /// FACS action unit number.
    pub au: u32,
    /// Side of the face.
    pub side: Option<Side>,
    /// Intensity.
    pub amount: Option<f64>,
}

/// A `<pose part lexeme>` inside a posture.
#[derive(Debug, Clone, PartialEq)]
pub struct Pose {
    /// Body part.
    pub part: PosePart,
    /// Pose lexeme, e.g. `ARMS_CROSSED`.
    pub lexeme: String,
}

/// `<posture>` / `<postureShift>` content.
#[derive(Debug, Clone, PartialEq)]
pub struct Posture {
    /// The `<stance type>`.
    pub stance: StanceType,
    /// `<pose>` children.
    pub poses: Vec<Pose>,
}

/// `<locomotion target manner>`.
#[derive(Debug, Clone, PartialEq)]
pub struct Locomotion {
    /// Where to go.
    pub target: String,
    /// Manner, e.g. `WALK` (default).
    pub manner: Option<String>,
}

/// `<wait max-wait>`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Wait {
    /// Longest wait in seconds.
    pub max_wait: Option<f64>,
}

/// BMLA/BMLT `<interrupt target include exclude>`.
#[derive(Debug, Clone, PartialEq)]
pub struct Interrupt {
    /// Block to interrupt.
    pub target: String,
    /// Behaviours to interrupt (empty: all).
    pub include: Vec<String>,
    /// Behaviours to spare.
    pub exclude: Vec<String>,
}

/// BMLA/BMLT `<activate target>`.
#[derive(Debug, Clone, PartialEq)]
pub struct Activate {
    /// Pre-planned block to activate.
    pub target: String,
}

/// The trajectory of a parameter value change.
#[derive(Debug, Clone, PartialEq)]
pub struct Trajectory {
    /// `linear` or `instant`.
    pub kind: TrajectoryType,
    /// Start value (default: the target's value at the change's start).
    pub initial_value: Option<f64>,
    /// Value reached at the end.
    pub target_value: f64,
}

/// BMLA/BMLT `<parametervaluechange target paramId>` with its `<trajectory>`.
#[derive(Debug, Clone, PartialEq)]
pub struct ParameterValueChange {
    /// Block of the target behaviour, if given (`block:behaviour`).
    pub target_block: Option<String>,
    /// Target behaviour.
    pub target_behaviour: String,
    /// Parameter to change.
    pub param_id: String,
    /// How it changes.
    pub trajectory: Trajectory,
}

/// A BMLT animation behaviour (`procanimation`, `procanimationgesture`, `keyframe`).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Animation {
    /// `name`.
    pub name: Option<String>,
    /// `fileName`.
    pub file_name: Option<String>,
    /// `<parameter>` children.
    pub params: Vec<Param>,
    /// Other content (e.g. an inline SkeletonInterpolator) as raw XML.
    pub content: String,
    /// Namespace prefixes (prefix, URI) declared outside the content and used in it.
    pub namespaces: Vec<(String, String)>,
}

/// BMLT `<controller class name>`.
#[derive(Debug, Clone, PartialEq)]
pub struct Controller {
    /// Controller class.
    pub class: String,
    /// Optional name.
    pub name: Option<String>,
    /// `<parameter>` children.
    pub params: Vec<Param>,
}

/// BMLT `<noise joint type>`.
#[derive(Debug, Clone, PartialEq)]
pub struct Noise {
    /// Joint to move.
    pub joint: String,
    /// Noise type, e.g. `perlin`.
    pub kind: String,
    /// `<parameter>` children.
    pub params: Vec<Param>,
}

/// BMLT `<facemorph targetname intensity>`.
#[derive(Debug, Clone, PartialEq)]
pub struct FaceMorph {
    /// Morph target name.
    pub target_name: String,
    /// Intensity (default 1).
    pub intensity: Option<f64>,
}

/// BMLT `<transition class>`.
#[derive(Debug, Clone, PartialEq)]
pub struct Transition {
    /// Transition class, e.g. `SlerpTransition`.
    pub class: String,
    /// `<parameter>` children.
    pub params: Vec<Param>,
}

/// A behaviour element from a namespace or of a name this realizer does not support; kept verbatim.
#[derive(Debug, Clone, PartialEq)]
pub struct UnknownBehaviour {
    /// Namespace URI.
    pub ns: String,
    /// Element local name.
    pub name: String,
    /// Attributes other than `id` and the sync attributes (namespace "" for unprefixed ones).
    pub attrs: Vec<ForeignAttr>,
    /// Raw XML content.
    pub content: String,
    /// Namespace prefixes (prefix, URI) declared outside the content and used in it.
    pub namespaces: Vec<(String, String)>,
}

/// Every behaviour kind with its specific attributes.
#[derive(Debug, Clone, PartialEq)]
pub enum BehaviourKind {
    /// `<speech>`.
    Speech(Speech),
    /// `<gesture>`.
    Gesture(Gesture),
    /// `<pointing>`.
    Pointing(Pointing),
    /// `<head>`.
    Head(Head),
    /// `<headDirectionShift target>`.
    HeadDirectionShift {
        /// What to turn the head towards, for good.
        target: String,
    },
    /// `<gaze>`.
    Gaze(Gaze),
    /// `<gazeShift>`.
    GazeShift(Gaze),
    /// `<face>`.
    Face(Face),
    /// `<faceLexeme>`.
    FaceLexeme(FaceLexeme),
    /// `<faceFacs>`.
    FaceFacs(FaceFacs),
    /// `<faceShift>`.
    FaceShift(FaceLexeme),
    /// `<posture>`.
    Posture(Posture),
    /// `<postureShift>`.
    PostureShift(Posture),
    /// `<locomotion>`.
    Locomotion(Locomotion),
    /// `<wait>`.
    Wait(Wait),
    /// BMLA/BMLT `<interrupt>`.
    Interrupt(Interrupt),
    /// BMLA/BMLT `<activate>`.
    Activate(Activate),
    /// BMLA/BMLT `<parametervaluechange>`.
    ParameterValueChange(ParameterValueChange),
    /// BMLT `<procanimation>`.
    ProcAnimation(Animation),
    /// BMLT `<procanimationgesture>`.
    ProcAnimationGesture(Animation),
    /// BMLT `<keyframe>`.
    Keyframe(Animation),
    /// BMLT `<controller>`.
    Controller(Controller),
    /// BMLT `<audiofile fileName>`.
    AudioFile {
        /// The audio file.
        file_name: String,
    },
    /// BMLT `<noise>`.
    Noise(Noise),
    /// BMLT `<facemorph>`.
    FaceMorph(FaceMorph),
    /// BMLT `<transition>`.
    Transition(Transition),
    /// BMLT `<text>`: speech shown as text.
    Text(Speech),
    /// An unsupported extension behaviour.
    Unknown(UnknownBehaviour),
}

/// One child of a `<constraint>`, as written.
#[derive(Debug, Clone, PartialEq)]
pub enum ConstraintItem {
    /// `<synchronize ref?>`: the ref (if any) and every child sync occur at the same time.
    Synchronize {
        /// The optional `ref` attribute.
        reference: Option<SyncRef>,
        /// The `<sync ref>` children.
        syncs: Vec<ConstraintSync>,
        /// Where the element starts.
        pos: Pos,
    },
    /// `<before ref>`: every child sync occurs at or before `ref`.
    Before {
        /// The reference.
        reference: SyncRef,
        /// The `<sync ref>` children.
        syncs: Vec<ConstraintSync>,
        /// Where the element starts.
        pos: Pos,
    },
    /// `<after ref>`: every child sync occurs at or after `ref`.
    After {
        /// The reference.
        reference: SyncRef,
        /// The `<sync ref>` children.
        syncs: Vec<ConstraintSync>,
        /// Where the element starts.
        pos: Pos,
    },
}

/// A `<sync ref>` inside a constraint item.
#[derive(Debug, Clone, PartialEq)]
pub struct ConstraintSync {
    /// The reference.
    pub reference: SyncRef,
    /// Where the element starts.
    pub pos: Pos,
}

/// A `<constraint>` element.
#[derive(Debug, Clone, PartialEq)]
pub struct ConstraintElement {
    /// Optional id.
    pub id: Option<String>,
    /// Its items in document order.
    pub items: Vec<ConstraintItem>,
    /// Whether it sits inside `<required>`.
    pub required: bool,
    /// Where the element starts.
    pub pos: Pos,
}
