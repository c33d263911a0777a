//! Feedback about the world rather than about blocks: what a character's synthetic vision
//! reports (`perception`), transitions of PaT-Nets (`net`) and changes of world variables
//! (`var`). They are not BML 1.0 elements: in XML they live in namespaces of their own
//! (`urn:bmlr:perception`, `urn:bmlr:nets`); in JSON lines their `feedback` key is `perception`,
//! `net` or `var`. They are sent only when perception or nets are turned on.

use std::fmt::Write as _;

use quick_xml::escape::escape;
use serde::{Deserialize, Serialize};

use super::{round_ms, FeedbackError};

/// The XML namespace of perception feedback.
pub const NS_PERCEPTION: &str = "urn:bmlr:perception";
/// The XML namespace of net and variable feedback.
pub const NS_NETS: &str = "urn:bmlr:nets";

/// One message about the world.
#[derive(Debug, Clone, PartialEq)]
pub enum WorldFeedback {
    /// What a character sees changed.
    Perception(PerceptionFeedback),
    /// A net moved from one state to another.
    Net(NetFeedback),
    /// A world variable changed.
    Var(VarFeedback),
}

/// What a character sees now, and what changed since its previous look.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase", deny_unknown_fields)]
pub struct PerceptionFeedback {
    /// The character that looked.
    pub character_id: String,
    /// When (global seconds).
    #[serde(serialize_with = "ms")]
    pub time: f64,
    /// Everything it sees now (sorted).
    pub seen: Vec<String>,
    /// What it did not see at its previous look (sorted).
    pub appeared: Vec<String>,
    /// What it saw at its previous look and sees no more (sorted).
    pub disappeared: Vec<String>,
}

/// A PaT-Net's transition.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "camelCase", deny_unknown_fields)]
pub struct NetFeedback {
    /// The net's name.
    pub net: String,
    /// Its character (`None`: a world-level net).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub character_id: Option<String>,
    /// The state it left.
    pub from: String,
    /// The state it entered.
    pub to: String,
    /// When (global seconds).
    #[serde(serialize_with = "ms")]
    pub time: f64,
}

/// A world variable's new value.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VarFeedback {
    /// The variable.
    pub name: String,
    /// Its value now.
    pub value: VarValue,
    /// When (global seconds).
    #[serde(serialize_with = "ms")]
    pub time: f64,
}

/// The value of a world variable: a number, a word or a truth value.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum VarValue {
    /// A truth value.
    Bool(bool),
    /// A number.
    Number(f64),
    /// A word.
    Text(String),
}

impl VarValue {
    /// How XML writes it (XML does not keep the kind: `from_xml_text` reads `true`/`false` as
    /// truth values and numbers as numbers).
    pub fn to_xml_text(&self) -> String {
        match self {
            VarValue::Bool(b) => b.to_string(),
            VarValue::Number(n) => n.to_string(),
            VarValue::Text(t) => t.clone(),
        }
    }

    /// The value XML text stands for.
    pub fn from_xml_text(text: &str) -> VarValue {
        match text {
            "true" => VarValue::Bool(true),
            "false" => VarValue::Bool(false),
            t => match t.parse::<f64>() {
                Ok(n) if n.is_finite() => VarValue::Number(n),
                _ => VarValue::Text(t.to_string()),
            },
        }
    }
}

impl std::fmt::Display for VarValue {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.to_xml_text())
    }
}

fn ms<S: serde::Serializer>(t: &f64, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_f64(round_ms(*t))
}

/// JSON's form: the fields with the `feedback` key first.
#[derive(Serialize)]
struct Tagged<'a, T: Serialize> {
    feedback: &'static str,
    #[serde(flatten)]
    body: &'a T,
}

