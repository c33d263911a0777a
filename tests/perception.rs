//! Synthetic vision in a running realizer: what hides, what shows, and when. Character `a`
//! stands at the origin looking along +z; the others and the obstacles are placed around it.

use bml_realizer::character::body::Skeleton;
use bml_realizer::language::feedback::{Feedback, WorldFeedback};
use bml_realizer::realizer::Realizer;
use bml_realizer::world::perception::Vision;
use bml_realizer::world::{Placement, World};
use glam::{Vec2, Vec3};

const NS: &str = r#"xmlns="http://www.bml-initiative.org/bml/bml-1.0""#;

/// A realizer with world file `world` (JSON), sight on with reports, `a` made a character.
fn realizer(world: &str) -> Realizer {
    let mut r = Realizer::new().with_idle(false);
    *r.world_mut() = World::from_json(world).expect("a world").0;
    r.set_perception(Some(Vision::default()), true).unwrap();
    r.perform_bml(&format!(r#"<bml {NS} id="still" characterId="a"/>"#))
        .unwrap();
    r
}

/// The period of looks with the default vision.
fn period() -> f64 {
    1.0 / Vision::default().rate
}

#[test]
fn what_an_obstacle_taller_than_the_eyes_hides_is_never_seen() {
    let world = |height: f64| {
        format!(
            r#"{{"characters": {{"a": {{"position": [0, 0, 0]}}}},
                "points": {{"box": [0.2, 1.0, 6]}},
                "obstacles": [{{"segment": [-3, 4, 3, 4], "height": {height}}}]}}"#
        )
    };
    // a wall of 2 m, above the eyes (1.64 m): nothing behind it, over 100 looks
    let mut r = realizer(&world(2.0));
    for k in 1..=600 {
        r.tick(k as f64 / 60.0);
        assert!(!r.seen("a").iter().any(|s| s == "box"), "seen at frame {k}");
    }
    // a wall of 0.8 m: the box above it is seen (the same rays, the same looks)
    let mut r = realizer(&world(0.8));
    let mut seen = false;
    for k in 1..=600 {
        r.tick(k as f64 / 60.0);
        seen |= r.seen("a").iter().any(|s| s == "box");
    }
    assert!(seen, "the box over a low wall is never seen");
}

/// The times (seconds) at which `id` appeared to `a` in perception feedback.
fn appearances(feedback: &[(f64, Feedback)], id: &str) -> Vec<f64> {
    (feedback.iter())
        .filter_map(|(t, f)| match f {
            Feedback::World(WorldFeedback::Perception(p))
                if p.character_id == "a" && p.appeared.iter().any(|s| s == id) =>
            {
                Some(*t)
            }
            _ => None,
        })
        .collect()
}

#[test]
fn what_comes_into_view_in_front_is_seen_within_one_period() {
    for (k, (what, at)) in [
        ("b", Vec3::new(1.0, 0.0, 3.0)),
        ("c", Vec3::new(-1.2, 0.0, 3.0)),
        // (a point is a ball of 0.1 m: at 1.3 m it spans 8.8°, wider than the rays' gaps)
        ("ball", Vec3::new(0.1, 1.5, 1.4)),
    ]
    .into_iter()
    .enumerate()
    {
        let mut r = realizer(r#"{"characters": {"a": {"position": [0, 0, 0]}}}"#);
        let mut feedback = Vec::new();
        let fps = 60.0;
        let mut t = 0.0;
        // run a while, then it appears at a time between looks
        let shown = 1.0 + 0.013 * k as f64;
        while t < 3.0 {
            t += 1.0 / fps;
            if t >= shown && !r.world().is_placed(what) && r.world().get(what).is_none() {
                if what == "ball" {
                    r.world_mut().set(what, at);
                } else {
                    r.world_mut()
                        .place(what, Placement::new(at, 180.0))
                        .unwrap();
                }
            }
            let frame = r.tick(t);
            feedback.extend(frame.feedback.into_iter().map(|f| (t, f)));
        }
        let seen = appearances(&feedback, what);
        let first = *seen.first().unwrap_or_else(|| panic!("{what} never seen"));
        // sensing reads the frame before: one frame more at most
        assert!(
            first - shown <= period() + 1.5 / fps,
            "{what} appeared {:.3} s after it was there",
            first - shown
        );
        // and it stays seen: in view, it does not flicker out
        assert_eq!(seen.len(), 1, "{what} appeared at {seen:?}");
    }
}

/// Whether the segment from `p` to `q` passes over the ground segment `a`–`b` below `height`.
fn blocked(p: Vec3, q: Vec3, a: Vec2, b: Vec2, height: f32) -> bool {
    let (p2, d2) = (Vec2::new(p.x, p.z), Vec2::new(q.x - p.x, q.z - p.z));
    let e = b - a;
    let den = d2.perp_dot(e);
    if den.abs() < 1e-9 {
        return false;
    }
    let t = (a - p2).perp_dot(e) / den;
    let s = (a - p2).perp_dot(d2) / den;
    (0.0..=1.0).contains(&t) && (0.0..=1.0).contains(&s) && p.y + t * (q.y - p.y) < height
}

#[test]
fn a_character_walking_out_from_behind_a_wall_appears_within_one_period_of_showing() {
    let world = r#"{"characters": {"a": {"position": [0, 0, 0]}, "b": {"position": [-2.5, 0, 6], "facing": 90}},
                    "obstacles": [{"segment": [-4, 4, 0, 4], "height": 2.5}]}"#;
    let mut r = realizer(world);
    r.perform_bml(&format!(
        r#"<bml {NS} id="walk" characterId="b"><locomotion id="l" target="3,6"/></bml>"#
    ))
    .unwrap();
    let skeleton = Skeleton::adult();
    let eyes = |pose: &bml_realizer::character::body::Pose| {
        let l = skeleton.joint("l_eyeball_joint").unwrap();
        let r = skeleton.joint("r_eyeball_joint").unwrap();
        (pose.joint_world(&skeleton, l).0 + pose.joint_world(&skeleton, r).0) / 2.0
    };
    let chest = |pose: &bml_realizer::character::body::Pose| {
        pose.joint_world(&skeleton, skeleton.joint("vt6").unwrap())
            .0
    };
    let (wa, wb) = (Vec2::new(-4.0, 4.0), Vec2::new(0.0, 4.0));
    let fps = 60.0;
    let mut showing: Option<f64> = None;
    let mut appeared: Option<f64> = None;
    for k in 1..=(8.0 * fps) as usize {
        let t = k as f64 / fps;
        let frame = r.tick(t);
        for f in &frame.feedback {
            if let Feedback::World(WorldFeedback::Perception(p)) = f {
                if p.character_id == "a" && p.appeared.iter().any(|s| s == "b") {
                    appeared.get_or_insert(t);
                }
            }
        }
        let (Some(pa), Some(pb)) = (frame.character("a"), frame.character("b")) else {
            continue;
        };
        let from = eyes(&pa.pose);
        // showing: a's eyes have a clear line to b's eyes and to its chest
        let clear = [eyes(&pb.pose), chest(&pb.pose)]
            .iter()
            .all(|q| !blocked(from, *q, wa, wb, 2.5));
        if clear {
            showing.get_or_insert(t);
        }
        // wholly behind the wall (every joint a body's width left of a's line of sight past
        // its end, which runs along +z): never seen
        let joints = pb.pose.world(&skeleton).positions;
        if joints.iter().all(|j| j.x < -0.25 && j.z > 4.2) {
            assert!(
                r.seen("a").iter().all(|s| s != "b"),
                "b seen through the wall at {t}"
            );
        }
    }
    let (showing, appeared) = (showing.expect("b shows"), appeared.expect("b appears"));
    eprintln!("b showed at {showing:.3} s, appeared to a at {appeared:.3} s");
    assert!(
        appeared - showing <= period() + 1.5 / fps,
        "b appeared {:.3} s after it showed",
        appeared - showing
    );
}

