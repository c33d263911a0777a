//! The gait as a pose of the skeleton, in the character's own frame (its root on the ground at
//! the origin, facing +z): pelvis height, rotation, list and sway; the trunk's counter-rotation;
//! the arms' swing against the legs; each leg placed by two-link IK from its hip to its ankle,
//! the foot turned to its heading and pitch. The pelvis is lowered where a planted foot would
//! otherwise be out of the leg's reach, so that planted feet stay where they are.

use glam::{Quat, Vec2, Vec3};

use super::gait::{forward, Body, FootPose, Gait, ANKLE_HEIGHT, BALL_AHEAD, OWN_PACE};
use crate::character::body::ik::{place_limb, LimbRoot, LEG_HINGE};
use crate::character::body::{Pose, Skeleton};

/// The joints the gait moves (indices into a skeleton).
#[derive(Debug, Clone, PartialEq)]
pub struct GaitJoints {
    legs: [[usize; 3]; 2],
    spine: [Option<usize>; 2],
    shoulders: [Option<usize>; 2],
    elbows: [Option<usize>; 2],
    /// Neck and skull base (the head turns into a bend ahead).
    neck: [Option<usize>; 2],
    /// The thigh's and the shin's lengths, m.
    links: [f32; 2],
}

impl GaitJoints {
    /// The joints of `skeleton` (H-Anim names); `None` without hips, knees and ankles.
    pub fn of(skeleton: &Skeleton) -> Option<GaitJoints> {
        let j = |n: &str| skeleton.joint(n);
        let leg = |s: &str| -> Option<[usize; 3]> {
            Some([
                j(&format!("{s}_hip"))?,
                j(&format!("{s}_knee"))?,
                j(&format!("{s}_talocrural"))?,
            ])
        };
        let legs = [leg("l")?, leg("r")?];
        let joints = skeleton.joints();
        let links = [
            joints[legs[0][1]].offset.length(),
            joints[legs[0][2]].offset.length(),
        ];
        Some(GaitJoints {
            legs,
            spine: [j("vl5"), j("vt6")],
            shoulders: [j("l_shoulder"), j("r_shoulder")],
            elbows: [j("l_elbow"), j("r_elbow")],
            neck: [j("vc4"), j("skullbase")],
            links,
        })
    }

    /// The names of the joints the gait sets or turns.
    pub fn names(skeleton: &Skeleton) -> Vec<&str> {
        let mut v = vec!["HumanoidRoot"];
        for s in ["l", "r"] {
            for n in ["hip", "knee", "talocrural", "shoulder", "elbow"] {
                if let Some(j) = skeleton
                    .joints()
                    .iter()
                    .find(|j| j.name == format!("{s}_{n}"))
                {
                    v.push(&j.name);
                }
            }
        }
        v.extend(["vl5", "vt6", "vc4", "skullbase"]);
        v
    }
}

/// A foot pose turned into the frame of a body standing at `body`.
fn to_local(f: FootPose, body: Body) -> FootPose {
    let rot = Quat::from_rotation_y(-body.facing);
    let rel = f.ankle - Vec3::new(body.at.x, 0.0, body.at.y);
    FootPose {
        ankle: rot * rel,
        yaw: f.yaw - body.facing,
        ..f
    }
}

/// How far above its standing height the pelvis is held running (m), more than the legs
/// reach: the legs' least knee bends bring it down to where people's is in the stance.
const PELVIS_RAISE: f32 = 0.03;
/// Walking, the pelvis's wave about its standing height (m): its middle, and half its rise and
/// fall, at 1.3 m/s and faster (less slower); its top a little above where the legs cap it.
const WALK_DROP: f32 = -0.025;
/// See [`WALK_DROP`].
const WALK_BOB: f32 = 0.035;
/// The pelvis's forward tilt walking at 1.3 m/s and faster (rad; less slower): people's is
/// about 10° (Kadaba 1990), so that the thigh flexes against the pelvis by that much more than
/// against the vertical.
const PELVIS_TILT: f32 = 0.17;
/// Half the running pelvis's rise and fall beyond what the legs give (m).
const RUN_BOB: f32 = 0.03;

