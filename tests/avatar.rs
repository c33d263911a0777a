//! Avatars: the default avatar's make (size, skin weights, face targets, rest pose), and the
//! realizer's motion retargeted onto avatars built here: a Mixamo-named T-pose in centimetres
//! under a turned armature, a VRM 1.0 in an A-pose with every bone's axes turned at random and
//! two spine bones, and a VRM 0.x in a T-pose facing −z. Over random realizer poses the world
//! direction of every limb bone must match the realizer's.

#[path = "common/avatars.rs"]
mod avatars;

use std::collections::BTreeMap;

use avatars::{glb, limb_errors, random_pose, test_avatar, Kind, LIMBS, TWISTS};
use bml_realizer::character::avatar::{self, Model, Retarget};
use bml_realizer::character::body::pose::Pose;
use bml_realizer::character::body::skeleton::Skeleton;
use bml_realizer::rng::Rng;
use glam::{Mat4, Quat, Vec3};
use serde_json::json;

#[test]
fn every_limb_bone_of_three_kinds_of_avatar_points_where_the_realizer_s_does() {
    let skeleton = Skeleton::adult();
    for (kind, what) in [
        (Kind::Mixamo, "Mixamo T-pose in cm"),
        (Kind::Vrm1, "VRM 1.0 A-pose, odd axes"),
        (Kind::Vrm0, "VRM 0.x facing -z"),
    ] {
        let model = Model::from_glb(what, &test_avatar(kind)).unwrap();
        let retarget = Retarget::new(&model, &skeleton, None).unwrap();
        let rest = limb_errors(&model, &retarget, &skeleton, &Pose::rest(&skeleton));
        // every limb is checked (none dropped for want of a bone)
        assert_eq!(rest.len(), LIMBS.len(), "{what}");
        let worst = rest.iter().fold(0.0f32, |a, &b| a.max(b));
        assert!(worst < 2.0, "{what}: at rest a limb is {worst}° off");
        let mut rng = Rng(99);
        let (mut sum, mut count, mut worst) = (0.0, 0, 0.0f32);
        for _ in 0..500 {
            let pose = random_pose(&skeleton, &mut rng, 1.2);
            for e in limb_errors(&model, &retarget, &skeleton, &pose) {
                sum += e;
                count += 1;
                worst = worst.max(e);
            }
        }
        let mean = sum / count as f32;
        assert!(
            mean < 1.0 && worst < 2.0,
            "{what}: mean {mean}°, worst {worst}°"
        );
    }
}

#[test]
fn arm_twist_bones_take_their_share_of_the_wrist_s_and_the_shoulder_s_twist() {
    let skeleton = Skeleton::adult();
    let model = Model::from_glb("vrm1", &test_avatar(Kind::Vrm1)).unwrap();
    let retarget = Retarget::new(&model, &skeleton, None).unwrap();
    let node = |name: &str| {
        (model.nodes.iter())
            .position(|n| n.name == name || n.name == format!("J_{name}"))
            .unwrap()
    };
    let rotation = |m: &Mat4| m.to_scale_rotation_translation().1;
    let rest = retarget.world(&retarget.pose(&Pose::rest(&skeleton)));
    let realizer_rest = Pose::rest(&skeleton).world(&skeleton).positions;
    let mut rng = Rng(5);
    let mut worst = [0.0f32; 2];
    for _ in 0..300 {
        let pose = random_pose(&skeleton, &mut rng, 1.2);
        let posed = retarget.world(&retarget.pose(&pose));
        for &(name, _, bone, share) in TWISTS {
            let (end_bone, start, end, twisting, kept) = avatars::twist_segment(bone);
            let (t, b, e) = (node(name), node(bone), node(&end_bone));
            let side = if bone.starts_with("left") { "l_" } else { "r_" };
            let joint = |j: &str| skeleton.joint(&format!("{side}{j}")).unwrap();
            // the twisting joint's twist about the realizer's segment
            let about = (realizer_rest[joint(end)] - realizer_rest[joint(start)]).normalize();
            let q = pose.rotations[joint(twisting)];
            let angle = 2.0 * Vec3::new(q.x, q.y, q.z).dot(about).atan2(q.w);
            // the twist bone turned, since rest, relative to the segment's bone: about the
            // avatar's segment by its share of that, less what the bone keeps itself
            let axis = (rest[e].w_axis - rest[b].w_axis).truncate().normalize();
            let since = |i: usize| rotation(&posed[i]) * rotation(&rest[i]).inverse();
            let relative = since(b).inverse() * since(t);
            let expected = Quat::from_axis_angle(axis, (share - kept) * angle);
            let upper = usize::from(kept > 0.5);
            worst[upper] = worst[upper].max(relative.angle_between(expected).to_degrees());
        }
    }
    assert!(
        worst[0] < 0.5 && worst[1] < 0.5,
        "a twist bone is off its share of the twist: forearm {}°, upper arm {}°",
        worst[0],
        worst[1]
    );
}

