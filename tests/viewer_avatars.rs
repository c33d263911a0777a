//! Avatars others published, drawn by the viewer page in headless Chromium (Debian's
//! `chromium`; `#[ignore]`d here, `.ci/run` runs it with `--ignored`): CesiumMan with its bone
//! map is drawn in its own texture's colours, and its arm moves between rest and the beat;
//! walking to the door of `room.json`, CesiumMan and the Cryptovoxels VRM 0.x (white) are
//! drawn going the way the realizer's character goes, towards the door on the screen's right
//! (once, the page played CesiumMan's own walk in place and the VRM walked off behind).

mod browser;
mod common;

use browser::{browse_for, far, page, Shot};

/// A green of CesiumMan's texture (the default avatar and the stage have none).
fn cesium_green([r, g, b]: [u8; 3]) -> bool {
    g > r.saturating_add(25) && g > b.saturating_add(10)
}

#[test]
#[ignore = "needs Debian's chromium; .ci/run installs it and runs this with --ignored"]
fn headless_chromium_draws_cesium_man_in_its_colours_and_moves_it() {
    let (_, dir) = page(
        "view-cesium",
        &[
            "--no-idle",
            "--avatar",
            "fixtures/avatars/cesium-man/CesiumMan.gltf",
            "--bone-map",
            "fixtures/avatars/cesium-man/bone-map.json",
            "fixtures/examples/welcome.xml",
        ],
    );
    let url = |t: &str| format!("file://{}#t={t}", dir.join("index.html").display());
    let (dom, console) = browse_for(&url("0"), "--dump-dom", 30_000);
    assert!(
        dom.contains("<title>bmlr view: ready</title>"),
        "{}",
        &dom[..dom.len().min(400)]
    );
    assert!(console.is_empty(), "the page logs nothing: {console:?}");
    let shots: Vec<Shot> = ["0", "0.821"]
        .iter()
        .map(|t| {
            let out = dir.join(format!("t{t}.png"));
            let (_, console) =
                browse_for(&url(t), &format!("--screenshot={}", out.display()), 30_000);
            assert!(console.is_empty(), "at t={t}: {console:?}");
            Shot::load(&out)
        })
        .collect();
    let (rest, beat) = (&shots[0], &shots[1]);
    // the 3D view: the upper left of the page
    let view = (0, rest.0 / 2, 0, rest.1 / 2);
    // drawn as CesiumMan at both times (a mannequin has none of its green)
    let green = rest.share(view, |x, y| cesium_green(rest.px(x, y)));
    let still = beat.share(view, |x, y| cesium_green(beat.px(x, y)));
    assert!(
        green > 0.002 && still > 0.002,
        "CesiumMan's green: {green:.4} and {still:.4} of the view"
    );
    let moved = rest.share(view, |x, y| far(rest.px(x, y), beat.px(x, y)));
    assert!(
        moved > 0.002,
        "{moved:.4} of the view changed between rest and the beat"
    );
    eprintln!("green {green:.4} of the view, {moved:.4} changed");
}

/// A pixel of the Cryptovoxels avatar: white and greys without the stage's blue.
fn neutral([r, g, b]: [u8; 3]) -> bool {
    r > 120 && r.abs_diff(b) <= 6 && r.abs_diff(g) <= 6
}

/// The mean x (pixels) of the 3D view's pixels for which `is` holds, and their share.
fn centre(shot: &Shot, is: impl Fn([u8; 3]) -> bool) -> (f64, f64) {
    // the 3D view: 900 × 430 of the 1280 × 720 page, above the controls
    let (w, h) = (shot.0 * 900 / 1280, shot.1 * 430 / 720);
    let (mut sum, mut count) = (0.0, 0usize);
    for y in 0..h {
        for x in 0..w {
            if is(shot.px(x, y)) {
                (sum, count) = (sum + x as f64, count + 1);
            }
        }
    }
    (sum / count.max(1) as f64, count as f64 / (w * h) as f64)
}

#[test]
#[ignore = "needs Debian's chromium; .ci/run installs it and runs this with --ignored"]
fn headless_chromium_walks_published_avatars_to_the_door() {
    type Colour = fn([u8; 3]) -> bool;
    let cases: [(&str, &[&str], Colour); 2] = [
        (
            "walk-cesium",
            &[
                "--avatar",
                "fixtures/avatars/cesium-man/CesiumMan.gltf",
                "--bone-map",
                "fixtures/avatars/cesium-man/bone-map.json",
            ],
            cesium_green,
        ),
        (
            "walk-cryptovoxels",
            &["--avatar", "fixtures/avatars/cryptovoxels/cryptovoxels.vrm"],
            neutral,
        ),
    ];
    for (name, avatar, colour) in cases {
        let mut args = vec!["--no-idle", "--world", "fixtures/examples/room.json"];
        args.extend_from_slice(avatar);
        args.push("fixtures/examples/walk-to-door.xml");
        let (_, dir) = page(name, &args);
        let at = |t: &str| {
            let url = format!("file://{}#t={t}", dir.join("index.html").display());
            let out = dir.join(format!("t{t}.png"));
            let (_, console) = browse_for(&url, &format!("--screenshot={}", out.display()), 30_000);
            assert!(console.is_empty(), "{name} at t={t}: {console:?}");
            centre(&Shot::load(&out), colour)
        };
        let ((from, there), (to, still)) = (at("0"), at("4"));
        eprintln!("{name}: x {from:.0} → {to:.0} px; {there:.4}, {still:.4} of the view");
        assert!(
            there > 0.0005 && still > 0.0005,
            "{name}: {there:.4}, {still:.4}"
        );
        assert!(
            to - from > 150.0,
            "{name} moved from x {from:.0} to {to:.0} px"
        );
    }
}
