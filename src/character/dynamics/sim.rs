//! One character's simulated body on rapier3d, stepped with mixed dynamics. The humanoid's parts
//! in the physical set are dynamic rigid bodies joined by impulse joints (balls; hinges at knees
//! and elbows, with their anatomical ranges) standing on a ground box; the others follow the
//! kinematic pose. Each step: the controllers' joint torques are summed and applied (each joint
//! torque turns the child part one way and its parent the other); every kinematic chain reaches
//! the part it hangs from, scaled by k (by default as its rigid inertia added to that part plus
//! the impulse of its relative motion's momentum change, `dynamics::coupling`; or, as the
//! thesis does, as its inverse dynamics' wrench on the connector's acceleration of the step
//! before); rapier integrates. The kinematic parts are then placed on their connectors as they
//! are after the step, and the simulated parts' rotations go back into the pose the host sees.
//!
//! Longer than 600 lines on purpose: the simulation is one state (rapier's sets, the parts,
//! their joints and motors, the glued feet, the kinematic chains' carried motion) that every
//! stage of a step reads and writes; the pieces that stand alone are modules of their own
//! (`coupling`, `controllers`, `zmp`, `humanoid`).

use std::f32::consts::PI;

use glam::{DMat3, DQuat, DVec2, DVec3, Quat, Vec3};
use rapier3d::prelude as rp;

use super::controllers::{outside, support_polygon, Drive, Pull};
use super::coupling::{relative_momentum, Carrier, Composite};
use super::humanoid::Humanoid;
use super::kinematics::derivatives;
use super::rnea::{inverse_dynamics, reaction, with_gravity, BaseMotion, JointMotion, Link};
use super::zmp::{zero_moment_point, Segment};
use super::{drot, dv, rot, v};
use crate::character::body::{Pose, Skeleton};

/// The default physics step (s): 200 Hz, as the thesis ran it.
pub const STEP: f64 = 1.0 / 200.0;

/// Solver iterations per step. Measured on the standing body with its feet held: 4 (rapier's
/// default) let it lean 1.6 cm/s under stiff motors; 8 pass every balance test; 10 keep a
/// margin at 37 µs per character step (16: 61 µs).
pub const SOLVER_ITERATIONS: usize = 10;

/// The time constant (s) of the low-pass on the parts' measured accelerations (see
/// `Simulation::measure`).
pub const ACCELERATION_SMOOTHING: f64 = 0.02;

/// The share of a ball joint's swing ranges its rapier limits allow (see
/// `Simulation::ball_ranges`): the box of 0.8 × the ranges has its corners 13 % outside the
/// ellipse, where the full ranges' are 41 % outside.
const BALL_SWING_SHARE: f32 = 0.8;

/// The angular axes of a joint.
const ANGULAR: [rp::JointAxis; 3] = [
    rp::JointAxis::AngX,
    rp::JointAxis::AngY,
    rp::JointAxis::AngZ,
];

/// Friction between the feet and the ground.
const GROUND_FRICTION: f32 = 1.0;

/// Which of rapier's joints hold the simulated parts together (docs/physics.md measures both
/// on the standing body).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Joints {
    /// Impulse joints: constraints between bodies, solved iteratively; the held feet are
    /// fixed bodies.
    #[default]
    Impulse,
    /// One multibody (reduced coordinates) from the sacroiliac down; the held feet are fixed
    /// to the ground by impulse joints (a multibody cannot hold a fixed link). Kept for the
    /// measurement in docs/physics.md: with the balance controller the body is thrown over
    /// within 25 ms (the glue's constraints against the reduced coordinates), so the realizer
    /// does not use it.
    Multibody,
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum JointHandle {
    Impulse(rp::ImpulseJointHandle),
    Multibody(rp::MultibodyJointHandle),
}

/// How a kinematic chain's inverse dynamics reaches its connector.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Coupling {
    /// As the thesis does it: the chain's inverse dynamics on the connector's velocity, its
    /// acceleration over the step before and gravity, applied as a wrench. One step late, so
    /// it is stable only while the chain's inertia is small against what the connector moves
    /// with; on the humanoid (arms and head on a ball-jointed trunk) it is not: the loop gain
    /// exceeds one and the body flies apart within 0.1 s (docs/physics.md).
    Lagged,
    /// The chain's inertia, as a rigid body in its current configuration, added to the
    /// connector's mass properties (so rapier moves it with the connector, gravity included,
    /// within the step), and what the chain's motion relative to the connector adds given to
    /// the connector as momentum: over each step, the opposite of the change of that motion's
    /// momentum and of rapier's own when the composite changes (`dynamics::coupling::Carrier`).
    /// The impulses add up to the chain's inverse dynamics integrated over the steps, so the
    /// whole keeps its momentum; both parts are scaled by k.
    #[default]
    Implicit,
}

