//! Avatars other people published, read as they are (`fixtures/avatars/`, each with its
//! licence beside it; docs/avatars.md lists what was tried). CesiumMan (Cesium, CC-BY 4.0, as
//! Khronos's glTF sample models carry it: a `.gltf` with its `.bin` and texture beside it,
//! written by COLLADA2GLTF): its joints have no names, so it is refused naming the bones and
//! showing the bone-map form with the joints' indices, and driven with the bone map beside it
//! (node indices): every limb within 1° mean / 2° worst of the realizer's over 500 random
//! poses, and the right hand up for the beat of the welcome block. The Cryptovoxels avatar (a
//! VRM 0.x written by UniVRM, its own meta licence allowing redistribution): its humanoid map
//! read, every limb within the same bounds, the hand up for the beat. And each, walking to the
//! door of `room.json`, goes where the default avatar goes (a VRM 0.x faces −z and CesiumMan
//! +x: both once walked off the other way or sideways while the world's objects stayed put).

#[path = "common/avatars.rs"]
mod avatars;
mod common;

use std::collections::BTreeMap;

use serde_json::json;
use std::path::Path;

use avatars::{floats_of, glb_json, limb_errors_by, random_pose};
use bml_realizer::character::avatar::{humanoid, Model, Retarget};
use bml_realizer::character::body::pose::Pose;
use bml_realizer::character::body::skeleton::Skeleton;
use bml_realizer::realizer::Realizer;
use bml_realizer::rng::Rng;
use common::drive;

const CESIUM_MAN: &str = "fixtures/avatars/cesium-man/CesiumMan.gltf";
const CESIUM_MAP: &str = "fixtures/avatars/cesium-man/bone-map.json";
const CRYPTOVOXELS: &str = "fixtures/avatars/cryptovoxels/cryptovoxels.vrm";

/// A bone map file, as `--bone-map` reads it.
fn bone_map(path: &str) -> BTreeMap<String, String> {
    humanoid::bone_map_from_json(&std::fs::read_to_string(path).unwrap()).unwrap()
}

#[test]
fn cesium_man_without_a_bone_map_is_refused_showing_the_map_to_write() {
    let out = std::env::temp_dir().join(format!("cesium-{}.glb", std::process::id()));
    let (code, stdout, err) = drive(Path::new(CESIUM_MAN), &[], &out);
    assert_eq!(code, 2, "{err}");
    assert!(stdout.is_empty());
    for says in [
        "CesiumMan.gltf: its skeleton's names match no known scheme",
        r#"Give a bone map (--bone-map MAP.json) naming the node of each: {"hips": "NODE""#,
        "the skin's joints are 2 (no name), 11 (no name), 12 (no name)",
    ] {
        assert!(err.contains(says), "'{says}' not in {err}");
    }
    assert!(!out.exists());
}

#[test]
fn cesium_man_with_its_bone_map_follows_every_limb() {
    let skeleton = Skeleton::adult();
    let model = Model::read(Path::new(CESIUM_MAN)).unwrap();
    assert_eq!((model.nodes.len(), model.joints.len()), (22, 19));
    let map = bone_map(CESIUM_MAP);
    let retarget = Retarget::new(&model, &skeleton, Some(&map)).unwrap();
    // (the feet are taken to rest alike, not aligned: CesiumMan's toe joint sits lower on the
    // foot than the realizer's, so its foot points 41° further down at rest; they are checked
    // for turning as the realizer's do, below)
    let limbs = |bone: &str| !bone.ends_with("Toes");
    let node_of = |bone: &str| {
        let n = map.get(bone).filter(|_| limbs(bone))?;
        Some(n[1..].parse::<usize>().unwrap())
    };
    let rest = limb_errors_by(&retarget, &skeleton, &Pose::rest(&skeleton), node_of);
    // (CesiumMan has no fingers: arms to the hands, legs to the feet)
    assert_eq!(rest.len(), 8, "{rest:?}");
    let (mean, worst, feet) = follows(&retarget, &skeleton, node_of, [(9, 10), (5, 6)], 5);
    assert!(mean < 1.0 && worst < 2.0, "mean {mean}°, worst {worst}°");
    assert!(feet < 2.0, "a foot turned {feet}° away from the realizer's");
    // the welcome block's beat lifts the right hand (node 15) at its stroke
    let rise = beat_rise(&retarget, 15);
    assert!(rise > 0.1, "the right hand rose {rise} m for the beat");
}