/// Poses the gait of a body standing at `body` on `pose` (the character's own frame): the
/// pelvis, trunk and arms on top of what is there, the legs set.
pub fn pose_gait(skeleton: &Skeleton, j: &GaitJoints, gait: &Gait, body: Body, pose: &mut Pose) {
    let amount = gait.amount;
    let tau = std::f32::consts::TAU;
    let beta = gait.stance();
    let (psi_l, psi_r) = (gait.foot_phase(0), gait.foot_phase(1));
    let mid_left = (tau * (psi_l - beta / 2.0)).cos();
    // pelvis: the swinging side's hip forward, the swing side lower, the weight over the
    // standing foot; highest at mid-stance when walking, lowest when running
    let run = gait.running;
    let yaw = -(if run { 0.1 } else { 0.07 }) * amount * (tau * psi_l).cos();
    let list = (if run { 0.03 } else { 0.06 }) * amount * mid_left;
    let sway = (if run { 0.01 } else { 0.02 }) * amount * mid_left;
    // the pelvis rises over each foot and falls between them, highest at mid-stance walking
    // and lowest there running; walking, the legs cap it at the top (as high as the knee's least
    // bend lets it), and its fall, begun on its own, leaves the reaching foot little to pull
    let wave = (2.0 * tau * (psi_l - beta / 2.0)).cos();
    let pace = (gait.speed / OWN_PACE).clamp(0.4, 1.0).powi(2);
    let bob = if run {
        PELVIS_RAISE - RUN_BOB * wave
    } else {
        (WALK_DROP + WALK_BOB * wave) * pace
    } * amount;
    let rest_y = skeleton.joints()[0].offset.y;
    pose.root.x = pose.root.x * (1.0 - amount) + sway;
    pose.root.z *= 1.0 - amount;
    pose.root.y = rest_y + bob;
    // (it tilts further the faster the walk)
    let tilt = Quat::from_rotation_x(PELVIS_TILT * amount * pace);
    pose.rotations[0] = Quat::from_rotation_y(yaw) * Quat::from_rotation_z(list) * tilt;
    // (the lower back takes the tilt back: the trunk stays upright)
    if let Some(i) = j.spine[0] {
        pose.rotate(i, tilt.inverse());
    }
    let feet = [0, 1].map(|k| to_local(gait.foot_pose(k, body, amount), body));
    lower_to_reach(skeleton, j, &feet, gait.knee, pose);
    for (k, foot) in feet.iter().enumerate() {
        place_leg(skeleton, j.legs[k], *foot, pose);
    }
    // the trunk turns back against the pelvis; the arms swing against the legs
    for (joint, share) in j.spine.iter().zip([-0.8, -0.6]) {
        if let Some(i) = *joint {
            pose.rotate(i, Quat::from_rotation_y(yaw * share));
        }
    }
    let arm = if run { 0.55 } else { 0.3 } * amount;
    let swing = [(tau * psi_r).cos(), (tau * psi_l).cos()];
    for ((shoulder, elbow), swing) in j.shoulders.iter().zip(&j.elbows).zip(swing) {
        if let Some(s) = *shoulder {
            pose.rotate(s, Quat::from_rotation_x(-(arm * swing + 0.05 * amount)));
        }
        if let Some(e) = *elbow {
            let bend = if run {
                1.4
            } else {
                0.25 + 0.15 * swing.max(0.0)
            } * amount;
            pose.rotate(e, Quat::from_axis_angle(Vec3::NEG_X, bend));
        }
    }
}

/// The head leads a turn: turned toward where the way goes `ahead` radians off the facing
/// (the route a little way ahead), by up to 35°, 40 % at the neck and 60 % at the skull base,
/// as much as the body walks (`amount`). Gaze behaviours turn the head on top of it.
pub fn lead_the_turn(j: &GaitJoints, ahead: f32, amount: f32, pose: &mut Pose) {
    let turn = ahead.clamp(-0.6, 0.6) * amount;
    for (joint, share) in j.neck.iter().zip([0.4, 0.6]) {
        if let Some(i) = *joint {
            pose.rotate(i, Quat::from_rotation_y(turn * share));
        }
    }
}

/// Deepest the pelvis sinks to keep a planted foot in reach (m): a knee bend. A foot further
/// away is lifted by the gait (`Gait::step`); the pelvis sank to 0.1 m above the floor for a
/// foot left behind by a body pushed in a jam.
pub const MAX_SINK: f32 = 0.15;

