//! The avatars walk as the realizer's skeleton does: while the realizer plants a foot, the
//! avatar's ankle stands at its own rest height and does not slide. Checked on the default
//! avatar (its skeleton is the realizer's) and on a Mixamo-named T-pose in centimetres (every
//! bone aligned and turned, the travel scaled by the ratio of leg lengths) and on a published
//! VRM 0.x (`fixtures/avatars/cryptovoxels/`, facing −z) — a test of what the
//! pictures show: feet on the floor, not skating.

#[path = "common/avatars.rs"]
mod avatars;

use avatars::{test_avatar, Kind};
use bml_realizer::character::avatar::{default_model, Model, Retarget};
use bml_realizer::character::body::pose::Pose;
use bml_realizer::character::body::skeleton::Skeleton;
use bml_realizer::realizer::Realizer;
use glam::Vec3;

/// Poses and foot contacts of a character walking 4 m ahead, at 60 Hz.
fn walk() -> Vec<(Pose, [bool; 2])> {
    let mut r = Realizer::new();
    r.perform_bml(
        r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" id="w"><locomotion id="l" target="0,4"/></bml>"#,
    )
    .unwrap();
    let mut out = Vec::new();
    for k in 0..(60 * 8) {
        let f = r.tick(k as f64 / 60.0);
        let p = &f.poses[0];
        if let Some(contacts) = p.contacts {
            out.push((p.pose.clone(), contacts));
        }
    }
    out
}

/// The lower of a foot's two points (ankle, ball) above its rest height, which it is, and
/// where it is.
fn lowest(points: [Vec3; 2], rest: [Vec3; 2]) -> (f32, usize, Vec3) {
    let up = [points[0].y - rest[0].y, points[1].y - rest[1].y];
    let k = usize::from(up[1] < up[0]);
    (up[k], k, points[k])
}

/// Over the frames in which the realizer's foot is truly planted (its lower point within 5 mm
/// of its rest height): (how far above its rest the avatar's foot's lower point is at worst,
/// how far it slides within one such stance at worst: the point it stands on, from where that
/// point stood when the foot came down on it).
fn planted(model: &Model, feet: [[&str; 2]; 2], frames: &[(Pose, [bool; 2])]) -> (f32, f32) {
    let skeleton = Skeleton::adult();
    let retarget = Retarget::new(model, &skeleton, None).unwrap();
    let sides = [
        ["l_talocrural", "l_metatarsal"],
        ["r_talocrural", "r_metatarsal"],
    ];
    let rest = Pose::rest(&skeleton).world(&skeleton);
    let (mut height, mut slide) = (0.0f32, 0.0f32);
    let mut stance: [Option<(usize, Vec3)>; 2] = [None, None];
    for (pose, contacts) in frames {
        let world = retarget.world(&retarget.pose(pose));
        let theirs = pose.world(&skeleton);
        for side in 0..2 {
            let joints = sides[side].map(|j| skeleton.joint(j).unwrap());
            let (up, _, _) = lowest(
                joints.map(|j| theirs.positions[j]),
                joints.map(|j| rest.positions[j]),
            );
            if !(contacts[side] && up.abs() < 0.005) {
                stance[side] = None;
                continue;
            }
            let nodes = feet[side].map(|n| model.node(n).unwrap());
            let ours = nodes.map(|n| world[n].w_axis.truncate());
            let (up, point, at) =
                lowest(ours, nodes.map(|n| model.rest_world(n).w_axis.truncate()));
            height = height.max(up.abs());
            if stance[side].is_none_or(|(p, _)| p != point) {
                stance[side] = Some((point, at));
            }
            let first = stance[side].map_or(at, |(_, f)| f);
            slide = slide.max(Vec3::new(at.x - first.x, 0.0, at.z - first.z).length());
        }
    }
    (height, slide)
}

#[test]
fn a_walking_avatar_s_planted_feet_stay_on_the_floor_and_do_not_slide() {
    let frames = walk();
    let stances = frames.iter().filter(|(_, c)| c[0] != c[1]).count();
    assert!(
        stances > 60,
        "the character walked ({stances} frames on one foot)"
    );
    let feet = [
        ["l_talocrural", "l_metatarsal"],
        ["r_talocrural", "r_metatarsal"],
    ];
    let (height, slide) = planted(&default_model(), feet, &frames);
    eprintln!("default avatar: planted feet {height:.4} m off the floor, slide {slide:.4} m");
    assert!(
        height < 0.015 && slide < 0.02,
        "default avatar: {height} m high, {slide} m slid"
    );
    let mixamo = Model::from_glb("mixamo", &test_avatar(Kind::Mixamo)).unwrap();
    let feet = [
        ["mixamorig:LeftFoot", "mixamorig:LeftToeBase"],
        ["mixamorig:RightFoot", "mixamorig:RightToeBase"],
    ];
    let (height, slide) = planted(&mixamo, feet, &frames);
    eprintln!("Mixamo avatar: planted feet {height:.4} m off the floor, slide {slide:.4} m");
    assert!(
        height < 0.015 && slide < 0.02,
        "Mixamo avatar: {height} m high, {slide} m slid"
    );
    // a VRM 0.x someone published (facing −z, shorter legs: its travel scaled by about 0.77)
    let path = std::path::Path::new("fixtures/avatars/cryptovoxels/cryptovoxels.vrm");
    let vrm = Model::read(path).unwrap();
    let feet = [["Left ankle", "Left toe"], ["Right ankle", "Right toe"]];
    let (height, slide) = planted(&vrm, feet, &frames);
    eprintln!("published VRM 0.x: planted feet {height:.4} m off the floor, slide {slide:.4} m");
    assert!(
        height < 0.015 && slide < 0.02,
        "published VRM 0.x: {height} m high, {slide} m slid"
    );
}
