//! The realized gait measured as gait laboratories measure people: a straight walk at STROLL,
//! WALK and RUN realized at 240 frames a second, each frame's joint places by forward
//! kinematics, the left leg's sagittal angles (knee flexion, hip flexion against the pelvis,
//! ankle dorsiflexion against its rest) over the gait cycles of the steady part of the walk,
//! cycles cut at the left foot's contact. Prints, per manner, the values the published norms
//! give (knee at contact, loading peak, least stance flexion, swing peak and when; hip at
//! contact, greatest extension, range; ankle at contact, in loading, greatest stance
//! dorsiflexion, at toe-off; the pelvis's rise; the stance fraction), averaged over cycles.
//!
//! Run: `cargo run --release --example gait_norms`

use bml_realizer::body::{Pose, Skeleton};
use bml_realizer::realizer::Realizer;
use glam::{Quat, Vec3};

const FPS: f64 = 240.0;

/// One frame's measures of the left leg.
#[derive(Clone, Copy, Debug)]
struct Sample {
    knee: f32,
    hip: f32,
    ankle: f32,
    pelvis_y: f32,
    contact: bool,
}

fn main() {
    let skeleton = Skeleton::adult();
    let j = |n: &str| skeleton.joint(n).unwrap();
    let (hip, knee, ankle, ball) = (
        j("l_hip"),
        j("l_knee"),
        j("l_talocrural"),
        j("l_metatarsal"),
    );
    let rest = Pose::rest(&skeleton).world(&skeleton);
    let rest_ankle_angle = sagittal_angle(
        rest.positions[ankle] - rest.positions[knee],
        rest.positions[ball] - rest.positions[ankle],
    );
    let rest_ball_y = rest.positions[ball].y;
    // the heel: under the ankle on the floor, 5 cm behind it, at rest (in the foot's frame)
    let heel_offset =
        rest.orientations[ankle].inverse() * Vec3::new(0.0, -rest.positions[ankle].y, -0.05);
    for (manner, distance) in [("STROLL", 20), ("WALK", 30), ("RUN", 60)] {
        let bml = format!(
            r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="b"><locomotion id="w" target="0,{distance}" manner="{manner}"/></bml>"#
        );
        let mut r = Realizer::new().with_idle(false);
        r.perform_bml(&bml).unwrap();
        let mut samples = Vec::new();
        let seconds = match manner {
            "RUN" => 16.0,
            _ => 18.0,
        };
        for i in 0..(seconds * FPS) as usize {
            let t = i as f64 / FPS;
            let frame = r.tick(t);
            let world = frame.poses[0].pose.world(&skeleton);
            let p = |k: usize| world.positions[k];
            let pelvis = world.orientations[0];
            let heel = p(ankle) + world.orientations[ankle] * heel_offset;
            // on the ground: the heel or the ball of the foot down
            let contact = heel.y < 0.02 || p(ball).y < rest_ball_y + 0.01;
            let thigh = p(knee) - p(hip);
            let down = pelvis * Vec3::NEG_Y;
            samples.push(Sample {
                knee: 180.0
                    - (p(hip) - p(knee))
                        .angle_between(p(ankle) - p(knee))
                        .to_degrees(),
                hip: signed_forward(down, thigh, pelvis),
                ankle: rest_ankle_angle - sagittal_angle(p(ankle) - p(knee), p(ball) - p(ankle)),
                pelvis_y: frame.poses[0].pose.root.y,
                contact,
            });
        }
        report(manner, &samples);
    }
}

/// The angle (degrees) from `a` to `b` in the sagittal (y, z) plane, positive turning
/// forward (+z) from down.
fn sagittal_angle(a: Vec3, b: Vec3) -> f32 {
    let angle = |v: Vec3| v.z.atan2(-v.y);
    (angle(b) - angle(a)).to_degrees()
}

