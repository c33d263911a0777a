//! The XML line codec of feedback: one BML 1.0 feedback element per line, times with millisecond
//! precision, BMLA attributes prefixed `bmla:`.

use std::fmt::Write as _;

use quick_xml::escape::escape;
use quick_xml::events::{BytesStart, Event};
use quick_xml::name::ResolveResult;
use quick_xml::NsReader;

use super::*;

fn t(v: f64) -> String {
    format!("{:.3}", round_ms(v))
}

fn open(out: &mut String, name: &str, bmla: bool) {
    let _ = write!(out, "<{name} xmlns=\"{NS_FEEDBACK}\"");
    if bmla {
        let _ = write!(out, " xmlns:bmla=\"{NS_BMLA}\"");
    }
}

fn attr(out: &mut String, name: &str, value: &str) {
    let _ = write!(out, " {name}=\"{}\"", escape(value));
}

/// Encodes one message as a single line of XML (no trailing newline). One arm per feedback
/// element, written attribute by attribute in the order of docs/cli.md.
pub fn to_xml(fb: &Feedback) -> String {
    let mut o = String::with_capacity(160);
    match fb {
        Feedback::BlockProgress(b) => {
            open(
                &mut o,
                "blockProgress",
                b.status.is_some() || b.posix_time.is_some(),
            );
            attr(&mut o, "id", &format!("{}:{}", b.block, b.sync));
            attr(&mut o, "globalTime", &t(b.global_time));
            if let Some(c) = &b.character_id {
                attr(&mut o, "characterId", c);
            }
            if let Some(s) = b.status {
                attr(&mut o, "bmla:status", s.as_str());
            }
            if let Some(p) = b.posix_time {
                attr(&mut o, "bmla:posixTime", &p.to_string());
            }
            o.push_str("/>");
        }
        Feedback::SyncPointProgress(s) => {
            open(
                &mut o,
                "syncPointProgress",
                s.posix_time.is_some() || s.skipped,
            );
            attr(
                &mut o,
                "id",
                &format!("{}:{}:{}", s.block, s.behaviour, s.sync),
            );
            attr(&mut o, "time", &t(s.time));
            attr(&mut o, "globalTime", &t(s.global_time));
            if let Some(c) = &s.character_id {
                attr(&mut o, "characterId", c);
            }
            if let Some(p) = s.posix_time {
                attr(&mut o, "bmla:posixTime", &p.to_string());
            }
            if s.skipped {
                attr(&mut o, "bmla:skipped", "true");
            }
            o.push_str("/>");
        }
        Feedback::Prediction(p) => prediction_to_xml(&mut o, p),
        Feedback::World(w) => return w.to_xml(),
        Feedback::Warning(w) => {
            open(&mut o, "warningFeedback", false);
            attr(&mut o, "id", &w.id);
            attr(&mut o, "type", w.kind.as_str());
            if let Some(c) = &w.character_id {
                attr(&mut o, "characterId", c);
            }
            o.push('>');
            // keep the message on one line: newlines become character references
            o.push_str(
                &escape(&w.text)
                    .replace('\n', "&#10;")
                    .replace('\r', "&#13;"),
            );
            o.push_str("</warningFeedback>");
        }
    }
    o
}

/// A `predictionFeedback`: its blocks' and behaviours' predicted times as child elements.
fn prediction_to_xml(o: &mut String, p: &PredictionFeedback) {
    open(
        o,
        "predictionFeedback",
        p.blocks.iter().any(|b| b.status.is_some()),
    );
    if let Some(c) = &p.character_id {
        attr(o, "characterId", c);
    }
    if p.blocks.is_empty() && p.behaviours.is_empty() {
        o.push_str("/>");
        return;
    }
    o.push('>');
    for b in &p.blocks {
        o.push_str("<bml");
        attr(o, "id", &b.id);
        if let Some(v) = b.global_start {
            attr(o, "globalStart", &t(v));
        }
        if let Some(v) = b.global_end {
            attr(o, "globalEnd", &t(v));
        }
        if let Some(s) = b.status {
            attr(o, "bmla:status", s.as_str());
        }
        o.push_str("/>");
    }
    for b in &p.behaviours {
        let _ = write!(o, "<{}", b.kind);
        attr(o, "id", &format!("{}:{}", b.block, b.behaviour));
        for (name, v) in &b.attributes {
            attr(o, name, v);
        }
        // (a repeated head's later strokes, `stroke:1` …, are no XML attribute names:
        // their times come in syncPointProgress and in the JSON form)
        for (sync, v) in b.syncs.iter().filter(|(s, _)| !s.contains(':')) {
            attr(o, sync, &t(*v));
        }
        o.push_str("/>");
    }
    o.push_str("</predictionFeedback>");
}

