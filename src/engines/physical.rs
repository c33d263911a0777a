//! The physical engine: BMLT `controller` behaviours as physical controllers of a simulated body
//! (mixed dynamics, `dynamics::sim`). While a controller runs, the character's lower body and
//! trunk (for a rag doll, the whole body) are simulated on rapier3d at 200 Hz; the arms and
//! head keep playing what the kinematic engines set, and push back on the trunk through their
//! inverse dynamics. Classes and parameters (changeable while they run):
//!
//! - `BalanceController`: stands and balances (`pelvisheight`, relative to the leg's length,
//!   0.98; `stiffnessmultiplier` 1; `reactiongain`, the k of the arms' push, 1). When the centre
//!   of mass leaves the feet, it lets go: the body falls as a rag doll, with a warning.
//! - `PoseController`: PD tracking of what the kinematic engines would set on the simulated
//!   joints (`stiffnessmultiplier` 1: 300 N m/rad, 30 N m s/rad).
//! - `RagDoll`: no torque; the whole body simulated (alone, it lets go of the feet).
//! - compound controllers (`dynamics::compound`), defined as data: the embedded
//!   `HangingLeftArm` and `HangingRightArm` (the arm simulated and hanging down loosely) and any
//!   an `--assets` directory's `compounds.json` adds (`stiffnessmultiplier` 1 scales their
//!   gains). They hold only their own parts: run them with a `BalanceController` (alone, the
//!   legs and trunk have no controller and the realizer warns).
//!
//! A class is named in any case, with or without its `Controller` suffix (`Balance`).
//!
//! Several controllers at once add their torques and pulls. The simulated set is the smallest of
//! the [`CONFIGURATIONS`] (lower body and trunk, with one arm, with both, the whole body) that
//! covers every running controller, and it changes when they do, the new simulation starting
//! where the body is, at the speeds it has. With no controller left the body returns to the kinematic pose over 0.3 s
//! (longer from far away), along a Hermite curve that starts with the pose and the speed it had.
//! The engine registers last: it steps the simulation up to each frame with the kinematic pose
//! the others made (interpolated between frames) and writes the simulated joints over it.
//!
//!
//! Longer than 600 lines on purpose: the controller catalogue, the choice of configuration, the
//! warnings and the run loop all work on the running controllers and the one simulation; the
//! hand-back to the kinematic pose, which stands alone, is `physical/release.rs`.

use glam::{DVec3, Quat};

use std::sync::Arc;

use crate::character::body::{Pose, Skeleton};
use crate::character::dynamics::compound::{same_name, Compound, CompoundLibrary, CompoundSpec};
use crate::character::dynamics::config::{smallest_covering, Configuration};
use crate::character::dynamics::controllers::{
    Balance, Controller, Drive, PoseController, RagDoll,
};
use crate::character::dynamics::sim::{Simulation, STEP};
use crate::engines::interface::{
    named_param, named_params, Engine, EngineError, MotionKind, Params, Steering, Unit, UnitKey,
    Units,
};
use crate::language::bml::{Behaviour, BehaviourKind};
use crate::world::World;
use release::{Offset, Release};

/// The lower body and the trunk (parts of `dynamics::humanoid::PARTS`).
pub const LOWER_BODY: [usize; 8] = [0, 1, 9, 10, 11, 12, 13, 14];
/// Every part.
pub const WHOLE_BODY: [usize; 15] = [0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14];

/// The body configurations the engine simulates, by the parts simulated (the rest are
/// kinematic chains): it takes the smallest that covers what the running controllers need.
pub const CONFIGURATIONS: [(&str, &[usize]); 5] = [
    ("lower body", &LOWER_BODY),
    (
        "lower body, left arm",
        &[0, 1, 3, 4, 5, 9, 10, 11, 12, 13, 14],
    ),
    (
        "lower body, right arm",
        &[0, 1, 6, 7, 8, 9, 10, 11, 12, 13, 14],
    ),
    (
        "lower body, arms",
        &[0, 1, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14],
    ),
    ("whole body", &WHOLE_BODY),
];

