//! The JSON-lines codec of feedback: one object per line, `"feedback"` naming the element, the
//! other keys being the XML attribute names verbatim (`"bmla:status"`, ...), times as numbers
//! rounded to the millisecond, a warning's text under `"text"`, a prediction's children under
//! `"bml"` and `"behaviors"` (objects of the same shape).

use serde_json::{json, Map, Value};

use super::*;

fn time(v: f64) -> Value {
    json!(round_ms(v))
}

fn put_opt(m: &mut Map<String, Value>, k: &str, v: Option<Value>) {
    if let Some(v) = v {
        m.insert(k.to_string(), v);
    }
}

fn to_value(fb: &Feedback) -> Value {
    let mut m = Map::new();
    m.insert("feedback".into(), json!(fb.element_name()));
    match fb {
        Feedback::BlockProgress(b) => {
            m.insert("id".into(), json!(format!("{}:{}", b.block, b.sync)));
            m.insert("globalTime".into(), time(b.global_time));
            put_opt(
                &mut m,
                "characterId",
                b.character_id.as_ref().map(|c| json!(c)),
            );
            put_opt(&mut m, "bmla:status", b.status.map(|s| json!(s.as_str())));
            put_opt(&mut m, "bmla:posixTime", b.posix_time.map(|p| json!(p)));
        }
        Feedback::SyncPointProgress(s) => {
            m.insert(
                "id".into(),
                json!(format!("{}:{}:{}", s.block, s.behaviour, s.sync)),
            );
            m.insert("time".into(), time(s.time));
            m.insert("globalTime".into(), time(s.global_time));
            put_opt(
                &mut m,
                "characterId",
                s.character_id.as_ref().map(|c| json!(c)),
            );
            put_opt(&mut m, "bmla:posixTime", s.posix_time.map(|p| json!(p)));
            if s.skipped {
                m.insert("bmla:skipped".into(), json!(true));
            }
        }
        Feedback::Prediction(p) => {
            put_opt(
                &mut m,
                "characterId",
                p.character_id.as_ref().map(|c| json!(c)),
            );
            let blocks: Vec<Value> = p
                .blocks
                .iter()
                .map(|b| {
                    let mut o = Map::new();
                    o.insert("feedback".into(), json!("bml"));
                    o.insert("id".into(), json!(b.id.as_str()));
                    put_opt(&mut o, "globalStart", b.global_start.map(time));
                    put_opt(&mut o, "globalEnd", b.global_end.map(time));
                    put_opt(&mut o, "bmla:status", b.status.map(|s| json!(s.as_str())));
                    Value::Object(o)
                })
                .collect();
            let behaviours: Vec<Value> = p
                .behaviours
                .iter()
                .map(|b| {
                    let mut o = Map::new();
                    o.insert("feedback".into(), json!(b.kind.as_str()));
                    o.insert("id".into(), json!(format!("{}:{}", b.block, b.behaviour)));
                    for (sync, t) in &b.syncs {
                        o.insert(sync.to_string(), time(*t));
                    }
                    Value::Object(o)
                })
                .collect();
            m.insert("bml".into(), Value::Array(blocks));
            m.insert("behaviors".into(), Value::Array(behaviours));
        }
        Feedback::Warning(w) => {
            m.insert("id".into(), json!(w.id));
            m.insert("type".into(), json!(w.kind.as_str()));
            put_opt(
                &mut m,
                "characterId",
                w.character_id.as_ref().map(|c| json!(c)),
            );
            m.insert("text".into(), json!(w.text));
        }
    }
    Value::Object(m)
}

/// Encodes one message as one JSON line (no trailing newline).
pub fn to_json(fb: &Feedback) -> String {
    to_value(fb).to_string()
}

fn str_of<'a>(m: &'a Map<String, Value>, k: &str) -> Result<&'a str, FeedbackError> {
    m.get(k)
        .and_then(Value::as_str)
        .ok_or_else(|| FeedbackError(format!("missing or non-string \"{k}\"")))
}

fn opt_str(m: &Map<String, Value>, k: &str) -> Result<Option<String>, FeedbackError> {
    match m.get(k) {
        None | Some(Value::Null) => Ok(None),
        Some(Value::String(s)) => Ok(Some(s.clone())),
        Some(_) => Err(FeedbackError(format!("\"{k}\" should be a string"))),
    }
}

fn num_of(m: &Map<String, Value>, k: &str) -> Result<f64, FeedbackError> {
    m.get(k)
        .and_then(Value::as_f64)
        .ok_or_else(|| FeedbackError(format!("missing or non-numeric \"{k}\"")))
}

fn opt_num(m: &Map<String, Value>, k: &str) -> Result<Option<f64>, FeedbackError> {
    match m.get(k) {
        None | Some(Value::Null) => Ok(None),
        Some(v) => v
            .as_f64()
            .map(Some)
            .ok_or_else(|| FeedbackError(format!("\"{k}\" should be a number"))),
    }
}

