//! The locomotion engine: BML `<locomotion target manner>` as a character that walks there.
//!
//! - The target is a point of the world, a point moving along a path (followed as it moves), a
//!   placed character (the walker stops 1.2 m from them, turned to face them) or `x,z` in world
//!   metres. `manner` is WALK (1.3 m/s), STROLL (0.8 m/s) or RUN (3.0 m/s, with a flight
//!   phase); `bmlt:speed` (m/s) overrides the speed; `bmlt:planner="footsteps"` walks by
//!   footsteps chosen one at a time (`locomotion::footsteps`) instead of steering.
//! - Timing: when the block is scheduled the engine rehearses the walk from where the character
//!   stands (the same fixed-step simulation it will run), which gives the preferred times of
//!   `start` (first weight shift), `ready` (cruising speed), `relax` (final deceleration begins)
//!   and `end` (standing, both feet planted). While walking it revises them ([`Travel`]): a sync
//!   point passes when it really happens, and what is tied to it follows.
//! - Each frame the character's body is stepped to the frame's time before the frame's sync
//!   points pass; where it stands becomes the character's placement in the world (its other
//!   engines see the world from there); the gait poses the legs, pelvis and arms
//!   (`locomotion::posing`) under whatever upper-body engines play after it.
//! - An interrupted walk slows down and stands within a step or two. A target inside an
//!   obstacle or walled in gives EXECUTION_FAILURE and the walk ends where it stands; an
//!   unknown one NO_SUCH_TARGET.

use std::cell::RefCell;
use std::sync::Arc;

use glam::Vec2;

use crate::character::body::{Pose, Skeleton};
use crate::engines::interface::{
    Engine, EngineError, Revision, Steering, Travel, Unit, UnitKey, Units,
};
use crate::language::bml::{Behaviour, BehaviourKind, NS_BMLT};
use crate::language::feedback::KnownWarning;
use crate::planning::timing::{SyncName, TimingModel, TimingModels};
use crate::world::locomotion::posing::{lead_the_turn, pose_gait, GaitJoints};
use crate::world::locomotion::room::Room;
use crate::world::locomotion::{walker, Moments, Walk, Walker};
use crate::world::space::Obstacles;
use crate::world::{Placement, World};
use targets::{resolve, Pursuit};

pub mod targets;
mod travel;

/// Fastest `bmlt:speed` taken (m/s).
pub const MAX_SPEED: f32 = 10.0;
/// Longest walk rehearsed when scheduling (s of walking, about 7 ms of work); a longer one is
/// predicted from its length.
pub const REHEARSAL_LIMIT: f64 = 30.0;

/// A walk as written: where to and how.
#[derive(Debug, Clone, PartialEq)]
struct Order {
    target: String,
    speed: f32,
    running: bool,
    /// Walks by footsteps (`bmlt:planner="footsteps"`).
    footsteps: bool,
    /// Why the speed, manner or planner written was not taken.
    note: Option<String>,
}

/// The longest time waiting one's turn at doors puts off a walk's deadline (s): a walk held
/// at a door for longer (turns that never come) fails with a warning rather than waiting for
/// ever.
pub const MOST_QUEUED: f64 = 300.0;

/// Past its deadline, a walk goes on while it has come
/// [`NEARER`](crate::world::locomotion::walker::NEARER) nearer its goal within this long (s).
pub const STALL: f64 = 15.0;
/// The longest a walk still getting nearer goes on past its deadline (s).
pub const MOST_LATE: f64 = 120.0;

/// What a unit is doing.
#[derive(Debug, Clone, PartialEq)]
struct WalkUnit {
    order: Order,
    started: bool,
    /// Interrupted: slowing down to stand where it is.
    halted: bool,
    /// A walk still going then has failed (global time), unless it is still getting nearer
    /// (`fails_at`).
    deadline: f64,
}

