//! What only some engines do, one trait per capability: moving the body ([`Motion`]), taking
//! part in animation prediction ([`Prediction`]), parameters that change while a unit runs
//! ([`Parameters`]), body resources and exclusive groups ([`Resources`]), actions on the plan
//! ([`Control`]), moving about the world ([`Travel`]) and looking at whom the walk attends to
//! ([`Attend`]), sound streamed in by the host ([`Streams`]), speaking ([`Speaking`]). An engine offers one by returning itself from the matching `as_…` method of
//! [`Engine`](super::Engine).

use super::{EngineError, ParameterChange, UnitKey};
use crate::character::body::{Pose, Skeleton};
use crate::language::bml::Behaviour;
use crate::world::World;

/// An engine that moves the body.
pub trait Motion {
    /// Applies the units running at `now` to `pose` (joint rotations on top of what earlier
    /// engines set), with targets from `world`.
    fn animate(&mut self, now: f64, skeleton: &Skeleton, world: &World, pose: &mut Pose);

    /// The joints a unit for `behaviour` steers on `skeleton`, how, and whether additively;
    /// `None` for behaviours that move no joints.
    fn steers(&self, behaviour: &Behaviour, skeleton: &Skeleton) -> Option<Steering>;
}

/// An engine that moves the face: it raises action units and blendshapes of the frame's face
/// (sources combine by maximum; see `face::mixer`).
pub trait Expression {
    /// Shows the units running at `now` on `face`.
    fn express(&mut self, now: f64, face: &mut crate::character::face::Face);
}

/// An engine that plays sound the host streams in (`voice::stream`): it is handed every stream
/// the host opens, and plays the behaviours that name one.
pub trait Streams {
    /// Takes `stream` (a handle shared with the host).
    fn add_stream(&mut self, stream: crate::character::voice::stream::AudioStream);
}

/// An engine that speaks: the idle layer's eyes look away as an utterance begins
/// (`character::body::aversion`).
pub trait Speaking {
    /// Of the utterances being said at `now`, the one that began last.
    fn utterance(&self, now: f64) -> Option<crate::character::body::aversion::Utterance>;
}

/// An engine that makes sound (synthesized speech, audio clips).
pub trait Sound {
    /// Appends what plays at `now` to `out`.
    fn sounds(&self, now: f64, out: &mut Vec<crate::character::sound::Playing>);
}

/// An engine's part in animation prediction: predictable engines say what they will have set
/// at a future time; others (a transition) ask for those predicted poses.
pub trait Prediction {
    /// Writes what this engine's *predictable* units (whose motion is a function of time
    /// alone, such as keyframes and procedural units) will have set at global time `t` into
    /// `pose`, without changing any state. Returns whether any of its units is running then.
    fn predict(&self, _t: f64, _skeleton: &Skeleton, _world: &World, _pose: &mut Pose) -> bool {
        false
    }

    /// Global times at which this engine needs the predicted pose for its frame at `now` (a
    /// transition's end); the runtime then calls [`predicted`](Prediction::predicted) before
    /// [`Motion::animate`].
    fn prediction_times(&self, _now: f64) -> Vec<f64> {
        Vec::new()
    }

    /// The predicted poses (rest pose plus every engine's [`predict`](Prediction::predict)) at
    /// the times [`prediction_times`](Prediction::prediction_times) asked for.
    fn predicted(&mut self, _poses: Vec<(f64, Pose)>) {}
}

/// An engine whose units have parameters that can be read and changed while they run (BMLA
/// `parametervaluechange`).
pub trait Parameters {
    /// Current value of parameter `name` of unit `key`.
    fn parameter(&self, key: &UnitKey, name: &str) -> Option<f64>;

    /// Sets parameter `name` of a running unit at global time `now`. A parameter that changes
    /// timing (a speech's `rate`) returns the unit's new sync times (as for
    /// [`Engine::interrupt`](super::Engine::interrupt)); others return `None`.
    fn set_parameter(
        &mut self,
        key: &UnitKey,
        name: &str,
        value: f64,
        now: f64,
    ) -> Result<Option<Vec<f64>>, EngineError>;
}

