//! `bml_realizer`: a realizer for the Behavior Markup Language (BML 1.0 with the BMLA/BMLT
//! continuous-interaction extensions) for virtual humans.
//!
//! Where to start reading: [`realizer::Realizer`] is what a host holds (perform a block, `tick`
//! each frame, read frames and feedback); follow a block from there through [`language::bml`]
//! (text to a typed block), [`planning::schedule`] (its sync times), [`realizer::blocks`] (its
//! life at run time) and the [`engines`] that play it into a [`character`]'s body, face and
//! voice.
//!
//! The source is seven floors, in the order below; each uses only the floors before it (and
//! the small helpers at the root), which `docs/architecture.md` draws room by room:
//! - [`language`]: BML — the typed model of BML 1.0 with BMLA/BMLT, parser, validation,
//!   constraint extraction, writer ([`language::bml`]) — and BML 1.0 feedback with its XML and
//!   JSON-lines codecs ([`language::feedback`]);
//! - [`character`]: a virtual human — the H-Anim skeleton, poses, limits and kinematics
//!   ([`character::body`]), its physics for mixed dynamics ([`character::dynamics`]), FACS
//!   action units and ARKit blendshapes ([`character::face`]), text-to-speech, a speech's own
//!   sound and marks, streams and lip-sync ([`character::voice`]), what sounds in a frame
//!   ([`character::sound`]); above them the character whole: each frame's body and face joined,
//!   the frames file, skinned avatars (glTF/VRM, also at [`avatar`]);
//! - [`planning`]: timing models — what an engine tells the scheduler about a behaviour's syncs
//!   ([`planning::timing`]), the order-invariant scheduler ([`planning::schedule`]), the
//!   flexible plan of time pegs and anticipators ([`planning::plan`]);
//! - [`world`]: what the characters act in — the host's named points, points moving on keyed
//!   paths, where each character stands, and on the floor below the [`world::World`] that holds
//!   their shared state: the geometry of space ([`world::space`]: obstacles, routes), walking
//!   ([`world::locomotion`]), walkers sharing space ([`world::crowd`]), synthetic vision with
//!   memory ([`world::perception`]), PaT-Nets and behaviour nets ([`world::nets`]);
//! - [`engines`]: the engine interface, its capabilities and the registry
//!   ([`engines::interface`]) and the built-in engines (gesture, gaze, face, speech, keyframe,
//!   procedural, physical, locomotion…);
//! - [`realizer`]: the facade a host embeds, routing blocks to characters, with blocks at run
//!   time ([`realizer::blocks`]) and virtual and wall clocks ([`realizer::clock`]);
//! - [`ports`]: the realizer on MQTT or STOMP brokers with ipaaca's, AsapRealizer's and
//!   Greta's conventions (`ports::broker`, feature `broker`), as a port of the RealizerTester
//!   suite (`ports::conformance`, feature `conformance`), timeline pictures (SVG) of plans and
//!   logs ([`ports::timeline`]).
//!
//! At the root: [`rng`], the deterministic generator motion draws from.
//!
//! Until the next release the old paths (`bml_realizer::bml`, `::body`, `::engine`, …) still
//! compile as hidden re-exports; `CHANGELOG.md` lists where each went.

#![warn(missing_docs)]

pub mod language;

pub mod character;

pub mod planning;

pub mod world;

pub mod engines;

pub mod realizer;

pub mod ports;

mod data;
pub mod rng;
#[cfg(test)]
mod testrand;

pub use character::avatar;

// The paths before the floors, kept compiling for one release (see `CHANGELOG.md`).
#[doc(hidden)]
pub use character::{body, dynamics, face, sound, voice};
#[doc(hidden)]
pub use engines::interface as engine;
#[doc(hidden)]
pub use language::{bml, feedback};
#[doc(hidden)]
pub use planning::{plan, schedule, timing};
#[cfg(feature = "broker")]
#[doc(hidden)]
pub use ports::broker;
#[cfg(feature = "conformance")]
#[doc(hidden)]
pub use ports::conformance;
#[doc(hidden)]
pub use ports::timeline;
#[doc(hidden)]
pub use realizer::{blocks, clock};
#[doc(hidden)]
pub use world::{crowd, locomotion, nets, perception};

/// The README's code runs as a doc test, so that it stays true.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;

/// The embedding guide's code runs as a doc test too.
#[cfg(doctest)]
#[doc = include_str!("../docs/embedding.md")]
pub struct EmbeddingDoctests;

/// The engine guide's complete engine compiles and runs as a doc test.
#[cfg(doctest)]
#[doc = include_str!("../docs/engines.md")]
pub struct EngineGuideDoctests;