#[test]
fn the_world_file_s_vision_and_variables_are_read_and_bad_values_named() {
    let (w, _) = World::from_json(
        r#"{"vision": {"rate": 5, "side": 10, "memory": {"count": 3}}, "lights": {"light": "WALK"}}"#,
    )
    .unwrap();
    assert_eq!((w.vision().rate, w.vision().side), (5.0, 10));
    assert_eq!(w.vision().memory.count, Some(3));
    assert_eq!(w.vision().memory.millis, None, "a bound left out is off");
    assert_eq!(w.variables()["light"].to_string(), "WALK");
    for (bad, field) in [
        (r#"{"vision": {"rate": 0}}"#, "vision.rate"),
        (r#"{"vision": {"side": 65}}"#, "vision.side"),
        (r#"{"vision": {"field": [120, 200]}}"#, "vision.field[1]"),
        (r#"{"vision": {"sight": 1}}"#, "sight"),
    ] {
        let e = World::from_json(bad).unwrap_err();
        assert!(e.contains(field), "{e}");
    }
}

/// `bmlr run --until`: after the blocks end, the characters go on looking on their own grid of
/// times up to the end (the last look used to fall on the end itself, off the grid, and the
/// looks between were lost).
#[test]
fn looks_after_the_blocks_end_stay_on_their_grid_up_to_until() {
    let dir = std::env::temp_dir().join(format!("bmlr-looks-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // a ball crosses in front of ann and goes behind her after her nod has ended
    let world = dir.join("world.json");
    std::fs::write(
        &world,
        r#"{"paths": {"ball": {"keys": [[0, [-3, 1.6, 2]], [1.5, [0, 1.6, 2]], [2.2, [0, 1.6, -3]]]}},
            "characters": {"ann": {"position": [0, 0, 0], "facing": 0}}}"#,
    )
    .unwrap();
    let block = dir.join("nod.xml");
    std::fs::write(
        &block,
        format!(r#"<bml {NS} id="b1" characterId="ann"><head id="h" lexeme="NOD" start="0" end="0.5"/></bml>"#),
    )
    .unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_bmlr"))
        .args([
            "run",
            "--format",
            "jsonl",
            "--perception",
            "--until",
            "2.5",
            "--world",
        ])
        .arg(&world)
        .arg(&block)
        .output()
        .unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let times: Vec<f64> = (String::from_utf8_lossy(&out.stdout).lines())
        .filter_map(|l| serde_json::from_str::<serde_json::Value>(l).ok())
        .filter(|v| v["feedback"] == "perception" && v["characterId"] == "ann")
        .map(|v| v["time"].as_f64().unwrap())
        .collect();
    assert!(
        times.iter().any(|&t| t > 0.5 && t < 2.4),
        "no look between the nod's end and --until: {times:?}"
    );
    for t in &times {
        let on = (t - times[0]) / period();
        assert!(
            (on - on.round()).abs() < 0.02,
            "{t} is off the grid of {times:?}"
        );
    }
}