/// The state of one part after a step, in the world (joint origin, orientation, velocities).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct PartState {
    /// Where its joint is (m).
    pub position: DVec3,
    /// Its orientation.
    pub orientation: DQuat,
    /// The velocity of its joint's origin (m/s).
    pub velocity: DVec3,
    /// Its angular velocity (rad/s, world frame).
    pub angular: DVec3,
    /// Its centre of mass (m).
    pub com: DVec3,
    /// Its mass (kg).
    pub mass: f64,
}

/// A simulated character (see the module documentation).
pub struct Simulation {
    world: rp::PhysicsWorld,
    humanoid: Humanoid,
    skeleton: Skeleton,
    handles: Vec<rp::RigidBodyHandle>,
    /// Per part: simulated (`true`) or following the kinematic pose.
    physical: Vec<bool>,
    /// Per part, its state after the last step.
    state: Vec<PartState>,
    /// Per part, its accelerations over the last step (linear of the joint origin, angular).
    accel: Vec<(DVec3, DVec3)>,
    /// The parts' frames (joint position, orientation) in the kinematic pose one step ago and
    /// now (inputs of the chains' differences).
    history: [Vec<(Vec3, Quat)>; 2],
    /// Per part, the joint to its parent part (simulated parts only).
    joints: Vec<Option<JointHandle>>,
    /// Which kind of joint.
    kind: Joints,
    /// The ground as a body (for the multibody's glue joints).
    floor: rp::RigidBodyHandle,
    /// The multibody's glue joints.
    glue_joints: Vec<rp::ImpulseJointHandle>,
    /// Per part, its joint's anchor on the parent (parent's frame).
    anchors: Vec<rp::Vector>,
    /// Per ball-jointed part, its joint's ranges about x, y and z (see [`Self::ball_ranges`]).
    ball_ranges: Vec<Option<[[f32; 2]; 3]>>,
    /// The feet held where they stand (empty when let go).
    glue: Vec<usize>,
    /// The reaction gain k (1: exact).
    pub reaction_gain: f64,
    /// How the chains' inverse dynamics reaches their connectors.
    pub coupling: Coupling,
    /// Seconds simulated.
    pub time: f64,
    /// Per part, the wrench its chain put on it at the last step (force, moment; world).
    pub last_reaction: Vec<(DVec3, DVec3)>,
    /// Per kinematic part, the torque its joint needed at the last step (world frame).
    torques: Vec<DVec3>,
    /// Per part, what it carries as a connector of kinematic chains.
    carriers: Vec<Carrier>,
    /// Steps taken, and those after which the zero-moment point lay outside the support
    /// polygon while the feet stood on the ground.
    zmp_count: (usize, usize),
}

impl Simulation {
    /// A character on `skeleton` standing in `pose`, its parts listed in `physical` simulated
    /// (the others follow the kinematic pose), stepping every `step` seconds.
    pub fn new(
        skeleton: &Skeleton,
        pose: &Pose,
        physical: &[usize],
        step: f64,
    ) -> Result<Simulation, String> {
        Self::with_joints(skeleton, pose, physical, step, Joints::default())
    }

    /// [`new`](Self::new) with the parts held together by `kind` joints.
    pub fn with_joints(
        skeleton: &Skeleton,
        pose: &Pose,
        physical: &[usize],
        step: f64,
        kind: Joints,
    ) -> Result<Simulation, String> {
        if !(step > 0.0 && step <= 0.05) {
            return Err(format!("a physics step of {step} s: between 0 and 0.05"));
        }
        let humanoid = Humanoid::new(skeleton)?;
        let mut world = rp::PhysicsWorld::new();
        world.integration_parameters.dt = step as f32;
        // rapier's default of 4 solver iterations leaves the joints of a standing body soft: it
        // leaned 1.6 cm in a second under stiff joint motors (docs/physics.md)
        world.integration_parameters.num_solver_iterations = SOLVER_ITERATIONS;
        let ground = rp::ColliderBuilder::cuboid(50.0, 0.1, 50.0)
            .translation(rp::Vector::new(0.0, -0.1, 0.0))
            .friction(GROUND_FRICTION)
            .collision_groups(rp::InteractionGroups::new(
                rp::Group::GROUP_2,
                rp::Group::GROUP_1,
                rp::InteractionTestMode::And,
            ));
        let floor = world.bodies.insert(rp::RigidBodyBuilder::fixed());
        world
            .colliders
            .insert_with_parent(ground, floor, &mut world.bodies);
        let n = humanoid.parts.len();
        let mut sim = Simulation {
            world,
            skeleton: skeleton.clone(),
            handles: Vec::with_capacity(n),
            physical: (0..n).map(|i| physical.contains(&i)).collect(),
            state: vec![PartState::default(); n],
            accel: vec![(DVec3::ZERO, DVec3::ZERO); n],
            history: [Vec::new(), Vec::new()],
            joints: vec![None; n],
            kind,
            floor,
            glue_joints: Vec::new(),
            anchors: vec![rp::Vector::ZERO; n],
            ball_ranges: vec![None; n],
            glue: Vec::new(),
            reaction_gain: 1.0,
            coupling: Coupling::default(),
            time: 0.0,
            last_reaction: vec![(DVec3::ZERO, DVec3::ZERO); n],
            torques: vec![DVec3::ZERO; n],
            carriers: vec![Carrier::default(); n],
            zmp_count: (0, 0),
            humanoid,
        };
        let frames = sim.humanoid.frames(skeleton, pose);
        sim.history = [frames.clone(), frames];
        sim.build(pose);
        sim.measure(0.0);
        sim.glue_feet();
        Ok(sim)
    }

