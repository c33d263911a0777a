//! A side view of one steady WALK cycle as the realizer makes it, beside people's key poses:
//! the realized walk at 240 frames a second, one cycle cut at the left foot's contact, drawn at
//! the moments of the gait's phases (initial contact, loading response, mid-stance, terminal
//! stance, toe-off, initial, mid and terminal swing) by forward kinematics in the sagittal
//! plane (left leg red, right leg grey, trunk black); under each, the left leg posed at the
//! normal mean angles of that moment (green). Writes `docs/gait-poses.svg`.
//!
//! Run: `cargo run --release --example gait_poses`

use bml_realizer::character::body::Skeleton;
use bml_realizer::realizer::Realizer;
use glam::{Vec2, Vec3};
use std::fmt::Write;

const FPS: f64 = 240.0;
/// Pixels a metre.
const SCALE: f32 = 190.0;

/// The gait's phases drawn: name, moment (% of the cycle from the left heel strike), and the
/// left leg's normal mean angles then (degrees: hip flexion against the pelvis, knee flexion,
/// ankle dorsiflexion), read off the normal curves of adults at their own pace (Kadaba,
/// Ramakrishnan & Wootten 1990; Perry's *Gait Analysis* 1992 for the phases' moments).
const PHASES: [(&str, f32, [f32; 3]); 8] = [
    ("contact", 0.0, [30.0, 5.0, 0.0]),
    ("loading", 12.0, [28.0, 18.0, -7.0]),
    ("mid-stance", 31.0, [8.0, 5.0, 5.0]),
    ("term. stance", 50.0, [-8.0, 8.0, 10.0]),
    ("toe-off", 62.0, [0.0, 38.0, -15.0]),
    ("init. swing", 73.0, [20.0, 60.0, -8.0]),
    ("mid-swing", 87.0, [30.0, 30.0, 0.0]),
    ("term. swing", 100.0, [30.0, 5.0, 0.0]),
];

/// The pelvis's forward tilt (degrees) the norms' hip angles are measured against.
const TILT: f32 = 10.0;

/// One frame in the sagittal plane (forward, up; metres, forward from the root): the left and
/// the right leg (hip, knee, ankle, ball) and the trunk (root, mid-back, skull base).
type Figure = ([[Vec2; 4]; 2], [Vec2; 3]);

fn main() {
    let skeleton = Skeleton::adult();
    let j = |n: &str| skeleton.joint(n).expect("the adult's joints");
    let legs = ["l", "r"].map(|s| {
        [
            j(&format!("{s}_hip")),
            j(&format!("{s}_knee")),
            j(&format!("{s}_talocrural")),
            j(&format!("{s}_metatarsal")),
        ]
    });
    let trunk = [0, j("vt6"), j("skullbase")];
    let bml = r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="b"><locomotion id="w" target="0,30" manner="WALK"/></bml>"#;
    let mut r = Realizer::new().with_idle(false);
    r.perform_bml(bml).expect("the walk");
    let mut frames: Vec<(Figure, bool)> = Vec::new();
    for i in 0..(14.0 * FPS) as usize {
        let frame = r.tick(i as f64 / FPS);
        let c = &frame.poses[0];
        let world = c.pose.world(&skeleton);
        let root = world.positions[0];
        let side = |p: Vec3| Vec2::new(p.z - root.z, p.y);
        let figure = (
            legs.map(|leg| leg.map(|k| side(world.positions[k]))),
            trunk.map(|k| side(world.positions[k])),
        );
        frames.push((figure, c.contacts.unwrap_or([true, true])[0]));
    }
    let strikes: Vec<usize> = (1..frames.len())
        .filter(|&i| frames[i].1 && !frames[i - 1].1)
        .collect();
    let cycle = &frames[strikes[4]..=strikes[5]];
    let n = cycle.len() - 1;
    let svg = sheet(|pct| cycle[((pct / 100.0) * n as f32).round() as usize].0);
    std::fs::write("docs/gait-poses.svg", svg).expect("write docs/gait-poses.svg");
    println!("wrote docs/gait-poses.svg ({} frames in the cycle)", n);
}

