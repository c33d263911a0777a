//! The JSON-lines codec of feedback: one object per line, `"feedback"` naming the element, the
//! other keys being the XML attribute names verbatim (`"bmla:status"`, ...), times as numbers
//! rounded to the millisecond, a warning's text under `"text"`, a prediction's children under
//! `"bml"` and `"behaviors"` (objects of the same shape). The wire shape is the serde types
//! below; decoding errors name the field.

use indexmap::IndexMap;
use serde::{Deserialize, Serialize, Serializer};

use super::*;

/// One feedback line as it is written: one struct per element, each with its `"feedback"` key
/// first.
#[derive(Serialize)]
#[serde(untagged)]
enum Line {
    BlockProgress(BlockProgressLine),
    SyncPointProgress(SyncPointLine),
    Prediction(PredictionLine),
    Warning(WarningLine),
}

#[derive(Serialize, Deserialize)]
struct BlockProgressLine {
    feedback: String,
    /// `block:sync`.
    id: String,
    #[serde(rename = "globalTime", serialize_with = "ms")]
    global_time: f64,
    #[serde(rename = "characterId", default, skip_serializing_if = "none")]
    character_id: Option<String>,
    #[serde(rename = "bmla:status", default, skip_serializing_if = "none")]
    status: Option<String>,
    #[serde(rename = "bmla:posixTime", default, skip_serializing_if = "none")]
    posix_time: Option<u64>,
}

#[derive(Serialize, Deserialize)]
struct SyncPointLine {
    feedback: String,
    /// `block:behaviour:sync`.
    id: String,
    #[serde(serialize_with = "ms")]
    time: f64,
    #[serde(rename = "globalTime", serialize_with = "ms")]
    global_time: f64,
    #[serde(rename = "characterId", default, skip_serializing_if = "none")]
    character_id: Option<String>,
    #[serde(rename = "bmla:posixTime", default, skip_serializing_if = "none")]
    posix_time: Option<u64>,
    #[serde(rename = "bmla:skipped", default, skip_serializing_if = "is_false")]
    skipped: bool,
}

#[derive(Serialize, Deserialize)]
struct PredictionLine {
    feedback: String,
    #[serde(rename = "characterId", default, skip_serializing_if = "none")]
    character_id: Option<String>,
    #[serde(default)]
    bml: Vec<BlockLine>,
    #[serde(default)]
    behaviors: Vec<BehaviourLine>,
}

#[derive(Serialize, Deserialize)]
struct WarningLine {
    feedback: String,
    id: String,
    #[serde(rename = "type")]
    kind: String,
    #[serde(rename = "characterId", default, skip_serializing_if = "none")]
    character_id: Option<String>,
    #[serde(default)]
    text: String,
}

/// A `<bml>` child of a prediction.
#[derive(Serialize, Deserialize)]
struct BlockLine {
    /// Always `bml`.
    feedback: String,
    id: String,
    #[serde(rename = "globalStart", default, serialize_with = "opt_ms")]
    #[serde(skip_serializing_if = "none")]
    global_start: Option<f64>,
    #[serde(rename = "globalEnd", default, serialize_with = "opt_ms")]
    #[serde(skip_serializing_if = "none")]
    global_end: Option<f64>,
    #[serde(rename = "bmla:status", default, skip_serializing_if = "none")]
    status: Option<String>,
}

/// A behaviour child of a prediction: its element name, `block:behaviour`, and a key per sync.
#[derive(Serialize, Deserialize)]
struct BehaviourLine {
    feedback: String,
    id: String,
    #[serde(flatten, serialize_with = "syncs_ms")]
    syncs: IndexMap<String, f64>,
}

/// Whether an optional field is absent (its key is then left out of the line).
fn none<T>(o: &Option<T>) -> bool {
    o.is_none()
}

fn is_false(b: &bool) -> bool {
    !*b
}

fn ms<S: Serializer>(t: &f64, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_f64(round_ms(*t))
}