    /// The humanoid's parts and their skeleton joints.
    pub fn humanoid(&self) -> &Humanoid {
        &self.humanoid
    }

    /// Sets gravity (m/s², world; −9.81 in y by default), e.g. zero for tests of the joints
    /// alone.
    pub fn set_gravity(&mut self, g: DVec3) {
        self.world.gravity = v(g);
    }

    /// The physics step (s).
    pub fn step_size(&self) -> f64 {
        f64::from(self.world.integration_parameters.dt)
    }

    /// Per part, the torque (N m, world frame) its joint needed at the last step to move as
    /// the kinematic pose moved it — the inverse dynamics of the kinematic chains, on the
    /// connector's motion over the step before, gravity included; zero for simulated parts.
    /// What a planner reads to judge effort or strength.
    pub fn kinematic_torques(&self) -> &[DVec3] {
        &self.torques
    }

    /// Whether part `i` is simulated.
    pub fn is_physical(&self, i: usize) -> bool {
        self.physical[i]
    }

    /// Every part's state after the last step.
    pub fn parts(&self) -> &[PartState] {
        &self.state
    }

    /// Inserts one body per part at its place in `pose`, and a joint from each simulated part
    /// to its simulated parent.
    fn build(&mut self, pose: &Pose) {
        let frames = self.humanoid.frames(&self.skeleton, pose);
        for (i, p) in self.humanoid.parts.iter().enumerate() {
            let (at, q) = frames[i];
            let builder = if self.physical[i] {
                rp::RigidBodyBuilder::dynamic()
            } else {
                rp::RigidBodyBuilder::kinematic_position_based()
            };
            let body = builder
                .pose(rp::Pose::from_parts(v(at.as_dvec3()), rot(q.as_dquat())))
                .can_sleep(false)
                .linear_damping(0.0)
                .angular_damping(0.0);
            let h = self.world.bodies.insert(body);
            let half = DVec3::from_array(p.size) / 2.0;
            // only simulated parts touch the ground; parts never collide with each other
            let groups = if self.physical[i] {
                rp::InteractionGroups::new(
                    rp::Group::GROUP_1,
                    rp::Group::GROUP_2,
                    rp::InteractionTestMode::And,
                )
            } else {
                rp::InteractionGroups::none()
            };
            let collider = rp::ColliderBuilder::cuboid(half.x as f32, half.y as f32, half.z as f32)
                .translation(v(DVec3::from_array(p.centre)))
                .density((p.density * 1000.0) as f32)
                .friction(GROUND_FRICTION)
                .collision_groups(groups);
            self.world
                .colliders
                .insert_with_parent(collider, h, &mut self.world.bodies);
            self.handles.push(h);
        }
        for i in 0..self.humanoid.parts.len() {
            let Some(parent) = self.humanoid.parts[i].parent else {
                continue;
            };
            if self.physical[i] && self.physical[parent] {
                self.join(parent, i, &frames);
            }
        }
    }

    /// The range (radians) of the bend about x of part `i`'s skeleton joint, from the
    /// skeleton's joint limits (`None`: the joint is not limited about x).
    fn bend_range(&self, i: usize) -> Option<[f32; 2]> {
        let limit = self.skeleton.limits().of(self.humanoid.joints[i])?;
        let &(_, lo, hi) = limit.swing.iter().find(|s| s.0 == 0)?;
        Some([lo, hi])
    }

    /// The ranges (radians) about x, y and z of ball-jointed part `i`'s skeleton joint: its
    /// two swing components' ranges and its twist's about the bone axis (taken as the nearest
    /// of ±x, ±y, ±z). rapier limits each axis' angle on its own: a box, whose corners lie
    /// outside the limits' swing ellipse (a foot turned to both its swing ends at once was
    /// 0.38 rad past it). The swing ranges are therefore [`BALL_SWING_SHARE`] of the limits',
    /// which puts the corners near the ellipse; `None`: the joint is not limited.
    fn ball_ranges(&self, i: usize) -> Option<[[f32; 2]; 3]> {
        let limit = self.skeleton.limits().of(self.humanoid.joints[i])?;
        let mut ranges = [[-PI, PI]; 3];
        for &(k, lo, hi) in &limit.swing {
            ranges[k] = [lo * BALL_SWING_SHARE, hi * BALL_SWING_SHARE];
        }
        let a = limit.axis;
        let k = (0..3).max_by(|&p, &q| a[p].abs().total_cmp(&a[q].abs()))?;
        let (lo, hi) = limit.twist;
        ranges[k] = if a[k] > 0.0 { [lo, hi] } else { [-hi, -lo] };
        Some(ranges)
    }

