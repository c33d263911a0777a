//! Does the character walk like a person? Each test realizes BML with `<locomotion>` on the
//! virtual clock and judges the frames through forward kinematics: where the root goes and how
//! fast, whether planted feet stay put, how long the steps are and how often they come, whether
//! the body keeps clear of obstacles, and when the sync points are reported.

#[path = "common/motion.rs"]
mod motion;

use bml_realizer::character::body::{Pose, Skeleton};
use bml_realizer::language::feedback::Feedback;
use bml_realizer::realizer::Realizer;
use bml_realizer::world::World;
use glam::{Vec2, Vec3};
use motion::fastest_joint_but_the_eyes;

const NS: &str = r#"xmlns="http://www.bml-initiative.org/bml/bml-1.0""#;
const BMLT: &str = r#"xmlns:bmlt="http://hmi.ewi.utwente.nl/bmlt""#;

/// What a run produced: every frame's time and pose of the default character, and the feedback.
struct Run {
    dt: f64,
    frames: Vec<(f64, Pose)>,
    feedback: Vec<Feedback>,
}

fn run_in(world: Option<World>, bml: &[&str], seconds: f64, fps: f64) -> Run {
    let mut r = Realizer::new();
    if let Some(w) = world {
        *r.world_mut() = w;
    }
    let mut feedback = Vec::new();
    let mut frames = Vec::new();
    for b in bml {
        let _ = r.perform_bml(b);
    }
    for i in 0..=(seconds * fps).ceil() as u32 {
        let t = f64::from(i) / fps;
        let f = r.tick(t);
        feedback.extend(f.feedback);
        frames.push((t, f.poses[0].pose.clone()));
    }
    Run {
        dt: 1.0 / fps,
        frames,
        feedback,
    }
}

fn run(bml: &[&str], seconds: f64) -> Run {
    run_in(None, bml, seconds, 60.0)
}