/// Lowers the root so that each foot is within the reach of its leg with the knee bent by at
/// least `knee` (rad; the gait's [`Gait::knee`]), by [`MAX_SINK`] at most; over both feet, so
/// that the height changes smoothly as they lift and land.
fn lower_to_reach(
    skeleton: &Skeleton,
    j: &GaitJoints,
    feet: &[FootPose; 2],
    knee: [f32; 2],
    pose: &mut Pose,
) {
    let [a, b] = j.links;
    let mut drop = 0.0f32;
    for (k, foot) in feet.iter().enumerate() {
        let reach = (a * a + b * b + 2.0 * a * b * knee[k].cos()).sqrt();
        let hip = pose.joint_world(skeleton, j.legs[k][0]).0;
        let d = hip - foot.ankle;
        let reach = soft_reach(d.length(), reach);
        let h = Vec2::new(d.x, d.z).length().min(reach);
        let vertical = (reach * reach - h * h).sqrt();
        drop = drop.max(d.y - vertical);
    }
    pose.root.y -= drop.min(MAX_SINK);
}

/// How far short of its reach (m) a leg starts to be held short, softly: see [`soft_reach`].
const SOFT: f32 = 0.015;

/// The distance (m) a leg reaching for a foot `distance` away is given, at most `reach`: the
/// distance itself up to [`SOFT`] short of the reach, then nearing the reach ever more slowly
/// (the pelvis lowered for the rest). A knee near straight turns far for a millimetre of
/// length; held to a hard reach, a foot coming within it let the knee snap from 22° to 4° in
/// one frame (19 rad/s), where a soft one straightens it over several.
fn soft_reach(distance: f32, reach: f32) -> f32 {
    let knee = reach - SOFT;
    if distance <= knee {
        return distance;
    }
    knee + SOFT * (1.0 - (-(distance - knee) / SOFT).exp())
}

/// The most the ankle is bent toes-up against the shin (rad; its limit is 20°).
const MAX_DORSIFLEXION: f32 = 0.28;
/// The most a rolling foot is bent toes-down against the shin (rad), 25°: people's push-off
/// (setting off with short steps, the heel's rise at its full height bent the ankle past its
/// limit, and the clamped foot slid 1 cm).
const MAX_PLANTARFLEXION: f32 = 0.44;

/// Puts a leg's ankle at `foot` (hip and knee by IK, knee toward the foot's heading) and turns
/// the foot to its heading and pitch. Where the shin leans so far over the foot that the ankle
/// would bend past [`MAX_DORSIFLEXION`], the heel rises instead: a planted foot rolls about the
/// ball of the foot (which stays on the ground), a swinging one about its ankle.
fn place_leg(skeleton: &Skeleton, leg: [usize; 3], foot: FootPose, pose: &mut Pose) {
    let mut foot = foot;
    for _ in 0..4 {
        let dorsiflexion = set_leg(skeleton, leg, foot, pose);
        // (a heel raised further than the ankle bends toes-down is let down as far)
        let excess = (dorsiflexion - MAX_DORSIFLEXION).max(0.0)
            + (dorsiflexion + MAX_PLANTARFLEXION).min(0.0);
        // (never below flat)
        let excess = if excess < 0.0 {
            excess.max(foot.pitch.min(0.0))
        } else {
            excess
        };
        if excess.abs() < 1e-3 {
            return;
        }
        let f = forward(foot.yaw);
        let axis = Vec3::new(f.y, 0.0, -f.x);
        let turn = Quat::from_axis_angle(axis, excess);
        if foot.planted {
            let orientation = Quat::from_rotation_y(foot.yaw) * Quat::from_rotation_x(-foot.pitch);
            let ball = foot.ankle + orientation * Vec3::new(0.0, -ANKLE_HEIGHT, BALL_AHEAD);
            foot.ankle = ball + turn * (foot.ankle - ball);
        }
        foot.pitch -= excess;
    }
}

/// Sets one leg to `foot`; returns how far the ankle is bent toes-up against the shin (rad).
fn set_leg(
    skeleton: &Skeleton,
    [hip, knee, ankle]: [usize; 3],
    foot: FootPose,
    pose: &mut Pose,
) -> f32 {
    let Some(frame) = LimbRoot::chain(skeleton, pose, hip) else {
        return 0.0;
    };
    let f = forward(foot.yaw);
    let pole = Vec3::new(f.x, 0.0, f.y);
    if let Some((h, k)) = place_limb(
        skeleton,
        frame,
        [hip, knee, ankle],
        foot.ankle,
        pole,
        LEG_HINGE,
    ) {
        pose.rotations[hip] = h;
        pose.rotations[knee] = k;
    }
    let shin = pose.joint_world(skeleton, knee).1;
    let wanted = Quat::from_rotation_y(foot.yaw) * Quat::from_rotation_x(-foot.pitch);
    let local = (shin.inverse() * wanted).normalize();
    pose.rotations[ankle] = local;
    // toes-up is a turn about −x
    -local.to_euler(glam::EulerRot::XYZ).0
}
