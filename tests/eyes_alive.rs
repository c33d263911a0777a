//! Eyes alive, measured through the realizer's frames (sampled at 500 Hz) against people's:
//! at rest for 60 s and speaking for 45 s, the eyes make at least 12 saccades a minute, each on
//! the main sequence (Carpenter, "Movements of the Eyes", 1988: a saccade of A degrees lasts
//! about 2.2·A + 21 ms, its peak speed rising with A and levelling off below 600°/s); most
//! utterances begin with a look away that comes back (Kendon, 1967; Cassell, Torres and
//! Prevost, 1999); a running BML gaze holds the eyes over all of it; and the lids blink at
//! people's rates (Bentivoglio et al., 1997: 17 ± 13 a minute at rest, 26 ± 15 in
//! conversation), at irregular intervals (coefficient of variation at least 0.4), each blink
//! 100–400 ms long.

use bml_realizer::character::body::Skeleton;
use bml_realizer::character::face::Face;
use bml_realizer::language::feedback::Feedback;
use bml_realizer::realizer::Realizer;
use glam::Vec3;

const NS: &str = r#"xmlns="http://www.bml-initiative.org/bml/bml-1.0""#;
/// Samples a second.
const RATE: f64 = 500.0;
/// The characters measured.
const WHO: [&str; 3] = ["anna", "bob", "carl"];

/// One character's eyes (yaw left, pitch up; degrees) and blink closure, sample by sample.
struct Track {
    eyes: Vec<(f64, f64)>,
    closed: Vec<f32>,
}

/// What a run of `blocks` (each `{c}` replaced by a character's id) for [`WHO`] over
/// `seconds` shows: each character's track and the sync times (`character/behaviour:sync`).
fn run(blocks: &[&str], seconds: f64) -> (Vec<Track>, Vec<(String, f64)>) {
    let mut r = Realizer::new();
    r.world_mut().set("listener", Vec3::new(0.3, 1.55, 1.5));
    for c in WHO {
        for b in blocks {
            r.perform_bml(&b.replace("{c}", c)).unwrap();
        }
    }
    let skeleton = Skeleton::adult();
    let eye = ["l_eyeball_joint", "r_eyeball_joint"].map(|j| skeleton.joint(j).unwrap());
    let mut tracks: Vec<Track> = WHO
        .iter()
        .map(|_| Track {
            eyes: Vec::new(),
            closed: Vec::new(),
        })
        .collect();
    let mut syncs = Vec::new();
    for i in 0..=(seconds * RATE) as u32 {
        let frame = r.tick(f64::from(i) / RATE);
        for fb in &frame.feedback {
            if let Feedback::SyncPointProgress(p) = fb {
                syncs.push((format!("{}:{}", p.behaviour, p.sync), p.global_time));
            }
        }
        for (c, track) in WHO.iter().zip(&mut tracks) {
            let pose = frame.character(c).unwrap();
            let d = (pose.pose.rotations[eye[0]] * Vec3::Z + pose.pose.rotations[eye[1]] * Vec3::Z)
                .normalize();
            let (yaw, pitch) = (d.x.atan2(d.z), d.y.asin());
            track
                .eyes
                .push((f64::from(yaw).to_degrees(), f64::from(pitch).to_degrees()));
            track.closed.push(blink(&pose.face));
        }
    }
    (tracks, syncs)
}

/// How closed the left lid is by a blink (AU45).
fn blink(face: &Face) -> f32 {
    let m = bml_realizer::character::face::FaceModel::default_model();
    face.aus.0[m
        .slots(45, bml_realizer::language::bml::Side::Left)
        .unwrap()[0]]
}

/// The saccades of `eyes`: (start, duration, amplitude in degrees, peak speed in degrees a
/// second), found from the eyes' speed alone.
fn saccades(eyes: &[(f64, f64)]) -> Vec<(f64, f64, f64, f64)> {
    let dt = 1.0 / RATE;
    let (mut out, mut moving, mut from, mut at, mut peak) =
        (Vec::new(), false, (0.0, 0.0), 0.0, 0.0f64);
    for (i, w) in eyes.windows(2).enumerate() {
        let t = (i + 1) as f64 * dt;
        let speed = (w[1].0 - w[0].0).hypot(w[1].1 - w[0].1) / dt;
        if speed > 2.0 && !moving {
            (moving, from, at, peak) = (true, w[0], t - dt, 0.0);
        }
        if moving {
            peak = peak.max(speed);
            if speed < 0.5 {
                moving = false;
                let amplitude = (w[1].0 - from.0).hypot(w[1].1 - from.1);
                out.push((at, t - dt - at, amplitude, peak));
            }
        }
    }
    out
}

