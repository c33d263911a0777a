//! Several characters in one world: each stands where the world places it, its frames are in
//! world coordinates, it sees the world from where it stands, and a placed character is a
//! target, so two characters can look at each other.

use bml_realizer::character::body::{Pose, Skeleton};
use bml_realizer::realizer::Realizer;
use bml_realizer::world::{Placement, CHARACTER_EYES};
use glam::Vec3;

const NS: &str = r#"xmlns="http://www.bml-initiative.org/bml/bml-1.0""#;

/// Bob stands 1.2 m to Alice's left and 2 m in front of her, turned 120° (he faces partly
/// away from her); Alice stands at the origin facing +z.
fn bob() -> Placement {
    Placement::new(Vec3::new(1.2, 0.0, 2.0), -120.0)
}

fn realizer() -> Realizer {
    let mut r = Realizer::new().with_idle(false);
    r.world_mut().place("Bob", bob()).unwrap();
    r.world_mut().place("Alice", Placement::default()).unwrap();
    r
}

/// Where the eyes of `pose` are and the way they look (the mean of both eyes' +z), in the world.
fn eyes(skeleton: &Skeleton, pose: &Pose) -> (Vec3, Vec3) {
    let w = pose.world(skeleton);
    let (l, r) = (
        skeleton.joint("l_eyeball_joint").unwrap(),
        skeleton.joint("r_eyeball_joint").unwrap(),
    );
    let at = (w.positions[l] + w.positions[r]) / 2.0;
    let look = (w.orientations[l] * Vec3::Z + w.orientations[r] * Vec3::Z).normalize();
    (at, look)
}

fn pose_of(frame: &bml_realizer::engines::interface::Frame, id: &str) -> Pose {
    (frame.poses.iter())
        .find(|p| p.character.as_deref() == Some(id))
        .unwrap_or_else(|| panic!("no {id} in the frame"))
        .pose
        .clone()
}

/// At rest Bob stands where he is placed and faces his way; Alice at the origin facing +z.
#[test]
fn a_placed_character_stands_where_the_world_puts_it() {
    let mut r = realizer();
    for id in ["Alice", "Bob"] {
        r.perform_bml(&format!(r#"<bml {NS} id="b" characterId="{id}"/>"#))
            .unwrap();
    }
    let frame = r.tick(0.5);
    let skeleton = Skeleton::adult();
    let (at, look) = eyes(&skeleton, &pose_of(&frame, "Bob"));
    let want = bob().to_world(CHARACTER_EYES);
    assert!(at.distance(want) < 0.01, "Bob's eyes at {at}, not {want}");
    let facing = Vec3::new(
        (-120f32).to_radians().sin(),
        0.0,
        (-120f32).to_radians().cos(),
    );
    assert!(look.angle_between(facing) < 0.02, "Bob looks along {look}");
    let (at, look) = eyes(&skeleton, &pose_of(&frame, "Alice"));
    assert!(at.distance(CHARACTER_EYES) < 0.01 && look.angle_between(Vec3::Z) < 0.02);
}

/// Alice and Bob gaze at each other: once the gazes have arrived, each one's eyes point at the
/// other's eyes (within 2°), although Bob must turn about 90° to his right and Alice 31° to her
/// left. Without the view from where each stands, Bob would look at a point in his own frame.
#[test]
fn two_characters_look_at_each_other() {
    let mut r = realizer();
    for (id, other) in [("Alice", "Bob"), ("Bob", "Alice")] {
        r.perform_bml(&format!(
            r#"<bml {NS} id="b" characterId="{id}"><gaze id="g" target="{other}" influence="NECK" start="0" ready="1" end="4"/></bml>"#
        ))
        .unwrap();
    }
    let mut frame = r.tick(0.0);
    for k in 1..=120 {
        frame = r.tick(f64::from(k) / 60.0);
    }
    let skeleton = Skeleton::adult();
    let (alice, bob) = (
        eyes(&skeleton, &pose_of(&frame, "Alice")),
        eyes(&skeleton, &pose_of(&frame, "Bob")),
    );
    for (who, (at, look), other) in [("Alice", alice, bob.0), ("Bob", bob, alice.0)] {
        let off = look.angle_between(other - at).to_degrees();
        assert!(
            off < 2.0,
            "{who} looks {off:.1}° away from the other's eyes"
        );
    }
}

/// A placement that is not finite is refused, saying whose.
#[test]
fn a_placement_must_be_finite() {
    let mut r = Realizer::new();
    let e = (r.world_mut())
        .place("Bob", Placement::new(Vec3::new(f32::NAN, 0.0, 0.0), 0.0))
        .unwrap_err();
    assert!(e.contains("Bob"), "{e}");
}

/// Bob, placed and turned, points at Alice with his right hand: at the stroke his index finger
/// points at her eyes (within 3°), in the world.
#[test]
fn a_placed_character_points_at_another() {
    let mut r = realizer();
    r.perform_bml(&format!(
        r#"<bml {NS} id="b" characterId="Bob"><pointing id="p" target="Alice" mode="RIGHT_HAND" start="0" stroke="1" end="3"/></bml>"#
    ))
    .unwrap();
    r.perform_bml(&format!(r#"<bml {NS} id="a" characterId="Alice"/>"#))
        .unwrap();
    for k in 0..60 {
        r.tick(f64::from(k) / 60.0);
    }
    let frame = r.tick(1.0);
    let skeleton = Skeleton::adult();
    let w = pose_of(&frame, "Bob").world(&skeleton);
    let (i1, i3) = (
        skeleton.joint("r_index1").unwrap(),
        skeleton.joint("r_index3").unwrap(),
    );
    let alice = eyes(&skeleton, &pose_of(&frame, "Alice")).0;
    let finger = w.positions[i3] - w.positions[i1];
    let off = finger.angle_between(alice - w.positions[i3]).to_degrees();
    assert!(off < 3.0, "Bob's finger points {off:.1}° away from Alice");
}