/// The locomotion engine (see the module documentation).
#[derive(Debug, Default)]
pub struct LocomotionEngine {
    units: Units<WalkUnit>,
    walker: Option<Walker>,
    /// The unit being walked.
    current: Option<UnitKey>,
    /// The shared world and where the character stood, as of the last travel.
    world: Option<std::sync::Arc<World>>,
    at: Placement,
    id: String,
    joints: Option<Option<GaitJoints>>,
    /// Whether the character has walked (until then the gait leaves the pose alone).
    walked: bool,
    revisions: Vec<Revision>,
    warnings: Vec<(UnitKey, String)>,
    /// The last rehearsal: (walker state, walk) → moments relative to its start.
    rehearsed: RefCell<Option<(Walker, Walk, Moments)>>,
    /// The pursuit of the current walk's target (which may move).
    pursuit: Pursuit,
    /// What the walk under way goes round (see [`LocomotionEngine::round`]).
    obstacles: Arc<Obstacles>,
    /// Standing, whether it made room for a walker and where it stood before.
    room: Option<Room>,
    /// Where its last walk arrived (cleared when another starts): pressed off it while
    /// standing, it steps back (`locomotion::room::back_to`).
    place: Option<crate::world::locomotion::gait::Body>,
    /// Whether the walk under way waits for one standing on its goal or settles beside them.
    settling: targets::Settling,
}

/// Reads a locomotion behaviour's order.
fn order(b: &Behaviour) -> Option<Order> {
    let BehaviourKind::Locomotion(l) = &b.kind else {
        return None;
    };
    let mut note = None;
    let (mut speed, running) = match l.manner.as_deref().map(str::to_ascii_uppercase).as_deref() {
        None | Some("WALK") => (1.3, false),
        Some("STROLL") => (0.8, false),
        Some("RUN") => (3.0, true),
        Some(other) => {
            note = Some(format!(
                "manner '{other}' is not one of WALK, STROLL, RUN: it walks"
            ));
            (1.3, false)
        }
    };
    let written = b
        .foreign_attrs
        .iter()
        .find(|a| a.ns == NS_BMLT && a.name == "speed");
    if let Some(a) = written {
        match a.value.trim().parse::<f32>() {
            Ok(v) if v.is_finite() && v > 0.05 && v <= MAX_SPEED => speed = v,
            _ => {
                note = Some(format!(
                    "bmlt:speed '{}' is not a speed above 0.05 and at most {MAX_SPEED} m/s: it goes at {speed} m/s",
                    a.value
                ))
            }
        }
    }
    let planner = b
        .foreign_attrs
        .iter()
        .find(|a| a.ns == NS_BMLT && a.name == "planner");
    let footsteps = match planner.map(|a| a.value.trim()) {
        None | Some("steering") => false,
        Some("footsteps") => true,
        Some(other) => {
            note = Some(format!(
                "bmlt:planner '{other}' is not one of steering, footsteps: it steers"
            ));
            false
        }
    };
    Some(Order {
        target: l.target.clone(),
        speed,
        running,
        footsteps,
        note,
    })
}

fn to_times(syncs: &[(SyncName, f64)]) -> Vec<f64> {
    syncs.iter().map(|s| s.1).collect()
}

impl LocomotionEngine {
    /// The walker, standing where the character stands if it has none yet.
    fn walker(&mut self, at: Placement, world: &World, now: f64) -> &mut Walker {
        let here = Vec2::new(at.position.x, at.position.z);
        let moved_by_host = self.walker.as_ref().is_some_and(|w| {
            let b = w.body();
            b.at.distance(here) > 1e-3
                || crate::world::locomotion::gait::angle_diff(b.facing, at.facing).abs() > 1e-3
        });
        if self.walker.is_none() || moved_by_host {
            // on the walker's grid of steps, so that where it is at a time does not depend on
            // when the host's frames come
            let time = (now / walker::STEP).floor() * walker::STEP;
            self.walker = Some(self.standing(at, world, time));
        }
        self.walker.as_mut().expect("just made")
    }

    /// A walker of this character standing at `at` at time `time`.
    fn standing(&self, at: Placement, world: &World, time: f64) -> Walker {
        let here = Vec2::new(at.position.x, at.position.z);
        let mut w = Walker::new(here, at.facing, world.radius(&self.id), time);
        w.combine = world.combiner(&self.id);
        w.profile = world.profile(&self.id);
        w
    }

    /// What `walker` goes round on `walk`: the obstacles and the space of every conversing group
    /// it is not in, or the obstacles alone when the groups leave no way there.
    fn round(&self, world: &World, walker: &Walker, walk: &Walk) -> Arc<Obstacles> {
        let all = world.obstacles_for(&self.id);
        if Arc::ptr_eq(&all, world.obstacles_shared()) || walker.can_route(walk, &all) {
            all
        } else {
            world.obstacles_shared().clone()
        }
    }

