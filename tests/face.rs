//! The face, measured through the realizer at 60 frames a second: expression envelopes, mixing
//! overlapping expressions without jumps, faceShift's lasting rest expression, action units by
//! side, blendshapes and the jaw, warnings for what the face model lacks, and blinks.

use bml_realizer::character::face::mixer::MAX_RATE;
use bml_realizer::character::face::{Face, FaceModel};
use bml_realizer::language::feedback::Feedback;
use bml_realizer::realizer::Realizer;

const FPS: f64 = 60.0;
const NS: &str = r#"xmlns="http://www.bml-initiative.org/bml/bml-1.0""#;
const BMLA: &str = r#"xmlns:bmla="http://www.asap-project.org/bmla""#;

/// Every frame's face, the sync times (`behaviour:sync`) and the warnings.
type Run = (Vec<(f64, Face)>, Vec<(String, f64)>, Vec<String>);

/// A run of `blocks` sent at 0 (idle layer off unless `idle`).
fn run(blocks: &[&str], until: f64, idle: bool) -> Run {
    let mut r = Realizer::new().with_idle(idle);
    for b in blocks {
        let _ = r.perform_bml(b);
    }
    let (mut faces, mut syncs, mut warnings) = (Vec::new(), Vec::new(), Vec::new());
    for i in 0..=(until * FPS).ceil() as u32 {
        let t = f64::from(i) / FPS;
        let frame = r.tick(t);
        for fb in &frame.feedback {
            match fb {
                Feedback::SyncPointProgress(p) => {
                    syncs.push((format!("{}:{}", p.behaviour, p.sync), p.global_time))
                }
                Feedback::Warning(w) => warnings.push(w.text.clone()),
                _ => {}
            }
        }
        faces.push((t, frame.poses[0].face.clone()));
    }
    (faces, syncs, warnings)
}

fn at(syncs: &[(String, f64)], name: &str) -> f64 {
    syncs
        .iter()
        .find(|s| s.0 == name)
        .unwrap_or_else(|| panic!("{name}: {syncs:?}"))
        .1
}

/// The intensity of `au` on the left (`L`) or right side.
fn au(face: &Face, name: &str) -> f32 {
    let m = FaceModel::default_model();
    let (n, side) = name.split_at(name.len() - 1);
    let side = if side == "L" {
        bml_realizer::language::bml::Side::Left
    } else {
        bml_realizer::language::bml::Side::Right
    };
    face.aus.0[m
        .slots(n.trim_start_matches("AU").parse().unwrap(), side)
        .unwrap()[0]]
}

/// The largest change of any action unit or blendshape between two frames.
fn largest_step(faces: &[(f64, Face)]) -> f32 {
    faces
        .windows(2)
        .map(|w| {
            let aus = w[0]
                .1
                .aus
                .0
                .iter()
                .zip(&w[1].1.aus.0)
                .map(|(a, b)| (a - b).abs());
            let morphs = w[0]
                .1
                .morphs
                .0
                .iter()
                .zip(&w[1].1.morphs.0)
                .map(|(a, b)| (a - b).abs());
            aus.chain(morphs).fold(0.0, f32::max)
        })
        .fold(0.0, f32::max)
}

