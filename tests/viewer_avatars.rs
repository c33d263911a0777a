//! Avatars others published, drawn by the viewer page in headless Chromium (Debian's
//! `chromium`; `#[ignore]`d here, `.ci/run` runs it with `--ignored`): CesiumMan with its bone
//! map is drawn in its own texture's colours, and its arm moves between rest and the beat.

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
