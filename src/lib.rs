//! `bml_realizer`: a realizer for the Behavior Markup Language (BML 1.0 with the BMLA/BMLT
//! continuous-interaction extensions) for virtual humans.
//!
//! Layers (see `docs/architecture.md`):
//! - [`bml`]: the language — typed model, parser, validation, constraint extraction, writer;
//! - [`feedback`]: BML 1.0 feedback messages and their XML and JSON-lines codecs;
//! - [`engine`]: what engines tell the scheduler (so far timing models and their defaults);
//! - [`plan`]: the flexible plan (so far the peg board);
//! - [`schedule`]: the scheduler (so far its difference-constraint solver).

#![warn(missing_docs)]

pub mod bml;
pub mod engine;
pub mod feedback;
pub mod plan;
pub mod schedule;
mod xmlname;

/// The README's code runs as a doc test, so that it stays true.
#[cfg(doctest)]
#[doc = include_str!("../README.md")]
pub struct ReadmeDoctests;
