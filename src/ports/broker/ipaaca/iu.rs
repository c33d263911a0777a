//! ipaaca's incremental units (IUs) as ipaacar puts them on the broker, and the requests an
//! AsapRealizer-style planner makes with them. ipaacar (the Rust ipaaca, whose Python binding
//! `ipaacar-python` is the reference here) sends every event of an IU of category `C` on channel
//! `CH` to the topic `CH/C/IU/UID`, encoded as MessagePack: a one-entry map whose key names the
//! event — `Publish` with the IU as an array `[category, uid, owner buffer, last writer, [links],
//! payload, component]`, or `Update` with `[uid, change]`, the change being `{"Payload": P}`
//! (the whole new payload) or `{"Close": "Committed" | "Retracted"}`. Payloads are JSON objects
//! (ipaacar refuses others), carried as MessagePack maps. This layout was read off the broker
//! while ipaacar-python 0.2.1 published, updated and committed IUs (docs/broker.md); it is
//! decoded loosely by position so that an added trailing field does not break it.
//!
//! AsapRealizer's IU adapter (its `asap.ipaacaiuadapters` package, read for the keys) takes IUs
//! of category `realizerRequest` whose payload says `type` (`bml`: the block is in `request`;
//! `bmlfile`: `request` is a path) and answers by merging keys into the same IU's payload:
//! `status` (`((RECEIVED))`, `IN_EXEC`, `DONE`, `ERROR`), `bmlid`, `lastSyncId`,
//! `predictedStartTime`/`predictedEndTime` (POSIX seconds) and `error`. An update replaces the
//! whole payload, so the table below keeps each request's payload to merge into.

use std::collections::{HashMap, VecDeque};

use rmpv::Value;
use serde_json::{Map, Value as Json};

/// The category of AsapRealizer's request IUs.
pub const REQUEST_CATEGORY: &str = "realizerRequest";

/// Requests remembered at most; beyond, the oldest are forgotten (their later feedback is then
/// sent only as `bmlfeedback` messages).
pub const REQUESTS_KEPT: usize = 4_096;

/// One IU event read off the broker.
#[derive(Debug, Clone, PartialEq)]
pub enum IuEvent {
    /// A new IU: its category, uid and payload.
    Published {
        /// The IU's category.
        category: String,
        /// Its unique id.
        uid: String,
        /// Its payload (a JSON object).
        payload: Map<String, Json>,
    },
    /// An IU's payload replaced.
    Payload {
        /// The IU's uid.
        uid: String,
        /// The new payload.
        payload: Map<String, Json>,
    },
    /// An IU committed or retracted.
    Closed {
        /// The IU's uid.
        uid: String,
    },
    /// Another event (links changed, …).
    Other,
}

/// Reads an IU event (MessagePack); `Err` says why it is not one.
pub fn read_event(bytes: &[u8]) -> Result<IuEvent, String> {
    let value = rmpv::decode::read_value(&mut &bytes[..])
        .map_err(|e| format!("not a MessagePack IU event: {e}"))?;
    let Value::Map(entries) = value else {
        return Err("an IU event is a one-entry map".into());
    };
    let [(Value::String(kind), body)] = entries.as_slice() else {
        return Err("an IU event is a one-entry map named by the event".into());
    };
    let fields = match body {
        Value::Array(f) => f.as_slice(),
        _ => return Err("an IU event's body is an array".into()),
    };
    let text = |i: usize| match fields.get(i) {
        Some(Value::String(s)) => s.as_str().map(str::to_string),
        _ => None,
    };
    match kind.as_str() {
        Some("Publish") => {
            let (Some(category), Some(uid)) = (text(0), text(1)) else {
                return Err("a published IU without category or uid".into());
            };
            let payload = object(fields.get(5))?;
            Ok(IuEvent::Published {
                category,
                uid,
                payload,
            })
        }
        Some("Update") => {
            let uid = text(0).ok_or("an IU update without uid")?;
            let change = match fields.get(1) {
                Some(Value::Map(m)) => m.as_slice(),
                // a unit change (a bare string) carries no payload
                _ => return Ok(IuEvent::Other),
            };
            match change.first() {
                Some((Value::String(k), v)) if k.as_str() == Some("Payload") => {
                    Ok(IuEvent::Payload {
                        uid,
                        payload: object(Some(v))?,
                    })
                }
                Some((Value::String(k), _)) if k.as_str() == Some("Close") => {
                    Ok(IuEvent::Closed { uid })
                }
                _ => Ok(IuEvent::Other),
            }
        }
        _ => Ok(IuEvent::Other),
    }
}

