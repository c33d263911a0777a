//! Procedural motion units from data: joint rotations and end-effector positions
//! given as expressions in the unit's canonical time α ∈ [0, 1] and named parameters, compiled
//! once (the expression language of [`super::expr`]) and evaluated every frame.
//!
//! A library file (`fixtures/procedural/units.json`, embedded as the default library) names each
//! unit with its keys (sync name → α), its preferred/min/max duration, default parameters,
//! per-joint rotations (`[z, x, y]` Euler degrees, as in BVH and the gesture lexicon) and
//! end effectors (wrist or ankle positions in metres, reached by analytic two-link IK):
//!
//! ```json
//! {"units": {"lift": {
//!   "parameters": {"height": 1.2},
//!   "keys": {"start": 0, "stroke": 0.5, "end": 1},
//!   "duration": {"preferred": 1.0, "min": 0.5, "max": 3.0},
//!   "rotations": {"r_wrist": ["0", "0", "20 * sin(pi * t)"]},
//!   "effectors": {"r_wrist": {"frame": "body", "position": ["-0.3", "height * t", "0.3"]}}
//! }}}
//! ```
//!
//! Expressions have arithmetic, comparisons, `&&`/`||`, `sin`, `cos`, `tan`, `asin`, …, `abs`,
//! `min`, `max`, `floor`, `pi` (or `pi()`), the unit's time as `t` or `alpha`, its parameters by
//! name, and the macros `if(c, a, b)`, `hermite(p0, p1, m0, m1, s)`, `tcb(p0, p1, p2, p3, tension,
//! continuity, bias, s)` (Kochanek–Bartels between `p1` and `p2`) and `perlin(x)` / `perlin(x,
//! seed)` (1-D gradient noise in [−1, 1], zero at integers).
//!
//! A unit may also declare a replacement `group` (of the running units of a group only the
//! one with the latest start plays, ties going to the earliest end; units of one block with the
//! same start and end leave one and a warning), that it is `additive` (its rotations add to
//! what the joints have: a layer, e.g. a sway over a posture), a `blend` time (it eases in
//! from what the joints have after its start and back out before its end; otherwise it replaces
//! the joints it sets) and a `release` time (it eases out only, over that time before its end:
//! it starts where a transition led the joints and still lets go of them by its end).
//!
//! Time is warped linearly between keys: at each key's scheduled time α is exactly the key's
//! α. Effector `frame` is `body` (the character's space, as [`Pose::world`] gives it) or `limb`
//! (relative to the limb's root joint: the shoulder for a wrist, the hip for an ankle). A mirrored
//! unit swaps left and right joints first, then reflects every rotation and position in the
//! body's mid-sagittal plane (x ↦ −x); mirroring twice gives the unit back.
//!
//! The [`ProceduralEngine`] realizes BMLT `procanimation` and `procanimationgesture` with units of
//! its library (by `name`, or by the stem of `fileName`), `<bmlt:parameter>` children overriding
//! the defaults; every parameter can change while the unit runs (`parametervaluechange`).
//!
//!
//! Longer than 600 lines on purpose: the library's file form, the unit built from it, its
//! evaluation each frame and the engine's parameters share the unit type and its expressions;
//! the expression language itself is `engines::expr`.

use std::collections::HashMap;
use std::sync::Arc;

use glam::{EulerRot, Quat, Vec3};
use indexmap::IndexMap;
use serde::Deserialize;

use crate::character::body::ik::{place_limb, LimbRoot, ARM_HINGE, ARM_POLE, LEG_HINGE, LEG_POLE};
use crate::character::body::{Pose, Skeleton};
use crate::engines::interface::{
    named_param, named_params, set_named_param, Engine, EngineError, Steering, SyncTimes, Unit,
    UnitKey, Units,
};
use crate::engines::motion::min_jerk;
use crate::language::bml::{Behaviour, BehaviourKind, Id, Param};
use crate::planning::timing::SyncName;
use crate::planning::timing::{Flexibility, SyncKey, TimingModel, MIN_DURATION};
use crate::world::World;

