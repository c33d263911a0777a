//! Gesture strokes move the hand as people's do: over each phase of a gesture (preparation,
//! stroke, retraction) the wrist's speed rises to one peak and falls again, shaped like a
//! minimum-jerk reach (Flash & Hogan 1985: speed ∝ s²(1 − s)², a peak 1.875 × the mean). The
//! wrist is placed by forward kinematics every 1/240 s through the whole realizer.

use bml_realizer::character::body::Skeleton;
use bml_realizer::language::feedback::Feedback;
use bml_realizer::realizer::Realizer;

const FPS: f64 = 240.0;
const NS: &str = r#"xmlns="http://www.bml-initiative.org/bml/bml-1.0""#;

/// How a phase's wrist speeds compare with a minimum-jerk move of the same length.
#[derive(Debug)]
struct Shape {
    /// Peaks above a fifth of the highest.
    peaks: usize,
    /// Highest speed over the mean.
    peak_over_mean: f64,
    /// Correlation with the minimum-jerk bell.
    correlation: f64,
}

fn shape(speeds: &[f64]) -> Shape {
    let n = speeds.len();
    let top = speeds.iter().cloned().fold(0.0, f64::max);
    let mean = speeds.iter().sum::<f64>() / n as f64;
    let peaks = (1..n - 1)
        .filter(|&i| {
            speeds[i] > 0.2 * top && speeds[i] >= speeds[i - 1] && speeds[i] > speeds[i + 1]
        })
        .count();
    let bell: Vec<f64> = (0..n)
        .map(|i| {
            let s = (i as f64 + 0.5) / n as f64;
            s * s * (1.0 - s) * (1.0 - s)
        })
        .collect();
    let m = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let (ma, mb) = (m(speeds), m(&bell));
    let cov: f64 = speeds
        .iter()
        .zip(&bell)
        .map(|(a, b)| (a - ma) * (b - mb))
        .sum();
    let va: f64 = speeds.iter().map(|a| (a - ma).powi(2)).sum();
    let vb: f64 = bell.iter().map(|b| (b - mb).powi(2)).sum();
    Shape {
        peaks,
        peak_over_mean: top / mean,
        correlation: cov / (va * vb).sqrt(),
    }
}

/// Whether a phase moves like one human reach.
fn human(s: &Shape) -> bool {
    s.peaks == 1 && (1.5..=2.3).contains(&s.peak_over_mean) && s.correlation >= 0.85
}

/// (time, value) samples.
type Series = Vec<(f64, f64)>;

/// The right wrist's speed every frame and the gesture's sync times.
fn gesture(lexeme: &str) -> (Series, Vec<(String, f64)>) {
    let s = Skeleton::adult();
    let wrist = s.joint("r_wrist").unwrap();
    let mut r = Realizer::new().with_idle(false);
    r.perform_bml(&format!(
        r#"<bml {NS} id="b"><gesture id="g" lexeme="{lexeme}" start="0.2"/></bml>"#
    ))
    .unwrap();
    let (mut speeds, mut syncs, mut last) = (Vec::new(), Vec::new(), None);
    for i in 0..(4.0 * FPS) as u32 {
        let t = f64::from(i) / FPS;
        let frame = r.tick(t);
        for f in &frame.feedback {
            if let Feedback::SyncPointProgress(p) = f {
                if p.behaviour == "g" {
                    syncs.push((p.sync.to_string(), p.global_time));
                }
            }
        }
        let at = frame.poses[0].pose.world(&s).positions[wrist];
        if let Some(prev) = last {
            speeds.push((t, f64::from(at.distance(prev)) * FPS));
        }
        last = Some(at);
    }
    (speeds, syncs)
}

fn between(speeds: &[(f64, f64)], from: f64, to: f64) -> Vec<f64> {
    (speeds.iter())
        .filter(|(t, _)| *t > from + 1e-9 && *t <= to + 1e-9)
        .map(|s| s.1)
        .collect()
}

#[test]
fn the_test_tells_a_reach_from_a_glide_and_a_double_move() {
    let n = 100;
    let bell: Vec<f64> = (0..n)
        .map(|i| {
            let s = (i as f64 + 0.5) / n as f64;
            s * s * (1.0 - s) * (1.0 - s)
        })
        .collect();
    assert!(human(&shape(&bell)), "{:?}", shape(&bell));
    // constant speed (linear interpolation), and two reaches in one phase
    let glide = vec![1.0; n];
    assert!(!human(&shape(&glide)), "{:?}", shape(&glide));
    let double: Vec<f64> = (0..n).map(|i| bell[(2 * i) % n]).collect();
    assert!(!human(&shape(&double)), "{:?}", shape(&double));
}

/// The lexicon's gestures.
const LEXEMES: [&str; 17] = [
    "BEAT",
    "CALM",
    "CONDUIT",
    "CUP",
    "ENUMERATE",
    "FRAME",
    "HELLO",
    "INDICATE_LEFT",
    "INDICATE_RIGHT",
    "NEGATE",
    "OFFER",
    "POINT",
    "SHRUG",
    "STOP",
    "SWEEP",
    "THINK",
    "WAVE",
];

#[test]
fn each_gesture_reaches_out_and_back_like_a_person() {
    for lexeme in LEXEMES {
        let (speeds, syncs) = gesture(lexeme);
        let at = |n: &str| {
            (syncs.iter())
                .find(|s| s.0 == n)
                .unwrap_or_else(|| panic!("{lexeme}: no {n} in {syncs:?}"))
                .1
        };
        for (from, to) in [("start", "ready"), ("relax", "end")] {
            let v = between(&speeds, at(from), at(to));
            let moved = v.iter().cloned().fold(0.0, f64::max) > 0.05;
            if !moved {
                continue; // a gesture that keeps the left hand still
            }
            let s = shape(&v);
            assert!(human(&s), "{lexeme} {from}->{to}: {s:?}");
        }
    }
}
