//! ipaaca as ipaacar speaks it, so that the realizer can stand in for AsapRealizer among ipaaca
//! components (`bmlr serve --mqtt URL --ipaaca CH[,CH2…]`). ipaacar (the reference: its Python
//! binding `ipaacar-python`, run against this realizer in the tests) puts a message of category
//! `C` on channel `CH` on the MQTT topic `CH/C/M` — `M` is literal, it marks a message — with
//! the payload exactly as the sender gave it, and every event of an IU on `CH/C/IU/UID`
//! ([`iu`]). A channel is a character: AsapRealizer's adapters take the character id as the
//! channel, `default` when there is none (here: the realizer's default character).
//!
//! What the realizer understands on each channel, as AsapRealizer's adapters define it (read in
//! its `asap.ipaacaadapters` and `asap.ipaacaiuadapters` sources, never copied):
//! - messages of category `bml`, payload `{"bml": TEXT}` (also the bare `<bml …>` text);
//! - IUs of category `realizerRequest` (`{"type": "bml", "request": TEXT}` or `"type":
//!   "bmlfile"` with a path), answered by updates of the same IU ([`iu::Requests`]);
//! - `componentNotify` messages (ipaaca's component announcement: `name`, `function`,
//!   `send_categories`, `receive_categories`, `state` = `new` | `old` | `down`): the realizer
//!   announces itself `new` on start, answers another's `new` with `old`, says `down` on close.
//!
//! What it sends: every feedback element as a message of category `bmlfeedback`, payload
//! `{"bmlfeedback": XML}`, on the channel of the character it is about.

pub mod iu;

use serde::{Deserialize, Serialize};
use serde_json::{Map, Value as Json};

use super::topics::{level_ok, DEFAULT_CHARACTER};

/// The channel of the default character.
pub const DEFAULT_CHANNEL: &str = "default";

/// ipaaca's component-announcement category.
pub const NOTIFY_CATEGORY: &str = "componentNotify";

/// The ipaaca channels a realizer serves (one per character).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Ipaaca {
    channels: Vec<String>,
    name: String,
}

/// What arrived on an ipaaca topic.
#[derive(Debug, Clone, PartialEq)]
pub enum Heard {
    /// A block for the channel's character; `request` is the IU that asked for it (its uid
    /// and payload), if one did.
    Block {
        /// The channel.
        channel: String,
        /// The block's text.
        text: String,
        /// The request IU's uid and payload.
        request: Option<(String, Map<String, Json>)>,
    },
    /// Something for the channel that is not a block it can read (why); the request IU (uid
    /// and payload), if it came as one.
    Bad {
        /// The channel.
        channel: String,
        /// Why it cannot be read.
        why: String,
        /// The request IU's uid and payload.
        request: Option<(String, Map<String, Json>)>,
    },
    /// A request IU's payload replaced (by its owner, or this realizer's own update heard back).
    Replaced {
        /// The IU's uid.
        uid: String,
        /// Its payload now.
        payload: Map<String, Json>,
    },
    /// A request IU committed or retracted.
    Closed {
        /// The IU's uid.
        uid: String,
    },
    /// Another component announced itself as new on the channel: answer with [`Ipaaca::notify`].
    NewComponent {
        /// The channel.
        channel: String,
    },
    /// Nothing for the realizer (its own messages, other categories, other events).
    Nothing,
}

#[derive(Deserialize)]
struct BmlMessage {
    bml: String,
}

#[derive(Serialize)]
struct FeedbackMessage<'a> {
    bmlfeedback: &'a str,
}

#[derive(Serialize, Deserialize)]
struct Notify {
    name: String,
    #[serde(default)]
    function: String,
    #[serde(default)]
    send_categories: String,
    #[serde(default)]
    receive_categories: String,
    state: String,
}

impl Ipaaca {
    /// Serves `channels` (each one topic level; `default` is the default character) as the
    /// component `name`.
    pub fn new(channels: &[String], name: &str) -> Result<Ipaaca, String> {
        if channels.is_empty() {
            return Err("names no channel (e.g. --ipaaca default,Alice)".into());
        }
        if let Some(bad) = channels.iter().find(|c| !level_ok(c)) {
            return Err(format!(
                "'{bad}' is not an ipaaca channel (one topic level, no '/', '+', '#')"
            ));
        }
        Ok(Ipaaca {
            channels: channels.to_vec(),
            name: name.to_string(),
        })
    }

    /// The channels served.
    pub fn channels(&self) -> &[String] {
        &self.channels
    }

    /// The character (a topic level, `_` the default one) a channel stands for.
    pub fn character(channel: &str) -> &str {
        if channel == DEFAULT_CHANNEL {
            DEFAULT_CHARACTER
        } else {
            channel
        }
    }