/// The event that replaces IU `uid`'s payload with `payload`, as ipaacar encodes it.
pub fn payload_update(uid: &str, payload: &Map<String, Json>) -> Vec<u8> {
    let change = Value::Map(vec![(
        Value::from("Payload"),
        to_msgpack(&Json::Object(payload.clone())),
    )]);
    let event = Value::Map(vec![(
        Value::from("Update"),
        Value::Array(vec![Value::from(uid), change]),
    )]);
    let mut out = Vec::new();
    rmpv::encode::write_value(&mut out, &event).expect("writing to a Vec cannot fail");
    out
}

/// A payload (a MessagePack map with string keys) as a JSON object.
fn object(v: Option<&Value>) -> Result<Map<String, Json>, String> {
    match v.map(to_json) {
        Some(Json::Object(m)) => Ok(m),
        _ => Err("an IU's payload is not a map".into()),
    }
}

fn to_json(v: &Value) -> Json {
    match v {
        Value::Nil => Json::Null,
        Value::Boolean(b) => Json::Bool(*b),
        Value::Integer(i) => (i.as_i64().map(Json::from))
            .or_else(|| i.as_u64().map(Json::from))
            .unwrap_or(Json::Null),
        Value::F32(f) => {
            serde_json::Number::from_f64(f64::from(*f)).map_or(Json::Null, Json::Number)
        }
        Value::F64(f) => serde_json::Number::from_f64(*f).map_or(Json::Null, Json::Number),
        Value::String(s) => Json::String(s.as_str().unwrap_or_default().to_string()),
        Value::Binary(b) => Json::String(String::from_utf8_lossy(b).into_owned()),
        Value::Array(a) => Json::Array(a.iter().map(to_json).collect()),
        Value::Map(m) => Json::Object(m.iter().map(|(k, v)| (key(k), to_json(v))).collect()),
        Value::Ext(..) => Json::Null,
    }
}

fn key(k: &Value) -> String {
    match k {
        Value::String(s) => s.as_str().unwrap_or_default().to_string(),
        other => other.to_string(),
    }
}

fn to_msgpack(v: &Json) -> Value {
    match v {
        Json::Null => Value::Nil,
        Json::Bool(b) => Value::Boolean(*b),
        Json::Number(n) => (n.as_i64().map(Value::from))
            .or_else(|| n.as_u64().map(Value::from))
            .unwrap_or_else(|| Value::F64(n.as_f64().unwrap_or(0.0))),
        Json::String(s) => Value::from(s.as_str()),
        Json::Array(a) => Value::Array(a.iter().map(to_msgpack).collect()),
        Json::Object(m) => Value::Map(
            m.iter()
                .map(|(k, v)| (Value::from(k.as_str()), to_msgpack(v)))
                .collect(),
        ),
    }
}

/// A request IU being answered.
#[derive(Debug, Clone)]
struct Request {
    channel: String,
    payload: Map<String, Json>,
    /// The payloads this realizer sent and has not heard back yet (an update comes back to
    /// every subscriber, the sender too; one heard back is not the owner's change).
    sent: VecDeque<Map<String, Json>>,
}

/// Updates of one request awaited back at most.
const ECHOES: usize = 64;

/// The request IUs being answered: by uid, and by the block they asked for (so that the
/// block's feedback finds its IU). Bounded by [`REQUESTS_KEPT`].
#[derive(Debug, Default)]
pub struct Requests {
    by_uid: HashMap<String, Request>,
    by_block: HashMap<(String, String), String>,
    order: VecDeque<String>,
}

