//! `bmlt:controller` through the realizer: the simulated body in the frames, pushes from the
//! host, a fall reported as a warning, parameters changed while the controller runs, and the
//! body handed back to the kinematic engines when it ends.

use bml_realizer::character::body::Skeleton;
use bml_realizer::language::feedback::Feedback;
use bml_realizer::realizer::Realizer;

const NS: &str = r#"xmlns="http://www.bml-initiative.org/bml/bml-1.0" xmlns:bmlt="http://hmi.ewi.utwente.nl/bmlt" xmlns:bmla="http://www.asap-project.org/bmla""#;
const FPS: f64 = 60.0;

/// Where the pelvis (the sacroiliac joint) is in a frame.
fn pelvis(r: &mut Realizer, t: f64) -> (glam::Vec3, Vec<Feedback>) {
    let frame = r.tick(t);
    let skeleton = Skeleton::adult();
    let p = frame.poses[0]
        .pose
        .joint_world(&skeleton, skeleton.joint("sacroiliac").unwrap());
    (p.0, frame.feedback)
}

fn warnings(fb: &[Feedback]) -> Vec<String> {
    fb.iter()
        .filter_map(|f| match f {
            Feedback::Warning(w) => Some(w.text.clone()),
            _ => None,
        })
        .collect()
}

/// Runs `bml` for `seconds` at 60 Hz, calling `at` before each frame: the pelvis' path and
/// every warning.
fn run(
    bml: &str,
    seconds: f64,
    mut at: impl FnMut(&mut Realizer, f64),
) -> (Vec<(f64, glam::Vec3)>, Vec<String>) {
    let mut r = Realizer::new().with_idle(false);
    r.perform_bml(bml).unwrap();
    let mut path = Vec::new();
    let mut warned = Vec::new();
    for k in 0..=(seconds * FPS) as usize {
        let t = k as f64 / FPS;
        at(&mut r, t);
        let (p, fb) = pelvis(&mut r, t);
        assert!(p.is_finite(), "not a number at {t}");
        path.push((t, p));
        warned.extend(warnings(&fb));
    }
    (path, warned)
}

/// Where the pelvis is at time `t` (a frame time) on `path`.
fn at(path: &[(f64, glam::Vec3)], t: f64) -> glam::Vec3 {
    path.iter().find(|(u, _)| (u - t).abs() < 1e-9).unwrap().1
}

fn balance(extra: &str) -> String {
    format!(
        r#"<bml {NS} id="b"><bmlt:controller id="c" class="BalanceController" start="0"/>{extra}</bml>"#
    )
}

/// Standing under the balance controller while the arms gesture: the pelvis stays at its height
/// (0.93 m, within 2 cm after the first second) and over the feet, and nothing is warned.
#[test]
fn the_balance_controller_keeps_the_character_standing_while_it_gestures() {
    let gestures = r#"<gesture id="w" lexeme="WAVE" mode="RIGHT_HAND" start="1"/><gesture id="f" lexeme="FRAME" mode="BOTH_HANDS" start="w:end"/>"#;
    let (path, warned) = run(&balance(gestures), 10.0, |_, _| {});
    assert!(warned.is_empty(), "{warned:?}");
    for (t, p) in path.iter().filter(|(t, _)| *t >= 1.0) {
        assert!((p.y - 0.932).abs() < 0.02, "pelvis at {} m at {t} s", p.y);
        assert!(
            p.x.abs() < 0.1 && p.z.abs() < 0.15,
            "pelvis at {p} at {t} s"
        );
    }
    // the simulated pelvis is not the kinematic one: it moves with the arms' dynamics
    let moved = path
        .iter()
        .map(|(_, p)| p.distance(path[0].1))
        .fold(0.0, f32::max);
    assert!(moved > 0.005, "the pelvis moved only {moved} m");
}