    /// A joint from `parent` to `child` at the child's joint: a ball, or a hinge about the
    /// child's x axis within the skeleton's range for it (the adult's knee −5°..135°, elbow
    /// −150°..5°). Angles
    /// count from the rest pose, where every part's frame is the world's; a hinge that starts
    /// bent about another axis is pulled onto its own.
    fn join(&mut self, parent: usize, child: usize, frames: &[(Vec3, Quat)]) {
        let (pp, pq) = (frames[parent].0.as_dvec3(), frames[parent].1.as_dquat());
        let cp = frames[child].0.as_dvec3();
        let anchor = pq.inverse() * (cp - pp);
        let frame1 = rp::Pose::from_parts(v(anchor), rp::Rotation::IDENTITY);
        let frame2 = rp::Pose::from_parts(rp::Vector::ZERO, rp::Rotation::IDENTITY);
        let p = &self.humanoid.parts[child];
        let mut joint = if p.hinge {
            let hinge = rp::GenericJointBuilder::new(rp::JointAxesMask::LOCKED_REVOLUTE_AXES);
            match self.bend_range(child) {
                Some(range) => hinge.limits(rp::JointAxis::AngX, range),
                None => hinge,
            }
        } else {
            // its limits are set with its motors before every step (`set_motors`)
            self.ball_ranges[child] = self.ball_ranges(child);
            rp::GenericJointBuilder::new(rp::JointAxesMask::LOCKED_SPHERICAL_AXES)
        };
        joint = joint
            .local_frame1(frame1)
            .local_frame2(frame2)
            .contacts_enabled(false);
        for axis in ANGULAR {
            joint = joint.motor_model(axis, rp::MotorModel::ForceBased);
        }
        let (a, b) = (self.handles[parent], self.handles[child]);
        let handle = match self.kind {
            Joints::Impulse => Some(JointHandle::Impulse(self.world.impulse_joints.insert(
                a,
                b,
                joint.build(),
                true,
            ))),
            Joints::Multibody => self
                .world
                .multibody_joints
                .insert(a, b, joint.build(), true)
                .map(JointHandle::Multibody),
        };
        self.joints[child] = handle;
        self.anchors[child] = v(anchor);
    }

    /// Reads every part's state from rapier; with `dt` > 0 also its accelerations since the
    /// last reading.
    fn measure(&mut self, dt: f64) {
        for (i, p) in self.humanoid.parts.iter().enumerate() {
            let (position, orientation, velocity, angular) = match self.connector_of(i) {
                Some(c) if c != i => self.carried_state(i, c, dt),
                _ => {
                    let b = &self.world.bodies[self.handles[i]];
                    let angular = dv(b.angvel());
                    // rapier's centre of mass counts the chains a connector carries
                    let at = dv(b.translation());
                    let velocity = dv(b.linvel()) + angular.cross(at - dv(b.center_of_mass()));
                    (at, drot(b.rotation()), velocity, angular)
                }
            };
            let m = p.mass();
            let (com, mass) = (position + orientation * m.com, m.mass);
            if dt > 0.0 {
                // a step's difference of rapier's velocities jitters (the solver's iterations
                // leave m/s² of noise: a held arm's shoulder torque swung by 6 N m from one step
                // to the next); a first-order low-pass over ACCELERATION_SMOOTHING seconds keeps
                // the connector's acceleration what the body does
                let before = self.state[i];
                let raw = (
                    (velocity - before.velocity) / dt,
                    (angular - before.angular) / dt,
                );
                let a = dt / (ACCELERATION_SMOOTHING + dt);
                let (l, w) = self.accel[i];
                self.accel[i] = (l + (raw.0 - l) * a, w + (raw.1 - w) * a);
            }
            self.state[i] = PartState {
                position,
                orientation,
                velocity,
                angular,
                com,
                mass,
            };
        }
    }

    /// Where kinematic part `i` is after a step and how it moves: placed by the kinematic pose on
    /// its simulated connector `c` (already measured) as the connector is now, moving with it
    /// plus the pose's own motion over the step (the last two kinematic poses, `dt` apart).
    fn carried_state(&self, i: usize, c: usize, dt: f64) -> (DVec3, DQuat, DVec3, DVec3) {
        let on = |f: &[(Vec3, Quat)]| {
            let back = f[c].1.as_dquat().inverse();
            (
                back * (f[i].0 - f[c].0).as_dvec3(),
                (back * f[i].1.as_dquat()).normalize(),
            )
        };
        let (before, now) = (on(&self.history[0]), on(&self.history[1]));
        let s = self.state[c];
        let (position, orientation) = (s.position + s.orientation * now.0, s.orientation * now.1);
        let (mut velocity, mut angular) = (
            s.velocity + s.angular.cross(position - s.position),
            s.angular,
        );
        if dt > 0.0 {
            let turn = now.1 * before.1.inverse();
            let turn = if turn.w < 0.0 { -turn } else { turn };
            let (axis, angle) = turn.to_axis_angle();
            velocity += s.orientation * (now.0 - before.0) / dt;
            angular += s.orientation * axis * (angle / dt);
        }
        (position, orientation, velocity, angular)
    }

