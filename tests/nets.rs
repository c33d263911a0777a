//! PaT-Nets through `bmlr run --nets`: the crosswalk of fixtures/examples/crosswalk (a world
//! light net and four pedestrians waiting at the curb), and nets files that are refused.

mod common;

use common::bmlr;

const DIR: &str = "fixtures/examples/crosswalk";

fn crosswalk() -> String {
    let (world, nets, start) = (
        format!("{DIR}/world.json"),
        format!("{DIR}/nets.json"),
        format!("{DIR}/start.xml"),
    );
    let args = [
        "run", "--world", &world, "--nets", &nets, "--until", "16", "--format", "jsonl", &start,
    ];
    let (code, out, err) = bmlr(&args, "");
    assert_eq!(code, 0, "{err}");
    out
}

/// The `time` of every line of `out` that holds all of `parts`.
fn times(out: &str, parts: &[&str]) -> Vec<f64> {
    (out.lines())
        .filter(|l| parts.iter().all(|p| l.contains(p)))
        .map(|l| serde_json::from_str::<serde_json::Value>(l).unwrap())
        .map(|v| {
            v.get("time")
                .or(v.get("globalTime"))
                .and_then(|t| t.as_f64())
                .unwrap()
        })
        .collect()
}

#[test]
fn pedestrians_leave_the_curb_within_a_frame_after_the_light_turns_and_never_before() {
    let out = crosswalk();
    let walk = times(&out, &[r#""feedback":"var""#, r#""value":"WALK""#]);
    assert_eq!(walk.first(), Some(&3.0), "{out}");
    for who in ["ann", "ben", "cal", "dee"] {
        let id = format!(r#""characterId":"{who}""#);
        let left = times(&out, &[r#""net":""#, &id, r#""from":"curb""#]);
        assert_eq!(left.len(), 1, "{who}");
        let started = times(&out, &[r#""id":"cross:start""#, &id]);
        assert_eq!(started.len(), 1, "{who}");
        // one frame (1/60 s) after the light, never before it
        assert!(
            left[0] > walk[0] && left[0] - walk[0] <= 1.0 / 60.0 + 1e-3,
            "{who} left at {}",
            left[0]
        );
        assert!(
            started[0] >= left[0] && started[0] - walk[0] <= 1.0 / 60.0 + 1e-3,
            "{who} started at {}",
            started[0]
        );
        // and they get across
        assert_eq!(
            times(&out, &[r#""net":""#, &id, r#""to":"across""#]).len(),
            1,
            "{who}"
        );
    }
}

#[test]
fn the_crosswalk_runs_the_same_byte_for_byte() {
    assert_eq!(crosswalk(), crosswalk());
}

#[test]
fn a_bad_nets_file_is_refused_with_exit_2_naming_the_file_and_field() {
    let dir = std::env::temp_dir().join(format!("bmlr-nets-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let cases = [
        (
            r#"{"nets": {"a": {"states": ["x"], "transitions": [{"from": "x", "to": "y", "when": {"after": 1}}]}}}"#,
            "nets.a.transitions[0].to",
        ),
        (
            r#"{"nets": {"a": {"states": ["x"], "transitions": [{"from": "x", "to": "x", "when": {"soon": 1}}]}}}"#,
            "nets.a.transitions[0].when",
        ),
        (
            r#"{"nets": {"a": {"states": ["x"], "transitions": [{"from": "x", "to": "x", "when": {"after": 1}, "do": [{"net": "a"}]}]}}}"#,
            "cycle",
        ),
        (r#"{"nets": "#, "EOF"),
    ];
    for (k, (text, field)) in cases.iter().enumerate() {
        let path = dir.join(format!("bad{k}.json"));
        std::fs::write(&path, text).unwrap();
        let p = path.to_str().unwrap();
        let (code, out, err) = bmlr(
            &[
                "run",
                "--nets",
                p,
                "--until",
                "1",
                "fixtures/examples/welcome.xml",
            ],
            "",
        );
        assert_eq!(code, 2, "{err}");
        assert!(out.is_empty(), "nothing runs: {out}");
        assert!(err.contains(p) && err.contains(field), "{err}");
    }
    // and --nets without --until
    let (code, _, err) = bmlr(
        &[
            "run",
            "--nets",
            &format!("{DIR}/nets.json"),
            "fixtures/examples/welcome.xml",
        ],
        "",
    );
    assert_eq!(code, 2);
    assert!(err.contains("--until"), "{err}");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_sees_guard_makes_a_character_look_at_a_newcomer_only_after_it_appears() {
    use bml_realizer::language::feedback::{Feedback, WorldFeedback};
    use bml_realizer::realizer::Realizer;
    use bml_realizer::world::nets::{file, Nets};
    use bml_realizer::world::World;
    // b walks out from behind a wall into a's view; a's net looks at b once a sees it
    let world = r#"{"characters": {"a": {"position": [0, 0, 0]}, "b": {"position": [-2.5, 0, 6], "facing": 90}},
                    "obstacles": [{"segment": [-4, 4, 0, 4], "height": 2.5}]}"#;
    let nets = r#"{"nets": {"watch": {"character": "a", "states": ["idle", "looking"], "transitions": [
        {"from": "idle", "to": "looking", "when": {"sees": "b"},
         "do": [{"bml": "<bml xmlns=\"http://www.bml-initiative.org/bml/bml-1.0\" id=\"look\"><gaze id=\"g\" target=\"b\" start=\"0\" end=\"2\"/></bml>"}]}]}}}"#;
    let mut r = Realizer::new().with_idle(false);
    *r.world_mut() = World::from_json(world).unwrap().0;
    r.set_perception(Some(r.world().vision()), true).unwrap();
    let nets = Nets::new(file::read(nets, r.limits()).unwrap(), Default::default());
    r.set_nets(Some(nets), true).unwrap();
    r.perform_bml(
        r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="walk" characterId="b"><locomotion id="l" target="3,6"/></bml>"#,
    )
    .unwrap();
    let (mut appeared, mut turned, mut gaze) = (None, None, None);
    for k in 1..=(8 * 60) {
        let t = f64::from(k) / 60.0;
        for f in r.tick(t).feedback {
            match f {
                Feedback::World(WorldFeedback::Perception(p))
                    if p.character_id == "a" && p.appeared.iter().any(|s| s == "b") =>
                {
                    appeared.get_or_insert(t);
                }
                Feedback::World(WorldFeedback::Net(n)) if n.to == "looking" => {
                    turned.get_or_insert(t);
                }
                Feedback::BlockProgress(b)
                    if b.block.as_str() == "look" && b.sync.as_str() == "start" =>
                {
                    gaze.get_or_insert(b.global_time);
                }
                _ => {}
            }
        }
    }
    let (appeared, turned, gaze) = (
        appeared.expect("b appears"),
        turned.expect("the net turns"),
        gaze.expect("a looks"),
    );
    eprintln!("b appeared at {appeared:.3} s; the net turned at {turned:.3} s; the gaze started at {gaze:.3} s");
    // not before b appeared to a: in the frame it appeared (sensing comes first in a frame,
    // then the nets), at most the next
    assert!(turned >= appeared && turned - appeared <= 1.0 / 60.0 + 1e-9);
    assert!(gaze >= turned - 1e-9 && gaze - turned < 1e-9);
}