#[test]
fn raise_brows_reaches_its_amount_at_attack_peak_holds_and_is_gone_at_the_end() {
    let bml = format!(
        r#"<bml {NS} id="f"><faceLexeme id="b" lexeme="RAISE_BROWS" amount="0.7" start="0.5"/></bml>"#
    );
    let (faces, syncs, _) = run(&[&bml], 2.5, false);
    let (start, peak, relax, end) = (
        at(&syncs, "b:start"),
        at(&syncs, "b:attackPeak"),
        at(&syncs, "b:relax"),
        at(&syncs, "b:end"),
    );
    let value = |t: f64, name: &str| {
        let (_, f) = faces
            .iter()
            .min_by(|a, b| (a.0 - t).abs().total_cmp(&(b.0 - t).abs()))
            .unwrap();
        au(f, name)
    };
    for side in ["AU1L", "AU1R", "AU2L", "AU2R"] {
        assert!(
            (value(peak, side) - 0.7).abs() <= 0.01,
            "{side} at attackPeak: {}",
            value(peak, side)
        );
        assert!(
            (value((peak + relax) / 2.0, side) - 0.7).abs() <= 0.01,
            "holds"
        );
        assert!(
            value(end + 1.0 / FPS, side) == 0.0,
            "gone a frame after the end"
        );
        assert!(value(start, side) == 0.0);
    }
    let series: Vec<(f64, f32)> = faces.iter().map(|(t, f)| (*t, au(f, "AU1L"))).collect();
    for w in series.windows(2) {
        let ((t0, a), (t1, b)) = (w[0], w[1]);
        if t1 <= peak {
            assert!(b >= a, "rises during the attack: {t0} {a} → {t1} {b}");
        } else if t0 >= peak && t1 <= relax {
            assert!((b - a).abs() < 1e-6, "holds");
        } else if t0 >= relax {
            assert!(b <= a, "falls during the release");
        }
    }
    // the AUs drive the brows' blendshapes
    let (_, f) = faces
        .iter()
        .find(|(t, _)| (*t - peak).abs() < 0.5 / FPS)
        .unwrap();
    assert!(
        (f.morphs.get("browInnerUp") - 0.7).abs() < 0.01
            && (f.morphs.get("browOuterUpLeft") - 0.7).abs() < 0.01
    );
}

#[test]
fn overlapping_interrupted_and_changed_expressions_never_jump() {
    // RAISE_BROWS, then the inner brow by AU at 0.9 on top, interrupted halfway through its
    // attack, and the first one's amount changed while it holds
    let a = format!(
        r#"<bml {NS} id="a"><faceLexeme id="b" lexeme="RAISE_BROWS" amount="0.5" start="0" end="3"/><faceFacs id="c" au="1" amount="0.9" start="0.4" attackPeak="0.9" end="2.5"/></bml>"#
    );
    let stop = format!(
        r#"<bml {NS} {BMLA} id="s" bmla:onStart="a"><bmla:interrupt id="i" target="a" include="c" start="0.8"/></bml>"#
    );
    let change = format!(
        r#"<bml {NS} {BMLA} id="p"><bmla:parametervaluechange id="v" target="a:b" paramId="amount" start="1.6"><bmla:trajectory type="instant" targetValue="1.0"/></bmla:parametervaluechange></bml>"#
    );
    let (faces, syncs, warnings) = run(&[&a, &stop, &change], 3.5, false);
    assert!(warnings.is_empty(), "{warnings:?}");
    // the interrupt cut the attack short: c relaxed at 0.8
    assert!((at(&syncs, "c:relax") - 0.8).abs() < 0.02, "{syncs:?}");
    let step = largest_step(&faces);
    assert!(
        step <= MAX_RATE / FPS as f32 + 1e-4,
        "a weight changed by {step} in one frame"
    );
    // the larger of the two wins where both drive AU1, and the amount change arrived
    let value = |t: f64| au(&faces[(t * FPS).round() as usize].1, "AU1L");
    assert!(
        value(0.79) > 0.5,
        "the AU1 expression on top of the brows: {}",
        value(0.79)
    );
    assert!(
        (value(2.2) - 1.0).abs() < 0.01,
        "amount 1 after the change: {}",
        value(2.2)
    );
}