impl Requests {
    /// Keeps request `uid` on `channel` with its `payload`.
    pub fn add(&mut self, channel: &str, uid: &str, payload: Map<String, Json>) {
        if self.order.len() >= REQUESTS_KEPT {
            if let Some(old) = self.order.pop_front() {
                self.forget(&old);
            }
        }
        let request = Request {
            channel: channel.to_string(),
            payload,
            sent: VecDeque::new(),
        };
        if self.by_uid.insert(uid.to_string(), request).is_none() {
            self.order.push_back(uid.to_string());
        }
    }

    /// Ties block `block` on `channel` to request `uid` (its feedback updates that IU).
    pub fn bind(&mut self, channel: &str, block: &str, uid: &str) {
        if self.by_uid.contains_key(uid) {
            (self.by_block).insert((channel.to_string(), block.to_string()), uid.to_string());
        }
    }

    /// The channel of request `uid`, if known.
    pub fn channel(&self, uid: &str) -> Option<&str> {
        self.by_uid.get(uid).map(|r| r.channel.as_str())
    }

    /// The request of `block` on `channel`, if one asked for it.
    pub fn of_block(&self, channel: &str, block: &str) -> Option<&str> {
        (self.by_block.get(&(channel.to_string(), block.to_string()))).map(String::as_str)
    }

    /// Someone replaced request `uid`'s payload: its owner (kept, to merge into), or this
    /// realizer's own update heard back (ignored: later ones may have been sent since).
    pub fn replaced(&mut self, uid: &str, payload: Map<String, Json>) {
        let Some(r) = self.by_uid.get_mut(uid) else {
            return;
        };
        match r.sent.iter().position(|p| *p == payload) {
            Some(i) => {
                r.sent.drain(..=i);
            }
            None => r.payload = payload,
        }
    }

    /// Forgets request `uid` (closed, or too old).
    pub fn forget(&mut self, uid: &str) {
        if let Some(r) = self.by_uid.remove(uid) {
            self.by_block
                .retain(|(c, _), u| !(u == uid && *c == r.channel));
        }
        self.order.retain(|u| u != uid);
    }

    /// Merges `items` into request `uid`'s payload: the channel and the update event to
    /// publish, or `None` for a request not (or no longer) known.
    pub fn merge(&mut self, uid: &str, items: &[(&str, String)]) -> Option<(String, Vec<u8>)> {
        let r = self.by_uid.get_mut(uid)?;
        for (k, v) in items {
            r.payload.insert(k.to_string(), Json::String(v.clone()));
        }
        if r.sent.len() >= ECHOES {
            r.sent.pop_front();
        }
        r.sent.push_back(r.payload.clone());
        Some((r.channel.clone(), payload_update(uid, &r.payload)))
    }

    /// Requests kept.
    pub fn len(&self) -> usize {
        self.by_uid.len()
    }

