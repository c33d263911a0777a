//! Scheduling: turns a parsed block and the engines' timing models into sync-point times.
//!
//! - [`strategy`]: the `SchedulingStrategy` trait and the schedule it produces;
//! - [`optimal`]: the default, order-invariant strategy;
//! - [`greedy`]: Elckerlyc's sorted greedy algorithm, the baseline;
//! - [`diff`]: the difference-constraint solver under it;
//! - [`check`]: what the scheduler would refuse, as diagnostics (`bmlr validate`);
//! - [`performable`]: the shortest phases a person can perform, and the phases a schedule
//!   squeezes below them.
//!
//! A schedule goes on the peg board in [`crate::planning::plan::to_pegs`].

pub mod check;
pub mod diff;
pub mod greedy;
mod links;
pub(crate) mod offsets;
pub mod optimal;
pub mod performable;
pub mod strategy;

pub use greedy::SortedGreedy;
pub use optimal::{LinearProgram, Optimal};
pub use strategy::{
    BlockSchedule, Dropped, ExternalTimes, NoExternal, ScheduleError, ScheduledBehaviour,
    SchedulingStrategy, SyncName,
};
