//! Compound controllers through the realizer: `HangingLeftArm` with the balance controller
//! simulates the left arm, which hangs and swings loosely when the body is pushed while the
//! kinematic right arm moves only with the trunk; the arm goes back to the kinematic pose
//! without a jump when its controller ends, and a compound alone says that nothing holds the
//! legs.

use bml_realizer::character::body::{Pose, Skeleton};
use bml_realizer::language::feedback::Feedback;
use bml_realizer::realizer::Realizer;
use glam::Vec3;

const NS: &str = r#"xmlns="http://www.bml-initiative.org/bml/bml-1.0" xmlns:bmlt="http://hmi.ewi.utwente.nl/bmlt""#;
const FPS: f64 = 60.0;
/// When the body is pushed (s): the arm still swings when its controller ends at 4 s.
const PUSH: f64 = 3.6;

/// Realizes `bml` for `seconds` at 60 Hz, pushing the upper body sideways with `push` N s at
/// [`PUSH`]: each frame's time and pose, and the warnings.
fn realize(bml: &str, seconds: f64, push: f64) -> (Vec<(f64, Pose)>, Vec<String>) {
    realize_with(Realizer::new().with_idle(false), bml, seconds, push)
}

/// [`realize`] on realizer `r`.
fn realize_with(
    mut r: Realizer,
    bml: &str,
    seconds: f64,
    push: f64,
) -> (Vec<(f64, Pose)>, Vec<String>) {
    r.perform_bml(bml).unwrap();
    let mut frames = Vec::new();
    let mut warned = Vec::new();
    for k in 0..=(seconds * FPS) as usize {
        let t = k as f64 / FPS;
        if k == (PUSH * FPS) as usize && push != 0.0 {
            r.push("", "upper-body", [push, 0.0, 0.0]).unwrap();
        }
        let frame = r.tick(t);
        warned.extend(frame.feedback.iter().filter_map(|f| match f {
            Feedback::Warning(w) => Some(w.text.clone()),
            _ => None,
        }));
        frames.push((t, frame.poses[0].pose.clone()));
    }
    (frames, warned)
}

/// Where joint `name` is in the trunk's frame (the vl5 joint's).
fn in_trunk(pose: &Pose, skeleton: &Skeleton, name: &str) -> Vec3 {
    let (at, turn) = pose.joint_world(skeleton, skeleton.joint("vl5").unwrap());
    let (p, _) = pose.joint_world(skeleton, skeleton.joint(name).unwrap());
    turn.inverse() * (p - at)
}

fn world(pose: &Pose, skeleton: &Skeleton, name: &str) -> Vec3 {
    pose.joint_world(skeleton, skeleton.joint(name).unwrap()).0
}

