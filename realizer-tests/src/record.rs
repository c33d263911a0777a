//! The feedback recorder of RealizerTester's handler: five arrival-ordered lists (sync progress,
//! performance start, performance stop, warnings, exceptions) plus the predictions the BMLA tests
//! wait on, filled from BML 1.0 feedback XML exactly as the original `XMLRealizerTestPort` maps it.

use quick_xml::events::{BytesStart, Event};
use quick_xml::Reader;

/// `syncPointProgress` → the original's `BMLSyncPointProgressFeedback`.
#[derive(Debug, Clone, PartialEq)]
pub struct SyncProgress {
    /// Block id.
    pub bml_id: String,
    /// Behaviour id.
    pub behaviour_id: String,
    /// Sync id.
    pub sync_id: String,
    /// Block-relative time (`time`), seconds.
    pub bml_block_time: f64,
    /// Global time (`globalTime`), seconds.
    pub time_stamp: f64,
}

/// `blockProgress id="B:start"` → performance start.
#[derive(Debug, Clone, PartialEq)]
pub struct PerformanceStart {
    /// Character, if any.
    pub character_id: Option<String>,
    /// Block id.
    pub bml_id: String,
    /// Global time.
    pub time_stamp: f64,
}

/// `blockProgress id="B:end"` → performance stop.
#[derive(Debug, Clone, PartialEq)]
pub struct PerformanceStop {
    /// Character, if any.
    pub character_id: Option<String>,
    /// Block id.
    pub bml_id: String,
    /// Global time.
    pub time_stamp: f64,
}

/// `warningFeedback id="B:beh"` → warning; `modified_behaviours` always has exactly one element
/// (the part after the first `:`, or the empty string), as in the original port.
#[derive(Debug, Clone, PartialEq)]
pub struct Warning {
    /// Character, if any.
    pub character_id: Option<String>,
    /// Block id (the part before the first `:`).
    pub bml_id: String,
    /// The behaviour named by the warning's id.
    pub modified_behaviours: Vec<String>,
    /// `type: text`.
    pub text: String,
}

/// Everything received, in arrival order.
#[derive(Debug, Clone, Default)]
pub struct Recorder {
    /// Sync-point progress.
    pub syncs: Vec<SyncProgress>,
    /// Block starts.
    pub starts: Vec<PerformanceStart>,
    /// Block ends.
    pub stops: Vec<PerformanceStop>,
    /// Warnings.
    pub warnings: Vec<Warning>,
    /// Exceptions (BML 1.0 has none; kept so that NoExc means what it meant).
    pub exceptions: Vec<String>,
    /// Blocks for which a prediction with a known end arrived ("scheduling finished").
    pub scheduled: Vec<String>,
    /// Lines that were not feedback (reported in failure traces).
    pub unreadable: Vec<String>,
}

fn attr(e: &BytesStart, name: &[u8]) -> Option<String> {
    e.attributes()
        .flatten()
        .find(|a| a.key.as_ref() == name)
        .and_then(|a| a.unescape_value().ok().map(|v| v.into_owned()))
}

fn number(e: &BytesStart, name: &[u8]) -> Option<f64> {
    attr(e, name).and_then(|v| v.trim().parse().ok())
}

impl Recorder {
    /// An empty recorder.
    pub fn new() -> Self {
        Self::default()
    }

    /// Empties every list (the original's `clearFeedbackLists`, plus predictions).
    pub fn clear(&mut self) {
        *self = Self::default();
    }

