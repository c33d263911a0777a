//! The unit tests of `procedural`.

use super::*;
use crate::engines::interface::Motion;

fn ids(v: &[(&'static str, f64)]) -> Vec<(Id, f64)> {
    v.iter().map(|&(n, t)| (Id::new_static(n), t)).collect()
}

#[test]
fn time_warps_linearly_and_hits_every_key_exactly() {
    let keys = ids(&[("start", 0.0), ("stroke", 0.4), ("end", 1.0)]);
    let syncs = ids(&[("start", 2.0), ("stroke", 2.3), ("end", 4.0)]);
    for (k, s) in keys.iter().zip(&syncs) {
        assert!((alpha_at(&keys, &syncs, s.1) - k.1).abs() < 1e-12);
    }
    assert!((alpha_at(&keys, &syncs, 2.15) - 0.2).abs() < 1e-12);
    assert!((alpha_at(&keys, &syncs, 3.15) - 0.7).abs() < 1e-12);
    let mut last = -1.0;
    for i in 0..=300 {
        let a = alpha_at(&keys, &syncs, 1.5 + i as f64 * 0.01);
        assert!(a >= last && (0.0..=1.0).contains(&a));
        last = a;
    }
}

#[test]
fn macros_match_their_definitions() {
    // Hermite: ends and end tangents
    assert_eq!(hermite(1.0, 3.0, 0.5, -2.0, 0.0), 1.0);
    assert_eq!(hermite(1.0, 3.0, 0.5, -2.0, 1.0), 3.0);
    let d = |f: &dyn Fn(f64) -> f64, s: f64| (f(s + 1e-6) - f(s - 1e-6)) / 2e-6;
    assert!((d(&|s| hermite(1.0, 3.0, 0.5, -2.0, s), 0.0) - 0.5).abs() < 1e-6);
    assert!((d(&|s| hermite(1.0, 3.0, 0.5, -2.0, s), 1.0) + 2.0).abs() < 1e-6);
    // TCB with zero parameters is Catmull-Rom: the tangent at p1 is (p2 - p0) / 2
    let p = [0.0, 1.0, 4.0, 5.0];
    assert_eq!(tcb(p, 0.0, 0.0, 0.0, 0.0), 1.0);
    assert_eq!(tcb(p, 0.0, 0.0, 0.0, 1.0), 4.0);
    assert!((d(&|s| tcb(p, 0.0, 0.0, 0.0, s), 0.0) - 2.0).abs() < 1e-6);
    // full tension: zero tangents
    assert!(d(&|s| tcb(p, 1.0, 0.0, 0.0, s), 0.0).abs() < 1e-6);
    // Perlin: zero at integers, bounded, continuous, different seeds differ
    let mut max: f64 = 0.0;
    for i in 0..4000 {
        let x = i as f64 * 0.0137 - 20.0;
        let v = perlin(x, 0.0);
        assert!(v.abs() <= 1.0);
        assert!((perlin(x + 1e-7, 0.0) - v).abs() < 1e-5);
        max = max.max(v.abs());
    }
    assert!(max > 0.3, "the noise moves ({max})");
    for i in -5..5 {
        assert_eq!(perlin(i as f64, 3.0), 0.0);
    }
    assert_ne!(perlin(0.5, 1.0), perlin(0.5, 2.0));
}

#[test]
fn expressions_have_trig_if_parameters_and_alpha() {
    let e = Expr::compile("if(t < 0.5, a * sin(pi * t), cos(pi) + max(a, 2)) + alpha").unwrap();
    let params = [("a".to_string(), 3.0)];
    let at = |t: f64| {
        let names = Names {
            alpha: t,
            params: &params,
        };
        e.eval(&|n: &str| names.get(n)).unwrap()
    };
    assert!((at(0.25) - (3.0 * (std::f64::consts::PI * 0.25).sin() + 0.25)).abs() < 1e-12);
    assert!((at(0.75) - (-1.0 + 3.0 + 0.75)).abs() < 1e-12);
    let names = Names {
        alpha: 0.0,
        params: &params,
    };
    let unknown = Expr::compile("b + 1").unwrap();
    assert!(unknown.eval(&|n: &str| names.get(n)).is_err());
    assert!(Expr::compile("print(1)").is_err());
    assert!(Expr::compile("2 * print (t)").is_err());
    // a name that merely contains "print" is fine
    let footprint = [("footprint".to_string(), 2.0)];
    let names = Names {
        alpha: 0.0,
        params: &footprint,
    };
    let e = Expr::compile("footprint * 3").unwrap();
    assert_eq!(e.eval(&|n: &str| names.get(n)), Ok(6.0));
    assert!(Expr::compile("1 +").is_err());
}

#[test]
fn a_mirrored_unit_is_the_reflected_motion_on_the_other_side_and_mirrors_back() {
    let skeleton = Skeleton::adult();
    let lib = Library::default_library();
    let reflect = |v: Vec3| Vec3::new(-v.x, v.y, v.z);
    for (name, end) in [
        ("lift", "wrist"),
        ("wave", "wrist"),
        ("foot_lift", "talocrural"),
    ] {
        let u = lib.get(name).unwrap();
        for alpha in [0.1, 0.5, 0.9] {
            let (mut plain, mut mirrored) = (Pose::rest(&skeleton), Pose::rest(&skeleton));
            u.apply(alpha, &u.params, false, 1.0, &skeleton, &mut plain)
                .unwrap();
            u.apply(alpha, &u.params, true, 1.0, &skeleton, &mut mirrored)
                .unwrap();
            let (wp, wm) = (plain.world(&skeleton), mirrored.world(&skeleton));
            for side in ["l", "r"] {
                let other = if side == "l" { "r" } else { "l" };
                let a = skeleton.joint(&format!("{side}_{end}")).unwrap();
                let b = skeleton.joint(&format!("{other}_{end}")).unwrap();
                let d = (wm.positions[b] - reflect(wp.positions[a])).length();
                assert!(d < 1e-3, "{name} at {alpha}: {side} {d}");
            }
        }
    }
    // the rotation of a mirrored joint, and mirroring twice
    let q = Quat::from_euler(EulerRot::ZXY, 0.3, -0.2, 0.7);
    assert!(mirror_rotation(mirror_rotation(q)).angle_between(q) < 1e-6);
    assert_eq!(mirror_name(&mirror_name("r_elbow")), "r_elbow");
    assert_eq!(mirror_name("l_hip"), "r_hip");
    assert_eq!(mirror_name("vl5"), "vl5");
}

/// An engine over `units` (library JSON) with `(id, unit name, start, end)` added.
fn engine(units: &str, runs: &[(&str, &str, f64, f64)]) -> ProceduralEngine {
    let mut e = ProceduralEngine::new(Library::from_json(units).unwrap());
    let world = World::default();
    for &(id, name, start, end) in runs {
        let block = crate::language::bml::load(&format!(
            r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" xmlns:bmlt="http://hmi.ewi.utwente.nl/bmlt" id="b"><bmlt:procanimation id="{id}" name="{name}"/></bml>"#
        ))
        .unwrap()
        .block;
        let key = UnitKey::new("b", id);
        let syncs = ids(&[("start", start), ("end", end)]);
        e.add(Unit {
            key: &key,
            behaviour: &block.behaviours[0],
            syncs,
            world: &world,
        })
        .unwrap();
    }
    e
}

/// The r_elbow's angle (degrees, about z) after the engine animates a rest pose at `t`.
fn elbow(e: &mut ProceduralEngine, t: f64) -> f64 {
    let skeleton = Skeleton::adult();
    let mut pose = Pose::rest(&skeleton);
    e.animate(t, &skeleton, &World::default(), &mut pose);
    let q = pose.rotations[skeleton.joint("r_elbow").unwrap()];
    let (z, _, _) = q.to_euler(EulerRot::ZXY);
    f64::from(z).to_degrees()
}

const UNITS: &str = r#"{"units": {
    "a": {"keys": {"start": 0, "end": 1}, "duration": {"preferred": 1}, "group": "arm",
          "rotations": {"r_elbow": ["30", "0", "0"]}},
    "b": {"keys": {"start": 0, "end": 1}, "duration": {"preferred": 1}, "group": "arm",
          "rotations": {"r_elbow": ["60", "0", "0"]}},
    "layer": {"keys": {"start": 0, "end": 1}, "duration": {"preferred": 1}, "additive": true,
          "rotations": {"r_elbow": ["10", "0", "0"]}},
    "soft": {"keys": {"start": 0, "end": 1}, "duration": {"preferred": 1}, "blend": 0.5,
          "rotations": {"r_elbow": ["60", "0", "0"]}}
}}"#;