/// A push from the host sways the body and it recovers; a large one throws it over: a warning
/// says it fell, and it lies on the ground.
#[test]
fn pushes_from_the_host_sway_it_or_make_it_fall() {
    let push = |n: f64| {
        move |r: &mut Realizer, t: f64| {
            if (t - 1.0).abs() < 1e-9 {
                r.push("", "sacroiliac", [0.0, 0.0, n]).unwrap();
            }
        }
    };
    let (path, warned) = run(&balance(""), 4.0, push(20.0));
    assert!(warned.is_empty(), "{warned:?}");
    let at = |t: f64| at(&path, t);
    let sway = path
        .iter()
        .map(|(_, p)| (p.z - at(1.0).z).abs())
        .fold(0.0, f32::max);
    assert!(sway > 0.01, "swayed {sway} m");
    assert!(
        (at(3.0) - at(1.0)).length() < 0.02,
        "not back: {} vs {}",
        at(3.0),
        at(1.0)
    );
    let (path, warned) = run(&balance(""), 4.0, push(150.0));
    assert_eq!(warned.len(), 1, "{warned:?}");
    assert!(warned[0].contains("fell"), "{warned:?}");
    assert!(
        path.last().unwrap().1.y < 0.5,
        "still up: {}",
        path.last().unwrap().1
    );
}

#[test]
fn a_push_without_a_simulated_body_says_why() {
    let mut r = Realizer::new();
    let e = r.push("", "sacroiliac", [1.0, 0.0, 0.0]).unwrap_err();
    assert!(e.contains("no character ''"), "{e}");
    r.perform_bml(&format!(
        r#"<bml {NS} id="a"><gesture id="g" lexeme="BEAT"/></bml>"#
    ))
    .unwrap();
    r.tick(0.0);
    let e = r.push("", "sacroiliac", [1.0, 0.0, 0.0]).unwrap_err();
    assert!(e.contains("no body is simulated"), "{e}");
    r.perform_bml(&balance("")).unwrap();
    r.tick(0.1);
    let e = r.push("", "tail", [1.0, 0.0, 0.0]).unwrap_err();
    assert!(e.contains("no body part 'tail'"), "{e}");
    let e = r.push("", "l_hand", [1.0, 0.0, 0.0]).unwrap_err();
    assert!(e.contains("not simulated"), "{e}");
    assert!(
        r.push("", "l_knee", [1.0, 0.0, 0.0]).is_ok(),
        "a skeleton joint names its part"
    );
    assert!(r
        .push("nobody", "sacroiliac", [1.0, 0.0, 0.0])
        .unwrap_err()
        .contains("no character"));
}

/// The host reads how the body stands: while it stands and gestures, the zero-moment point and
/// the centre of mass lie over the feet at every frame and the steps are counted (200 a
/// second); a large push sends the zero-moment point off the feet before the body falls; with
/// no controller there is no reading, and the message says why.
#[test]
fn the_host_reads_the_centre_of_mass_and_the_zero_moment_point() {
    let inside = |polygon: &[[f64; 2]], p: [f64; 3]| {
        let n = polygon.len();
        n >= 3
            && (0..n).all(|i| {
                let (a, b) = (polygon[i], polygon[(i + 1) % n]);
                (b[0] - a[0]) * (p[2] - a[1]) - (b[1] - a[1]) * (p[0] - a[0]) >= 0.0
            })
    };
    let gestures = r#"<gesture id="w" lexeme="WAVE" mode="RIGHT_HAND" start="0.5"/><gesture id="f" lexeme="FRAME" mode="BOTH_HANDS" start="w:end"/>"#;
    let mut readings = Vec::new();
    run(&balance(gestures), 6.0, |r, t| {
        if t > 0.0 {
            readings.push(r.balance("").unwrap());
        }
    });
    for b in &readings {
        let zmp = b.zero_moment_point.expect("standing presses on the ground");
        assert!(inside(&b.support, zmp), "{b:?}");
        assert!(inside(&b.support, b.centre_of_mass), "{b:?}");
    }
    let last = readings.last().unwrap();
    assert_eq!(last.zmp_outside, 0);
    // read before the last frame: 200 steps a second up to the frame before it
    let want = (6.0 - 1.0 / FPS) * 200.0;
    assert!(
        (last.steps as f64 - want).abs() <= 1.0,
        "{} steps",
        last.steps
    );
    let mut fell_after = None;
    run(&balance(""), 3.0, |r, t| {
        if (t - 1.0).abs() < 1e-9 {
            r.push("", "sacroiliac", [0.0, 0.0, 150.0]).unwrap();
        }
        if t > 1.0 && fell_after.is_none() {
            fell_after = Some(r.balance("").unwrap().zmp_outside);
        }
    });
    assert!(
        fell_after.unwrap() > 0,
        "the push never sent the zero-moment point off the feet"
    );
    let mut r = Realizer::new();
    r.perform_bml(&format!(
        r#"<bml {NS} id="a"><gesture id="g" lexeme="BEAT"/></bml>"#
    ))
    .unwrap();
    r.tick(0.0);
    let e = r.balance("").unwrap_err();
    assert!(e.contains("no body is simulated"), "{e}");
    assert!(r.balance("nobody").unwrap_err().contains("no character"));
}