    /// The moments of `walk` from the walker's state, relative to its start.
    fn rehearse(
        &self,
        walker: &Walker,
        walk: &Walk,
        obstacles: &crate::world::space::Obstacles,
    ) -> Result<Moments, String> {
        if let Some((w, k, m)) = self.rehearsed.borrow().as_ref() {
            if w == walker && k == walk {
                return Ok(*m);
            }
        }
        let m = walker
            .rehearse(walk.clone(), obstacles, REHEARSAL_LIMIT)
            .map_err(|e| e.to_string())?;
        let rel = |t: Option<f64>| t.map(|t| t - walker.time);
        let rel = Moments {
            start: Some(0.0),
            ready: rel(m.ready),
            relax: rel(m.relax),
            end: rel(m.end),
        };
        *self.rehearsed.borrow_mut() = Some((walker.clone(), walk.clone(), rel));
        Ok(rel)
    }

    /// Starts the walk of unit `key` now; a walk under way stops where it is.
    fn start_walk(&mut self, key: UnitKey, world: &World) {
        let Some(u) = self.units.get(&key).cloned() else {
            return;
        };
        let here = self.walker.as_ref().map_or(Vec2::ZERO, |w| w.body().at);
        self.settling = targets::Settling::default();
        self.place = None;
        let walk = match resolve(world, &self.id, &u.order.target, here) {
            Some(goal) => Walk {
                goal: goal.at,
                speed: u.order.speed,
                running: u.order.running,
                face: goal.face,
                stepping: false,
                footsteps: u.order.footsteps,
            },
            None => {
                self.fail(&key, world.unknown_target(&u.order.target));
                return;
            }
        };
        if let Some(old) = self.current.take() {
            self.end_now(&old);
        }
        let Some(walker) = self.walker.clone() else {
            return;
        };
        let obstacles = self.round(world, &walker, &walk);
        let planned = self.rehearse(&walker, &walk, &obstacles);
        let w = self.walker.as_mut().expect("a walker");
        match w.start(walk, &obstacles) {
            Ok(()) => {
                self.obstacles = obstacles;
                self.walked = true;
                self.current = Some(key.clone());
                self.pursuit = Pursuit::default();
                let t0 = w.time;
                if let (Ok(m), Some((syncs, unit))) = (planned, self.units.get_mut(&key)) {
                    unit.started = true;
                    let planned = m.end.or(m.relax).unwrap_or(REHEARSAL_LIMIT);
                    unit.deadline = t0 + 2.0 * planned + 10.0;
                    // the rehearsal from here is what will happen: the plan follows it
                    let at = |o: Option<f64>| o.map_or(f64::INFINITY, |o| t0 + o);
                    let new: Vec<f64> = syncs
                        .iter()
                        .map(|(n, t)| match n.as_ref() {
                            "ready" => at(m.ready),
                            "relax" => at(m.relax),
                            "end" => at(m.end.or(m.relax.map(|r| r + 2.0))),
                            _ => *t,
                        })
                        .collect();
                    if new.iter().all(|t| t.is_finite()) {
                        self.revise(&key, new, true);
                    }
                }
            }
            Err(e) => self.fail(&key, format!("{key}: {e}")),
        }
    }

    /// When walk `key` fails if it has not arrived: at its deadline, put off by the time it
    /// waited its turn at doors (at most [`MOST_QUEUED`]) and, while it still gets nearer its
    /// goal, until [`STALL`] after it last came nearer (at most [`MOST_LATE`] beyond), as a
    /// person in a press goes on while the press moves. On the walker's steps alone, whatever
    /// the host's frames.
    pub(crate) fn fails_at(&self, key: &UnitKey) -> f64 {
        let Some(u) = self.units.get(key) else {
            return f64::INFINITY;
        };
        let Some(w) = self.walker.as_ref() else {
            return u.deadline;
        };
        let due = u.deadline + w.queued.min(MOST_QUEUED);
        due.max(w.nearest.1 + STALL).min(due + MOST_LATE)
    }

    /// A walk that cannot go: a warning, and it ends at once where the character stands.
    fn fail(&mut self, key: &UnitKey, why: String) {
        self.warnings.push((key.clone(), why));
        self.end_now(key);
    }

    /// Unit `key` ends now: its syncs still ahead move to the walker's time.
    fn end_now(&mut self, key: &UnitKey) {
        let now = self.walker.as_ref().map_or(0.0, |w| w.time);
        if let Some((syncs, u)) = self.units.get_mut(key) {
            u.started = true;
            let new: Vec<f64> = syncs.iter().map(|s| s.1.min(now)).collect();
            self.revise(key, new, false);
        }
    }

