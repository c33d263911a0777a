//! Motion, measured on the body the realizer moves (headless numeric tests): a nod
//! through the whole realizer at 60 Hz.

use bml_realizer::character::body::Skeleton;
use bml_realizer::engines::head::{DEFAULT_AMOUNT, NOD_DEGREES};
use bml_realizer::language::feedback::Feedback;
use bml_realizer::realizer::Realizer;

/// A realizer without the idle layer: these tests measure each engine's motion exactly, from the
/// rest pose (tests/body.rs looks at the body with the idle layer on, as a person sees it).
fn still() -> Realizer {
    Realizer::new().with_idle(false)
}
use glam::Vec3;

const FPS: f64 = 60.0;

/// (time, value) samples.
type Series = Vec<(f64, f64)>;

/// (time, head pitch in degrees) every frame, and the scheduled sync times.
fn run(bml: &str, until: f64) -> (Series, Vec<(String, f64)>) {
    let skeleton = Skeleton::adult();
    let skull = skeleton.joint("skullbase").unwrap();
    let mut r = still();
    r.perform_bml(bml).unwrap();
    let (mut pitches, mut syncs) = (Vec::new(), Vec::new());
    let frames = (until * FPS).ceil() as u32;
    for i in 0..=frames {
        let t = f64::from(i) / FPS;
        let frame = r.tick(t);
        for fb in &frame.feedback {
            if let Feedback::SyncPointProgress(p) = fb {
                syncs.push((p.sync.to_string(), p.global_time));
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

#[test]
fn a_head_lexeme_bound_only_in_the_data_file_moves_the_head() {
    // TOSS: pitch back by 20° at amount 1 (fixtures/bindings/heads.json)
    let (toss, _) = run(
        r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="b"><head id="t" lexeme="TOSS" amount="1" start="0" end="1"/></bml>"#,
        1.0,
    );
    let min = toss.iter().map(|p| p.1).fold(0.0, f64::min);
    assert!((min + 20.0).abs() <= 1.0, "{min}");
}

// ---- gaze ---------------------------------------------------------------------------------

use bml_realizer::engines::gaze::{EYE_PITCH_LIMIT, EYE_YAW_LIMIT};
use glam::Quat;

/// Angle (degrees) between each eye's line of sight (+z of the eye joint) and the direction to
/// `target`, the larger of the two eyes.
fn eye_error(skeleton: &Skeleton, pose: &bml_realizer::character::body::Pose, target: Vec3) -> f64 {
    let w = pose.world(skeleton);
    ["l_eyeball_joint", "r_eyeball_joint"]
        .iter()
        .map(|e| {
            let i = skeleton.joint(e).unwrap();
            let sight = w.orientations[i] * Vec3::Z;
            sight.angle_between(target - w.positions[i]).to_degrees() as f64
        })
        .fold(0.0, f64::max)
}

fn eye_angles(skeleton: &Skeleton, pose: &bml_realizer::character::body::Pose) -> Vec<(f32, f32)> {
    ["l_eyeball_joint", "r_eyeball_joint"]
        .iter()
        .map(|e| {
            let d = pose.rotations[skeleton.joint(e).unwrap()] * Vec3::Z;
            (
                d.x.atan2(d.z).to_degrees(),
                (-d.y).atan2((d.x * d.x + d.z * d.z).sqrt()).to_degrees(),
            )
        })
        .collect()
}

fn gaze_block(id: &str, target: &str, extra: &str) -> String {
    format!(
        r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="{id}"><gaze id="g" target="{target}" {extra}/></bml>"#
    )
}

#[test]
fn a_gaze_puts_the_eyes_on_a_static_target_within_their_limits() {
    let skeleton = Skeleton::adult();
    let target = Vec3::new(0.5, 1.3, 1.0);
    let mut r = still();
    r.world_mut().set("cup", target);
    r.perform_bml(&gaze_block(
        "b",
        "cup",
        r#"start="0" ready="0.5" relax="2" end="2.5""#,
    ))
    .unwrap();
    let skull = skeleton.joint("skullbase").unwrap();
    let mut yaw_speed = Vec::new();
    let mut last_yaw = 0.0f32;
    for i in 0..=150 {
        let t = f64::from(i) / FPS;
        let frame = r.tick(t);
        let pose = &frame.poses[0].pose;
        if (0.5..2.0).contains(&t) {
            let e = eye_error(&skeleton, pose, target);
            assert!(e < 0.5, "eye-line error {e}° at {t}");
        }
        for (y, p) in eye_angles(&skeleton, pose) {
            assert!(y.abs() <= EYE_YAW_LIMIT + 1e-3 && p.abs() <= EYE_PITCH_LIMIT + 1e-3);
        }
        let w = pose.world(&skeleton);
        let face = w.orientations[skull] * Vec3::Z;
        let yaw = face.x.atan2(face.z);
        if t <= 0.5 {
            yaw_speed.push(yaw - last_yaw);
        }
        last_yaw = yaw;
        if t >= 2.5 {
            assert!(yaw.abs().to_degrees() < 0.5, "back at rest: {yaw}");
        }
    }
    // head velocity single-peaked while shifting to the target
    let peak = yaw_speed
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(b.1))
        .unwrap()
        .0;
    assert!(yaw_speed[..=peak].windows(2).all(|w| w[1] >= w[0] - 1e-7));
    assert!(yaw_speed[peak..].windows(2).all(|w| w[1] <= w[0] + 1e-7));
}

#[test]
fn donders_the_final_head_orientation_does_not_depend_on_where_the_head_was() {
    let skeleton = Skeleton::adult();
    let skull = skeleton.joint("skullbase").unwrap();
    let head_at = |before: Option<&str>| -> Quat {
        let mut r = still();
        r.world_mut().set("left", Vec3::new(1.0, 1.0, 0.8));
        r.world_mut().set("cup", Vec3::new(-0.4, 1.2, 1.0));
        if let Some(t) = before {
            r.perform_bml(&format!(
                r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="a"><gazeShift id="s" target="{t}" start="0" end="1"/></bml>"#
            ))
            .unwrap();
            r.tick(1.5);
        }
        let now = r.now();
        // block-relative times: the gaze starts when the block does
        r.perform_bml(&gaze_block("b", "cup", r#"start="0" ready="0.5" end="3""#))
            .unwrap();
        let frame = r.tick(now + 1.0);
        frame.poses[0].pose.world(&skeleton).orientations[skull]
    };
    let straight = head_at(None);
    let shifted = head_at(Some("left"));
    let diff = straight.angle_between(shifted).to_degrees();
    assert!(diff < 0.1, "{diff}°");
}

#[test]
fn a_moving_target_is_tracked_after_ready() {
    let mut r = still();
    let place = |t: f64| {
        // 30°/s around the character, 1.2 m away, at eye height
        let a = (30.0 * t).to_radians();
        Vec3::new(1.2 * a.sin() as f32, 1.55, 1.2 * a.cos() as f32)
    };
    // up to 60° to the side by relax: within reach of the neck and the eyes
    let timing = r#"start="0" ready="0.4" relax="2" end="2.4""#;
    let (e, t) = held_gaze_error(&mut r, place, timing, 0.4..2.0, 150);
    assert!(e < 2.0, "tracking error {e}° at {t}");
}

/// Gazes at a world point that is at `place(t)` at each frame `t` (60 a second, `frames` of
/// them) with a block of `timing`; the worst eye-line error (°) over `held`, and when.
fn held_gaze_error(
    r: &mut Realizer,
    place: impl Fn(f64) -> Vec3,
    timing: &str,
    held: std::ops::Range<f64>,
    frames: u32,
) -> (f64, f64) {
    let skeleton = Skeleton::adult();
    r.world_mut().set("target", place(0.0));
    r.perform_bml(&gaze_block("b", "target", timing)).unwrap();
    let mut worst = (0.0, 0.0);
    for i in 0..=frames {
        let t = f64::from(i) / FPS;
        r.world_mut().set("target", place(t));
        let frame = r.tick(t);
        if held.contains(&t) {
            let e = eye_error(&skeleton, &frame.poses[0].pose, place(t));
            if e >= worst.0 {
                worst = (e, t);
            }
        }
    }
    worst
}

#[test]
fn a_gaze_at_a_target_the_world_lacks_is_refused_with_a_warning() {
    let mut r = still();
    let log = std::sync::Arc::new(std::sync::Mutex::new(Vec::new()));
    let sink = log.clone();
    r.add_listener(Box::new(move |f: &Feedback| {
        sink.lock().unwrap().push(f.clone())
    }));
    r.perform_bml(&gaze_block("b", "nowhere", "")).unwrap();
    let warnings: Vec<String> = log
        .lock()
        .unwrap()
        .iter()
        .filter_map(|f| match f {
            Feedback::Warning(w) => Some(format!("{} {} {}", w.id, w.kind.as_str(), w.text)),
            _ => None,
        })
        .collect();
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(warnings[0].starts_with("b:g EXECUTION_FAILURE b:g: there is no target 'nowhere'"));
}

#[test]
fn a_gaze_shift_keeps_looking_at_its_target_after_it_ends() {
    let skeleton = Skeleton::adult();
    let target = Vec3::new(1.0, 1.0, 0.8);
    let mut r = still();
    r.world_mut().set("left", target);
    r.perform_bml(r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="a"><gazeShift id="s" target="left" start="0" end="1"/></bml>"#)
        .unwrap();
    let frame = r.tick(5.0);
    assert_eq!(r.next_event(), None, "the shift has ended");
    let pose = &frame.poses[0].pose;
    assert!(eye_error(&skeleton, pose, target) < 0.5);
    let skull = skeleton.joint("skullbase").unwrap();
    let face = pose.world(&skeleton).orientations[skull] * Vec3::Z;
    assert!(
        face.x.atan2(face.z).to_degrees() > 20.0,
        "the head stays turned left"
    );
}

// ---- pointing -----------------------------------------------------------------------------

#[test]
fn pointing_aims_the_index_finger_at_the_target_at_the_stroke_and_returns() {
    let skeleton = Skeleton::adult();
    for (mode, side, target) in [
        ("RIGHT_HAND", "r", Vec3::new(-0.6, 1.3, 1.2)),
        ("LEFT_HAND", "l", Vec3::new(0.8, 0.9, 0.7)),
        ("RIGHT_HAND", "r", Vec3::new(0.1, 1.8, 1.0)),
    ] {
        let mut r = still();
        r.world_mut().set("thing", target);
        let log = std::sync::Arc::new(std::sync::Mutex::new(Vec::new()));
        let sink = log.clone();
        r.add_listener(Box::new(move |f: &Feedback| {
            sink.lock().unwrap().push(f.clone())
        }));
        r.perform_bml(&format!(
            r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="b"><pointing id="p" target="thing" mode="{mode}" start="0.2" end="2.4"/></bml>"#
        ))
        .unwrap();
        let mut stroke = None;
        let (i1, i3) = (
            skeleton.joint(&format!("{side}_index1")).unwrap(),
            skeleton.joint(&format!("{side}_index3")).unwrap(),
        );
        for i in 0..=180 {
            let t = f64::from(i) / FPS;
            let frame = r.tick(t);
            if stroke.is_none() {
                stroke = log.lock().unwrap().iter().find_map(|f| match f {
                    Feedback::SyncPointProgress(p) if p.sync == "stroke" => Some(p.global_time),
                    _ => None,
                });
                if let Some(s) = stroke {
                    // the frame of the stroke: the index finger points at the target
                    let at_stroke = r.tick(s);
                    let w = at_stroke.poses[0].pose.world(&skeleton);
                    let finger = w.positions[i3] - w.positions[i1];
                    let error = finger.angle_between(target - w.positions[i3]).to_degrees();
                    assert!(error < 3.0, "{mode}: finger {error}° off the target");
                }
            }
            if t >= 2.4 {
                // back to the start pose
                let pose = &frame.poses[0].pose;
                for j in ["shoulder", "elbow", "wrist"] {
                    let q = pose.rotations[skeleton.joint(&format!("{side}_{j}")).unwrap()];
                    assert!(
                        q.angle_between(Quat::IDENTITY).to_degrees() < 0.5,
                        "{j} at {t}"
                    );
                }
            }
        }
        assert!(stroke.is_some());
    }
}

// ---- keyframes ----------------------------------------------------------------------------

#[test]
fn keyframes_hit_every_key_exactly_at_its_stretched_time() {
    let skeleton = Skeleton::adult();
    let elbow = skeleton.joint("r_elbow").unwrap();
    let keys = [
        (0.0, Quat::IDENTITY),
        (1.0, Quat::from_rotation_y(1.0)),
        // (a twist and a bend forward: both inside the elbow's limits)
        (
            3.0,
            Quat::from_rotation_x(-0.4) * Quat::from_rotation_y(-0.5),
        ),
    ];
    let lines: String = keys
        .iter()
        .map(|(t, q)| format!("{t} {} {} {} {}\n", q.w, q.x, q.y, q.z))
        .collect();
    let mut r = still();
    // 3 s of keys stretched over 1..7: keys at 1, 3 and 7
    r.perform_bml(&format!(
        r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" xmlns:bmlt="http://hmi.ewi.utwente.nl/bmlt" id="b">
             <bmlt:keyframe id="kf" start="1" end="7">
               <SkeletonInterpolator rotationEncoding="quaternions" parts="r_elbow" encoding="R">{lines}</SkeletonInterpolator>
             </bmlt:keyframe></bml>"#
    ))
    .unwrap();
    for ((_, q), t) in keys.iter().zip([1.0, 3.0, 7.0]) {
        let frame = r.tick(t);
        let got = frame.poses[0].pose.rotations[elbow];
        assert!(got.angle_between(*q) < 1e-6, "key at {t}: {got:?} vs {q:?}");
    }
}

#[test]
fn a_gaze_offset_looks_beside_the_target() {
    let skeleton = Skeleton::adult();
    let target = Vec3::new(0.0, 1.55, 2.0);
    let mut r = still();
    r.world_mut().set("door", target);
    r.perform_bml(&gaze_block(
        "b",
        "door",
        r#"offsetAngle="15" offsetDirection="LEFT" start="0" ready="0.3" end="2""#,
    ))
    .unwrap();
    let frame = r.tick(1.0);
    let w = frame.poses[0].pose.world(&skeleton);
    for e in ["l_eyeball_joint", "r_eyeball_joint"] {
        let i = skeleton.joint(e).unwrap();
        let sight = w.orientations[i] * Vec3::Z;
        let to_target = target - w.positions[i];
        let off = sight.angle_between(to_target).to_degrees();
        assert!((off - 15.0).abs() < 1.0, "{e}: {off}° off the target");
        assert!(
            sight.x > to_target.normalize().x,
            "to the character's left (+x)"
        );
    }
}

// ---- gestures from the lexicon ------------------------------------------------------------

#[test]
fn a_beat_hits_its_bound_keys_at_its_syncs_and_the_left_hand_mirrors_them() {
    use bml_realizer::engines::gesture::{mirror, Lexicon};
    let skeleton = Skeleton::adult();
    let lexicon = Lexicon::default_lexicon();
    let beat = lexicon.keys("BEAT").unwrap();
    for mode in ["RIGHT_HAND", "LEFT_HAND"] {
        let mut r = still();
        let log = std::sync::Arc::new(std::sync::Mutex::new(Vec::new()));
        let sink = log.clone();
        r.add_listener(Box::new(move |f: &Feedback| {
            sink.lock().unwrap().push(f.clone())
        }));
        r.perform_bml(&format!(
            r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="b"><gesture id="g" lexeme="BEAT" mode="{mode}" start="0.5" end="2"/></bml>"#
        ))
        .unwrap();
        // the scheduled sync times, from the PENDING prediction
        let predicted: Vec<(String, f64)> = log
            .lock()
            .unwrap()
            .iter()
            .find_map(|f| match f {
                Feedback::Prediction(p) if !p.behaviours.is_empty() => Some(
                    p.behaviours[0]
                        .syncs
                        .iter()
                        .map(|(n, t)| (n.to_string(), *t))
                        .collect(),
                ),
                _ => None,
            })
            .unwrap();
        for (sync, joints) in beat {
            let t = predicted.iter().find(|s| &s.0 == sync).unwrap().1;
            let frame = r.tick(t);
            let pose = &frame.poses[0].pose;
            for (joint, q) in joints {
                let (name, q) = if mode == "LEFT_HAND" {
                    mirror(joint, *q)
                } else {
                    (joint.clone(), *q)
                };
                let got = pose.rotations[skeleton.joint(&name).unwrap()];
                assert!(got.angle_between(q) < 1e-5, "{mode} {sync} {name}");
            }
        }
        let frame = r.tick(2.0);
        for q in &frame.poses[0].pose.rotations {
            assert!(
                q.angle_between(Quat::IDENTITY) < 1e-5,
                "{mode}: back at rest at the end"
            );
        }
    }
}

// ---- posture ------------------------------------------------------------------------------

#[test]
fn a_sitting_shift_folds_the_legs_and_stays_a_posture_returns() {
    let skeleton = Skeleton::adult();
    let (knee, hip) = (
        skeleton.joint("l_knee").unwrap(),
        skeleton.joint("l_hip").unwrap(),
    );
    let mut r = still();
    r.perform_bml(
        r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="a"><postureShift id="sit" start="0" end="2"><stance type="SITTING"/></postureShift></bml>"#,
    )
    .unwrap();
    let rest_height = Skeleton::adult().joints()[0].offset.y;
    let mid = r.tick(1.0);
    let half = mid.poses[0].pose.root.y;
    assert!(
        half < rest_height && half > rest_height - 0.45,
        "half way down: {half}"
    );
    let frame = r.tick(10.0);
    let pose = &frame.poses[0].pose;
    assert!(
        (pose.root.y - (rest_height - 0.45)).abs() < 1e-5,
        "seated: {}",
        pose.root.y
    );
    let knee_deg = pose.rotations[knee]
        .angle_between(Quat::IDENTITY)
        .to_degrees();
    let hip_deg = pose.rotations[hip]
        .angle_between(Quat::IDENTITY)
        .to_degrees();
    assert!(
        (knee_deg - 90.0).abs() < 0.5 && (hip_deg - 90.0).abs() < 0.5,
        "{knee_deg} {hip_deg}"
    );
    // a posture (not a shift) goes back to the rest stance — now seated — by its end
    r.perform_bml(
        r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="b"><posture id="up" start="0" ready="1" relax="2" end="3"><stance type="STANDING"/></posture></bml>"#,
    )
    .unwrap();
    let standing = r.tick(11.5);
    assert!(
        (standing.poses[0].pose.root.y - rest_height).abs() < 1e-5,
        "stood up"
    );
    let back = r.tick(13.5);
    assert!(
        (back.poses[0].pose.root.y - (rest_height - 0.45)).abs() < 1e-5,
        "seated again"
    );
}

/// A run recorded by [`record`]: every frame's (time, pose), the sync times
/// ("block:behaviour:sync") and the warnings ("TYPE text").
struct Recording {
    frames: Vec<(f64, bml_realizer::character::body::Pose)>,
    syncs: Vec<(String, f64)>,
    warnings: Vec<String>,
}

/// Runs `bml` at 60 Hz from 0 to `until` and records it.
fn record(bml: &str, until: f64) -> Recording {
    let mut r = still();
    r.perform_bml(bml).unwrap();
    let (mut frames, mut syncs, mut warnings) = (Vec::new(), Vec::new(), Vec::new());
    for i in 0..=(until * FPS).round() as u32 {
        let t = f64::from(i) / FPS;
        let mut frame = r.tick(t);
        for fb in &frame.feedback {
            match fb {
                Feedback::SyncPointProgress(p) => syncs.push((
                    format!("{}:{}:{}", p.block, p.behaviour, p.sync),
                    p.global_time,
                )),
                Feedback::Warning(w) => warnings.push(format!("{} {}", w.kind.as_str(), w.text)),
                _ => {}
            }
        }
        frames.push((t, frame.poses.swap_remove(0).pose));
    }
    Recording {
        frames,
        syncs,
        warnings,
    }
}

impl Recording {
    /// The world position of `joint` (adult skeleton) every frame.
    fn positions(&self, joint: &str) -> Vec<(f64, Vec3)> {
        let skeleton = Skeleton::adult();
        let j = skeleton.joint(joint).unwrap();
        self.frames
            .iter()
            .map(|(t, p)| (*t, p.joint_world(&skeleton, j).0))
            .collect()
    }

    /// The pose of the frame at time `t` (a multiple of 1/60 s).
    fn at(&self, t: f64) -> &bml_realizer::character::body::Pose {
        &self
            .frames
            .iter()
            .find(|f| (f.0 - t).abs() < 1e-9)
            .unwrap()
            .1
    }
}

/// What [`track`] records: per frame (time, joint position), the sync times, the warnings.
struct Track {
    positions: Vec<(f64, Vec3)>,
    syncs: Vec<(String, f64)>,
    warnings: Vec<String>,
}

/// Runs `bml` at 60 Hz and records the world position of `joint` every frame, with the sync
/// times and warnings reported.
fn track(bml: &str, joint: &str, until: f64) -> Track {
    let r = record(bml, until);
    Track {
        positions: r.positions(joint),
        syncs: r.syncs,
        warnings: r.warnings,
    }
}

/// Some warning names every one of `parts`.
fn assert_warned(warnings: &[String], parts: &[&str]) {
    assert!(
        warnings.iter().any(|w| parts.iter().all(|p| w.contains(p))),
        "no warning with {parts:?} in {warnings:?}"
    );
}

const BMLT: &str = r#"xmlns="http://www.bml-initiative.org/bml/bml-1.0" xmlns:bmlt="http://hmi.ewi.utwente.nl/bmlt""#;

#[test]
fn a_procedural_wrist_follows_its_expression_by_ik_and_keeps_its_keys_when_stretched() {
    // lift: keys start 0, stroke 0.5, end 1; preferred 1 s, stretched here to 2 s (max 3 s)
    let Track {
        positions: wrist,
        syncs,
        warnings,
    } = track(
        &format!(
            r#"<bml {BMLT} id="b"><bmlt:procanimation id="p" name="lift" start="1" end="3"/></bml>"#
        ),
        "r_wrist",
        3.5,
    );
    assert!(warnings.is_empty(), "{warnings:?}");
    assert!((at(&syncs, "b:p:stroke") - 2.0).abs() < 1e-9, "{syncs:?}");
    assert!((at(&syncs, "b:p:end") - 3.0).abs() < 1e-9);
    // every frame of the unit until it starts letting go (0.6 s before its end): the wrist where
    // the expression puts it, within a millimetre (position [-0.3, hermite(1.1, 1.35, 0, 0, α),
    // 0.2], α linear in time from 1 s to 3 s)
    for (t, p) in wrist.iter().filter(|(t, _)| (1.0..=2.4).contains(t)) {
        let a = (t - 1.0) / 2.0;
        let y = 1.1 + (1.35 - 1.1) * (3.0 * a * a - 2.0 * a * a * a);
        let goal = Vec3::new(-0.3, y as f32, 0.2);
        assert!((*p - goal).length() < 1e-3, "at {t}: {p} vs {goal}");
    }
    // at the stroke (α = 0.5) halfway up
    let stroke = wrist
        .iter()
        .find(|(t, _)| (*t - 2.0).abs() < 1e-9)
        .unwrap()
        .1;
    assert!((stroke.y - 1.225).abs() < 1e-3);
    // before and after, the arm is at rest (hanging at the side); it lets go by its end
    let rest = wrist[0].1;
    assert!((wrist.last().unwrap().1 - rest).length() < 1e-6);
    let at_end = wrist
        .iter()
        .find(|(t, _)| (*t - 3.0).abs() < 1e-9)
        .unwrap()
        .1;
    assert!(
        (at_end - rest).length() < 1e-3,
        "at its end the arm is back: {at_end}"
    );
}

#[test]
fn a_procedural_unit_stretched_beyond_its_maximum_is_invalid_and_dropped() {
    // 4 s asked, the unit lasts at most 3 s
    let Track {
        positions: wrist,
        syncs,
        warnings,
    } = track(
        &format!(
            r#"<bml {BMLT} id="b"><bmlt:procanimation id="p" name="lift" start="1" end="5"/><gesture id="g" lexeme="BEAT" mode="LEFT_HAND" start="1"/></bml>"#
        ),
        "r_wrist",
        5.5,
    );
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(warnings[0].starts_with("INVALID_TIMING"), "{warnings:?}");
    assert!(
        warnings[0].contains("'p'") && warnings[0].contains("duration"),
        "{warnings:?}"
    );
    assert!(syncs.iter().all(|s| !s.0.starts_with("b:p:")), "{syncs:?}");
    assert!(
        syncs.iter().any(|s| s.0 == "b:g:end"),
        "the rest of the block runs"
    );
    // the right arm never moves (the beat is left-handed)
    let rest = wrist[0].1;
    assert!(wrist.iter().all(|(_, p)| (*p - rest).length() < 1e-6));
}

#[test]
fn a_limb_frame_effector_lifts_the_foot_relative_to_the_hip() {
    let skeleton = Skeleton::adult();
    let hip = skeleton.joint("l_hip").unwrap();
    let ankle = skeleton.joint("l_talocrural").unwrap();
    let mut r = still();
    r.perform_bml(&format!(
        r#"<bml {BMLT} id="b"><bmlt:procanimation id="f" name="foot_lift" start="0.5"/></bml>"#
    ))
    .unwrap();
    // preferred 0.8 s: the stroke (α = 0.5) at 0.9 s
    r.tick(0.0);
    let w = r.tick(0.9).poses[0].pose.world(&skeleton);
    let rel = w.positions[ankle] - w.positions[hip];
    assert!(
        (rel - Vec3::new(0.0, -0.845 + 0.12, 0.1)).length() < 1e-3,
        "{rel}"
    );
}

#[test]
fn a_procedural_parameter_changes_while_the_unit_runs() {
    let skeleton = Skeleton::adult();
    let wrist = skeleton.joint("r_wrist").unwrap();
    let mut r = still();
    r.perform_bml(&format!(
        r#"<bml {BMLT} xmlns:bmla="http://www.asap-project.org/bmla" id="b"><bmlt:procanimation id="p" name="lift" start="0" end="2"><bmlt:parameter name="height" value="1.2"/></bmlt:procanimation><bmla:parametervaluechange id="c" target="b:p" paramId="height" start="0.5" end="0.6"><bmla:trajectory type="instant" targetValue="1.4"/></bmla:parametervaluechange></bml>"#
    ))
    .unwrap();
    let y = |r: &mut Realizer, t: f64| r.tick(t).poses[0].pose.world(&skeleton).positions[wrist].y;
    // at α = 0.65 (blended in fully, not yet letting go) the wrist is on its way to the height
    // changed to, not the one written: hermite(1.1, 1.4, 0, 0, 0.65) = 1.1 + 0.3 × 0.71825
    y(&mut r, 0.0);
    y(&mut r, 0.4);
    let late = y(&mut r, 1.3);
    assert!((late - (1.1 + 0.3 * 0.71825)).abs() < 1e-3, "{late}");
}

#[test]
fn a_procanimation_naming_a_unit_the_library_lacks_is_refused_with_the_reason() {
    let Track { warnings, .. } = track(
        &format!(
            r#"<bml {BMLT} id="b"><bmlt:procanimation id="p" name="moonwalk" start="0"/></bml>"#
        ),
        "r_wrist",
        0.5,
    );
    assert_warned(&warnings, &["no procedural unit 'moonwalk'", "lift"]);
}

#[test]
fn noise_moves_its_joint_smoothly_within_its_amplitude_and_fades_in_and_out() {
    let skull = Skeleton::adult().joint("skullbase").unwrap();
    let run = record(
        &format!(
            r#"<bml {BMLT} id="b"><bmlt:noise id="n" type="perlin" joint="skullbase" start="1" end="6"><bmlt:parameter name="baseamplitudex" value="3"/><bmlt:parameter name="basefreqx" value="0.7"/></bmlt:noise></bml>"#
        ),
        7.0,
    );
    let angles: Vec<(f64, f64)> = run
        .frames
        .iter()
        .map(|(t, p)| {
            (
                *t,
                f64::from(p.rotations[skull].angle_between(Quat::IDENTITY)).to_degrees(),
            )
        })
        .collect();
    // bounded by the amplitudes over both octaves: (3 + 2) · (1 + 0.5) degrees
    assert!(angles.iter().all(|(_, a)| *a <= 7.5), "{angles:?}");
    let peak = angles.iter().map(|a| a.1).fold(0.0, f64::max);
    assert!(peak > 0.3, "it moves ({peak})");
    // still before the start and after the end, and at both ends (the fades)
    for (t, a) in &angles {
        if *t <= 1.0 || *t >= 6.0 {
            assert!(*a < 1e-3, "{a} at {t}");
        }
    }
    // smooth: no jump between frames
    for w in angles.windows(2) {
        assert!((w[1].1 - w[0].1).abs() < 0.5, "{w:?}");
    }
}

#[test]
fn noise_of_an_unknown_type_is_refused_with_the_reason() {
    let Track { warnings, .. } = track(
        &format!(
            r#"<bml {BMLT} id="b"><bmlt:noise id="n" type="white" joint="skullbase" start="0" end="1"/></bml>"#
        ),
        "skullbase",
        0.5,
    );
    assert_warned(&warnings, &["noise type 'white'", "perlin"]);
}

#[test]
fn a_gesture_bound_to_a_procedural_unit_takes_its_timing_and_both_hands_mirror() {
    let run = record(
        r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="b"><gesture id="g" lexeme="HELLO" mode="BOTH_HANDS" start="0.5"/></bml>"#,
        4.0,
    );
    let (left, right) = (run.positions("l_wrist"), run.positions("r_wrist"));
    let mut moved = 0.0f32;
    for ((t, l), (_, r)) in left.iter().zip(&right) {
        assert!((*l - Vec3::new(-r.x, r.y, r.z)).length() < 1e-3, "at {t}");
        moved = moved.max((*r - right[0].1).length());
    }
    // the procedural wave's timing: 3 s preferred, stroke at α 0.5
    assert!(
        (at(&run.syncs, "b:g:end") - 3.5).abs() < 1e-9,
        "{:?}",
        run.syncs
    );
    assert!((at(&run.syncs, "b:g:stroke") - 2.0).abs() < 1e-9);
    assert!(moved > 0.1, "the arms wave ({moved} m)");
}

#[test]
fn two_units_of_one_replacement_group_with_the_same_timing_keep_one_and_warn() {
    let Track {
        warnings, syncs, ..
    } = track(
        &format!(
            r#"<bml {BMLT} id="b"><bmlt:procanimation id="p1" name="lift" start="0" end="2"/><bmlt:procanimation id="p2" name="wave" start="0" end="2"/></bml>"#
        ),
        "r_wrist",
        2.5,
    );
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(
        warnings[0].contains("'p1' and 'p2'") && warnings[0].contains("right_arm"),
        "{warnings:?}"
    );
    assert!(syncs.iter().any(|s| s.0 == "b:p1:end"));
    assert!(syncs.iter().all(|s| !s.0.starts_with("b:p2:")), "{syncs:?}");
}

#[test]
fn a_transition_starts_at_the_current_pose_and_ends_at_the_predicted_one() {
    let skeleton = Skeleton::adult();
    let (shoulder, elbow, wrist) = (
        skeleton.joint("r_shoulder").unwrap(),
        skeleton.joint("r_elbow").unwrap(),
        skeleton.joint("r_wrist").unwrap(),
    );
    // a keyframe bends the arm until 1 s; the transition (1 s to 1.5 s) leads into the
    // procedural akimbo that starts at 1.5 s
    let run = record(
        &format!(
            r#"<bml {BMLT} id="b">
        <bmlt:keyframe id="kf" start="0" end="1"><SkeletonInterpolator rotationEncoding="quaternions" parts="r_shoulder r_elbow" encoding="R">
            0 1 0 0 0 1 0 0 0
            1 0.9239 0 0 0.3827 0.7071 0 0.7071 0
        </SkeletonInterpolator></bmlt:keyframe>
        <bmlt:transition id="tr" class="SlerpTransition" start="kf:end" end="p:start"><bmlt:parameter name="joints" value="r_shoulder r_elbow"/></bmlt:transition>
        <bmlt:procanimation id="p" name="akimbo" start="1.5" end="2.5"/></bml>"#
        ),
        2.6,
    );
    // its first frame is the pose the body had (the frame before)
    let (before, first) = (run.at(59.0 / FPS), run.at(1.0));
    for j in [shoulder, elbow] {
        assert!(first.rotations[j].angle_between(before.rotations[j]) < 1e-4);
    }
    // its last frame is the procedural unit's first pose: the wrist at the unit's target
    let last = run.at(1.5).world(&skeleton);
    assert!(
        (last.positions[wrist] - Vec3::new(-0.24, 1.0, 0.02)).length() < 1e-3,
        "{}",
        last.positions[wrist]
    );
    // no jump anywhere from the keyframe through the transition into the lift: no step larger
    // than the peak of a minimum-jerk move (1.875 × the mean speed) through the transition's
    // whole angle, with 20 % to spare, or 6° where that is less
    for j in [shoulder, elbow] {
        let whole = run.at(1.5).rotations[j].angle_between(run.at(1.0).rotations[j]);
        let bound = (1.875 * whole.to_degrees() / (0.5 * FPS as f32) * 1.2).max(6.0);
        for w in (run.frames.windows(2)).filter(|w| w[0].0 >= 0.5 && w[1].0 <= 2.0) {
            let step = w[1].1.rotations[j]
                .angle_between(w[0].1.rotations[j])
                .to_degrees();
            assert!(
                step < bound,
                "{step}° (bound {bound}°) at {} (joint {j})",
                w[1].0
            );
        }
    }
}

#[test]
fn a_hermite_keyframe_is_accepted_and_an_unknown_interpolation_refused() {
    let kf = |how: &str| {
        format!(
            r#"<bml {BMLT} id="b"><bmlt:keyframe id="kf" start="0" end="1"><bmlt:parameter name="interpolation" value="{how}"/><SkeletonInterpolator rotationEncoding="quaternions" parts="r_elbow" encoding="R">
            0 1 0 0 0
            0.5 0.9239 0 0.3827 0
            1 0.7071 0 0.7071 0
            </SkeletonInterpolator></bmlt:keyframe></bml>"#
        )
    };
    let Track { warnings, .. } = track(&kf("hermite"), "r_wrist", 1.2);
    assert!(warnings.is_empty(), "{warnings:?}");
    let Track { warnings, .. } = track(&kf("cubic"), "r_wrist", 1.2);
    assert_warned(&warnings, &["interpolation", "cubic"]);
}

#[test]
fn a_posture_pose_holds_the_arms_akimbo_with_its_stance_and_lets_go_by_its_end() {
    let run = record(
        r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="b"><posture id="p" start="0" ready="0.5" relax="2" end="2.5"><stance type="STANDING"/><pose part="ARMS" lexeme="AKIMBO"/></posture></bml>"#,
        2.5,
    );
    let (left, right) = (run.positions("l_wrist"), run.positions("r_wrist"));
    let at =
        |series: &[(f64, Vec3)], t: f64| series.iter().find(|p| (p.0 - t).abs() < 1e-9).unwrap().1;
    for t in [0.5, 1.2, 2.0] {
        let (l, r) = (at(&left, t), at(&right, t));
        assert!(
            (r - Vec3::new(-0.24, 1.0, 0.02)).length() < 1e-3,
            "{t}: {r}"
        );
        assert!((l - Vec3::new(0.24, 1.0, 0.02)).length() < 1e-3, "{t}: {l}");
    }
    // back at rest by the end
    let skeleton = Skeleton::adult();
    let wrist = skeleton.joint("r_wrist").unwrap();
    let rest = bml_realizer::character::body::Pose::rest(&skeleton)
        .joint_world(&skeleton, wrist)
        .0;
    assert!((at(&right, 2.5) - rest).length() < 1e-4);
}

#[test]
fn a_posture_with_a_pose_the_bindings_lack_is_refused_naming_the_poses() {
    let Track { warnings, .. } = track(
        r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="b"><posture id="p" start="0"><stance type="SITTING"/><pose part="ARMS" lexeme="JUGGLING"/></posture></bml>"#,
        "r_wrist",
        0.5,
    );
    assert_warned(&warnings, &["no pose JUGGLING for ARMS", "ARMS AKIMBO"]);
}

#[test]
fn a_head_direction_shift_turns_the_face_to_its_target_and_keeps_it_there() {
    let skeleton = Skeleton::adult();
    let skull = skeleton.joint("skullbase").unwrap();
    let eyes: Vec3 = {
        let w = bml_realizer::character::body::Pose::rest(&skeleton).world(&skeleton);
        (w.positions[skeleton.joint("l_eyeball_joint").unwrap()]
            + w.positions[skeleton.joint("r_eyeball_joint").unwrap()])
            / 2.0
    };
    let target = Vec3::new(-0.4, 1.6, 1.5); // the default world's speaker
    let mut r = still();
    r.perform_bml(r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="b"><headDirectionShift id="h" target="speaker" start="0.5" end="1.5"/></bml>"#)
        .unwrap();
    let face = |r: &mut Realizer, t: f64| {
        let w = r.tick(t).poses[0].pose.world(&skeleton);
        (w.orientations[skull] * Vec3::Z).angle_between((target - eyes).normalize())
    };
    let at_start = face(&mut r, 0.5);
    assert!(at_start.to_degrees() > 10.0, "not turned yet");
    let mut last = at_start;
    for i in 1..=60 {
        let a = face(&mut r, 0.5 + f64::from(i) / 60.0);
        assert!(a <= last + 1e-4, "turning steadily toward it");
        last = a;
    }
    assert!(last.to_degrees() < 0.5, "{}", last.to_degrees());
    // kept after the shift
    assert!(face(&mut r, 3.0).to_degrees() < 0.5);
}

#[test]
fn a_murml_keyframed_gesture_turns_its_joints_exactly_at_its_frames() {
    let skeleton = Skeleton::adult();
    let shoulder = skeleton.joint("l_shoulder").unwrap();
    let mut r = still();
    r.perform_bml(include_str!(
        "../fixtures/realizertester/bml-1/murml/murmlbodykeyframe.xml"
    ))
    .unwrap();
    let mut angle = |t: f64| {
        let frame = r.tick(t);
        let q = frame.poses[0].pose.rotations[shoulder];
        let (x, y, z) = q.to_euler(glam::EulerRot::XYZ);
        assert!(y.abs() < 1e-4 && z.abs() < 1e-4);
        (
            f64::from(x).to_degrees(),
            frame.poses[0].clamped.contains(&shoulder),
        )
    };
    // frames at 0, 0.5, 1, 1.5, 2 (0°, 100°, 0°, 100°, 0°) from the start at 2 s. The file's
    // 100° turn the arm backward (x > 0 is extension), which a shoulder does only to 60°: the
    // frame clamps it there and says so; below 60° the frames are exact
    for (t, deg) in [
        (1.0, 0.0),
        (2.0, 0.0),
        (2.25, 50.0),
        (2.5, 100.0),
        (3.0, 0.0),
        (3.5, 100.0),
        (4.0, 0.0),
    ] {
        let (got, clamped) = angle(t);
        assert!(
            (got - f64::min(deg, 60.0)).abs() < 1e-2,
            "{t}: {got} vs {deg}"
        );
        assert_eq!(clamped, deg > 60.0, "{t}: clamped");
    }
}

#[test]
fn every_motion_behaviour_declares_the_joints_it_steers() {
    use bml_realizer::engines::default_registry;
    use bml_realizer::engines::interface::MotionKind;
    use bml_realizer::planning::timing::DefaultTimingModels;
    let skeleton = Skeleton::adult();
    let mut registry = default_registry(DefaultTimingModels::default());
    let block = bml_realizer::language::bml::load(&format!(
        r#"<bml {BMLT} xmlns:m="http://www.techfak.uni-bielefeld.de/ags/soa/murml" id="b">
        <head id="nod" lexeme="NOD"/>
        <headDirectionShift id="hd" target="user"/>
        <gaze id="gz" target="user" influence="SHOULDER"/>
        <pointing id="pt" target="bluebox" mode="LEFT_HAND"/>
        <gesture id="beat" lexeme="BEAT" mode="BOTH_HANDS"/>
        <gesture id="hello" lexeme="HELLO" mode="LEFT_HAND"/>
        <posture id="po"><stance type="SITTING"/><pose part="ARMS" lexeme="AKIMBO"/></posture>
        <bmlt:procanimation id="pa" name="lift"/>
        <bmlt:keyframe id="kf"><SkeletonInterpolator rotationEncoding="quaternions" parts="r_elbow" encoding="R">0 1 0 0 0</SkeletonInterpolator></bmlt:keyframe>
        <bmlt:noise id="n" type="perlin" joint="vl5"/>
        <bmlt:transition id="tr" class="SlerpTransition"><bmlt:parameter name="joints" value="l_elbow"/></bmlt:transition>
        <m:murmlgesture id="mg"><m:murml-description><m:dynamic><m:keyframing><m:phase><m:frame ftime="1"><m:posture>Humanoid (l_shoulder 3 10 0 0)</m:posture></m:frame></m:phase></m:keyframing></m:dynamic></m:murml-description></m:murmlgesture>
        <speech id="s"><text>Not a motion.</text></speech>
        </bml>"#
    ))
    .unwrap()
    .block;
    let mut names = |id: &str| -> Vec<String> {
        let b = block.behaviour(id).unwrap();
        let e = registry.engine_mut(registry.engine_for(b).unwrap());
        let s = (e.as_motion())
            .and_then(|m| m.steers(b, &skeleton))
            .unwrap_or_else(|| panic!("{id} steers nothing"));
        assert_eq!(s.kind, MotionKind::Kinematic);
        s.joints
            .iter()
            .map(|&j| skeleton.joints()[j].name.clone())
            .collect()
    };
    let mut has = |id: &str, joints: &[&str]| {
        let n = names(id);
        for j in joints {
            assert!(n.iter().any(|x| x == j), "{id}: {j} not in {n:?}");
        }
        n
    };
    has("nod", &["vc4", "skullbase"]);
    has("hd", &["vc4", "skullbase"]);
    has("gz", &["vt6", "l_eyeball_joint", "r_eyeball_joint"]);
    let pt = has("pt", &["l_shoulder", "l_elbow", "l_wrist"]);
    assert!(!pt.iter().any(|j| j.starts_with("r_")), "{pt:?}");
    has("beat", &["r_shoulder", "l_shoulder", "r_elbow", "l_elbow"]);
    let hello = has("hello", &["l_wrist", "l_elbow", "l_shoulder"]);
    assert!(
        !hello.iter().any(|j| j.starts_with("r_")),
        "mirrored: {hello:?}"
    );
    has(
        "po",
        &["l_knee", "r_hip", "HumanoidRoot", "l_wrist", "r_elbow"],
    );
    has("pa", &["r_wrist", "r_elbow", "r_shoulder"]);
    assert_eq!(names("kf"), ["r_elbow"]);
    assert_eq!(names("n"), ["vl5"]);
    assert_eq!(names("tr"), ["l_elbow"]);
    assert_eq!(names("mg"), ["l_shoulder"]);
    let s = block.behaviour("s").unwrap();
    let speech = registry.engine_mut(registry.engine_for(s).unwrap());
    assert!(speech.as_motion().is_none(), "speech moves no joints");
}

#[test]
fn the_eyes_saccade_in_an_amplitude_dependent_time_then_the_head_catches_up() {
    use bml_realizer::engines::gaze::{saccade_duration, SACCADE_PEAK_VELOCITY};
    let skeleton = Skeleton::adult();
    let target = Vec3::new(0.6, 1.2, 1.2); // bluebox
    let eyes_rest = {
        let w = bml_realizer::character::body::Pose::rest(&skeleton).world(&skeleton);
        (w.positions[skeleton.joint("l_eyeball_joint").unwrap()]
            + w.positions[skeleton.joint("r_eyeball_joint").unwrap()])
            / 2.0
    };
    let amplitude = f64::from(Vec3::Z.angle_between(target - eyes_rest));
    let d = saccade_duration(amplitude);
    assert!((d - (0.021 + 1.875 / 8.7 * amplitude)).abs() < 1e-12);
    let mut r = still();
    r.perform_bml(&gaze_block(
        "b",
        "bluebox",
        r#"start="0" ready="1.5" relax="3" end="4""#,
    ))
    .unwrap();
    let eye = skeleton.joint("l_eyeball_joint").unwrap();
    let hz = 1000.0;
    let (mut last_sight, mut peak, mut on_target_at) = (None::<Vec3>, 0.0f64, None::<f64>);
    let mut in_head = Vec::new();
    for i in 0..=(1.5 * hz) as u32 {
        let t = f64::from(i) / hz;
        let pose = r.tick(t).poses[0].pose.clone();
        let w = pose.world(&skeleton);
        let sight = w.orientations[eye] * Vec3::Z;
        if let Some(prev) = last_sight {
            peak = peak.max(f64::from(prev.angle_between(sight)) * hz);
        }
        last_sight = Some(sight);
        if on_target_at.is_none() && eye_error(&skeleton, &pose, target) < 0.5 {
            on_target_at = Some(t);
        }
        if on_target_at.is_some() {
            assert!(
                eye_error(&skeleton, &pose, target) < 0.5,
                "stays on target at {t}"
            );
        }
        if t >= d {
            // the saccade is over
            in_head.push(f64::from(pose.rotations[eye].angle_between(Quat::IDENTITY)));
        }
    }
    // the eyes are there after about one saccade (not at ready, 1.5 s), at a bounded speed
    let reached = on_target_at.expect("the eyes reach the target");
    assert!(
        reached <= d + 0.01 && reached >= 0.5 * d,
        "{reached} vs saccade {d}"
    );
    assert!(peak <= SACCADE_PEAK_VELOCITY * 1.02, "peak {peak} rad/s");
    // then the head catches up: the eye-in-head angle only shrinks
    assert!(in_head.windows(2).all(|w| w[1] <= w[0] + 1e-4));
    assert!(in_head.last().unwrap() < &(in_head[0] * 0.8));
}

#[test]
fn saccades_are_affine_in_amplitude_and_never_too_fast() {
    use bml_realizer::engines::gaze::{saccade_duration, SACCADE_PEAK_VELOCITY};
    for deg in [1.0f64, 5.0, 10.0, 20.0, 40.0, 60.0, 90.0] {
        let a = deg.to_radians();
        let d = saccade_duration(a);
        assert!(1.875 * a / d <= SACCADE_PEAK_VELOCITY + 1e-9, "{deg}°");
    }
    // affine: equal steps in amplitude give equal steps in duration
    let (d1, d2, d3) = (
        saccade_duration(0.1),
        saccade_duration(0.2),
        saccade_duration(0.3),
    );
    assert!(((d2 - d1) - (d3 - d2)).abs() < 1e-12);
}

/// The fastest a wrist moves, in m/s, between frames at 60 Hz while `bml` plays for `until` s,
/// and when.
fn fastest_wrist(bml: &str, wrist: &str, until: f64) -> (f64, f64) {
    let skeleton = Skeleton::adult();
    let w = skeleton.joint(wrist).unwrap();
    let mut r = still();
    r.perform_bml(bml).unwrap();
    let (mut last, mut fastest) = (None::<Vec3>, (0.0, 0.0));
    for i in 0..=(until * FPS).ceil() as u32 {
        let t = f64::from(i) / FPS;
        let p = r.tick(t).poses[0].pose.world(&skeleton).positions[w];
        if let Some(q) = last {
            let speed = f64::from(p.distance(q)) * FPS;
            if speed > fastest.0 {
                fastest = (speed, t);
            }
        }
        last = Some(p);
    }
    fastest
}

/// Seen in a stick-figure plot of `fixtures/examples/lift-and-wave.xml`: when the procedural
/// lift ends at 3 s, the right arm snaps back to the rest pose within one frame (29 m/s between
/// two 60 Hz frames; a quick human gesture stays under about 5 m/s). Nothing retracts the arm.
#[test]
fn a_wrist_never_moves_faster_than_a_hand_can() {
    let bml = std::fs::read_to_string("fixtures/examples/lift-and-wave.xml").unwrap();
    for wrist in ["r_wrist", "l_wrist"] {
        let (speed, t) = fastest_wrist(&bml, wrist, 4.0);
        assert!(speed < 5.0, "{wrist} moves at {speed:.1} m/s at {t:.2} s");
    }
}

#[test]
fn a_repeated_nod_peaks_at_each_stroke_also_one_tied_to_a_gesture() {
    // the second nod's stroke (`stroke:1`) pulled to a gesture's stroke at 1.4 s
    let (pitches, syncs) = run(
        concat!(
            r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="b"><head id="n" lexeme="NOD" repetition="3" start="0.2"/>"#,
            r#"<gesture id="g" lexeme="BEAT" stroke="1.4"/><constraint><synchronize><sync ref="n:stroke:1"/><sync ref="g:stroke"/></synchronize></constraint></bml>"#
        ),
        3.0,
    );
    let amplitude = DEFAULT_AMOUNT * NOD_DEGREES;
    let strokes = ["stroke", "stroke:1", "stroke:2"].map(|s| at(&syncs, s));
    assert!((strokes[1] - 1.4).abs() < 1e-3, "{strokes:?}");
    assert!(
        strokes[0] < strokes[1] && strokes[1] < strokes[2],
        "{strokes:?}"
    );
    let pitch = |t: f64| {
        let near = pitches
            .iter()
            .min_by(|a, b| (a.0 - t).abs().total_cmp(&(b.0 - t).abs()));
        near.unwrap().1
    };
    for (k, s) in strokes.iter().enumerate() {
        // each stroke a peak: within 5 % of the amplitude, the frames a tenth of a second
        // either side lower
        assert!(
            (pitch(*s) - amplitude).abs() <= 0.05 * amplitude,
            "stroke {k} at {s}: pitch {}",
            pitch(*s)
        );
        assert!(pitch(s - 0.1) < pitch(*s) - 1.0 && pitch(s + 0.1) < pitch(*s) - 1.0);
        // and the head comes up between two strokes
        if let Some(next) = strokes.get(k + 1) {
            let between = pitch((s + next) / 2.0);
            assert!(
                between < 0.1 * amplitude,
                "between {s} and {next}: {between}"
            );
        }
    }
}

/// With the idle layer on, a standing character's eyes jump now and then (idle saccades);
/// a BML gaze sets them over that and holds its target as steadily as without.
#[test]
fn idle_eyes_look_about_and_a_bml_gaze_still_holds_its_target() {
    let skeleton = Skeleton::adult();
    let mut r = Realizer::new();
    // (a block that moves nothing, so that the character is there)
    r.perform_bml(r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="w"><wait id="w" start="0" end="10"/></bml>"#)
        .unwrap();
    let (mut jumps, mut was) = (0, None::<Vec<(f32, f32)>>);
    for i in 0..=600 {
        let pose = r.tick(f64::from(i) / FPS).poses[0].pose.clone();
        let now = eye_angles(&skeleton, &pose);
        if let Some(w) = &was {
            // (a frame in which the eyes turned by more than half a degree)
            if (now[0].0 - w[0].0).abs().max((now[0].1 - w[0].1).abs()) > 0.5 {
                jumps += 1;
            }
        }
        was = Some(now);
    }
    assert!(
        jumps >= 6,
        "the idle eyes moved in {jumps} frames over 10 s"
    );
    let target = Vec3::new(0.5, 1.3, 1.0);
    let timing = r#"start="0" ready="0.5" relax="4" end="4.5""#;
    let (e, t) = held_gaze_error(&mut Realizer::new(), |_| target, timing, 0.5..4.0, 240);
    assert!(e < 0.5, "eye-line error {e}° at {t} with the idle layer on");
}
