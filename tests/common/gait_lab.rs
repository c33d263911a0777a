//! A gait laboratory for the realized walk: a straight walk at a BML manner realized frame by
//! frame, each frame's joint places by forward kinematics, the left leg's sagittal angles (knee
//! flexion, hip flexion against the pelvis, ankle dorsiflexion against its rest), the pelvis's
//! height, list and rotation, and both feet's contacts as the realizer reports them (the force
//! plate); the steady cycles cut at the left foot's contact; per cycle the measures the
//! published norms give, with the norm bands (about mean ± 2 SD, rounded) beside them. Used by
//! `tests/gait_norms.rs` and `examples/gait_norms.rs`.
#![allow(dead_code)] // the test and the example use their own shares

use bml_realizer::character::body::{Pose, Skeleton};
use bml_realizer::realizer::Realizer;
use glam::{Quat, Vec3};

/// One frame's measures.
#[derive(Clone, Copy, Debug)]
pub struct Sample {
    /// Left knee flexion (deg).
    pub knee: f32,
    /// Left hip flexion against the pelvis (deg, extension negative).
    pub hip: f32,
    /// Left ankle dorsiflexion against its rest (deg, plantarflexion negative).
    pub ankle: f32,
    /// The root's height (m).
    pub pelvis_y: f32,
    /// The pelvis's list (deg) and rotation about the vertical (deg).
    pub list: f32,
    /// See `list`.
    pub turn: f32,
    /// Whether the left and the right foot are planted.
    pub contact: [bool; 2],
}

/// Realizes a straight walk of `distance` m at `manner` for `seconds` at `fps` and samples it.
pub fn record(manner: &str, distance: f32, seconds: f64, fps: f64) -> Vec<Sample> {
    let skeleton = Skeleton::adult();
    let bml = format!(
        r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="b"><locomotion id="w" target="0,{distance}" manner="{manner}"/></bml>"#
    );
    let mut r = Realizer::new().with_idle(false);
    r.perform_bml(&bml).unwrap();
    (0..(seconds * fps) as usize)
        .map(|i| {
            let frame = r.tick(i as f64 / fps);
            let character = &frame.poses[0];
            sample(
                &skeleton,
                &character.pose,
                character.contacts.unwrap_or([true, true]),
            )
        })
        .collect()
}