fn opt_ms<S: Serializer>(t: &Option<f64>, s: S) -> Result<S::Ok, S::Error> {
    match t {
        Some(t) => s.serialize_some(&round_ms(*t)),
        None => s.serialize_none(),
    }
}

fn syncs_ms<S: Serializer>(syncs: &IndexMap<String, f64>, s: S) -> Result<S::Ok, S::Error> {
    s.collect_map(syncs.iter().map(|(k, t)| (k, round_ms(*t))))
}

/// Encodes one message as one JSON line (no trailing newline).
pub fn to_json(fb: &Feedback) -> String {
    if let Feedback::World(w) = fb {
        return w.to_json();
    }
    serde_json::to_string(&Line::of(fb)).expect("feedback always encodes")
}

/// Decodes one JSON feedback line.
pub fn from_json(line: &str) -> Result<Feedback, FeedbackError> {
    let value: serde_json::Value =
        serde_json::from_str(line).map_err(|e| FeedbackError(format!("not JSON: {e}")))?;
    let kind = value.get("feedback").ok_or_else(|| {
        FeedbackError("a feedback element is a JSON object with a \"feedback\" key".into())
    })?;
    let line = match kind.as_str() {
        Some("blockProgress") => Line::BlockProgress(field_checked(value)?),
        Some("syncPointProgress") => Line::SyncPointProgress(field_checked(value)?),
        Some("predictionFeedback") => Line::Prediction(field_checked(value)?),
        Some("warningFeedback") => Line::Warning(field_checked(value)?),
        Some(k @ ("perception" | "net" | "var")) => {
            let k = k.to_string();
            return WorldFeedback::from_json(&k, value)
                .expect("one of the world's kinds")
                .map(Feedback::World);
        }
        _ => return Err(FeedbackError(format!("unknown feedback {kind}"))),
    };
    line.feedback()
}

/// `value` read as a `T`; the error names the field (`bml[0].globalStart: ...`).
fn field_checked<T: serde::de::DeserializeOwned>(
    value: serde_json::Value,
) -> Result<T, FeedbackError> {
    serde_path_to_error::deserialize(value).map_err(|e| {
        let path = e.path().to_string();
        match path.as_str() {
            "." => FeedbackError(e.into_inner().to_string()),
            _ => FeedbackError(format!("{path}: {}", e.into_inner())),
        }
    })
}

impl Line {
    fn of(fb: &Feedback) -> Line {
        match fb {
            Feedback::BlockProgress(b) => Line::BlockProgress(BlockProgressLine {
                feedback: fb.element_name().into(),
                id: format!("{}:{}", b.block, b.sync),
                global_time: b.global_time,
                character_id: b.character_id.clone(),
                status: b.status.map(|s| s.as_str().to_string()),
                posix_time: b.posix_time,
            }),
            Feedback::SyncPointProgress(s) => Line::SyncPointProgress(SyncPointLine {
                feedback: fb.element_name().into(),
                id: format!("{}:{}:{}", s.block, s.behaviour, s.sync),
                time: s.time,
                global_time: s.global_time,
                character_id: s.character_id.clone(),
                posix_time: s.posix_time,
                skipped: s.skipped,
            }),
            Feedback::Prediction(p) => Line::Prediction(PredictionLine {
                feedback: fb.element_name().into(),
                character_id: p.character_id.clone(),
                bml: p.blocks.iter().map(BlockLine::of).collect(),
                behaviors: p.behaviours.iter().map(BehaviourLine::of).collect(),
            }),
            Feedback::World(_) => unreachable!("written by to_json"),
            Feedback::Warning(w) => Line::Warning(WarningLine {
                feedback: fb.element_name().into(),
                id: w.id.clone(),
                kind: w.kind.as_str().to_string(),
                character_id: w.character_id.clone(),
                text: w.text.clone(),
            }),
        }
    }