/// An engine whose behaviours occupy parts of the body or exclude each other.
pub trait Resources {
    /// Behaviours of the same exclusive group cannot run at once (gaze, posture; the
    /// replacement groups of procedural units).
    fn exclusive_group(&self, _behaviour: &Behaviour) -> Option<&str> {
        None
    }

    /// Body resources the behaviour occupies (e.g. `left_hand`, `voice`): a chunked block
    /// co-articulates with the block before it where they share one (the earlier behaviour skips
    /// the rest of its retraction).
    fn resources(&self, _behaviour: &Behaviour) -> &'static [&'static str] {
        &[]
    }
}

/// An engine of control behaviours: it acts on the plan when its units' syncs pass.
pub trait Control {
    /// The sync point `sync` of `key` passed at global time `time`; push what follows to
    /// `actions`.
    fn sync_passed(&mut self, key: &UnitKey, sync: &str, time: f64, actions: &mut Vec<Action>);
}

/// An engine that simulates the body (mixed dynamics): the host can push it and read how it
/// stands.
pub trait Physics {
    /// Pushes the simulated body part `part` (a body part of the physical humanoid, such as
    /// `sacroiliac` or `l_thigh`, or a skeleton joint, meaning the part it moves with) with
    /// `impulse` (N s, world frame). `Err` says why nothing was pushed: no simulated body now,
    /// an unknown part, a part not simulated, an impulse that is not finite.
    fn push(&mut self, part: &str, impulse: [f64; 3]) -> Result<(), String>;

    /// How the simulated body stands now; `Err` says why there is no reading (no body is
    /// simulated now).
    fn balance(&self) -> Result<BalanceReading, String>;
}

/// An engine that moves the whole character about the world (locomotion): it steps the
/// character's body to each frame's time before that frame's sync points pass, so that the sync
/// points of its units can follow what really happens (a walker that arrives later than
/// predicted moves its `end`, and what hangs on it follows).
pub trait Travel {
    /// Moves character `id` on to global time `now` in `world` (the shared world, world
    /// frame), from where it stood (`at`; a host that placed it elsewhere moves it there).
    /// Returns where it stands now.
    fn travel(
        &mut self,
        now: f64,
        world: &std::sync::Arc<World>,
        id: &str,
        at: crate::world::Placement,
    ) -> crate::world::Placement;

    /// Whether a foot of the character is on the ground (left, right), for the frames.
    fn contacts(&self) -> Option<[bool; 2]> {
        None
    }

    /// Whether the character is on the move (others then see it on the crowd's grid of times).
    fn moving(&self) -> bool {
        false
    }

    /// Whether the character is on a walk of its own (going somewhere: if it stands still
    /// now, it waits; it does not stand there for good).
    fn on_its_way(&self) -> bool {
        false
    }

    /// Whether the character is off its place to make room for someone (stepping aside,
    /// standing aside or going back): it goes back, it does not stand there for good.
    fn making_room(&self) -> bool {
        false
    }

    /// Where the person stands whom the character, held back, asks to make room (world x, z),
    /// if it asks anyone (`crowd::negotiate`).
    fn asking(&self) -> Option<glam::Vec2> {
        None
    }

    /// The narrow door the character's walk goes through next, if one is near, and how
    /// (`crowd::doorway`): the realizer decides the turns at doors from these.
    fn passing(&self) -> Option<crate::world::crowd::doorway::Passing> {
        None
    }

    /// The way the character's walk goes now (world x, z, unit), if it walks among others:
    /// others see one standing in a press as still going that way.
    fn heading(&self) -> Option<glam::Vec2> {
        None
    }

    /// Whom the character attends to as it moves (the one it asks for room, the walker it
    /// makes room for): where they stand (world x, z) and how much (0 to 1, eased). Engines that
    /// [`Attend`] look there.
    fn attending(&self) -> Option<(glam::Vec2, f32)> {
        None
    }
}

/// Someone the character attends to: where their eyes are in the character's own frame (the
/// origin facing +z), and how much it attends (0 to 1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Attention {
    /// Their eyes, in the character's frame (m).
    pub at: glam::Vec3,
    /// How much it attends (0 to 1).
    pub weight: f32,
}

