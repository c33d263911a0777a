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
