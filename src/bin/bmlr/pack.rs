//! The frames of a crowd for `bmlr view`, packed: a page of hundreds of characters cannot carry
//! the frames file's JSON (2 kB a character a frame), so it carries each frame's roots as 32-bit
//! floats and only the joints that move, their rotations as 16-bit integers (a quaternion's
//! components times 32767: within 0.01° of the frames file). A joint that never moves for any
//! character is written once per character. The page draws such crowds without faces.

use base64::Engine as _;
use bml_realizer::character::body::{Pose, Skeleton};
use serde_json::{json, Value};

/// Frame times and each character's body in every frame (in the order of `ids`).
pub fn packed(times: &[f64], poses: &[Vec<&Pose>], ids: &[&str]) -> Value {
    let skeleton = Skeleton::adult();
    let joints = skeleton.len();
    let moving: Vec<usize> = (0..joints)
        .filter(|&j| {
            (poses.iter()).any(|frames| {
                let first = frames.first().map(|p| p.rotations[j]);
                (frames.iter()).any(|p| Some(p.rotations[j]) != first)
            })
        })
        .collect();
    let still: Vec<Vec<[f32; 4]>> = (poses.iter())
        .map(|frames| {
            let first = frames.first();
            (0..joints)
                .map(|j| first.map_or([0.0, 0.0, 0.0, 1.0], |p| rounded(p.rotations[j])))
                .collect()
        })
        .collect();
    let mut roots: Vec<u8> = Vec::with_capacity(times.len() * ids.len() * 28);
    let mut rotations: Vec<u8> = Vec::with_capacity(times.len() * ids.len() * moving.len() * 8);
    for k in 0..times.len() {
        for frames in poses {
            let p = frames[k];
            let world = p.world(&skeleton);
            let (at, turn) = (world.positions[0], world.orientations[0].normalize());
            for v in [at.x, at.y, at.z, turn.x, turn.y, turn.z, turn.w] {
                roots.extend_from_slice(&v.to_le_bytes());
            }
            for &j in &moving {
                for v in rounded(p.rotations[j]) {
                    let q = (v * 32767.0).round().clamp(-32767.0, 32767.0) as i16;
                    rotations.extend_from_slice(&q.to_le_bytes());
                }
            }
        }
    }
    let b64 = |bytes: &[u8]| base64::engine::general_purpose::STANDARD.encode(bytes);
    json!({
        "characters": ids,
        "times": times.iter().map(|t| (t * 1e6).round() / 1e6).collect::<Vec<_>>(),
        "moving": moving,
        "still": still,
        "roots": b64(&roots),
        "rotations": b64(&rotations),
    })
}

/// A rotation normalised, its components as `f32`.
fn rounded(q: glam::Quat) -> [f32; 4] {
    q.normalize().to_array()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(turn: f32, x: f32) -> Pose {
        let s = Skeleton::adult();
        let mut pose = Pose::rest(&s);
        pose.rotate(
            s.joint("l_knee").unwrap(),
            glam::Quat::from_rotation_x(turn),
        );
        pose.root.x = x;
        pose
    }

    #[test]
    fn only_moving_joints_go_in_every_frame_and_they_come_back_within_a_hundredth_of_a_degree() {
        let poses = [[at(0.0, 0.0), at(0.5, 0.3)], [at(0.2, 1.0), at(0.2, 1.0)]];
        let borrowed: Vec<Vec<&Pose>> = poses.iter().map(|f| f.iter().collect()).collect();
        let v = packed(&[0.0, 0.5], &borrowed, &["a", "b"]);
        let knee = Skeleton::adult().joint("l_knee").unwrap();
        assert_eq!(v["moving"], json!([knee]));
        let b64 = |k: &str| {
            base64::engine::general_purpose::STANDARD
                .decode(v[k].as_str().unwrap())
                .unwrap()
        };
        let (roots, rotations) = (b64("roots"), b64("rotations"));
        assert_eq!(roots.len(), 2 * 2 * 7 * 4);
        assert_eq!(rotations.len(), 2 * 2 * 4 * 2);
        // frame 1, character a: x 0.3 (the rest root is at x 0), knee turned 0.5 rad
        let f = |b: &[u8], i: usize| f32::from_le_bytes(b[4 * i..4 * i + 4].try_into().unwrap());
        assert_eq!(f(&roots, 14), 0.3);
        let i = |i: usize| i16::from_le_bytes(rotations[2 * i..2 * i + 2].try_into().unwrap());
        let q = glam::Quat::from_xyzw(
            f32::from(i(8)) / 32767.0,
            f32::from(i(9)) / 32767.0,
            f32::from(i(10)) / 32767.0,
            f32::from(i(11)) / 32767.0,
        );
        // component by component (acos is too coarse this near 0): 1e-4 is 0.01°
        let want = poses[0][1].rotations[knee];
        let off = (glam::Vec4::from(q.normalize()) - glam::Vec4::from(want))
            .abs()
            .max_element();
        assert!(off < 1e-4, "{q} against {want}");
        // every joint's first rotation is there too, for the joints that never move
        assert!((v["still"][1][knee][0].as_f64().unwrap() - (0.1f64).sin()).abs() < 1e-6);
    }
}