/// An engine that looks at whom the character attends to ([`Travel::attending`]) when nothing
/// else directs its gaze: the gaze engine, under any running BML gaze.
pub trait Attend {
    /// Whom the character attends to this frame, if anyone (called before the frame's
    /// [`Motion::animate`]).
    fn attend(&mut self, cue: Option<Attention>);
}

/// An engine that revises the sync times of its units while they run, from what happens (a
/// walker arrives later than predicted; a streamed speech's words come in with its sound). Its
/// engine says which behaviours with [`Engine::self_timed`](super::Engine::self_timed).
pub trait Revising {
    /// Units whose sync times changed since last asked, at global time `now`: the unit and the
    /// new global times of all its syncs in sync order (passed syncs as they were). A sync that
    /// happened has its real time; one still ahead is a prediction later than `now`.
    fn take_revisions(&mut self, now: f64) -> Vec<Revision>;
}

/// New sync times for a unit of a [`Revising`] engine.
#[derive(Debug, Clone, PartialEq)]
pub struct Revision {
    /// The unit.
    pub unit: UnitKey,
    /// The global times of all its syncs, in sync order.
    pub times: Vec<f64>,
    /// Whether behaviours tied to its syncs follow (false for an interrupted unit, whose new
    /// times concern only itself).
    pub others_follow: bool,
}

/// How a simulated body stands, for hosts and planners that judge balance (world frame, m).
#[derive(Debug, Clone, PartialEq)]
pub struct BalanceReading {
    /// The whole body's centre of mass.
    pub centre_of_mass: [f64; 3],
    /// The zero-moment point on the ground: where the ground's push must act to balance
    /// gravity and the body's accelerations (`None` while nothing presses on the ground).
    pub zero_moment_point: Option<[f64; 3]>,
    /// The support polygon: the convex hull of the sole corners on the ground, as (x, z),
    /// counter-clockwise (empty when no foot stands).
    pub support: Vec<[f64; 2]>,
    /// Physics steps simulated for this character so far.
    pub steps: usize,
    /// Of those, the steps that ended with the zero-moment point outside the support polygon
    /// while a foot stood: moments where the feet, had they not been held, would have rolled
    /// over an edge.
    pub zmp_outside: usize,
}

/// How a motion unit moves its joints.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MotionKind {
    /// It sets or changes joint rotations directly.
    Kinematic,
    /// It applies torques to a physically simulated body (mixed dynamics).
    Physical,
}

/// What a motion unit steers: its joints, how, and whether it layers over other units.
#[derive(Debug, Clone, PartialEq)]
pub struct Steering {
    /// Joints whose rotation it sets or changes (the root joint also for its translation), in
    /// the skeleton's joint order.
    pub joints: Vec<usize>,
    /// Kinematic or physical.
    pub kind: MotionKind,
    /// Whether it adds to what other units set (a layer) rather than replacing it.
    pub additive: bool,
}

impl Steering {
    /// Kinematic steering of the joints of `skeleton` named `names` (unknown names are left out).
    pub fn kinematic<'a>(
        skeleton: &Skeleton,
        names: impl IntoIterator<Item = &'a str>,
        additive: bool,
    ) -> Steering {
        let mut joints: Vec<usize> = names
            .into_iter()
            .filter_map(|n| skeleton.joint(n))
            .collect();
        joints.sort_unstable();
        joints.dedup();
        Steering {
            joints,
            kind: MotionKind::Kinematic,
            additive,
        }
    }
}

/// What a control engine asks the runtime to do (control behaviours act on blocks and other engines).
#[derive(Debug, Clone, PartialEq)]
pub enum Action {
    /// Interrupt behaviours of block `target`: those in `include` (all if empty) except `exclude`.
    Interrupt {
        /// The behaviour asking (for warnings).
        by: UnitKey,
        /// Block to interrupt.
        target: String,
        /// Behaviours to interrupt (empty: all).
        include: Vec<String>,
        /// Behaviours to spare.
        exclude: Vec<String>,
    },
    /// Activate the pre-planned block `target`.
    Activate {
        /// The behaviour asking (for warnings).
        by: UnitKey,
        /// Block to activate.
        target: String,
    },
    /// Change a parameter of another behaviour over time.
    ChangeParameter(ParameterChange),
}