impl WorldFeedback {
    /// The `feedback` key in JSON (`perception`, `net`, `var`).
    pub fn kind(&self) -> &'static str {
        match self {
            WorldFeedback::Perception(_) => "perception",
            WorldFeedback::Net(_) => "net",
            WorldFeedback::Var(_) => "var",
        }
    }

    /// The element name in XML.
    pub fn element_name(&self) -> &'static str {
        match self {
            WorldFeedback::Perception(_) => "perceptionFeedback",
            WorldFeedback::Net(_) => "netFeedback",
            WorldFeedback::Var(_) => "varFeedback",
        }
    }

    /// The character it is about, if any.
    pub fn character_id(&self) -> Option<&str> {
        match self {
            WorldFeedback::Perception(p) => Some(&p.character_id),
            WorldFeedback::Net(n) => n.character_id.as_deref(),
            WorldFeedback::Var(_) => None,
        }
    }

    /// One JSON line.
    pub fn to_json(&self) -> String {
        let feedback = self.kind();
        let text = match self {
            WorldFeedback::Perception(p) => serde_json::to_string(&Tagged { feedback, body: p }),
            WorldFeedback::Net(n) => serde_json::to_string(&Tagged { feedback, body: n }),
            WorldFeedback::Var(v) => serde_json::to_string(&Tagged { feedback, body: v }),
        };
        text.expect("world feedback always encodes")
    }

    /// Reads a JSON object whose `feedback` key is `kind`; `None` when `kind` is not one of
    /// these.
    pub fn from_json(
        kind: &str,
        mut value: serde_json::Value,
    ) -> Option<Result<WorldFeedback, FeedbackError>> {
        if let Some(o) = value.as_object_mut() {
            o.remove("feedback");
        }
        let bad = |e: serde_json::Error| FeedbackError(format!("{kind} feedback: {e}"));
        Some(match kind {
            "perception" => serde_json::from_value(value)
                .map(WorldFeedback::Perception)
                .map_err(bad),
            "net" => serde_json::from_value(value)
                .map(WorldFeedback::Net)
                .map_err(bad),
            "var" => serde_json::from_value(value)
                .map(WorldFeedback::Var)
                .map_err(bad),
            _ => return None,
        })
    }

    /// One XML element on one line.
    pub fn to_xml(&self) -> String {
        let mut o = String::with_capacity(160);
        let ns = match self {
            WorldFeedback::Perception(_) => NS_PERCEPTION,
            _ => NS_NETS,
        };
        let _ = write!(o, "<{} xmlns=\"{ns}\"", self.element_name());
        let mut attr = |name: &str, value: &str| {
            let _ = write!(o, " {name}=\"{}\"", escape(value));
        };
        let t = |v: f64| format!("{:.3}", round_ms(v));
        match self {
            WorldFeedback::Perception(p) => {
                attr("characterId", &p.character_id);
                attr("time", &t(p.time));
                attr("seen", &p.seen.join(" "));
                attr("appeared", &p.appeared.join(" "));
                attr("disappeared", &p.disappeared.join(" "));
            }
            WorldFeedback::Net(n) => {
                attr("net", &n.net);
                if let Some(c) = &n.character_id {
                    attr("characterId", c);
                }
                attr("from", &n.from);
                attr("to", &n.to);
                attr("time", &t(n.time));
            }
            WorldFeedback::Var(v) => {
                attr("name", &v.name);
                attr("value", &v.value.to_xml_text());
                attr("time", &t(v.time));
            }
        }
        o.push_str("/>");
        o
    }

    /// Reads the element `name` of namespace `ns` from its attributes (local name, value);
    /// `None` when the namespace is not one of these.
    pub fn from_xml(
        ns: &[u8],
        name: &str,
        attrs: &[(String, String)],
    ) -> Option<Result<WorldFeedback, FeedbackError>> {
        if ns != NS_PERCEPTION.as_bytes() && ns != NS_NETS.as_bytes() {
            return None;
        }
        let get = |k: &str| attrs.iter().find(|(n, _)| n == k).map(|(_, v)| v.as_str());
        let req =
            |k: &str| get(k).ok_or_else(|| FeedbackError(format!("<{name}> has no {k} attribute")));
        let time = || -> Result<f64, FeedbackError> {
            let v = req("time")?;
            (v.trim().parse::<f64>().ok())
                .filter(|t| t.is_finite())
                .ok_or_else(|| FeedbackError(format!("time='{v}' is not a number")))
        };
        let list = |k: &str| -> Result<Vec<String>, FeedbackError> {
            Ok(req(k)?.split_whitespace().map(str::to_string).collect())
        };
        let read = || -> Result<WorldFeedback, FeedbackError> {
            Ok(match name {
                "perceptionFeedback" => WorldFeedback::Perception(PerceptionFeedback {
                    character_id: req("characterId")?.to_string(),
                    time: time()?,
                    seen: list("seen")?,
                    appeared: list("appeared")?,
                    disappeared: list("disappeared")?,
                }),
                "netFeedback" => WorldFeedback::Net(NetFeedback {
                    net: req("net")?.to_string(),
                    character_id: get("characterId").map(str::to_string),
                    from: req("from")?.to_string(),
                    to: req("to")?.to_string(),
                    time: time()?,
                }),
                "varFeedback" => WorldFeedback::Var(VarFeedback {
                    name: req("name")?.to_string(),
                    value: VarValue::from_xml_text(req("value")?),
                    time: time()?,
                }),
                other => return Err(FeedbackError(format!("unknown world feedback <{other}>"))),
            })
        };
        Some(read())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::language::feedback::{from_line, Feedback, Format};

    fn all() -> Vec<Feedback> {
        vec![
            Feedback::World(WorldFeedback::Perception(PerceptionFeedback {
                character_id: "a".into(),
                time: 1.25,
                seen: vec!["b".into(), "door".into()],
                appeared: vec!["b".into()],
                disappeared: vec![],
            })),
            Feedback::World(WorldFeedback::Net(NetFeedback {
                net: "north".into(),
                character_id: Some("a".into()),
                from: "curb".into(),
                to: "crossing".into(),
                time: 3.0,
            })),
            Feedback::World(WorldFeedback::Var(VarFeedback {
                name: "light".into(),
                value: VarValue::Text("WALK".into()),
                time: 2.5,
            })),
        ]
    }

    #[test]
    fn both_formats_write_the_contract_s_lines_and_read_them_back() {
        let [p, n, v] = <[Feedback; 3]>::try_from(all()).unwrap();
        assert_eq!(
            Format::Jsonl.encode(&p),
            r#"{"feedback":"perception","characterId":"a","time":1.25,"seen":["b","door"],"appeared":["b"],"disappeared":[]}"#
        );
        assert_eq!(
            Format::Xml.encode(&p),
            r#"<perceptionFeedback xmlns="urn:bmlr:perception" characterId="a" time="1.250" seen="b door" appeared="b" disappeared=""/>"#
        );
        assert_eq!(
            Format::Jsonl.encode(&n),
            r#"{"feedback":"net","net":"north","characterId":"a","from":"curb","to":"crossing","time":3.0}"#
        );
        assert_eq!(
            Format::Xml.encode(&n),
            r#"<netFeedback xmlns="urn:bmlr:nets" net="north" characterId="a" from="curb" to="crossing" time="3.000"/>"#
        );
        assert_eq!(
            Format::Jsonl.encode(&v),
            r#"{"feedback":"var","name":"light","value":"WALK","time":2.5}"#
        );
        for fb in all() {
            for f in [Format::Xml, Format::Jsonl] {
                assert_eq!(from_line(&f.encode(&fb)).unwrap(), fb, "{f:?}");
            }
        }
    }

    #[test]
    fn a_world_element_missing_a_field_is_refused_with_its_name() {
        let e = from_line(r#"<netFeedback xmlns="urn:bmlr:nets" net="n" from="a" time="1"/>"#)
            .unwrap_err();
        assert!(e.0.contains("to"), "{e}");
        let e = from_line(r#"{"feedback":"var","name":"x","time":1}"#).unwrap_err();
        assert!(e.0.contains("value"), "{e}");
    }
}