/// Attributes of one element: (is BMLA, local name, value).
type Attrs = Vec<(bool, String, String)>;

fn attrs(r: &NsReader<&[u8]>, e: &BytesStart) -> Result<Attrs, FeedbackError> {
    let mut out = Vec::new();
    for a in e.attributes() {
        let a = a.map_err(|e| FeedbackError(format!("malformed attribute: {e}")))?;
        if a.key.as_ref() == b"xmlns" || a.key.as_ref().starts_with(b"xmlns:") {
            continue;
        }
        let bmla = matches!(r.resolve_attribute(a.key).0, ResolveResult::Bound(n) if n.as_ref() == NS_BMLA.as_bytes());
        let name = String::from_utf8_lossy(a.key.local_name().as_ref()).into_owned();
        let value = a
            .unescape_value()
            .map_err(|e| FeedbackError(format!("attribute {name}: {e}")))?
            .into_owned();
        out.push((bmla, name, value));
    }
    Ok(out)
}

fn get<'a>(a: &'a Attrs, bmla: bool, name: &str) -> Option<&'a str> {
    a.iter()
        .find(|(b, n, _)| *b == bmla && n == name)
        .map(|(_, _, v)| v.as_str())
}

fn req<'a>(a: &'a Attrs, name: &str, el: &str) -> Result<&'a str, FeedbackError> {
    get(a, false, name).ok_or_else(|| FeedbackError(format!("<{el}> has no {name} attribute")))
}

fn num(v: &str, name: &str) -> Result<f64, FeedbackError> {
    v.trim()
        .parse::<f64>()
        .ok()
        .filter(|v| v.is_finite())
        .ok_or_else(|| FeedbackError(format!("{name}='{v}' is not a number")))
}

fn opt_num(a: &Attrs, bmla: bool, name: &str) -> Result<Option<f64>, FeedbackError> {
    get(a, bmla, name).map(|v| num(v, name)).transpose()
}

fn posix(a: &Attrs, name: &str) -> Result<Option<u64>, FeedbackError> {
    get(a, true, name)
        .map(|v| {
            v.trim().parse::<u64>().map_err(|_| {
                FeedbackError(format!("bmla:{name}='{v}' is not a whole number of ms"))
            })
        })
        .transpose()
}

fn status(a: &Attrs) -> Result<Option<BlockStatus>, FeedbackError> {
    get(a, true, "status")
        .map(|v| {
            BlockStatus::parse(v).ok_or_else(|| FeedbackError(format!("unknown bmla:status '{v}'")))
        })
        .transpose()
}

fn is_feedback_ns(res: &ResolveResult) -> bool {
    match res {
        ResolveResult::Bound(n) => n.as_ref() == NS_FEEDBACK.as_bytes(),
        ResolveResult::Unbound => true,
        ResolveResult::Unknown(_) => false,
    }
}