    /// The world centre of mass of the whole body and its velocity.
    pub fn centre_of_mass(&self) -> (DVec3, DVec3) {
        let mass: f64 = self.state.iter().map(|s| s.mass).sum();
        let c = self.state.iter().map(|s| s.mass * s.com).sum::<DVec3>() / mass;
        let vel = (self.state.iter())
            .map(|s| s.mass * (s.velocity + s.angular.cross(s.com - s.position)))
            .sum::<DVec3>()
            / mass;
        (c, vel)
    }

    /// The corners of the feet's soles that touch the ground (y below 2 cm), in the world.
    pub fn contacts(&self) -> Vec<DVec3> {
        let mut out = Vec::new();
        for (i, p) in self.humanoid.parts.iter().enumerate() {
            let Some(sole) = p.sole().filter(|_| self.physical[i]) else {
                continue;
            };
            let s = self.state[i];
            let corners = sole.map(|c| s.position + s.orientation * c);
            out.extend(corners.into_iter().filter(|c| c.y < 0.02));
        }
        out
    }

    /// Holds every simulated foot whose sole touches the ground where it stands, as the
    /// thesis' foot glue does (§3.6): a standing character's feet do not slide or lift while
    /// the balance controller keeps the centre of mass over them, which is what the
    /// controller's limit on the ankle torques (the centre of pressure inside the sole) stands
    /// for. A held foot is a fixed body for rapier (it moves not at all, and costs no joint
    /// rows: a fixed joint to the ground made the step 20 % slower).
    /// [`let_go`](Self::let_go) ends it (a fall).
    pub fn glue_feet(&mut self) {
        if !self.glue.is_empty() {
            return;
        }
        for (i, p) in self.humanoid.parts.iter().enumerate() {
            if !(p.is_foot() && self.physical[i]) || self.sole_centre(i).y > 0.01 {
                continue;
            }
            if self.kind == Joints::Multibody {
                let st = self.state[i];
                let joint = rp::FixedJointBuilder::new()
                    .local_frame1(rp::Pose::from_parts(v(st.position), rot(st.orientation)))
                    .local_frame2(rp::Pose::from_parts(
                        rp::Vector::ZERO,
                        rp::Rotation::IDENTITY,
                    ))
                    .contacts_enabled(false);
                let h =
                    (self.world.impulse_joints).insert(self.floor, self.handles[i], joint, true);
                self.glue_joints.push(h);
            } else {
                let body = &mut self.world.bodies[self.handles[i]];
                body.set_body_type(rp::RigidBodyType::Fixed, true);
            }
            self.glue.push(i);
        }
    }

    /// Lets go of the feet (see [`glue_feet`](Self::glue_feet)).
    pub fn let_go(&mut self) {
        for h in self.glue_joints.drain(..) {
            self.world.impulse_joints.remove(h, true);
        }
        for i in self.glue.drain(..) {
            if self.kind == Joints::Impulse {
                let body = &mut self.world.bodies[self.handles[i]];
                body.set_body_type(rp::RigidBodyType::Dynamic, true);
            }
        }
    }

    /// Whether the feet are held.
    pub fn glued(&self) -> bool {
        !self.glue.is_empty()
    }

    /// The middle of part `i`'s box's underside, in the world (for a foot: its sole).
    pub fn sole_centre(&self, i: usize) -> DVec3 {
        let s = self.state[i];
        s.position + s.orientation * self.humanoid.parts[i].underside()
    }

    /// The part named `name`: a part's own name (`l_thigh`), or a skeleton joint's, meaning the
    /// part that joint moves with.
    pub fn part_named(&self, name: &str) -> Option<usize> {
        let h = &self.humanoid;
        h.parts
            .iter()
            .position(|p| p.name == name)
            .or_else(|| h.part_of[self.skeleton.joint(name)?])
    }

    /// Gives the simulated parts the velocities of `from` (the states of an earlier
    /// simulation of the same humanoid): a body handed from one simulation to the next keeps
    /// moving as it did.
    pub fn carry_velocities(&mut self, from: &[PartState]) {
        for (i, s) in from.iter().enumerate().take(self.handles.len()) {
            if !self.physical[i] {
                continue;
            }
            let b = &mut self.world.bodies[self.handles[i]];
            let com = dv(b.center_of_mass());
            let linear = s.velocity + s.angular.cross(com - s.position);
            b.set_linvel(v(linear), true);
            b.set_angvel(v(s.angular), true);
            self.state[i].velocity = s.velocity;
            self.state[i].angular = s.angular;
        }
    }

