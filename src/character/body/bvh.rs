//! BVH export: a skeleton's hierarchy (offsets in centimetres, the root with position and
//! rotation channels, every other joint with rotations, Z X Y order as most tools expect) and one
//! motion line per pose.

use std::fmt::Write as _;

use glam::{EulerRot, Quat};

use super::pose::Pose;
use super::skeleton::Skeleton;

/// Metres to BVH centimetres.
const CM: f32 = 100.0;

/// Z, X, Y Euler angles in degrees of a rotation, such that `Rz · Rx · Ry` is the rotation (the
/// meaning of BVH's `Zrotation Xrotation Yrotation` channels).
pub fn zxy_degrees(q: Quat) -> [f32; 3] {
    let (z, x, y) = q.to_euler(EulerRot::ZXY);
    [z.to_degrees(), x.to_degrees(), y.to_degrees()]
}

fn hierarchy(s: &Skeleton, i: usize, depth: usize, out: &mut String) {
    let pad = "  ".repeat(depth);
    let j = &s.joints()[i];
    let o = j.offset * CM;
    if j.parent.is_none() {
        let _ = writeln!(out, "{pad}ROOT {}", j.name);
        let _ = writeln!(out, "{pad}{{");
        // the root's translation is a channel; its offset is the origin
        let _ = writeln!(out, "{pad}  OFFSET 0.000000 0.000000 0.000000");
        let _ = writeln!(
            out,
            "{pad}  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation"
        );
    } else {
        let _ = writeln!(out, "{pad}JOINT {}", j.name);
        let _ = writeln!(out, "{pad}{{");
        let _ = writeln!(out, "{pad}  OFFSET {:.6} {:.6} {:.6}", o.x, o.y, o.z);
        let _ = writeln!(out, "{pad}  CHANNELS 3 Zrotation Xrotation Yrotation");
    }
    let children: Vec<usize> = s.children(i).collect();
    if children.is_empty() {
        // a leaf ends a little further along its bone
        let end = if j.offset.length() > 0.0 {
            j.offset.normalize() * 0.05 * CM
        } else {
            glam::Vec3::Y * 0.05 * CM
        };
        let _ = writeln!(out, "{pad}  End Site");
        let _ = writeln!(out, "{pad}  {{");
        let _ = writeln!(
            out,
            "{pad}    OFFSET {:.6} {:.6} {:.6}",
            end.x, end.y, end.z
        );
        let _ = writeln!(out, "{pad}  }}");
    }
    for c in children {
        hierarchy(s, c, depth + 1, out);
    }
    let _ = writeln!(out, "{pad}}}");
}

/// The joints in the order their channels appear (depth first, as the hierarchy is written).
fn channel_order(s: &Skeleton) -> Vec<usize> {
    fn visit(s: &Skeleton, i: usize, out: &mut Vec<usize>) {
        out.push(i);
        for c in s.children(i) {
            visit(s, c, out);
        }
    }
    let mut out = Vec::with_capacity(s.len());
    visit(s, 0, &mut out);
    out
}

/// The BVH text of `poses` sampled every `1 / fps` seconds.
pub fn write(skeleton: &Skeleton, poses: &[Pose], fps: f64) -> String {
    let mut out = String::from("HIERARCHY\n");
    hierarchy(skeleton, 0, 0, &mut out);
    let _ = writeln!(out, "MOTION");
    let _ = writeln!(out, "Frames: {}", poses.len());
    let _ = writeln!(out, "Frame Time: {:.6}", 1.0 / fps);
    let order = channel_order(skeleton);
    for p in poses {
        let mut line = String::new();
        for (k, &i) in order.iter().enumerate() {
            if k == 0 {
                let r = p.root * CM;
                let _ = write!(line, "{:.4} {:.4} {:.4} ", r.x, r.y, r.z);
            }
            let q = p.rotations.get(i).copied().unwrap_or(Quat::IDENTITY);
            let [z, x, y] = zxy_degrees(q);
            let _ = write!(line, "{z:.4} {x:.4} {y:.4} ");
        }
        out.push_str(line.trim_end());
        out.push('\n');
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zxy_angles_compose_back_to_the_rotation() {
        let q =
            Quat::from_rotation_z(0.3) * Quat::from_rotation_x(-0.4) * Quat::from_rotation_y(1.1);
        let [z, x, y] = zxy_degrees(q);
        assert!((z - 0.3f32.to_degrees()).abs() < 1e-3);
        assert!((x + 0.4f32.to_degrees()).abs() < 1e-3);
        assert!((y - 1.1f32.to_degrees()).abs() < 1e-3);
    }

    #[test]
    fn a_bvh_has_every_joint_and_one_line_of_channels_per_frame() {
        let s = Skeleton::adult();
        let mut nod = Pose::rest(&s);
        nod.rotate(s.joint("skullbase").unwrap(), Quat::from_rotation_x(0.2));
        let text = write(&s, &[Pose::rest(&s), nod], 60.0);
        assert_eq!(
            text.matches("JOINT ").count() + text.matches("ROOT ").count(),
            s.len()
        );
        assert!(text.contains("Frames: 2\nFrame Time: 0.016667\n"));
        let frames: Vec<&str> = text
            .lines()
            .skip_while(|l| !l.starts_with("Frame Time"))
            .skip(1)
            .collect();
        assert_eq!(frames.len(), 2);
        for f in &frames {
            assert_eq!(f.split_whitespace().count(), 6 + 3 * (s.len() - 1));
        }
        // the root starts at its rest height (95 cm)
        assert!(frames[0].starts_with("0.0000 95.0000 0.0000 "));
        // the nod shows as an X rotation of 11.46° on the skull base's channels
        assert!(frames[1].contains("11.4592"), "{}", frames[1]);
    }
}
