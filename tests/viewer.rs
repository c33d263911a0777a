//! `bmlr view` and the live view of `bmlr serve --view`: the page holds the run (frames that put
//! the hand where the gesture says, the feedback with its times, the timeline, the world), it is
//! served on loopback only, and the live WebSocket streams frames and feedback as blocks arrive.
//! The browser test (headless Chromium draws the page) needs Debian's `chromium`: it is
//! `#[ignore]`d here and `.ci/run` installs the browser and runs it with `--ignored`.

mod browser;
mod common;

use browser::{browse, data, far, page, scratch, Shot};

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use glam::{Quat, Vec3};
use serde_json::Value;

const WELCOME: &str = "fixtures/examples/welcome.xml";
const NS: &str = r#"xmlns="http://www.bml-initiative.org/bml/bml-1.0""#;

fn vec3(v: &Value) -> Vec3 {
    let f = |i: usize| v[i].as_f64().unwrap() as f32;
    Vec3::new(f(0), f(1), f(2))
}

fn quat(v: &Value) -> Quat {
    let f = |i: usize| v[i].as_f64().unwrap() as f32;
    Quat::from_xyzw(f(0), f(1), f(2), f(3))
}

/// World positions of every joint of character `id` in a frame line, by forward kinematics
/// over the header's skeleton (written here, independently of the page's script).
fn world(header: &Value, frame: &Value, id: &str) -> Vec<(String, Vec3)> {
    let c = &frame["characters"][id];
    let mut out: Vec<(String, Vec3, Quat)> = Vec::new();
    for j in header["skeleton"]["joints"].as_array().unwrap() {
        let name = j["name"].as_str().unwrap().to_string();
        let (p, q) = match j["parent"].as_str() {
            None => (vec3(&c["root"]), quat(&c["rotation"])),
            Some(parent) => {
                let (_, pp, pq) = out.iter().find(|(n, _, _)| n == parent).unwrap();
                (
                    *pp + *pq * vec3(&j["offset"]),
                    *pq * quat(&c["joints"][&name]),
                )
            }
        };
        out.push((name, p, q));
    }
    out.into_iter().map(|(n, p, _)| (n, p)).collect()
}

fn at(joints: &[(String, Vec3)], name: &str) -> Vec3 {
    joints.iter().find(|(n, _)| n == name).unwrap().1
}