    /// Records new times for `key` (and in the engine's own copy).
    fn revise(&mut self, key: &UnitKey, times: Vec<f64>, others_follow: bool) {
        self.units.retime(key, &times);
        self.revisions.retain(|r| r.unit != *key);
        self.revisions.push(Revision {
            unit: key.clone(),
            times,
            others_follow,
        });
    }

    /// After stepping to `now`: moments that happened become the sync times; syncs still
    /// ahead whose planned time has come are put off a little.
    fn follow_moments(&mut self, now: f64, ended: Option<Moments>) {
        let Some(key) = self.current.clone() else {
            return;
        };
        let Some(w) = self.walker.as_ref() else {
            return;
        };
        let m = ended.or_else(|| w.moments()).unwrap_or_default();
        let fails_at = self.fails_at(&key);
        let Some((syncs, u)) = self.units.get_mut(&key) else {
            return;
        };
        if ended.is_none() && now > fails_at {
            let why = format!(
                "{key}: the walk to '{}' has not arrived {:.1} s after it set off; it stops where it is",
                u.order.target,
                now - syncs[0].1
            );
            if let Some(w) = self.walker.as_mut() {
                w.halt();
                w.stand();
            }
            self.current = None;
            self.fail(&key, why);
            return;
        }
        let (mut new, mut changed) = (to_times(syncs), false);
        for (k, (name, t)) in syncs.iter().enumerate() {
            let happened = match name.as_ref() {
                "ready" => m.ready,
                "relax" => m.relax,
                "end" => m.end,
                _ => continue,
            };
            let want = match happened {
                Some(h) => h,
                // late: put off by half a second at a time (a prediction a frame, no more)
                None if *t <= now => now + 0.5,
                None => *t,
            };
            if (want - t).abs() > 1e-9 {
                new[k] = want;
                changed = true;
            }
        }
        // keep the order
        for k in 1..new.len() {
            new[k] = new[k].max(new[k - 1]);
        }
        if ended.is_some() {
            self.current = None;
            // (where it stopped: one pressed on while its feet closed went back only to
            // where the press had left it, 0.54 m from its goal)
            self.place = (self.walker.as_ref()).map(|w| crate::world::locomotion::gait::Body {
                at: w.stopped_at.unwrap_or(w.body().at),
                ..w.body()
            });
            if let Some(short) = self.walker.as_mut().and_then(|w| w.stuck.take()) {
                self.warnings.push((
                    key.clone(),
                    format!("{key}: the footstep walk stopped {short:.2} m short of its goal: no step led anywhere better (a local minimum of its behaviour net)"),
                ));
            }
        }
        if changed {
            let follow = !self.units.get(&key).is_some_and(|u| u.halted);
            self.revise(&key, new, follow);
        }
    }
}

impl Engine for LocomotionEngine {
    crate::units_retime_len!();
    crate::units_play!("locomotion");

