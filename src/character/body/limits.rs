//! Joint limits: how far each joint may turn from the rest pose, as data
//! (`fixtures/skeletons/adult-limits.json` for the default adult, with its sources), and the clamp
//! that keeps a pose inside them.
//!
//! A joint's rotation is split into a swing, which moves the joint's bone axis (the direction to
//! its first child; a joint without one continues its own bone; the file may name another axis),
//! and a twist about that axis. The swing is a rotation vector perpendicular to
//! the axis; its two components about the joint's local axes each have a range, and together they
//! must lie inside the ellipse those ranges span (a range's end on each side of zero is that
//! side's semi-axis), so that a diagonal swing is limited as well as a straight one. The twist has
//! a range of its own. A left joint takes its right twin's limits mirrored.

use std::collections::BTreeMap;

use glam::{Quat, Vec3};

use super::pose::Pose;
use super::skeleton::Skeleton;

/// The embedded limits of the default adult.
pub(crate) const ADULT_LIMITS: &str = include_str!("../../../fixtures/skeletons/adult-limits.json");

/// Rotations this close to a limit (radians) count as inside it.
const SLACK: f32 = 1e-4;

/// One joint's limits, in radians, in its local frame.
#[derive(Debug, Clone, PartialEq)]
pub struct Limit {
    /// The bone axis the twist turns about (unit length).
    pub axis: Vec3,
    /// The two swing components: a local axis (0 x, 1 y, 2 z, neither of them `axis`) and its
    /// range.
    pub swing: [(usize, f32, f32); 2],
    /// The range of the twist about `axis`.
    pub twist: (f32, f32),
    /// cos(½ · the smallest range end): a rotation by a smaller angle is inside every range, as
    /// neither its swing nor its twist can turn further than it does (most joints, most of the
    /// time, are near rest: this keeps the clamp cheap for them; `tick` of 100 characters × 20
    /// units spent 0.5 ms clamping 57 joints each without it).
    free_cos: f32,
}

/// The limits of every limited joint of a skeleton (in joint order; `None`: free).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Limits {
    joints: Vec<Option<Limit>>,
}