#[test]
fn the_travel_of_the_root_is_scaled_by_leg_length_and_turned_into_the_avatar_s_frame() {
    let skeleton = Skeleton::adult();
    let model = Model::from_glb("vrm0", &test_avatar(Kind::Vrm0)).unwrap();
    let retarget = Retarget::new(&model, &skeleton, None).unwrap();
    let mut pose = Pose::rest(&skeleton);
    let at_rest = retarget.pose(&pose);
    let rest_world = retarget.world(&at_rest);
    pose.root += Vec3::new(0.0, 0.0, 1.0);
    let walked = retarget.world(&retarget.pose(&pose));
    let hips = at_rest.hips.0;
    let moved = walked[hips].w_axis.truncate() - rest_world[hips].w_axis.truncate();
    // same leg length (built from the realizer's skeleton), facing −z: a metre forward is −z
    assert!(moved.distance(Vec3::new(0.0, 0.0, -1.0)) < 1e-4, "{moved}");
}

#[test]
fn bad_avatars_are_refused_naming_the_file_and_what_is_missing() {
    let skeleton = Skeleton::adult();
    // no skin
    let doc = json!({"asset": {"version": "2.0"}, "nodes": [{"name": "a"}]});
    let e = Model::from_glb("noskin.glb", &glb(&doc)).unwrap_err();
    assert_eq!(
        e.to_string(),
        "noskin.glb: it has no skin (no skinned mesh)"
    );
    // names that match nothing
    let doc = json!({"asset": {"version": "2.0"}, "nodes": [{"name": "bone1"}, {"name": "bone2"}],
                     "skins": [{"joints": [0, 1]}]});
    let model = Model::from_glb("odd.glb", &glb(&doc)).unwrap();
    let e = Retarget::new(&model, &skeleton, None).unwrap_err();
    assert!(
        e.to_string()
            .starts_with("odd.glb: its skeleton's names match no known scheme"),
        "{e}"
    );
    // a VRM without a lower arm
    let model = Model::from_glb("vrm.glb", &test_avatar(Kind::Vrm1)).unwrap();
    let mut json = model.json.clone();
    json["extensions"]["VRMC_vrm"]["humanoid"]["humanBones"]
        .as_object_mut()
        .unwrap()
        .remove("leftLowerArm");
    let model = Model::from_glb("vrm.vrm", &glb(&json)).unwrap();
    let e = Retarget::new(&model, &skeleton, None).unwrap_err();
    assert!(
        e.to_string().starts_with(concat!(
            "vrm.vrm: its skeleton is not a whole humanoid: no bone leftLowerArm was found. ",
            r#"Give a bone map (--bone-map MAP.json) naming the node of each: {"leftLowerArm": "NODE"}; "#,
            "the skin's joints are J_hips, J_spine,"
        )),
        "{e}"
    );
    // broken bytes
    for bytes in [
        &b"glTF\x02\0\0\0\xff\xff"[..],
        b"not a model",
        b"glTF\x02\0\0\0\x40\0\0\0\x10\0\0\0JSON{",
    ] {
        let e = Model::from_glb("broken.glb", bytes).unwrap_err();
        assert!(e.to_string().starts_with("broken.glb: "), "{e}");
    }
    // a glTF whose node names a child out of range
    let doc = json!({"asset": {"version": "2.0"}, "nodes": [{"name": "a", "children": [5]}],
                     "skins": [{"joints": [0]}]});
    let e = Model::from_glb("range.glb", &glb(&doc)).unwrap_err();
    assert!(
        e.to_string().starts_with("range.glb: not valid glTF"),
        "{e}"
    );
    // a huge file (sparse: no disk is used)
    let dir = std::env::temp_dir().join(format!("bmlr-avatar-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let huge = dir.join("huge.glb");
    std::fs::File::create(&huge)
        .unwrap()
        .set_len(avatar::MAX_AVATAR_BYTES + 1)
        .unwrap();
    let e = Model::read(&huge).unwrap_err();
    assert!(e.to_string().contains("more than the"), "{e}");
    // a bone map naming a node that is not there
    let model = Model::from_glb("mixamo.glb", &test_avatar(Kind::Mixamo)).unwrap();
    let map = BTreeMap::from([("leftUpperArm".to_string(), "Arm.L".to_string())]);
    let e = Retarget::new(&model, &skeleton, Some(&map)).unwrap_err();
    assert_eq!(
        e.to_string(),
        "mixamo.glb: bone map: leftUpperArm: no node named 'Arm.L'"
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_default_avatar_is_a_skinned_person_standing_in_the_realizer_s_rest() {
    let g = gltf::Gltf::from_slice(avatar::DEFAULT_GLB).unwrap();
    let blob = g.blob.as_deref().unwrap();
    let mesh = g.document.meshes().next().unwrap();
    let mut triangles = 0;
    for p in mesh.primitives() {
        let r = p.reader(|_| Some(blob));
        triangles += r.read_indices().unwrap().into_u32().count() / 3;
    }
    assert!(triangles >= 10_000, "{triangles} triangles");
    let first = mesh.primitives().next().unwrap();
    let r = first.reader(|_| Some(blob));
    let places: Vec<Vec3> = r.read_positions().unwrap().map(Vec3::from).collect();
    let weights: Vec<[f32; 4]> = r.read_weights(0).unwrap().into_f32().collect();
    for w in &weights {
        let sum: f32 = w.iter().sum();
        assert!((sum - 1.0).abs() < 1e-3, "weights {w:?}");
    }
    let blended = weights
        .iter()
        .filter(|w| w.iter().filter(|&&x| x > 0.0).count() >= 2);
    let share = blended.count() as f32 / weights.len() as f32;
    assert!(
        share >= 0.3,
        "{share} of the vertices blend two joints or more"
    );
    let (low, high) = places
        .iter()
        .fold((f32::MAX, f32::MIN), |(l, h), p| (l.min(p.y), h.max(p.y)));
    assert!(low.abs() < 0.005, "the feet are {low} m off the floor");
    assert!((1.6..=1.9).contains(&(high - low)), "{} m tall", high - low);
    // facing +z: the foremost point above the shoulders is the nose, ahead of the eyes
    let nose = places
        .iter()
        .filter(|p| p.y > 1.4)
        .fold(Vec3::NEG_INFINITY, |a, &p| if p.z > a.z { p } else { a });
    let model = avatar::default_model();
    let eye = model
        .rest_world(model.node("l_eyeball_joint").unwrap())
        .w_axis
        .truncate();
    assert!(
        nose.z > eye.z + 0.005 && (nose.y - eye.y).abs() < 0.08,
        "nose {nose}, eye {eye}"
    );
    // the 52 ARKit targets by name
    let names: std::collections::BTreeSet<&str> =
        model.morphs[0].iter().map(String::as_str).collect();
    let arkit: std::collections::BTreeSet<&str> = bml_realizer::character::face::model::ARKIT
        .into_iter()
        .collect();
    assert_eq!(names, arkit);
    // the realizer's rest: arms and legs straight down, limb by limb as the realizer's skeleton
    let skeleton = Skeleton::adult();
    let rest = Pose::rest(&skeleton).world(&skeleton);
    for (a, b) in [
        ("l_shoulder", "l_elbow"),
        ("l_elbow", "l_wrist"),
        ("r_shoulder", "r_elbow"),
        ("r_elbow", "r_wrist"),
        ("l_wrist", "l_middle1"),
        ("l_hip", "l_knee"),
        ("l_knee", "l_talocrural"),
        ("r_hip", "r_knee"),
        ("r_knee", "r_talocrural"),
    ] {
        let at = |n: &str| model.rest_world(model.node(n).unwrap()).w_axis.truncate();
        let ours = at(b) - at(a);
        let theirs =
            rest.positions[skeleton.joint(b).unwrap()] - rest.positions[skeleton.joint(a).unwrap()];
        let angle = ours.angle_between(theirs).to_degrees();
        assert!(angle < 2.0, "{a}→{b} is {angle}° from the realizer's rest");
    }
    // and the realizer drives it joint by joint, each node turning as its joint (no
    // arithmetic): its limbs point where the realizer's do
    let retarget = Retarget::new(&model, &skeleton, None).unwrap();
    assert!(retarget.is_direct());
    assert_eq!(
        retarget.source(model.node("l_elbow").unwrap()),
        skeleton.joint("l_elbow")
    );
    let mut rng = Rng(5);
    for _ in 0..100 {
        let pose = random_pose(&skeleton, &mut rng, 1.0);
        let world = retarget.world(&retarget.pose(&pose));
        let theirs = pose.world(&skeleton);
        for (a, b) in [
            ("l_shoulder", "l_elbow"),
            ("r_elbow", "r_wrist"),
            ("l_hip", "l_knee"),
        ] {
            let at = |n: &str| world[model.node(n).unwrap()].w_axis.truncate();
            let ours = at(b) - at(a);
            let (ja, jb) = (skeleton.joint(a).unwrap(), skeleton.joint(b).unwrap());
            let angle = ours.angle_between(theirs.positions[jb] - theirs.positions[ja]);
            assert!(angle.to_degrees() < 0.5, "{a}→{b}: {}°", angle.to_degrees());
        }
    }
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig::with_cases(200))]

    /// Built avatars with bytes changed or cut: read, recognised and retargeted, or refused,
    /// never a panic.
    #[test]
    fn damaged_avatars_are_refused_or_driven_never_a_panic(
        kind in 0..3usize,
        changes in proptest::collection::vec((0.0..1.0f64, proptest::prelude::any::<u8>()), 0..12),
        cut in 0.0..1.0f64,
    ) {
        let kind = [Kind::Mixamo, Kind::Vrm1, Kind::Vrm0][kind];
        let mut bytes = test_avatar(kind);
        for (at, value) in changes {
            let i = (at * bytes.len() as f64) as usize % bytes.len();
            bytes[i] = value;
        }
        if cut > 0.8 {
            bytes.truncate((cut * bytes.len() as f64) as usize);
        }
        let skeleton = Skeleton::adult();
        if let Ok(model) = Model::from_glb("damaged.glb", &bytes) {
            if let Ok(retarget) = Retarget::new(&model, &skeleton, None) {
                let posed = retarget.pose(&Pose::rest(&skeleton));
                proptest::prop_assert_eq!(posed.rotations.len(), model.nodes.len());
            }
        }
    }
}