/// The embedded default library.
const DEFAULT: &str = include_str!("../../fixtures/procedural/units.json");

use super::expr::Expr;
pub use super::expr::{hermite, perlin, tcb};

/// Names expressions give a meaning of their own (parameters cannot take them).
const RESERVED: &[&str] = &["t", "alpha", "pi", "if", "hermite", "tcb", "perlin"];

/// What expressions can name: the unit's time (`t` or `alpha`) and its parameters.
struct Names<'a> {
    alpha: f64,
    params: &'a [(String, f64)],
}

impl Names<'_> {
    fn get(&self, name: &str) -> Option<f64> {
        match name {
            "t" | "alpha" => Some(self.alpha),
            _ => self.params.iter().find(|p| p.0 == name).map(|p| p.1),
        }
    }
}

/// Where an end effector's position is measured from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Frame {
    /// The character's space (as [`Pose::world`] gives it).
    Body,
    /// The limb's root joint (shoulder, hip), axes of the character's space.
    Limb,
}

#[derive(Debug)]
struct Effector {
    joint: String,
    frame: Frame,
    position: [Expr; 3],
}

/// A procedural unit from a library (see the module documentation).
#[derive(Debug)]
pub struct ProcUnit {
    /// Its name in the library.
    pub name: String,
    /// Default parameters, by name.
    pub params: Vec<(String, f64)>,
    /// (sync name, α), α increasing from 0 at `start` to 1 at `end`.
    pub keys: Vec<(Id, f64)>,
    /// Preferred, minimum and maximum duration (seconds).
    pub duration: (f64, f64, f64),
    /// Whether its rotations add to what the joints have (a layer) instead of replacing it.
    pub additive: bool,
    /// Seconds over which it blends in after its start and out before its end (0: none).
    pub blend: f64,
    /// Seconds over which it lets go before its end, where that is longer than `blend`: a unit
    /// that starts where the motion before it leads (a transition) but must end at rest.
    pub release: f64,
    /// Its replacement group: of the running units of a group, only the one with the
    /// latest start plays (ties: the earliest end).
    pub group: Option<String>,
    rotations: Vec<(String, [Expr; 3])>,
    effectors: Vec<Effector>,
}

