//! How a served realizer speaks on its broker: which topics carry blocks in and feedback out,
//! and in what form (docs/broker.md). Four dialects:
//! - `Topics` (MQTT, this project's own): blocks on `PREFIX/CHARACTER/bml`, feedback on
//!   `PREFIX/CHARACTER/feedback`;
//! - `Ipaaca` (MQTT, as ipaacar speaks it): per channel, `bml` messages and `realizerRequest`
//!   IUs in, `bmlfeedback` messages out, request IUs updated (`bml_realizer::ports::broker::ipaaca`);
//! - `Asap` (STOMP, as AsapRealizer's ActiveMQ adapters do): blocks as text on
//!   `asap.bml.request`, every feedback element as text on `asap.bml.feedback`;
//! - `Greta` (STOMP, as Greta's ActiveMQ components do): blocks as text on `greta.BML`, block
//!   callbacks on `greta.output.feedback.BML` — an empty text message whose properties
//!   `feedback-type` (`start`, `end`, `stopped` when interrupted, `dead` when revoked before it
//!   started), `feedback-id` (the block) and `feedback-time` (ms) say what happened.
//!
//! On the STOMP dialects the block's `characterId` names its character (the topics are shared).

use bml_realizer::language::feedback::{BlockStatus, Feedback, Format};
use bml_realizer::ports::broker::ipaaca::{self, iu::Requests, Heard};
use bml_realizer::ports::broker::{Ipaaca, Topics, DEFAULT_CHARACTER};
use quick_xml::events::Event;

/// Whose queue a block waits in (each character's in turn: one character's flood does not
/// hold up another's).
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord)]
pub enum Lane {
    /// The character a topic names (MQTT topics, ipaaca channels).
    Topic(String),
    /// A shared topic (the STOMP dialects): the character the block's `characterId` names,
    /// peeked at on arrival ([`peek_character`]); the block, once read, decides.
    Shared(String),
}

impl Lane {
    /// The character the lane is for.
    pub fn character(&self) -> &str {
        match self {
            Lane::Topic(c) | Lane::Shared(c) => c,
        }
    }
}

/// The `characterId` of the root element of `payload` (the default character when it has none
/// or cannot be read): only the start of the text is read.
pub fn peek_character(payload: &[u8]) -> String {
    let mut reader = quick_xml::Reader::from_reader(payload);
    let mut buf = Vec::new();
    loop {
        match reader.read_event_into(&mut buf) {
            Ok(Event::Start(e) | Event::Empty(e)) => {
                let id = (e.attributes().flatten())
                    .find(|a| a.key.local_name().as_ref() == b"characterId")
                    .and_then(|a| a.unescape_value().ok().map(|v| v.into_owned()));
                return block_character(id.as_deref());
            }
            Ok(Event::Eof) | Err(_) => return DEFAULT_CHARACTER.to_string(),
            Ok(_) => buf.clear(),
        }
    }
}

/// A dialect (see the module documentation).
pub enum Dialect {
    /// This project's MQTT topics.
    Topics(Topics),
    /// ipaaca over MQTT, and the request IUs being answered.
    Ipaaca(Ipaaca, Requests),
    /// AsapRealizer's ActiveMQ topics: (blocks in, feedback out).
    Asap(String, String),
    /// Greta's ActiveMQ topics: (blocks in, callbacks out).
    Greta(String, String),
}

/// What arrived, as the serving loop needs it.
pub enum Arrived {
    /// A block waiting in `lane`, asked for by request IU `request` if one did.
    Block {
        lane: Lane,
        payload: Vec<u8>,
        request: Option<String>,
    },
    /// Something for `character` that cannot be read (why).
    Bad {
        character: String,
        why: String,
        request: Option<String>,
    },
    /// Something only the dialect needed (done); nothing for the realizer.
    Nothing,
}

/// A message's headers (STOMP).
pub type Headers = Vec<(String, String)>;

/// One message out: topic (a name, not yet a STOMP destination), payload, headers.
pub type Out = (String, Vec<u8>, Headers);