#[test]
fn face_shift_stays_after_its_end_and_a_later_one_replaces_it_smoothly() {
    let bml = format!(
        r#"<bml {NS} id="f"><faceShift id="s1" lexeme="RAISE_MOUTH_CORNERS" amount="0.6" start="0" end="1"/><faceShift id="s2" lexeme="LOWER_BROWS" amount="0.8" start="3" end="4"/></bml>"#
    );
    let (faces, _, _) = run(&[&bml], 6.0, false);
    let f = |t: f64| &faces[(t * FPS).round() as usize].1;
    assert!(
        (au(f(2.5), "AU12L") - 0.6).abs() < 0.01,
        "the smile stays after its end"
    );
    assert!(au(f(5.5), "AU12L") < 0.01, "replaced by the second shift");
    assert!(
        (au(f(5.5), "AU4R") - 0.8).abs() < 0.01,
        "the brows stay lowered"
    );
    assert!(
        au(f(3.5), "AU12L") > 0.05 && au(f(3.5), "AU4L") > 0.05,
        "cross-fading"
    );
    assert!(largest_step(&faces) <= MAX_RATE / FPS as f32 + 1e-4);
}

#[test]
fn action_units_by_side_blendshapes_and_the_jaw() {
    let bmlt = r#"xmlns:bmlt="http://hmi.ewi.utwente.nl/bmlt""#;
    let bml = format!(
        r#"<bml {NS} {bmlt} id="f"><faceFacs id="c" au="12" side="LEFT" amount="0.8"/><bmlt:facemorph id="m" targetname="jawOpen" intensity="1"/><face id="l"><lexeme lexeme="RAISE_BROWS" amount="0.4"/></face></bml>"#
    );
    let mut r = Realizer::new().with_idle(false);
    r.perform_bml(&bml).unwrap();
    let skeleton = bml_realizer::character::body::Skeleton::adult();
    let jaw = skeleton.joint("temporomandibular").unwrap();
    let frame = r.tick(0.0);
    let closed = frame.poses[0].pose.rotations[jaw];
    let frame = r.tick(0.6);
    let face = &frame.poses[0].face;
    assert!((au(face, "AU12L") - 0.8).abs() < 0.01 && au(face, "AU12R") == 0.0);
    assert!((face.morphs.get("mouthSmileLeft") - 0.8).abs() < 0.01);
    assert_eq!(face.morphs.get("mouthSmileRight"), 0.0);
    assert!(
        (au(face, "AU2R") - 0.4).abs() < 0.01,
        "the <lexeme> child form"
    );
    assert!((face.morphs.get("jawOpen") - 1.0).abs() < 1e-6);
    // the jaw opened: the chin went down (rotation about +x)
    let open = frame.poses[0].pose.rotations[jaw];
    let angle = closed.angle_between(open).to_degrees();
    assert!(angle > 15.0 && angle <= 30.0, "jaw open by {angle}°");
    assert!((open * glam::Vec3::Z).y < -0.2, "the chin down");
}

#[test]
fn what_the_face_model_lacks_plays_its_timing_with_a_warning() {
    let bmlt = r#"xmlns:bmlt="http://hmi.ewi.utwente.nl/bmlt""#;
    let bml = format!(
        r#"<bml {NS} {bmlt} id="f"><faceLexeme id="b" lexeme="GRIN"/><faceFacs id="c" au="99"/><bmlt:facemorph id="m" targetname="Happy"/></bml>"#
    );
    let (faces, syncs, warnings) = run(&[&bml], 2.0, false);
    assert_eq!(warnings.len(), 3, "{warnings:?}");
    assert!(warnings[0].contains("no lexeme 'GRIN'"));
    assert!(warnings[1].contains("no AU 99"));
    assert!(warnings[2].contains("'Happy' is not one of the 52 ARKit blendshapes"));
    assert!(syncs.iter().any(|s| s.0 == "b:end"), "the timing plays");
    assert!(
        faces.iter().all(|(_, f)| f.aus.0.iter().all(|&w| w == 0.0)),
        "nothing moves"
    );
}