#[test]
fn in_a_replacement_group_the_latest_start_plays_then_the_earliest_end() {
    // b starts later: from its start it replaces a
    let mut e = engine(UNITS, &[("pa", "a", 0.0, 4.0), ("pb", "b", 1.0, 2.0)]);
    assert!((elbow(&mut e, 0.5) - 30.0).abs() < 1e-3);
    assert!((elbow(&mut e, 1.5) - 60.0).abs() < 1e-3);
    assert!(
        (elbow(&mut e, 3.0) - 30.0).abs() < 1e-3,
        "a again once b ended"
    );
    // same start: the earlier end plays
    let mut e = engine(UNITS, &[("pa", "a", 0.0, 4.0), ("pb", "b", 0.0, 2.0)]);
    assert!((elbow(&mut e, 1.0) - 60.0).abs() < 1e-3);
    // full tie: the unit added first (the runtime drops the other with a warning)
    let mut e = engine(UNITS, &[("pa", "a", 0.0, 2.0), ("pb", "b", 0.0, 2.0)]);
    assert!((elbow(&mut e, 1.0) - 30.0).abs() < 1e-3);
}

#[test]
fn additive_units_layer_and_blending_units_ease_in_and_out_over_what_was_there() {
    // an additive unit adds its rotation to the one under it
    let mut e = engine(UNITS, &[("pa", "a", 0.0, 2.0), ("pl", "layer", 0.0, 2.0)]);
    assert!((elbow(&mut e, 1.0) - 40.0).abs() < 1e-3);
    // a blending unit over a: from a's 30° at its start to its own 60° after 0.5 s, back
    // to 30° at its end, smoothly (minimum jerk: half way at a quarter second)
    let mut e = engine(UNITS, &[("pa", "a", 0.0, 4.0), ("ps", "soft", 1.0, 3.0)]);
    assert!((elbow(&mut e, 1.0) - 30.0).abs() < 1e-3);
    assert!((elbow(&mut e, 1.25) - 45.0).abs() < 1e-2);
    assert!((elbow(&mut e, 2.0) - 60.0).abs() < 1e-3);
    assert!((elbow(&mut e, 3.0) - 30.0).abs() < 1e-3);
    let mut last = elbow(&mut e, 1.0);
    for i in 1..=50 {
        let v = elbow(&mut e, 1.0 + f64::from(i) * 0.01);
        assert!(v >= last - 1e-6, "monotone while blending in");
        last = v;
    }
}