#[test]
fn the_page_holds_the_run_frames_feedback_timeline_and_world() {
    let (page, dir) = page("view-welcome", &[WELCOME]);
    assert!(
        dir.join("three-LICENSE.txt").exists(),
        "three.js's licence beside the page"
    );
    let d = data(&page);
    let header = &d["header"];
    assert_eq!(header["skeleton"]["joints"].as_array().unwrap().len(), 57);
    assert_eq!(header["characters"], serde_json::json!([""]));
    // frames every 1/30 s from 0 to the block's end (2.882 s)
    let frames = d["frames"].as_array().unwrap();
    let times: Vec<f64> = frames.iter().map(|f| f["time"].as_f64().unwrap()).collect();
    assert_eq!(times[0], 0.0);
    assert!((2.882 - times.last().unwrap()) < 1.0 / 30.0, "{times:?}");
    assert!(times
        .windows(2)
        .all(|w| w[1] > w[0] && w[1] - w[0] <= 1.0 / 30.0 + 1e-6));
    // at rest the right wrist hangs at the side; at the beat's stroke (0.821 s, on "welcome") it
    // is in front of the torso between waist and chest
    let frame_at = |t: f64| {
        let near = |x: &f64| (x - t).abs();
        let k = (0..times.len())
            .min_by(|&a, &b| near(&times[a]).total_cmp(&near(&times[b])))
            .unwrap();
        world(header, &frames[k], "")
    };
    let rest = frame_at(0.0);
    assert!(at(&rest, "r_wrist").y < at(&rest, "r_hip").y + 0.25);
    let stroke = frame_at(0.821);
    let (wrist, pelvis, neck) = (
        at(&stroke, "r_wrist"),
        at(&stroke, "sacroiliac"),
        at(&stroke, "vc7"),
    );
    assert!(wrist.z > pelvis.z + 0.15, "in front: {wrist} vs {pelvis}");
    assert!(
        wrist.y > pelvis.y && wrist.y < neck.y,
        "waist to chest: {wrist}"
    );
    // every feedback message of `bmlr run`, in time order, with the time it was sent
    let (_, run, _) = common::bmlr(&["run", WELCOME], "");
    let feedback = d["feedback"].as_array().unwrap();
    assert_eq!(feedback.len(), run.lines().count());
    let sent: Vec<f64> = feedback
        .iter()
        .map(|m| m["time"].as_f64().unwrap())
        .collect();
    assert!(sent.windows(2).all(|w| w[1] >= w[0]));
    let stroke_message = (feedback.iter())
        .find(|m| {
            m["text"]
                .as_str()
                .unwrap()
                .contains(r#"id="greet:beat:stroke""#)
        })
        .unwrap();
    assert!((stroke_message["time"].as_f64().unwrap() - 0.821).abs() < 1e-3);
    assert_eq!(stroke_message["kind"], "syncPointProgress");
    // the timeline picture and where its times are
    assert!(d["timeline"]["svg"].as_str().unwrap().starts_with("<svg"));
    assert_eq!(d["timeline"]["axis"]["t0"], 0.0);
    assert!((d["timeline"]["axis"]["t1"].as_f64().unwrap() - 2.882).abs() < 1e-3);
    // the world's points, and the mannequin's boxes (one per bone and the head)
    assert_eq!(
        d["world"]["points"]["bluebox"],
        serde_json::json!([0.6, 1.2, 1.2])
    );
    assert_eq!(d["segments"].as_array().unwrap().len(), 57);
    assert!(page.contains("bmlr view: ready"));
}

#[test]
fn the_page_is_the_same_for_the_same_input_and_shows_moving_world_points() {
    let args = ["--world", "fixtures/examples/world.json", WELCOME];
    let (a, _) = page("view-world-a", &args);
    let (b, _) = page("view-world-b", &args);
    assert!(a == b, "byte-identical pages");
    let d = data(&a);
    let paths = d["world"]["paths"].as_object().unwrap();
    assert!(!paths.is_empty(), "world.json has a moving point");
    for keys in paths.values() {
        assert!(keys[0][1].as_array().unwrap().len() == 3);
    }
}

#[test]
fn a_run_without_a_valid_block_shows_the_character_standing_and_exits_1() {
    let dir = scratch("view-invalid");
    let (code, _, err) = common::bmlr(
        &["view", "--out", dir.to_str().unwrap(), "-"],
        "<bml id=\"oops\"><gesture",
    );
    assert_eq!(code, 1, "{err}");
    let d = data(&std::fs::read_to_string(dir.join("index.html")).unwrap());
    assert_eq!(d["header"]["characters"], serde_json::json!([""]));
    let warning = &d["feedback"][0];
    assert_eq!(warning["kind"], "warningFeedback", "{d}");
}

#[test]
fn the_page_is_served_on_loopback_only() {
    let (code, _, err) = common::bmlr(&["view", "--serve", "0.0.0.0:0", WELCOME], "");
    assert_eq!(code, 2);
    assert!(err.contains("not a loopback address"), "{err}");
    let (code, _, err) = common::bmlr(
        &["serve", "--tcp", "127.0.0.1:0", "--view", "0.0.0.0:0"],
        "",
    );
    assert_eq!(code, 2);
    assert!(
        err.contains("--view") && err.contains("not a loopback address"),
        "{err}"
    );
    let (code, _, err) = common::bmlr(&["view", WELCOME], "");
    assert_eq!(code, 2, "--out or --serve is needed: {err}");
}

/// A `bmlr` child process, killed when dropped, and the address it printed on stderr.
struct Server {
    child: Child,
    lines: Vec<String>,
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// Starts `bmlr ARGS` and reads stderr until `n` lines have come.
fn spawn(args: &[&str], n: usize) -> Server {
    let mut child = Command::new(env!("CARGO_BIN_EXE_bmlr"))
        .args(args)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut err = BufReader::new(child.stderr.take().unwrap());
    let lines = (0..n)
        .map(|_| {
            let mut line = String::new();
            err.read_line(&mut line).unwrap();
            line.trim().to_string()
        })
        .collect();
    Server { child, lines }
}

/// The address after `prefix` in one of the lines.
fn address(lines: &[String], prefix: &str) -> String {
    let line = lines
        .iter()
        .find(|l| l.starts_with(prefix))
        .unwrap_or_else(|| panic!("{lines:?}"));
    let rest = &line[prefix.len()..];
    rest.trim_start_matches("http://")
        .split(['/', ' '])
        .next()
        .unwrap()
        .to_string()
}

/// GET `path` from `addr`: (status line, body).
fn get(addr: &str, path: &str) -> (String, Vec<u8>) {
    let mut s = TcpStream::connect(addr).unwrap();
    write!(s, "GET {path} HTTP/1.1\r\nHost: {addr}\r\n\r\n").unwrap();
    let mut all = Vec::new();
    s.read_to_end(&mut all).unwrap();
    let split = all.windows(4).position(|w| w == b"\r\n\r\n").unwrap();
    let head = String::from_utf8_lossy(&all[..split]).into_owned();
    (
        head.lines().next().unwrap().to_string(),
        all[split + 4..].to_vec(),
    )
}

#[test]
fn view_serve_serves_the_same_page() {
    let (written, _) = page("view-served", &[WELCOME]);
    let server = spawn(&["view", "--serve", "127.0.0.1:0", WELCOME], 1);
    let addr = address(&server.lines, "bmlr view: serving ");
    let (status, body) = get(&addr, "/");
    assert_eq!(status, "HTTP/1.1 200 OK");
    assert!(
        body == written.as_bytes(),
        "the served page is the written one"
    );
    let (status, body) = get(&addr, "/three-LICENSE.txt");
    assert_eq!(status, "HTTP/1.1 200 OK");
    assert!(String::from_utf8_lossy(&body).contains("MIT License"));
    assert_eq!(get(&addr, "/elsewhere").0, "HTTP/1.1 404 Not Found");
}

#[test]
fn the_live_view_streams_frames_and_feedback_as_blocks_arrive() {
    let server = spawn(
        &["serve", "--tcp", "127.0.0.1:0", "--view", "127.0.0.1:0"],
        2,
    );
    let port = address(&server.lines, "bmlr serve: listening on ");
    let view = address(&server.lines, "bmlr serve: live view on ");
    let (status, body) = get(&view, "/");
    assert_eq!(status, "HTTP/1.1 200 OK");
    let d = data(&String::from_utf8(body).unwrap());
    assert_eq!(d["live"], true);
    let header = d["header"].clone();
    // the default character is shown as the default avatar: its moving nodes by name
    let wiring = &d["liveAvatars"][0];
    assert_eq!(wiring["id"], "");
    let glb = {
        use base64::Engine as _;
        let text = d["avatars"][0].as_str().unwrap();
        base64::engine::general_purpose::STANDARD
            .decode(text)
            .unwrap()
    };
    let model = bml_realizer::character::avatar::Model::from_glb("live", &glb).unwrap();
    let moving: Vec<String> = (wiring["moving"].as_array().unwrap().iter())
        .map(|i| model.nodes[i.as_u64().unwrap() as usize].name.clone())
        .collect();
    let skeleton = bml_realizer::character::body::Skeleton::adult();
    let retarget = bml_realizer::character::avatar::Retarget::new(&model, &skeleton, None).unwrap();
    let targets: u64 = (wiring["morphs"].as_array().unwrap().iter())
        .map(|m| m[1].as_u64().unwrap())
        .sum();
    let (mut socket, _) = tungstenite::connect(format!("ws://{view}/live")).unwrap();
    let mut client = TcpStream::connect(&port).unwrap();
    let block = format!(
        r#"<bml {NS} id="hi"><gesture id="g" lexeme="WAVE" mode="RIGHT_HAND" start="0" end="1.5"/></bml>"#
    );
    writeln!(client, "{block}").unwrap();
    // until the block ends: every frame, the feedback, the highest the right wrist went
    let deadline = Instant::now() + Duration::from_secs(10);
    let (mut frames, mut ended, mut timeline, mut highest) = (0, false, false, f32::MIN);
    let mut feedback = Vec::new();
    while !ended || !timeline {
        assert!(Instant::now() < deadline, "{frames} frames, {feedback:?}");
        let m: Value = serde_json::from_str(socket.read().unwrap().to_text().unwrap()).unwrap();
        if let Some(frame) = m.get("frame").filter(|f| f["characters"].get("").is_some()) {
            frames += 1;
            let joints = world(&header, frame, "");
            highest = highest.max(at(&joints, "r_wrist").y - at(&joints, "r_shoulder").y);
            // the avatar's nodes turn as their joints (its skeleton is the realizer's), its
            // hips stand where the frame's root is, and every morph target has a weight
            let avatar = &m["avatars"][""];
            let r = avatar["r"].as_array().unwrap();
            assert_eq!(r.len(), 4 * moving.len() + 3);
            for (k, name) in moving.iter().enumerate() {
                let node = quat(&Value::Array(r[4 * k..4 * k + 4].to_vec())).normalize();
                let joint = quat(&frame["characters"][""]["joints"][name]).normalize();
                // (compared component-wise, either sign: an angle from acos is too coarse
                // near 0 in f32)
                let off = (node - joint).length().min((node + joint).length());
                assert!(off < 1e-4, "{name}: {node} vs {joint}");
            }
            let c = &frame["characters"][""];
            let pose = bml_realizer::character::body::Pose {
                root: vec3(&c["root"]),
                rotations: (skeleton.joints().iter())
                    .map(|j| quat(&c["joints"][&j.name]).normalize())
                    .collect(),
            };
            let hips = vec3(&Value::Array(r[r.len() - 3..].to_vec()));
            let expected = retarget.pose(&pose).hips.1;
            assert!(
                hips.distance(expected) < 1e-4,
                "hips {hips}, not {expected}"
            );
            assert_eq!(avatar["w"].as_array().unwrap().len() as u64, targets);
        }
        if let Some(f) = m.get("feedback") {
            let text = f["text"].as_str().unwrap().to_string();
            ended |= text.contains(r#"id="hi:end""#);
            feedback.push(text);
        }
        timeline |= ended && m.get("timeline").is_some();
    }
    assert!(frames >= 30, "about 30 frames a second: {frames} in 1.5 s");
    assert!(
        highest > 0.0,
        "the wave raised the wrist above the shoulder: {highest}"
    );
    assert!(feedback.iter().any(|t| t.contains(r#"id="hi:g:stroke""#)));
}

#[test]
#[ignore = "needs Debian's chromium; .ci/run installs it and runs this with --ignored"]
fn headless_chromium_draws_the_character_and_the_beat_moves_the_arm() {
    // without the idle layer, so that only the gesture moves between the two pictures
    let (_, dir) = page("view-browser", &["--no-idle", WELCOME]);
    let url = |t: &str| format!("file://{}#t={t}", dir.join("index.html").display());
    let (dom, console) = browse(&url("0"), "--dump-dom");
    assert!(
        dom.contains("<title>bmlr view: ready</title>"),
        "{}",
        &dom[..dom.len().min(400)]
    );
    assert!(console.is_empty(), "the page logs nothing: {console:?}");
    // the feedback list at the cursor, to the millisecond it prints: at 0.821 s the stroke
    // the feedback reports at 0.821 (0.8213 s) is shown, a millisecond earlier it is not
    let stroke_shown = |t: &str| {
        let (dom, _) = browse(&url(t), "--dump-dom");
        let line = (dom.lines())
            .flat_map(|l| l.split("<li"))
            .find(|li| {
                li.contains("greet:beat:stroke&quot;") || li.contains(r#"greet:beat:stroke""#)
            })
            .unwrap_or_else(|| panic!("no stroke message in the page at {t}"))
            .to_string();
        !line.contains("hidden")
    };
    assert!(stroke_shown("0.821"), "the stroke is not listed at 0.821 s");
    assert!(
        !stroke_shown("0.820"),
        "the stroke is listed before it happens"
    );
    let shots: Vec<Shot> = ["0", "0.821"]
        .iter()
        .map(|t| {
            let out = dir.join(format!("t{t}.png"));
            let (_, console) = browse(&url(t), &format!("--screenshot={}", out.display()));
            assert!(console.is_empty(), "at t={t}: {console:?}");
            Shot::load(&out)
        })
        .collect();
    let (rest, beat) = (&shots[0], &shots[1]);
    assert_eq!((rest.0, rest.1), (1280, 720));
    // the stage's background, taken at its top right corner
    let background = rest.px(880, 60);
    let body = (410, 490, 60, 400);
    let empty = (620, 880, 60, 240);
    let drawn = rest.share(body, |x, y| far(rest.px(x, y), background));
    let blank = rest.share(empty, |x, y| far(rest.px(x, y), background));
    assert!(
        drawn > 0.5,
        "the figure stands in the middle: {drawn:.2} of its box drawn"
    );
    assert!(blank < 0.05, "beside it, the background: {blank:.2} drawn");
    // the right arm (on the left of the picture) comes up in front at the stroke; the legs stay
    let arm = (330, 420, 130, 200);
    let legs = (410, 490, 300, 400);
    let moved = |b| rest.share(b, |x, y| far(rest.px(x, y), beat.px(x, y)));
    let (arm_moved, legs_moved) = (moved(arm), moved(legs));
    assert!(
        arm_moved > 0.15,
        "the arm moved: {arm_moved:.2} of its box changed"
    );
    assert!(
        legs_moved < 0.01,
        "the legs stayed: {legs_moved:.2} changed"
    );
    eprintln!(
        "figure {drawn:.2} drawn, background {blank:.2}, arm {arm_moved:.2} changed, legs {legs_moved:.2}"
    );
}

/// With `#com` the page of balance.xml draws the centre of mass (a red ball with a line down to
/// the floor, between the feet) and the support polygon; without it, no such red.
#[test]
#[ignore = "needs Debian's chromium; .ci/run installs it and runs this with --ignored"]
fn headless_chromium_draws_the_centre_of_mass_when_asked() {
    let (_, dir) = page("view-com", &["--no-idle", "fixtures/examples/balance.xml"]);
    let shot = |hash: &str| {
        let url = format!("file://{}#t=1.8{hash}", dir.join("index.html").display());
        let out = dir.join(format!("com{}.png", hash.len()));
        let (_, console) = browse(&url, &format!("--screenshot={}", out.display()));
        assert!(console.is_empty(), "{hash}: {console:?}");
        Shot::load(&out)
    };
    let (plain, marked) = (shot(""), shot("&com"));
    // the marks' red (0xd03030), in the column under the body
    let red = |s: &Shot| {
        s.share((400, 500, 60, 700), |x, y| {
            let [r, g, b] = s.px(x, y);
            r > 180 && g < 90 && b < 90
        })
    };
    let (without, with) = (red(&plain), red(&marked));
    eprintln!("red under the body: {without:.4} without #com, {with:.4} with it");
    assert!(without < 1e-4, "red without #com: {without}");
    assert!(with > 5e-4, "no centre of mass drawn: {with}");
}

/// The camera looks at the characters where the world places them: Bob alone, 3 m from the
/// origin, stands in the middle of the picture; with Alice, both are drawn, apart.
#[test]
#[ignore = "needs Debian's chromium; .ci/run installs it and runs this with --ignored"]
fn headless_chromium_frames_characters_where_they_stand() {
    // the page shows every character the world places: Bob alone is in a world of his own
    let dir = scratch("view-world");
    let (alone, both) = (dir.join("bob.json"), dir.join("world.json"));
    let bob = r#""Bob": {"position": [2.4, 0, 1.8], "facing": -120}"#;
    std::fs::write(&alone, format!(r#"{{"characters": {{{bob}}}}}"#)).unwrap();
    let alice = r#""Alice": {"position": [0, 0, 0]}"#;
    std::fs::write(&both, format!(r#"{{"characters": {{{alice}, {bob}}}}}"#)).unwrap();
    let shot = |name: &str, files: &[&str]| {
        let world = if files.len() == 1 { &alone } else { &both };
        let mut args = vec!["--no-idle", "--world", world.to_str().unwrap()];
        args.extend_from_slice(files);
        let (_, dir) = page(name, &args);
        let url = format!("file://{}#t=0", dir.join("index.html").display());
        let out = dir.join("shot.png");
        let (_, console) = browse(&url, &format!("--screenshot={}", out.display()));
        assert!(console.is_empty(), "{name}: {console:?}");
        Shot::load(&out)
    };
    let bob = shot("view-bob", &["fixtures/examples/two-bob.xml"]);
    let background = bob.px(880, 60);
    let drawn = |s: &Shot, b| s.share(b, |x, y| far(s.px(x, y), background));
    let middle = drawn(&bob, (410, 490, 60, 400));
    assert!(
        middle > 0.3,
        "Bob is not in the middle: {middle:.2} of its box drawn"
    );
    let both = shot(
        "view-two",
        &[
            "fixtures/examples/two-alice.xml",
            "fixtures/examples/two-bob.xml",
        ],
    );
    // the stage's middle lies between them; each stands to one side of it
    let (left, right) = (
        drawn(&both, (300, 440, 100, 330)),
        drawn(&both, (450, 600, 100, 330)),
    );
    eprintln!("Bob alone: {middle:.2} drawn; two: {left:.2} left, {right:.2} right");
    assert!(
        left > 0.1 && right > 0.1,
        "not both drawn: {left:.2}, {right:.2}"
    );
}

/// A walker stays in view and moves across it; the obstacles are drawn. The example walks round
/// a table to a door on the right: the figure's dark suit is far to the right at the door.
#[test]
#[ignore = "needs Debian's chromium; .ci/run installs it and runs this with --ignored"]
fn headless_chromium_follows_a_walker_and_draws_the_obstacles() {
    let (_, dir) = page(
        "view-walk",
        &[
            "--world",
            "fixtures/examples/room.json",
            "fixtures/examples/walk-to-door.xml",
        ],
    );
    let shot = |t: &str| {
        let url = format!("file://{}#t={t}", dir.join("index.html").display());
        let out = dir.join(format!("walk{t}.png"));
        let (_, console) = browse(&url, &format!("--screenshot={}", out.display()));
        assert!(console.is_empty(), "{t}: {console:?}");
        Shot::load(&out)
    };
    // the mean x of the shirt's blue pixels in the 3D view (the avatar's shirt, or the
    // mannequin's suit; the background, floor and table are grey, the points orange)
    let suit = |s: &Shot| {
        let (mut sum, mut n) = (0usize, 0usize);
        for y in 0..430 {
            for x in 0..895 {
                let [r, _, b] = s.px(x, y);
                if u16::from(b) > u16::from(r) + 40 {
                    sum += x;
                    n += 1;
                }
            }
        }
        assert!(n > 500, "no figure drawn ({n} pixels)");
        sum as f64 / n as f64
    };
    let (start, door) = (shot("0.5"), shot("6.5"));
    let (a, b) = (suit(&start), suit(&door));
    eprintln!("the walker's suit at x = {a:.0} px, then {b:.0} px");
    assert!(
        b - a > 150.0,
        "the walker did not cross the view: {a} → {b}"
    );
    // the table: grey, between the two places
    let grey = start.share((380, 520, 250, 380), |x, y| {
        let [r, g, b] = start.px(x, y);
        let (lo, hi) = (r.min(g).min(b), r.max(g).max(b));
        hi - lo < 25 && (100..200).contains(&lo)
    });
    assert!(grey > 0.3, "no table drawn: {grey:.2}");
}

/// The default avatar's face close up (#face): the mouth open on "aa" at 0.3 s and pressed on
/// "PP" at 1.2 s of welcome.xml; the eyes (no idle blinks) stay as they are.
#[test]
#[ignore = "needs Debian's chromium; .ci/run installs it and runs this with --ignored"]
fn headless_chromium_shows_the_avatar_s_mouth_speaking() {
    let (_, dir) = page("view-mouth", &["--no-idle", WELCOME]);
    let shot = |t: &str| {
        let url = format!("file://{}#t={t}&face", dir.join("index.html").display());
        let out = dir.join(format!("face{t}.png"));
        let (_, console) = browse(&url, &format!("--screenshot={}", out.display()));
        assert!(console.is_empty(), "{t}: {console:?}");
        Shot::load(&out)
    };
    let (open, pressed) = (shot("0.3"), shot("1.2"));
    let changed = |b| open.share(b, |x, y| far(open.px(x, y), pressed.px(x, y)));
    let background = open.px(880, 60);
    let face = open.share((340, 500, 200, 380), |x, y| far(open.px(x, y), background));
    let (mouth, eyes) = (changed((370, 480, 300, 365)), changed((330, 490, 215, 255)));
    eprintln!("face {face:.2} drawn, mouth {mouth:.2} changed, eyes {eyes:.2}");
    assert!(face > 0.6, "no face close up: {face:.2} of its box drawn");
    assert!(mouth > 0.1, "the mouth did not move: {mouth:.2} changed");
    assert!(eyes < 0.02, "the eyes moved: {eyes:.2} changed");
}

/// The live page of `bmlr serve --view` draws the default character as the default avatar (its
/// light-blue shirt; the mannequin has none) while a block plays.
#[test]
#[ignore = "needs Debian's chromium; .ci/run installs it and runs this with --ignored"]
fn headless_chromium_draws_the_live_view_s_avatar() {
    let server = spawn(
        &["serve", "--tcp", "127.0.0.1:0", "--view", "127.0.0.1:0"],
        2,
    );
    let port = address(&server.lines, "bmlr serve: listening on ");
    let view = address(&server.lines, "bmlr serve: live view on ");
    let mut client = TcpStream::connect(&port).unwrap();
    let block = format!(
        r#"<bml {NS} id="hi"><gesture id="g" lexeme="WAVE" mode="RIGHT_HAND" start="0" end="30"/></bml>"#
    );
    writeln!(client, "{block}").unwrap();
    let out = scratch("live-avatar").join("live.png");
    let (_, console) = browse(
        &format!("http://{view}/"),
        &format!("--screenshot={}", out.display()),
    );
    assert!(console.is_empty(), "{console:?}");
    let shot = Shot::load(&out);
    let shirt = shot.share((0, 900, 0, 430), |x, y| {
        let [r, g, b] = shot.px(x, y);
        b > 180 && r < 150 && g > 120
    });
    eprintln!("shirt {shirt:.4} of the view");
    assert!(
        shirt > 0.004,
        "no avatar drawn: {shirt:.4} of the view is its shirt"
    );
}