    fn feedback(self) -> Result<Feedback, FeedbackError> {
        Ok(match self {
            Line::BlockProgress(BlockProgressLine {
                id,
                global_time,
                character_id,
                status,
                posix_time,
                ..
            }) => {
                let (block, sync) = block_and_sync(&id)?;
                Feedback::BlockProgress(BlockProgress {
                    block: block.into(),
                    sync: sync.into(),
                    global_time,
                    character_id,
                    status: status_of(status)?,
                    posix_time,
                })
            }
            Line::SyncPointProgress(SyncPointLine {
                id,
                time,
                global_time,
                character_id,
                posix_time,
                skipped,
                ..
            }) => {
                let [block, behaviour, sync] = sync_point_id(&id)?;
                Feedback::SyncPointProgress(SyncPointProgress {
                    block: block.into(),
                    behaviour: behaviour.into(),
                    sync: sync.into(),
                    time,
                    global_time,
                    character_id,
                    posix_time,
                    skipped,
                })
            }
            Line::Prediction(PredictionLine {
                character_id,
                bml,
                behaviors,
                ..
            }) => Feedback::Prediction(PredictionFeedback {
                character_id,
                blocks: bml
                    .into_iter()
                    .map(BlockLine::prediction)
                    .collect::<Result<_, _>>()?,
                behaviours: (behaviors.into_iter())
                    .map(BehaviourLine::prediction)
                    .collect::<Result<_, _>>()?,
            }),
            Line::Warning(WarningLine {
                id,
                kind,
                character_id,
                text,
                ..
            }) => Feedback::Warning(WarningFeedback {
                id,
                kind: WarningType::parse(&kind),
                character_id,
                text,
            }),
        })
    }
}

impl BlockLine {
    fn of(b: &BlockPrediction) -> BlockLine {
        BlockLine {
            feedback: "bml".into(),
            id: b.id.to_string(),
            global_start: b.global_start,
            global_end: b.global_end,
            status: b.status.map(|s| s.as_str().to_string()),
        }
    }

    fn prediction(self) -> Result<BlockPrediction, FeedbackError> {
        if self.feedback != "bml" {
            return Err(FeedbackError(format!(
                "a block prediction under \"bml\" is a \"bml\" element, not \"{}\"",
                self.feedback
            )));
        }
        Ok(BlockPrediction {
            id: self.id.into(),
            global_start: self.global_start,
            global_end: self.global_end,
            status: status_of(self.status)?,
        })
    }
}

impl BehaviourLine {
    fn of(b: &BehaviourPrediction) -> BehaviourLine {
        BehaviourLine {
            feedback: b.kind.to_string(),
            id: format!("{}:{}", b.block, b.behaviour),
            syncs: (b.syncs.iter()).map(|(s, t)| (s.to_string(), *t)).collect(),
        }
    }

    fn prediction(self) -> Result<BehaviourPrediction, FeedbackError> {
        let parts = split_id(&self.id, 2, "behaviour prediction")?;
        let [block, behaviour] = <[String; 2]>::try_from(parts).expect("two parts");
        check_name(&self.feedback)?;
        if self.feedback == "bml" {
            return Err(FeedbackError(
                "a behaviour prediction cannot be named 'bml'".into(),
            ));
        }
        let mut syncs = Vec::with_capacity(self.syncs.len());
        for (sync, t) in self.syncs {
            check_name(&sync)?;
            syncs.push((sync.as_str().into(), t));
        }
        Ok(BehaviourPrediction {
            kind: self.feedback.as_str().into(),
            block: block.into(),
            behaviour: behaviour.into(),
            syncs,
            attributes: Vec::new(),
        })
    }
}

fn status_of(status: Option<String>) -> Result<Option<BlockStatus>, FeedbackError> {
    status
        .map(|s| {
            BlockStatus::parse(&s)
                .ok_or_else(|| FeedbackError(format!("unknown bmla:status '{s}'")))
        })
        .transpose()
}