    /// Takes one feedback document (one line of a realizer's output).
    pub fn feedback_xml(&mut self, xml: &str) {
        let mut reader = Reader::from_str(xml);
        let root = loop {
            match reader.read_event() {
                Ok(Event::Start(e)) => break Some((e.into_owned(), false)),
                Ok(Event::Empty(e)) => break Some((e.into_owned(), true)),
                Ok(Event::Eof) | Err(_) => break None,
                Ok(_) => {}
            }
        };
        let Some((root, empty)) = root else {
            self.unreadable.push(xml.to_string());
            return;
        };
        let character_id = attr(&root, b"characterId");
        match root.local_name().as_ref() {
            b"blockProgress" => {
                let (Some(id), Some(t)) = (attr(&root, b"id"), number(&root, b"globalTime")) else {
                    self.unreadable.push(xml.to_string());
                    return;
                };
                let Some((block, sync)) = id.rsplit_once(':') else {
                    self.unreadable.push(xml.to_string());
                    return;
                };
                match sync {
                    "start" => self.starts.push(PerformanceStart {
                        character_id,
                        bml_id: block.to_string(),
                        time_stamp: t,
                    }),
                    "end" => self.stops.push(PerformanceStop {
                        character_id,
                        bml_id: block.to_string(),
                        time_stamp: t,
                    }),
                    _ => {} // other block syncs are dropped, as in the original
                }
            }
            b"syncPointProgress" => {
                let id = attr(&root, b"id").unwrap_or_default();
                let parts: Vec<&str> = id.splitn(3, ':').collect();
                match (
                    parts.as_slice(),
                    number(&root, b"time"),
                    number(&root, b"globalTime"),
                ) {
                    ([b, beh, s], Some(rel), Some(global)) => self.syncs.push(SyncProgress {
                        bml_id: b.to_string(),
                        behaviour_id: beh.to_string(),
                        sync_id: s.to_string(),
                        bml_block_time: rel,
                        time_stamp: global,
                    }),
                    _ => self.unreadable.push(xml.to_string()),
                }
            }
            b"warningFeedback" => {
                let id = attr(&root, b"id").unwrap_or_default();
                let kind = attr(&root, b"type").unwrap_or_default();
                let (block, behaviour) = id.split_once(':').unwrap_or((id.as_str(), ""));
                let mut text = String::new();
                if !empty {
                    while let Ok(ev) = reader.read_event() {
                        match ev {
                            Event::Text(t) => {
                                let raw = String::from_utf8_lossy(t.as_ref()).into_owned();
                                match quick_xml::escape::unescape(&raw) {
                                    Ok(u) => text.push_str(&u),
                                    Err(_) => text.push_str(&raw),
                                }
                            }
                            Event::GeneralRef(r) => text.push_str(match r.as_ref() {
                                b"amp" => "&",
                                b"lt" => "<",
                                b"gt" => ">",
                                b"quot" => "\"",
                                b"apos" => "'",
                                _ => "",
                            }),
                            Event::End(_) | Event::Eof => break,
                            _ => {}
                        }
                    }
                }
                self.warnings.push(Warning {
                    character_id,
                    bml_id: block.to_string(),
                    modified_behaviours: vec![behaviour.to_string()],
                    text: format!("{kind}: {text}"),
                });
            }
            b"predictionFeedback" => {
                if empty {
                    return;
                }
                while let Ok(ev) = reader.read_event() {
                    match ev {
                        Event::Start(e) | Event::Empty(e) if e.local_name().as_ref() == b"bml" => {
                            if let (Some(id), Some(_)) = (attr(&e, b"id"), attr(&e, b"globalEnd")) {
                                self.scheduled.push(id);
                            }
                        }
                        Event::Eof => break,
                        _ => {}
                    }
                }
            }
            _ => {} // unknown roots are ignored, as in the original
        }
    }

    /// The first sync-progress entry for `block:behaviour:sync`.
    pub fn sync(&self, block: &str, behaviour: &str, sync: &str) -> Option<&SyncProgress> {
        self.syncs
            .iter()
            .find(|s| s.bml_id == block && s.behaviour_id == behaviour && s.sync_id == sync)
    }

    /// The first start of `block`.
    pub fn start(&self, block: &str) -> Option<&PerformanceStart> {
        self.starts.iter().find(|s| s.bml_id == block)
    }