/// [`CONFIGURATIONS`] over a skeleton's joints (as `dynamics::config` chooses among them).
#[derive(Debug)]
struct Catalogue {
    /// Per skeleton joint, the part it moves with.
    part_of: Vec<Option<usize>>,
    /// One per entry of [`CONFIGURATIONS`], in its order.
    configurations: Vec<Configuration>,
}

impl Catalogue {
    fn new(skeleton: &Skeleton) -> Catalogue {
        let part_of = crate::character::dynamics::humanoid::Humanoid::new(skeleton)
            .map(|h| h.part_of)
            .unwrap_or_default();
        let mut catalogue = Catalogue {
            part_of,
            configurations: Vec::new(),
        };
        catalogue.configurations = (CONFIGURATIONS.iter())
            .map(|(name, parts)| {
                Configuration::from_physical(name, skeleton, &catalogue.joints(parts))
            })
            .collect();
        catalogue
    }

    /// The skeleton joints that move with `parts`.
    fn joints(&self, parts: &[usize]) -> Vec<usize> {
        (0..self.part_of.len())
            .filter(|&j| self.part_of[j].is_some_and(|p| parts.contains(&p)))
            .collect()
    }

    /// The parts of the smallest configuration whose simulated joints cover those of `parts`
    /// (the whole body if none does).
    fn smallest_covering(&self, parts: &[usize]) -> &'static [usize] {
        let chosen = smallest_covering(&self.configurations, &self.joints(parts));
        chosen
            .and_then(|c| self.configurations.iter().position(|x| std::ptr::eq(x, c)))
            .map_or(&WHOLE_BODY, |k| CONFIGURATIONS[k].1)
    }
}

/// How far (rad) the kinematic engines may turn a simulated joint from rest before the engine
/// warns that the simulation hides it (the idle layer's weight shift stays below: it bends the
/// knee of the leg it unloads by up to about 8°, 0.14 rad, to keep both feet on the floor).
const HIDDEN: f32 = 0.2;

/// The classes and their parameters (defaults).
const CLASSES: &[(&str, &[(&str, f64)])] = &[
    (
        "BalanceController",
        &[
            ("pelvisheight", 0.98),
            ("stiffnessmultiplier", 1.0),
            ("reactiongain", 1.0),
        ],
    ),
    ("PoseController", &[("stiffnessmultiplier", 1.0)]),
    ("RagDoll", &[]),
];

#[derive(Debug, Clone)]
struct ControllerUnit {
    /// The class (for a compound, [`COMPOUND`]).
    class: &'static str,
    /// A compound's definition.
    compound: Option<Arc<CompoundSpec>>,
    params: Params,
}

/// The class of every compound controller unit.
const COMPOUND: &str = "compound";

impl ControllerUnit {
    fn value(&self, name: &str) -> f64 {
        named_param(&self.params, name).unwrap_or(0.0)
    }

    /// The balance controller its parameters make (for a `BalanceController`).
    fn balance(&self) -> Balance {
        Balance {
            pelvis_height: self.value("pelvisheight"),
            stiffness: self.value("stiffnessmultiplier"),
        }
    }

    /// The parts it needs simulated.
    fn needs(&self) -> Vec<usize> {
        match (&self.compound, self.class) {
            (Some(c), _) => c.required(),
            (None, "RagDoll") => WHOLE_BODY.to_vec(),
            _ => LOWER_BODY.to_vec(),
        }
    }

    /// Whether it holds the legs and the trunk (something stands the body).
    fn holds_the_legs(&self) -> bool {
        matches!(
            self.class,
            "BalanceController" | "PoseController" | "RagDoll"
        )
    }
}

