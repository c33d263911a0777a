//! `bmlr view` of a crowd: more than 16 characters come packed (roots as floats, the moving
//! joints as 16-bit integers) and are drawn as one instanced crowd; the characters the world
//! file places without blocks stand where it places them. The browser test needs Debian's
//! `chromium` (`#[ignore]`d here; `.ci/run` runs it with `--ignored`).

mod browser;
mod common;

use base64::Engine as _;
use browser::{browse, data, page, Shot};
use serde_json::Value;

const WORLD: &str = "fixtures/examples/plaza/world.json";
const PLAZA: &str = "fixtures/examples/plaza";

/// The packed roots: per frame, per character, x y z and the rotation's x y z w.
fn roots(packed: &Value) -> Vec<f32> {
    let bytes = base64::engine::general_purpose::STANDARD
        .decode(packed["roots"].as_str().unwrap())
        .unwrap();
    (bytes.chunks(4))
        .map(|b| f32::from_le_bytes(b.try_into().unwrap()))
        .collect()
}

#[test]
fn a_crowd_page_carries_packed_frames_that_match_the_frames_file() {
    let (page, dir) = page("view-crowd", &["--world", WORLD, "--until", "2", PLAZA]);
    let data = data(&page);
    let packed = &data["packed"];
    assert_eq!(data["frames"], serde_json::json!([]), "no frame lines");
    let ids: Vec<&str> = (packed["characters"].as_array().unwrap().iter())
        .map(|v| v.as_str().unwrap())
        .collect();
    assert_eq!(
        ids.len(),
        43,
        "40 walkers and the 3 talkers the world places"
    );
    let times = packed["times"].as_array().unwrap();
    assert_eq!(times.len(), 61, "0 .. 2 s at 30 fps");
    // 43 are few enough to be drawn as people: the default avatar goes in once
    let avatar = data["crowdAvatar"].as_str().expect("the crowd's avatar");
    assert!(avatar.len() > 1_000_000, "{} bytes of base64", avatar.len());
    let roots = roots(packed);
    assert_eq!(roots.len(), times.len() * ids.len() * 7);
    // the same run's frames file, roots only, at the page's rate
    let frames = dir.join("roots.jsonl");
    let (code, _, err) = common::bmlr(
        &[
            "run",
            "--world",
            WORLD,
            "--until",
            "2",
            "--fps",
            "30",
            "--frames",
            frames.to_str().unwrap(),
            "--frames-roots",
            PLAZA,
        ],
        "",
    );
    assert_eq!(code, 0, "{err}");
    let text = std::fs::read_to_string(&frames).unwrap();
    let lines: Vec<Value> = text
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(lines.len(), 1 + times.len());
    let mut worst = 0f32;
    for (k, line) in lines[1..].iter().enumerate() {
        for (c, id) in ids
            .iter()
            .enumerate()
            .filter(|(_, id)| id.starts_with("walker"))
        {
            let at = &roots[(k * ids.len() + c) * 7..][..3];
            let want = &line["characters"][*id]["root"];
            for (i, v) in at.iter().enumerate() {
                worst = worst.max((v - want[i].as_f64().unwrap() as f32).abs());
            }
        }
    }
    assert!(worst < 1e-5, "packed roots {worst} m off the frames file");
    // a talker stands where the world places it (talker0 at 3.308, 2.846), all along
    let t = ids.iter().position(|id| *id == "talker0").unwrap();
    for k in [0, times.len() - 1] {
        let at = &roots[(k * ids.len() + t) * 7..][..3];
        assert!(
            (at[0] - 3.308).abs() < 1e-4 && (at[2] - 2.846).abs() < 1e-4,
            "{at:?}"
        );
    }
}

#[test]
#[ignore = "needs Debian's chromium; .ci/run installs it and runs this with --ignored"]
fn headless_chromium_draws_the_crowd() {
    let (_, dir) = page(
        "view-crowd-browser",
        &["--world", WORLD, "--until", "3", PLAZA],
    );
    let url = format!("file://{}#t=2", dir.join("index.html").display());
    let out = dir.join("crowd.png");
    let (_, console) = browse(&url, &format!("--screenshot={}", out.display()));
    assert!(console.is_empty(), "{console:?}");
    let shot = Shot::load(&out);
    // the shirts' blue in the 3D view (floor, grid, background and obstacles are grey), and
    // spread over it: figures all over the plaza, not one heap; drawn as people, so with the
    // avatar's dark brown hair and shoes, which the mannequins lack (486 such pixels with
    // people, 1 with mannequins)
    let mut columns = std::collections::BTreeSet::new();
    let (mut n, mut hair) = (0, 0);
    for y in 0..430 {
        for x in 0..895 {
            let [r, g, b] = shot.px(x, y);
            if u16::from(b) > u16::from(r) + 40 {
                n += 1;
                columns.insert(x / 50);
            }
            if u16::from(r) > u16::from(b) + 30 && r < 140 && g < 110 {
                hair += 1;
            }
        }
    }
    eprintln!(
        "{n} shirt pixels in {} of 18 columns, {hair} hair and shoe pixels",
        columns.len()
    );
    assert!(n > 2000, "the crowd is not drawn ({n} shirt pixels)");
    assert!(
        hair > 200,
        "the crowd is not drawn as people ({hair} hair pixels)"
    );
    assert!(
        columns.len() >= 12,
        "the crowd is not spread out: {columns:?}"
    );
}
