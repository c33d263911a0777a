//! The realizer's motion on an avatar's skeleton, rest-pose aware. Each avatar bone paired
//! with a realizer joint takes that joint's world rotation since rest. Before that the two rest
//! poses are aligned bone by bone: a limb bone of the avatar (upper and lower arm, hand, finger,
//! thigh, shin) is turned, the short way, so that it points where its realizer joint's bone
//! points at rest, whatever pose the avatar was made in (T, A) and whatever its bones' own axes;
//! the feet, like the trunk, are taken to rest alike (soles on the floor). The avatar's frame may differ from the realizer's (y up, facing +z, left +x):
//! it is found from the skeleton itself (left from the right upper arm to the left, up from
//! the hips to the head), so that a VRM 0.x facing −z or a file in centimetres under a turned
//! armature are driven alike. The root's travel is scaled by the ratio of leg lengths. Bones
//! with no realizer joint keep their rest rotation relative to their parent.

use std::collections::BTreeMap;

use glam::{Mat3, Mat4, Quat, Vec3};

use super::file::{AvatarError, Model};
use super::humanoid::{self, BONES};
use super::twist::{self, TwistBone};
use crate::character::body::pose::Pose;
use crate::character::body::skeleton::Skeleton;

/// The joint a realizer joint's bone points at, for aligning rest poses.
fn points_at(joint: &str) -> Option<String> {
    let (side, rest) = joint.split_at_checked(2)?;
    let next = match rest {
        "shoulder" => "elbow".to_string(),
        "elbow" => "wrist".to_string(),
        "wrist" => "middle1".to_string(),
        "hip" => "knee".to_string(),
        "knee" => "talocrural".to_string(),
        r => {
            let (finger, k) = r.split_at_checked(r.len().checked_sub(1)?)?;
            let k: u32 = k.parse().ok()?;
            if !["thumb", "index", "middle", "ring", "pinky"].contains(&finger) || k >= 3 {
                return None;
            }
            format!("{finger}{}", k + 1)
        }
    };
    matches!(side, "l_" | "r_").then(|| format!("{side}{next}"))
}

/// How one node turns each frame.
#[derive(Debug, Clone, Copy)]
pub(super) enum NodeMotion {
    /// It keeps its rest rotation relative to its parent.
    Rest,
    /// It follows a realizer joint: its local rotation is `before · Π steps · after`, where
    /// the steps (`Retarget::steps[from..to]`) are the realizer's local rotations (or their
    /// inverses) on the way from the joint its nearest following ancestor follows to its own.
    Follow {
        before: Quat,
        from: usize,
        to: usize,
        after: Quat,
    },
    /// An arm twist bone (see [`TwistBone`]).
    Twist(TwistBone),
}

/// How one avatar is driven by one realizer skeleton.
#[derive(Debug, Clone)]
pub struct Retarget {
    /// Per node, the realizer joint it follows.
    source: Vec<Option<usize>>,
    /// Per node, its parent node.
    parents: Vec<Option<usize>>,
    /// The nodes in parents-first order.
    order: Vec<usize>,
    /// Per node, its rest scale, rotation and translation relative to its parent.
    rest: Vec<(Vec3, Quat, Vec3)>,
    /// Per node, how it turns.
    drives: Vec<NodeMotion>,
    /// The realizer joints (and whether inverted) the followers' rotations are made of.
    steps: Vec<(usize, bool)>,
    /// The realizer's frame in the avatar's: realizer x (left), y (up), z (forward).
    frame: Quat,
    /// The node that carries the root's travel, its rest world place, and the travel's scale.
    hips: usize,
    hips_rest: Vec3,
    scale: f32,
    /// The rest world rotation, place and scale of the hips' parent (none: the identity).
    hips_parent: (Quat, Vec3, Vec3),
    /// The realizer's root at rest.
    root_rest: Vec3,
    /// The realizer's eyeball joints (left, right), if its skeleton has them.
    eyes: Option<(usize, usize)>,
    /// Where the character stands: the realizer's root at rest there. Its travel from here is
    /// scaled by leg length; the way from the origin to here is not.
    anchor: Vec3,
    /// Whether the avatar's skeleton is the realizer's (same hierarchy, same frame, every rest
    /// rotation and alignment the identity): then each node's local rotation is its joint's,
    /// with no arithmetic (the default avatar).
    direct: bool,
}