/// How far (degrees) `thigh` points forward of `down`, in the pelvis's sagittal plane.
fn signed_forward(down: Vec3, thigh: Vec3, pelvis: Quat) -> f32 {
    let to_pelvis = pelvis.inverse();
    let (d, t) = (to_pelvis * down, to_pelvis * thigh);
    sagittal_angle(Vec3::new(0.0, d.y, d.z), Vec3::new(0.0, t.y, t.z))
}

fn report(manner: &str, s: &[Sample]) {
    // contacts (heel strikes) of the left foot: down after a tenth of a second in the air
    let air = (0.1 * FPS) as usize;
    let strikes: Vec<usize> = (air..s.len())
        .filter(|&i| s[i].contact && s[i - air..i].iter().all(|x| !x.contact))
        .collect();
    // the steady part: drop the first two and the last two cycles
    if strikes.len() < 6 {
        println!("{manner}: only {} strikes", strikes.len());
        return;
    }
    let cycles: Vec<(usize, usize)> = strikes[2..strikes.len() - 2]
        .windows(2)
        .map(|w| (w[0], w[1]))
        .collect();
    let mut rows: Vec<[f32; 15]> = Vec::new();
    for &(a, b) in &cycles {
        let c = &s[a..b];
        let n = c.len();
        let at = |f: f32| ((f * n as f32) as usize).min(n - 1);
        let span = |f0: f32, f1: f32| &c[at(f0)..at(f1).max(at(f0) + 1)];
        let max = |v: &[Sample], g: fn(&Sample) -> f32| v.iter().map(g).fold(f32::MIN, f32::max);
        let min = |v: &[Sample], g: fn(&Sample) -> f32| v.iter().map(g).fold(f32::MAX, f32::min);
        let toe_off = (0..n)
            .find(|&i| c[i..(i + air).min(n)].iter().all(|x| !x.contact))
            .unwrap_or(n);
        let stance = toe_off as f32 / n as f32;
        let (swing_peak, swing_at) = c
            .iter()
            .enumerate()
            .map(|(i, x)| (x.knee, i))
            .fold((f32::MIN, 0), |m, v| if v.0 > m.0 { v } else { m });
        let hips: Vec<f32> = c.iter().map(|x| x.hip).collect();
        let hip_max = hips.iter().copied().fold(f32::MIN, f32::max);
        let hip_min = hips.iter().copied().fold(f32::MAX, f32::min);
        rows.push([
            c[0].knee,
            max(span(0.0, 0.2), |x| x.knee),
            min(span(0.15, stance), |x| x.knee),
            swing_peak,
            swing_at as f32 / n as f32 * 100.0,
            c[0].hip,
            hip_min,
            hip_max - hip_min,
            c[0].ankle,
            min(span(0.0, 0.15), |x| x.ankle),
            max(span(0.1, stance), |x| x.ankle),
            min(span(stance - 0.05, stance + 0.08), |x| x.ankle),
            max(c, |x| x.pelvis_y) - min(c, |x| x.pelvis_y),
            stance * 100.0,
            (b - a) as f32 / FPS as f32,
        ]);
    }
    let names = [
        "knee at contact (deg)",
        "knee loading peak",
        "knee least in stance",
        "knee swing peak",
        "  its time (% cycle)",
        "hip at contact",
        "hip greatest extension",
        "hip range",
        "ankle at contact",
        "ankle least in loading",
        "ankle greatest stance dorsiflexion",
        "ankle at toe-off",
        "pelvis rise (m)",
        "stance (% cycle)",
        "cycle (s)",
    ];
    println!("{manner}: {} cycles", rows.len());
    for (k, name) in names.iter().enumerate() {
        let v: Vec<f32> = rows.iter().map(|r| r[k]).collect();
        let mean = v.iter().sum::<f32>() / v.len() as f32;
        let (lo, hi) = v
            .iter()
            .fold((f32::MAX, f32::MIN), |(l, h), &x| (l.min(x), h.max(x)));
        println!("  {name:<36} {mean:8.3}   ({lo:.3} … {hi:.3})");
    }
}
