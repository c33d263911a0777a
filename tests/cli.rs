//! The `bmlr` command line: exit codes and output of `validate`, `run` and `plan`.

mod common;

fn bmlr(args: &[&str]) -> (i32, String, String) {
    common::bmlr(args, "")
}

const RT: &str = "fixtures/realizertester/bml-1";

#[test]
fn validate_valid_file_exits_0() {
    let (code, out, _) = bmlr(&["validate", &format!("{RT}/core/testspeechgestures.xml")]);
    assert_eq!(code, 0);
    assert_eq!(out, format!("{RT}/core/testspeechgestures.xml: valid\n"));
}

#[test]
fn validate_block_without_id_exits_1_with_file_line_col() {
    let (code, out, err) = bmlr(&[
        "validate",
        &format!("{RT}/core/testface.xml"),
        &format!("{RT}/core/bmlnoid.xml"),
    ]);
    assert_eq!(code, 1);
    assert!(
        out.contains(&format!(
            "{RT}/core/bmlnoid.xml:13:1: error[missing-block-id]: the <bml> block has no id"
        )),
        "{out}"
    );
    assert!(err.contains("2 files checked: 1 valid, 1 invalid"), "{err}");
}

#[test]
fn validate_unknown_extension_warns_and_exits_0() {
    let (code, out, _) = bmlr(&["validate", &format!("{RT}/murml/murmlhandlocation.xml")]);
    assert_eq!(code, 0);
    assert!(out.contains("warning[unsupported-extension]: unsupported extension behaviour <murmlgesture id=\"gesture1\">"), "{out}");
    assert!(out.contains("valid (1 warning)"));
}

#[test]
fn validate_missing_file_exits_2() {
    let (code, _, err) = bmlr(&["validate", "no/such/file.xml"]);
    assert_eq!(code, 2);
    assert!(err.contains("no/such/file.xml: cannot read"), "{err}");
}

#[test]
fn usage_error_exits_2() {
    let (code, _, _) = bmlr(&["validate"]);
    assert_eq!(code, 2);
}

#[test]
fn plan_prints_block_relative_and_global_times() {
    let (code, out, err) = bmlr(&[
        "plan",
        "fixtures/examples/welcome.xml",
        &format!("{RT}/core/testspeechappend.xml"),
    ]);
    assert_eq!((code, err.as_str()), (0, ""));
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(lines[0], "greet start 0.000 end 2.882");
    assert_eq!(lines[2], "  greet:hello:stress 0.821 (0.821)");
    assert!(lines.contains(&"  greet:beat:stroke 0.821 (0.821)"));
    // the appended block is planned after the greeting
    assert_eq!(
        &lines[lines.len() - 3..],
        [
            "bml2 start 2.882 end 4.611",
            "  bml2:speech1:start 0.000 (2.882)",
            "  bml2:speech1:end 1.729 (4.611)",
        ]
    );
}