/// An avatar's skeleton posed: per node its local rotation, and the local translation of the
/// node that carries the root's travel.
#[derive(Debug, Clone, PartialEq)]
pub struct Posed {
    /// Every node's local rotation (rest for those that follow no joint).
    pub rotations: Vec<Quat>,
    /// The travelling node and its local translation.
    pub hips: (usize, Vec3),
}

impl Retarget {
    /// The driving of `model` by `skeleton`, its bones recognised by `map` or by
    /// [`humanoid::recognise`]; an avatar whose nodes carry the realizer's own joint names
    /// follows joint by joint.
    pub fn new(
        model: &Model,
        skeleton: &Skeleton,
        map: Option<&BTreeMap<String, String>>,
    ) -> Result<Retarget, AvatarError> {
        let pairs = pairs(model, skeleton, map)?;
        let n = model.nodes.len();
        let mut source = vec![None; n];
        for &(node, joint) in &pairs {
            source[node] = Some(joint);
        }
        let world: Vec<Mat4> = (0..n).map(|i| model.rest_world(i)).collect();
        let place = |i: usize| world[i].w_axis.truncate();
        let node_of = |joint: &str| {
            let j = skeleton.joint(joint)?;
            pairs.iter().find(|p| p.1 == j).map(|p| p.0)
        };
        let need = |joint: &str| {
            node_of(joint).ok_or_else(|| {
                AvatarError::new(
                    &model.file,
                    format!("no bone follows the realizer's {joint}"),
                )
            })
        };
        // the avatar's frame: left, up, forward
        let left = (place(need("l_shoulder")?) - place(need("r_shoulder")?)).normalize_or_zero();
        let up = place(need("skullbase")?) - place(need("sacroiliac")?);
        let up = (up - left * up.dot(left)).normalize_or_zero();
        if left == Vec3::ZERO || up == Vec3::ZERO {
            return Err(AvatarError::new(
                &model.file,
                "its shoulders or its hips and head are in one place: no frame",
            ));
        }
        let frame = snapped(Quat::from_mat3(&Mat3::from_cols(left, up, left.cross(up))));
        // the realizer's rest places
        let rest = Pose::rest(skeleton).world(skeleton);
        let order = parents_first(model);
        let mut align = vec![Quat::IDENTITY; n];
        for &i in &order {
            let inherited = ancestors(model, i)
                .find(|&a| source[a].is_some())
                .map_or(Quat::IDENTITY, |a| align[a]);
            align[i] = inherited;
            let Some(j) = source[i] else { continue };
            let name = &skeleton.joints()[j].name;
            let Some(next) = points_at(name) else {
                // trunk, head, clavicles and feet (soles flat on the floor in both): their
                // rests are taken to agree
                if !is_limb(name) || name.ends_with("talocrural") || name.ends_with("metatarsal") {
                    align[i] = Quat::IDENTITY;
                }
                continue;
            };
            let (Some(t), Some(m)) = (skeleton.joint(&next), node_of(&next)) else {
                continue;
            };
            let theirs = frame * (rest.positions[t] - rest.positions[j]);
            let ours = place(m) - place(i);
            if theirs.length() > 1e-6 && ours.length() > 1e-6 {
                align[i] = Quat::from_rotation_arc(ours.normalize(), theirs.normalize());
            }
        }
        let leg = |a: &str, b: &str, c: &str| -> Result<f32, AvatarError> {
            Ok(place(need(a)?).distance(place(need(b)?))
                + place(need(b)?).distance(place(need(c)?)))
        };
        let theirs = |a: &str, b: &str| {
            let (a, b) = (skeleton.joint(a), skeleton.joint(b));
            a.zip(b)
                .map_or(0.0, |(a, b)| rest.positions[a].distance(rest.positions[b]))
        };
        let ours = leg("l_hip", "l_knee", "l_talocrural")?;
        let realizer = theirs("l_hip", "l_knee") + theirs("l_knee", "l_talocrural");
        let hips = match node_of("HumanoidRoot") {
            Some(root) => root,
            None => need("sacroiliac")?,
        };
        let parents: Vec<Option<usize>> = model.nodes.iter().map(|n| n.parent).collect();
        let rest_rotation: Vec<Quat> = world.iter().map(rotation_of).collect();
        // (within a tenth of a degree: the default avatar's file keeps places in f32)
        let near = |q: Quat| q.normalize().angle_between(Quat::IDENTITY) < 1.7e-3;
        let node_of_joint = |j: usize| pairs.iter().find(|p| p.1 == j).map(|p| p.0);
        let direct = near(frame)
            && parents[hips].is_none()
            && pairs.iter().all(|&(i, j)| {
                let parent_joint = skeleton.joints()[j].parent;
                near(align[i])
                    && near(rest_rotation[i])
                    && parents[i] == parent_joint.and_then(node_of_joint)
            });
        // what a follower's joint's world rotation since rest (in the realizer's frame) is
        // applied to: its rest world rotation, aligned with the realizer's rest, taken into the
        // realizer's frame
        let pre: Vec<Quat> = (0..n)
            .map(|i| frame.inverse() * align[i] * rest_rotation[i])
            .collect();
        let rest_local: Vec<(Vec3, Quat, Vec3)> = (model.nodes.iter())
            .map(|n| (n.scale, n.rotation, n.translation))
            .collect();
        let mut plan = Plan {
            model,
            skeleton,
            source: &source,
            pre: &pre,
            rest: &rest_local,
            frame,
            steps: Vec::new(),
        };
        let mut drives: Vec<NodeMotion> = (0..n).map(|i| plan.follow(i)).collect();
        for (i, bone) in twist::bones(model, skeleton, &source, &pre, &rest.positions, &world) {
            drives[i] = NodeMotion::Twist(bone);
        }
        Ok(Retarget {
            steps: plan.steps,
            drives,
            source,
            parents,
            order,
            rest: rest_local,
            frame,
            hips,
            hips_rest: place(hips),
            scale: if realizer > 1e-6 {
                ours / realizer
            } else {
                1.0
            },
            root_rest: rest.positions[0],
            anchor: rest.positions[0],
            eyes: (skeleton.joint("l_eyeball_joint")).zip(skeleton.joint("r_eyeball_joint")),
            hips_parent: match model.nodes[hips].parent {
                Some(p) => {
                    let (scale, rotation, place) = world[p].to_scale_rotation_translation();
                    (rotation.normalize(), place, scale)
                }
                None => (Quat::IDENTITY, Vec3::ZERO, Vec3::ONE),
            },
            direct,
        })
    }