/// `pelvisheight` changed while the controller runs: the body lowers to the new height.
#[test]
fn the_pelvis_height_changes_while_the_controller_runs() {
    let change = r#"<bmla:parametervaluechange id="p" target="b:c" paramId="pelvisheight" start="2" end="2.1"><bmla:trajectory type="instant" targetValue="0.9"/></bmla:parametervaluechange>"#;
    let (path, warned) = run(&balance(change), 5.0, |_, _| {});
    assert!(warned.is_empty(), "{warned:?}");
    let at = |t: f64| at(&path, t);
    // 0.95 − (1 − 0.9) × 0.9 m of leg
    assert!((at(1.9).y - 0.932).abs() < 0.02, "{}", at(1.9));
    assert!((at(5.0).y - 0.86).abs() < 0.02, "{}", at(5.0));
}

/// A controller with an end: the body is simulated until then and back in the kinematic pose
/// 0.3 s later, without a jump on the way.
#[test]
fn when_the_controller_ends_the_body_returns_to_the_kinematic_pose() {
    let bml = format!(
        r#"<bml {NS} id="b"><bmlt:controller id="c" class="Balance" start="0" end="2"/></bml>"#
    );
    let (path, warned) = run(&bml, 3.0, |_, _| {});
    assert!(warned.is_empty(), "{warned:?}");
    let rest = glam::Vec3::new(0.0, 0.95, 0.0);
    let at = |t: f64| at(&path, t);
    assert!(at(1.9).distance(rest) > 0.01, "simulated: {}", at(1.9));
    assert!(at(2.5).distance(rest) < 1e-5, "{}", at(2.5));
    let step = path
        .windows(2)
        .map(|w| w[1].1.distance(w[0].1))
        .fold(0.0, f32::max);
    assert!(step < 0.01, "the pelvis jumped {step} m in a frame");
}