    /// Pushes part `part` with `impulse` (N s, world) at its centre of mass.
    pub fn push(&mut self, part: usize, impulse: DVec3) {
        if let Some(h) = self.handles.get(part) {
            self.world.bodies[*h].apply_impulse(v(impulse), true);
        }
    }

    /// One step: the `drive`'s torques applied to the simulated parts and its PD pulls set on
    /// their joints' motors, the kinematic chains' reactions on their connectors from
    /// `kinematic` (the kinematic pose one step ahead), and rapier's integration.
    pub fn step(&mut self, kinematic: &Pose, drive: &Drive) {
        let torques = &drive.torques;
        let h = f64::from(self.world.integration_parameters.dt);
        for &handle in &self.handles {
            let b = &mut self.world.bodies[handle];
            b.reset_forces(false);
            b.reset_torques(false);
        }
        for (i, p) in self.humanoid.parts.iter().enumerate() {
            let t = torques.get(i).copied().unwrap_or(DVec3::ZERO);
            if t == DVec3::ZERO || !self.physical[i] {
                continue;
            }
            self.world.bodies[self.handles[i]].add_torque(v(t), true);
            if let Some(parent) = p.parent.filter(|&q| self.physical[q]) {
                self.world.bodies[self.handles[parent]].add_torque(v(-t), true);
            }
        }
        self.set_motors(&drive.pulls);
        let frames = self.humanoid.frames(&self.skeleton, kinematic);
        self.react(&frames, h);
        self.follow(&frames);
        self.world.step();
        let [_, now] = std::mem::take(&mut self.history);
        self.history = [now, frames];
        self.time += h;
        self.measure(h);
        self.count_zmp();
    }

    /// The zero-moment point of the whole body on the ground (`dynamics::zmp`), from every
    /// part's motion over the last steps (accelerations through the 20 ms low-pass of
    /// [`ACCELERATION_SMOOTHING`], so it trails sudden changes by about that); `None` while
    /// nothing presses on the ground.
    pub fn zero_moment_point(&self) -> Option<DVec3> {
        let segments: Vec<Segment> = (self.humanoid.parts.iter().enumerate())
            .map(|(i, p)| {
                let (s, (linear, angular)) = (self.state[i], self.accel[i]);
                let m = p.mass();
                let r = DMat3::from_quat(s.orientation);
                let arm = s.com - s.position;
                Segment {
                    mass: m.mass,
                    com: s.com,
                    acceleration: linear
                        + angular.cross(arm)
                        + s.angular.cross(s.angular.cross(arm)),
                    inertia: r * m.inertia * r.transpose(),
                    spin: s.angular,
                    spin_rate: angular,
                }
            })
            .collect();
        zero_moment_point(&segments, dv(self.world.gravity), 0.0)
    }

    /// Steps taken, and how many of them ended with the zero-moment point outside the
    /// support polygon (the hull of the sole corners on the ground) while feet stood on it:
    /// a balance metric (a body standing still scores none).
    pub fn zmp_outside(&self) -> (usize, usize) {
        self.zmp_count
    }

    /// Counts the step (see [`zmp_outside`](Self::zmp_outside)).
    fn count_zmp(&mut self) {
        self.zmp_count.0 += 1;
        let polygon = support_polygon(&self.contacts());
        if polygon.len() < 3 {
            return;
        }
        if let Some(p) = self.zero_moment_point() {
            if outside(&polygon, DVec2::new(p.x, p.z)) > 0.0 {
                self.zmp_count.1 += 1;
            }
        }
    }