/// From 1 s to 4 s the left arm is simulated: it hangs (wrist under elbow under shoulder, near
/// the body); pushed at 3.6 s (25 N s), it swings against the trunk by centimetres while the
/// kinematic right arm keeps its place on the trunk; at 4 s it is handed back, swinging,
/// without a joint turning more than 0.03 rad in a frame (measured 0.012; without the hand-back
/// the arm jumped 0.058 rad to its kinematic pose), and it is back in that pose by 4.5 s.
#[test]
fn a_hanging_arm_swings_loosely_when_the_body_is_pushed() {
    let bml = format!(
        r#"<bml {NS} id="b"><bmlt:controller id="c" class="BalanceController" start="0"/><bmlt:controller id="arm" class="HangingLeftArm" start="1" end="4"/></bml>"#
    );
    let (frames, warned) = realize(&bml, 5.0, 25.0);
    assert!(warned.is_empty(), "{warned:?}");
    let s = Skeleton::adult();
    let at = |t: f64| &frames.iter().find(|f| (f.0 - t).abs() < 1e-9).unwrap().1;
    for (t, pose) in frames.iter().filter(|f| (1.0..4.0).contains(&f.0)) {
        let (shoulder, elbow, wrist) = (
            world(pose, &s, "l_shoulder"),
            world(pose, &s, "l_elbow"),
            world(pose, &s, "l_wrist"),
        );
        assert!(
            wrist.y < elbow.y && elbow.y < shoulder.y,
            "the arm does not hang at {t} s: shoulder {shoulder}, elbow {elbow}, wrist {wrist}"
        );
        assert!(
            wrist.x.hypot(wrist.z) < 0.4,
            "the wrist at {wrist} at {t} s"
        );
    }
    let swing = |name: &str| {
        let before = in_trunk(at(PUSH - 0.05), &s, name);
        (frames.iter().filter(|f| (PUSH..4.0).contains(&f.0)))
            .map(|(_, p)| in_trunk(p, &s, name).distance(before))
            .fold(0.0, f32::max)
    };
    let (left, right) = (swing("l_wrist"), swing("r_wrist"));
    eprintln!("pushed, the left wrist swung {left:.3} m on the trunk, the right {right:.5} m");
    assert!(left > 0.02, "the simulated arm swung only {left} m");
    assert!(
        right < 1e-3,
        "the kinematic arm moved {right} m on the trunk"
    );
    let mut worst: f32 = 0.0;
    for w in frames.windows(2).filter(|w| (3.9..4.4).contains(&w[0].0)) {
        for (a, b) in w[0].1.rotations.iter().zip(&w[1].1.rotations) {
            worst = worst.max(a.angle_between(*b));
        }
    }
    eprintln!("largest turn in a frame at the hand-back: {worst:.3} rad");
    assert!(
        worst < 0.03,
        "a joint turned {worst} rad in a frame at the hand-back"
    );
    let rest = in_trunk(at(0.9), &s, "l_wrist");
    let back = in_trunk(at(4.5), &s, "l_wrist");
    assert!(
        back.distance(rest) < 1e-4,
        "the arm is not back: {back} vs {rest}"
    );
}

#[test]
fn a_compound_alone_says_that_nothing_holds_the_legs() {
    let bml = format!(
        r#"<bml {NS} id="b"><bmlt:controller id="arm" class="HangingRightArm" start="0"/></bml>"#
    );
    let (_, warned) = realize(&bml, 0.5, 0.0);
    assert_eq!(warned.len(), 1, "{warned:?}");
    assert!(
        warned[0].contains("HangingRightArm") && warned[0].contains("BalanceController"),
        "{warned:?}"
    );
}

/// A left-hand BEAT while `HangingLeftArm` simulates that arm: the arm keeps hanging (the beat
/// does not show), and one warning, on the compound, names the left-arm joints it hides; the right
/// arm's WAVE, kinematic, plays and warns nothing.
#[test]
fn kinematic_motion_on_a_simulated_arm_is_hidden_and_said() {
    let bml = format!(
        r#"<bml {NS} id="b"><bmlt:controller id="c" class="BalanceController" start="0"/><bmlt:controller id="arm" class="HangingLeftArm" start="0.5" end="4"/><gesture id="w" lexeme="WAVE" mode="RIGHT_HAND" start="1"/><gesture id="l" lexeme="BEAT" mode="LEFT_HAND" start="2"/></bml>"#
    );
    let mut r = Realizer::new().with_idle(false);
    r.perform_bml(&bml).unwrap();
    let s = Skeleton::adult();
    let mut warned = Vec::new();
    let mut highest: f32 = f32::NEG_INFINITY;
    for k in 0..=(3.5 * FPS) as usize {
        let frame = r.tick(k as f64 / FPS);
        for f in &frame.feedback {
            if let Feedback::Warning(w) = f {
                warned.push((w.id.clone(), w.text.clone()));
            }
        }
        let pose = &frame.poses[0].pose;
        highest = highest.max(world(pose, &s, "l_wrist").y - world(pose, &s, "l_elbow").y);
    }
    assert_eq!(warned.len(), 1, "{warned:?}");
    let (id, text) = &warned[0];
    assert_eq!(id, "b:arm");
    assert!(
        text.contains("l_elbow") || text.contains("l_shoulder"),
        "{text}"
    );
    assert!(!text.contains("r_shoulder"), "{text}");
    assert!(
        highest < -0.2,
        "the left wrist rose to {highest} m from the elbow"
    );
}

