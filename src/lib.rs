//! `bml_realizer`: a realizer for the Behavior Markup Language (BML 1.0 with the BMLA/BMLT
//! continuous-interaction extensions) for virtual humans.
//!
//! Where to start reading: [`realizer::Realizer`] is what a host holds (perform a block, `tick`
//! each frame, read frames and feedback); follow a block from there through [`bml`] (text to a
//! typed block), [`schedule`] (its sync times), [`blocks`] (its life at run time) and the
//! [`engines`] that play it into a [`body`], a [`face`] and a [`voice`].
//!
//! Every public module, from the language up (see `docs/architecture.md` for the layers and
//! what each may use):
//! - [`bml`]: the language — typed model of BML 1.0 with BMLA/BMLT, parser, validation,
//!   constraint extraction, writer;
//! - [`feedback`]: BML 1.0 feedback messages, listeners, and their XML and JSON-lines codecs;
//! - [`timing`]: timing models — what an engine tells the scheduler about a behaviour's syncs;
//! - [`schedule`]: the scheduler — constraints and timing models to sync times, order-invariant;
//! - [`plan`]: the flexible plan — the peg board, schedules on it, anticipators;
//! - [`clock`]: virtual and wall clocks; [`rng`]: the deterministic generator motion draws from;
//! - [`body`]: the H-Anim skeleton, poses, forward kinematics, BVH/glTF export, the frames file;
//! - [`face`]: FACS action units, their mixing and the ARKit blendshapes they drive;
//! - [`voice`]: text-to-speech (built-in, flite, espeak-ng), a speech's own sound and marks,
//!   streams, lip-sync; [`sound`]: what plays in a frame and the mix of a run;
//! - [`dynamics`]: inverse/forward dynamics and balance for mixed dynamics;
//! - [`character`]: a character as a whole — body and face joined each frame, skinned avatars
//!   (glTF/VRM, re-exported as [`avatar`]) the motion is retargeted onto;
//! - [`world`]: what the characters act in — the host's named points, points moving on keyed
//!   paths, where each character stands with its radius, avatar and steering combiner,
//!   obstacles, groups and the crowd's shared state, character profiles, vision and what each
//!   character has seen, and the variables the nets read;
//! - [`locomotion`]: walking — steering, paths round obstacles, the walker's gait and footsteps;
//! - [`crowd`]: walkers that share space — avoidance, negotiation, contact, crowd scenes and
//!   their quality measures;
//! - [`perception`]: synthetic vision with memory; [`nets`]: PaT-Nets that sequence behaviour by
//!   watching the world;
//! - [`engine`]: the engine interface, its capabilities and the registry; [`engines`]: the
//!   built-in engines (gesture, gaze, face, speech, keyframe, procedural, physical, locomotion…);
//! - [`blocks`]: blocks at run time for one character — lifecycle, composition, the event loop;
//! - [`realizer`]: the facade a host embeds, routing blocks to characters;
//! - [`broker`]: the realizer on MQTT or STOMP brokers, with ipaaca's, AsapRealizer's and
//!   Greta's conventions (feature `broker`);
//! - [`conformance`]: this realizer as a port of the RealizerTester suite (feature
//!   `conformance`); [`timeline`]: timeline pictures (SVG) of plans and logs.
//!
//! The order above is the intended one; a few arrows still run against it (crowd and nets use
//! locomotion's obstacles and paths, which sit above them), listed in `docs/architecture.md`.

#![warn(missing_docs)]

pub use character::avatar;
pub mod blocks;
pub mod bml;
pub mod body;
#[cfg(feature = "broker")]
pub mod broker;
pub mod character;
pub mod clock;
#[cfg(feature = "conformance")]
pub mod conformance;
pub mod crowd;
mod data;
pub mod dynamics;
pub mod engine;
pub mod engines;
pub mod face;
pub mod feedback;
pub mod locomotion;
pub mod nets;
pub mod perception;
pub mod plan;
pub mod realizer;
pub mod rng;
pub mod schedule;
pub mod sound;
pub mod space;
#[cfg(test)]
mod testrand;
pub mod timeline;
pub mod timing;
pub mod voice;
pub mod world;
mod xmlname;

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
