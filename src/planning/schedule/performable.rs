//! What a person can perform: the shortest each movement phase of a behaviour may last. The
//! scheduler meets the constraints it is given, and a tight set can leave a gesture's stroke a
//! millisecond long. Such a schedule is kept (the constraints asked for it, and the timing of the
//! rest of the block depends on it), but every phase squeezed below its floor is named in a
//! warning, so a gesture of zero length never passes in silence. The floors are per kind of
//! behaviour and lie at the scale of the fastest deliberate movements people make: a tenth of a
//! second for an arm's reach, stroke or return, and for a head's stroke; half that for a head's or
//! face's onset and release; 30 ms for a gaze shift (a small saccade of the eyes, the fastest
//! movement people make, already takes about 25 ms); 0.3 s to change the posture of the body.
//! Holds (`ready` to `strokeStart`, `strokeEnd` to `relax`) may be empty: people skip them.

use super::strategy::{BlockSchedule, ScheduledBehaviour};
use crate::language::bml::{BehaviourKind, Block};

/// The shortest a span between two sync points of a behaviour may last.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Floor {
    /// What the span is, in words ("stroke").
    pub what: &'static str,
    /// The sync point the span starts at.
    pub from: &'static str,
    /// The sync point the span ends at.
    pub to: &'static str,
    /// Its shortest duration, seconds.
    pub seconds: f64,
}

const fn floor(what: &'static str, from: &'static str, to: &'static str, seconds: f64) -> Floor {
    Floor {
        what,
        from,
        to,
        seconds,
    }
}

/// An arm's gesture or pointing: preparation, stroke and retraction.
const ARM: &[Floor] = &[
    floor("preparation", "start", "ready", 0.1),
    floor("stroke", "strokeStart", "strokeEnd", 0.1),
    floor("retraction", "relax", "end", 0.1),
];
/// A head movement (a nod, a shake, repeated or not).
const HEAD: &[Floor] = &[
    floor("preparation", "start", "ready", 0.05),
    floor("stroke", "strokeStart", "strokeEnd", 0.1),
    floor("retraction", "relax", "end", 0.05),
];
/// A gaze held for a while: the shift there and the shift back.
const GAZE: &[Floor] = &[
    floor("gaze shift", "start", "ready", 0.03),
    floor("return", "relax", "end", 0.03),
];
/// A facial expression: its onset and its release.
const FACE: &[Floor] = &[
    floor("onset", "start", "attackPeak", 0.05),
    floor("release", "relax", "end", 0.05),
];
/// A posture held for a while: getting into it and out of it.
const POSTURE: &[Floor] = &[
    floor("change", "start", "ready", 0.3),
    floor("return", "relax", "end", 0.3),
];
const HEAD_SHIFT: &[Floor] = &[floor("turn", "start", "end", 0.1)];
const GAZE_SHIFT: &[Floor] = &[floor("gaze shift", "start", "end", 0.03)];
const FACE_SHIFT: &[Floor] = &[floor("change", "start", "end", 0.05)];
const POSTURE_SHIFT: &[Floor] = &[floor("change", "start", "end", 0.3)];

/// The floors of a kind of behaviour (none for speech and sound, whose timing their voice sets,
/// nor for the behaviours that move nothing or are timed by their own data).
pub fn floors(kind: &BehaviourKind) -> &'static [Floor] {
    match kind {
        BehaviourKind::Gesture(_) | BehaviourKind::Pointing(_) => ARM,
        BehaviourKind::Head(_) => HEAD,
        BehaviourKind::HeadDirectionShift { .. } => HEAD_SHIFT,
        BehaviourKind::Gaze(_) => GAZE,
        BehaviourKind::GazeShift(_) => GAZE_SHIFT,
        BehaviourKind::Face(_) | BehaviourKind::FaceLexeme(_) | BehaviourKind::FaceFacs(_) => FACE,
        BehaviourKind::FaceShift(_) => FACE_SHIFT,
        BehaviourKind::Posture(_) => POSTURE,
        BehaviourKind::PostureShift(_) => POSTURE_SHIFT,
        _ => &[],
    }
}