    /// Sets every simulated joint's motors to its pull (free where there is none): a hinge's
    /// about its axis, a ball's as a spring toward its target, by turning its frame on the
    /// parent to the target and pulling every axis to zero.
    fn set_motors(&mut self, pulls: &[Option<Pull>]) {
        for (i, handle) in self.joints.iter().enumerate() {
            let Some(handle) = *handle else { continue };
            let pull = pulls.get(i).copied().flatten();
            let joint = match handle {
                JointHandle::Impulse(h) => self
                    .world
                    .impulse_joints
                    .get_mut(h, false)
                    .map(|j| &mut j.data),
                JointHandle::Multibody(h) => self
                    .world
                    .multibody_joints
                    .get_mut(h)
                    .and_then(|(m, link)| m.link_mut(link))
                    .map(|l| &mut l.joint.data),
            };
            let Some(joint) = joint else { continue };
            let hinge = self.humanoid.parts[i].hinge;
            match pull {
                // motors off: a rapier motor with zero gains is not free but holds its joint
                // still (a rigid velocity constraint), which made a rag doll fall over stiff
                // as a statue
                None => {
                    joint.motor_axes.remove(rp::JointAxesMask::ANG_AXES);
                    if !hinge {
                        let frame = rp::Pose::from_parts(self.anchors[i], rp::Rotation::IDENTITY);
                        joint.set_local_frame1(frame);
                        for (axis, range) in ANGULAR
                            .into_iter()
                            .zip(self.ball_ranges[i].iter().flatten())
                        {
                            joint.set_limits(axis, *range);
                        }
                    }
                }
                Some(p) => {
                    let (kp, kd) = (p.kp as f32, p.kd as f32);
                    if hinge {
                        let angle = 2.0 * p.target.x.atan2(p.target.w);
                        joint.set_motor(rp::JointAxis::AngX, angle as f32, 0.0, kp, kd);
                    } else {
                        let frame = rp::Pose::from_parts(self.anchors[i], rot(p.target));
                        joint.set_local_frame1(frame);
                        // the limits count from the joint's frame, which the pull turns to its
                        // target: off while it pulls (the joint stays near its target). Off,
                        // not widened: each limited axis costs a constraint row (100 standing
                        // characters stepped in 4.85 ms with the limits at ±π, 3.8 without)
                        joint.limit_axes.remove(rp::JointAxesMask::ANG_AXES);
                        for axis in ANGULAR {
                            joint.set_motor(axis, 0.0, 0.0, kp, kd);
                        }
                    }
                }
            }
        }
    }

    /// Moves the kinematic parts to where `kinematic` puts them relative to their simulated
    /// connector (they carry no weight in rapier: their effect is the chains' reaction).
    fn follow(&mut self, frames: &[(Vec3, Quat)]) {
        for i in 0..self.humanoid.parts.len() {
            if self.physical[i] {
                continue;
            }
            let Some(root) = self.connector_of(i) else {
                continue;
            };
            let (kp, kq) = (frames[root].0.as_dvec3(), frames[root].1.as_dquat());
            let s = self.state[root];
            let (at, q) = (frames[i].0.as_dvec3(), frames[i].1.as_dquat());
            let place = s.position + s.orientation * (kq.inverse() * (at - kp));
            let turn = s.orientation * kq.inverse() * q;
            self.world.bodies[self.handles[i]]
                .set_next_kinematic_position(rp::Pose::from_parts(v(place), rot(turn)));
        }
    }

    /// The simulated part a kinematic part's chain hangs from.
    fn connector_of(&self, mut i: usize) -> Option<usize> {
        while !self.physical[i] {
            i = self.humanoid.parts[i].parent?;
        }
        Some(i)
    }

    /// Every kinematic chain's effect on its connector, scaled by k (see [`Coupling`]), and the
    /// torques its joints need (its inverse dynamics, whatever the coupling).
    fn react(&mut self, now: &[(Vec3, Quat)], h: f64) {
        for r in &mut self.last_reaction {
            *r = (DVec3::ZERO, DVec3::ZERO);
        }
        let frames: [&[(Vec3, Quat)]; 3] = [&self.history[0], &self.history[1], now];
        let n = self.humanoid.parts.len();
        let mut carried = vec![Composite::default(); n];
        let mut moving = vec![(DVec3::ZERO, DVec3::ZERO); n];
        for top in 0..n {
            let parent = self.humanoid.parts[top].parent;
            let Some(connector) = parent.filter(|&c| self.physical[c] && !self.physical[top])
            else {
                continue;
            };
            let chain = self.chain_from(top);
            let (links, motions) = self.chain_links(&chain, connector, &frames, h);
            let s = self.state[connector];
            let back = s.orientation.inverse();
            // the chain's inverse dynamics on the connector's motion over the step before: the
            // lagged coupling's wrench, and the torques its joints make (exposed either way)
            let base = with_gravity(
                BaseMotion {
                    velocity: back * s.angular,
                    acceleration: back * self.accel[connector].1,
                    linear: back * self.accel[connector].0,
                },
                s.orientation,
            );
            let d = inverse_dynamics(&links, &motions, base);
            for (&part, t) in chain.iter().zip(&d.torques) {
                // the torque in the link's frame; the link is turned as the kinematic pose
                // turns it on the simulated connector
                let turn = s.orientation
                    * (frames[1][connector].1.inverse() * frames[1][part].1).as_dquat();
                self.torques[part] = turn * *t;
            }
            match self.coupling {
                Coupling::Lagged => {
                    let (f, m) = reaction(&d, self.reaction_gain);
                    let (f, m) = (s.orientation * f, s.orientation * m);
                    let b = &mut self.world.bodies[self.handles[connector]];
                    b.add_force_at_point(v(f), v(s.position), true);
                    b.add_torque(v(m), true);
                    self.last_reaction[connector] = (f, m);
                }
                Coupling::Implicit => {
                    carried[connector].add(&links, &motions);
                    let (l, a) = relative_momentum(&links, &motions);
                    moving[connector].0 += l;
                    moving[connector].1 += a;
                }
            }
        }
        if self.coupling == Coupling::Implicit {
            for i in 0..n {
                if self.physical[i] && carried[i].mass > 0.0 {
                    self.carry(i, carried[i], moving[i], h);
                }
            }
        }
    }

