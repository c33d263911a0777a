//! `bmlr run --gltf` with avatars: the default one carries the frames' face weights, a
//! Mixamo one moves, bad ones are refused with exit 2 naming the file.

#[path = "common/avatars.rs"]
mod avatars;

use avatars::{glb, test_avatar, Kind};
use bml_realizer::character::avatar::{self, Model};
use serde_json::Value;

/// `bmlr run --gltf out --avatar avatar fixtures/examples/welcome.xml`: exit code and stderr.
fn welcome_on(avatar: &std::path::Path, out: &std::path::Path) -> (i32, String) {
    bmlr(&[
        "run",
        "--gltf",
        out.to_str().unwrap(),
        "--avatar",
        avatar.to_str().unwrap(),
        "fixtures/examples/welcome.xml",
    ])
}

/// `bmlr` with `args`: its exit code and stderr.
fn bmlr(args: &[&str]) -> (i32, String) {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_bmlr"))
        .args(args)
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn the_exported_avatar_carries_the_frames_face_weights_and_its_own_node_names() {
    let dir = std::env::temp_dir().join(format!("bmlr-avatar-run-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (glb, frames) = (dir.join("welcome.glb"), dir.join("welcome.jsonl"));
    let (code, err) = bmlr(&[
        "run",
        "--gltf",
        glb.to_str().unwrap(),
        "--frames",
        frames.to_str().unwrap(),
        "fixtures/examples/welcome.xml",
    ]);
    assert_eq!(code, 0, "{err}");
    let g = gltf::Gltf::from_slice(&std::fs::read(&glb).unwrap()).unwrap();
    let blob = g.blob.as_deref().unwrap();
    let names: Vec<&str> = g.document.nodes().filter_map(|n| n.name()).collect();
    assert!(
        names.contains(&"l_elbow") && names.contains(&"body"),
        "{names:?}"
    );
    let animation = g.document.animations().next().unwrap();
    let weights = animation
        .channels()
        .find(|c| c.target().property() == gltf::animation::Property::MorphTargetWeights)
        .unwrap();
    let r = weights.reader(|_| Some(blob));
    let times: Vec<f32> = r.read_inputs().unwrap().collect();
    let values: Vec<f32> = match r.read_outputs().unwrap() {
        gltf::animation::util::ReadOutputs::MorphTargetWeights(w) => w.into_f32().collect(),
        _ => unreachable!(),
    };
    let targets = avatar::default_model().morphs[0].clone();
    let lines: Vec<Value> = std::fs::read_to_string(&frames)
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(lines.len(), times.len());
    let mut spoken = 0;
    for (k, line) in lines.iter().enumerate() {
        assert!((line["time"].as_f64().unwrap() as f32 - times[k]).abs() < 1e-6);
        let morphs = line["characters"][""]["morphs"]
            .as_object()
            .cloned()
            .unwrap_or_default();
        for (m, name) in targets.iter().enumerate() {
            let want = morphs.get(name).and_then(Value::as_f64).unwrap_or(0.0) as f32;
            let got = values[k * targets.len() + m];
            assert!(
                (want - got).abs() < 1e-3,
                "frame {k} {name}: {got} in the file, {want} in the frames"
            );
        }
        spoken += usize::from(morphs.get("jawOpen").and_then(Value::as_f64).unwrap_or(0.0) > 0.2);
    }
    assert!(spoken > 20, "the mouth opens in {spoken} frames");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bmlr_refuses_a_bad_avatar_with_exit_2_naming_the_file() {
    let dir = std::env::temp_dir().join(format!("bmlr-avatar-bad-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bad = dir.join("broken.glb");
    std::fs::write(&bad, b"glTF\x02\0\0\0garbage").unwrap();
    let out = dir.join("out.glb");
    let (code, err) = welcome_on(&bad, &out);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("broken.glb: not a valid GLB"), "{err}");
    assert!(!out.exists());
    let vrm = dir.join("nolowerarm.vrm");
    let model = Model::from_glb("x", &test_avatar(Kind::Vrm1)).unwrap();
    let mut json = model.json.clone();
    json["extensions"]["VRMC_vrm"]["humanoid"]["humanBones"]
        .as_object_mut()
        .unwrap()
        .remove("rightLowerArm");
    std::fs::write(&vrm, glb(&json)).unwrap();
    let (code, err) = welcome_on(&vrm, &out);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("nolowerarm.vrm: its skeleton is not a whole humanoid: no bone rightLowerArm was found. Give a bone map"),
        "{err}"
    );
    let (code, err) = bmlr(&[
        "run",
        "--avatar",
        vrm.to_str().unwrap(),
        "fixtures/examples/welcome.xml",
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--avatar shows the motion in --gltf"), "{err}");
    // the live view: a bad avatar stops `serve` before it listens; no view, no avatar
    let live = ["serve", "--tcp", "127.0.0.1:0", "--view", "127.0.0.1:0"];
    let (code, err) = bmlr(&[&live[..], &["--avatar", bad.to_str().unwrap()]].concat());
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("broken.glb: not a valid GLB"), "{err}");
    let (code, err) = bmlr(&[
        "serve",
        "--tcp",
        "127.0.0.1:0",
        "--avatar",
        bad.to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("give --view too"), "{err}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_mixamo_avatar_moves_under_bmlr_run_and_the_file_passes_through_gltf() {
    let dir = std::env::temp_dir().join(format!("bmlr-avatar-mixamo-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let avatar = dir.join("mixamo.glb");
    std::fs::write(&avatar, test_avatar(Kind::Mixamo)).unwrap();
    let out = dir.join("out.glb");
    let (code, err) = welcome_on(&avatar, &out);
    assert_eq!(code, 0, "{err}");
    let model = Model::read(&out).unwrap();
    assert!(model.node("mixamorig:RightForeArm").is_some());
    let g = gltf::Gltf::from_slice(&std::fs::read(&out).unwrap()).unwrap();
    let animation = g.document.animations().next().unwrap();
    // the beat lifts the right upper arm: its keys turn it well away from its first one
    let blob = g.blob.as_deref().unwrap();
    let arm = animation
        .channels()
        .find(|c| {
            c.target().property() == gltf::animation::Property::Rotation
                && c.target().node().name() == Some("mixamorig:RightArm")
        })
        .expect("a rotation channel for mixamorig:RightArm");
    let keys: Vec<glam::Quat> = match arm.reader(|_| Some(blob)).read_outputs().unwrap() {
        gltf::animation::util::ReadOutputs::Rotations(r) => {
            r.into_f32().map(glam::Quat::from_array).collect()
        }
        _ => unreachable!(),
    };
    let widest = keys
        .iter()
        .map(|q| q.angle_between(keys[0]))
        .fold(0.0f32, f32::max);
    assert!(
        widest.to_degrees() > 20.0,
        "the right arm turns {}°",
        widest.to_degrees()
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_exported_avatar_animates_its_forearm_twist_bones() {
    let dir = std::env::temp_dir().join(format!("bmlr-avatar-twist-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let avatar = dir.join("twist.vrm");
    std::fs::write(&avatar, test_avatar(Kind::Vrm1)).unwrap();
    let out = dir.join("out.glb");
    let (code, err) = welcome_on(&avatar, &out);
    assert_eq!(code, 0, "{err}");
    let g = gltf::Gltf::from_slice(&std::fs::read(&out).unwrap()).unwrap();
    let animation = g.document.animations().next().unwrap();
    let turned: Vec<String> = (animation.channels())
        .filter(|c| c.target().property() == gltf::animation::Property::Rotation)
        .filter_map(|c| c.target().node().name().map(str::to_string))
        .collect();
    for (twist, ..) in avatars::TWISTS {
        assert!(turned.iter().any(|n| n == twist), "no keys for {twist}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_character_takes_the_avatar_the_world_file_gives_it() {
    let dir = std::env::temp_dir().join(format!("bmlr-avatar-world-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("mixamo.glb"), test_avatar(Kind::Mixamo)).unwrap();
    let mut world: Value =
        serde_json::from_str(&std::fs::read_to_string("fixtures/examples/world.json").unwrap())
            .unwrap();
    world["characters"]["Alice"]["avatar"] = Value::from("mixamo.glb");
    let file = dir.join("world.json");
    std::fs::write(&file, world.to_string()).unwrap();
    let (alice, bob) = (dir.join("alice.glb"), dir.join("bob.glb"));
    let run = |out: &std::path::Path, who: &str, blocks: &str| {
        bmlr(&[
            "run",
            "--world",
            file.to_str().unwrap(),
            "--character",
            who,
            "--gltf",
            out.to_str().unwrap(),
            blocks,
        ])
    };
    let (code, err) = run(&alice, "Alice", "fixtures/examples/two-alice.xml");
    assert_eq!(code, 0, "{err}");
    assert!(Model::read(&alice)
        .unwrap()
        .node("mixamorig:RightArm")
        .is_some());
    // Bob has none in the world file: the default avatar
    let (code, err) = run(&bob, "Bob", "fixtures/examples/two-bob.xml");
    assert_eq!(code, 0, "{err}");
    assert!(Model::read(&bob).unwrap().node("l_eyeball_joint").is_some());
    // both without --character: one scene, Alice on hers (the world file's), Bob on the default
    let both = dir.join("both.glb");
    let (code, err) = bmlr(&[
        "run",
        "--world",
        file.to_str().unwrap(),
        "--gltf",
        both.to_str().unwrap(),
        "fixtures/examples/two-alice.xml",
        "fixtures/examples/two-bob.xml",
    ]);
    assert_eq!(code, 0, "{err}");
    let g = gltf::Gltf::from_slice(&std::fs::read(&both).unwrap()).unwrap();
    assert_eq!(g.document.skins().count(), 2, "a skin per character");
    assert_eq!(
        g.document.animations().count(),
        1,
        "one animation plays both"
    );
    let under = |who: &str| -> Vec<String> {
        let top = g.document.nodes().find(|n| n.name() == Some(who)).unwrap();
        let mut names = Vec::new();
        let mut stack: Vec<_> = top.children().collect();
        while let Some(n) = stack.pop() {
            names.extend(n.name().map(str::to_string));
            stack.extend(n.children());
        }
        names
    };
    assert!(under("Alice").iter().any(|n| n == "mixamorig:RightArm"));
    assert!(under("Bob").iter().any(|n| n == "l_eyeball_joint"));
    // every channel's node is one of the scene's, and both characters' bones are keyed
    let animation = g.document.animations().next().unwrap();
    let keyed: Vec<String> = (animation.channels())
        .filter_map(|c| c.target().node().name().map(str::to_string))
        .collect();
    assert!(keyed.iter().any(|n| n == "mixamorig:RightArm"));
    assert!(keyed.iter().any(|n| n == "r_shoulder"));
    // a world file naming an avatar that is not there: exit 2 naming the character and file
    world["characters"]["Bob"]["avatar"] = Value::from("missing.vrm");
    std::fs::write(&file, world.to_string()).unwrap();
    let (code, err) = run(&bob, "Bob", "fixtures/examples/two-bob.xml");
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("world file: character 'Bob': ")
            && err.contains("missing.vrm: cannot read it"),
        "{err}"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}