/// A behaviour whose schedule squeezes phases below what a person can perform.
#[derive(Debug, Clone, PartialEq)]
pub struct Squeeze {
    /// The behaviour's id.
    pub behaviour: crate::language::bml::Id,
    /// Each squeezed phase's floor, with how long the schedule lets it last (seconds).
    pub phases: Vec<(Floor, f64)>,
}

impl Squeeze {
    /// The warning's sentence, naming every squeezed phase.
    pub fn sentence(&self) -> String {
        let phases: Vec<String> = (self.phases.iter())
            .map(|(f, lasts)| {
                format!(
                    "its {} ({} to {}) lasts {lasts:.3} s where a person needs {} s",
                    f.what, f.from, f.to, f.seconds
                )
            })
            .collect();
        format!(
            "'{}' is squeezed: {}; it is performed that fast because its constraints ask for it",
            self.behaviour,
            phases.join(", ")
        )
    }
}

/// The behaviours of `schedule` (from `block`) with phases shorter than their floors, in document
/// order. A phase whose end is not scheduled (a persistent behaviour) is not squeezed.
pub fn squeezed(block: &Block, schedule: &BlockSchedule) -> Vec<Squeeze> {
    // (by id: a block may hold many thousands of behaviours)
    let scheduled: std::collections::HashMap<&str, &ScheduledBehaviour> =
        (schedule.behaviours.iter())
            .map(|s| (s.id.as_str(), s))
            .collect();
    let mut out = Vec::new();
    for b in &block.behaviours {
        let Some(s) = scheduled.get(b.id.as_str()) else {
            continue;
        };
        let phases: Vec<(Floor, f64)> = (floors(&b.kind).iter())
            .filter_map(|f| Some((*f, s.time(f.to)? - s.time(f.from)?)))
            // (1 µs: the solver's own tolerance)
            .filter(|(f, lasts)| lasts.is_finite() && *lasts < f.seconds - 1e-6)
            .collect();
        if !phases.is_empty() {
            out.push(Squeeze {
                behaviour: b.id.clone(),
                phases,
            });
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::planning::schedule::{NoExternal, Optimal, SchedulingStrategy};
    use crate::planning::timing::DefaultTimingModels;

    fn squeezes(text: &str) -> Vec<String> {
        let block = crate::language::bml::load(text).unwrap().block;
        let schedule = Optimal
            .schedule(&block, &DefaultTimingModels::default(), &NoExternal)
            .unwrap();
        (squeezed(&block, &schedule).iter())
            .flat_map(|s| {
                s.phases
                    .iter()
                    .map(|(f, _)| format!("{}:{}", s.behaviour, f.what))
            })
            .collect()
    }

    #[test]
    fn a_gesture_ten_milliseconds_long_is_squeezed_in_every_moving_phase() {
        let text = r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="b">
            <gesture id="g" lexeme="BEAT" start="4" end="4.01"/></bml>"#;
        assert_eq!(
            squeezes(text),
            ["g:preparation", "g:stroke", "g:retraction"]
        );
    }

    #[test]
    fn behaviours_at_their_own_pace_are_not_squeezed() {
        let text = r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="b">
            <gesture id="g" lexeme="BEAT" start="4"/>
            <head id="h" lexeme="NOD" start="g:end"/>
            <gaze id="z" target="user" end="g:end+3"/>
            <faceLexeme id="f" lexeme="SMILE" start="1"/>
            <posture id="p" start="0"><stance type="STANDING"/></posture>
            </bml>"#;
        assert!(squeezes(text).is_empty(), "{:?}", squeezes(text));
    }

    #[test]
    fn a_stroke_pinned_short_is_squeezed_but_its_slow_preparation_is_not() {
        let text = r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="b">
            <gesture id="g" lexeme="BEAT" strokeStart="2" strokeEnd="2.02"/></bml>"#;
        assert_eq!(squeezes(text), ["g:stroke"]);
    }
}