    /// Loads connector `i` with its chains for the coming step (`dynamics::coupling`): their
    /// `composite` and the momentum of their relative motion (`moving`), scaled by k.
    fn carry(&mut self, i: usize, composite: Composite, moving: (DVec3, DVec3), h: f64) {
        let k = self.reaction_gain;
        let own = Composite::of(&self.humanoid.parts[i].mass());
        let body = &mut self.world.bodies[self.handles[i]];
        let moving = (moving.0 * k, moving.1 * k);
        let wrench = self.carriers[i].load(body, &own, composite.scaled(k), moving, h);
        self.last_reaction[i] = wrench;
    }

    /// The parts of the kinematic chain that starts at `top`, parents first.
    fn chain_from(&self, top: usize) -> Vec<usize> {
        let mut chain = vec![top];
        for (i, p) in self.humanoid.parts.iter().enumerate() {
            if p.parent.is_some_and(|q| chain.contains(&q)) && !self.physical[i] {
                chain.push(i);
            }
        }
        chain
    }

    /// The links of `chain` (hanging from `connector`) and their motions at the middle of the
    /// three kinematic poses in `frames` (one step apart).
    fn chain_links(
        &self,
        chain: &[usize],
        connector: usize,
        frames: &[&[(Vec3, Quat)]; 3],
        h: f64,
    ) -> (Vec<Link>, Vec<JointMotion>) {
        let mut links = Vec::with_capacity(chain.len());
        let mut motions = Vec::with_capacity(chain.len());
        let now = frames[1];
        for &i in chain {
            let p = self.humanoid.parts[i];
            let up = p.parent.unwrap_or(connector);
            let offset = now[up].1.as_dquat().inverse() * (now[i].0 - now[up].0).as_dvec3();
            let relative = |f: &[(Vec3, Quat)]| (f[up].1.inverse() * f[i].1).as_dquat().normalize();
            let (w, dw, _) = derivatives(
                relative(frames[0]),
                relative(frames[1]),
                relative(frames[2]),
                h,
            );
            let m = p.mass();
            links.push(Link {
                parent: chain.iter().position(|&c| Some(c) == p.parent),
                offset,
                mass: m.mass,
                com: m.com,
                inertia: m.inertia,
            });
            motions.push(JointMotion {
                rotation: relative(frames[1]),
                velocity: w,
                acceleration: dw,
            });
        }
        (links, motions)
    }

    /// Writes the simulated parts into `pose`: the root's place and turn from the sacroiliac,
    /// each simulated part's joint turned so that it ends up as its body is (the skeleton joints
    /// lumped into a part keep the rotations `pose` gives them, as the kinematic parts that hang
    /// from them were placed with those).
    pub fn write(&self, pose: &mut Pose) {
        let joints = self.skeleton.joints();
        for (i, p) in self.humanoid.parts.iter().enumerate() {
            if !self.physical[i] {
                continue;
            }
            let j = self.humanoid.joints[i];
            let s = self.state[i];
            // the world orientation of the skeleton joint above j (through lumped joints)
            let parent_world = match p.parent {
                Some(q) => self.state[q].orientation,
                None => DQuat::IDENTITY,
            };
            let lumped = lumped_turn(&self.skeleton, pose, &self.humanoid, j);
            let local = (parent_world * lumped).inverse() * s.orientation;
            if p.parent.is_none() {
                // the root carries the place and the turn; the sacroiliac stays at rest
                let root = self
                    .skeleton
                    .joints()
                    .iter()
                    .position(|x| x.parent.is_none());
                if let Some(r) = root {
                    pose.rotations[r] = s.orientation.as_quat();
                    let offset = joints[j].offset.as_dvec3();
                    pose.root = (s.position - s.orientation * offset).as_vec3();
                }
                pose.rotations[j] = Quat::IDENTITY;
            } else {
                pose.rotations[j] = local.as_quat().normalize();
            }
        }
    }
}

fn is_part_joint(h: &Humanoid, k: usize) -> bool {
    h.joints.contains(&k)
}

/// The rotation from part-joint `j`'s parent part's frame to the frame of `j`'s skeleton
/// parent: the turns of the skeleton joints between them, as `pose` has them (identity where
/// the simulation holds them straight).
fn lumped_turn(skeleton: &Skeleton, pose: &Pose, h: &Humanoid, j: usize) -> DQuat {
    let joints = skeleton.joints();
    let mut q = DQuat::IDENTITY;
    let mut a = joints[j].parent;
    while let Some(k) = a {
        if is_part_joint(h, k) || joints[k].parent.is_none() {
            break;
        }
        q = pose.rotations[k].as_dquat() * q;
        a = joints[k].parent;
    }
    q
}
