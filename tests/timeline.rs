//! Timeline pictures: `bmlr plan --svg` and `bmlr timeline --svg` write well-formed SVG that a real
//! renderer (the pure-Rust `resvg`) draws with every behaviour's lane visible, also for a plan of
//! 50 behaviours.

use std::path::{Path, PathBuf};

fn tmp(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!("bmlr-timeline-{}-{name}", std::process::id()))
}

mod common;

fn bmlr(args: &[&str]) -> (i32, String, String) {
    common::bmlr(args, "")
}

fn well_formed(svg: &Path) -> String {
    let text = std::fs::read_to_string(svg).unwrap();
    let mut r = quick_xml::Reader::from_str(&text);
    loop {
        match r.read_event() {
            Ok(quick_xml::events::Event::Eof) => break,
            Ok(_) => {}
            Err(e) => panic!("{}: not well-formed: {e}", svg.display()),
        }
    }
    text
}

/// Renders with resvg (pure Rust; text is left out) and checks that the picture is drawn: the
/// middle of every behaviour's lane (a 3 px line) is not the white background. Returns the
/// picture's (width, height).
fn render(svg: &Path) -> (u32, u32) {
    use resvg::{tiny_skia, usvg};
    let text = std::fs::read_to_string(svg).unwrap();
    let tree = usvg::Tree::from_str(&text, &usvg::Options::default())
        .unwrap_or_else(|e| panic!("{}: {e}", svg.display()));
    let size = tree.size().to_int_size();
    let mut pixmap = tiny_skia::Pixmap::new(size.width(), size.height()).unwrap();
    resvg::render(&tree, tiny_skia::Transform::default(), &mut pixmap.as_mut());
    let attr = |line: &str, name: &str| -> f32 {
        let at = line.find(&format!(" {name}=\"")).unwrap() + name.len() + 3;
        line[at..].split('"').next().unwrap().parse().unwrap()
    };
    let mut lanes = 0;
    for line in text.lines().filter(|l| l.contains(r#"stroke-width="3""#)) {
        let (x, y) = (
            (attr(line, "x1") + attr(line, "x2")) / 2.0,
            attr(line, "y1"),
        );
        let px = pixmap.pixel(x as u32, y as u32).unwrap();
        let white = px.red() > 240 && px.green() > 240 && px.blue() > 240;
        assert!(
            !white,
            "{}: the lane at ({x}, {y}) is not drawn",
            svg.display()
        );
        lanes += 1;
    }
    assert!(lanes > 0, "{}: no lanes", svg.display());
    (size.width(), size.height())
}

#[test]
fn plan_svg_shows_lanes_syncs_and_constraint_links_and_renders() {
    let svg = tmp("plan.svg");
    let (code, _, err) = bmlr(&[
        "plan",
        "fixtures/realizertester/bml-1/core/testspeechgestures.xml",
        "--svg",
        svg.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("(1 block, 4 behaviours)"), "{err}");
    let text = well_formed(&svg);
    for lane in [
        "welkom (speech)",
        "g1 (gesture)",
        "relaxleft (gesture)",
        "transleft (gesture)",
    ] {
        assert!(text.contains(lane), "{lane}");
    }
    // the six constraints of the block are drawn as links
    assert_eq!(text.matches("stroke-dasharray").count(), 6);
    assert!(text.contains("<title>bml1:g1:start = bml1:welkom:deicticheart1</title>"));
    let (w, h) = render(&svg);
    assert!(w > 1000 && h > 100, "{w}x{h}");
}

#[test]
fn timeline_of_a_log_shows_what_happened_with_warnings() {
    let log = tmp("gaze.log");
    let (_, out, _) = bmlr(&[
        "run",
        "fixtures/realizertester/bml-1/core/testgazeoverlap.xml",
    ]);
    std::fs::write(&log, out).unwrap();
    let svg = tmp("gaze.svg");
    let (code, _, err) = bmlr(&[
        "timeline",
        log.to_str().unwrap(),
        "--svg",
        svg.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let text = well_formed(&svg);
    assert!(text.contains("gaze1 (gaze)"));
    assert!(text.contains("⚠ bml1:gaze2"), "the warning is shown");
    render(&svg);
    // an unreadable log is an error with its line
    std::fs::write(&log, "garbage\n").unwrap();
    let (code, _, err) = bmlr(&[
        "timeline",
        log.to_str().unwrap(),
        "--svg",
        svg.to_str().unwrap(),
    ]);
    assert_eq!(code, 2);
    assert!(err.contains(":1: bad feedback"), "{err}");
}

#[test]
fn fifty_behaviours_stay_readable() {
    let mut body = String::new();
    for i in 0..50 {
        let kind = [
            "gesture lexeme=\"BEAT\"",
            "head lexeme=\"NOD\"",
            "gaze target=\"user\"",
        ][i % 3];
        let start = if i == 0 {
            String::from("0")
        } else {
            format!("b{}:end", i - 1)
        };
        body.push_str(&format!(r#"<{kind} id="b{i}" start="{start}"/>"#));
    }
    let bml = tmp("fifty.xml");
    std::fs::write(
        &bml,
        format!(r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="many">{body}</bml>"#),
    )
    .unwrap();
    let svg = tmp("fifty.svg");
    let (code, _, err) = bmlr(&[
        "plan",
        bml.to_str().unwrap(),
        "--svg",
        svg.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("(1 block, 50 behaviours)"), "{err}");
    well_formed(&svg);
    let (w, h) = render(&svg);
    // one 30 px lane per behaviour, a time axis that keeps 20 px per second at least
    assert!((1500..1700).contains(&h), "{w}x{h}");
    assert!((1200..6000).contains(&w), "{w}x{h}");
}
