//! Timing people can perform: a schedule never squeezes a behaviour's stroke below the shortest a
//! person can do (0.1 s for an arm's or head's stroke) without saying so. The realizer meets the
//! constraints it is given; when they leave a stroke shorter than that, an `INVALID_TIMING`
//! warning names the behaviour and the phase. Checked on the known cases and on random
//! constraint sets through the whole realizer (its predictions and its warnings).

#[path = "common/random_bml.rs"]
mod random_bml;

use bml_realizer::language::feedback::{Feedback, WarningType};
use bml_realizer::realizer::Realizer;
use proptest::prelude::*;

const NS: &str = "http://www.bml-initiative.org/bml/bml-1.0";
/// The shortest stroke (`strokeStart` to `strokeEnd`) of an arm's gesture or a head's movement.
const STROKE_FLOOR: f64 = 0.1;

/// Each behaviour's predicted syncs: (`block:behaviour`, [(sync, time)]).
type Predicted = Vec<(String, Vec<(String, f64)>)>;
/// Warnings: (id, type, text).
type Warnings = Vec<(String, String, String)>;

/// Performs `text` at 0 and returns the predictions and the warnings.
fn plan(text: &str) -> (Predicted, Warnings) {
    let mut r = Realizer::new();
    let _ = r.perform_bml(text);
    let (mut behaviours, mut warnings) = (Vec::new(), Vec::new());
    for f in r.tick(0.0).feedback {
        match f {
            Feedback::Prediction(p) => {
                for b in p.behaviours {
                    let syncs = b.syncs.iter().map(|(s, t)| (s.to_string(), *t)).collect();
                    behaviours.push((format!("{}:{}", b.block, b.behaviour), syncs));
                }
            }
            Feedback::Warning(w) => {
                let kind = match &w.kind {
                    WarningType::Known(k) => k.as_str().to_string(),
                    WarningType::Other(s) => s.clone(),
                };
                warnings.push((w.id, kind, w.text));
            }
            _ => {}
        }
    }
    (behaviours, warnings)
}

fn time(syncs: &[(String, f64)], name: &str) -> Option<f64> {
    syncs.iter().find(|(s, _)| s == name).map(|(_, t)| *t)
}

/// The behaviours whose stroke lasts less than the floor and that no warning names.
fn silent_squeezes(text: &str) -> Vec<String> {
    let (behaviours, warnings) = plan(text);
    behaviours
        .iter()
        .filter(|(_, syncs)| {
            let stroke = time(syncs, "strokeEnd").zip(time(syncs, "strokeStart"));
            stroke.is_some_and(|(b, a)| b - a < STROKE_FLOOR - 1e-6)
        })
        .filter(|(id, _)| {
            !warnings.iter().any(|(w, kind, text)| {
                w == id && kind == "INVALID_TIMING" && text.contains("stroke")
            })
        })
        .map(|(id, syncs)| format!("{id} {syncs:?}"))
        .collect()
}

#[test]
fn a_beat_pinned_into_ten_milliseconds_is_warned_about_naming_its_phases() {
    let text = format!(
        r#"<bml xmlns="{NS}" id="b"><gesture id="g1" lexeme="BEAT" start="4" end="4.01"/></bml>"#
    );
    let (behaviours, warnings) = plan(&text);
    assert_eq!(behaviours.len(), 1, "performed, as its constraints ask");
    let (id, kind, sentence) = &warnings[..].first().expect("a warning").clone();
    assert_eq!((id.as_str(), kind.as_str()), ("b:g1", "INVALID_TIMING"));
    for phase in ["preparation", "stroke", "retraction"] {
        assert!(sentence.contains(phase), "{sentence}");
    }
    assert_eq!(
        warnings.len(),
        1,
        "one warning for the behaviour: {warnings:?}"
    );
}

#[test]
fn the_beat_others_hang_on_keeps_its_own_length() {
    // a second gesture at g1's start, a nod at its end, a gaze ending 3 s after it: nothing asks
    // g1 to be short, so it is not (no two of its seven syncs at one time) and nothing is warned
    let text = format!(
        r#"<bml xmlns="{NS}" id="b">
        <gesture id="g1" lexeme="BEAT" start="4"/>
        <gesture id="g2" lexeme="BEAT" start="g1:start"/>
        <head id="nod" lexeme="NOD" start="g1:end"/>
        <gaze id="gz" target="user" end="g1:end+3"/></bml>"#
    );
    let (behaviours, warnings) = plan(&text);
    assert!(warnings.is_empty(), "{warnings:?}");
    let g1 = &behaviours.iter().find(|(id, _)| id == "b:g1").unwrap().1;
    assert_eq!(g1.len(), 7);
    for w in g1.windows(2) {
        assert!(w[1].1 > w[0].1 + 1e-3, "{g1:?}");
    }
    assert!(time(g1, "strokeEnd").unwrap() - time(g1, "strokeStart").unwrap() >= STROKE_FLOOR);
}

const KINDS: &[&str] = &[
    r#"gesture lexeme="BEAT""#,
    r#"gesture lexeme="POINT" target="user""#,
    r#"head lexeme="NOD""#,
    r#"head lexeme="SHAKE" repetition="2""#,
    r#"gaze target="user""#,
];
/// A gesture's or head's sync points, in order.
const SYNCS: &[&str] = bml_realizer::language::bml::GESTURE_SYNCS;
const TIMES: &[&str] = &["0", "0.01", "0.05", "0.2", "1", "1.02", "3"];

/// A behaviour: its kind and (sync, time, tied to an earlier behaviour's sync?) constraints.
type Beh = (usize, Vec<(usize, usize, Option<(usize, usize)>)>);

fn block(behaviours: &[Beh]) -> String {
    let mut body = String::new();
    for (b, (kind, syncs)) in behaviours.iter().enumerate() {
        let kind = KINDS[*kind];
        let gaze = kind.starts_with("gaze");
        let syncs = syncs.iter().map(|&(sync, t, tie)| {
            // a gaze has start, ready, relax and end
            let sync = if gaze {
                [0, 1, 1, 1, 5, 5, 6][sync]
            } else {
                sync
            };
            let value = match tie.filter(|_| b > 0) {
                Some((other, s)) => format!("x{}:{}+{}", other % b, ["start", "end"][s], TIMES[t]),
                None => TIMES[t].to_string(),
            };
            (SYNCS[sync], value)
        });
        body.push_str(&random_bml::behaviour(kind, b, syncs));
    }
    format!(r#"<bml xmlns="{NS}" id="r">{body}</bml>"#)
}

fn behaviour() -> impl Strategy<Value = Beh> {
    (
        0..KINDS.len(),
        proptest::collection::vec(
            (
                0..SYNCS.len(),
                0..TIMES.len(),
                proptest::option::of((0usize..4, 0usize..2)),
            ),
            0..4,
        ),
    )
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 400, ..ProptestConfig::default() })]

    #[test]
    fn no_stroke_is_squeezed_below_a_person_s_without_a_warning(
        behaviours in proptest::collection::vec(behaviour(), 1..5),
    ) {
        let text = block(&behaviours);
        let silent = silent_squeezes(&text);
        prop_assert!(silent.is_empty(), "{text}\nsilently squeezed: {silent:?}");
    }
}
