//! The unit tests of `gaze`.

use super::*;
use crate::engines::interface::Motion;

#[test]
fn yaw_is_toward_the_left_and_pitch_down() {
    let (y, p) = yaw_pitch(Vec3::new(1.0, 0.0, 1.0));
    assert!((y - std::f32::consts::FRAC_PI_4).abs() < 1e-6 && p.abs() < 1e-6);
    let (y, p) = yaw_pitch(Vec3::new(0.0, -1.0, 1.0));
    assert!(y.abs() < 1e-6 && (p - std::f32::consts::FRAC_PI_4).abs() < 1e-6);
    // the Donders rotation takes +z to that direction
    let d = donders(0.3, 0.2) * Vec3::Z;
    let (y, p) = yaw_pitch(d);
    assert!((y - 0.3).abs() < 1e-5 && (p - 0.2).abs() < 1e-5);
}

/// The mean line of sight of the eyes and the head's yaw (world, rad) of `pose`.
fn sight(s: &Skeleton, pose: &Pose) -> (Vec3, f32) {
    let w = pose.world(s);
    let eyes = ["l_eyeball_joint", "r_eyeball_joint"].map(|e| s.joint(e).unwrap());
    let sight: Vec3 = eyes.iter().map(|&e| w.orientations[e] * Vec3::Z).sum();
    let head = w.orientations[s.joint("skullbase").unwrap()] * Vec3::Z;
    (sight.normalize(), head.x.atan2(head.z))
}

/// Whom the walk attends to is looked at (eyes on them, the head turned part of the way,
/// as much as attended), under a BML gaze, which wins while it runs.
#[test]
fn it_looks_at_whom_the_walk_attends_to_unless_a_bml_gaze_runs() {
    let s = Skeleton::adult();
    let mut world = World::default();
    let (left, right) = (Vec3::new(1.5, 1.64, 1.5), Vec3::new(-2.0, 1.64, 1.0));
    world.set("right", right);
    let eyes = eyes_at_rest(&s);
    let mut e = GazeEngine::default();
    let look = |e: &mut GazeEngine, t: f64| {
        let mut pose = Pose::rest(&s);
        e.animate(t, &s, &world, &mut pose);
        sight(&s, &pose)
    };
    e.attend(Some(Attention {
        at: left,
        weight: 1.0,
    }));
    let (sight_full, head_full) = look(&mut e, 0.0);
    let off = sight_full.angle_between(left - eyes).to_degrees();
    assert!(off < 3.0, "the eyes are {off}° off whom it attends to");
    // the neck and head take 60 % of the 45° turn
    assert!((head_full.to_degrees() - 27.0).abs() < 3.0, "{head_full}");
    e.attend(Some(Attention {
        at: left,
        weight: 0.5,
    }));
    let (_, head_half) = look(&mut e, 0.0);
    assert!((head_half - head_full / 2.0).abs() < 0.02, "{head_half}");
    // nobody attended to: the rest pose
    e.attend(None);
    assert!(look(&mut e, 0.0).1.abs() < 1e-4);
    // a BML gaze at someone on the right, once it has turned, wins over the attention
    let block = crate::language::bml::load(
        r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="b"><gaze id="g" target="right"/></bml>"#,
    )
    .unwrap()
    .block;
    let key = UnitKey::new("b", "g");
    let syncs = [("start", 0.0), ("ready", 0.5), ("relax", 3.0), ("end", 4.0)];
    e.add(Unit {
        key: &key,
        behaviour: &block.behaviours[0],
        syncs: syncs.map(|(n, t)| (SyncName::new_static(n), t)).to_vec(),
        world: &world,
    })
    .unwrap();
    e.attend(Some(Attention {
        at: left,
        weight: 1.0,
    }));
    let (sight, head) = look(&mut e, 1.0);
    let off = sight.angle_between(right - eyes).to_degrees();
    assert!(
        off < 3.0 && head < -0.3,
        "{off}° off the gaze's target, head {head}"
    );
    // and once it has ended, the eyes go back to whom the walk attends to
    let (sight, _) = look(&mut e, 4.5);
    assert!(sight.angle_between(left - eyes).to_degrees() < 3.0);
}

/// A placed character as a target is where the default adult's eyes are.
#[test]
fn a_character_target_is_at_the_adult_s_eyes() {
    let eyes = eyes_at_rest(&crate::character::body::Skeleton::adult());
    let d = eyes.distance(crate::world::CHARACTER_EYES);
    assert!(d < 0.01, "{eyes} vs {}", crate::world::CHARACTER_EYES);
}
