//! Avatars written in every way the glTF 2.0 specification allows (tests/common/avatar_mesh.rs):
//! accessors without a `bufferView` (zeros), sparse accessors without a base view, normalized
//! 8- and 16-bit joints and weights, quantized positions, targets moving one of two primitives,
//! `.gltf` files with `data:` URIs and with two `.bin` files beside them. Each is read, its limbs
//! retargeted within 1° mean / 2° worst over 500 random poses, and driven by `bmlr run --avatar
//! … --gltf`: the export keeps the file's own data and adds the animation (its arm turns, its
//! `jawOpen` target is keyed where it has one). The exports are left in
//! `target/avatar-forms/` for `.ci/run`, which passes them through the Khronos glTF-Validator
//! and three.js's loader. Also: what is refused, and how (exit 2, a sentence, nothing on
//! stdout).

#[path = "common/avatar_mesh.rs"]
mod avatar_mesh;
#[path = "common/avatars.rs"]
mod avatars;
mod common;

use std::path::{Path, PathBuf};

use avatar_mesh::{gltf_embedded, gltf_two_files, with_mesh, Case, CASES};
use avatars::{floats_of, glb_json, glb_with, limb_errors, random_pose, test_avatar, Kind, LIMBS};
use bml_realizer::character::avatar::{Model, Retarget};
use bml_realizer::character::body::pose::Pose;
use bml_realizer::character::body::skeleton::Skeleton;
use bml_realizer::rng::Rng;
use common::drive;
use serde_json::{json, Value};

/// The Mixamo-named test avatar's JSON and rest transforms (no mesh yet).
fn skeleton_only() -> (Value, Vec<glam::Mat4>) {
    let model = Model::from_glb("mixamo", &test_avatar(Kind::Mixamo)).unwrap();
    let rest = (0..model.nodes.len())
        .map(|i| model.rest_world(i))
        .collect();
    (model.json, rest)
}