/// The physical engine (see the module documentation).
#[derive(Default)]
pub struct PhysicalEngine {
    units: Units<ControllerUnit>,
    sim: Option<Simulation>,
    /// Global time the simulation has reached.
    clock: f64,
    /// The kinematic pose of the last frame, and its time.
    last: Option<(f64, Pose)>,
    /// The pose the simulation last wrote (where the body is).
    written: Option<Pose>,
    /// How the simulated pose differed from the kinematic one at the last two simulated
    /// frames (for a release that keeps the body's speed).
    offsets: [Option<Offset>; 2],
    /// Releasing to the kinematic pose.
    release: Option<Release>,
    /// The balance gave up (until the controllers change).
    fallen: bool,
    /// The configurations over the skeleton's joints (made at the first frame).
    catalogue: Option<Catalogue>,
    /// Warned that no controller holds the legs (until the controllers change).
    unheld: bool,
    /// Warned that the simulation hides kinematic motion (until the controllers change).
    hidden: bool,
    /// The zero-moment point counts (steps, outside the feet) of the simulations before this one.
    zmp_before: (usize, usize),
    /// The compound controllers BML may name.
    compounds: CompoundLibrary,
    warnings: Vec<(UnitKey, String)>,
}

impl std::fmt::Debug for PhysicalEngine {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("PhysicalEngine")
            .field("units", &self.units.len())
            .field("simulating", &self.sim.is_some())
            .field("clock", &self.clock)
            .finish()
    }
}

impl PhysicalEngine {
    /// An engine whose compound controllers are `compounds` (the built-in classes besides).
    pub fn new(compounds: CompoundLibrary) -> PhysicalEngine {
        PhysicalEngine {
            compounds,
            ..PhysicalEngine::default()
        }
    }

    /// The simulation, while one runs.
    pub fn simulation(&self) -> Option<&Simulation> {
        self.sim.as_ref()
    }

    /// Adds an ended simulation's zero-moment point counts to the character's.
    fn count_zmp(&mut self, ended: Option<&Simulation>) {
        if let Some(sim) = ended {
            let (steps, outside) = sim.zmp_outside();
            self.zmp_before.0 += steps;
            self.zmp_before.1 += outside;
        }
    }

    /// The running controllers at `now`.
    fn active(&self, now: f64) -> Vec<(UnitKey, ControllerUnit)> {
        self.units
            .running(now)
            .map(|(k, _, u)| ((**k).clone(), u.clone()))
            .collect()
    }