    /// Whether none is kept.
    pub fn is_empty(&self) -> bool {
        self.by_uid.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A Publish event as ipaacar-python 0.2.1 put it on the broker (bytes captured from
    /// `OutputBuffer.create_new_iu("realizerRequest", '{"type": "bml", "request": "<bml id=\"b1\"/>"}')`).
    const PUBLISHED: &str = "81a75075626c69736897af7265616c697a657252657175657374d92463343564653362362d623538662d346164622d393465662d393666306332316637653862a36f6231c0918082a772657175657374ae3c626d6c2069643d226231222f3ea474797065a3626d6ca5416c696365";
    /// The Update ipaacar sent for `iu.set_payload('{"x":2}')` on another IU.
    const UPDATED: &str = "81a655706461746592d92464653531623061312d363037622d346633662d613036622d62623439323765653636636481a75061796c6f616481a17802";
    /// The Update ipaacar sent for `commit_iu` on that IU.
    const COMMITTED: &str = "81a655706461746592d92464653531623061312d363037622d346633662d613036622d62623439323765653636636481a5436c6f7365a9436f6d6d6974746564";

    fn hex(s: &str) -> Vec<u8> {
        (0..s.len())
            .step_by(2)
            .map(|i| u8::from_str_radix(&s[i..i + 2], 16).unwrap())
            .collect()
    }

    #[test]
    fn ipaacar_s_own_iu_events_are_read() {
        let IuEvent::Published {
            category,
            uid,
            payload,
        } = read_event(&hex(PUBLISHED)).unwrap()
        else {
            panic!("not read as a publication")
        };
        assert_eq!(category, "realizerRequest");
        assert_eq!(uid, "c45de3b6-b58f-4adb-94ef-96f0c21f7e8b");
        assert_eq!(payload["type"], "bml");
        assert_eq!(payload["request"], r#"<bml id="b1"/>"#);
        let IuEvent::Payload { uid, payload } = read_event(&hex(UPDATED)).unwrap() else {
            panic!("not read as a payload update")
        };
        assert_eq!(uid, "de51b0a1-607b-4f3f-a06b-bb4927ee66cd");
        assert_eq!(payload["x"], 2);
        assert_eq!(
            read_event(&hex(COMMITTED)).unwrap(),
            IuEvent::Closed { uid }
        );
        assert!(read_event(b"{\"json\": 1}").is_err());
        assert!(read_event(&[0x81, 0xa7]).is_err());
    }

    #[test]
    fn a_payload_update_is_written_as_ipaacar_writes_it() {
        // the same bytes as ipaacar's own update of that IU (UPDATED above)
        let mut p = Map::new();
        p.insert("x".into(), Json::from(2));
        assert_eq!(
            payload_update("de51b0a1-607b-4f3f-a06b-bb4927ee66cd", &p),
            hex(UPDATED)
        );
    }

    #[test]
    fn requests_merge_into_the_payload_and_stay_bounded() {
        let mut r = Requests::default();
        let mut p = Map::new();
        p.insert("type".into(), "bml".into());
        r.add("Alice", "u1", p);
        r.bind("Alice", "b1", "u1");
        assert_eq!(r.of_block("Alice", "b1"), Some("u1"));
        assert_eq!(r.of_block("Bob", "b1"), None);
        let (channel, bytes) = r.merge("u1", &[("status", "IN_EXEC".into())]).unwrap();
        assert_eq!(channel, "Alice");
        let IuEvent::Payload { payload, .. } = read_event(&bytes).unwrap() else {
            panic!()
        };
        assert_eq!(
            (payload["type"].as_str(), payload["status"].as_str()),
            (Some("bml"), Some("IN_EXEC"))
        );
        // its own updates heard back late change nothing; the owner's change is kept
        let first = r.merge("u1", &[("status", "DONE".into())]).unwrap().1;
        let IuEvent::Payload { payload: old, .. } = read_event(&bytes).unwrap() else {
            panic!()
        };
        r.replaced("u1", old);
        let IuEvent::Payload { payload: done, .. } = read_event(&first).unwrap() else {
            panic!()
        };
        assert_eq!(done["status"], "DONE");
        let again = r.merge("u1", &[]).unwrap().1;
        let IuEvent::Payload { payload: now, .. } = read_event(&again).unwrap() else {
            panic!()
        };
        assert_eq!(
            now["status"], "DONE",
            "an old echo of its own update was taken as the owner's"
        );
        let mut owners = now.clone();
        owners.insert("note".into(), "from the owner".into());
        r.replaced("u1", owners);
        let IuEvent::Payload { payload: now, .. } =
            read_event(&r.merge("u1", &[]).unwrap().1).unwrap()
        else {
            panic!()
        };
        assert_eq!(now["note"], "from the owner");
        r.forget("u1");
        assert!(r.merge("u1", &[]).is_none() && r.of_block("Alice", "b1").is_none());
        for i in 0..REQUESTS_KEPT + 10 {
            r.add("c", &format!("u{i}"), Map::new());
        }
        assert_eq!(r.len(), REQUESTS_KEPT);
        assert!(r.merge("u0", &[]).is_none());
    }
}