fn walk(attrs: &str, then: &str) -> String {
    format!(r#"<bml {NS} {BMLT} id="b1"><locomotion id="w" {attrs}/>{then}</bml>"#)
}

impl Run {
    /// The global time of sync `id` (`b1:w:end`).
    fn sync(&self, id: &str) -> f64 {
        self.feedback
            .iter()
            .find_map(|f| match f {
                Feedback::SyncPointProgress(p)
                    if format!("{}:{}:{}", p.block, p.behaviour, p.sync) == id =>
                {
                    Some(p.global_time)
                }
                _ => None,
            })
            .unwrap_or_else(|| panic!("no {id} in {:#?}", self.feedback))
    }

    fn warnings(&self) -> Vec<(String, String)> {
        (self.feedback.iter())
            .filter_map(|f| match f {
                Feedback::Warning(w) => Some((w.kind.as_str().to_string(), w.text.clone())),
                _ => None,
            })
            .collect()
    }

    fn block_ended(&self) -> bool {
        (self.feedback.iter())
            .any(|f| matches!(f, Feedback::BlockProgress(p) if p.block == "b1" && p.sync == "end"))
    }

    fn root(&self, k: usize) -> Vec2 {
        let r = self.frames[k].1.root;
        Vec2::new(r.x, r.z)
    }

    /// Horizontal root speed between frames k−1 and k.
    fn speed(&self, k: usize) -> f32 {
        if k == 0 {
            return 0.0;
        }
        self.root(k).distance(self.root(k - 1)) / self.dt as f32
    }

    fn frame_at(&self, t: f64) -> usize {
        self.frames
            .partition_point(|f| f.0 < t - 1e-9)
            .min(self.frames.len() - 1)
    }
}

/// The points of each foot that touch the ground: heel and ball (world), by forward kinematics.
fn soles(s: &Skeleton, pose: &Pose) -> [[Vec3; 2]; 2] {
    let w = pose.world(s);
    ["l", "r"].map(|side| {
        let a = s.joint(&format!("{side}_talocrural")).unwrap();
        let ball = w.positions[s.joint(&format!("{side}_metatarsal")).unwrap()];
        let heel = w.positions[a] + w.orientations[a] * Vec3::new(0.0, -0.05, -0.05);
        [heel, ball]
    })
}

/// For each foot, each stretch of frames with a sole point on the ground (within 4 mm): how far
/// the points on the ground moved over it (summed frame to frame), and when it began.
fn stances(run: &Run) -> [Vec<(f64, f32, Vec2)>; 2] {
    let s = Skeleton::adult();
    let mut out: [Vec<(f64, f32, Vec2)>; 2] = [Vec::new(), Vec::new()];
    let mut prev: Option<[[Vec3; 2]; 2]> = None;
    let mut open = [false; 2];
    for (t, pose) in &run.frames {
        let now = soles(&s, pose);
        for k in 0..2 {
            let down = now[k].iter().any(|p| p.y < 0.004);
            if down && !open[k] {
                let at = (now[k][0] + now[k][1]) / 2.0;
                out[k].push((*t, 0.0, Vec2::new(at.x, at.z)));
            }
            if let (true, true, Some(p)) = (down, open[k], prev) {
                let slide: f32 = (0..2)
                    .filter(|&i| now[k][i].y < 0.004 && p[k][i].y < 0.004)
                    .map(|i| Vec2::new(now[k][i].x - p[k][i].x, now[k][i].z - p[k][i].z).length())
                    .fold(0.0, f32::max);
                out[k].last_mut().unwrap().1 += slide;
            }
            open[k] = down;
        }
        prev = Some(now);
    }
    out
}

#[test]
fn a_walk_arrives_stops_and_reports_its_end_when_it_stands() {
    let r = run(&[&walk(r#"target="1,5""#, "")], 9.0);
    let end = r.sync("b1:w:end");
    let k = r.frame_at(end);
    let last = r.frames.len() - 1;
    assert!(
        r.root(last).distance(Vec2::new(1.0, 5.0)) < 0.15,
        "{}",
        r.root(last)
    );
    assert!(r.speed(k) < 0.05, "{}", r.speed(k));
    // the real stop: no foot moves along the ground after `end`, and one did a frame before
    let s = Skeleton::adult();
    let feet_moved = |a: usize, b: usize| {
        let (p, q) = (soles(&s, &r.frames[a].1), soles(&s, &r.frames[b].1));
        let feet = (0..2).flat_map(|f| (0..2).map(move |i| (f, i)));
        let xz = |v: Vec3| Vec2::new(v.x, v.z);
        feet.map(|(f, i)| xz(p[f][i]).distance(xz(q[f][i])))
            .fold(0.0, f32::max)
    };
    assert!(feet_moved(k, last) < 0.003, "{}", feet_moved(k, last));
    // (the root sways with the weight shift while standing, slowly)
    assert!((k..=last).all(|i| r.speed(i) < 0.05));
    // the body slows to its stop, it does not stop dead from the arrival's floor speed
    let dropped = (r.frame_at(end - 1.0)..=k)
        .map(|i| r.speed(i - 1) - r.speed(i))
        .fold(0.0, f32::max);
    assert!(dropped < 0.05, "speed fell {dropped} m/s in one frame");
    assert!(
        feet_moved(k - 2, k) > 1e-4,
        "the end came late: nothing moved before it"
    );
    // sync order and the block's end
    let (s0, rd, rx) = (
        r.sync("b1:w:start"),
        r.sync("b1:w:ready"),
        r.sync("b1:w:relax"),
    );
    assert!(s0 <= rd && rd <= rx && rx < end);
    assert!(r.block_ended());
}

#[test]
fn cruising_speed_is_the_manner_s() {
    for (attrs, speed) in [
        (r#"target="0,8""#, 1.3),
        (r#"target="0,8" manner="STROLL""#, 0.8),
        (r#"target="0,12" manner="RUN""#, 3.0),
        (r#"target="0,8" bmlt:speed="1.0""#, 1.0),
    ] {
        let r = run(&[&walk(attrs, "")], 14.0);
        let (rd, rx) = (r.sync("b1:w:ready"), r.sync("b1:w:relax"));
        let ks = r.frame_at(rd)..r.frame_at(rx);
        let mean = ks.clone().map(|k| r.speed(k)).sum::<f32>() / ks.len() as f32;
        assert!((mean - speed).abs() < 0.1 * speed, "{attrs}: {mean}");
    }
}

#[test]
fn planted_feet_do_not_slide_and_stay_above_the_floor() {
    let r = run(&[&walk(r#"target="2,6""#, "")], 10.0);
    let st = stances(&r);
    for (k, foot) in st.iter().enumerate() {
        assert!(foot.len() >= 4, "{k}: {foot:?}");
        for (t, slide, _) in foot {
            assert!(
                *slide < 0.01,
                "foot {k} slid {slide} m in the stance from {t}"
            );
        }
    }
    let s = Skeleton::adult();
    for (t, p) in &r.frames {
        let w = p.world(&s);
        let low = w
            .positions
            .iter()
            .map(|q| q.y)
            .fold(f32::INFINITY, f32::min);
        assert!(low > -0.01, "at {t} a joint is {low} m under the floor");
    }
}

#[test]
fn steps_are_as_long_and_as_frequent_as_a_person_s() {
    // the walk ratio: cadence √(60 v / 0.0061) steps/min, step length 0.0061 × cadence
    for (attrs, v) in [
        (r#"target="0,12" manner="STROLL""#, 0.8f32),
        (r#"target="0,12" bmlt:speed="1.0""#, 1.0),
        (r#"target="0,14""#, 1.3),
    ] {
        let r = run(&[&walk(attrs, "")], 20.0);
        let (rd, rx) = (r.sync("b1:w:ready"), r.sync("b1:w:relax"));
        // heel strikes of both feet while cruising, in time order
        let mut strikes: Vec<(f64, Vec2)> = stances(&r)
            .into_iter()
            .flatten()
            .filter(|s| s.0 > rd && s.0 < rx)
            .map(|s| (s.0, s.2))
            .collect();
        strikes.sort_by(|a, b| a.0.total_cmp(&b.0));
        assert!(strikes.len() >= 4, "{attrs}: {strikes:?}");
        let n = (strikes.len() - 1) as f32;
        let span = (strikes.last().unwrap().0 - strikes[0].0) as f32;
        let cadence = 60.0 * n / span;
        let step = (strikes.last().unwrap().1.y - strikes[0].1.y) / n;
        let want_c = (60.0 * v / 0.0061).sqrt();
        let want_s = 0.0061 * want_c;
        assert!(
            (cadence - want_c).abs() < 0.15 * want_c,
            "{attrs}: {cadence} vs {want_c}"
        );
        assert!(
            (step - want_s).abs() < 0.15 * want_s,
            "{attrs}: {step} vs {want_s}"
        );
    }
}

#[test]
fn knees_bend_in_swing_and_no_joint_turns_too_fast() {
    let r = run(&[&walk(r#"target="0,6""#, "")], 8.0);
    let s = Skeleton::adult();
    let knee = s.joint("l_knee").unwrap();
    let most = (r.frames.iter())
        .map(|(_, p)| p.rotations[knee].angle_between(glam::Quat::IDENTITY))
        .fold(0.0, f32::max);
    assert!(most > 0.7, "the knee bends at most {most} rad");
    let fastest = fastest_joint_but_the_eyes(&s, r.frames.iter().map(|(t, p)| (*t, p)));
    let (rate, joint, t) = fastest;
    assert!(rate < 15.0, "{joint} turns at {rate} rad/s at {t}");
}

#[test]
fn the_same_walk_at_20_and_90_frames_a_second_ends_alike() {
    let mut world = World::default();
    world.set("door", Vec3::new(-2.0, 1.0, 5.0));
    let bml = walk(r#"target="door""#, "");
    let a = run_in(Some(world.clone()), &[&bml], 10.0, 20.0);
    let b = run_in(Some(world), &[&bml], 10.0, 90.0);
    let (ea, eb) = (a.sync("b1:w:end"), b.sync("b1:w:end"));
    assert!((ea - eb).abs() < 1e-9, "{ea} {eb}");
    let (pa, pb) = (a.root(a.frames.len() - 1), b.root(b.frames.len() - 1));
    assert!(pa.distance(pb) < 1e-5, "{pa} {pb}");
}

#[test]
fn a_walk_started_between_frames_begins_when_it_is_due_whatever_the_frames() {
    // the second block waits for the first, which ends between frames — at a planned time,
    // or when the first walk really arrives: the second walk begins then, not at the next
    // frame, so it ends at the same time at any frame rate
    let mut world = World::default();
    world.set("door", Vec3::new(-2.0, 1.0, 5.0));
    world.set("corner", Vec3::new(1.0, 1.0, 2.0));
    let nod =
        format!(r#"<bml {NS} id="b0"><head id="h" lexeme="NOD" start="0" end="1.013"/></bml>"#);
    let walk = format!(r#"<bml {NS} id="b0"><locomotion id="w" target="corner"/></bml>"#);
    let then = format!(
        r#"<bml {NS} id="b1" composition="APPEND"><locomotion id="w" target="door"/></bml>"#
    );
    for (first, end) in [(nod, "b0:h:end"), (walk, "b0:w:end")] {
        let syncs: Vec<(f64, f64, f64)> = [7.0, 20.0, 60.0, 90.0]
            .iter()
            .map(|&fps| {
                let run = run_in(Some(world.clone()), &[&first, &then], 14.0, fps);
                (run.sync(end), run.sync("b1:w:start"), run.sync("b1:w:end"))
            })
            .collect();
        let same = |a: f64, b: f64| (a - b).abs() < 1e-9;
        assert!(
            syncs
                .iter()
                .all(|s| same(s.0, s.1) && same(s.2, syncs[0].2)),
            "(first ends, second starts, second ends): {syncs:?}"
        );
    }
}

fn obstacle_world(json: &str) -> World {
    World::from_json(json).expect("a world").0
}

#[test]
fn the_body_keeps_its_radius_from_obstacles_and_leaves_a_u_shaped_trap() {
    let world = obstacle_world(
        r#"{"obstacles": [{"segment": [-1.5, 2, 1.5, 2]}, {"segment": [-1.5, 2, -1.5, -0.5]},
            {"segment": [1.5, 2, 1.5, -0.5]}, {"circle": [0.5, 4, 0.4]}, {"box": [-3, 5.5, -1, 6]}]}"#,
    );
    let r = run_in(
        Some(world.clone()),
        &[&walk(r#"target="0,7""#, "")],
        20.0,
        60.0,
    );
    assert!(r.root(r.frames.len() - 1).distance(Vec2::new(0.0, 7.0)) < 0.15);
    for (k, (t, _)) in r.frames.iter().enumerate() {
        let d = world.obstacles().clearance(r.root(k), 1.0);
        assert!(
            d >= 0.25 - 1e-3,
            "at {t} the root is {d} m from an obstacle"
        );
    }
}

#[test]
fn speech_tied_to_the_walk_s_end_starts_when_it_really_arrives() {
    let mut world = World::default();
    // a target that walks away while the character comes: the walk takes longer than planned
    world
        .set_path(
            "walker",
            vec![
                (0.0, Vec3::new(0.0, 1.0, 3.0)),
                (3.0, Vec3::new(0.0, 1.0, 6.0)),
            ],
        )
        .unwrap();
    let speech = r#"<speech id="s" start="w:end"><text>Here I am.</text></speech>"#;
    let r = run_in(
        Some(world),
        &[&walk(r#"target="walker""#, speech)],
        14.0,
        60.0,
    );
    let (end, said) = (r.sync("b1:w:end"), r.sync("b1:s:start"));
    assert_eq!(end, said);
    // it arrived at the target's end point, and stood still when it spoke
    let k = r.frame_at(said);
    assert!(
        r.root(k).distance(Vec2::new(0.0, 6.0)) < 0.15,
        "{}",
        r.root(k)
    );
    assert!(r.speed(k) < 0.05);
    // the first plan had it arrive earlier: the end was revised
    let planned = r.feedback.iter().find_map(|f| match f {
        Feedback::Prediction(p) => p
            .behaviours
            .iter()
            .find(|b| b.behaviour == "w")
            .map(|b| b.syncs.last().unwrap().1),
        _ => None,
    });
    assert!(planned.unwrap() < end - 0.5, "{planned:?} {end}");
}

#[test]
fn a_target_crossing_ahead_is_pursued_where_it_will_be_and_caught() {
    let mut world = World::default();
    // a point crossing 6 m ahead, left to right at 1 m/s, then resting at x = 4
    world
        .set_path(
            "cat",
            vec![
                (0.0, Vec3::new(-4.0, 0.0, 6.0)),
                (8.0, Vec3::new(4.0, 0.0, 6.0)),
            ],
        )
        .unwrap();
    let r = run_in(Some(world), &[&walk(r#"target="cat""#, "")], 14.0, 30.0);
    // it meets the line ahead of the target (a follower aiming at where the target is comes
    // from behind it: about 1.1 m behind here)
    let k = (0..r.frames.len()).find(|&k| r.root(k).y > 5.5).unwrap();
    let target_x = -4.0 + r.frames[k].0 as f32;
    assert!(
        r.root(k).x > target_x,
        "{} at {}: target at {target_x}",
        r.root(k),
        r.frames[k].0
    );
    // and it stands where the target rests, with one end reported
    let end = r.sync("b1:w:end");
    let k = r.frame_at(end);
    assert!(
        r.root(k).distance(Vec2::new(4.0, 6.0)) < 0.15,
        "{}",
        r.root(k)
    );
    // relax is reported once, not re-planned every frame
    let predictions = (r.feedback.iter())
        .filter(|f| matches!(f, Feedback::Prediction(_)))
        .count();
    assert!(predictions < 30, "{predictions} predictions");
}

#[test]
fn an_interrupted_walk_stands_within_two_steps() {
    let interrupt = format!(
        r#"<bml {NS} xmlns:bmla="http://www.asap-project.org/bmla" id="b2"><bmla:interrupt id="i" target="b1" start="2"/></bml>"#
    );
    let r = run(&[&walk(r#"target="0,10""#, ""), &interrupt], 8.0);
    let k2 = r.frame_at(2.0);
    let end = r.sync("b1:w:end");
    let ke = r.frame_at(end);
    assert!(end - 2.0 < 2.0, "{end}");
    assert!(
        r.root(ke).distance(r.root(k2)) < 1.5,
        "{} {}",
        r.root(k2),
        r.root(ke)
    );
    assert!(r.speed(ke) < 0.05);
    let s = Skeleton::adult();
    let last = r.frames.len() - 1;
    // standing on both feet, not frozen mid-stride
    for foot in soles(&s, &r.frames[last].1) {
        assert!(foot.iter().all(|p| p.y < 0.004), "{foot:?}");
    }
    assert!(r.block_ended());
}

#[test]
fn bad_targets_and_speeds_are_warned_about_and_the_block_ends() {
    let r = run(&[&walk(r#"target="nowhere""#, "")], 2.0);
    let w = r.warnings();
    assert!(
        w.iter()
            .any(|(k, t)| k == "NO_SUCH_TARGET" && t.contains("nowhere") && t.contains("user")),
        "{w:?}"
    );
    assert!(r.block_ended());
    for bad in [r#"target="NaN,1""#, r#"target="1e30,1""#] {
        let r = run(&[&walk(bad, "")], 2.0);
        assert!(
            r.warnings().iter().any(|(k, _)| k == "NO_SUCH_TARGET"),
            "{bad}"
        );
        assert!(r.block_ended());
    }
    for speed in ["0", "-1", "1e9", "fast"] {
        let r = run(
            &[&walk(&format!(r#"target="0,2" bmlt:speed="{speed}""#), "")],
            8.0,
        );
        let w = r.warnings();
        assert!(
            w.iter().any(|(_, t)| t.contains("bmlt:speed")),
            "{speed}: {w:?}"
        );
        assert!(r.block_ended(), "{speed}");
    }
    // a goal inside an obstacle, and one walled in
    let world = obstacle_world(
        r#"{"obstacles": [{"circle": [0, 3, 1]}, {"segment": [4, 4, 6, 4]}, {"segment": [6, 4, 6, 6]},
            {"segment": [6, 6, 4, 6]}, {"segment": [4, 6, 4, 4]}]}"#,
    );
    for goal in ["0,3", "5,5"] {
        let r = run_in(
            Some(world.clone()),
            &[&walk(&format!(r#"target="{goal}""#), "")],
            3.0,
            60.0,
        );
        assert!(
            r.warnings().iter().any(|(k, _)| k == "EXECUTION_FAILURE"),
            "{goal}"
        );
        assert!(r.block_ended(), "{goal}");
    }
}

#[test]
fn a_thousand_obstacles_and_a_long_path_do_not_stall() {
    let obstacles: Vec<String> = (0..1000)
        .map(|i| {
            format!(
                r#"{{"circle": [{}, {}, 0.2]}}"#,
                3.0 + (i % 40) as f32 * 1.5,
                3.0 + (i / 40) as f32 * 1.5
            )
        })
        .collect();
    let keys: Vec<String> = (0..100_000)
        .map(|i| format!("[{}, [{}, 1, -3]]", i as f64 * 0.01, (i % 7) as f64))
        .collect();
    let json = format!(
        r#"{{"obstacles": [{}], "paths": {{"far": {{"keys": [{}]}}}}}}"#,
        obstacles.join(","),
        keys.join(",")
    );
    let world = obstacle_world(&json);
    // into the field of posts, to a gap between four of them
    let r = run_in(
        Some(world.clone()),
        &[&walk(r#"target="29.25,29.25""#, "")],
        60.0,
        30.0,
    );
    assert!(r.warnings().is_empty(), "{:?}", r.warnings());
    let last = r.frames.len() - 1;
    assert!(
        r.root(last).distance(Vec2::new(29.25, 29.25)) < 0.15,
        "{}",
        r.root(last)
    );
    for k in 0..r.frames.len() {
        assert!(world.obstacles().clearance(r.root(k), 1.0) >= 0.25 - 1e-3);
    }
    assert!(r.block_ended());
    // after a point that jumps 6 m every 10 ms along a 100 000-key path: the walk ends in time
    let r = run_in(Some(world), &[&walk(r#"target="far""#, "")], 15.0, 30.0);
    assert!(r.sync("b1:w:end") < 15.0);
    assert!(r.block_ended());
}

/// Distance from `p` to the torso's axis, a segment from the pelvis to the neck base.
fn from_torso_axis(s: &Skeleton, pose: &Pose, p: Vec3) -> f32 {
    let w = pose.world(s);
    let (a, b) = (
        w.positions[s.joint("sacroiliac").unwrap()],
        w.positions[s.joint("vc7").unwrap()],
    );
    let t = ((p - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
    p.distance(a + t * (b - a))
}

#[test]
fn gestures_play_over_the_gait_and_keep_the_hands_out_of_the_torso() {
    let gestures = r#"<gesture id="g1" lexeme="BEAT" start="1"/><gesture id="g2" lexeme="WAVE" mode="LEFT_HAND" start="2.5"/><gesture id="g3" lexeme="SHRUG" start="4.5"/>"#;
    let r = run(&[&walk(r#"target="0,8""#, gestures)], 9.0);
    let s = Skeleton::adult();
    let (g1, w) = (r.sync("b1:g1:stroke"), r.frame_at(r.sync("b1:g1:stroke")));
    // the beat's stroke happens while walking, with the gesture's arm in front of the body
    assert!(r.speed(w) > 1.0, "walking at {g1}");
    for (t, pose) in &r.frames {
        for joint in ["l_wrist", "r_wrist", "l_elbow", "r_elbow"] {
            let at = pose.world(&s).positions[s.joint(joint).unwrap()];
            let d = from_torso_axis(&s, pose, at);
            assert!(d > 0.12, "{joint} {d} m from the torso axis at {t}");
        }
    }
    // the wave is up beside the head while the legs walk
    let k = r.frame_at(r.sync("b1:g2:stroke"));
    let pw = r.frames[k].1.world(&s);
    let (wrist, head) = (
        pw.positions[s.joint("l_wrist").unwrap()],
        pw.positions[s.joint("skullbase").unwrap()],
    );
    assert!(wrist.y > head.y - 0.25, "{wrist} {head}");
    assert!(r.speed(k) > 1.0);
}

#[test]
fn standing_still_for_half_a_minute_the_feet_stay_put() {
    let wait = format!(r#"<bml {NS} id="b1"><wait id="w" max-wait="0.5"/></bml>"#);
    for bml in [wait, walk(r#"target="1,1""#, "")] {
        let r = run(&[&bml], 36.0);
        let s = Skeleton::adult();
        let from = r.frame_at(6.0);
        let start = soles(&s, &r.frames[from].1);
        for (t, pose) in &r.frames[from..] {
            let now = soles(&s, pose);
            for k in 0..2 {
                for i in 0..2 {
                    let d = now[k][i].distance(start[k][i]);
                    assert!(d < 0.003, "{bml:?}: a foot moved {d} m by {t}");
                }
            }
        }
    }
}

#[test]
fn a_target_behind_is_turned_to_on_the_spot_then_walked_to() {
    let r = run(&[&walk(r#"target="0,-3""#, "")], 9.0);
    // facing +z at first: it turns round before it walks, without stepping backwards
    let s = Skeleton::adult();
    let facing = |k: usize| {
        let q = r.frames[k].1.rotations[0];
        let f = q * Vec3::Z;
        f.x.atan2(f.z)
    };
    let k = r.frame_at(0.5);
    assert!(
        r.root(k).length() < 0.1,
        "it set off before turning: {}",
        r.root(k)
    );
    assert!(
        facing(k).abs() > 0.45,
        "half a second in, it faces {}",
        facing(k)
    );
    let last = r.frames.len() - 1;
    assert!(r.root(last).distance(Vec2::new(0.0, -3.0)) < 0.15);
    assert!(facing(last).abs() > 2.8, "{}", facing(last));
    for (k, foot) in stances(&r).iter().enumerate() {
        for (t, slide, _) in foot {
            assert!(*slide < 0.01, "foot {k} slid {slide} m from {t}");
        }
    }
    let _ = s;
}

#[test]
fn a_walk_to_another_character_stops_at_social_distance_facing_them() {
    let world =
        obstacle_world(r#"{"characters": {"Bob": {"position": [1, 0, 5], "facing": 180}}}"#);
    let r = run_in(Some(world), &[&walk(r#"target="Bob""#, "")], 10.0, 60.0);
    let last = r.frames.len() - 1;
    let d = r.root(last).distance(Vec2::new(1.0, 5.0));
    assert!((d - 1.2).abs() < 0.15, "{d}");
    let f = r.frames[last].1.rotations[0] * Vec3::Z;
    let to_bob = (Vec2::new(1.0, 5.0) - r.root(last)).normalize();
    assert!(Vec2::new(f.x, f.z).normalize().dot(to_bob) > 0.97, "{f}");
}

#[test]
fn a_walk_to_a_place_someone_stands_on_stops_beside_them_and_says_so() {
    // Bob stands where the walk is sent; before, the walker circled him for 20 s and gave up
    // "has not arrived"
    let world =
        obstacle_world(r#"{"characters": {"Bob": {"position": [0, 0, 5], "facing": 180}}}"#);
    let r = run_in(Some(world), &[&walk(r#"target="0,5""#, "")], 14.0, 60.0);
    assert!(r.block_ended(), "the walk never ended");
    // (within 2 m of the place it waits 2 s for him to go)
    let end = r.sync("b1:w:end");
    assert!(end < 10.0, "it ended at {end} s");
    let bob = Vec2::new(0.0, 5.0);
    let last = r.frames.len() - 1;
    // beside him, just outside his personal space (the bodies, 0.25 m
    // each, widened by half as the avoidance widens them: 0.75 m, and 5 cm)
    let d = r.root(last).distance(bob);
    assert!((d - 0.8).abs() < 0.1, "it stopped {d} m from him");
    let closest = (0..=last)
        .map(|k| r.root(k).distance(bob))
        .fold(f32::MAX, f32::min);
    assert!(closest > 0.5, "it came within {closest} m of him");
    let warnings = r.warnings();
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(
        warnings[0]
            .1
            .contains("'Bob' stands on the walk's goal '0,5'; it stops beside them"),
        "{warnings:?}"
    );
}

mod routes {
    use bml_realizer::world::space::path::{self, PathError};
    use bml_realizer::world::space::{Obstacle, Obstacles, Shape};
    use glam::Vec2;
    use proptest::prelude::*;

    fn shape() -> impl Strategy<Value = Shape> {
        let p = || (-5.0f32..5.0, -5.0f32..5.0);
        prop_oneof![
            (p(), 0.1f32..1.0).prop_map(|((x, z), r)| Shape::Circle {
                centre: Vec2::new(x, z),
                radius: r
            }),
            (p(), 0.1f32..2.0, 0.1f32..2.0).prop_map(|((x, z), w, d)| Shape::Box {
                min: Vec2::new(x, z),
                max: Vec2::new(x + w, z + d)
            }),
            (p(), p()).prop_map(|((x0, z0), (x1, z1))| Shape::Segment {
                a: Vec2::new(x0, z0),
                b: Vec2::new(x1, z1)
            }),
        ]
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]
        /// A route starts where asked, ends at the goal and keeps the clearance all along; no
        /// route means the goal is too near an obstacle or walled in (then no straight line
        /// reaches it either).
        #[test]
        fn routes_keep_their_clearance(
            shapes in proptest::collection::vec(shape(), 0..12),
            goal in (-6.0f32..6.0, -6.0f32..6.0),
        ) {
            let o = Obstacles::new(shapes.into_iter().map(|shape| Obstacle { shape, height: 2.0 }).collect());
            let (start, goal, c) = (Vec2::new(0.0, -6.5), Vec2::new(goal.0, goal.1), 0.33);
            prop_assume!(o.clearance(start, 1.0) > c);
            match path::plan(&o, start, goal, c) {
                Ok(route) => {
                    prop_assert_eq!(route[0], start);
                    prop_assert_eq!(*route.last().unwrap(), goal);
                    for w in route.windows(2) {
                        prop_assert!(o.segment_clear(w[0], w[1], c - 1e-3), "{:?}", w);
                    }
                }
                Err(PathError::GoalBlocked { .. }) => prop_assert!(o.clearance(goal, 1.0) < c),
                Err(PathError::Enclosed { .. }) => {
                    prop_assert!(!o.segment_clear(start, goal, c));
                }
                Err(e) => prop_assert!(false, "{e}"),
            }
        }
    }
}

#[test]
fn running_has_a_flight_phase_and_speed_never_jumps() {
    let s = Skeleton::adult();
    let r = run(&[&walk(r#"target="0,15" manner="RUN""#, "")], 10.0);
    let (rd, rx) = (
        r.frame_at(r.sync("b1:w:ready")),
        r.frame_at(r.sync("b1:w:relax")),
    );
    let flying = (rd..rx)
        .filter(|&k| {
            soles(&s, &r.frames[k].1)
                .iter()
                .flatten()
                .all(|p| p.y > 0.01)
        })
        .count();
    assert!(
        flying * 10 > rx - rd,
        "both feet off the ground in {flying} of {} frames",
        rx - rd
    );
    // walking and running: the speed changes by less than 0.2 m/s from one frame to the next
    for r in [r, run(&[&walk(r#"target="3,4""#, "")], 8.0)] {
        for k in 2..r.frames.len() {
            let dv = (r.speed(k) - r.speed(k - 1)).abs();
            assert!(
                dv < 0.2,
                "the speed jumped by {dv} m/s at {}",
                r.frames[k].0
            );
        }
    }
}

#[test]
fn each_character_s_steering_combiner_comes_from_the_world_file() {
    use bml_realizer::world::locomotion::steering::Combine;
    let json = r#"{"characters": {"A": {"position": [0, 0, 0], "steering": "weighted"},
        "B": {"position": [3, 0, 0], "steering": "dithering"}, "C": {"position": [6, 0, 0]}},
        "obstacles": [{"box": [-0.5, 2, 0.3, 2.5]}, {"box": [2.5, 2, 3.3, 2.5]}, {"box": [5.5, 2, 6.3, 2.5]}]}"#;
    let world = obstacle_world(json);
    assert_eq!(world.combiner("A"), Combine::WeightedSum);
    assert_eq!(world.combiner("B"), Combine::Dithering);
    assert_eq!(world.combiner("C"), Combine::Prioritised);
    let e =
        World::from_json(r#"{"characters": {"A": {"position": [0, 0, 0], "steering": "fast"}}}"#);
    assert!(e.unwrap_err().contains("'A': steering 'fast'"));
    // each walks past its box to a point behind it, keeping its radius
    for (id, x) in [("A", 0.0f32), ("B", 3.0), ("C", 6.0)] {
        let bml = format!(
            r#"<bml {NS} id="b1" characterId="{id}"><locomotion id="w" target="{x},5"/></bml>"#
        );
        let r = run_in(Some(world.clone()), &[&bml], 12.0, 60.0);
        assert!(r.block_ended(), "{id}");
        let last = r.frames.len() - 1;
        assert!(
            r.root(last).distance(Vec2::new(x, 5.0)) < 0.15,
            "{id}: {}",
            r.root(last)
        );
        for k in 0..r.frames.len() {
            assert!(
                world.obstacles().clearance(r.root(k), 1.0) >= 0.25 - 1e-3,
                "{id}"
            );
        }
    }
}

#[test]
fn the_head_leads_the_turn_round_an_obstacle() {
    // round the table of the example room: while the body turns, the head is already turned
    // further the same way
    let world = obstacle_world(include_str!("../fixtures/examples/room.json"));
    let r = run_in(Some(world), &[&walk(r#"target="door""#, "")], 8.0, 60.0);
    let s = Skeleton::adult();
    let (skull, root) = (s.joint("skullbase").unwrap(), 0);
    let yaw = |k: usize, j: usize| {
        let f = r.frames[k].1.world(&s).orientations[j] * Vec3::Z;
        f.x.atan2(f.z)
    };
    // the body's heading: the pelvis's averaged over half a second (it turns to and fro with
    // every step, so its own rate changes sign with the steps while the body turns one way)
    let body = |k: usize| {
        let (a, b) = (k.saturating_sub(15), (k + 15).min(r.frames.len() - 1));
        let sum: Vec2 = (a..=b)
            .map(|i| Vec2::new(yaw(i, root).sin(), yaw(i, root).cos()))
            .sum();
        sum.x.atan2(sum.y)
    };
    let (mut agree, mut turning) = (0, 0);
    let (ready, relax) = (
        r.frame_at(r.sync("b1:w:ready")),
        r.frame_at(r.sync("b1:w:relax")),
    );
    for k in ready.max(1)..relax {
        let rate = (body(k) - body(k - 1)) / r.dt as f32;
        if rate.abs() < 0.3 {
            continue;
        }
        turning += 1;
        let lead = yaw(k, skull) - body(k);
        if lead * rate > 0.0 && lead.abs() > 0.05 {
            agree += 1;
        }
    }
    assert!(turning > 10, "{turning} turning frames");
    assert!(
        agree * 20 >= turning * 17,
        "the head led {agree} of {turning} turning frames"
    );
}