    /// The parts the running controllers need: the smallest configuration covering them.
    fn configuration(
        &mut self,
        active: &[(UnitKey, ControllerUnit)],
        skeleton: &Skeleton,
    ) -> &'static [usize] {
        let catalogue = self
            .catalogue
            .get_or_insert_with(|| Catalogue::new(skeleton));
        let needed: Vec<usize> = active.iter().flat_map(|(_, u)| u.needs()).collect();
        catalogue.smallest_covering(&needed)
    }

    /// The way back to the kinematic pose for the joints of the parts `sim` simulates and
    /// `parts` does not (an arm whose controller ended while the legs stay simulated), from the
    /// last simulated frames; `None` when no part leaves.
    fn handing_back(&self, sim: &Simulation, parts: &[usize]) -> Option<Release> {
        let h = sim.humanoid();
        let leaving =
            |j: usize| h.part_of[j].is_some_and(|p| sim.is_physical(p) && !parts.contains(&p));
        if !(0..h.part_of.len()).any(leaving) {
            return None;
        }
        let only_leaving = |o: &Offset| Offset {
            time: o.time,
            root: glam::Vec3::ZERO,
            turns: (o.turns.iter().enumerate())
                .map(|(j, t)| if leaving(j) { *t } else { glam::Vec3::ZERO })
                .collect(),
        };
        let [before, last] = &self.offsets;
        let last = only_leaving(last.as_ref()?);
        Some(Release::new(
            &last,
            before.as_ref().map(only_leaving).as_ref(),
        ))
    }

    /// Warns once (until the controllers change) when the kinematic engines turn a simulated
    /// joint more than [`HIDDEN`] from rest while no `PoseController` tracks them: the
    /// simulation decides that joint, so their motion there is not shown (a left-hand BEAT
    /// under `HangingLeftArm`).
    fn warn_hidden(
        &mut self,
        active: &[(UnitKey, ControllerUnit)],
        skeleton: &Skeleton,
        kinematic: &Pose,
    ) {
        let Some(sim) = &self.sim else { return };
        if self.hidden || active.iter().any(|(_, u)| u.class == "PoseController") {
            return;
        }
        let h = sim.humanoid();
        let moved: Vec<usize> = (0..h.parts.len())
            .filter(|&i| sim.is_physical(i))
            .filter(|&i| kinematic.rotations[h.joints[i]].angle_between(Quat::IDENTITY) > HIDDEN)
            .collect();
        let Some(&first) = moved.first() else { return };
        // told to the controller that makes that part simulated (the narrowest that needs it)
        let owner = (active.iter())
            .filter(|(_, u)| u.needs().contains(&first))
            .min_by_key(|(_, u)| u.needs().len())
            .or(active.first());
        let Some((key, _)) = owner else { return };
        let names: Vec<&str> = (moved.iter())
            .map(|&i| skeleton.joints()[h.joints[i]].name.as_str())
            .collect();
        self.hidden = true;
        self.warnings.push((
            key.clone(),
            format!(
                "the simulated body hides what other behaviours move on {}: no PoseController tracks them",
                names.join(", ")
            ),
        ));
    }

    /// Starts (or restarts with other parts) the simulation from where the body is.
    fn start(&mut self, skeleton: &Skeleton, kinematic: &Pose, parts: &[usize], now: f64) {
        let from = self.written.clone().unwrap_or_else(|| kinematic.clone());
        let before = self.sim.take();
        self.count_zmp(before.as_ref());
        match Simulation::new(skeleton, &from, parts, STEP) {
            Ok(mut sim) => {
                if let Some(b) = &before {
                    sim.carry_velocities(b.parts());
                }
                self.sim = Some(sim);
                self.clock = now;
            }
            Err(e) => {
                if let Some((k, _)) = self.active(now).first() {
                    self.warnings.push((k.clone(), e));
                }
            }
        }
    }

    /// What the running controllers ask of the joints, with the kinematic pose as the pose
    /// controller's target.
    fn drive(
        &self,
        sim: &Simulation,
        active: &[(UnitKey, ControllerUnit)],
        compounds: &[Compound],
        kinematic: &Pose,
        skeleton: &Skeleton,
    ) -> Drive {
        let mut drive = Drive::new(sim.humanoid().parts.len());
        for c in compounds {
            c.drive(sim, &mut drive);
        }
        for (_, u) in active.iter().filter(|(_, u)| u.compound.is_none()) {
            match u.class {
                "BalanceController" if !self.fallen => u.balance().drive(sim, &mut drive),
                "PoseController" => {
                    let k = u.value("stiffnessmultiplier");
                    let frames = sim.humanoid().frames(skeleton, kinematic);
                    let targets = (1..sim.humanoid().parts.len())
                        .filter(|&i| sim.is_physical(i))
                        .filter_map(|i| {
                            let p = sim.humanoid().parts[i].parent?;
                            let q = (frames[p].1.inverse() * frames[i].1).as_dquat();
                            Some((i, q.normalize(), 300.0 * k, 30.0 * k))
                        })
                        .collect();
                    PoseController { targets }.drive(sim, &mut drive);
                }
                _ => RagDoll.drive(sim, &mut drive),
            }
        }
        drive
    }

    /// Steps the simulation up to `now`, the kinematic pose interpolated from the last frame's.
    fn run(&mut self, now: f64, skeleton: &Skeleton, kinematic: &Pose) {
        let active = self.active(now);
        let (t0, p0) = self.last.clone().unwrap_or((now, kinematic.clone()));
        let mut sim = self.sim.take().expect("running");
        let balance = active.iter().find(|(_, u)| u.class == "BalanceController");
        // the feet are held while something stands the body; a rag doll alone lets them go
        if active.iter().all(|(_, u)| u.class == "RagDoll") {
            sim.let_go();
        }
        sim.reaction_gain = balance.map_or(1.0, |(_, u)| u.value("reactiongain"));
        if !self.unheld && !active.iter().any(|(_, u)| u.holds_the_legs()) {
            self.unheld = true;
            if let Some((key, u)) = active.first() {
                let name = u.compound.as_ref().map_or(u.class, |c| c.name.as_str());
                self.warnings.push((
                    key.clone(),
                    format!("{name} holds only its own joints: the legs and trunk are simulated with no controller and the body sinks; run it with a BalanceController"),
                ));
            }
        }
        // the compounds bound to this frame's simulated parts (the configuration covers their
        // required parts: binding cannot fail)
        let compounds: Vec<Compound> = (active.iter())
            .filter_map(|(_, u)| {
                u.compound
                    .as_ref()?
                    .bind(&sim, u.value("stiffnessmultiplier"))
                    .ok()
            })
            .collect();
        while self.clock + STEP <= now + 1e-9 {
            self.clock += STEP;
            let a = if now > t0 {
                ((self.clock - t0) / (now - t0)).clamp(0.0, 1.0)
            } else {
                1.0
            };
            let pose = blend(&p0, kinematic, a as f32);
            if let Some((key, u)) = balance {
                let b = u.balance();
                if !self.fallen && b.fallen(&sim) {
                    self.fallen = true;
                    sim.let_go();
                    let (c, _) = sim.centre_of_mass();
                    self.warnings.push((
                        key.clone(),
                        format!(
                            "the character fell at {:.3} s: its centre of mass ({:.2}, {:.2}) m left its feet; the balance controller lets go and the body falls as a rag doll",
                            self.clock, c.x, c.z
                        ),
                    ));
                }
            }
            let drive = self.drive(&sim, &active, &compounds, &pose, skeleton);
            sim.step(&pose, &drive);
        }
        self.sim = Some(sim);
    }
}