impl Dialect {
    /// The topics to hear blocks on.
    pub fn subscriptions(&self, topics: &Topics, characters: &[String]) -> Vec<String> {
        match self {
            Dialect::Topics(_) if characters.is_empty() => vec![topics.all_bml()],
            Dialect::Topics(_) => characters.iter().map(|c| topics.bml(c)).collect(),
            Dialect::Ipaaca(ip, _) => ip.subscriptions(),
            Dialect::Asap(bml, _) | Dialect::Greta(bml, _) => vec![bml.clone()],
        }
    }

    /// Reads a message on `topic`: `None` when it is not one of this dialect's block topics.
    pub fn read(&mut self, topic: &str, payload: Vec<u8>) -> Option<Arrived> {
        match self {
            Dialect::Topics(t) => {
                let lane = Lane::Topic(t.bml_character(topic)?.to_string());
                Some(Arrived::Block {
                    lane,
                    payload,
                    request: None,
                })
            }
            Dialect::Asap(bml, _) | Dialect::Greta(bml, _) => {
                (topic == bml).then(|| Arrived::Block {
                    lane: Lane::Shared(peek_character(&payload)),
                    payload,
                    request: None,
                })
            }
            Dialect::Ipaaca(ip, requests) => Some(match ip.read(topic, &payload)? {
                Heard::Block {
                    channel,
                    text,
                    request,
                } => {
                    let request = request.map(|(uid, p)| {
                        requests.add(&channel, &uid, p);
                        uid
                    });
                    Arrived::Block {
                        lane: Lane::Topic(Ipaaca::character(&channel).to_string()),
                        payload: text.into_bytes(),
                        request,
                    }
                }
                Heard::Bad {
                    channel,
                    why,
                    request,
                } => {
                    let request = request.map(|(uid, p)| {
                        requests.add(&channel, &uid, p);
                        uid
                    });
                    Arrived::Bad {
                        character: Ipaaca::character(&channel).to_string(),
                        why,
                        request,
                    }
                }
                Heard::Replaced { uid, payload } => {
                    requests.replaced(&uid, payload);
                    Arrived::Nothing
                }
                Heard::Closed { uid } => {
                    requests.forget(&uid);
                    Arrived::Nothing
                }
                // (answered by the loop, which can send)
                Heard::NewComponent { .. } | Heard::Nothing => Arrived::Nothing,
            }),
        }
    }

    /// Where blocks for `character` come from (named in warnings).
    pub fn source(&self, character: &str) -> String {
        match self {
            Dialect::Topics(t) => t.bml(character),
            Dialect::Ipaaca(ip, _) => {
                let channel = ip.channel_of(character).unwrap_or(ipaaca::DEFAULT_CHANNEL);
                format!("{channel}/bml/M")
            }
            Dialect::Asap(bml, _) | Dialect::Greta(bml, _) => bml.clone(),
        }
    }

    /// The messages that say `fb` about `character` (a topic level); `posix` is the POSIX
    /// time (s) of the realizer's time 0.
    pub fn feedback(
        &mut self,
        character: &str,
        fb: &Feedback,
        format: Format,
        posix: f64,
    ) -> Vec<Out> {
        match self {
            Dialect::Topics(t) => vec![(
                t.feedback(character),
                format.encode(fb).into_bytes(),
                Vec::new(),
            )],
            Dialect::Asap(_, out) => {
                vec![(out.clone(), format.encode(fb).into_bytes(), Vec::new())]
            }
            Dialect::Greta(_, out) => greta_callback(fb)
                .map(|(body, headers)| (out.clone(), body, headers))
                .into_iter()
                .collect(),
            Dialect::Ipaaca(ip, requests) => {
                let xml = Format::Xml.encode(fb);
                let mut out: Vec<Out> = (ip.feedback(character, &xml))
                    .map(|(t, p)| (t, p, Vec::new()))
                    .into_iter()
                    .collect();
                let channel = ip.channel_of(character).unwrap_or(ipaaca::DEFAULT_CHANNEL);
                out.extend(request_updates(requests, channel, fb, posix));
                out
            }
        }
    }

