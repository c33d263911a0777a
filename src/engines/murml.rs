//! MURML behaviours (`murmlgesture`, `murmlface` in the namespace
//! `http://www.techfak.uni-bielefeld.de/ags/soa/murml`), timing only: the `<murml-description>` is
//! read for its timing — a `<keyframing>` lasts until its last `<frame ftime>`, a `<dynamic>`
//! movement or a `<static>` posture gets the default second — and the behaviour is played with
//! gesture syncs (`murmlgesture`) or face syncs (`murmlface`, as the conformance suite expects).
//! No joints or face targets move until the animation engine (issue #7) interprets the frames.

use quick_xml::events::Event;
use quick_xml::Reader;

use crate::bml::{Behaviour, BehaviourKind};
use crate::engine::timing::TimingModel;
use crate::engine::{Engine, EngineError, Unit, Units};

/// The MURML namespace.
pub const NS_MURML: &str = "http://www.techfak.uni-bielefeld.de/ags/soa/murml";

/// Duration of a MURML description without keyframes.
pub const DEFAULT_DURATION: f64 = 1.0;

/// How long a MURML description lasts: its last keyframe time, or [`DEFAULT_DURATION`]. `Err` if
/// the content is not well-formed XML.
pub fn duration(content: &str) -> Result<f64, String> {
    let mut reader = Reader::from_str(content);
    let mut last: Option<f64> = None;
    loop {
        match reader.read_event() {
            Ok(Event::Start(e)) | Ok(Event::Empty(e)) if e.local_name().as_ref() == b"frame" => {
                let t = e
                    .attributes()
                    .flatten()
                    .find(|a| a.key.local_name().as_ref() == b"ftime")
                    .and_then(|a| a.unescape_value().ok()?.trim().parse::<f64>().ok());
                match t {
                    Some(t) if t.is_finite() && t >= 0.0 => {
                        last = Some(last.map_or(t, |l: f64| l.max(t)))
                    }
                    _ => return Err("a MURML <frame> needs a time ftime >= 0".into()),
                }
            }
            Ok(Event::Eof) => break,
            Err(e) => return Err(format!("the MURML description is not well-formed: {e}")),
            Ok(_) => {}
        }
    }
    Ok(last.filter(|&d| d > 0.0).unwrap_or(DEFAULT_DURATION))
}

/// The two MURML kinds.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Kind {
    Gesture,
    Face,
}

fn kind(b: &Behaviour) -> Option<(Kind, &str)> {
    match &b.kind {
        BehaviourKind::Unknown(u) if u.ns == NS_MURML && u.name == "murmlgesture" => {
            Some((Kind::Gesture, &u.content))
        }
        BehaviourKind::Unknown(u) if u.ns == NS_MURML && u.name == "murmlface" => {
            Some((Kind::Face, &u.content))
        }
        _ => None,
    }
}

/// The MURML engine (see the module documentation).
#[derive(Debug, Default)]
pub struct MurmlEngine {
    units: Units<()>,
}

impl Engine for MurmlEngine {
    crate::units_remove!();
    crate::units_retime_len!();
    crate::units_play!("murml");
    crate::units_interrupt!(crate::engine::relax_now);

    fn name(&self) -> &'static str {
        "murml"
    }

    fn timing(&self, behaviour: &Behaviour) -> Option<TimingModel> {
        let (k, content) = kind(behaviour)?;
        // a malformed description is refused when the unit is added, with the reason
        let d = duration(content).unwrap_or(DEFAULT_DURATION);
        Some(match k {
            Kind::Gesture => TimingModel::gesture(d),
            Kind::Face => TimingModel::face(d),
        })
    }

    fn resources(&self, behaviour: &Behaviour) -> &'static [&'static str] {
        match kind(behaviour) {
            Some((Kind::Gesture, _)) => &["left_hand", "right_hand"],
            Some((Kind::Face, _)) => &["face"],
            None => &[],
        }
    }

    fn add(&mut self, unit: Unit<'_>) -> Result<(), EngineError> {
        let (_, content) = kind(unit.behaviour).ok_or_else(|| {
            EngineError("the MURML engine realizes murmlgesture and murmlface".into())
        })?;
        duration(content).map_err(EngineError)?;
        self.units.add(unit, ());
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_keyframed_description_lasts_until_its_last_frame() {
        let d = duration(
            r#"<murml-description><dynamic><keyframing><phase>
                 <frame ftime="0"><posture>Humanoid (l_shoulder 3 0 0 0)</posture></frame>
                 <frame ftime="2.5"/><frame ftime="1"/>
               </phase></keyframing></dynamic></murml-description>"#,
        );
        assert_eq!(d, Ok(2.5));
        assert_eq!(
            duration(r#"<murml-description><dynamic slot="PalmOrientation"/></murml-description>"#),
            Ok(DEFAULT_DURATION)
        );
        assert!(duration(r#"<frame ftime="soon"/>"#).is_err());
        // the keyframes' length is the gesture's, its syncs at the usual places
        let m = TimingModel::gesture(2.5);
        assert_eq!(m.preferred_duration(), 2.5);
        assert!((m.keys[m.key("stroke").unwrap()].at - 1.25).abs() < 1e-12);
        let f = TimingModel::face(3.0);
        assert!((f.keys[f.key("attackPeak").unwrap()].at - 0.6).abs() < 1e-12);
        assert!(duration(r#"<murml-description><frame></murml-description>"#).is_err());
    }
}