/// Whether `name` is one of the built-in controller classes (`BalanceController`, …), which a
/// compound definition may not take.
pub fn is_built_in_class(name: &str) -> bool {
    CLASSES.iter().any(|(class, _)| same_name(class, name))
}

/// `a` and `b` mixed: the root's place linearly, each rotation by slerp (`w` = 0: `a`).
fn blend(a: &Pose, b: &Pose, w: f32) -> Pose {
    let mut out = b.clone();
    out.root = a.root.lerp(b.root, w);
    for (o, (x, y)) in out
        .rotations
        .iter_mut()
        .zip(a.rotations.iter().zip(&b.rotations))
    {
        *o = x.slerp(*y, w);
    }
    out
}

impl Engine for PhysicalEngine {
    crate::units_persistent!("physical", Controller);

    fn add(&mut self, unit: Unit<'_>) -> Result<(), EngineError> {
        let BehaviourKind::Controller(c) = &unit.behaviour.kind else {
            return Err(EngineError(
                "the physical engine realizes bmlt:controller".into(),
            ));
        };
        let fail = |why: String| EngineError(format!("{}: {why}", unit.key));
        let found = CLASSES.iter().find(|(name, _)| same_name(name, &c.class));
        let compound = self.compounds.find(&c.class).cloned();
        let (class, defaults): (&'static str, &[(&str, f64)]) = match (found, &compound) {
            (Some((class, defaults)), _) => (class, defaults),
            (None, Some(_)) => (COMPOUND, &[("stiffnessmultiplier", 1.0)]),
            (None, None) => {
                let known: Vec<String> = (CLASSES.iter().map(|c| c.0.to_string()))
                    .chain(self.compounds.specs().iter().map(|s| s.name.clone()))
                    .collect();
                return Err(fail(format!(
                    "controller class '{}' is not known ({})",
                    c.class,
                    known.join(", ")
                )));
            }
        };
        let params = named_params(&c.class, defaults.iter().copied(), &c.params).map_err(fail)?;
        let compound = compound.map(Arc::new);
        self.units.add(
            unit,
            ControllerUnit {
                class,
                compound,
                params,
            },
        );
        Ok(())
    }

    fn as_motion(&mut self) -> Option<&mut dyn crate::engines::interface::Motion> {
        Some(self)
    }

    fn as_parameters(&mut self) -> Option<&mut dyn crate::engines::interface::Parameters> {
        Some(self)
    }

    fn as_physics(&mut self) -> Option<&mut dyn crate::engines::interface::Physics> {
        Some(self)
    }

    fn take_warnings(&mut self) -> Vec<(UnitKey, String)> {
        std::mem::take(&mut self.warnings)
    }
}