/// Decodes one XML feedback element (one log line). One arm per feedback element, the mirror of
/// [`to_xml`]: long, but a flat table.
pub fn from_xml(line: &str) -> Result<Feedback, FeedbackError> {
    let mut r = NsReader::from_str(line);
    let xml_err = |e: quick_xml::Error| FeedbackError(format!("not well-formed XML: {e}"));
    loop {
        let (res, ev) = r.read_resolved_event().map_err(xml_err)?;
        let (e, empty) = match ev {
            Event::Start(e) => (e, false),
            Event::Empty(e) => (e, true),
            Event::Eof => return Err(FeedbackError("no feedback element".into())),
            Event::Text(t) if t.iter().all(u8::is_ascii_whitespace) => continue,
            Event::Decl(_) | Event::Comment(_) | Event::PI(_) | Event::DocType(_) => continue,
            _ => return Err(FeedbackError("expected a feedback element".into())),
        };
        let ns = match &res {
            ResolveResult::Bound(ns) => Some(ns.as_ref().to_vec()),
            _ => None,
        };
        if !is_feedback_ns(&res) {
            let local = String::from_utf8_lossy(e.local_name().as_ref()).into_owned();
            let plain: Vec<(String, String)> = (attrs(&r, &e)?.into_iter())
                .map(|(_, n, v)| (n, v))
                .collect();
            return match WorldFeedback::from_xml(ns.as_deref().unwrap_or(b""), &local, &plain) {
                Some(w) => w.map(Feedback::World),
                None => Err(FeedbackError(
                    "feedback element is not in the BML 1.0 namespace".into(),
                )),
            };
        }
        let name = String::from_utf8_lossy(e.local_name().as_ref()).into_owned();
        let a = attrs(&r, &e)?;
        let character_id = get(&a, false, "characterId").map(str::to_string);
        return match name.as_str() {
            "blockProgress" => {
                let id = req(&a, "id", &name)?;
                let (block, sync) = block_and_sync(id)?;
                Ok(Feedback::BlockProgress(BlockProgress {
                    block: block.into(),
                    sync: sync.into(),
                    global_time: num(req(&a, "globalTime", &name)?, "globalTime")?,
                    character_id,
                    status: status(&a)?,
                    posix_time: posix(&a, "posixTime")?,
                }))
            }
            "syncPointProgress" => {
                let [block, behaviour, sync] = sync_point_id(req(&a, "id", &name)?)?;
                Ok(Feedback::SyncPointProgress(SyncPointProgress {
                    block: block.into(),
                    behaviour: behaviour.into(),
                    sync: sync.into(),
                    time: num(req(&a, "time", &name)?, "time")?,
                    global_time: num(req(&a, "globalTime", &name)?, "globalTime")?,
                    character_id,
                    posix_time: posix(&a, "posixTime")?,
                    skipped: get(&a, true, "skipped").is_some_and(|v| v.trim() == "true"),
                }))
            }
            "warningFeedback" => {
                let id = req(&a, "id", &name)?.to_string();
                let kind = WarningType::parse(req(&a, "type", &name)?);
                let text = if empty {
                    String::new()
                } else {
                    element_text(&mut r)?
                };
                Ok(Feedback::Warning(WarningFeedback {
                    id,
                    kind,
                    character_id,
                    text,
                }))
            }
            "predictionFeedback" => {
                let mut p = PredictionFeedback {
                    character_id,
                    ..Default::default()
                };
                if !empty {
                    prediction_children(&mut r, &mut p, None)?;
                }
                Ok(Feedback::Prediction(p))
            }
            other => Err(FeedbackError(format!("unknown feedback element <{other}>"))),
        };
    }
}

/// The text content of the element whose start tag was just read, up to its end tag.
fn element_text(r: &mut NsReader<&[u8]>) -> Result<String, FeedbackError> {
    let xml_err = |e: quick_xml::Error| FeedbackError(format!("not well-formed XML: {e}"));
    let mut text = String::new();
    loop {
        match r.read_event().map_err(xml_err)? {
            Event::Text(t) => {
                text.push_str(&t.xml_content().map_err(|e| FeedbackError(e.to_string()))?)
            }
            Event::CData(c) => {
                text.push_str(&c.decode().map_err(|e| FeedbackError(e.to_string()))?)
            }
            Event::GeneralRef(g) => match g.resolve_char_ref().map_err(xml_err)? {
                Some(c) => text.push(c),
                None => {
                    let name = g.decode().map_err(|e| FeedbackError(e.to_string()))?;
                    let v = quick_xml::escape::resolve_predefined_entity(&name)
                        .ok_or_else(|| FeedbackError(format!("unknown entity &{name};")))?;
                    text.push_str(v);
                }
            },
            Event::End(_) => return Ok(text),
            Event::Eof => return Err(FeedbackError("warningFeedback is not closed".into())),
            _ => return Err(FeedbackError("warningFeedback may hold text only".into())),
        }
    }
}

