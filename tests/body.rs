//! Does the body look like a person? Each test realizes BML on the virtual clock at 60 Hz and
//! looks at the frames through forward kinematics, the way a person looks at the character: where
//! the hands are, whether an arm passes through the torso, how fast a joint turns. (A test that
//! only checks that joints reach their bound rotations passes on a hand behind the head.)

#[path = "common/motion.rs"]
mod motion;

use bml_realizer::character::body::{Pose, Skeleton};
use bml_realizer::engines::interface::CharacterPose;
use bml_realizer::realizer::Realizer;
use glam::Vec3;
use motion::fastest_joint_but_the_eyes;

const FPS: f64 = 60.0;
const NS: &str = r#"xmlns="http://www.bml-initiative.org/bml/bml-1.0""#;

/// The poses of the default character while `bml` plays, at 60 Hz for `seconds`.
fn frames(bml: &[&str], seconds: f64) -> Vec<(f64, Pose)> {
    poses(bml, seconds)
        .into_iter()
        .map(|(t, p)| (t, p.pose))
        .collect()
}

/// The default character's frames while `bml` plays, at 60 Hz for `seconds`.
fn poses(bml: &[&str], seconds: f64) -> Vec<(f64, CharacterPose)> {
    let mut r = Realizer::new();
    for b in bml {
        r.perform_bml(b).unwrap();
    }
    (0..=(seconds * FPS).ceil() as u32)
        .map(|i| {
            let t = f64::from(i) / FPS;
            (t, r.tick(t).poses[0].clone())
        })
        .collect()
}

/// World positions of the named joints.
struct Body {
    skeleton: Skeleton,
}

impl Body {
    fn new() -> Body {
        Body {
            skeleton: Skeleton::adult(),
        }
    }

    fn at(&self, pose: &Pose, joint: &str) -> Vec3 {
        let j = self
            .skeleton
            .joint(joint)
            .unwrap_or_else(|| panic!("no {joint}"));
        pose.world(&self.skeleton).positions[j]
    }

    /// The direction the palm of `side`'s hand faces in the world (at rest toward the thigh).
    fn palm(&self, pose: &Pose, side: char) -> Vec3 {
        let j = self.skeleton.joint(&format!("{side}_wrist")).unwrap();
        let rest_normal = if side == 'l' { -Vec3::X } else { Vec3::X };
        pose.world(&self.skeleton).orientations[j] * rest_normal
    }

