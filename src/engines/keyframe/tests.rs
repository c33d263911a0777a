//! The unit tests of `keyframe`.

use super::*;

const KEYS: &str = r#"<SkeletonInterpolator rotationEncoding="quaternions" parts="r_elbow" encoding="R">
    0 1 0 0 0
    1 0.70710678 0 0.70710678 0
    3 0 0 1 0
</SkeletonInterpolator>"#;

#[test]
fn keys_are_read_and_sampled_exactly_at_their_times() {
    let k = read_keys(KEYS).unwrap();
    assert_eq!(k.parts, ["r_elbow"]);
    assert_eq!(k.keys.len(), 3);
    assert_eq!(k.duration(), 3.0);
    for (t, _, q) in &k.keys {
        let (_, s) = k.sample(*t);
        assert!(s[0].angle_between(q[0]) < 1e-6);
    }
    // slerp against its formula: q(u) = q0 sin((1-u)θ)/sin θ + q1 sin(uθ)/sin θ
    let (_, mid) = k.sample(0.25);
    let (q0, q1) = (k.keys[0].2[0], k.keys[1].2[0]);
    let theta = q0.dot(q1).acos();
    let u = 0.25f32;
    let reference =
        q0 * ((1.0 - u) * theta).sin() / theta.sin() + q1 * (u * theta).sin() / theta.sin();
    assert!(mid[0].angle_between(reference.normalize()) < 1e-5);
}

#[test]
fn hermite_keys_are_exact_and_the_angular_velocity_is_continuous_through_them() {
    // unevenly spaced keys turning about changing axes
    let k = read_keys(
        r#"<SkeletonInterpolator rotationEncoding="quaternions" parts="a" encoding="R">
        0   1 0 0 0
        0.4 0.9239 0.3827 0 0
        1.5 0.7071 0 0.7071 0
        2   0.5 0.5 0.5 0.5
        </SkeletonInterpolator>"#,
    )
    .unwrap();
    let controls = hermite_controls(&k.keys);
    let at = |how, t: f64| k.sample_with(t, how, &controls).1[0];
    for (t, _, q) in &k.keys {
        assert!(at(Interpolation::Hermite, *t).angle_between(q[0]) < 1e-6);
    }
    // angular velocity (rad/s) just before and just after a key
    let velocity =
        |how, t: f64, dt: f64| rotvec(at(how, t).inverse() * at(how, t + dt)) / dt as f32;
    let h = 1e-4;
    for key in [0.4, 1.5] {
        let (before, after) = (
            velocity(Interpolation::Hermite, key - h, h),
            velocity(Interpolation::Hermite, key, h),
        );
        assert!(
            (before - after).length() < 0.01,
            "{key}: {before} vs {after}"
        );
        // slerp kinks there
        let (sb, sa) = (
            velocity(Interpolation::Slerp, key - h, h),
            velocity(Interpolation::Slerp, key, h),
        );
        assert!((sb - sa).length() > 0.3, "{key}: slerp {sb} vs {sa}");
    }
}

#[test]
fn bad_keyframes_are_refused_with_a_reason() {
    let bad = |c: &str| read_keys(c).unwrap_err();
    assert_eq!(bad("<x/>"), "no <SkeletonInterpolator> in the keyframe");
    assert!(
        bad(r#"<SkeletonInterpolator parts="a" encoding="R">0 1 0 0</SkeletonInterpolator>"#)
            .contains("do not make keys")
    );
    assert!(bad(
        r#"<SkeletonInterpolator parts="a" encoding="R">1 1 0 0 0 0 1 0 0 0</SkeletonInterpolator>"#
    )
    .contains("must increase"));
    assert!(bad(
        r#"<SkeletonInterpolator parts="a" encoding="Q">0 1 0 0 0</SkeletonInterpolator>"#
    )
    .contains("encoding 'Q'"));
}

/// Keys of one joint turning about x by `angle(t)` at `times`.
fn swing(times: impl Iterator<Item = f64>, angle: impl Fn(f64) -> f64) -> Keys {
    Keys {
        parts: vec!["r_shoulder".into()],
        root_translation: false,
        keys: times
            .map(|t| (t, Vec3::ZERO, vec![Quat::from_rotation_x(angle(t) as f32)]))
            .collect(),
    }
}

fn angle_of(q: Quat) -> f64 {
    f64::from(2.0 * q.x.atan2(q.w))
}

/// Motion capture at 100 Hz — a 1 Hz swing with ±0.02 rad of white jitter — is smoothed:
/// it keeps closer to the swing (the jitter above 20 Hz, most of it, is gone), its largest
/// second difference (the acceleration the inverse dynamics would see) drops by more than
/// half, its quaternions stay unit. Authored keys, uneven keys and
/// motion sampled at 40 Hz or less are left as they are.
#[test]
fn sampled_motion_is_smoothed_and_authored_keys_are_not() {
    let mut seed = 0x2545_F491_4F6C_DD1Du64;
    let mut jitter = || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64 * 0.04 - 0.02
    };
    let clean = |t: f64| 0.6 * (2.0 * std::f64::consts::PI * t).sin();
    let noise: Vec<f64> = (0..=200).map(|_| jitter()).collect();
    let raw = swing((0..=200).map(|k| k as f64 / 100.0), |t| {
        clean(t) + noise[(t * 100.0).round() as usize]
    });
    let smooth = raw
        .smoothed()
        .expect("100 keys a second are sampled motion");
    let angles = |k: &Keys| {
        k.keys
            .iter()
            .map(|key| angle_of(key.2[0]))
            .collect::<Vec<_>>()
    };
    let (a, b) = (angles(&raw), angles(&smooth));
    let off = |x: &[f64]| {
        let sum: f64 = (x.iter().enumerate())
            .map(|(i, v)| (v - clean(i as f64 / 100.0)).powi(2))
            .sum();
        (sum / x.len() as f64).sqrt()
    };
    let jerk = |x: &[f64]| {
        x.windows(3)
            .map(|w| (w[2] - 2.0 * w[1] + w[0]).abs())
            .fold(0.0, f64::max)
    };
    eprintln!(
        "off the swing (rms): {:.4} rad raw, {:.4} smoothed; largest second difference {:.4} raw, {:.4} smoothed",
        off(&a),
        off(&b),
        jerk(&a),
        jerk(&b)
    );
    assert!(
        off(&b) < 0.8 * off(&a),
        "smoothed {} raw {}",
        off(&b),
        off(&a)
    );
    assert!(
        jerk(&b) < 0.4 * jerk(&a),
        "smoothed {} raw {}",
        jerk(&b),
        jerk(&a)
    );
    assert!(smooth
        .keys
        .iter()
        .all(|k| (k.2[0].length() - 1.0).abs() < 1e-6));
    // authored: few keys, uneven keys, or slow sampling
    assert!(swing([0.0, 0.5, 1.0].into_iter(), clean)
        .smoothed()
        .is_none());
    let uneven = (0..20).map(|k| k as f64 * 0.01 + if k == 7 { 0.003 } else { 0.0 });
    assert!(swing(uneven, clean).smoothed().is_none());
    assert!(swing((0..40).map(|k| k as f64 / 40.0), clean)
        .smoothed()
        .is_none());
}