/// The children of a `<predictionFeedback>` (or, with `block`, of its `<bml id=block>`).
fn prediction_children(
    r: &mut NsReader<&[u8]>,
    p: &mut PredictionFeedback,
    block: Option<&str>,
) -> Result<(), FeedbackError> {
    let xml_err = |e: quick_xml::Error| FeedbackError(format!("not well-formed XML: {e}"));
    loop {
        let (_, ev) = r.read_resolved_event().map_err(xml_err)?;
        let (e, empty) = match ev {
            Event::Start(e) => (e, false),
            Event::Empty(e) => (e, true),
            Event::End(_) => return Ok(()),
            Event::Eof => return Err(FeedbackError("predictionFeedback is not closed".into())),
            _ => continue,
        };
        let name = String::from_utf8_lossy(e.local_name().as_ref()).into_owned();
        check_name(&name)?;
        let a = attrs(r, &e)?;
        if name == "bml" && block.is_none() {
            let id = req(&a, "id", "bml")?;
            p.blocks.push(BlockPrediction {
                id: id.into(),
                global_start: opt_num(&a, false, "globalStart")?,
                global_end: opt_num(&a, false, "globalEnd")?,
                status: status(&a)?,
            });
            // (BML 1.0 as the peers write it: the block's behaviours inside its <bml>)
            if !empty {
                prediction_children(r, p, Some(id))?;
            }
            continue;
        }
        if !empty {
            r.read_to_end(e.name()).map_err(xml_err)?;
        }
        p.behaviours.push(behaviour_prediction(
            &name,
            &a,
            block.or(p.blocks.last().map(|b| b.id.as_str())),
        )?);
    }
}

/// Numeric attributes of BML behaviours that are not times (the standard sync points, the
/// gesture's, are always times).
const NOT_TIMES: [&str; 6] = [
    "amount",
    "repetition",
    "offsetAngle",
    "speed",
    "power",
    "weight",
];

/// A behaviour inside a prediction: its id `B:beh` (or `beh` inside or after the `<bml>` of
/// block `block`), its sync points (the standard ones, and any other attribute whose value is a
/// time) and its other attributes, kept as they are.
fn behaviour_prediction(
    name: &str,
    a: &Attrs,
    block: Option<&str>,
) -> Result<BehaviourPrediction, FeedbackError> {
    let id = req(a, "id", name)?;
    let (block, behaviour) = match (id.split_once(':'), block) {
        (None, Some(b)) if !id.is_empty() => (b.to_string(), id.to_string()),
        _ => {
            let parts = split_id(id, 2, "behaviour prediction")?;
            let [b, beh] = <[String; 2]>::try_from(parts).expect("two parts");
            (b, beh)
        }
    };
    let (mut syncs, mut attributes) = (Vec::new(), Vec::new());
    for (bmla, n, v) in a {
        if *bmla || n == "id" {
            continue;
        }
        check_name(n)?;
        let time = v.trim().parse::<f64>().ok().filter(|t| t.is_finite());
        let standard = crate::language::bml::GESTURE_SYNCS.contains(&n.as_str());
        match time {
            Some(t) if standard || !NOT_TIMES.contains(&n.as_str()) => {
                syncs.push((n.as_str().into(), t))
            }
            None if standard => return Err(FeedbackError(format!("{n}='{v}' is not a number"))),
            _ => attributes.push((n.clone(), v.clone())),
        }
    }
    Ok(BehaviourPrediction {
        kind: name.into(),
        block: block.into(),
        behaviour: behaviour.into(),
        syncs,
        attributes,
    })
}