    /// The realizer's eyeball joints (left, right), if its skeleton has them.
    pub fn eyes(&self) -> Option<(usize, usize)> {
        self.eyes
    }

    /// The avatar posed as the realizer's `pose` (of the skeleton it was made for).
    pub fn pose(&self, pose: &Pose) -> Posed {
        let mut rotations: Vec<Quat> = self.rest.iter().map(|r| r.1).collect();
        let travel =
            self.frame * ((self.anchor - self.root_rest) + (pose.root - self.anchor) * self.scale);
        let turn = |j: usize| pose.rotations.get(j).copied().unwrap_or(Quat::IDENTITY);
        if self.direct {
            for (i, s) in self.source.iter().enumerate() {
                if let Some(j) = *s {
                    rotations[i] = turn(j);
                }
            }
            let hips = (self.hips, self.hips_rest + travel);
            return Posed { rotations, hips };
        }
        // each node on its own: its local rotation from the realizer's local rotations between
        // its joint and its nearest following ancestor's (no world rotations needed)
        for (rotation, drive) in rotations.iter_mut().zip(&self.drives) {
            match *drive {
                NodeMotion::Rest => {}
                NodeMotion::Follow {
                    before,
                    from,
                    to,
                    after,
                } => {
                    let mut q = before;
                    for &(j, inverse) in &self.steps[from..to] {
                        q *= if inverse {
                            turn(j).conjugate()
                        } else {
                            turn(j)
                        };
                    }
                    *rotation = (q * after).normalize();
                }
                NodeMotion::Twist(TwistBone {
                    joint,
                    about,
                    axis,
                    share,
                }) => {
                    let angle = twist::angle(turn(joint), about);
                    *rotation = Quat::from_axis_angle(axis, share * angle) * *rotation;
                }
            }
        }
        // the hips' ancestors follow no joint: they stay at rest
        let (pr, pp, ps) = self.hips_parent;
        let hips = (
            self.hips,
            pr.inverse() * (self.hips_rest + travel - pp) / ps,
        );
        Posed { rotations, hips }
    }