    /// Distance from `p` to the torso's axis, a segment from the pelvis to the neck.
    fn distance_to_torso_axis(&self, pose: &Pose, p: Vec3) -> f32 {
        let (a, b) = (self.at(pose, "sacroiliac"), self.at(pose, "vc7"));
        let s = ((p - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
        p.distance(a + s * (b - a))
    }
}

#[test]
fn at_rest_the_arms_hang_at_the_sides() {
    let body = Body::new();
    let rest = Pose::rest(&body.skeleton);
    let hips = body.at(&rest, "l_hip").y.max(body.at(&rest, "r_hip").y);
    for side in ['l', 'r'] {
        let (elbow, wrist) = (
            body.at(&rest, &format!("{side}_elbow")),
            body.at(&rest, &format!("{side}_wrist")),
        );
        assert!(
            wrist.y < elbow.y,
            "{side}: wrist {wrist} not below the elbow {elbow}"
        );
        assert!(
            wrist.y < hips + 0.25,
            "{side}: wrist {wrist} not below the hips + 0.25 m"
        );
        let from_axis = Vec3::new(wrist.x, 0.0, wrist.z).length();
        assert!(
            from_axis < 0.4,
            "{side}: wrist {from_axis} m from the body axis"
        );
        // palms toward the thighs
        let palm = body.palm(&rest, side);
        assert!(
            palm.x * wrist.x < 0.0 && palm.x.abs() > 0.9,
            "{side}: palm {palm}"
        );
        // the fingers hang below the wrist
        let tip = body.at(&rest, &format!("{side}_middle3"));
        assert!(tip.y < wrist.y - 0.1, "{side}: fingertip {tip}");
    }
    // and a character with nothing to do stands that way
    let (_, idle) = frames(&[&format!(r#"<bml {NS} id="nothing"/>"#)], 1.0)
        .pop()
        .unwrap();
    for side in ['l', 'r'] {
        let wrist = body.at(&idle, &format!("{side}_wrist"));
        assert!(wrist.y < hips + 0.25, "{side}: idle wrist {wrist}");
    }
}

#[test]
fn the_hands_have_five_fingers_and_the_head_a_jaw() {
    let s = Skeleton::adult();
    for side in ["l", "r"] {
        for finger in ["thumb", "index", "middle", "ring", "pinky"] {
            for k in 1..=3 {
                let name = format!("{side}_{finger}{k}");
                assert!(s.joint(&name).is_some(), "no {name}");
            }
        }
    }
    assert!(s.joint("temporomandibular").is_some());
}

/// Where a gesture's hand must be at its stroke, in the character's frame (+z forward, +x to
/// its left), for the right hand; the left hand mirrors it.
struct Stroke {
    lexeme: &'static str,
    check: fn(&Body, &Pose, char) -> Result<(), String>,
}

fn front_of_torso(body: &Body, pose: &Pose, side: char) -> Result<(), String> {
    let w = body.at(pose, &format!("{side}_wrist"));
    let ok = w.z > 0.15 && (1.0..1.35).contains(&w.y) && w.x.abs() < 0.35;
    ok.then_some(()).ok_or(format!(
        "wrist {w} not in front of the torso between waist and chest"
    ))
}

fn beside_the_head_palm_forward(body: &Body, pose: &Pose, side: char) -> Result<(), String> {
    let (w, shoulder) = (
        body.at(pose, &format!("{side}_wrist")),
        body.at(pose, &format!("{side}_shoulder")),
    );
    let palm = body.palm(pose, side);
    let outward = if side == 'l' { w.x > 0.15 } else { w.x < -0.15 };
    if w.y <= shoulder.y || !outward {
        return Err(format!(
            "wrist {w} not raised beside the head (shoulder {shoulder})"
        ));
    }
    (palm.z > 0.7)
        .then_some(())
        .ok_or(format!("palm {palm} not forward"))
}

fn open_palm_up_in_front(body: &Body, pose: &Pose, side: char) -> Result<(), String> {
    let w = body.at(pose, &format!("{side}_wrist"));
    let palm = body.palm(pose, side);
    (w.z > 0.25 && palm.y > 0.8).then_some(()).ok_or(format!(
        "wrist {w}, palm {palm}: not an open palm up in front"
    ))
}

fn pointing_forward(body: &Body, pose: &Pose, side: char) -> Result<(), String> {
    let (w, shoulder) = (
        body.at(pose, &format!("{side}_wrist")),
        body.at(pose, &format!("{side}_shoulder")),
    );
    let (index, middle) = (
        body.at(pose, &format!("{side}_index3")),
        body.at(pose, &format!("{side}_middle3")),
    );
    let ok = w.z > 0.4 && (w.y - shoulder.y).abs() < 0.15 && index.z > w.z + 0.08;
    // the other fingers are curled: their tips stay near the palm
    (ok && middle.z < index.z - 0.05)
        .then_some(())
        .ok_or(format!(
            "wrist {w}, index tip {index}, middle tip {middle}: not pointing forward"
        ))
}

fn palm_out_in_front(body: &Body, pose: &Pose, side: char) -> Result<(), String> {
    let w = body.at(pose, &format!("{side}_wrist"));
    let palm = body.palm(pose, side);
    (w.z > 0.3 && palm.z > 0.7)
        .then_some(())
        .ok_or(format!("wrist {w}, palm {palm}: not a palm out in front"))
}

/// +1 for the left side, -1 for the right: x toward the hand's own side.
fn outward(side: char) -> f32 {
    if side == 'l' {
        1.0
    } else {
        -1.0
    }
}

fn shoulders_up_palms_up(body: &Body, pose: &Pose, side: char) -> Result<(), String> {
    let rest = Pose::rest(&body.skeleton);
    let shoulder = format!("{side}_shoulder");
    let lift = body.at(pose, &shoulder).y - body.at(&rest, &shoulder).y;
    let palm = body.palm(pose, side);
    (lift > 0.02 && palm.y > 0.7)
        .then_some(())
        .ok_or(format!("shoulder up {lift:.3} m, palm {palm}: not a shrug"))
}

fn palm_down_in_front(body: &Body, pose: &Pose, side: char) -> Result<(), String> {
    let w = body.at(pose, &format!("{side}_wrist"));
    let palm = body.palm(pose, side);
    (w.z > 0.2 && palm.y < -0.8)
        .then_some(())
        .ok_or(format!("wrist {w}, palm {palm}: not a palm down in front"))
}

fn raised_palm_out(body: &Body, pose: &Pose, side: char) -> Result<(), String> {
    let w = body.at(pose, &format!("{side}_wrist"));
    let palm = body.palm(pose, side);
    (w.z > 0.3 && w.y > 1.25 && palm.z > 0.6)
        .then_some(())
        .ok_or(format!(
            "wrist {w}, palm {palm}: not a raised hand, palm out"
        ))
}

fn index_up(body: &Body, pose: &Pose, side: char) -> Result<(), String> {
    let w = body.at(pose, &format!("{side}_wrist"));
    let index = body.at(pose, &format!("{side}_index3"));
    let middle = body.at(pose, &format!("{side}_middle3"));
    (w.z > 0.2 && index.y > w.y + 0.06 && middle.y < index.y - 0.05)
        .then_some(())
        .ok_or(format!(
            "wrist {w}, index {index}, middle {middle}: not the index up"
        ))
}

fn out_to_the_side_palm_down(body: &Body, pose: &Pose, side: char) -> Result<(), String> {
    let w = body.at(pose, &format!("{side}_wrist"));
    let palm = body.palm(pose, side);
    (w.x * outward(side) > 0.35 && palm.y < -0.5)
        .then_some(())
        .ok_or(format!("wrist {w}, palm {palm}: not swept out to the side"))
}

fn framing(body: &Body, pose: &Pose, side: char) -> Result<(), String> {
    let w = body.at(pose, &format!("{side}_wrist"));
    let palm = body.palm(pose, side);
    // the palm faces the middle of the body
    (w.z > 0.3 && (1.25..1.55).contains(&w.y) && palm.x * outward(side) < -0.7)
        .then_some(())
        .ok_or(format!("wrist {w}, palm {palm}: not a framing hand"))
}

fn hand_to_chin(body: &Body, pose: &Pose, side: char) -> Result<(), String> {
    let chin = body.at(pose, "temporomandibular") + Vec3::new(0.0, -0.07, 0.05);
    let tip = body.at(pose, &format!("{side}_middle3"));
    (tip.distance(chin) < 0.12).then_some(()).ok_or(format!(
        "fingers {tip} {:.2} m from the chin {chin}",
        tip.distance(chin)
    ))
}

/// Presenting the open hand to the character's left (`left`) or right: out beyond the shoulder
/// with the hand of that side, across to the middle with the other.
fn presented(body: &Body, pose: &Pose, side: char, left: bool) -> Result<(), String> {
    let w = body.at(pose, &format!("{side}_wrist"));
    let own = (side == 'l') == left;
    let x = if left { w.x } else { -w.x };
    let ok = w.z > 0.25 && if own { x > 0.35 } else { x > -0.05 };
    ok.then_some(()).ok_or(format!(
        "wrist {w}: not presented to the {}",
        if left { "left" } else { "right" }
    ))
}

const STROKES: &[Stroke] = &[
    Stroke {
        lexeme: "BEAT",
        check: front_of_torso,
    },
    Stroke {
        lexeme: "WAVE",
        check: beside_the_head_palm_forward,
    },
    Stroke {
        lexeme: "HELLO",
        check: beside_the_head_palm_forward,
    },
    Stroke {
        lexeme: "CONDUIT",
        check: open_palm_up_in_front,
    },
    Stroke {
        lexeme: "OFFER",
        check: open_palm_up_in_front,
    },
    Stroke {
        lexeme: "CUP",
        check: open_palm_up_in_front,
    },
    Stroke {
        lexeme: "POINT",
        check: pointing_forward,
    },
    Stroke {
        lexeme: "STOP",
        check: palm_out_in_front,
    },
    Stroke {
        lexeme: "SHRUG",
        check: shoulders_up_palms_up,
    },
    Stroke {
        lexeme: "CALM",
        check: palm_down_in_front,
    },
    Stroke {
        lexeme: "NEGATE",
        check: raised_palm_out,
    },
    Stroke {
        lexeme: "ENUMERATE",
        check: index_up,
    },
    Stroke {
        lexeme: "SWEEP",
        check: out_to_the_side_palm_down,
    },
    Stroke {
        lexeme: "FRAME",
        check: framing,
    },
    Stroke {
        lexeme: "THINK",
        check: hand_to_chin,
    },
    Stroke {
        lexeme: "INDICATE_LEFT",
        check: to_the_left,
    },
    Stroke {
        lexeme: "INDICATE_RIGHT",
        check: to_the_right,
    },
];

fn to_the_left(body: &Body, pose: &Pose, side: char) -> Result<(), String> {
    presented(body, pose, side, true)
}

fn to_the_right(body: &Body, pose: &Pose, side: char) -> Result<(), String> {
    presented(body, pose, side, false)
}

/// When [`gesture`] strokes (s).
const STROKE: f64 = 1.5;

/// A gesture with room for its preparation and retraction: stroke at [`STROKE`], end 2 s later
/// (the longest lexeme, WAVE, takes 1.3 s to its stroke and 1.5 s after it at its own pace).
fn gesture(lexeme: &str, mode: &str) -> String {
    format!(
        r#"<bml {NS} id="b"><gesture id="g" lexeme="{lexeme}" mode="{mode}" start="0" stroke="{STROKE}" end="3.5"/></bml>"#
    )
}

#[test]
fn at_its_stroke_each_lexeme_puts_the_hand_where_it_should_be() {
    let body = Body::new();
    let mut wrong = Vec::new();
    for s in STROKES {
        for (mode, side) in [("RIGHT_HAND", 'r'), ("LEFT_HAND", 'l')] {
            let f = frames(&[&gesture(s.lexeme, mode)], STROKE);
            let (_, pose) = f.last().unwrap();
            if let Err(e) = (s.check)(&body, pose, side) {
                wrong.push(format!("{} {mode}: {e}", s.lexeme));
            }
            // the other hand stays at rest
            let other = if side == 'l' { 'r' } else { 'l' };
            let w = body.at(pose, &format!("{other}_wrist"));
            if w.y > 1.0 {
                wrong.push(format!("{} {mode}: the other wrist moved to {w}", s.lexeme));
            }
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

/// Every example, every RealizerTester file of one block, and every lexeme with each hand.
fn everything() -> Vec<(String, Vec<(f64, Pose)>)> {
    (everything_framed().into_iter())
        .map(|(name, f)| (name, f.into_iter().map(|(t, p)| (t, p.pose)).collect()))
        .collect()
}

fn everything_framed() -> Vec<(String, Vec<(f64, CharacterPose)>)> {
    let mut runs = Vec::new();
    let suite = "fixtures/realizertester/bml-1";
    let dirs = ["fixtures/examples".to_string()]
        .into_iter()
        .chain(["core", "bmlt", "bmlis", "murml", "asap"].map(|d| format!("{suite}/{d}")));
    for dir in dirs {
        let mut paths: Vec<_> = (std::fs::read_dir(&dir).unwrap())
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|e| e == "xml"))
            .collect();
        paths.sort();
        for path in paths {
            let text = std::fs::read_to_string(&path).unwrap();
            // (the suite's files of bad BML, refused as they should be, move nothing)
            if Realizer::new().perform_bml(&text).is_ok() {
                runs.push((path.display().to_string(), poses(&[&text], 8.0)));
            }
        }
    }
    for s in STROKES {
        for mode in ["RIGHT_HAND", "LEFT_HAND", "BOTH_HANDS"] {
            let name = format!("{} {mode}", s.lexeme);
            runs.push((name, poses(&[&gesture(s.lexeme, mode)], 4.0)));
        }
    }
    runs
}

#[test]
fn no_wrist_or_elbow_ever_enters_the_torso() {
    let body = Body::new();
    let mut wrong = Vec::new();
    for (name, frames) in everything() {
        for (t, pose) in &frames {
            for joint in ["l_wrist", "r_wrist", "l_elbow", "r_elbow"] {
                let d = body.distance_to_torso_axis(pose, body.at(pose, joint));
                if d < 0.12 {
                    wrong.push(format!(
                        "{name}: {joint} {d:.3} m from the torso axis at {t:.2} s"
                    ));
                    break;
                }
            }
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

#[test]
fn no_joint_but_the_eyes_turns_faster_than_15_rad_per_s() {
    let skeleton = Skeleton::adult();
    let mut wrong = Vec::new();
    for (name, frames) in everything() {
        let fastest = fastest_joint_but_the_eyes(&skeleton, frames.iter().map(|(t, p)| (*t, p)));
        let (speed, joint, t) = fastest;
        if speed > 15.0 {
            wrong.push(format!("{name}: {joint} at {speed:.1} rad/s at {t:.2} s"));
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

#[test]
fn no_joint_ever_leaves_its_limits() {
    let skeleton = Skeleton::adult();
    let mut wrong = Vec::new();
    let mut counted = 0;
    for (name, frames) in everything_framed() {
        // RealizerTester's MURML keyframes turn l_shoulder 100° about x: backward, past the
        // shoulder's 60° of extension. Rotations given in the BML are the author's; the
        // realizer clamps them and counts the clamp in the frame.
        let authored = name.ends_with("murmlbodykeyframe.xml");
        for (t, p) in &frames {
            if authored {
                counted += p.clamped.len();
            }
            // the engines' own motion stays inside the anatomical limits: nothing needs clamping
            if let Some(&j) = p.clamped.first().filter(|_| !authored) {
                let joint = &skeleton.joints()[j].name;
                wrong.push(format!(
                    "{name}: {joint} clamped into its limits at {t:.2} s"
                ));
                break;
            }
            // and what the frame shows is inside them
            for (j, q) in p.pose.rotations.iter().enumerate() {
                if let Some(limit) = skeleton.limits().of(j) {
                    assert!(limit.admits(*q), "{name}: joint {j} outside at {t:.2} s");
                }
            }
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
    assert!(
        counted > 0,
        "the authored shoulder past its range was not counted"
    );
}

/// The pictures of the lexicon's stroke poses in `docs/lexemes/` (shown in docs/bml-support.md)
/// are what the realizer does now: drawn by `body::sketch` from the frame at the stroke, without
/// the idle layer. `BMLR_BLESS=1 cargo test --test body` redraws them.
#[test]
fn the_lexicon_pictures_in_the_docs_are_current() {
    let skeleton = Skeleton::adult();
    let bless = std::env::var_os("BMLR_BLESS").is_some();
    let mut stale = Vec::new();
    for s in STROKES {
        let mode = if matches!(s.lexeme, "SHRUG" | "FRAME") {
            "BOTH_HANDS"
        } else {
            "RIGHT_HAND"
        };
        let mut r = Realizer::new().with_idle(false);
        r.perform_bml(&gesture(s.lexeme, mode)).unwrap();
        r.tick(0.0);
        let pose = r.tick(STROKE).poses[0].pose.clone();
        let title = format!("{} ({mode}) at its stroke", s.lexeme);
        let svg = bml_realizer::character::body::sketch::svg(&skeleton, &pose, &title);
        let path = format!("docs/lexemes/{}.svg", s.lexeme.to_lowercase());
        if bless {
            std::fs::create_dir_all("docs/lexemes").unwrap();
            std::fs::write(&path, &svg).unwrap();
        } else if std::fs::read_to_string(&path).ok().as_deref() != Some(svg.as_str()) {
            stale.push(path);
        }
    }
    assert!(stale.is_empty(), "redraw with BMLR_BLESS=1: {stale:?}");
}

/// Seen in a plot of lift-and-wave: when the procedural lift eased in from rest, the transition
/// that leads the raised arm into it aimed at the rest pose, so the arm dropped to the thigh
/// between the raise and the lift (the wrist at 0.91 m, its rest height) and rose again. Led by a transition, the
/// arm stays up; and the lift still lets go by its end.
#[test]
fn a_transition_leads_the_raised_arm_into_the_lift_without_dropping_it() {
    let text = std::fs::read_to_string("fixtures/examples/lift-and-wave.xml").unwrap();
    let body = Body::new();
    let f = frames(&[&text], 3.5);
    let wrist = |t: f64| {
        let (_, p) = f.iter().find(|(u, _)| (*u - t).abs() < 1e-9).unwrap();
        body.at(p, "r_wrist").y
    };
    let lowest = (60..=135)
        .map(|i| wrist(f64::from(i) / FPS))
        .fold(f32::INFINITY, f32::min);
    assert!(
        lowest > 1.05,
        "the wrist drops to {lowest} m between the raise and the lift"
    );
    assert!(
        wrist(3.5) < 0.95,
        "the arm is down again after the lift: {}",
        wrist(3.5)
    );
}

/// The fastest a hand moves in conversational gestures (m/s): measured peak hand speeds stay
/// around 1–2.5 m/s (fast beats at the top of that range).
const NATURAL_HAND_SPEED: f32 = 2.5;

/// The peak speed of each wrist in every example and lexeme, in world coordinates.
fn peak_hand_speeds() -> Vec<(String, f32, f64)> {
    let body = Body::new();
    let mut out = Vec::new();
    for (name, frames) in everything() {
        for wrist in ["l_wrist", "r_wrist"] {
            let (mut peak, mut at) = (0.0f32, 0.0);
            for w in frames.windows(2) {
                let d = body.at(&w[1].1, wrist).distance(body.at(&w[0].1, wrist));
                let v = d / (w[1].0 - w[0].0) as f32;
                if v > peak {
                    (peak, at) = (v, w[0].0);
                }
            }
            out.push((format!("{name} {wrist}"), peak, at));
        }
    }
    out
}

/// Every hand, in every example and lexeme, stays at a person's speed. This failed (up to
/// 3.97 m/s, BEAT's preparation in welcome.xml) while a gesture's preparation lasted the default
/// 0.3 s however far the hand had to go; now each span between a lexeme's keys lasts long enough
/// for its distance, and the procedural wave and lift take their time.
#[test]
fn hands_move_no_faster_than_a_person_gestures() {
    let too_fast: Vec<String> = (peak_hand_speeds().into_iter())
        .filter(|(_, v, _)| *v > NATURAL_HAND_SPEED)
        .map(|(name, v, at)| format!("{name}: {v:.2} m/s at {at:.2} s"))
        .collect();
    assert!(
        too_fast.is_empty(),
        "{} too fast:\n{}",
        too_fast.len(),
        too_fast.join("\n")
    );
}