    /// The request IU `uid`'s answer to a block taken (`bmlid`, status `((RECEIVED))`) or
    /// refused (status `ERROR` with `error`), as AsapRealizer's IU adapter answers.
    pub fn answer_request(
        &mut self,
        uid: &str,
        block: Option<&str>,
        error: Option<&str>,
    ) -> Vec<Out> {
        let Dialect::Ipaaca(_, requests) = self else {
            return Vec::new();
        };
        let items = match (block, error) {
            (_, Some(e)) => vec![("status", "ERROR".to_string()), ("error", e.to_string())],
            (Some(b), None) => vec![
                ("bmlid", b.to_string()),
                ("status", "((RECEIVED))".to_string()),
            ],
            (None, None) => return Vec::new(),
        };
        if let (Some(b), None) = (block, error) {
            if let Some(channel) = requests.channel(uid).map(str::to_string) {
                requests.bind(&channel, b, uid);
            }
        }
        (requests.merge(uid, &items))
            .map(|(channel, bytes)| (Ipaaca::request_topic(&channel, uid), bytes, Vec::new()))
            .into_iter()
            .collect()
    }
}

/// The updates of the request IU (if any) that asked for `fb`'s block, as AsapRealizer's IU
/// adapter makes them: start → `IN_EXEC` with `lastSyncId` `start`, a sync point → its
/// `lastSyncId`, end → `DONE`, a prediction → `predictedStartTime`/`predictedEndTime` (POSIX
/// seconds; the realizer's time 0 is `posix`).
fn request_updates(requests: &mut Requests, channel: &str, fb: &Feedback, posix: f64) -> Vec<Out> {
    let mut changes: Vec<(String, Vec<(&str, String)>)> = Vec::new();
    match fb {
        Feedback::BlockProgress(p) if p.sync.as_str() == "start" => changes.push((
            p.block.to_string(),
            vec![("status", "IN_EXEC".into()), ("lastSyncId", "start".into())],
        )),
        Feedback::BlockProgress(p) if p.sync.as_str() == "end" => {
            changes.push((p.block.to_string(), vec![("status", "DONE".into())]))
        }
        Feedback::SyncPointProgress(p) if p.sync.as_str() != "start" => changes.push((
            p.block.to_string(),
            vec![("lastSyncId", format!("{}:{}", p.behaviour, p.sync))],
        )),
        Feedback::Prediction(pf) => {
            for b in &pf.blocks {
                let mut items = Vec::new();
                if let Some(s) = b.global_start {
                    items.push(("predictedStartTime", format!("{:.3}", posix + s)));
                }
                if let Some(e) = b.global_end {
                    items.push(("predictedEndTime", format!("{:.3}", posix + e)));
                }
                changes.push((b.id.to_string(), items));
            }
        }
        _ => {}
    }
    (changes.into_iter())
        .filter_map(|(block, items)| {
            let uid = requests.of_block(channel, &block)?.to_string();
            let (channel, bytes) = requests.merge(&uid, &items)?;
            Some((Ipaaca::request_topic(&channel, &uid), bytes, Vec::new()))
        })
        .collect()
}

/// Greta's callback for `fb`, if it is one Greta has: an empty body and its properties; a
/// warning travels as its XML with `feedback-type` `warning`.
fn greta_callback(fb: &Feedback) -> Option<(Vec<u8>, Headers)> {
    let ms = |t: f64| format!("{}", (t * 1000.0).round() as i64);
    let (kind, id, time, body) = match fb {
        Feedback::BlockProgress(p) => {
            let kind = match (p.sync.as_str(), p.status) {
                ("start", _) => "start",
                ("end", Some(BlockStatus::Interrupted)) => "stopped",
                ("end", Some(BlockStatus::Revoked)) => "dead",
                ("end", _) => "end",
                _ => return None,
            };
            (kind, p.block.to_string(), ms(p.global_time), Vec::new())
        }
        Feedback::Warning(w) => (
            "warning",
            w.id.clone(),
            String::new(),
            Format::Xml.encode(fb).into_bytes(),
        ),
        _ => return None,
    };
    let mut headers = vec![
        ("feedback-type".to_string(), kind.to_string()),
        ("feedback-id".to_string(), id),
    ];
    if !time.is_empty() {
        headers.push(("feedback-time".to_string(), time));
    }
    Some((body, headers))
}

/// The character (a topic level) of a block whose character only the block says.
pub fn block_character(character_id: Option<&str>) -> String {
    character_id.unwrap_or(DEFAULT_CHARACTER).to_string()
}
