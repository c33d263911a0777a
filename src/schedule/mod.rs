//! Scheduling: turns a parsed block and the engines' timing models into sync-point times.
//!
//! Today this holds the difference-constraint solver the strategies build on ([`diff`]); the peg
//! plan, timing models and strategies of issue #3 come next.

pub mod diff;
pub mod optimal;