fn opt_posix(m: &Map<String, Value>) -> Result<Option<u64>, FeedbackError> {
    match m.get("bmla:posixTime") {
        None | Some(Value::Null) => Ok(None),
        Some(v) => v.as_u64().map(Some).ok_or_else(|| {
            FeedbackError("\"bmla:posixTime\" should be a whole number of ms".into())
        }),
    }
}

fn opt_status(m: &Map<String, Value>) -> Result<Option<BlockStatus>, FeedbackError> {
    opt_str(m, "bmla:status")?
        .map(|s| {
            BlockStatus::parse(&s)
                .ok_or_else(|| FeedbackError(format!("unknown bmla:status '{s}'")))
        })
        .transpose()
}

fn objects<'a>(
    m: &'a Map<String, Value>,
    k: &str,
) -> Result<Vec<&'a Map<String, Value>>, FeedbackError> {
    match m.get(k) {
        None => Ok(Vec::new()),
        Some(Value::Array(a)) => a
            .iter()
            .map(|v| {
                v.as_object()
                    .ok_or_else(|| FeedbackError(format!("\"{k}\" should hold objects")))
            })
            .collect(),
        Some(_) => Err(FeedbackError(format!("\"{k}\" should be a list"))),
    }
}

/// Decodes one JSON feedback line.
pub fn from_json(line: &str) -> Result<Feedback, FeedbackError> {
    let v: Value =
        serde_json::from_str(line).map_err(|e| FeedbackError(format!("not JSON: {e}")))?;
    let m = v
        .as_object()
        .ok_or_else(|| FeedbackError("a feedback line must be a JSON object".into()))?;
    let character_id = opt_str(m, "characterId")?;
    match str_of(m, "feedback")? {
        "blockProgress" => {
            let id = str_of(m, "id")?;
            let (block, sync) = id
                .rsplit_once(':')
                .filter(|(b, s)| !b.is_empty() && !s.is_empty())
                .ok_or_else(|| {
                    FeedbackError(format!("blockProgress id '{id}' should be block:sync"))
                })?;
            Ok(Feedback::BlockProgress(BlockProgress {
                block: block.into(),
                sync: sync.into(),
                global_time: num_of(m, "globalTime")?,
                character_id,
                status: opt_status(m)?,
                posix_time: opt_posix(m)?,
            }))
        }
        "syncPointProgress" => {
            let p = split_id(str_of(m, "id")?, 3, "syncPointProgress")?;
            let [block, behaviour, sync] = <[String; 3]>::try_from(p).expect("three parts");
            Ok(Feedback::SyncPointProgress(SyncPointProgress {
                block: block.into(),
                behaviour: behaviour.into(),
                sync: sync.into(),
                time: num_of(m, "time")?,
                global_time: num_of(m, "globalTime")?,
                character_id,
                posix_time: opt_posix(m)?,
                skipped: m.get("bmla:skipped") == Some(&Value::Bool(true)),
            }))
        }
        "warningFeedback" => Ok(Feedback::Warning(WarningFeedback {
            id: str_of(m, "id")?.into(),
            kind: WarningType::parse(str_of(m, "type")?),
            character_id,
            text: opt_str(m, "text")?.unwrap_or_default(),
        })),
        "predictionFeedback" => {
            let mut p = PredictionFeedback {
                character_id,
                ..Default::default()
            };
            for b in objects(m, "bml")? {
                p.blocks.push(BlockPrediction {
                    id: str_of(b, "id")?.into(),
                    global_start: opt_num(b, "globalStart")?,
                    global_end: opt_num(b, "globalEnd")?,
                    status: opt_status(b)?,
                });
            }
            for b in objects(m, "behaviors")? {
                let parts = split_id(str_of(b, "id")?, 2, "behaviour prediction")?;
                let [block, behaviour] = <[String; 2]>::try_from(parts).expect("two parts");
                let mut syncs = Vec::new();
                for (k, v) in b {
                    if k != "id" && k != "feedback" {
                        check_name(k)?;
                        let t = v.as_f64().ok_or_else(|| {
                            FeedbackError(format!("predicted time \"{k}\" should be a number"))
                        })?;
                        syncs.push((k.as_str().into(), t));
                    }
                }
                let kind = str_of(b, "feedback")?;
                check_name(kind)?;
                if kind == "bml" {
                    return Err(FeedbackError(
                        "a behaviour prediction cannot be named 'bml'".into(),
                    ));
                }
                p.behaviours.push(BehaviourPrediction {
                    kind: kind.into(),
                    block: block.into(),
                    behaviour: behaviour.into(),
                    syncs,
                });
            }
            Ok(Feedback::Prediction(p))
        }
        other => Err(FeedbackError(format!("unknown feedback \"{other}\""))),
    }
}