    /// The channel of `character` (a topic level), if served.
    pub fn channel_of(&self, character: &str) -> Option<&str> {
        let channel = if character == DEFAULT_CHARACTER {
            DEFAULT_CHANNEL
        } else {
            character
        };
        self.channels
            .iter()
            .find(|c| *c == channel)
            .map(String::as_str)
    }

    /// What the realizer subscribes to: per channel, the `bml` messages, the request IUs and
    /// the component announcements.
    pub fn subscriptions(&self) -> Vec<String> {
        (self.channels.iter())
            .flat_map(|c| {
                [
                    format!("{c}/bml/M"),
                    format!("{c}/{}/IU/+", iu::REQUEST_CATEGORY),
                    format!("{c}/{NOTIFY_CATEGORY}/M"),
                ]
            })
            .collect()
    }

    /// Reads a message on `topic`: `None` when the topic is not one of the served channels'.
    pub fn read(&self, topic: &str, payload: &[u8]) -> Option<Heard> {
        let mut levels = topic.split('/');
        let (channel, category, kind) = (levels.next()?, levels.next()?, levels.next()?);
        let uid = levels.next();
        if levels.next().is_some() || !self.channels.iter().any(|c| c == channel) {
            return None;
        }
        let channel = channel.to_string();
        Some(match (category, kind, uid) {
            ("bml", "M", None) => match read_bml(payload) {
                Ok(text) => Heard::Block {
                    channel,
                    text,
                    request: None,
                },
                Err(why) => Heard::Bad {
                    channel,
                    why,
                    request: None,
                },
            },
            (NOTIFY_CATEGORY, "M", None) => match serde_json::from_slice::<Notify>(payload) {
                Ok(n) if n.state == "new" && n.name != self.name => Heard::NewComponent { channel },
                _ => Heard::Nothing,
            },
            (iu::REQUEST_CATEGORY, "IU", Some(uid)) => self.read_request(channel, uid, payload),
            _ => Heard::Nothing,
        })
    }

    fn read_request(&self, channel: String, uid: &str, payload: &[u8]) -> Heard {
        let event = match iu::read_event(payload) {
            Ok(e) => e,
            Err(why) => {
                return Heard::Bad {
                    channel,
                    why,
                    request: None,
                }
            }
        };
        match event {
            iu::IuEvent::Published { payload, .. } => {
                let block = read_request(&payload);
                let request = Some((uid.to_string(), payload));
                match block {
                    Ok(text) => Heard::Block {
                        channel,
                        text,
                        request,
                    },
                    Err(why) => Heard::Bad {
                        channel,
                        why,
                        request,
                    },
                }
            }
            iu::IuEvent::Payload { uid, payload } => Heard::Replaced { uid, payload },
            iu::IuEvent::Closed { uid } => Heard::Closed { uid },
            iu::IuEvent::Other => Heard::Nothing,
        }
    }

    /// The topic and payload of one feedback element `xml` about `character` (a topic level):
    /// `None` when no channel serves that character.
    pub fn feedback(&self, character: &str, xml: &str) -> Option<(String, Vec<u8>)> {
        let channel = self.channel_of(character)?;
        let payload =
            serde_json::to_vec(&FeedbackMessage { bmlfeedback: xml }).expect("a string serialises");
        Some((format!("{channel}/bmlfeedback/M"), payload))
    }

    /// The topic of request `uid` on `channel` (where its updates go).
    pub fn request_topic(channel: &str, uid: &str) -> String {
        format!("{channel}/{}/IU/{uid}", iu::REQUEST_CATEGORY)
    }

    /// The component announcement (`new`, `old` or `down`) on every channel served.
    pub fn notify(&self, state: &str) -> Vec<(String, Vec<u8>)> {
        let n = Notify {
            name: self.name.clone(),
            function: "bmlrealizer".into(),
            send_categories: "bmlfeedback".into(),
            receive_categories: format!("bml,{}", iu::REQUEST_CATEGORY),
            state: state.into(),
        };
        let payload = serde_json::to_vec(&n).expect("strings serialise");
        (self.channels.iter())
            .map(|c| (format!("{c}/{NOTIFY_CATEGORY}/M"), payload.clone()))
            .collect()
    }
}

/// A `bml` message's block: `{"bml": TEXT}`, or the bare text of a `<bml>` element.
fn read_bml(payload: &[u8]) -> Result<String, String> {
    let text = std::str::from_utf8(payload).map_err(|_| "the payload is not UTF-8 text")?;
    if text.trim_start().starts_with('<') {
        return Ok(text.to_string());
    }
    serde_json::from_str::<BmlMessage>(text)
        .map(|m| m.bml)
        .map_err(|e| format!("not an ipaaca BML message ({{\"bml\": TEXT}}): {e}"))
}