    /// Every node's world transform in `posed`.
    pub fn world(&self, posed: &Posed) -> Vec<Mat4> {
        let mut world = vec![Mat4::IDENTITY; self.rest.len()];
        for &i in &self.order {
            let parent = self.parents[i].map_or(Mat4::IDENTITY, |p| world[p]);
            let (scale, _, mut translation) = self.rest[i];
            if i == posed.hips.0 {
                translation = posed.hips.1;
            }
            let local =
                Mat4::from_scale_rotation_translation(scale, posed.rotations[i], translation);
            world[i] = parent * local;
        }
        world
    }

    /// Places the avatar where the character stood when its motion began: its travel from
    /// there is scaled by the ratio of leg lengths, its place is not.
    pub fn place_at(&mut self, at: crate::character::body::Placement) {
        self.anchor = at.to_world(self.root_rest);
    }

    /// Whether the avatar's skeleton is the realizer's own (each node turns as its joint).
    pub fn is_direct(&self) -> bool {
        self.direct
    }

    /// The node that carries the root's travel (the hips, or `HumanoidRoot`).
    pub fn hips(&self) -> usize {
        self.hips
    }

    /// The realizer joint node `i` follows.
    pub fn source(&self, i: usize) -> Option<usize> {
        self.source.get(i).copied().flatten()
    }

    /// Whether node `i` turns with the realizer's motion (follows a joint or is a twist bone).
    pub fn moves(&self, i: usize) -> bool {
        !matches!(self.drives.get(i), None | Some(NodeMotion::Rest))
    }

    /// The realizer's frame in the avatar's (its x, y, z: left, up, forward).
    pub fn frame(&self) -> Quat {
        self.frame
    }

    /// How the avatar's whole scene turns to stand in the realizer's world: the inverse of
    /// [`Retarget::frame`]. The poses, travel and [`Retarget::world`] are in the avatar's own
    /// frame; a host showing the avatar beside the world's objects turns it by this (the
    /// glTF export does it with a node over the avatar's roots).
    pub fn stand(&self) -> Quat {
        self.frame.inverse()
    }
}

/// What making the followers' drives needs.
struct Plan<'a> {
    model: &'a Model,
    skeleton: &'a Skeleton,
    source: &'a [Option<usize>],
    pre: &'a [Quat],
    rest: &'a [(Vec3, Quat, Vec3)],
    frame: Quat,
    steps: Vec<(usize, bool)>,
}

impl Plan<'_> {
    /// How node `i` turns: if it follows a joint, its world rotation in the realizer's frame is
    /// its joint's world rotation times its `pre`, and its local rotation is that seen from
    /// its parent, whose world rotation is its nearest following ancestor's times the rest
    /// rotations between them. Joint world rotations cancel down to the realizer's local
    /// rotations on the way between the two joints.
    fn follow(&mut self, i: usize) -> NodeMotion {
        let Some(j) = self.source[i] else {
            return NodeMotion::Rest;
        };
        let mut between = Quat::IDENTITY;
        let mut anchor = None;
        for a in ancestors(self.model, i) {
            if let Some(ja) = self.source[a] {
                anchor = Some((a, ja));
                break;
            }
            between = self.rest[a].1 * between;
        }
        let from = self.steps.len();
        let before = match anchor {
            Some((a, ja)) => {
                let up = self.chain(ja);
                let down = self.chain(j);
                let common = up.iter().filter(|k| down.contains(k)).count();
                let (up, down) = (&up[..up.len() - common], &down[..down.len() - common]);
                self.steps.extend(up.iter().map(|&k| (k, true)));
                self.steps.extend(down.iter().rev().map(|&k| (k, false)));
                (self.pre[a] * between).inverse()
            }
            None => {
                let down = self.chain(j);
                self.steps.extend(down.iter().rev().map(|&k| (k, false)));
                between.inverse() * self.frame
            }
        };
        NodeMotion::Follow {
            before,
            from,
            to: self.steps.len(),
            after: self.pre[i],
        }
    }

    /// Joint `j` and its ancestors, nearest first.
    fn chain(&self, j: usize) -> Vec<usize> {
        let joints = self.skeleton.joints();
        std::iter::successors(Some(j), |&k| joints[k].parent)
            .take(joints.len())
            .collect()
    }
}

