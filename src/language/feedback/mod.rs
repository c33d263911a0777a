//! BML 1.0 feedback: typed messages (block progress, sync-point progress, predictions, warnings,
//! with the BMLA status and posix-time extensions), the listener trait, and the two line codecs of
//! docs/cli.md — XML (one element per line) and JSON lines.

pub mod diff;
mod json;
pub mod world;
mod xml;
pub use world::WorldFeedback;

use std::fmt;

pub use json::{from_json, to_json};
pub use xml::{from_xml, to_xml};

/// Namespace of feedback elements (BML 1.0).
pub const NS_FEEDBACK: &str = "http://www.bml-initiative.org/bml/bml-1.0";
/// Namespace of the BMLA feedback attributes (`bmla:status`, `bmla:posixTime`).
pub const NS_BMLA: &str = "http://www.asap-project.org/bmla";

/// Declares a closed set of upper-case feedback constants.
macro_rules! constants {
    ($(#[$m:meta])* $name:ident { $($(#[$vm:meta])* $var:ident = $s:literal),+ $(,)? }) => {
        $(#[$m])*
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
        pub enum $name { $($(#[$vm])* $var),+ }
        impl $name {
            /// Every value.
            pub const ALL: &'static [$name] = &[$($name::$var),+];
            /// The feedback spelling.
            pub fn as_str(self) -> &'static str { match self { $($name::$var => $s),+ } }
            /// Parses the feedback spelling.
            pub fn parse(s: &str) -> Option<Self> { match s { $($s => Some($name::$var),)+ _ => None } }
        }
        impl fmt::Display for $name {
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result { f.write_str(self.as_str()) }
        }
    };
}

constants!(
    /// BMLA block status.
    BlockStatus {
        /// Being scheduled.
        InPrep = "IN_PREP",
        /// Scheduled, waiting for activation (pre-planned) or start.
        Pending = "PENDING",
        /// Scheduled, waiting for blocks it is appended to.
        Lurking = "LURKING",
        /// Executing.
        InExec = "IN_EXEC",
        /// Only retractions remain.
        Subsiding = "SUBSIDING",
        /// Finished.
        Done = "DONE",
        /// Stopped while executing.
        Interrupted = "INTERRUPTED",
        /// Removed before it started.
        Revoked = "REVOKED",
    }
);

/// The `type` of a warning. The named constants are those of docs/cli.md; `Other` keeps any other
/// type read from a log.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum WarningType {
    /// A known warning type.
    Known(KnownWarning),
    /// Any other type string.
    Other(String),
}

constants!(
    /// The warning types of docs/cli.md.
    KnownWarning {
        /// The BML could not be parsed.
        ParsingFailure = "PARSING_FAILURE",
        /// A referenced block, behaviour or target does not exist.
        NoSuchTarget = "NO_SUCH_TARGET",
        /// A behaviour could not be placed in time.
        ImpossibleToSchedule = "IMPOSSIBLE_TO_SCHEDULE",
        /// No engine realizes this behaviour kind.
        BehaviorTypeNotSupported = "BEHAVIOR_TYPE_NOT_SUPPORTED",
        /// An extension attribute is not interpreted.
        CustomAttributeNotSupported = "CUSTOM_ATTRIBUTE_NOT_SUPPORTED",
        /// The constraints cannot all hold.
        CannotSatisfyConstraints = "CANNOT_SATISFY_CONSTRAINTS",
        /// A timing that breaks sync order or block start, or squeezes a phase of a behaviour
        /// below what a person can perform.
        InvalidTiming = "INVALID_TIMING",
        /// An engine failed while executing.
        ExecutionFailure = "EXECUTION_FAILURE",
        /// The behaviour plays its timing, but no binding of its lexeme moves anything.
        LexemeNotSupported = "LEXEME_NOT_SUPPORTED",
    }
);

impl WarningType {
    /// The type string.
    pub fn as_str(&self) -> &str {
        match self {
            WarningType::Known(k) => k.as_str(),
            WarningType::Other(s) => s,
        }
    }

    /// Reads a type string.
    pub fn parse(s: &str) -> WarningType {
        KnownWarning::parse(s).map_or_else(|| WarningType::Other(s.to_string()), WarningType::Known)
    }
}

impl From<KnownWarning> for WarningType {
    fn from(k: KnownWarning) -> Self {
        WarningType::Known(k)
    }
}

/// `<blockProgress id="B:sync" globalTime>`: a block started or ended.
#[derive(Debug, Clone, PartialEq)]
pub struct BlockProgress {
    /// Block id.
    pub block: crate::language::bml::Id,
    /// `start` or `end` (other block sync ids are accepted when reading).
    pub sync: crate::language::bml::Id,
    /// Global time in seconds.
    pub global_time: f64,
    /// Character, if any.
    pub character_id: Option<String>,
    /// BMLA status after the event.
    pub status: Option<BlockStatus>,
    /// BMLA wall-clock time, ms since the Unix epoch (omitted on the virtual clock).
    pub posix_time: Option<u64>,
}

/// `<syncPointProgress id="B:beh:sync" time globalTime>`: a behaviour passed a sync point.
#[derive(Debug, Clone, PartialEq)]
pub struct SyncPointProgress {
    /// Block id.
    pub block: crate::language::bml::Id,
    /// Behaviour id.
    pub behaviour: crate::language::bml::Id,
    /// Sync point id.
    pub sync: crate::language::bml::Id,
    /// Time relative to the block start, seconds.
    pub time: f64,
    /// Global time in seconds.
    pub global_time: f64,
    /// Character, if any.
    pub character_id: Option<String>,
    /// BMLA wall-clock time, ms since the Unix epoch.
    pub posix_time: Option<u64>,
    /// The behaviour never reached this sync point: it was interrupted (or its block was) before
    /// it, and the point is reported at the moment of the interruption (`bmla:skipped="true"`).
    pub skipped: bool,
}

/// A `<bml id globalStart globalEnd bmla:status>` child of a prediction.
#[derive(Debug, Clone, PartialEq)]
pub struct BlockPrediction {
    /// Block id.
    pub id: crate::language::bml::Id,
    /// Predicted global start.
    pub global_start: Option<f64>,
    /// Predicted global end (absent while unknown).
    pub global_end: Option<f64>,
    /// Block status at prediction time.
    pub status: Option<BlockStatus>,
}

/// A behaviour child of a prediction: element name, `id="B:beh"` and predicted sync times
/// (relative to block start).
#[derive(Debug, Clone, PartialEq)]
pub struct BehaviourPrediction {
    /// Behaviour element name, e.g. `gesture`.
    pub kind: crate::language::bml::Id,
    /// Block id.
    pub block: crate::language::bml::Id,
    /// Behaviour id.
    pub behaviour: crate::language::bml::Id,
    /// (sync id, predicted time) in sync order.
    pub syncs: Vec<(crate::language::bml::Id, f64)>,
    /// The behaviour's other attributes as a peer wrote them (`lexeme`, `mode`, `target`…),
    /// kept verbatim in order; this realizer's own predictions carry none.
    pub attributes: Vec<(String, String)>,
}

/// `<predictionFeedback>`: predicted timing of blocks and behaviours.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PredictionFeedback {
    /// Character, if any.
    pub character_id: Option<String>,
    /// Block predictions: in practice one (the realizer sends one per block), so it is kept
    /// inline.
    pub blocks: Vec<BlockPrediction>,
    /// Behaviour predictions.
    pub behaviours: Vec<BehaviourPrediction>,
}

/// `<warningFeedback id type>text</warningFeedback>`.
#[derive(Debug, Clone, PartialEq)]
pub struct WarningFeedback {
    /// `B` or `B:beh` (`<no id>` when the block id is unknown).
    pub id: String,
    /// Warning type.
    pub kind: WarningType,
    /// Character, if any.
    pub character_id: Option<String>,
    /// Human explanation.
    pub text: String,
}

/// One feedback message.
#[derive(Debug, Clone, PartialEq)]
pub enum Feedback {
    /// Block start/end.
    BlockProgress(BlockProgress),
    /// A sync point passed.
    SyncPointProgress(SyncPointProgress),
    /// Predicted timing.
    Prediction(PredictionFeedback),
    /// Something was dropped, changed or failed.
    Warning(WarningFeedback),
    /// About the world, not a block: perception, nets, world variables (see [`world`]).
    World(WorldFeedback),
}

impl Feedback {
    /// The element name (`blockProgress`, `syncPointProgress`, `predictionFeedback`,
    /// `warningFeedback`).
    pub fn element_name(&self) -> &'static str {
        match self {
            Feedback::BlockProgress(_) => "blockProgress",
            Feedback::SyncPointProgress(_) => "syncPointProgress",
            Feedback::Prediction(_) => "predictionFeedback",
            Feedback::Warning(_) => "warningFeedback",
            Feedback::World(w) => w.element_name(),
        }
    }

    /// The character it names, if any.
    pub fn character_id(&self) -> Option<&str> {
        match self {
            Feedback::BlockProgress(p) => p.character_id.as_deref(),
            Feedback::SyncPointProgress(p) => p.character_id.as_deref(),
            Feedback::Prediction(p) => p.character_id.as_deref(),
            Feedback::Warning(w) => w.character_id.as_deref(),
            Feedback::World(w) => w.character_id(),
        }
    }
}

/// The line format of a feedback log.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Format {
    /// BML 1.0 XML, one element per line.
    #[default]
    Xml,
    /// JSON lines.
    Jsonl,
}

impl Format {
    /// Encodes one message as one line (without the newline).
    pub fn encode(self, fb: &Feedback) -> String {
        match self {
            Format::Xml => to_xml(fb),
            Format::Jsonl => to_json(fb),
        }
    }
}

/// Decodes one log line in either format (JSON if it starts with `{`).
pub fn from_line(line: &str) -> Result<Feedback, FeedbackError> {
    if line.trim_start().starts_with('{') {
        from_json(line)
    } else {
        from_xml(line)
    }
}

/// Why a feedback line could not be read.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("bad feedback: {0}")]
pub struct FeedbackError(pub String);

/// Receives feedback messages as the realizer produces them.
pub trait FeedbackListener: Send {
    /// Called once per message, in order.
    fn feedback(&mut self, fb: &Feedback);
}

impl FeedbackListener for Vec<Feedback> {
    fn feedback(&mut self, fb: &Feedback) {
        self.push(fb.clone());
    }
}

impl<F: FnMut(&Feedback) + Send> FeedbackListener for F {
    fn feedback(&mut self, fb: &Feedback) {
        self(fb)
    }
}

/// Rounds seconds to the millisecond precision of the logs.
pub fn round_ms(t: f64) -> f64 {
    // beyond 1e12 s an f64 has no sub-millisecond digits left: rounding would only add error
    if t.abs() < 1e12 {
        (t * 1000.0).round() / 1000.0
    } else {
        t
    }
}

/// Behaviour element names and predicted sync names become XML names when written: check them.
pub(crate) fn check_name(name: &str) -> Result<(), FeedbackError> {
    if crate::language::xmlname::is_ncname(name) && name != "xmlns" {
        Ok(())
    } else {
        Err(FeedbackError(format!("'{name}' is not an XML name")))
    }
}

/// A blockProgress id `block:sync` (the block id may hold ':'; the sync is after the last).
pub(crate) fn block_and_sync(id: &str) -> Result<(&str, &str), FeedbackError> {
    id.rsplit_once(':')
        .filter(|(b, s)| !b.is_empty() && !s.is_empty())
        .ok_or_else(|| FeedbackError(format!("blockProgress id '{id}' should be block:sync")))
}

/// A syncPointProgress id `block:behaviour:sync`, or `block:behaviour:stroke:N` for the later
/// strokes of a repeated head (the sync `stroke:N`).
pub(crate) fn sync_point_id(id: &str) -> Result<[String; 3], FeedbackError> {
    let parts: Vec<&str> = id.split(':').collect();
    let sync = match parts[..] {
        [_, _, s] => s.to_string(),
        [_, _, "stroke", n] if !n.is_empty() && n.bytes().all(|b| b.is_ascii_digit()) => {
            format!("stroke:{n}")
        }
        _ => String::new(),
    };
    if sync.is_empty() || parts[..2].iter().any(|p| p.is_empty()) {
        return Err(FeedbackError(format!(
            "syncPointProgress id '{id}' should be block:behaviour:sync (or block:behaviour:stroke:N)"
        )));
    }
    Ok([parts[0].to_string(), parts[1].to_string(), sync])
}

/// Splits `a:b` ids; `n` is the number of parts expected.
pub(crate) fn split_id(id: &str, n: usize, what: &str) -> Result<Vec<String>, FeedbackError> {
    let parts: Vec<String> = id.split(':').map(str::to_string).collect();
    if parts.len() != n || parts.iter().any(String::is_empty) {
        return Err(FeedbackError(format!(
            "{what} id '{id}' should have {n} non-empty parts separated by ':'"
        )));
    }
    Ok(parts)
}