/// A compound controller a user defines as data (an `--assets` directory's `compounds.json`):
/// `ReachForward` pulls the right upper arm 70° forward (a target `[z, x, y]` in degrees) and
/// holds the elbow straight. With a balance controller the simulated arm comes up in front of
/// the body; the embedded compounds are still there.
#[test]
fn a_compound_defined_in_a_data_file_moves_the_simulated_arm() {
    use bml_realizer::engines::assets::Assets;
    let dir = std::env::temp_dir().join(format!("bmlr-compounds-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("compounds.json"),
        r#"{"compounds": {"ReachForward": {"members": [
            {"part": "r_upperarm", "kp": 400, "kd": 40, "need": "required", "target": [0, -70, 0]},
            {"part": "r_forearm", "kp": 100, "kd": 10, "need": "required"},
            {"part": "r_hand", "kp": 5, "kd": 0.5, "need": "desired"}]}}}"#,
    )
    .unwrap();
    let assets = Assets::from_dir(&dir).unwrap();
    assert!(assets.compounds.find("HangingLeftArm").is_some());
    let r = Realizer::new()
        .with_idle(false)
        .with_engines(move || bml_realizer::engines::registry_with(Default::default(), &assets));
    let bml = format!(
        r#"<bml {NS} id="b"><bmlt:controller id="bal" class="BalanceController" start="0" end="3"/><bmlt:controller id="reach" class="ReachForward" start="0.5" end="3"/></bml>"#
    );
    let (frames, warned) = realize_with(r, &bml, 3.0, 0.0);
    assert!(warned.is_empty(), "{warned:?}");
    let skeleton = Skeleton::adult();
    let (t, pose) = &frames[(2.5 * FPS) as usize];
    assert!((t - 2.5).abs() < 1e-9);
    let rest = Pose::rest(&skeleton);
    let (shoulder, wrist) = (
        in_trunk(pose, &skeleton, "r_shoulder"),
        in_trunk(pose, &skeleton, "r_wrist"),
    );
    let rest_wrist = in_trunk(&rest, &skeleton, "r_wrist");
    // 70° forward: the wrist ahead of the shoulder by about sin 70° of the arm's length
    // (0.55 m) and raised by about (1 - cos 70°) of it, from hanging straight down
    let arm = in_trunk(&rest, &skeleton, "r_shoulder").distance(rest_wrist);
    assert!(
        wrist.z - shoulder.z > 0.8 * arm * 70f32.to_radians().sin(),
        "the wrist {wrist} is not in front of the shoulder {shoulder}"
    );
    assert!(
        wrist.y > rest_wrist.y + 0.3,
        "the wrist {wrist} is not raised from {rest_wrist}"
    );
    // forward, not out to the side (measured: 0.50 m ahead, 0.21 m under the shoulder, in line)
    assert!(
        (wrist.x - shoulder.x).abs() < 0.05,
        "the wrist {wrist} went sideways"
    );
    std::fs::remove_dir_all(&dir).ok();
}

/// A data file's compound that names no body part, has no required member or takes a built-in
/// class's name is refused, naming the file and what is wrong.
#[test]
fn a_bad_compound_file_is_refused_saying_why() {
    use bml_realizer::engines::assets::Assets;
    let dir = std::env::temp_dir().join(format!("bmlr-bad-compounds-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let member = |part: &str, need: &str| {
        format!(r#"{{"part": "{part}", "kp": 1, "kd": 1, "need": "{need}"}}"#)
    };
    for (compounds, says) in [
        (
            format!(
                r#"{{"Wing": {{"members": [{}]}}}}"#,
                member("l_wing", "required")
            ),
            "l_wing",
        ),
        (
            format!(
                r#"{{"Loose": {{"members": [{}]}}}}"#,
                member("l_hand", "desired")
            ),
            "no required",
        ),
        (
            format!(
                r#"{{"Balance": {{"members": [{}]}}}}"#,
                member("l_hand", "required")
            ),
            "built-in",
        ),
        (
            format!(r#"{{"X": {{"members": [{}]}}}}"#, member("l_hand", "maybe")),
            "need",
        ),
    ] {
        std::fs::write(
            dir.join("compounds.json"),
            format!(r#"{{"compounds": {compounds}}}"#),
        )
        .unwrap();
        let e = Assets::from_dir(&dir).unwrap_err();
        assert!(
            e.contains("compounds.json") && e.contains(says),
            "{says}: {e}"
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}