/// Within this of glTF's +y up an avatar's frame is taken to be upright (rad); within this
/// of facing along an axis, to face along it: a body's own asymmetries (a head a little
/// forward of the hips) do not tilt the realizer's motion.
const SNAP: f32 = 0.17;

/// `frame` made upright and facing along an axis when it is within [`SNAP`] of that.
fn snapped(frame: Quat) -> Quat {
    let up = frame * Vec3::Y;
    if up.angle_between(Vec3::Y) > SNAP {
        return frame;
    }
    let forward = frame * Vec3::Z;
    let heading = forward.x.atan2(forward.z);
    let quarter = std::f32::consts::FRAC_PI_2;
    let axis = (heading / quarter).round() * quarter;
    let heading = if (heading - axis).abs() < SNAP {
        axis
    } else {
        heading
    };
    Quat::from_rotation_y(heading)
}

/// Whether a realizer joint is part of a limb (its alignment is inherited down the limb).
fn is_limb(joint: &str) -> bool {
    joint.starts_with("l_") || joint.starts_with("r_")
}

/// The rotation of a transform with uniform scale.
fn rotation_of(m: &Mat4) -> Quat {
    m.to_scale_rotation_translation().1.normalize()
}

/// Node `i`'s ancestors, nearest first.
fn ancestors(model: &Model, i: usize) -> impl Iterator<Item = usize> + '_ {
    let mut at = model.nodes[i].parent;
    let mut left = model.nodes.len();
    std::iter::from_fn(move || {
        let p = at.filter(|_| left > 0)?;
        left -= 1;
        at = model.nodes[p].parent;
        Some(p)
    })
}

/// Every node, parents before children.
fn parents_first(model: &Model) -> Vec<usize> {
    let mut depth: Vec<(usize, usize)> = (0..model.nodes.len())
        .map(|i| (ancestors(model, i).count(), i))
        .collect();
    depth.sort_unstable();
    depth.into_iter().map(|(_, i)| i).collect()
}

/// The (avatar node, realizer joint) pairs: node by node when the avatar's joints carry the
/// realizer's names, else bone by bone.
fn pairs(
    model: &Model,
    skeleton: &Skeleton,
    map: Option<&BTreeMap<String, String>>,
) -> Result<Vec<(usize, usize)>, AvatarError> {
    if map.is_none() {
        let named: Vec<(usize, usize)> = model
            .joints
            .iter()
            .filter_map(|&n| Some((n, skeleton.joint(&model.nodes[n].name)?)))
            .collect();
        if named.len() * 2 > skeleton.len() {
            return Ok(named);
        }
    }
    let bones = humanoid::recognise(model, map)?;
    let spine: Vec<&str> = ["spine", "chest", "upperChest"]
        .into_iter()
        .filter(|b| bones.contains_key(b))
        .collect();
    let spine_sources = humanoid::spine_sources(spine.len());
    let mut out = Vec::new();
    for (bone, _) in BONES {
        let Some(&node) = bones.get(bone) else {
            continue;
        };
        let joint = match spine.iter().position(|b| b == bone) {
            Some(k) => Some(spine_sources[k].to_string()),
            None => humanoid::source(bone),
        };
        if let Some(j) = joint.and_then(|j| skeleton.joint(&j)) {
            out.push((node, j));
        }
    }
    Ok(out)
}
