//! `bml_realizer`: a realizer for the Behavior Markup Language (BML 1.0 with the BMLA/BMLT
//! continuous-interaction extensions) for virtual humans.
//!
//! Layers (see `docs/architecture.md`):
//! - [`bml`]: the language — typed model, parser, validation, constraint extraction, writer;
//! - [`feedback`]: BML 1.0 feedback messages and their XML and JSON-lines codecs;
//! - [`realizer`]: the facade a host embeds (submit BML, `tick`, frames and feedback);
//! - [`blocks`]: blocks at run time — lifecycle, composition, the event loop;
//! - [`schedule`]: the scheduler — constraints to sync times, order-invariant;
//! - [`plan`]: the flexible plan of pegs;
//! - [`engine`]: the engine interface, registry and timing models; [`engines`]: built-in engines;
//! - [`body`]: the skeleton (H-Anim), poses and forward kinematics;
//! - [`body`] and [`face`] know nothing of each other; [`character`] joins them: a character's
//!   frame assembled (lids following the eyes, the jaw opened by the mouth, limits, placement),
//!   the frames file, and skinned avatars (glTF/VRM, [`avatar`]) the motion is retargeted onto;
//! - [`clock`]: virtual and wall clocks;
//! - [`conformance`]: this realizer as a port of the RealizerTester suite (`realizer-tests`;
//!   feature `conformance`, on by default);
//! - [`timeline`]: timeline pictures (SVG) of plans and logs;
//! - [`world`]: named target points the host places.

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
