//! Motion, measured on the body the realizer moves (headless numeric tests, issue #7): a nod
//! through the whole realizer at 60 Hz.

use bml_realizer::body::Skeleton;
use bml_realizer::engines::head::{DEFAULT_AMOUNT, NOD_DEGREES};
use bml_realizer::feedback::Feedback;
use bml_realizer::realizer::Realizer;
use glam::Vec3;

const FPS: f64 = 60.0;

/// (time, value) samples.
type Series = Vec<(f64, f64)>;

/// (time, head pitch in degrees) every frame, and the scheduled sync times.
fn run(bml: &str, until: f64) -> (Series, Vec<(String, f64)>) {
    let skeleton = Skeleton::adult();
    let skull = skeleton.joint("skullbase").unwrap();
    let mut r = Realizer::new();
    r.perform_bml(bml).unwrap();
    let (mut pitches, mut syncs) = (Vec::new(), Vec::new());
    let frames = (until * FPS).ceil() as u32;
    for i in 0..=frames {
        let t = f64::from(i) / FPS;
        let frame = r.tick(t);
        for fb in &frame.feedback {
            if let Feedback::SyncPointProgress(p) = fb {
                syncs.push((p.sync.clone(), p.global_time));
            }
        }
        let w = frame.poses[0].pose.world(&skeleton);
        // pitch: how far the face direction turned down from +z, in the y-z plane
        let face = w.orientations[skull] * Vec3::Z;
        let pitch = (-face.y).atan2(face.z).to_degrees() as f64;
        pitches.push((t, pitch));
    }
    (pitches, syncs)
}

fn at(syncs: &[(String, f64)], name: &str) -> f64 {
    syncs.iter().find(|s| s.0 == name).map(|s| s.1).unwrap()
}

#[test]
fn a_nod_reaches_its_amplitude_at_the_stroke_and_rests_at_the_end() {
    let (pitches, syncs) = run(
        r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="b"><head id="n" lexeme="NOD" start="0.5" end="1.7"/></bml>"#,
        2.0,
    );
    let amplitude = DEFAULT_AMOUNT * NOD_DEGREES;
    let (stroke, end) = (at(&syncs, "stroke"), at(&syncs, "end"));
    // the frame nearest the stroke: within 5 % of the amplitude
    let near = pitches
        .iter()
        .min_by(|a, b| (a.0 - stroke).abs().total_cmp(&(b.0 - stroke).abs()))
        .unwrap();
    assert!(
        (near.1 - amplitude).abs() <= 0.05 * amplitude,
        "pitch {} at {} (stroke {stroke})",
        near.1,
        near.0
    );
    // the peak is at the stroke, within one frame
    let peak = pitches.iter().max_by(|a, b| a.1.total_cmp(&b.1)).unwrap();
    assert!(
        (peak.0 - stroke).abs() <= 1.0 / FPS + 1e-9,
        "peak at {} stroke {stroke}",
        peak.0
    );
    assert!(peak.1 <= amplitude + 1e-3);
    // rest before the start and from the end on
    for (t, p) in &pitches {
        if *t <= 0.5 || *t >= end {
            assert!(p.abs() < 0.5, "pitch {p} at {t}");
        }
    }
}

#[test]
fn a_louder_nod_goes_further_and_a_shake_turns_instead() {
    let (nod, _) = run(
        r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="b"><head id="n" lexeme="NOD" amount="1" start="0" end="1"/></bml>"#,
        1.0,
    );
    let max = nod.iter().map(|p| p.1).fold(0.0, f64::max);
    assert!((max - NOD_DEGREES).abs() <= 0.05 * NOD_DEGREES, "{max}");
    let (shake, _) = run(
        r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="b"><head id="n" lexeme="SHAKE" start="0" end="1"/></bml>"#,
        1.0,
    );
    assert!(
        shake.iter().all(|p| p.1.abs() < 1e-3),
        "a shake does not pitch"
    );
}