#[test]
fn run_reads_a_stream_of_blocks_with_clock_advances_from_stdin() {
    let input = format!(
        "{}\n+1\nnot bml at all\n<bml xmlns=\"http://www.bml-initiative.org/bml/bml-1.0\" id=\"b\">\n<head id=\"h\" lexeme=\"NOD\"/>\n</bml>\n",
        r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="a"><speech id="s"><text>Hi</text></speech></bml>"#
    );
    let (code, out, err) = common::bmlr(&["run", "--format", "jsonl", "-"], &input);
    // the garbage line is invalid input: the rest runs, and the exit code says so
    assert_eq!(
        (code, err.as_str()),
        (
            1,
            "bmlr run: 1 block could not be parsed (see the warnings)\n"
        )
    );
    let has = |needle: &str| out.lines().any(|l| l.contains(needle));
    assert!(has(r#""id":"a:end","globalTime":0.2"#), "{out}");
    assert!(has(r#""type":"PARSING_FAILURE""#), "{out}");
    // the block after the garbage runs, one second later
    assert!(has(r#""id":"b:start","globalTime":1.0"#), "{out}");
    assert!(has(r#""id":"b:end","globalTime":1.6"#), "{out}");
}

#[test]
fn run_until_stops_the_clock_and_says_what_did_not_finish() {
    let (code, out, err) = bmlr(&["run", "--until", "1", "fixtures/examples/long-speech.xml"]);
    assert_eq!(code, 0);
    assert!(!out.contains("talk:end"));
    assert!(out.contains(r#"id="talk:nod1:start""#));
    assert!(!out.contains(r#"id="talk:nod1:ready""#)); // at 1.083
    assert_eq!(
        err,
        "bmlr run: block 'talk' did not finish at 1.000 s: IN_EXEC, still running\n"
    );
}

#[test]
fn run_usage_and_io_errors_exit_2() {
    let (code, _, err) = bmlr(&["run", "no/such/file.xml"]);
    assert_eq!(code, 2);
    assert!(
        err.starts_with("bmlr run: no/such/file.xml: cannot read"),
        "{err}"
    );
    let (code, _, err) = bmlr(&["run", "+soon", "fixtures/examples/welcome.xml"]);
    assert_eq!(code, 2);
    assert!(err.contains("'+soon' is not a clock advance"), "{err}");
    let (code, _, _) = bmlr(&["run", "--until", "-1", "fixtures/examples/welcome.xml"]);
    assert_eq!(code, 2);
}

#[test]
fn run_gives_byte_identical_logs_and_both_formats_carry_the_same_messages() {
    let args = [
        "run",
        "fixtures/examples/long-speech.xml",
        "+1.5",
        "fixtures/examples/interrupt-speech.xml",
    ];
    let (_, a, _) = bmlr(&args);
    let (_, b, _) = bmlr(&args);
    assert_eq!(a, b);
    let mut jsonl = vec!["run", "--format", "jsonl"];
    jsonl.extend_from_slice(&args[1..]);
    let (_, j, _) = bmlr(&jsonl);
    let decode = |text: &str| -> Vec<bml_realizer::language::feedback::Feedback> {
        text.lines()
            .map(|l| bml_realizer::language::feedback::from_line(l).unwrap())
            .collect()
    };
    assert_eq!(decode(&a), decode(&j));
}

#[test]
fn conformance_in_process_passes_all_41_tests() {
    let (code, out, _) = bmlr(&["conformance"]);
    assert_eq!(code, 0, "{out}");
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(lines.len(), 42);
    assert!(
        lines[..41].iter().all(|l| l.starts_with("ok     test")),
        "{out}"
    );
    assert_eq!(lines[41], "41 passed, 0 failed");
    let (code, out, _) = bmlr(&["conformance", "--filter", "Gaze"]);
    assert_eq!(code, 0);
    assert_eq!(out.lines().last(), Some("4 passed, 0 failed"));
}

#[test]
fn serve_stdio_answers_each_line_with_feedback_and_warns_on_garbage() {
    let input = concat!(
        r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="a"><speech id="s"><text>Hi</text></speech></bml>"#,
        "\n",
        "garbage\n",
    );
    let (code, out, err) = common::bmlr(&["serve", "--stdio"], input);
    assert_eq!((code, err.as_str()), (0, ""));
    let fb: Vec<bml_realizer::language::feedback::Feedback> = out
        .lines()
        .map(|l| bml_realizer::language::feedback::from_line(l).unwrap())
        .collect();
    let has = |needle: &str| out.lines().any(|l| l.contains(needle));
    assert!(
        has(r#"id="a:speech:start""#) || has(r#"id="a:s:start""#),
        "{out}"
    );
    assert!(has(r#"id="a:end""#), "{out}");
    assert!(has(r#"type="PARSING_FAILURE""#), "{out}");
    // wall clock: block and sync progress carry posix times
    assert!(fb.iter().any(|f| matches!(f,
        bml_realizer::language::feedback::Feedback::BlockProgress(p) if p.posix_time.is_some())));
}

#[test]
fn run_realtime_reports_on_the_wall_clock_with_posix_times() {
    let input = r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="a"><speech id="s"><text>Hi</text></speech></bml>"#;
    let (code, out, err) = common::bmlr(&["run", "--realtime", "--format", "jsonl", "-"], input);
    assert_eq!((code, err.as_str()), (0, ""));
    let end = out
        .lines()
        .find(|l| l.contains(r#""id":"a:end""#))
        .unwrap_or_else(|| panic!("{out}"));
    assert!(end.contains(r#""bmla:posixTime":"#), "{end}");
    // the speech lasts 0.2 s on the wall clock (the block starts when it arrives)
    let fb = bml_realizer::language::feedback::from_line(end).unwrap();
    let bml_realizer::language::feedback::Feedback::BlockProgress(p) = fb else {
        panic!("{end}")
    };
    assert!(p.global_time >= 0.2, "{}", p.global_time);
}

// ---- bmlr diff ---------------------------------------------------------------------------

use bml_realizer::language::feedback::{Feedback, Format};

/// The feedback of the greeting example, as messages.
fn greeting() -> Vec<Feedback> {
    let (_, out, _) = bmlr(&["run", "fixtures/examples/welcome.xml"]);
    out.lines()
        .map(|l| bml_realizer::language::feedback::from_line(l).unwrap())
        .collect()
}

fn write_log(name: &str, fb: &[Feedback], format: Format) -> String {
    let path = std::env::temp_dir().join(format!("bmlr-diff-{}-{name}", std::process::id()));
    let text: String = fb.iter().map(|f| format.encode(f) + "\n").collect();
    std::fs::write(&path, text).unwrap();
    path.to_str().unwrap().to_string()
}

fn diff_of(a: &str, b: &str) -> (i32, String) {
    let (code, out, err) = bmlr(&["diff", a, b, "--tolerance", "0.1"]);
    (code, out + &err)
}

#[test]
fn diff_equal_logs_even_across_formats_clock_origins_jitter_and_posix_times() {
    let base = greeting();
    let a = write_log("a.log", &base, Format::Xml);
    assert_eq!(diff_of(&a, &a).0, 0);
    // the same run: JSON lines, another clock origin, ±0.05 s jitter, wall-clock posix times
    let mut other = base.clone();
    for (i, f) in other.iter_mut().enumerate() {
        let jitter = if i % 2 == 0 { 0.05 } else { -0.05 };
        match f {
            Feedback::BlockProgress(p) => {
                p.global_time += 100.0 + jitter;
                p.posix_time = Some(1_700_000_000_000 + i as u64);
            }
            Feedback::SyncPointProgress(p) => {
                p.time += jitter;
                p.global_time += 100.0 + jitter;
                p.posix_time = Some(1_700_000_000_000 + i as u64);
            }
            _ => {}
        }
    }
    let b = write_log("b.jsonl", &other, Format::Jsonl);
    let (code, out) = diff_of(&a, &b);
    assert_eq!(code, 0, "{out}");
    assert!(out.contains("equal: 22 messages"), "{out}");
}

#[test]
fn diff_reports_a_missing_sync_and_swapped_syncs() {
    let base = greeting();
    let a = write_log("m-a.log", &base, Format::Xml);
    let without: Vec<Feedback> = base
        .iter()
        .filter(|f| !matches!(f, Feedback::SyncPointProgress(p) if p.behaviour == "nod" && p.sync == "stroke"))
        .cloned()
        .collect();
    let b = write_log("m-b.log", &without, Format::Xml);
    let (code, out) = diff_of(&a, &b);
    assert_eq!(code, 1);
    assert!(
        out.contains("missing in B: syncPointProgress greet:nod:stroke"),
        "{out}"
    );
    // two syncs of the beat swapped (with their times)
    let mut swapped = base.clone();
    let i = swapped
        .iter()
        .position(|f| matches!(f, Feedback::SyncPointProgress(p) if p.behaviour == "beat" && p.sync == "ready"))
        .unwrap();
    swapped.swap(i, i + 1);
    let c = write_log("m-c.log", &swapped, Format::Xml);
    let (code, out) = diff_of(&a, &c);
    assert_eq!(code, 1);
    assert!(
        out.contains("reordered: B has syncPointProgress greet:beat:strokeStart"),
        "{out}"
    );
}

#[test]
fn diff_of_a_truncated_or_garbage_file_exits_2_with_the_line() {
    let base = greeting();
    let a = write_log("t-a.log", &base, Format::Xml);
    let text = std::fs::read_to_string(&a).unwrap();
    let cut = &text[..text.len() - 40];
    let t = std::env::temp_dir().join(format!("bmlr-diff-{}-t.log", std::process::id()));
    std::fs::write(&t, cut).unwrap();
    let (code, out) = diff_of(&a, t.to_str().unwrap());
    assert_eq!(code, 2);
    assert!(
        out.contains(&format!("{}:22: bad feedback", t.display())),
        "{out}"
    );
    let g = std::env::temp_dir().join(format!("bmlr-diff-{}-g.log", std::process::id()));
    std::fs::write(&g, "hello\n").unwrap();
    let (code, out) = diff_of(g.to_str().unwrap(), &a);
    assert_eq!(code, 2);
    assert!(out.contains(":1: bad feedback"), "{out}");
}

#[test]
fn run_bvh_records_frames_without_changing_the_feedback() {
    let bvh = std::env::temp_dir().join(format!("bmlr-{}-welcome.bvh", std::process::id()));
    let (code, with, err) = bmlr(&[
        "run",
        "--fps",
        "50",
        "--bvh",
        bvh.to_str().unwrap(),
        "fixtures/examples/welcome.xml",
    ]);
    assert_eq!(code, 0, "{err}");
    let (_, without, _) = bmlr(&["run", "fixtures/examples/welcome.xml"]);
    assert_eq!(with, without, "frames do not change the feedback");
    // 0 .. 2.882 s every 1/50 s: 145 frames
    assert!(err.contains("(145 frames at 50 fps, 57 joints)"), "{err}");
    let text = std::fs::read_to_string(&bvh).unwrap();
    assert!(text.starts_with("HIERARCHY\nROOT HumanoidRoot\n"));
    assert!(text.contains("MOTION\nFrames: 145\nFrame Time: 0.020000\n"));
    let (code, _, err) = bmlr(&[
        "run",
        "--realtime",
        "--bvh",
        "x.bvh",
        "fixtures/examples/welcome.xml",
    ]);
    assert_eq!(code, 2);
    assert!(err.contains("leave out --realtime"), "{err}");
}

#[test]
fn run_assets_extend_the_motion_data_and_report_bad_files() {
    let dir = std::env::temp_dir().join(format!("bmlr-assets-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("units.json"),
        r#"{"units": {"swing": {"keys": {"start": 0, "stroke": 0.5, "end": 1},
            "duration": {"preferred": 1.5, "min": 0.5, "max": 3},
            "rotations": {"r_shoulder": ["0", "0", "40 * sin(pi * t)"]}}}}"#,
    )
    .unwrap();
    std::fs::write(
        dir.join("gestures.json"),
        r#"{"gestures": [{"lexeme": "SWING", "procedural": "swing"}]}"#,
    )
    .unwrap();
    let block = "-";
    let bml = r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" xmlns:bmlt="http://hmi.ewi.utwente.nl/bmlt" id="b"><bmlt:procanimation id="p" name="swing"/><gesture id="g" lexeme="SWING" start="p:end"/></bml>"#;
    let assets = dir.to_str().unwrap();
    let (code, out, err) = common::bmlr(
        &["run", "--assets", assets, "--format", "jsonl", block],
        bml,
    );
    assert_eq!(code, 0, "{err}");
    assert!(!out.contains("warning"), "{out}");
    // the unit's own timing: 1.5 s, then the gesture bound to it (1.5 s more)
    assert!(out.contains(r#""id":"b:p:end","time":1.5"#), "{out}");
    assert!(out.contains(r#""id":"b:g:end","time":3"#), "{out}");
    // without the directory the unit is unknown
    let (_, out, _) = common::bmlr(&["run", "--format", "jsonl", block], bml);
    assert!(out.contains("no procedural unit 'swing'"), "{out}");
    // a bad file: exit 2 naming it
    std::fs::write(
        dir.join("heads.json"),
        r#"{"heads": [{"lexeme": "X", "axis": "q", "degrees": 1}]}"#,
    )
    .unwrap();
    let (code, _, err) = common::bmlr(&["run", "--assets", assets, block], bml);
    assert_eq!(code, 2);
    assert!(err.contains("heads.json") && err.contains("axis"), "{err}");
    let (code, _, err) = bmlr(&["run", "--assets", "no/such/dir", "-"]);
    assert_eq!(code, 2);
    assert!(err.contains("not a directory"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn run_frames_writes_the_skeleton_and_every_frame_without_changing_the_feedback() {
    let path = std::env::temp_dir().join(format!("bmlr-{}-welcome.jsonl", std::process::id()));
    let args = [
        "run",
        "--frames",
        path.to_str().unwrap(),
        "fixtures/examples/welcome.xml",
    ];
    let (code, with, err) = bmlr(&args);
    assert_eq!(code, 0, "{err}");
    let (_, without, _) = bmlr(&["run", "fixtures/examples/welcome.xml"]);
    assert_eq!(with, without, "frames do not change the feedback");
    // 0 .. 2.882 s every 1/60 s: 173 frames
    assert!(
        err.contains("(173 frames at 60 fps, 1 character(s))"),
        "{err}"
    );
    let text = std::fs::read_to_string(&path).unwrap();
    let lines: Vec<serde_json::Value> = text
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let skeleton = bml_realizer::character::body::Skeleton::adult();
    let joints = lines[0]["skeleton"]["joints"].as_array().unwrap();
    assert_eq!(joints.len(), skeleton.len());
    assert_eq!(lines[0]["characters"], serde_json::json!([""]));
    assert_eq!(lines.len(), 1 + 173);
    // rebuild a pose from the file: at the beat's stroke (0.821 s, on "welcome") the right hand
    // is in front
    let near = |l: &&serde_json::Value| (l["time"].as_f64().unwrap_or(-9.0) - 0.821).abs();
    let stroke = lines
        .iter()
        .min_by(|a, b| near(a).total_cmp(&near(b)))
        .unwrap();
    let mut pose = bml_realizer::character::body::Pose::rest(&skeleton);
    for (i, j) in skeleton.joints().iter().enumerate() {
        let q = stroke["characters"][""]["joints"][&j.name]
            .as_array()
            .unwrap();
        let q: Vec<f32> = q.iter().map(|v| v.as_f64().unwrap() as f32).collect();
        pose.rotations[i] = glam::Quat::from_xyzw(q[0], q[1], q[2], q[3]);
    }
    let wrist = pose.world(&skeleton).positions[skeleton.joint("r_wrist").unwrap()];
    assert!(wrist.z > 0.15 && (1.0..1.35).contains(&wrist.y), "{wrist}");
    // the same input gives the same file
    bmlr(&args);
    assert_eq!(std::fs::read_to_string(&path).unwrap(), text);
    let (code, _, err) = bmlr(&[
        "run",
        "--realtime",
        "--frames",
        "x.jsonl",
        "fixtures/examples/welcome.xml",
    ]);
    assert_eq!(code, 2);
    assert!(
        err.contains("--frames records on the virtual clock"),
        "{err}"
    );
}

#[test]
fn run_frames_roots_writes_where_each_character_stands_and_nothing_else() {
    let dir = std::env::temp_dir();
    let full = dir.join(format!("bmlr-{}-full.jsonl", std::process::id()));
    let roots = dir.join(format!("bmlr-{}-roots.jsonl", std::process::id()));
    let file = "fixtures/examples/welcome.xml";
    let (code, _, err) = bmlr(&["run", "--frames", full.to_str().unwrap(), file]);
    assert_eq!(code, 0, "{err}");
    let args = [
        "run",
        "--frames",
        roots.to_str().unwrap(),
        "--frames-roots",
        file,
    ];
    let (code, _, err) = bmlr(&args);
    assert_eq!(code, 0, "{err}");
    let read = |p: &std::path::Path| -> Vec<serde_json::Value> {
        (std::fs::read_to_string(p).unwrap().lines())
            .map(|l| serde_json::from_str(l).unwrap())
            .collect()
    };
    let (full, roots) = (read(&full), read(&roots));
    assert_eq!(roots[0]["roots_only"], true);
    assert!(full[0].get("roots_only").is_none());
    assert_eq!(roots.len(), full.len());
    for (r, f) in roots.iter().zip(&full).skip(1) {
        let (r, f) = (&r["characters"][""], &f["characters"][""]);
        assert_eq!(
            r.as_object().unwrap().len(),
            2,
            "root and rotation only: {r}"
        );
        assert_eq!((&r["root"], &r["rotation"]), (&f["root"], &f["rotation"]));
    }
    let (code, _, err) = bmlr(&["run", "--frames-roots", file]);
    assert_eq!(code, 2);
    assert!(err.contains("--frames"), "{err}");
    let (code, _, err) = bmlr(&["run", "--frames", "/no/such/dir/f.jsonl", file]);
    assert_eq!(code, 2);
    assert!(err.contains("/no/such/dir/f.jsonl: cannot write"), "{err}");
}

#[test]
fn the_idle_layer_moves_the_body_and_never_the_feedback() {
    let dir = std::env::temp_dir();
    let (a, b) = (
        dir.join(format!("bmlr-{}-idle.jsonl", std::process::id())),
        dir.join(format!("bmlr-{}-still.jsonl", std::process::id())),
    );
    let run = |extra: &[&str], path: &std::path::Path| {
        let mut args = vec!["run", "--frames", path.to_str().unwrap()];
        args.extend_from_slice(extra);
        args.push("fixtures/examples/welcome.xml");
        let (code, out, err) = bmlr(&args);
        assert_eq!(code, 0, "{err}");
        out
    };
    assert_eq!(run(&[], &a), run(&["--no-idle"], &b), "the same feedback");
    let root_x = |path: &std::path::Path| -> Vec<f64> {
        let text = std::fs::read_to_string(path).unwrap();
        text.lines()
            .skip(1)
            .map(|l| serde_json::from_str::<serde_json::Value>(l).unwrap())
            .map(|f| f["characters"][""]["root"][0].as_f64().unwrap())
            .collect()
    };
    let (idle, still) = (root_x(&a), root_x(&b));
    assert!(
        still.iter().all(|&x| x == 0.0),
        "without it the pelvis stays put"
    );
    let sway = idle.iter().fold(0f64, |m, x| m.max(x.abs()));
    assert!(
        (0.001..0.02).contains(&sway),
        "with it the pelvis sways {sway} m"
    );
}

/// A `.glb`'s JSON (after checking its magic) and where its binary chunk's data starts.
fn glb_json(glb: &[u8]) -> (serde_json::Value, usize) {
    assert_eq!(&glb[0..4], b"glTF");
    let json_len = u32::from_le_bytes(glb[12..16].try_into().unwrap()) as usize;
    let json = serde_json::from_slice(&glb[20..20 + json_len]).unwrap();
    (json, 20 + json_len + 8)
}

#[test]
fn run_gltf_writes_the_default_avatar_with_the_motion() {
    let path = std::env::temp_dir().join(format!("bmlr-{}-welcome.glb", std::process::id()));
    let (code, with, err) = bmlr(&[
        "run",
        "--gltf",
        path.to_str().unwrap(),
        "fixtures/examples/welcome.xml",
    ]);
    assert_eq!(code, 0, "{err}");
    let (_, without, _) = bmlr(&["run", "fixtures/examples/welcome.xml"]);
    assert_eq!(with, without, "the glTF does not change the feedback");
    assert!(
        err.contains("(the character on default avatar, 173 frames at 60 fps,"),
        "{err}"
    );
    let glb = std::fs::read(&path).unwrap();
    let (gltf, _) = glb_json(&glb);
    let skeleton = bml_realizer::character::body::Skeleton::adult();
    assert_eq!(
        gltf["skins"][0]["joints"].as_array().unwrap().len(),
        skeleton.len()
    );
    let animation = &gltf["animations"][0];
    let input = animation["samplers"][0]["input"].as_u64().unwrap() as usize;
    assert_eq!(gltf["accessors"][input]["count"], 173);
    assert_eq!(
        gltf["accessors"][input]["max"],
        serde_json::json!([172.0f32 / 60.0])
    );
    // the skinned person: positions with bounds, its materials (skin, clothes, eyes, ...)
    let primitive = &gltf["meshes"][0]["primitives"][0];
    let position = primitive["attributes"]["POSITION"].as_u64().unwrap() as usize;
    let max_y = gltf["accessors"][position]["max"][1].as_f64().unwrap();
    assert!((1.6..1.9).contains(&max_y), "the avatar is {max_y} m tall");
    assert!(gltf["materials"].as_array().unwrap().len() >= 5);
    let (code, _, err) = bmlr(&[
        "run",
        "--realtime",
        "--gltf",
        "x.glb",
        "fixtures/examples/welcome.xml",
    ]);
    assert_eq!(code, 2);
    assert!(err.contains("--gltf records on the virtual clock"), "{err}");
}

/// Characters placed in the world make one glTF scene, each on its avatar where it stands:
/// Bob's hips are keyed at his place in the example world (x 0.7 m, z 0.3 m; not scaled by the
/// avatar's shorter legs, which would put him 4 cm nearer the origin).
#[test]
fn run_gltf_of_several_characters_is_one_scene() {
    let path = std::env::temp_dir().join(format!("bmlr-{}-two.glb", std::process::id()));
    let (code, _, err) = bmlr(&[
        "run",
        "--world",
        "fixtures/examples/world.json",
        "--gltf",
        path.to_str().unwrap(),
        "fixtures/examples/two-alice.xml",
        "fixtures/examples/two-bob.xml",
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("2 characters on their avatars"), "{err}");
    let glb = std::fs::read(&path).unwrap();
    let (gltf, bin) = glb_json(&glb);
    assert_eq!(gltf["skins"].as_array().unwrap().len(), 2);
    let nodes = gltf["nodes"].as_array().unwrap();
    let bob = nodes.iter().position(|n| n["name"] == "Bob").unwrap();
    // Bob's HumanoidRoot, the root of his skeleton under his node
    let hips = (nodes[bob]["children"].as_array().unwrap().iter())
        .map(|c| c.as_u64().unwrap() as usize)
        .find(|&c| nodes[c]["name"] == "HumanoidRoot")
        .unwrap();
    let channels = gltf["animations"][0]["channels"].as_array().unwrap();
    let root = (channels.iter())
        .find(|c| c["target"]["node"] == hips && c["target"]["path"] == "translation")
        .unwrap();
    let sampler = &gltf["animations"][0]["samplers"][root["sampler"].as_u64().unwrap() as usize];
    let output = &gltf["accessors"][sampler["output"].as_u64().unwrap() as usize];
    let view = &gltf["bufferViews"][output["bufferView"].as_u64().unwrap() as usize];
    let bin = bin + view["byteOffset"].as_u64().unwrap() as usize;
    let x = f32::from_le_bytes(glb[bin..bin + 4].try_into().unwrap());
    let z = f32::from_le_bytes(glb[bin + 8..bin + 12].try_into().unwrap());
    assert!(
        (x - 0.7).abs() < 0.02 && (z - 0.3).abs() < 0.02,
        "Bob's hips at x {x}, z {z}"
    );
    std::fs::remove_file(&path).ok();
}
