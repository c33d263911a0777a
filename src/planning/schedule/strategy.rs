//! What every scheduling strategy shares: the `SchedulingStrategy` trait, the schedule it
//! produces, the reasons it drops behaviours or fails a block, and the source of times for references
//! that leave the block.

use crate::language::bml::{Block, SyncPoint};
use crate::language::feedback::KnownWarning;
use crate::planning::timing::TimingModels;

/// A way of turning a block into sync times; strategies plug in from outside the core.
pub trait SchedulingStrategy: Send {
    /// A short name for logs and benches.
    fn name(&self) -> &'static str;

    /// Schedules `block` with the engines' timing `models`; times of references outside the block
    /// come from `external`.
    fn schedule(
        &self,
        block: &Block,
        models: &dyn TimingModels,
        external: &dyn ExternalTimes,
    ) -> Result<BlockSchedule, ScheduleError>;
}

/// Times of references that leave the block (other blocks' syncs, anticipators), block-local.
pub trait ExternalTimes {
    /// The block-local time of `point`, or `None` if it is unknown.
    fn time(&self, point: &SyncPoint) -> Option<f64>;

    /// Why the time of `point` is unknown, in a sentence (for the `NO_SUCH_TARGET` warning).
    fn why_unknown(&self, point: &SyncPoint) -> String {
        format!("the time of {point} is not known")
    }
}

/// No external references are known.
#[derive(Debug, Clone, Copy, Default)]
pub struct NoExternal;

impl ExternalTimes for NoExternal {
    fn time(&self, _: &SyncPoint) -> Option<f64> {
        None
    }
}

pub use crate::planning::timing::SyncName;

/// One behaviour's scheduled sync times (block-local seconds; a persistent end is infinite).
#[derive(Debug, Clone, PartialEq)]
pub struct ScheduledBehaviour {
    /// Behaviour id.
    pub id: crate::language::bml::Id,
    /// (sync id, time) in sync order. Standard sync names are static; a speech's inline syncs
    /// are owned.
    pub syncs: Vec<(SyncName, f64)>,
    /// Whether the behaviour's internal timing is fixed (TTS speech, audio): its syncs move together.
    pub rigid: bool,
}

impl ScheduledBehaviour {
    /// Time of sync `name`.
    pub fn time(&self, name: &str) -> Option<f64> {
        self.syncs.iter().find(|(s, _)| s == name).map(|(_, t)| *t)
    }
}

/// A behaviour left out of the schedule, with the warning to send.
#[derive(Debug, Clone, PartialEq)]
pub struct Dropped {
    /// Behaviour id.
    pub behaviour: crate::language::bml::Id,
    /// Warning type.
    pub warning: KnownWarning,
    /// Explanation, naming the constraints involved.
    pub reason: String,
    /// Whether it was dropped because constraints contradict each other (rather than for an
    /// unknown kind, sync point or external time).
    pub contradiction: bool,
}

/// The schedule of one block.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct BlockSchedule {
    /// Scheduled behaviours in document order.
    pub behaviours: Vec<ScheduledBehaviour>,
    /// Behaviours that could not be scheduled.
    pub dropped: Vec<Dropped>,
}

/// The furthest a scheduled time may lie from its block's start, seconds (about 31 years): a
/// behaviour timed further away could never be waited for.
pub const MAX_SCHEDULED_TIME: f64 = 1e9;

impl BlockSchedule {
    /// Moves every behaviour that could never run to `dropped` (INVALID_TIMING): one with a time
    /// that is not a number, or infinite (but for the `end` of a behaviour that `persistent`
    /// says runs until stopped), or further than [`MAX_SCHEDULED_TIME`] from the block start.
    /// Whatever a strategy computes, what is left can start and end.
    pub fn drop_unreachable(&mut self, persistent: impl Fn(&crate::language::bml::Id) -> bool) {
        let reachable = |b: &ScheduledBehaviour| {
            let last = b.syncs.len().saturating_sub(1);
            b.syncs.iter().enumerate().all(|(k, &(_, t))| {
                t.abs() <= MAX_SCHEDULED_TIME
                    || (k == last && t == f64::INFINITY && persistent(&b.id))
            })
        };
        let (keep, gone): (Vec<_>, Vec<_>) = std::mem::take(&mut self.behaviours)
            .into_iter()
            .partition(reachable);
        self.behaviours = keep;
        self.dropped.extend(gone.into_iter().map(|b| Dropped {
            reason: format!(
                "'{}' cannot be timed: its sync times are not numbers or lie further than {MAX_SCHEDULED_TIME} s from the block start",
                b.id
            ),
            behaviour: b.id,
            warning: KnownWarning::InvalidTiming,
            contradiction: false,
        }));
    }
}

impl BlockSchedule {
    /// The scheduled behaviour `id`.
    pub fn behaviour(&self, id: &str) -> Option<&ScheduledBehaviour> {
        self.behaviours.iter().find(|b| b.id == id)
    }

    /// Time of `behaviour:sync`.
    pub fn time(&self, behaviour: &str, sync: &str) -> Option<f64> {
        self.behaviour(behaviour).and_then(|b| b.time(sync))
    }
}

/// The whole block fails (a required behaviour or constraint cannot hold).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("block cannot be scheduled: {reason}")]
pub struct ScheduleError {
    /// Why, naming the constraints involved.
    pub reason: String,
    /// Whether required behaviours' constraints contradict each other (rather than a reference
    /// that cannot be resolved).
    pub contradiction: bool,
}