#[test]
fn an_unknown_controller_class_is_refused_with_the_known_ones() {
    let bml = format!(r#"<bml {NS} id="b"><bmlt:controller id="c" class="Juggler"/></bml>"#);
    let (_, warned) = run(&bml, 0.1, |_, _| {});
    assert!(
        warned
            .iter()
            .any(|w| w.contains("'Juggler' is not known") && w.contains("BalanceController")),
        "{warned:?}"
    );
}

/// The largest turn of any joint between two neighbouring frames (radians), and where.
fn largest_turn(frames: &[(f64, bml_realizer::character::body::Pose)]) -> (f32, f64, usize) {
    let mut worst = (0.0f32, 0.0, 0);
    for w in frames.windows(2) {
        for (j, (a, b)) in w[0].1.rotations.iter().zip(&w[1].1.rotations).enumerate() {
            let turn = a.angle_between(*b);
            if turn > worst.0 {
                worst = (turn, w[1].0, j);
            }
        }
    }
    worst
}

/// A rag doll starting while the balance holds the body and the right arm waves: the arms
/// (kinematic until then) become simulated where they are, moving as they were, and no joint
/// jumps. Bound: 0.3 rad in a 60 Hz frame (18 rad/s), above what the wave itself turns a joint
/// (0.13 rad) and far below a jump to another pose.
#[test]
fn switching_the_arms_from_kinematic_to_simulated_is_continuous() {
    let bml = format!(
        r#"<bml {NS} id="b"><bmlt:controller id="c" class="BalanceController" start="0"/><bmlt:controller id="r" class="RagDoll" start="2"/><gesture id="w" lexeme="WAVE" mode="RIGHT_HAND" start="0.5"/></bml>"#
    );
    let mut r = Realizer::new().with_idle(false);
    r.perform_bml(&bml).unwrap();
    let frames: Vec<(f64, bml_realizer::character::body::Pose)> = (0..=(3.0 * FPS) as usize)
        .map(|k| {
            let t = k as f64 / FPS;
            (t, r.tick(t).poses[0].pose.clone())
        })
        .collect();
    let before: Vec<_> = frames.iter().filter(|f| f.0 < 2.0).cloned().collect();
    let around: Vec<_> = frames
        .iter()
        .filter(|f| (1.9..2.3).contains(&f.0))
        .cloned()
        .collect();
    let (kinematic, ..) = largest_turn(&before);
    let (switch, at, joint) = largest_turn(&around);
    eprintln!("largest turn in a frame: {kinematic:.3} rad before the switch, {switch:.3} rad around it ({at:.3} s, joint {joint})");
    assert!(
        switch < 0.3,
        "joint {joint} turned {switch} rad in the frame at {at} s"
    );
    // the arm was raised at the switch and falls from there, not from rest
    let skeleton = Skeleton::adult();
    let wrist = skeleton.joint("r_wrist").unwrap();
    let height = |t: f64| {
        let f = frames.iter().find(|f| (f.0 - t).abs() < 1e-9).unwrap();
        f.1.joint_world(&skeleton, wrist).0.y
    };
    assert!(
        height(2.0) > 1.3,
        "the wrist is at {} m at the switch",
        height(2.0)
    );
    assert!(
        height(2.0 + 1.0 / FPS) > 1.25,
        "it dropped at once: {}",
        height(2.0 + 1.0 / FPS)
    );
}

/// Handed back while it moves: a rag doll falls for 0.4 s, then its controller ends. The
/// pelvis goes on at the speed it had and eases back to the kinematic pose within 0.3 s: its
/// speed across the hand-over (last simulated frame to first released one) is within 35 % of
/// its speed in the frame before (measured: 0.248 → 0.188 m/s; the fall was gaining 0.16 m/s a
/// frame, the ease-back loses it; a release that starts at rest, as the minimum-jerk blend from
/// a frozen pose did, gives 0.02 m/s).
#[test]
fn the_hand_back_to_the_kinematic_pose_keeps_the_speed() {
    let bml = format!(
        r#"<bml {NS} id="b"><bmlt:controller id="c" class="RagDoll" start="0" end="0.4"/></bml>"#
    );
    let (path, warned) = run(&bml, 1.0, |_, _| {});
    assert!(warned.is_empty(), "{warned:?}");
    let speed = |k: usize| (path[k + 1].1 - path[k].1).length() * FPS as f32;
    // frame 24 is at 0.4 s: the first without the controller
    let (before, after) = (speed(22), speed(23));
    eprintln!("pelvis speed {before:.3} m/s before the hand-over, {after:.3} m/s after");
    assert!(before > 0.2, "the rag doll did not fall: {before} m/s");
    assert!(
        (after - before).abs() < 0.35 * before,
        "{before} → {after} m/s"
    );
    let rest = glam::Vec3::new(0.0, 0.95, 0.0);
    assert!(
        path.last().unwrap().1.distance(rest) < 1e-5,
        "not back: {}",
        path.last().unwrap().1
    );
}

/// A rag doll that has fallen to the floor, handed back: the body returns to the kinematic
/// pose without a flick — the pelvis never faster than 1.5 m/s on the way (a 0.3 s hand-back
/// from the floor moved it at 6.5 m/s) — and is standing again within 2.5 s. It floats up, as
/// there is no getting-up motion (docs/physics.md).
#[test]
fn the_hand_back_from_the_floor_is_unhurried() {
    let bml = format!(
        r#"<bml {NS} id="b"><bmlt:controller id="c" class="RagDoll" start="0" end="2.5"/></bml>"#
    );
    let (path, warned) = run(&bml, 5.5, |_, _| {});
    assert!(warned.is_empty(), "{warned:?}");
    assert!(
        at(&path, 2.45).y < 0.5,
        "it did not fall: {}",
        at(&path, 2.45)
    );
    let fastest = (path.windows(2))
        .filter(|w| w[0].0 >= 2.5)
        .map(|w| w[1].1.distance(w[0].1) * FPS as f32)
        .fold(0.0, f32::max);
    eprintln!("fastest pelvis on the way back: {fastest:.2} m/s");
    assert!(fastest < 1.5, "the pelvis flew back at {fastest} m/s");
    let rest = glam::Vec3::new(0.0, 0.95, 0.0);
    assert!(
        at(&path, 5.0).distance(rest) < 1e-5,
        "not standing: {}",
        at(&path, 5.0)
    );
}