#[test]
fn bad_units_are_refused_with_a_reason() {
    let bad = |u: &str| Library::from_json(&format!(r#"{{"units": {{"u": {u}}}}}"#)).unwrap_err();
    let keys = r#""keys": {"start": 0, "end": 1}, "duration": {"preferred": 1}"#;
    assert!(bad(&format!(r#"{{{keys}, "parameters": {{"t": 1}}}}"#)).contains("reserved"));
    assert!(
        bad(r#"{"keys": {"start": 0.2, "end": 1}, "duration": {"preferred": 1}}"#)
            .contains("keys must go from start at 0")
    );
    assert!(bad(&format!(
        r#"{{{keys}, "rotations": {{"r_elbow": ["x", "0", "0"]}}}}"#
    ))
    .contains("'x'"));
    assert!(bad(&format!(
        r#"{{{keys}, "rotations": {{"r_elbow": ["1", "0"]}}}}"#
    ))
    .contains("units.u.rotations.r_elbow: invalid length 2"));
    assert!(
        bad(r#"{"keys": {"start": 0, "end": 1}, "duration": {"preferred": 1, "max": 0.5}}"#)
            .contains("min ≤ preferred ≤ max")
    );
    assert!(bad(&format!(
        r#"{{{keys}, "effectors": {{"r_wrist": {{"frame": "moon", "position": [0, 0, 0]}}}}}}"#
    ))
    .contains("units.u.effectors.r_wrist.frame: unknown variant `moon`"));
    let lib = Library::default_library();
    let u = lib.get("lift").unwrap();
    let p = |n: &str, v: &str| Param {
        name: n.into(),
        value: v.into(),
    };
    assert!(u
        .parameters(&[p("nope", "1")])
        .unwrap_err()
        .contains("no parameter 'nope'"));
    assert!(u
        .parameters(&[p("height", "high")])
        .unwrap_err()
        .contains("not a number"));
}