#[test]
fn idle_blinks_come_and_go_with_the_idle_layer_and_gaze_down_lowers_the_lids() {
    let empty = format!(r#"<bml {NS} id="e"/>"#);
    let (faces, _, _) = run(&[&empty], 20.0, true);
    let closed: Vec<f64> = faces
        .windows(2)
        .filter(|w| au(&w[1].1, "AU45L") >= 0.99 && au(&w[0].1, "AU45L") < 0.99)
        .map(|w| w[1].0)
        .collect();
    assert!(
        (3..=8).contains(&closed.len()),
        "blinks in 20 s: {closed:?}"
    );
    let (still, _, _) = run(&[&empty], 20.0, false);
    assert!(
        still.iter().all(|(_, f)| au(f, "AU45L") == 0.0),
        "no blinks without the idle layer"
    );
    // looking down at a point low in front lowers the lids (AU43)
    let down = format!(
        r#"<bml {NS} id="g"><gazeShift id="z" target="floor" influence="EYES" start="0" end="0.5"/></bml>"#
    );
    let mut r = Realizer::new().with_idle(true);
    r.world_mut().set("floor", glam::Vec3::new(0.0, 0.3, 1.0));
    r.perform_bml(&down).unwrap();
    let mut lowered = 0.0f32;
    for i in 0..120 {
        let frame = r.tick(f64::from(i) / FPS);
        lowered = lowered.max(au(&frame.poses[0].face, "AU43L"));
    }
    assert!(lowered > 0.2, "lids lowered by {lowered}");
}

#[test]
fn a_murmlface_moves_its_arkit_morph_targets_frame_by_frame() {
    let bml = format!(
        r#"<bml {NS} id="m"><murmlface xmlns="http://www.techfak.uni-bielefeld.de/ags/soa/murml" id="f" start="0"><murml-description><dynamic><keyframing><phase>
        <frame ftime="0"><posture>Humanoid (jawOpen 1 0) (Rig_Own_Target 1 100)</posture></frame>
        <frame ftime="0.5"><posture>Humanoid (jawOpen 1 80) (browInnerUp 1 50)</posture></frame>
        <frame ftime="1"><posture>Humanoid (jawOpen 1 0)</posture></frame>
        </phase></keyframing></dynamic></murml-description></murmlface></bml>"#
    );
    let (faces, syncs, warnings) = run(&[&bml], 1.5, false);
    assert!(warnings.is_empty(), "{warnings:?}");
    assert!(
        (at(&syncs, "f:end") - 1.0).abs() < 1e-9,
        "the last frame's time is its length"
    );
    let f = |t: f64| &faces[(t * FPS).round() as usize].1;
    assert!((f(0.5).morphs.get("jawOpen") - 0.8).abs() < 0.01);
    assert!(
        (f(0.25).morphs.get("jawOpen") - 0.4).abs() < 0.02,
        "linear between frames"
    );
    assert!((f(0.5).morphs.get("browInnerUp") - 0.5).abs() < 0.01);
    assert!(f(1.2).morphs.get("jawOpen") < 1e-6, "gone after its end");
}

#[test]
fn a_large_fast_gaze_shift_comes_with_a_blink() {
    // the first closed-lid moment after 1 s, with and without a gaze shift to the far left at 1 s
    let first_blink = |bml: &str| {
        let mut r = Realizer::new().with_idle(true);
        r.world_mut()
            .set("far-left", glam::Vec3::new(2.0, 1.6, 0.6));
        r.perform_bml(bml).unwrap();
        (60..240)
            .map(|i| f64::from(i) / FPS)
            .find(|&t| au(&r.tick(t).poses[0].face, "AU45L") >= 0.99)
    };
    let shift = format!(
        r#"<bml {NS} id="g"><gazeShift id="z" target="far-left" influence="EYES" start="1" end="1.3"/></bml>"#
    );
    let with = first_blink(&shift).expect("a blink");
    assert!((1.0..1.4).contains(&with), "blinked at {with}");
    let without = first_blink(&format!(r#"<bml {NS} id="g"/>"#));
    assert!(
        without.is_none_or(|t| t > 1.4),
        "an idle blink would have come at {without:?}"
    );
}
