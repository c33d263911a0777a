//! ipaaca's messages, so that the realizer can stand in for AsapRealizer in an ipaaca setup
//! (`bmlr serve --mqtt URL --ipaaca COMPONENT`). Matched to this project's broker contract for
//! ipaaca (2026-12): BML arrives on `COMPONENT/bml/M` as JSON `{"bml": TEXT}` with an optional
//! `"character"`; feedback leaves on `COMPONENT/bmlfeedback/M` as JSON `{"bmlfeedback": XML}`,
//! one feedback element a message. `M` is a free topic level on the way in; on the way out it is
//! the character (`_` for the default one), so a listener can follow one character or all
//! (`COMPONENT/bmlfeedback/+`). AsapRealizer's categories are `bml` and `bmlfeedback`.

use serde::{Deserialize, Serialize};

use super::topics::level_ok;

/// The ipaaca topics of one component.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Ipaaca {
    component: String,
}

#[derive(Deserialize)]
struct BmlMessage {
    bml: String,
    #[serde(default)]
    character: Option<String>,
}

#[derive(Serialize)]
struct FeedbackMessage<'a> {
    bmlfeedback: &'a str,
}

impl Ipaaca {
    /// The topics of `component` (one topic level, no wildcards).
    pub fn new(component: &str) -> Result<Ipaaca, String> {
        if !level_ok(component) {
            return Err(format!(
                "'{component}' is not an ipaaca component (one topic level, no '/', '+', '#')"
            ));
        }
        Ok(Ipaaca {
            component: component.to_string(),
        })
    }

    /// What the realizer subscribes to.
    pub fn subscription(&self) -> String {
        format!("{}/bml/+", self.component)
    }

    /// Reads a message on `topic`: `None` when the topic is not one of this component's BML
    /// topics; else the character (if given) and the block's text, or why the payload is not
    /// an ipaaca BML message.
    #[allow(clippy::type_complexity)]
    pub fn read(
        &self,
        topic: &str,
        payload: &[u8],
    ) -> Option<Result<(Option<String>, String), String>> {
        let rest = topic.strip_prefix(&self.component)?.strip_prefix("/bml/")?;
        if !level_ok(rest) {
            return None;
        }
        Some(
            serde_json::from_slice::<BmlMessage>(payload)
                .map(|m| (m.character, m.bml))
                .map_err(|e| format!("not an ipaaca BML message ({{\"bml\": TEXT}}): {e}")),
        )
    }

    /// The topic and payload of one feedback element `xml` about `character` (a topic level).
    pub fn feedback(&self, character: &str, xml: &str) -> (String, Vec<u8>) {
        let payload =
            serde_json::to_vec(&FeedbackMessage { bmlfeedback: xml }).expect("a string serialises");
        (
            format!("{}/bmlfeedback/{character}", self.component),
            payload,
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ipaaca_messages_are_read_and_written_as_the_contract_gives_them() {
        let ip = Ipaaca::new("asap").unwrap();
        assert_eq!(ip.subscription(), "asap/bml/+");
        let (c, bml) = ip
            .read(
                "asap/bml/m1",
                br#"{"bml": "<bml id=\"b\"/>", "character": "alice"}"#,
            )
            .unwrap()
            .unwrap();
        assert_eq!(
            (c.as_deref(), bml.as_str()),
            (Some("alice"), r#"<bml id="b"/>"#)
        );
        let (c, _) = ip.read("asap/bml/x", br#"{"bml": ""}"#).unwrap().unwrap();
        assert_eq!(c, None);
        assert!(ip.read("asap/bml/x", b"<bml/>").unwrap().is_err());
        assert!(ip.read("asap/bmlfeedback/x", b"{}").is_none());
        assert!(ip.read("other/bml/x", b"{}").is_none());
        let (topic, payload) = ip.feedback("_", r#"<blockProgress id="b:start"/>"#);
        assert_eq!(topic, "asap/bmlfeedback/_");
        assert_eq!(
            String::from_utf8(payload).unwrap(),
            r#"{"bmlfeedback":"<blockProgress id=\"b:start\"/>"}"#
        );
        assert!(Ipaaca::new("a/b").is_err());
    }
}
