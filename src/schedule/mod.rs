//! Scheduling: turns a parsed block and the engines' timing models into sync-point times.
//!
//! - [`strategy`]: the `SchedulingStrategy` trait and the schedule it produces;
//! - [`optimal`]: the default, order-invariant strategy;
//! - [`greedy`]: Elckerlyc's sorted greedy algorithm, the baseline;
//! - [`diff`]: the difference-constraint solver under it;
//! - [`check`]: what the scheduler would refuse, as diagnostics (`bmlr validate`);
//! - [`to_pegs`]: a schedule put on the peg board, and validity after run-time changes.

pub mod check;
pub mod diff;
pub mod greedy;
mod links;
mod offsets;
pub mod optimal;
pub mod strategy;
pub mod to_pegs;

pub use greedy::SortedGreedy;
pub use optimal::{LinearProgram, Optimal};
pub use strategy::{
    BlockSchedule, Dropped, ExternalTimes, NoExternal, ScheduleError, ScheduledBehaviour,
    SchedulingStrategy, SyncName,
};