    /// The first stop of `block`.
    pub fn stop(&self, block: &str) -> Option<&PerformanceStop> {
        self.stops.iter().find(|s| s.bml_id == block)
    }

    /// Everything, for failure traces (as the original prints all five lists on a timeout).
    pub fn trace(&self) -> String {
        let mut out = String::new();
        out.push_str(&format!(
            "starts: {:?}\nstops: {:?}\n",
            self.starts
                .iter()
                .map(|s| format!("{}@{:.3}", s.bml_id, s.time_stamp))
                .collect::<Vec<_>>(),
            self.stops
                .iter()
                .map(|s| format!("{}@{:.3}", s.bml_id, s.time_stamp))
                .collect::<Vec<_>>()
        ));
        out.push_str(&format!(
            "warnings: {:?}\n",
            self.warnings
                .iter()
                .map(|w| format!("{}:{} {}", w.bml_id, w.modified_behaviours[0], w.text))
                .collect::<Vec<_>>()
        ));
        out.push_str(&format!(
            "syncs: {:?}",
            self.syncs
                .iter()
                .map(|s| format!(
                    "{}:{}:{}@{:.3}",
                    s.bml_id, s.behaviour_id, s.sync_id, s.bml_block_time
                ))
                .collect::<Vec<_>>()
        ));
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const NS: &str = r#"xmlns="http://www.bml-initiative.org/bml/bml-1.0" xmlns:bmla="http://www.asap-project.org/bmla""#;

    #[test]
    fn feedback_maps_as_in_the_original_xml_port() {
        let mut r = Recorder::new();
        r.feedback_xml(&format!(r#"<blockProgress {NS} id="bml1:start" globalTime="1.5" characterId="anna" bmla:status="IN_EXEC"/>"#));
        r.feedback_xml(&format!(
            r#"<blockProgress {NS} id="bml1:relax" globalTime="2"/>"#
        ));
        r.feedback_xml(&format!(
            r#"<syncPointProgress {NS} id="bml1:g1:stroke" time="0.5" globalTime="2.0"/>"#
        ));
        r.feedback_xml(&format!(r#"<warningFeedback {NS} id="bml1:gaze2" type="IMPOSSIBLE_TO_SCHEDULE">dropped &amp; gone</warningFeedback>"#));
        r.feedback_xml(&format!(r#"<warningFeedback {NS} id="&lt;no id&gt;" type="PARSING_FAILURE">bad</warningFeedback>"#));
        r.feedback_xml(&format!(r#"<predictionFeedback {NS}><bml id="bml1" globalStart="0" bmla:status="IN_PREP"/></predictionFeedback>"#));
        r.feedback_xml(&format!(r#"<predictionFeedback {NS}><bml id="bml1" globalStart="0" globalEnd="3" bmla:status="PENDING"/></predictionFeedback>"#));
        r.feedback_xml(&format!(
            r#"<blockProgress {NS} id="bml1:end" globalTime="3"/>"#
        ));
        r.feedback_xml("not xml");
        assert_eq!(r.starts[0].bml_id, "bml1");
        assert_eq!(r.starts[0].character_id.as_deref(), Some("anna"));
        assert_eq!(r.stops.len(), 1, "other block syncs are dropped");
        assert_eq!(r.sync("bml1", "g1", "stroke").unwrap().bml_block_time, 0.5);
        assert_eq!(r.warnings[0].modified_behaviours, ["gaze2"]);
        assert_eq!(r.warnings[0].text, "IMPOSSIBLE_TO_SCHEDULE: dropped & gone");
        assert_eq!(r.warnings[1].bml_id, "<no id>");
        assert_eq!(r.warnings[1].modified_behaviours, [""]);
        assert_eq!(
            r.scheduled,
            ["bml1"],
            "only a prediction with a known end counts"
        );
        assert_eq!(r.unreadable, ["not xml"]);
    }
}