/// A library file as written (see the module documentation); [`ProcUnit::from_file`] checks
/// what the types cannot.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LibraryFile {
    #[serde(default, rename = "description")]
    _description: crate::data::Note,
    units: IndexMap<String, UnitFile>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct UnitFile {
    #[serde(default)]
    parameters: IndexMap<String, f64>,
    /// Sync name → α, in time order.
    keys: IndexMap<String, f64>,
    duration: DurationFile,
    #[serde(default)]
    rotations: IndexMap<String, [ExprText; 3]>,
    #[serde(default)]
    effectors: IndexMap<String, EffectorFile>,
    #[serde(default)]
    additive: bool,
    #[serde(default)]
    blend: f64,
    #[serde(default)]
    release: f64,
    group: Option<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct DurationFile {
    preferred: f64,
    #[serde(default = "min_duration")]
    min: f64,
    #[serde(default = "unbounded")]
    max: f64,
}

fn min_duration() -> f64 {
    MIN_DURATION
}

fn unbounded() -> f64 {
    f64::INFINITY
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct EffectorFile {
    #[serde(default)]
    frame: FrameName,
    position: [ExprText; 3],
}

#[derive(Deserialize, Default, Clone, Copy)]
#[serde(rename_all = "lowercase")]
enum FrameName {
    #[default]
    Body,
    Limb,
}

/// An expression as written: text, or a plain number.
#[derive(Deserialize)]
#[serde(untagged)]
enum ExprText {
    Text(String),
    Number(f64),
}

fn three_exprs(e: &[ExprText; 3], what: &str) -> Result<[Expr; 3], String> {
    let one = |e: &ExprText| {
        match e {
            ExprText::Text(s) => Expr::compile(s),
            ExprText::Number(n) => Expr::compile(&n.to_string()),
        }
        .map_err(|e| format!("{what}: {e}"))
    };
    Ok([one(&e[0])?, one(&e[1])?, one(&e[2])?])
}

impl ProcUnit {
    /// The joints the unit rotates or moves an end effector of.
    pub fn joint_names(&self) -> impl Iterator<Item = &str> {
        let rotated = self.rotations.iter().map(|(j, _)| j.as_str());
        rotated.chain(self.effectors.iter().map(|e| e.joint.as_str()))
    }

    fn from_file(name: &str, u: UnitFile) -> Result<ProcUnit, String> {
        let at = |what: &str| format!("unit '{name}': {what}");
        let finite = |v: f64, what: &str| {
            if v.is_finite() {
                Ok(v)
            } else {
                Err(at(&format!("{what} must be a finite number")))
            }
        };
        let mut params = Vec::new();
        for (k, x) in u.parameters {
            if RESERVED.contains(&k.as_str()) {
                return Err(at(&format!(
                    "parameter '{k}' is a reserved name {RESERVED:?}"
                )));
            }
            params.push((k, x));
        }
        let keys: Vec<(Id, f64)> = u.keys.iter().map(|(k, &a)| (Id::new(k), a)).collect();
        let ordered = keys.windows(2).all(|w| w[1].1 >= w[0].1);
        let ends = keys.first().is_some_and(|k| k.0 == "start" && k.1 == 0.0)
            && keys.last().is_some_and(|k| k.0 == "end" && k.1 == 1.0);
        if !ordered || !ends || keys.len() < 2 {
            return Err(at(
                "keys must go from start at 0 to end at 1, α not decreasing",
            ));
        }
        let preferred = finite(u.duration.preferred, "duration.preferred")?;
        let (min, max) = (u.duration.min, u.duration.max);
        if !(min.max(MIN_DURATION) <= preferred && preferred <= max) {
            return Err(at("duration: min ≤ preferred ≤ max, all positive"));
        }
        let mut rotations = Vec::new();
        for (joint, e) in &u.rotations {
            let what = at(&format!("rotation of {joint}"));
            rotations.push((joint.clone(), three_exprs(e, &what)?));
        }
        let mut effectors = Vec::new();
        for (joint, e) in &u.effectors {
            let frame = match e.frame {
                FrameName::Body => Frame::Body,
                FrameName::Limb => Frame::Limb,
            };
            let position = three_exprs(&e.position, &at(&format!("effector {joint}")))?;
            effectors.push(Effector {
                joint: joint.clone(),
                frame,
                position,
            });
        }
        let additive = u.additive;
        let blend = finite(u.blend, "blend")?.max(0.0);
        let release = finite(u.release, "release")?.max(0.0);
        let group = u.group;
        let unit = ProcUnit {
            name: name.to_string(),
            params,
            keys,
            duration: (preferred, min.max(MIN_DURATION), max),
            additive,
            blend,
            release,
            group,
            rotations,
            effectors,
        };
        // every name an expression uses must be known: try both ends with the defaults
        for alpha in [0.0, 1.0] {
            unit.evaluate(alpha, &unit.params).map_err(|e| at(&e))?;
        }
        Ok(unit)
    }

    /// The joints it steers on `skeleton` (its rotated joints and each effector's limb),
    /// mirrored or not, sorted.
    pub fn joints(&self, skeleton: &Skeleton, mirrored: bool) -> Vec<usize> {
        let joints = skeleton.joints();
        let mut out: Vec<usize> = self
            .rotations
            .iter()
            .filter_map(|(j, _)| skeleton.joint_mirrored(j, mirrored))
            .collect();
        for f in &self.effectors {
            let Some(end) = skeleton.joint_mirrored(&f.joint, mirrored) else {
                continue;
            };
            out.push(end);
            if let Some(mid) = joints[end].parent {
                out.push(mid);
                out.extend(joints[mid].parent);
            }
        }
        out.sort_unstable();
        out.dedup();
        out
    }

    /// The steering of a unit played on `sides` (`false` as authored, `true` mirrored).
    pub fn steering(&self, skeleton: &Skeleton, sides: &[bool]) -> Steering {
        let mut joints: Vec<usize> = sides
            .iter()
            .flat_map(|&m| self.joints(skeleton, m))
            .collect();
        joints.sort_unstable();
        joints.dedup();
        Steering {
            joints,
            kind: crate::engines::interface::MotionKind::Kinematic,
            additive: self.additive,
        }
    }

    /// The timing model: keys at α × the preferred duration, stretchable within [min, max].
    pub fn timing(&self) -> TimingModel {
        let (preferred, min, max) = self.duration;
        TimingModel {
            keys: self
                .keys
                .iter()
                .map(|(name, alpha)| SyncKey::new(name.clone(), alpha * preferred))
                .collect(),
            flexibility: Flexibility::Stretchable {
                min_duration: min,
                max_duration: max,
            },
            persistent: false,
        }
    }

    /// Evaluates every expression at `alpha` with `params` (an error names the failing one).
    fn evaluate(&self, alpha: f64, params: &[(String, f64)]) -> Result<(), String> {
        let names = Names { alpha, params };
        for (_, e) in &self.rotations {
            three(e, &names)?;
        }
        for f in &self.effectors {
            three(&f.position, &names)?;
        }
        Ok(())
    }

    /// Checks parameter overrides against the unit's parameters.
    pub fn parameters(&self, overrides: &[Param]) -> Result<Vec<(String, f64)>, String> {
        named_params(
            &format!("unit '{}'", self.name),
            self.params.iter().cloned(),
            overrides,
        )
    }

    /// Its weight at global time `t` for a run from `start` to `end`: blending in after `start`
    /// over [`blend`](Self::blend) seconds and out before `end` over the longer of `blend` and
    /// [`release`](Self::release) (minimum jerk), else 1.
    pub fn weight(&self, start: f64, end: f64, t: f64) -> f32 {
        let ease = |span: f64, d: f64| if span > 0.0 { min_jerk(d / span) } else { 1.0 };
        let out = self.blend.max(self.release);
        ease(self.blend, t - start).min(ease(out, end - t)) as f32
    }

    /// Plays a run timed by `syncs` (its keys' global times) at `t` on `sides` (`false` as
    /// authored, `true` mirrored): nothing outside `start..=end` (the end frame shows α = 1),
    /// else α from the keys and the blend weight. Returns whether it was active. An
    /// expression that fails at run time (a division by zero) leaves the pose as it is: the
    /// parameters were checked when the unit was added and on every change.
    pub fn play(
        &self,
        syncs: &[(SyncName, f64)],
        t: f64,
        params: &[(String, f64)],
        sides: &[bool],
        skeleton: &Skeleton,
        pose: &mut Pose,
    ) -> bool {
        let (Some(start), Some(end)) = (syncs.first().map(|s| s.1), syncs.last().map(|s| s.1))
        else {
            return false;
        };
        if t < start || t > end {
            return false;
        }
        let (alpha, weight) = (alpha_at(&self.keys, syncs, t), self.weight(start, end, t));
        for &mirrored in sides {
            let _ = self.apply(alpha, params, mirrored, weight, skeleton, pose);
        }
        true
    }

    /// Applies the unit at `alpha` with `weight` to `pose`: rotations first, then effectors by
    /// IK. A weight below 1 slerps from what the joints have toward the unit's rotations (for an
    /// additive unit: from none of its rotation); `mirrored` swaps left and right and reflects in
    /// the mid-sagittal plane.
    pub fn apply(
        &self,
        alpha: f64,
        params: &[(String, f64)],
        mirrored: bool,
        weight: f32,
        skeleton: &Skeleton,
        pose: &mut Pose,
    ) -> Result<(), String> {
        if weight <= 0.0 {
            return Ok(()); // nothing of it shows (a pose blended fully out)
        }
        let blend = |from: Quat, to: Quat| {
            if weight >= 1.0 {
                to
            } else {
                from.slerp(to, weight.max(0.0)).normalize()
            }
        };
        let names = Names {
            alpha: alpha.clamp(0.0, 1.0),
            params,
        };
        for (joint, e) in &self.rotations {
            let [z, x, y] = three(e, &names)?;
            let q = Quat::from_euler(
                EulerRot::ZXY,
                z.to_radians() as f32,
                x.to_radians() as f32,
                y.to_radians() as f32,
            );
            let q = if mirrored { mirror_rotation(q) } else { q };
            if let Some(i) = skeleton.joint_mirrored(joint, mirrored) {
                if self.additive {
                    pose.rotate(i, blend(Quat::IDENTITY, q));
                } else {
                    pose.rotations[i] = blend(pose.rotations[i], q);
                }
            }
        }
        for f in &self.effectors {
            let p = three(&f.position, &names)?;
            let mut goal = Vec3::new(p[0] as f32, p[1] as f32, p[2] as f32);
            if mirrored {
                goal.x = -goal.x;
            }
            let Some(end) = skeleton.joint_mirrored(&f.joint, mirrored) else {
                continue;
            };
            if let Some(([root, mid], (r, m))) = reach(skeleton, pose, end, f.frame, goal) {
                pose.rotations[root] = blend(pose.rotations[root], r);
                pose.rotations[mid] = blend(pose.rotations[mid], m);
            }
        }
        Ok(())
    }
}

/// The values of three expressions.
fn three(e: &[Expr; 3], names: &Names) -> Result<[f64; 3], String> {
    let var = |name: &str| names.get(name);
    Ok([e[0].eval(&var)?, e[1].eval(&var)?, e[2].eval(&var)?])
}

pub use crate::character::body::skeleton::mirror_name;

/// A rotation reflected in the mid-sagittal (y-z) plane.
pub fn mirror_rotation(q: Quat) -> Quat {
    Quat::from_xyzw(q.x, -q.y, -q.z, q.w)
}

/// The limb joints and their local rotations that put end joint `name` (a wrist or an ankle) at
/// `goal` by two-link IK.
fn reach(
    skeleton: &Skeleton,
    pose: &Pose,
    end: usize,
    frame: Frame,
    goal: Vec3,
) -> Option<([usize; 2], (Quat, Quat))> {
    let joints = skeleton.joints();
    let name = &joints[end].name;
    let mid = joints[end].parent?;
    let root = joints[mid].parent?;
    let limb = LimbRoot::chain(skeleton, pose, root)?;
    let goal = match frame {
        Frame::Body => goal,
        Frame::Limb => limb.position + goal,
    };
    let (pole, hinge) = if name.contains("talocrural") || name.contains("ankle") {
        (LEG_POLE, LEG_HINGE)
    } else {
        (ARM_POLE, ARM_HINGE)
    };
    let rotations = place_limb(skeleton, limb, [root, mid, end], goal, pole, hinge)?;
    Some(([root, mid], rotations))
}

/// α at global time `t` for a unit whose keys are at `syncs` (linear warping between keys):
/// exactly each key's α at its time, monotone in between, clamped to [0, 1].
pub fn alpha_at(keys: &[(Id, f64)], syncs: &[(SyncName, f64)], t: f64) -> f64 {
    let mut prev: Option<(f64, f64)> = None;
    for (name, a) in keys {
        let Some(&(_, time)) = syncs.iter().find(|s| s.0 == *name) else {
            continue;
        };
        match prev {
            None if t <= time => return *a,
            Some((t0, a0)) if t <= time => {
                return if time > t0 {
                    a0 + (t - t0) / (time - t0) * (a - a0)
                } else {
                    *a
                };
            }
            _ => prev = Some((time, *a)),
        }
    }
    prev.map_or(0.0, |p| p.1)
}

/// Procedural units by name.
#[derive(Debug, Clone, Default)]
pub struct Library {
    units: HashMap<String, Arc<ProcUnit>>,
}

impl Library {
    /// The embedded default library.
    pub fn default_library() -> Library {
        static LIBRARY: std::sync::LazyLock<Library> = std::sync::LazyLock::new(|| {
            Library::from_json(DEFAULT).expect("the embedded procedural library is valid")
        });
        LIBRARY.clone()
    }

    /// Reads a library file: `{"units": {NAME: UNIT, …}}` (see the module documentation).
    pub fn from_json(text: &str) -> Result<Library, String> {
        let file: LibraryFile = crate::data::from_json(text)?;
        let mut units = HashMap::new();
        for (name, u) in file.units {
            let unit = ProcUnit::from_file(&name, u)?;
            units.insert(name, Arc::new(unit));
        }
        Ok(Library { units })
    }

    /// This library with the units of `other` added (a unit of the same name replaces this
    /// library's).
    pub fn extended(mut self, other: Library) -> Library {
        self.units.extend(other.units);
        self
    }

    /// Every unit, in no particular order.
    pub fn units(&self) -> impl Iterator<Item = &Arc<ProcUnit>> {
        self.units.values()
    }

    /// The unit called `name`.
    pub fn get(&self, name: &str) -> Option<&Arc<ProcUnit>> {
        self.units.get(name)
    }

    /// Unit names, sorted.
    pub fn names(&self) -> Vec<&str> {
        let mut n: Vec<&str> = self.units.keys().map(String::as_str).collect();
        n.sort_unstable();
        n
    }

    /// The unit a `procanimation` or `procanimationgesture` asks for (by `name`, else by the stem
    /// of `fileName`), with its parameters; `None` for other behaviours.
    fn for_behaviour(&self, b: &Behaviour) -> Option<Result<Running, String>> {
        let a = match &b.kind {
            BehaviourKind::ProcAnimation(a) | BehaviourKind::ProcAnimationGesture(a) => a,
            _ => return None,
        };
        let name = a.name.clone().or_else(|| {
            a.file_name.as_deref().map(|f| {
                let base = f.rsplit(['/', '\\']).next().unwrap_or(f);
                base.split('.').next().unwrap_or(base).to_string()
            })
        });
        let Some(name) = name else {
            return Some(Err("a procanimation needs a name or fileName".into()));
        };
        Some(match self.get(&name) {
            None => Err(format!(
                "no procedural unit '{name}' (the library has {:?})",
                self.names()
            )),
            Some(u) => u.parameters(&a.params).map(|params| Running {
                unit: u.clone(),
                params,
            }),
        })
    }
}

#[derive(Debug, Clone)]
struct Running {
    unit: Arc<ProcUnit>,
    params: Vec<(String, f64)>,
}

/// The procedural engine (see the module documentation).
#[derive(Debug)]
pub struct ProceduralEngine {
    library: Library,
    units: Units<Running>,
}

impl Default for ProceduralEngine {
    fn default() -> Self {
        ProceduralEngine::new(Library::default_library())
    }
}

impl ProceduralEngine {
    /// An engine playing the units of `library`.
    pub fn new(library: Library) -> Self {
        ProceduralEngine {
            library,
            units: Units::new(),
        }
    }
}

impl Engine for ProceduralEngine {
    crate::units_remove!();
    crate::units_retime_len!();
    crate::units_play!("procedural");
    crate::units_interrupt!(crate::engines::interface::stop_now);

    fn name(&self) -> &'static str {
        "procedural"
    }

    fn timing(&self, behaviour: &Behaviour) -> Option<TimingModel> {
        match self.library.for_behaviour(behaviour)? {
            Ok(r) => Some(r.unit.timing()),
            // refused with the reason when it starts
            Err(_) => Some(TimingModel::stretchable(&[("start", 0.0), ("end", 1.0)])),
        }
    }

    fn add(&mut self, unit: Unit<'_>) -> Result<(), EngineError> {
        let running = self
            .library
            .for_behaviour(unit.behaviour)
            .ok_or_else(|| EngineError("the procedural engine realizes bmlt:procanimation".into()))?
            .map_err(|e| EngineError(format!("{}: {e}", unit.key)))?;
        self.units.add(unit, running);
        Ok(())
    }

    fn as_motion(&mut self) -> Option<&mut dyn crate::engines::interface::Motion> {
        Some(self)
    }

    fn as_prediction(&mut self) -> Option<&mut dyn crate::engines::interface::Prediction> {
        Some(self)
    }

    fn as_parameters(&mut self) -> Option<&mut dyn crate::engines::interface::Parameters> {
        Some(self)
    }

    fn as_resources(&self) -> Option<&dyn crate::engines::interface::Resources> {
        Some(self)
    }
}

impl crate::engines::interface::Motion for ProceduralEngine {
    fn steers(&self, behaviour: &Behaviour, skeleton: &Skeleton) -> Option<Steering> {
        let r = self.library.for_behaviour(behaviour)?.ok()?;
        Some(r.unit.steering(skeleton, &[false]))
    }

    fn animate(&mut self, now: f64, skeleton: &Skeleton, world: &World, pose: &mut Pose) {
        crate::engines::interface::Prediction::predict(self, now, skeleton, world, pose);
    }
}

impl crate::engines::interface::Prediction for ProceduralEngine {
    fn predict(&self, now: f64, skeleton: &Skeleton, _world: &World, pose: &mut Pose) -> bool {
        // active from start to end; the end frame shows α = 1
        let active: Vec<(&SyncTimes, &Running, f64, f64)> = self
            .units
            .all()
            .filter_map(|(syncs, r)| {
                let (start, end) = (syncs.first()?.1, syncs.last()?.1);
                (start <= now && now <= end).then_some((syncs, r, start, end))
            })
            .collect();
        for (i, &(syncs, r, start, end)) in active.iter().enumerate() {
            // in a replacement group the latest start plays; ties go to the earliest end,
            // then to the unit added first
            let replaced = r.unit.group.as_ref().is_some_and(|g| {
                active.iter().enumerate().any(|(k, &(_, o, s, e))| {
                    k != i
                        && o.unit.group.as_ref() == Some(g)
                        && (s > start || (s == start && (e < end || (e == end && k < i))))
                })
            });
            if replaced {
                continue;
            }
            r.unit.play(syncs, now, &r.params, &[false], skeleton, pose);
        }
        !active.is_empty()
    }
}

impl crate::engines::interface::Parameters for ProceduralEngine {
    fn parameter(&self, key: &UnitKey, name: &str) -> Option<f64> {
        named_param(&self.units.get(key)?.params, name)
    }

    fn set_parameter(
        &mut self,
        key: &UnitKey,
        name: &str,
        value: f64,
        _now: f64,
    ) -> Result<Option<Vec<f64>>, EngineError> {
        let running = self.units.get_mut(key).map(|(_, r)| r);
        let owner = running
            .as_ref()
            .map_or(String::new(), |r| format!("unit '{}'", r.unit.name));
        set_named_param(key, &owner, running.map(|r| &mut r.params), name, value)
    }
}

impl crate::engines::interface::Resources for ProceduralEngine {
    fn exclusive_group(&self, behaviour: &Behaviour) -> Option<&str> {
        let name = match &behaviour.kind {
            BehaviourKind::ProcAnimation(a) | BehaviourKind::ProcAnimationGesture(a) => {
                a.name.as_deref()?
            }
            _ => return None,
        };
        self.library.get(name)?.group.as_deref()
    }
}

#[cfg(test)]
mod tests;
