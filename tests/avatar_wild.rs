//! Avatars other people published, read as they are (`fixtures/avatars/`, each with its
//! licence beside it; docs/avatars.md lists what was tried). CesiumMan (Cesium, CC-BY 4.0, as
//! Khronos's glTF sample models carry it: a `.gltf` with its `.bin` and texture beside it,
//! written by COLLADA2GLTF): its joints have no names, so it is refused naming the bones and
//! showing the bone-map form with the joints' indices, and driven with the bone map beside it
//! (node indices): every limb within 1° mean / 2° worst of the realizer's over 500 random
//! poses, and the right hand up for the beat of the welcome block.

#[path = "common/avatars.rs"]
mod avatars;
mod common;

use std::collections::BTreeMap;
use std::path::Path;

use avatars::{glb_json, limb_errors_by, random_pose};
use bml_realizer::avatar::{humanoid, Model, Retarget};
use bml_realizer::body::pose::Pose;
use bml_realizer::body::skeleton::Skeleton;
use bml_realizer::realizer::Realizer;
use bml_realizer::rng::Rng;
use common::drive;

const CESIUM_MAN: &str = "fixtures/avatars/cesium-man/CesiumMan.gltf";
const CESIUM_MAP: &str = "fixtures/avatars/cesium-man/bone-map.json";

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
    let at_rest = Pose::rest(&skeleton).world(&skeleton);
    let rest_world = retarget.world(&retarget.pose(&Pose::rest(&skeleton)));
    let place = |m: &glam::Mat4| m.w_axis.truncate();
    let mut rng = Rng(5);
    let (mut sum, mut count, mut worst, mut feet) = (0.0, 0, 0.0f32, 0.0f32);
    for _ in 0..500 {
        let pose = random_pose(&skeleton, &mut rng, 1.2);
        for e in limb_errors_by(&retarget, &skeleton, &pose, node_of) {
            (sum, count, worst) = (sum + e, count + 1, worst.max(e));
        }
        // a foot turns as the realizer's ankle turns since rest
        let posed = retarget.world(&retarget.pose(&pose));
        let realizer = pose.world(&skeleton);
        for (foot, toes, ankle) in [(9, 10, "l_talocrural"), (5, 6, "r_talocrural")] {
            let j = skeleton.joint(ankle).unwrap();
            let turn = realizer.orientations[j] * at_rest.orientations[j].inverse();
            let f = retarget.frame();
            let want =
                f * turn * f.inverse() * (place(&rest_world[toes]) - place(&rest_world[foot]));
            let got = place(&posed[toes]) - place(&posed[foot]);
            feet = feet.max(got.angle_between(want).to_degrees());
        }
    }
    let mean = sum / count as f32;
    assert!(mean < 1.0 && worst < 2.0, "mean {mean}°, worst {worst}°");
    assert!(feet < 2.0, "a foot turned {feet}° away from the realizer's");
    // the welcome block's beat lifts the right hand (node 15) at its stroke
    let mut r = Realizer::new().with_idle(false);
    r.perform_bml(&std::fs::read_to_string("fixtures/examples/welcome.xml").unwrap())
        .unwrap();
    let hand_at = |r: &mut Realizer, t: f64| {
        let pose = r.tick(t).poses[0].pose.clone();
        let world = retarget.world(&retarget.pose(&pose));
        world[15].w_axis.truncate()
    };
    let before = hand_at(&mut r, 0.1);
    let stroke = hand_at(&mut r, 0.821);
    let rise = stroke.y - before.y;
    assert!(rise > 0.1, "the right hand rose {rise} m for the beat");
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
    let channels = json["animations"].as_array().unwrap().last().unwrap()["channels"]
        .as_array()
        .unwrap()
        .len();
    assert!(channels >= 19, "{channels} channels");
    let _ = std::fs::remove_file(&out);
}