/// Files a `bmlfile` request may name, at most (bytes; AsapRealizer's limit).
pub const BML_FILE_LIMIT: u64 = 4 << 20;

/// A request IU's block: `type` `bml` (or none) with the block in `request`, or `bmlfile`
/// with a path to read.
fn read_request(payload: &Map<String, Json>) -> Result<String, String> {
    let request = (payload.get("request").and_then(Json::as_str))
        .ok_or("a realizerRequest without a 'request' text")?;
    match payload.get("type").and_then(Json::as_str).unwrap_or("bml") {
        "bml" => Ok(request.to_string()),
        "bmlfile" => {
            let size = std::fs::metadata(request)
                .map_err(|e| format!("bmlfile '{request}': {e}"))?
                .len();
            if size > BML_FILE_LIMIT {
                return Err(format!("bmlfile '{request}' is larger than 4 MiB"));
            }
            std::fs::read_to_string(request).map_err(|e| format!("bmlfile '{request}': {e}"))
        }
        other => Err(format!("unknown request type '{other}' (bml or bmlfile)")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ip() -> Ipaaca {
        Ipaaca::new(&["default".into(), "Alice".into()], "bmlr").unwrap()
    }

    #[test]
    fn messages_are_read_on_the_channels_served_as_ipaacar_sends_them() {
        let ip = ip();
        assert_eq!(
            ip.subscriptions()[..3],
            [
                "default/bml/M",
                "default/realizerRequest/IU/+",
                "default/componentNotify/M"
            ]
        );
        assert_eq!(
            ip.read("Alice/bml/M", br#"{"bml": "<bml id=\"b\"/>"}"#),
            Some(Heard::Block {
                channel: "Alice".into(),
                text: r#"<bml id="b"/>"#.into(),
                request: None
            })
        );
        let bare = ip.read("default/bml/M", b" <bml id=\"b\"/>");
        assert!(matches!(bare, Some(Heard::Block { .. })));
        assert!(matches!(
            ip.read("Alice/bml/M", b"garbage"),
            Some(Heard::Bad { .. })
        ));
        assert_eq!(ip.read("Bob/bml/M", b"{}"), None);
        assert_eq!(ip.read("Alice/bml/x/y", b"{}"), Some(Heard::Nothing));
        assert_eq!(ip.read("Alice/bml/M/a/b", b"{}"), None);
        assert_eq!(ip.read("Alice/bmlfeedback/M", b"{}"), Some(Heard::Nothing));
        let (topic, payload) = ip
            .feedback("_", r#"<blockProgress id="b:start"/>"#)
            .unwrap();
        assert_eq!(topic, "default/bmlfeedback/M");
        assert_eq!(
            String::from_utf8(payload).unwrap(),
            r#"{"bmlfeedback":"<blockProgress id=\"b:start\"/>"}"#
        );
        assert!(ip.feedback("Bob", "x").is_none());
        assert!(Ipaaca::new(&["a/b".into()], "n").is_err());
        assert!(Ipaaca::new(&[], "n").is_err());
    }

    #[test]
    fn components_announce_themselves_and_others_are_answered() {
        let ip = ip();
        let notes = ip.notify("new");
        assert_eq!(notes.len(), 2);
        assert_eq!(notes[1].0, "Alice/componentNotify/M");
        // its own announcement heard back is nothing; another's `new` asks for an answer
        assert_eq!(ip.read(&notes[1].0, &notes[1].1), Some(Heard::Nothing));
        let other = br#"{"name": "planner", "function": "x", "send_categories": "bml", "receive_categories": "", "state": "new"}"#;
        assert_eq!(
            ip.read("Alice/componentNotify/M", other),
            Some(Heard::NewComponent {
                channel: "Alice".into()
            })
        );
    }

    #[test]
    fn request_payloads_give_their_block_or_say_why_not() {
        let mut p = Map::new();
        p.insert("type".into(), "bml".into());
        p.insert("request".into(), "<bml id=\"r\"/>".into());
        assert_eq!(read_request(&p).unwrap(), "<bml id=\"r\"/>");
        p.insert("type".into(), "speech".into());
        assert!(read_request(&p)
            .unwrap_err()
            .contains("unknown request type"));
        p.insert("type".into(), "bmlfile".into());
        p.insert("request".into(), "/no/such/file.xml".into());
        assert!(read_request(&p).unwrap_err().contains("/no/such/file.xml"));
        p.remove("request");
        assert!(read_request(&p).is_err());
    }
}