/// The moments the lids closed (AU45 reached 0.99) and each blink's length (from the lids
/// moving to open again).
fn blinks(closed: &[f32]) -> (Vec<f64>, Vec<f64>) {
    let (mut shut, mut lengths, mut began) = (Vec::new(), Vec::new(), None);
    for (i, w) in closed.windows(2).enumerate() {
        let t = (i + 1) as f64 / RATE;
        if w[1] >= 0.99 && w[0] < 0.99 {
            shut.push(t);
        }
        match (w[1] > 0.0, began) {
            (true, None) => began = Some(t),
            (false, Some(s)) => {
                lengths.push(t - s);
                began = None;
            }
            _ => {}
        }
    }
    (shut, lengths)
}

/// The coefficient of variation of intervals `d`.
fn cv(d: &[f64]) -> f64 {
    let mean = d.iter().sum::<f64>() / d.len() as f64;
    let var = d.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (d.len() - 1) as f64;
    var.sqrt() / mean
}

/// Checks the saccades and blinks of `tracks` over `seconds`; blinks a minute within `rate`.
/// The blinks' intervals vary as people's: measured over all characters' intervals (a minute
/// of one person's blinks is too few to tell).
fn on_people_s_norms(what: &str, tracks: &[Track], seconds: f64, rate: (f64, f64)) {
    let mut intervals = Vec::new();
    for (c, track) in WHO.iter().zip(tracks) {
        let all = saccades(&track.eyes);
        let per_minute = all.len() as f64 * 60.0 / seconds;
        let largest = all.iter().map(|s| s.2).fold(0.0, f64::max);
        println!("{what}, {c}: {per_minute:.1} saccades a minute, the largest {largest:.1}°");
        assert!(
            per_minute >= 12.0,
            "{what}, {c}: {per_minute:.1} saccades a minute"
        );
        for &(at, duration, amplitude, peak) in &all {
            if amplitude < 1.0 {
                continue;
            }
            let main = 0.0022 * amplitude + 0.021;
            let slack = 2.0 / RATE;
            assert!(
                duration >= 0.8 * main - slack && duration <= 1.6 * main + slack,
                "{what}, {c}: at {at:.3} s a {amplitude:.1}° saccade lasts {duration:.3} s"
            );
            assert!(
                peak > 20.0 * amplitude.min(10.0) && peak < 600.0,
                "{what}, {c}: at {at:.3} s {amplitude:.1}° at {peak:.0}°/s"
            );
        }
        let (shut, lengths) = blinks(&track.closed);
        let per_minute = shut.len() as f64 * 60.0 / seconds;
        println!("{what}, {c}: {per_minute:.1} blinks a minute");
        assert!(
            (rate.0..=rate.1).contains(&per_minute),
            "{what}, {c}: {per_minute:.1} blinks a minute"
        );
        intervals.extend(shut.windows(2).map(|w| w[1] - w[0]));
        for l in lengths {
            assert!((0.1..=0.4).contains(&l), "{what}, {c}: a blink of {l:.3} s");
        }
    }
    let cv = cv(&intervals);
    assert!(cv >= 0.4, "{what}: the blinks' intervals vary by {cv:.2}");
    println!("{what}: the blinks' intervals vary by {cv:.2}");
}

