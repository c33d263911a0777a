//! Stick-figure pictures of a pose (SVG): the body seen from the front and from its right side,
//! every bone a line, the head a circle, the right side drawn red. For documentation (the lexicon's
//! stroke poses in `docs/bml-support.md`) and for looking at a pose without a 3D viewer.

use std::fmt::Write as _;

use glam::Vec3;

use super::pose::Pose;
use super::skeleton::Skeleton;

/// Pixels per metre.
const SCALE: f32 = 100.0;
/// Each view's width, pixels.
const VIEW_W: f32 = 140.0;
/// The picture's height above the title, pixels.
const HEIGHT: f32 = 200.0;

/// An SVG of `pose` on `skeleton`: front view (the character facing the viewer, its left on the
/// viewer's right) beside a side view (facing right), with `title` under them.
pub fn svg(skeleton: &Skeleton, pose: &Pose, title: &str) -> String {
    let world = pose.world(skeleton);
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="sans-serif">"#,
        w = 2.0 * VIEW_W,
        h = HEIGHT + 16.0
    );
    let _ = writeln!(s, r#"<rect width="100%" height="100%" fill="white"/>"#);
    // front: x to the right as the viewer sees it (the character's left is +x, facing us)
    let front = |p: Vec3| (VIEW_W / 2.0 + p.x * SCALE, HEIGHT - 10.0 - p.y * SCALE);
    let side = |p: Vec3| (VIEW_W * 1.5 + p.z * SCALE, HEIGHT - 10.0 - p.y * SCALE);
    for view in [&front as &dyn Fn(Vec3) -> (f32, f32), &side] {
        for (i, j) in skeleton.joints().iter().enumerate() {
            let Some(parent) = j.parent else { continue };
            let ((x1, y1), (x2, y2)) = (view(world.positions[parent]), view(world.positions[i]));
            let colour = if j.name.starts_with("r_") {
                "#c0392b"
            } else {
                "#222"
            };
            let finger = ["thumb", "index", "middle", "ring", "pinky"];
            let width = if finger.iter().any(|f| j.name.contains(f)) {
                1.0
            } else {
                2.0
            };
            let _ = writeln!(
                s,
                r#"<line x1="{x1:.1}" y1="{y1:.1}" x2="{x2:.1}" y2="{y2:.1}" stroke="{colour}" stroke-width="{width}" stroke-linecap="round"/>"#
            );
        }
        if let Some(head) = skeleton.joint("skullbase") {
            let (x, y) =
                view(world.positions[head] + world.orientations[head] * Vec3::new(0.0, 0.1, 0.02));
            let _ = writeln!(
                s,
                r##"<circle cx="{x:.1}" cy="{y:.1}" r="{:.1}" fill="none" stroke="#222" stroke-width="2"/>"##,
                0.1 * SCALE
            );
        }
    }
    let _ = writeln!(
        s,
        r##"<text x="{:.1}" y="{:.1}" font-size="12" text-anchor="middle" fill="#333">{}</text>"##,
        VIEW_W,
        HEIGHT + 10.0,
        title.replace('&', "&amp;").replace('<', "&lt;")
    );
    s.push_str("</svg>\n");
    s
}