    fn name(&self) -> &'static str {
        "locomotion"
    }

    fn timing(&self, behaviour: &Behaviour) -> Option<TimingModel> {
        let o = order(behaviour)?;
        let fallback = crate::planning::timing::DefaultTimingModels::default().model(behaviour);
        let Some(world) = self.world.as_deref() else {
            return fallback;
        };
        // a character that has not walked yet stands where it is placed
        let standing;
        let walker = match self.walker.as_ref() {
            Some(w) => w,
            None => {
                standing = self.standing(self.at, world, 0.0);
                &standing
            }
        };
        let Some(goal) = resolve(world, &self.id, &o.target, walker.body().at) else {
            return fallback;
        };
        let walk = Walk {
            goal: goal.at,
            speed: o.speed,
            running: o.running,
            face: goal.face,
            stepping: false,
            footsteps: o.footsteps,
        };
        let m = match self.rehearse(walker, &walk, &self.round(world, walker, &walk)) {
            Ok(m) => m,
            Err(_) => return fallback,
        };
        // a walk longer than the rehearsal: its slowing down after `relax` as a walk's
        let end = m.end.unwrap_or(m.relax.unwrap_or(REHEARSAL_LIMIT) + 2.0);
        let relax = m.relax.unwrap_or(end - 1.0).clamp(0.0, end);
        let ready = m.ready.unwrap_or(relax.min(1.0)).clamp(0.0, relax);
        Some(TimingModel::stretchable(&[
            ("start", 0.0),
            ("ready", ready),
            ("relax", relax),
            ("end", end),
        ]))
    }

    fn check_timing(&self, _b: &Behaviour, _syncs: &[(SyncName, f64)]) -> Result<(), String> {
        // the walk decides its own times and revises them
        Ok(())
    }

    fn self_timed(&self, behaviour: &Behaviour) -> bool {
        matches!(behaviour.kind, BehaviourKind::Locomotion(_))
    }

    fn interprets(&self, ns: &str, name: &str) -> bool {
        ns == NS_BMLT && (name == "speed" || name == "planner")
    }

    fn refusal(&self, error: &EngineError) -> KnownWarning {
        if error.0.contains(crate::world::UNKNOWN_TARGET) {
            KnownWarning::NoSuchTarget
        } else {
            KnownWarning::ExecutionFailure
        }
    }

    fn add(&mut self, unit: Unit<'_>) -> Result<(), EngineError> {
        let o = order(unit.behaviour)
            .ok_or_else(|| EngineError("the locomotion engine realizes locomotion".into()))?;
        if let Some(world) = self.world.as_deref() {
            let here = self.walker.as_ref().map_or(Vec2::ZERO, |w| w.body().at);
            if resolve(world, &self.id, &o.target, here).is_none() {
                return Err(EngineError(format!(
                    "{}: {}",
                    unit.key,
                    world.unknown_target(&o.target)
                )));
            }
        }
        if let Some(note) = &o.note {
            self.warnings.push((unit.key.clone(), note.clone()));
        }
        self.units.add(
            unit,
            WalkUnit {
                order: o,
                started: false,
                halted: false,
                deadline: f64::INFINITY,
            },
        );
        Ok(())
    }

    fn remove(&mut self, key: &UnitKey) {
        if self.current.as_ref() == Some(key) {
            if let Some(w) = self.walker.as_mut() {
                w.halt();
            }
            self.current = None;
        }
        self.units.remove(key);
    }

    fn interrupt(&mut self, key: &UnitKey, now: f64, syncs: &[(SyncName, f64)]) -> Vec<f64> {
        let walking = self.current.as_ref() == Some(key);
        if !walking {
            let times = crate::engines::interface::stop_now(now, syncs);
            self.units.retime(key, &times);
            if let Some((_, u)) = self.units.get_mut(key) {
                u.started = true;
            }
            return times;
        }
        if let Some(w) = self.walker.as_mut() {
            w.halt();
        }
        let speed = self.walker.as_ref().map_or(0.0, |w| w.vehicle.speed());
        let stop = now + f64::from(speed / 1.2) + 0.6;
        let times: Vec<f64> = syncs
            .iter()
            .map(|(n, t)| match n.as_ref() {
                _ if *t <= now => *t,
                "end" => stop,
                _ => now,
            })
            .collect();
        self.units.retime(key, &times);
        if let Some((_, u)) = self.units.get_mut(key) {
            u.halted = true;
        }
        times
    }

    fn take_warnings(&mut self) -> Vec<(UnitKey, String)> {
        std::mem::take(&mut self.warnings)
    }

    fn as_travel(&mut self) -> Option<&mut dyn Travel> {
        Some(self)
    }

    fn as_revising(&mut self) -> Option<&mut dyn crate::engines::interface::Revising> {
        Some(self)
    }

    fn as_motion(&mut self) -> Option<&mut dyn crate::engines::interface::Motion> {
        Some(self)
    }
}

impl crate::engines::interface::Motion for LocomotionEngine {
    fn steers(&self, behaviour: &Behaviour, skeleton: &Skeleton) -> Option<Steering> {
        order(behaviour)?;
        Some(Steering::kinematic(
            skeleton,
            GaitJoints::names(skeleton),
            false,
        ))
    }

    fn animate(&mut self, _now: f64, skeleton: &Skeleton, _world: &World, pose: &mut Pose) {
        if !self.walked {
            return;
        }
        let Some(w) = self.walker.as_ref() else {
            return;
        };
        let joints = self.joints.get_or_insert_with(|| GaitJoints::of(skeleton));
        if let Some(j) = joints {
            pose_gait(skeleton, j, &w.gait, w.body(), pose);
            lead_the_turn(j, w.look_ahead(), w.gait.amount, pose);
        }
    }
}