/// Nine utterances, one every 5 s (each about 2–3 s long).
fn speaking(gaze: bool) -> String {
    let lines = [
        "Good morning, and thank you all for coming today.",
        "I would like to tell you about the project we started last spring.",
        "It began with a simple question about how people walk.",
        "We measured a hundred people in the hall downstairs.",
        "Some of them walked slowly, some of them ran.",
        "What we found surprised us at first.",
        "Everybody lifts the heel well before the other foot lands.",
        "So the knee is almost straight in the middle of the step.",
        "That is what our characters do now as well.",
    ];
    let mut bml = format!(r#"<bml {NS} id="talk" characterId="{{c}}">"#);
    if gaze {
        bml += r#"<gaze id="look" target="listener" start="0" end="47"/>"#;
    }
    for (i, line) in lines.iter().enumerate() {
        let start = 0.5 + 5.0 * i as f64;
        bml += &format!(r#"<speech id="s{i}" start="{start}"><text>{line}</text></speech>"#);
    }
    bml + "</bml>"
}

#[test]
fn idle_eyes_and_lids_live_as_people_s_at_rest() {
    let (tracks, _) = run(
        &[
            r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="rest" characterId="{c}"/>"#,
        ],
        60.0,
    );
    on_people_s_norms("at rest", &tracks, 60.0, (4.0, 30.0));
}

#[test]
fn speaking_eyes_look_away_as_utterances_begin_and_lids_blink_more() {
    let talk = speaking(false);
    let (tracks, syncs) = run(&[&talk], 45.0);
    on_people_s_norms("speaking", &tracks, 45.0, (11.0, 41.0));
    // the look away, as the difference from the same character's idle eyes at the same moment
    let rest = format!(r#"<bml {NS} id="rest" characterId="{{c}}"/>"#);
    let (idle, _) = run(&[&rest], 45.0);
    let at = |t: f64| (t * RATE).round() as usize;
    let (mut utterances, mut averted) = (0, 0);
    for (c, (track, idle)) in WHO.iter().zip(tracks.iter().zip(&idle)) {
        let away = |t: f64| {
            let (a, b) = (track.eyes[at(t)], idle.eyes[at(t)]);
            (a.0 - b.0).hypot(a.1 - b.1)
        };
        for i in 0..9 {
            let [start, end]: [f64; 2] = ["start", "end"].map(|s| {
                let name = format!("s{i}:{s}");
                (syncs.iter().find(|(n, _)| *n == name))
                    .map(|x| x.1)
                    .unwrap()
            });
            utterances += 1;
            assert!(away(start - 0.01) < 0.5, "{c}: away before s{i} began");
            // away within a saccade, held, back before the next
            if away(start + 0.1) > 9.0 {
                averted += 1;
                let back = (0.5 * (end - start)).clamp(0.6, 2.0);
                // (held until just before the jump back; an idle saccade due within a
                // saccade's length of it is left out, so the idle run may differ from then)
                assert!(away(start + back - 0.1) > 9.0, "{c}: s{i} held");
                let (yaw, pitch) = track.eyes[at(start + back + 0.15)];
                assert!(
                    yaw.abs() <= 10.001 && pitch.abs() <= 6.001,
                    "{c}: s{i} back: {yaw:.1}° {pitch:.1}°"
                );
            } else {
                assert!(away(start + 0.1) < 0.5, "{c}: s{i} half away");
            }
            // and with the idle eyes again once they make their next saccade
            assert!(away(start + 4.4) < 1e-6, "{c}: s{i} never came back");
        }
    }
    let share = f64::from(averted) / f64::from(utterances);
    println!("{averted} of {utterances} utterances begin with a look away");
    assert!(
        (0.5..=0.9).contains(&share),
        "{averted} of {utterances} utterances begin with a look away"
    );
}

#[test]
fn a_bml_gaze_holds_the_eyes_over_the_look_away_and_the_saccades() {
    let (with, _) = run(&[&speaking(true)], 12.0);
    let look = format!(
        r#"<bml {NS} id="look" characterId="{{c}}"><gaze id="look" target="listener" start="0" end="47"/></bml>"#
    );
    let (without, _) = run(&[&look], 12.0);
    for (c, (a, b)) in WHO.iter().zip(with.iter().zip(&without)) {
        // from when the gaze has reached the listener
        let most = (a.eyes.iter().zip(&b.eyes).skip(RATE as usize))
            .map(|(x, y)| (x.0 - y.0).hypot(x.1 - y.1))
            .fold(0.0, f64::max);
        assert!(most < 0.5, "{c}: the eyes left the listener by {most:.1}°");
    }
}