/// The measures of one pose of `skeleton` (the walk along +z), with the feet's `contact`.
pub fn sample(skeleton: &Skeleton, pose: &Pose, contact: [bool; 2]) -> Sample {
    let j = |n: &str| skeleton.joint(n).unwrap();
    let (hip, knee, ankle, ball) = (
        j("l_hip"),
        j("l_knee"),
        j("l_talocrural"),
        j("l_metatarsal"),
    );
    let rest = Pose::rest(skeleton).world(skeleton);
    let rest_ankle = sagittal_angle(
        rest.positions[ankle] - rest.positions[knee],
        rest.positions[ball] - rest.positions[ankle],
    );
    let world = pose.world(skeleton);
    let p = |k: usize| world.positions[k];
    let pelvis = world.orientations[0];
    let side = pelvis * Vec3::X;
    Sample {
        knee: 180.0
            - (p(hip) - p(knee))
                .angle_between(p(ankle) - p(knee))
                .to_degrees(),
        hip: signed_forward(pelvis * Vec3::NEG_Y, p(knee) - p(hip), pelvis),
        // toes toward the shin turn the foot's line forward and up, away from the shin's
        ankle: sagittal_angle(p(ankle) - p(knee), p(ball) - p(ankle)) - rest_ankle,
        pelvis_y: pose.root.y,
        list: side.y.asin().to_degrees(),
        turn: (-side.z).atan2(side.x).to_degrees(),
        contact,
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

/// The steady gait cycles: from each left contact to the next, the first two and the last two
/// dropped (setting off and stopping).
pub fn cycles(s: &[Sample]) -> Vec<&[Sample]> {
    let strikes: Vec<usize> = (1..s.len())
        .filter(|&i| s[i].contact[0] && !s[i - 1].contact[0])
        .collect();
    if strikes.len() < 6 {
        return Vec::new();
    }
    strikes[2..strikes.len() - 2]
        .windows(2)
        .map(|w| &s[w[0]..w[1]])
        .collect()
}

/// The walks measured: manner, distance (m) and how long it is recorded (s), long enough for
/// eight steady cycles or more.
pub const WALKS: [(&str, f32, f64); 3] = [
    ("STROLL", 20.0, 18.0),
    ("WALK", 30.0, 18.0),
    ("RUN", 60.0, 16.0),
];

/// The measures, in the order of [`MEASURES`].
pub const MEASURES: [&str; 22] = [
    "knee at contact (deg)",
    "knee loading peak",
    "knee least in stance",
    "knee swing peak",
    "  its time (% cycle)",
    "hip at contact",
    "hip greatest extension",
    "hip greatest flexion",
    "hip range",
    "ankle at contact",
    "ankle least in loading",
    "ankle greatest stance dorsiflexion",
    "ankle at toe-off",
    "pelvis rise (cm)",
    "pelvis list range (deg)",
    "pelvis rotation range (deg)",
    "stance (% cycle)",
    "double support (% cycle)",
    "cycle (s)",
    "knee range",
    "ankle range",
    "hip at toe-off",
];

/// The measures of one cycle (see [`MEASURES`]); `fps` the frame rate it was sampled at.
pub fn measure(c: &[Sample], fps: f64) -> [f32; 22] {
    let n = c.len();
    let at = |f: f32| ((f * n as f32) as usize).min(n - 1);
    let span = |f0: f32, f1: f32| &c[at(f0)..at(f1).max(at(f0) + 1)];
    let max = |v: &[Sample], g: fn(&Sample) -> f32| v.iter().map(g).fold(f32::MIN, f32::max);
    let min = |v: &[Sample], g: fn(&Sample) -> f32| v.iter().map(g).fold(f32::MAX, f32::min);
    let range = |g: fn(&Sample) -> f32| max(c, g) - min(c, g);
    let toe_off = (1..n).find(|&i| !c[i].contact[0]).unwrap_or(n);
    let stance = toe_off as f32 / n as f32;
    let both = c.iter().filter(|x| x.contact[0] && x.contact[1]).count();
    let argmax = |g: fn(&Sample) -> f32| {
        (0..n).fold(0, |m, i| if g(&c[i]) > g(&c[m]) { i } else { m }) as f32 / n as f32 * 100.0
    };
    let last = &c[toe_off.min(n - 1)];
    [
        c[0].knee,
        max(span(0.0, 0.2), |x| x.knee),
        min(span(0.15, stance), |x| x.knee),
        max(c, |x| x.knee),
        argmax(|x| x.knee),
        c[0].hip,
        min(c, |x| x.hip),
        max(c, |x| x.hip),
        range(|x| x.hip),
        c[0].ankle,
        min(span(0.0, 0.15), |x| x.ankle),
        max(span(0.1, stance), |x| x.ankle),
        min(span(stance - 0.05, stance + 0.08), |x| x.ankle),
        100.0 * range(|x| x.pelvis_y),
        range(|x| x.list),
        range(|x| x.turn),
        stance * 100.0,
        both as f32 / n as f32 * 100.0,
        n as f32 / fps as f32,
        range(|x| x.knee),
        range(|x| x.ankle),
        last.hip,
    ]
}

/// The mean of each measure over `cycles`.
pub fn means(cycles: &[&[Sample]], fps: f64) -> [f32; 22] {
    let mut sum = [0.0f32; 22];
    for c in cycles {
        for (s, v) in sum.iter_mut().zip(measure(c, fps)) {
            *s += v;
        }
    }
    sum.map(|s| s / cycles.len().max(1) as f32)
}

/// A norm band: measure (index into [`MEASURES`]), least and greatest, and its source.
pub type Band = (usize, f32, f32, &'static str);

/// Adults walking at their own pace (about 1.3 m/s): Kadaba, Ramakrishnan & Wootten 1990
/// (J Orthop Res 8:383–392), Perry's *Gait Analysis* (1992) and Winter's *Biomechanics and
/// Motor Control of Human Movement* for the sagittal angles; Gard & Childress 1997 for the
/// pelvis's rise; about mean ± 2 SD, rounded.
pub const WALK: &[Band] = &[
    (0, -2.0, 15.0, "Kadaba 1990"),
    (1, 8.0, 30.0, "Kadaba 1990"),
    (2, -2.0, 15.0, "Kadaba 1990"),
    (3, 50.0, 70.0, "Kadaba 1990"),
    (4, 64.0, 77.0, "Perry 1992"),
    (5, 20.0, 45.0, "Kadaba 1990"),
    (6, -25.0, 0.0, "Kadaba 1990"),
    (8, 32.0, 56.0, "Kadaba 1990"),
    (9, -8.0, 8.0, "Kadaba 1990"),
    (10, -15.0, 0.0, "Kadaba 1990"),
    (11, 4.0, 20.0, "Kadaba 1990"),
    (12, -32.0, -6.0, "Kadaba 1990"),
    (13, 2.4, 6.5, "Gard & Childress 1997"),
    (14, 3.0, 15.0, "Kadaba 1990"),
    (15, 3.0, 20.0, "Kadaba 1990"),
    (16, 56.0, 66.0, "Perry 1992"),
    (17, 14.0, 28.0, "Perry 1992"),
];

/// Slow walking (about 0.8 m/s), where the knee's and hip's excursions are smaller and the
/// stance longer: Schwartz, Rozumalski & Trost 2008 (J Biomech 41:1639–1650, curves
/// stratified by speed), with the walking bands otherwise.
pub const STROLL: &[Band] = &[
    (0, -2.0, 15.0, "Schwartz 2008"),
    (1, 3.0, 25.0, "Schwartz 2008"),
    (2, -2.0, 15.0, "Schwartz 2008"),
    (3, 45.0, 66.0, "Schwartz 2008"),
    (4, 64.0, 80.0, "Schwartz 2008"),
    (5, 15.0, 45.0, "Schwartz 2008"),
    (6, -25.0, 5.0, "Schwartz 2008"),
    (8, 28.0, 52.0, "Schwartz 2008"),
    (9, -8.0, 8.0, "Schwartz 2008"),
    (11, 4.0, 20.0, "Schwartz 2008"),
    (12, -30.0, -4.0, "Schwartz 2008"),
    (13, 1.0, 5.0, "Gard & Childress 1997"),
    (16, 58.0, 70.0, "Schwartz 2008"),
    (17, 16.0, 40.0, "Schwartz 2008"),
];

/// Running at about 3 m/s: Novacheck 1998 (Gait & Posture 7:77–95) for the angles and the
/// stance, Cavanagh & Lafortune 1980 and Novacheck for the body's vertical excursion.
pub const RUN: &[Band] = &[
    (0, 8.0, 32.0, "Novacheck 1998"),
    (1, 28.0, 52.0, "Novacheck 1998"),
    (3, 75.0, 110.0, "Novacheck 1998"),
    (8, 38.0, 72.0, "Novacheck 1998"),
    (12, -35.0, -10.0, "Novacheck 1998"),
    (13, 4.0, 12.0, "Novacheck 1998"),
    (16, 28.0, 45.0, "Novacheck 1998"),
    (17, 0.0, 0.5, "Novacheck 1998"),
];

/// The bands for `manner`.
pub fn bands(manner: &str) -> &'static [Band] {
    match manner {
        "STROLL" => STROLL,
        "RUN" => RUN,
        _ => WALK,
    }
}

/// The mean curves of knee, hip and ankle over `cycles`, at each whole percent of the cycle
/// (101 points).
pub fn mean_curves(cycles: &[&[Sample]]) -> [Vec<f32>; 3] {
    let get: [fn(&Sample) -> f32; 3] = [|x| x.knee, |x| x.hip, |x| x.ankle];
    get.map(|g| {
        (0..=100)
            .map(|pct| {
                let sum: f32 = cycles
                    .iter()
                    .map(|c| {
                        g(&c[((pct as f32 / 100.0 * c.len() as f32) as usize).min(c.len() - 1)])
                    })
                    .sum();
                sum / cycles.len().max(1) as f32
            })
            .collect()
    })
}