/// Where this test writes its files.
fn out_dir() -> PathBuf {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("target/avatar-forms");
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Every fixture, written under `in-TAG` (each test its own: they run at once): (name, file
/// written, what the avatar holds as JSON).
fn fixtures(tag: &str) -> Vec<(String, PathBuf, Value)> {
    let (json, rest) = skeleton_only();
    let dir = out_dir().join(format!("in-{tag}"));
    std::fs::create_dir_all(&dir).unwrap();
    let mut all = Vec::new();
    for case in CASES {
        let (doc, bin) = with_mesh(json.clone(), &rest, case);
        let name = format!("{case:?}");
        let path = dir.join(format!("{name}.glb"));
        std::fs::write(&path, glb_with(&doc, &bin)).unwrap();
        all.push((name, path, doc));
    }
    let (doc, bin) = with_mesh(json.clone(), &rest, Case::SparseNoBase);
    let path = dir.join("embedded.gltf");
    std::fs::write(&path, gltf_embedded(&doc, &bin)).unwrap();
    all.push(("embedded .gltf".into(), path, doc.clone()));
    let two = dir.join("two");
    std::fs::create_dir_all(&two).unwrap();
    let (text, files) = gltf_two_files(&doc, &bin);
    for (f, bytes) in files {
        std::fs::write(two.join(f), bytes).unwrap();
    }
    let path = two.join("two-buffers.gltf");
    std::fs::write(&path, text).unwrap();
    all.push(("two .bin files".into(), path, doc));
    all
}

#[test]
fn every_way_the_specification_allows_is_read_and_retargeted() {
    let skeleton = Skeleton::adult();
    for (name, path, _) in fixtures("read") {
        let model = Model::read(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
        let retarget = Retarget::new(&model, &skeleton, None).unwrap();
        assert_eq!(
            limb_errors(&model, &retarget, &skeleton, &Pose::rest(&skeleton)).len(),
            LIMBS.len()
        );
        let mut rng = Rng(7);
        let (mut sum, mut count, mut worst) = (0.0, 0, 0.0f32);
        for _ in 0..500 {
            let pose = random_pose(&skeleton, &mut rng, 1.2);
            for e in limb_errors(&model, &retarget, &skeleton, &pose) {
                (sum, count, worst) = (sum + e, count + 1, worst.max(e));
            }
        }
        let mean = sum / count as f32;
        assert!(
            mean < 1.0 && worst < 2.0,
            "{name}: mean {mean}°, worst {worst}°"
        );
        // the buffers gathered into one, every view inside it
        let views = model.json["bufferViews"].as_array().unwrap();
        for v in views {
            assert_eq!(v["buffer"], 0, "{name}");
            let end = v["byteOffset"].as_u64().unwrap_or(0) + v["byteLength"].as_u64().unwrap();
            assert!(end as usize <= model.bin.len(), "{name}");
        }
        // (the weights and quantized cases carry no morph target)
        let targets: &[&str] = match name.as_str() {
            "WeightsU8" | "WeightsU16" | "Quantized" => &[],
            _ => &["jawOpen"],
        };
        assert_eq!(model.morphs[0], targets, "{name}");
    }
}

#[test]
fn bmlr_drives_each_and_the_export_keeps_the_file_s_data() {
    let out = out_dir();
    for (name, path, doc) in fixtures("run") {
        let glb = out.join(format!("{}.glb", name.replace([' ', '.'], "-")));
        let (code, stdout, err) = drive(&path, &[], &glb);
        assert_eq!(code, 0, "{name}: {err}");
        assert!(stdout.contains("blockProgress"), "{name}");
        let json = glb_json(&std::fs::read(&glb).unwrap());
        // the file's own accessors kept as they were (a bufferView-less one stays without)
        let theirs = doc["accessors"].as_array().unwrap();
        let ours = json["accessors"].as_array().unwrap();
        for (k, a) in theirs.iter().enumerate() {
            assert_eq!(
                a.get("bufferView").is_some(),
                ours[k].get("bufferView").is_some(),
                "{name}: accessors[{k}]"
            );
            assert_eq!(
                a.get("sparse").is_some(),
                ours[k].get("sparse").is_some(),
                "{name}: accessors[{k}]"
            );
        }
        // the arm is keyed, and the face where there is a target
        let channels = json["animations"][0]["channels"].as_array().unwrap();
        let nodes = json["nodes"].as_array().unwrap();
        let keyed = |node: &str, path: &str| {
            channels.iter().any(|c| {
                let n = c["target"]["node"].as_u64().unwrap() as usize;
                c["target"]["path"] == path && nodes[n]["name"].as_str().unwrap().ends_with(node)
            })
        };
        assert!(keyed("LeftArm", "rotation"), "{name}");
        let has_target = doc["meshes"][0].get("weights").is_some();
        assert_eq!(keyed("body", "weights"), has_target, "{name}");
    }
}

#[test]
fn what_cannot_be_driven_is_refused_with_a_sentence_that_says_what_to_do() {
    let (json, rest) = skeleton_only();
    let (doc, bin) = with_mesh(json, &rest, Case::NoBufferView);
    let dir = out_dir().join("refused");
    std::fs::create_dir_all(&dir).unwrap();
    let mut refused = Vec::new();
    // meshopt and Draco: required extensions the realizer does not read
    for (ext, says) in [
        ("EXT_meshopt_compression", "compressed with meshopt"),
        ("KHR_draco_mesh_compression", "Draco-compressed"),
    ] {
        let mut d = doc.clone();
        d["extensionsUsed"] = json!([ext]);
        d["extensionsRequired"] = json!([ext]);
        let path = dir.join(format!("{ext}.glb"));
        std::fs::write(&path, glb_with(&d, &bin)).unwrap();
        refused.push((
            path,
            vec![
                format!("requires the glTF extension {ext}"),
                says.to_string(),
            ],
        ));
    }
    // a skeleton that is no humanoid: its bones renamed
    let mut d = doc.clone();
    for n in d["nodes"].as_array_mut().unwrap() {
        if let Some(name) = n["name"].as_str() {
            n["name"] = json!(name.replace("mixamorig:", "bone_"));
        }
    }
    let path = dir.join("odd-names.glb");
    std::fs::write(&path, glb_with(&d, &bin)).unwrap();
    refused.push((
        path,
        vec![
            "match no known scheme".into(),
            r#"Give a bone map (--bone-map MAP.json) naming the node of each: {"hips": "NODE""#
                .into(),
            "the skin's joints are bone_Hips, bone_Spine".into(),
        ],
    ));
    // an FBX
    let path = dir.join("rig.fbx");
    std::fs::write(&path, b"Kaydara FBX Binary  \x00\x1a\x00\xe8\x1c\x00\x00").unwrap();
    refused.push((
        path,
        vec!["an FBX file".into(), "FBX2glTF".into(), "Blender".into()],
    ));
    for (path, says) in refused {
        let (code, stdout, err) = drive(&path, &[], &path.with_extension("out.glb"));
        assert_eq!(code, 2, "{}: {err}", path.display());
        assert!(stdout.is_empty(), "{}: {stdout}", path.display());
        let file = path.file_name().unwrap().to_str().unwrap();
        assert!(err.contains(file), "{err}");
        for s in says {
            assert!(err.contains(&s), "{file}: '{s}' not in {err}");
        }
    }
}

#[test]
fn a_vrm_0_x_s_blend_shape_presets_move_its_own_targets_while_it_speaks() {
    let model = Model::from_glb("vrm0", &test_avatar(Kind::Vrm0)).unwrap();
    let rest: Vec<glam::Mat4> = (0..model.nodes.len())
        .map(|i| model.rest_world(i))
        .collect();
    let (mut doc, bin) = with_mesh(model.json, &rest, Case::SparseNoBase);
    // VRoid's own target name, reached only through the preset "a" (VRM 0.x weighs 0–100)
    doc["meshes"][0]["extras"]["targetNames"] = json!(["Fcl_MTH_A"]);
    doc["extensions"]["VRM"]["blendShapeMaster"] = json!({"blendShapeGroups": [
        {"name": "A", "presetName": "a", "binds": [{"mesh": 0, "index": 0, "weight": 100}]},
    ]});
    let dir = out_dir().join("in-vrm0");
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("presets.vrm");
    std::fs::write(&path, glb_with(&doc, &bin)).unwrap();
    let out = out_dir().join("vrm0-presets.glb");
    let (code, _, err) = drive(&path, &[], &out);
    assert_eq!(code, 0, "{err}");
    let bytes = std::fs::read(&out).unwrap();
    let json = glb_json(&bytes);
    let animation = &json["animations"][0];
    let nodes = json["nodes"].as_array().unwrap();
    let channel = (animation["channels"].as_array().unwrap().iter())
        .find(|c| {
            c["target"]["path"] == "weights"
                && nodes[c["target"]["node"].as_u64().unwrap() as usize]["name"] == "body"
        })
        .expect("the body's target weights are keyed");
    let sampler = &animation["samplers"][channel["sampler"].as_u64().unwrap() as usize];
    let weights = floats_of(&bytes, &json, sampler["output"].as_u64().unwrap() as usize);
    let most = weights.iter().fold(0.0f32, |a, &b| a.max(b));
    eprintln!("the A target peaks at {most} over {} keys", weights.len());
    // the mouth opens on "a" while "Hello and welcome" is spoken
    assert!(most > 0.2, "the A target's weight peaks at {most}");
}