/// Why a limits file was refused.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("joint limits: {0}")]
pub struct LimitsError(pub String);

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct LimitsFile {
    #[serde(default, rename = "description")]
    _description: crate::data::Note,
    joints: BTreeMap<String, JointFile>,
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct JointFile {
    /// The bone axis, where it is not the direction to the first child (or, for a joint without
    /// one, its own offset's direction).
    #[serde(default)]
    axis: Option<[f32; 3]>,
    swing: BTreeMap<String, [f32; 2]>,
    twist: [f32; 2],
}

impl Limits {
    /// No limits: every joint is free.
    pub fn none(skeleton: &Skeleton) -> Limits {
        Limits {
            joints: vec![None; skeleton.len()],
        }
    }

    /// Reads limits for `skeleton` (see the module documentation and the embedded file).
    pub fn from_json(text: &str, skeleton: &Skeleton) -> Result<Limits, LimitsError> {
        let file: LimitsFile = crate::data::from_json(text).map_err(LimitsError)?;
        let mut limits = Limits::none(skeleton);
        for (name, joint) in &file.joints {
            let i = (skeleton.joint(name))
                .ok_or_else(|| LimitsError(format!("joint '{name}' is not in the skeleton")))?;
            limits.joints[i] = Some(limit(skeleton, i, name, joint, false)?);
            // the left twin, mirrored
            if let Some(twin) = name.strip_prefix("r_").map(|rest| format!("l_{rest}")) {
                if let Some(t) = skeleton.joint(&twin) {
                    if !file.joints.contains_key(&twin) {
                        limits.joints[t] = Some(limit(skeleton, t, &twin, joint, true)?);
                    }
                }
            }
        }
        Ok(limits)
    }

    /// The limits of joint `i`, if it has any.
    pub fn of(&self, i: usize) -> Option<&Limit> {
        self.joints.get(i)?.as_ref()
    }

    /// Clamps every joint of `pose` into its limits; returns the joints that had left them.
    pub fn clamp(&self, pose: &mut Pose) -> Vec<usize> {
        let mut clamped = Vec::new();
        for (i, (limit, q)) in self.joints.iter().zip(&mut pose.rotations).enumerate() {
            if let Some(inside) = limit.as_ref().and_then(|l| l.clamped(*q)) {
                *q = inside;
                clamped.push(i);
            }
        }
        clamped
    }
}

/// Joint `i`'s limits from the file's degrees; `mirrored` for a left joint taking its right
/// twin's entry (a reflection across the middle plane turns rotations about y and z, and the
/// twist about the reflected axis, the other way).
fn limit(
    skeleton: &Skeleton,
    i: usize,
    name: &str,
    joint: &JointFile,
    mirrored: bool,
) -> Result<Limit, LimitsError> {
    let err = |m: String| LimitsError(format!("joint '{name}': {m}"));
    let first_child = skeleton.joints().iter().find(|j| j.parent == Some(i));
    let bone = first_child.map_or(skeleton.joints()[i].offset, |c| c.offset);
    let axis = match joint.axis {
        Some([x, y, z]) if mirrored => Vec3::new(-x, y, z),
        Some(a) => Vec3::from_array(a),
        None => bone,
    };
    let axis = axis.normalize_or(Vec3::Z);
    let twist_axis = axis.abs().max_position();
    let range = |[lo, hi]: [f32; 2], flips: bool| -> Result<(f32, f32), LimitsError> {
        if !(lo <= 0.0 && 0.0 <= hi && lo.is_finite() && hi.is_finite()) {
            return Err(err(format!(
                "range [{lo}, {hi}] must contain 0 (the rest pose)"
            )));
        }
        let (lo, hi) = if flips { (-hi, -lo) } else { (lo, hi) };
        Ok((lo.to_radians(), hi.to_radians()))
    };
    let mut swing = Vec::new();
    for (axis_name, r) in &joint.swing {
        let k = ["x", "y", "z"]
            .iter()
            .position(|a| a == axis_name)
            .ok_or_else(|| err(format!("swing axis '{axis_name}' is not x, y or z")))?;
        if k == twist_axis {
            return Err(err(format!(
                "it twists about {axis_name}; its swing is about the other two axes"
            )));
        }
        let (lo, hi) = range(*r, mirrored && k != 0)?;
        swing.push((k, lo, hi));
    }
    let swing: [(usize, f32, f32); 2] = swing
        .try_into()
        .map_err(|_| err("swing needs the ranges of the two axes other than the bone's".into()))?;
    let twist = range(joint.twist, mirrored)?;
    let ends = swing.iter().flat_map(|&(_, lo, hi)| [-lo, hi]);
    let free = ends
        .chain([-twist.0, twist.1])
        .fold(f32::INFINITY, f32::min);
    Ok(Limit {
        axis,
        swing,
        twist,
        free_cos: (free / 2.0).cos(),
    })
}

impl Limit {
    /// `q` moved inside the limits, or `None` if it is inside already.
    pub fn clamped(&self, q: Quat) -> Option<Quat> {
        if q.w.abs() >= self.free_cos {
            return None;
        }
        let (swing, twist) = self.swing_twist(q);
        let comps = self.swing.map(|(k, lo, hi)| (k, swing[k], lo, hi));
        let twist_inside = (self.twist.0 - SLACK..=self.twist.1 + SLACK).contains(&twist);
        if ellipse(&comps) <= (1.0 + SLACK).powi(2) && twist_inside {
            return None;
        }
        // each component into its range, then both onto the ellipse
        let inside = comps.map(|(k, c, lo, hi)| (k, c.clamp(lo, hi), lo, hi));
        let scale = ellipse(&inside).sqrt().max(1.0);
        let mut v = Vec3::ZERO;
        for (k, c, _, _) in inside {
            v[k] = c / scale;
        }
        let twist = twist.clamp(self.twist.0, self.twist.1);
        Some(Quat::from_scaled_axis(v) * Quat::from_axis_angle(self.axis, twist))
    }

    /// `q` = swing · twist: the swing as a rotation vector (perpendicular to the axis) and the
    /// twist's angle about the axis, in (-π, π].
    fn swing_twist(&self, q: Quat) -> (Vec3, f32) {
        let q = if q.w < 0.0 { -q } else { q };
        let along = self.axis * Vec3::new(q.x, q.y, q.z).dot(self.axis);
        let twist = Quat::from_xyzw(along.x, along.y, along.z, q.w).normalize();
        let twist = if twist.is_finite() {
            twist
        } else {
            Quat::IDENTITY
        };
        let swing = q * twist.inverse();
        let angle = 2.0
            * Vec3::new(twist.x, twist.y, twist.z)
                .dot(self.axis)
                .atan2(twist.w);
        (swing.to_scaled_axis(), wrap(angle))
    }

    /// Whether `q` is inside the limits.
    pub fn admits(&self, q: Quat) -> bool {
        self.clamped(q).is_none()
    }
}

/// Σ (component / its side's semi-axis)²: at most 1 inside the ellipse; infinite for a
/// component on a side with no room.
fn ellipse(comps: &[(usize, f32, f32, f32); 2]) -> f32 {
    comps
        .iter()
        .map(|&(_, c, lo, hi)| {
            let semi = if c < 0.0 { -lo } else { hi };
            if semi > 0.0 {
                (c / semi).powi(2)
            } else if c.abs() > SLACK {
                f32::INFINITY
            } else {
                0.0
            }
        })
        .sum()
}

/// An angle in (-π, π].
pub fn wrap(a: f32) -> f32 {
    let tau = std::f32::consts::TAU;
    let a = a.rem_euclid(tau);
    if a > std::f32::consts::PI {
        a - tau
    } else {
        a
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn adult() -> (Skeleton, Limits) {
        let s = Skeleton::adult();
        let l = Limits::from_json(ADULT_LIMITS, &s).unwrap();
        (s, l)
    }

    #[test]
    fn an_elbow_bends_forward_up_to_150_degrees_and_not_backward() {
        let (s, l) = adult();
        let e = l.of(s.joint("r_elbow").unwrap()).unwrap();
        let bend = |deg: f32| Quat::from_rotation_x(-deg.to_radians());
        assert!(e.admits(bend(140.0)));
        let c = e.clamped(bend(170.0)).unwrap();
        assert!((c.angle_between(bend(150.0))).to_degrees() < 0.01, "{c}");
        // bending backward: 5° at most
        let c = e.clamped(bend(-40.0)).unwrap();
        assert!((c.angle_between(bend(-5.0))).to_degrees() < 0.01);
    }

    #[test]
    fn a_left_joint_takes_the_right_limits_mirrored() {
        let (s, l) = adult();
        let (r, left) = (
            l.of(s.joint("r_shoulder").unwrap()).unwrap(),
            l.of(s.joint("l_shoulder").unwrap()).unwrap(),
        );
        // raising each arm outward 170° is allowed, across the body 60° is not (50° is the limit)
        let out = |deg: f32, side: f32| Quat::from_rotation_z(side * deg.to_radians());
        assert!(r.admits(out(-170.0, 1.0)) && left.admits(out(170.0, 1.0)));
        assert!(!r.admits(out(60.0, 1.0)) && !left.admits(out(-60.0, 1.0)));
        // the twist: the right arm turns outward 90° (a negative twist about its axis, -y) ...
        let twist = |deg: f32| Quat::from_rotation_y(deg.to_radians());
        assert!(r.admits(twist(-90.0)) && !r.admits(twist(-100.0)));
        // ... and the left one outward with the opposite sign
        assert!(left.admits(twist(90.0)) && !left.admits(twist(100.0)));
    }

    #[test]
    fn a_diagonal_swing_is_limited_by_the_ellipse() {
        let (s, l) = adult();
        let wrist = l.of(s.joint("r_wrist").unwrap()).unwrap();
        // 60° flexion alone (limit 80) and 25° deviation alone (limit 30) are fine; both at once
        // lie outside the ellipse (0.75² + 0.83² > 1) and are scaled back onto it
        let flex = Vec3::Z * 60f32.to_radians();
        let dev = Vec3::X * 25f32.to_radians();
        assert!(wrist.admits(Quat::from_scaled_axis(flex)));
        assert!(wrist.admits(Quat::from_scaled_axis(dev)));
        let both = Quat::from_scaled_axis(flex + dev);
        let c = wrist.clamped(both).unwrap();
        let v = c.to_scaled_axis();
        let e = (v.z / 80f32.to_radians()).powi(2) + (v.x / 30f32.to_radians()).powi(2);
        assert!((e - 1.0).abs() < 1e-3, "{e}");
        assert!(wrist.admits(c));
    }

    #[test]
    fn the_clamp_counts_the_joints_it_moved_and_keeps_the_rest() {
        let (s, l) = adult();
        let mut pose = Pose::rest(&s);
        let knee = s.joint("l_knee").unwrap();
        pose.rotations[knee] = Quat::from_rotation_x(-1.0); // bent forward: impossible
        let before = pose.clone();
        assert_eq!(l.clamp(&mut pose), [knee]);
        for (i, (a, b)) in before.rotations.iter().zip(&pose.rotations).enumerate() {
            if i != knee {
                assert_eq!(a, b);
            }
        }
        assert!(
            l.clamp(&mut Pose::rest(&s)).is_empty(),
            "the rest pose is inside"
        );
    }

    #[test]
    fn bad_files_are_refused_with_the_joint_named() {
        let s = Skeleton::adult();
        let bad = |t: &str| Limits::from_json(t, &s).unwrap_err().0;
        assert!(bad(
            r#"{"joints": {"r_tail": {"swing": {"x": [-1, 1], "z": [-1, 1]}, "twist": [0, 0]}}}"#
        )
        .contains("'r_tail' is not in the skeleton"));
        assert!(bad(
            r#"{"joints": {"r_elbow": {"swing": {"x": [10, 20], "z": [-1, 1]}, "twist": [0, 0]}}}"#
        )
        .contains("must contain 0"));
        assert!(bad(
            r#"{"joints": {"r_elbow": {"swing": {"y": [-1, 1], "z": [-1, 1]}, "twist": [0, 0]}}}"#
        )
        .contains("twists about y"));
    }
}