/// Over 500 random poses: the mean and worst angle (degrees) between a limb bone of the
/// avatar (where `node_of` finds both ends) and the realizer's, and the worst angle between
/// a foot (its foot and toes nodes, left and right) and the way the realizer's ankle turned it
/// since rest (feet are taken to rest alike, not aligned, so they are checked for turning).
fn follows(
    retarget: &Retarget,
    skeleton: &Skeleton,
    node_of: impl Fn(&str) -> Option<usize> + Copy,
    feet: [(usize, usize); 2],
    seed: u64,
) -> (f32, f32, f32) {
    let at_rest = Pose::rest(skeleton).world(skeleton);
    let rest_world = retarget.world(&retarget.pose(&Pose::rest(skeleton)));
    let place = |m: &glam::Mat4| m.w_axis.truncate();
    let mut rng = Rng(seed);
    let (mut sum, mut count, mut worst, mut feet_worst) = (0.0, 0, 0.0f32, 0.0f32);
    for _ in 0..500 {
        let pose = random_pose(skeleton, &mut rng, 1.2);
        for e in limb_errors_by(retarget, skeleton, &pose, node_of) {
            (sum, count, worst) = (sum + e, count + 1, worst.max(e));
        }
        let posed = retarget.world(&retarget.pose(&pose));
        let realizer = pose.world(skeleton);
        for ((foot, toes), ankle) in feet.into_iter().zip(["l_talocrural", "r_talocrural"]) {
            let j = skeleton.joint(ankle).unwrap();
            let turn = realizer.orientations[j] * at_rest.orientations[j].inverse();
            let f = retarget.frame();
            let want =
                f * turn * f.inverse() * (place(&rest_world[toes]) - place(&rest_world[foot]));
            let got = place(&posed[toes]) - place(&posed[foot]);
            feet_worst = feet_worst.max(got.angle_between(want).to_degrees());
        }
    }
    (sum / count as f32, worst, feet_worst)
}

/// How far (m) node `hand` of the avatar rises from rest to the stroke of the welcome
/// block's beat.
fn beat_rise(retarget: &Retarget, hand: usize) -> f32 {
    let mut r = Realizer::new().with_idle(false);
    r.perform_bml(&std::fs::read_to_string("fixtures/examples/welcome.xml").unwrap())
        .unwrap();
    let mut hand_at = |t: f64| {
        let pose = r.tick(t).poses[0].pose.clone();
        retarget.world(&retarget.pose(&pose))[hand]
            .w_axis
            .truncate()
    };
    let before = hand_at(0.1);
    hand_at(0.821).y - before.y
}

#[test]
fn bmlr_drives_cesium_man_with_its_bone_map_into_one_glb_with_its_texture() {
    let out = std::env::temp_dir().join(format!("cesium-driven-{}.glb", std::process::id()));
    let (code, _, err) = drive(Path::new(CESIUM_MAN), &["--bone-map", CESIUM_MAP], &out);
    assert_eq!(code, 0, "{err}");
    let json = glb_json(&std::fs::read(&out).unwrap());
    // one buffer, no file beside it: the texture went into the GLB
    assert_eq!(json["buffers"].as_array().unwrap().len(), 1);
    assert!(json["buffers"][0].get("uri").is_none());
    let image = &json["images"][0];
    assert_eq!(image["mimeType"], "image/jpeg");
    assert!(image.get("uri").is_none() && image.get("bufferView").is_some());
    // the realized motion first (what a viewer plays), CesiumMan's own walk (one animation a
    // joint, as COLLADA2GLTF writes it) kept after it
    let animations = json["animations"].as_array().unwrap();
    let own: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(CESIUM_MAN).unwrap()).unwrap();
    let own = own["animations"].as_array().unwrap();
    assert_eq!(
        (animations.len(), &animations[0]["name"]),
        (own.len() + 1, &json!("bml"))
    );
    assert_eq!(animations[1], own[0]);
    let channels = animations[0]["channels"].as_array().unwrap().len();
    assert!(channels >= 19, "{channels} channels");
    let _ = std::fs::remove_file(&out);
}

/// The VRM 0.x humanoid map of a `.vrm` file, as its JSON writes it: bone name → node.
fn vrm0_humanoid(path: &str) -> BTreeMap<String, usize> {
    let json = glb_json(&std::fs::read(path).unwrap());
    (json["extensions"]["VRM"]["humanoid"]["humanBones"]
        .as_array()
        .unwrap()
        .iter())
    .map(|b| {
        let node = b["node"].as_u64().unwrap() as usize;
        (b["bone"].as_str().unwrap().to_string(), node)
    })
    .collect()
}

#[test]
fn the_cryptovoxels_vrm_0_x_follows_every_limb_and_beats() {
    let skeleton = Skeleton::adult();
    let model = Model::read(Path::new(CRYPTOVOXELS)).unwrap();
    assert_eq!((model.nodes.len(), model.joints.len()), (74, 57));
    let retarget = Retarget::new(&model, &skeleton, None).unwrap();
    // a VRM 0.x faces −z: the realizer's frame in it is half a turn about the vertical
    let half = retarget
        .frame()
        .angle_between(glam::Quat::from_rotation_y(std::f32::consts::PI));
    assert!(half < 1e-3, "its frame is {:?}", retarget.frame());
    let bones = vrm0_humanoid(CRYPTOVOXELS);
    // (its toes, like CesiumMan's, sit otherwise on the foot: the feet are checked for turning)
    let node_of = |bone: &str| bones.get(bone).copied().filter(|_| !bone.ends_with("Toes"));
    let rest = limb_errors_by(&retarget, &skeleton, &Pose::rest(&skeleton), node_of);
    // arms, hands, legs and the fingers it has (no thumb in its map, no index distal)
    assert_eq!(rest.len(), 12, "{rest:?}");
    let feet = [
        bones["leftFoot"],
        bones["leftToes"],
        bones["rightFoot"],
        bones["rightToes"],
    ];
    let feet = [(feet[0], feet[1]), (feet[2], feet[3])];
    let (mean, worst, feet) = follows(&retarget, &skeleton, node_of, feet, 7);
    eprintln!("limbs {mean:.3}° mean, {worst:.3}° worst; feet {feet:.3}° worst");
    assert!(mean < 1.0 && worst < 2.0, "mean {mean}°, worst {worst}°");
    assert!(feet < 2.0, "a foot turned {feet}° away from the realizer's");
    let rise = beat_rise(&retarget, bones["rightHand"]);
    assert!(rise > 0.1, "the right hand rose {rise} m for the beat");
}