impl crate::engines::interface::Motion for PhysicalEngine {
    fn steers(&self, behaviour: &Behaviour, skeleton: &Skeleton) -> Option<Steering> {
        let BehaviourKind::Controller(c) = &behaviour.kind else {
            return None;
        };
        let parts: Vec<usize> = match self.compounds.find(&c.class) {
            Some(spec) => spec.parts(),
            None if same_name("RagDoll", &c.class) => WHOLE_BODY.to_vec(),
            None => LOWER_BODY.to_vec(),
        };
        let h = crate::character::dynamics::humanoid::Humanoid::new(skeleton).ok()?;
        let mut joints: Vec<usize> = (0..skeleton.len())
            .filter(|&j| h.part_of[j].is_some_and(|p| parts.contains(&p)))
            .collect();
        joints.sort_unstable();
        Some(Steering {
            joints,
            kind: MotionKind::Physical,
            additive: false,
        })
    }

    fn animate(&mut self, now: f64, skeleton: &Skeleton, _world: &World, pose: &mut Pose) {
        let active = self.active(now);
        if active.is_empty() {
            if let Some(sim) = self.sim.take() {
                self.count_zmp(Some(&sim));
                let [before, last] = std::mem::take(&mut self.offsets);
                self.release = last.map(|l| Release::new(&l, before.as_ref()));
                self.written = None;
            }
            self.fallen = false;
            self.unheld = false;
            self.hidden = false;
            self.last = Some((now, pose.clone()));
            if self.release.as_ref().is_some_and(|r| !r.apply(now, pose)) {
                self.release = None;
            }
            return;
        }
        let parts = self.configuration(&active, skeleton);
        let differs = self.sim.as_ref().is_none_or(|s| {
            (0..s.humanoid().parts.len()).any(|i| s.is_physical(i) != parts.contains(&i))
        });
        if differs {
            self.release = self.sim.as_ref().and_then(|s| self.handing_back(s, parts));
            self.start(skeleton, pose, parts, now);
        }
        if self.sim.is_none() {
            return;
        }
        let kinematic = pose.clone();
        self.warn_hidden(&active, skeleton, &kinematic);
        self.run(now, skeleton, &kinematic);
        if let Some(sim) = &self.sim {
            sim.write(pose);
        }
        if self.release.as_ref().is_some_and(|r| !r.apply(now, pose)) {
            self.release = None;
        }
        self.written = Some(pose.clone());
        let [_, last] = std::mem::take(&mut self.offsets);
        self.offsets = [last, Some(Offset::between(now, &kinematic, pose))];
        self.last = Some((now, kinematic));
    }
}

crate::units_named_params!(PhysicalEngine, "controller");

impl crate::engines::interface::Physics for PhysicalEngine {
    fn push(&mut self, part: &str, impulse: [f64; 3]) -> Result<(), String> {
        let impulse = DVec3::from_array(impulse);
        if !impulse.is_finite() {
            return Err(format!("an impulse of {impulse} N s is not a number"));
        }
        let Some(sim) = self.sim.as_mut() else {
            return Err("no body is simulated now (no controller runs)".into());
        };
        let Some(i) = sim.part_named(part) else {
            let names: Vec<&str> = sim.humanoid().parts.iter().map(|p| p.name).collect();
            return Err(format!("no body part '{part}' ({})", names.join(", ")));
        };
        if !sim.is_physical(i) {
            return Err(format!("the part '{part}' is not simulated now"));
        }
        sim.push(i, impulse);
        Ok(())
    }

    fn balance(&self) -> Result<crate::engines::interface::BalanceReading, String> {
        let Some(sim) = self.sim.as_ref() else {
            return Err("no body is simulated now (no controller runs)".into());
        };
        let (steps, outside) = sim.zmp_outside();
        let support = crate::character::dynamics::controllers::support_polygon(&sim.contacts());
        Ok(crate::engines::interface::BalanceReading {
            centre_of_mass: sim.centre_of_mass().0.to_array(),
            zero_moment_point: sim.zero_moment_point().map(|p| p.to_array()),
            support: support.iter().map(|p| p.to_array()).collect(),
            steps: self.zmp_before.0 + steps,
            zmp_outside: self.zmp_before.1 + outside,
        })
    }
}

mod release;

#[cfg(test)]
mod tests;