/// The left leg (hip, knee, ankle, ball) at the normal angles `[hip, knee, ankle]` (degrees),
/// the hip at the origin, with the adult's thigh, shin and foot.
fn normal_leg([hip, knee, ankle]: [f32; 3]) -> [Vec2; 4] {
    let (thigh, shin, foot) = (0.42, 0.42, 0.13);
    let along = |deg: f32| Vec2::new(deg.to_radians().sin(), -deg.to_radians().cos());
    let t = hip - TILT;
    let s = t - knee;
    let k = along(t) * thigh;
    let a = k + along(s) * shin;
    // the foot square to the shin, turned toes-up by the dorsiflexion
    let f = (s + ankle).to_radians();
    [Vec2::ZERO, k, a, a + Vec2::new(f.cos(), f.sin()) * foot]
}

/// The contact sheet: a column a phase, the realized figure (from `at`, by % of the cycle)
/// above the normal leg.
fn sheet(at: impl Fn(f32) -> Figure) -> String {
    let (w, h) = (150.0f32, 250.0f32);
    let mut out = String::new();
    let _ = writeln!(
        out,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{}" height="{}" font-family="sans-serif" font-size="11"><rect width="100%" height="100%" fill="white"/>"#,
        w * 8.0,
        2.0 * h + 30.0
    );
    let line = |out: &mut String, pts: &[Vec2], origin: Vec2, colour: &str, width: f32| {
        let p: Vec<String> = pts
            .iter()
            .map(|p| {
                format!(
                    "{:.1},{:.1}",
                    origin.x + p.x * SCALE,
                    origin.y - p.y * SCALE
                )
            })
            .collect();
        let _ = writeln!(
            out,
            r#"<polyline points="{}" fill="none" stroke="{colour}" stroke-width="{width}" stroke-linejoin="round"/>"#,
            p.join(" ")
        );
    };
    for (col, (name, pct, angles)) in PHASES.iter().enumerate() {
        let x = col as f32 * w + w / 2.0;
        let _ = writeln!(
            out,
            r#"<text x="{x}" y="14" text-anchor="middle">{name} ({pct} %)</text>"#
        );
        // realized: the floor at y = 0
        let floor = Vec2::new(x, 20.0 + h - 10.0);
        let ([left, right], trunk) = at(*pct);
        let _ = writeln!(
            out,
            r##"<line x1="{}" x2="{}" y1="{}" y2="{}" stroke="#bbb"/>"##,
            x - w / 2.0 + 8.0,
            x + w / 2.0 - 8.0,
            floor.y,
            floor.y
        );
        line(&mut out, &right, floor, "#999", 3.0);
        line(&mut out, &trunk, floor, "#222", 3.0);
        line(&mut out, &[left[0], right[0]], floor, "#222", 2.0);
        line(&mut out, &left, floor, "#c22", 3.0);
        // normal: the left leg from a hip at the realized hip's height
        let hip = Vec2::new(x, 20.0 + 2.0 * h - 10.0 - left[0].y * SCALE);
        line(&mut out, &normal_leg(*angles), hip, "#2a2", 3.0);
        let _ = writeln!(
            out,
            r##"<line x1="{}" x2="{}" y1="{}" y2="{}" stroke="#bbb"/><text x="{x}" y="{}" text-anchor="middle" fill="#2a2" font-size="10">hip {} knee {} ankle {}</text>"##,
            x - w / 2.0 + 8.0,
            x + w / 2.0 - 8.0,
            20.0 + 2.0 * h - 10.0,
            20.0 + 2.0 * h - 10.0,
            20.0 + 2.0 * h + 6.0,
            angles[0],
            angles[1],
            angles[2]
        );
    }
    let _ = writeln!(out, "</svg>");
    out
}