/// A node's transform relative to its parent, from its JSON.
fn local(node: &serde_json::Value) -> glam::Mat4 {
    let floats = |key: &str| -> Option<Vec<f32>> {
        let list = node[key].as_array()?;
        Some(list.iter().map(|x| x.as_f64().unwrap() as f32).collect())
    };
    if let Some(m) = floats("matrix") {
        return glam::Mat4::from_cols_slice(&m);
    }
    let t = floats("translation").map_or(glam::Vec3::ZERO, |v| glam::Vec3::from_slice(&v));
    let r = floats("rotation").map_or(glam::Quat::IDENTITY, |v| glam::Quat::from_slice(&v));
    let s = floats("scale").map_or(glam::Vec3::ONE, |v| glam::Vec3::from_slice(&v));
    glam::Mat4::from_scale_rotation_translation(s, r, t)
}

/// Where the exported avatar's travelling node is in the scene at its first and last key:
/// its keyed translation under its ancestors' rest transforms (none of which is keyed).
fn travel_in_scene(glb: &[u8]) -> (glam::Vec3, glam::Vec3) {
    let json = glb_json(glb);
    let animation = &json["animations"][0];
    let channel = (animation["channels"].as_array().unwrap().iter())
        .find(|c| c["target"]["path"] == "translation")
        .unwrap();
    let hips = channel["target"]["node"].as_u64().unwrap() as usize;
    let sampler = &animation["samplers"][channel["sampler"].as_u64().unwrap() as usize];
    let keys = floats_of(glb, &json, sampler["output"].as_u64().unwrap() as usize);
    let keys: Vec<glam::Vec3> = keys.chunks(3).map(glam::Vec3::from_slice).collect();
    let nodes = json["nodes"].as_array().unwrap();
    let parent_of = |i: usize| {
        (nodes.iter()).position(|n| {
            let children = n["children"].as_array();
            children.is_some_and(|c| c.iter().any(|c| c.as_u64() == Some(i as u64)))
        })
    };
    let mut above = glam::Mat4::IDENTITY;
    let mut at = parent_of(hips);
    while let Some(p) = at {
        above = local(&nodes[p]) * above;
        at = parent_of(p);
    }
    let place = |t: glam::Vec3| above.transform_point3(t);
    (place(keys[0]), place(*keys.last().unwrap()))
}

#[test]
fn published_avatars_walk_where_the_realizer_walks() {
    let walk = |avatar: &[&str]| {
        let tag = avatar.first().map_or("default", |a| &a[a.len() - 8..]);
        let out = std::env::temp_dir().join(format!("walk-{tag}-{}.glb", std::process::id()));
        let mut args = vec!["run", "--world", "fixtures/examples/room.json", "--no-idle"];
        if let Some(path) = avatar.first() {
            args.extend(["--avatar", path]);
        }
        args.extend(&avatar[avatar.len().min(1)..]);
        args.extend(["--gltf", out.to_str().unwrap()]);
        args.push("fixtures/examples/walk-to-door.xml");
        let (code, _, err) = common::bmlr(&args, "");
        assert_eq!(code, 0, "{err}");
        let glb = std::fs::read(&out).unwrap();
        let _ = std::fs::remove_file(&out);
        travel_in_scene(&glb)
    };
    let (from, to) = walk(&[]);
    let way = (to - from).with_y(0.0);
    assert!(way.length() > 3.0, "the default avatar walked {way}");
    for avatar in [
        &[CESIUM_MAN, "--bone-map", CESIUM_MAP][..],
        &[CRYPTOVOXELS][..],
    ] {
        let (start, end) = walk(avatar);
        let went = (end - start).with_y(0.0);
        let off = went.angle_between(way).to_degrees();
        let apart = (start - from).with_y(0.0).length();
        eprintln!(
            "{}: walked {went} ({off:.2}° off), started {apart:.3} m away ({start} against {from})",
            avatar[0]
        );
        assert!(
            off < 2.0,
            "{} walked {off}° off the realizer's way",
            avatar[0]
        );
        assert!(
            apart < 0.1,
            "{} started {apart} m from the realizer's place",
            avatar[0]
        );
    }
}
