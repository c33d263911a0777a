//! The `Optimal` scheduling strategy for one block. Every constraint kind is honoured, behaviours
//! keep their preferred timing as far as the constraints allow, ungrounded clusters start as early
//! as possible, and the result does not depend on the order of behaviours in the block.
//!
//! 1. Feasibility: every sync key becomes a variable of a difference system (explicit constraints,
//!    sync order, duration bounds, phase limits, rigid internal timing, nothing before block
//!    start). A contradictory cycle names the constraints in conflict; a behaviour involved that
//!    is not required is dropped and the rest tried again. If only required behaviours are
//!    involved, the block fails.
//! 2. Fast path: with every behaviour at its preferred timing (one variable per behaviour), the least
//!    solution of the difference system, if there is one, has zero deviation and the earliest starts.
//!    No LP is needed.
//! 3. Second fast path: if the `at` constraints fix the distances between the constrained keys of
//!    every behaviour constrained at two or more keys, the deviation splits into one term per
//!    behaviour; each such behaviour takes its own best timing and everything else keeps its
//!    preferred timing. Taken only where that is provably the linear program's answer (each best
//!    timing unique, every bound kept); `LinearProgram` is the same strategy without fast paths,
//!    to check them against.
//! 4. Otherwise a linear program (good_lp + microlp) first minimises the total deviation from
//!    preferred timing, measured as stretch `|σ − 1| · duration` plus non-uniformity
//!    `2 · Σ |phase − σ · preferred phase|` (a persistent behaviour's at a thousandth: it has no
//!    length of its own to keep). It then minimises the sum of all sync times with the deviation
//!    kept at that minimum. The program is built in a canonical order (behaviours sorted by id), so the
//!    same block in any order gives the same program and the same answer.
//! 5. Whichever step answered, the keys between two constrained keys of a stretchable behaviour
//!    are spaced in proportion to their preferred timing (thesis §8.3.2), which the deviation
//!    leaves open.
//!
//! Each step is a module of its own: `feasible` (1), `fast` (2, 3), `program` (4), `spread` (5).

use super::diff::{DiffSystem, EPSILON};
use super::links::{self, is_required, items, resolve_all, scheduled, IdIndex, Item, Link, Term};
use super::offsets::Offsets;
use super::strategy::{
    BlockSchedule, Dropped, ExternalTimes, ScheduleError, SchedulingStrategy, MAX_SCHEDULED_TIME,
};
use crate::language::bml::{extract, Block, Constraint, Relation};
use crate::language::feedback::KnownWarning;
use crate::planning::timing::{Flexibility, TimingModels, MIN_DURATION};

/// Cost of one second of non-uniform phase change relative to one second of uniform stretch: above
/// 1, so a behaviour that must change length stretches all its phases alike (as Elckerlyc's
/// linear stretch does) instead of putting the change into one phase.
pub const NON_UNIFORM_WEIGHT: f64 = 2.0;

/// Weight of a persistent behaviour's deviation (a physical controller, noise) against everyone
/// else's. Such a behaviour has no length of its own: its nominal second only places an end that
/// a constraint names without fixing it (`start="c:end"`). Counted in full, tying its end to a
/// gesture's (`end="g:end"`) made stretching the controller cost as much as squeezing the gesture,
/// and the tie went to the earlier times: the gesture squeezed into the controller's second.
pub const PERSISTENT_WEIGHT: f64 = 1e-3;

/// The optimal strategy (see the module documentation).
#[derive(Debug, Clone, Copy, Default)]
pub struct Optimal;

/// [`Optimal`] without its fast paths: every block that needs any behaviour to stretch goes
/// through the linear program. The same answers, slower; a reference to check the fast paths by.
#[derive(Debug, Clone, Copy, Default)]
pub struct LinearProgram;

/// What tells the two optimal strategies apart: their name and whether the fast paths may
/// answer. Both schedule through [`schedule`].
trait Paths {
    const NAME: &'static str;
    const FAST: bool;
}

impl Paths for Optimal {
    const NAME: &'static str = "optimal";
    const FAST: bool = true;
}

impl Paths for LinearProgram {
    const NAME: &'static str = "linear-program";
    const FAST: bool = false;
}

impl<T: Paths + Send> SchedulingStrategy for T {
    fn name(&self) -> &'static str {
        T::NAME
    }

    fn schedule(
        &self,
        block: &Block,
        models: &dyn TimingModels,
        external: &dyn ExternalTimes,
    ) -> Result<BlockSchedule, ScheduleError> {
        schedule(block, models, external, T::FAST)
    }
}

/// The optimal schedule of `block`; `fast` allows the fast paths.
fn schedule(
    block: &Block,
    models: &dyn TimingModels,
    external: &dyn ExternalTimes,
    fast: bool,
) -> Result<BlockSchedule, ScheduleError> {
    {
        let mut dropped = Vec::new();
        let constraints = extract(block);
        let mut items = items(block, models, &constraints, &mut dropped);
        loop {
            let links = resolve_all(block, &mut items, &constraints, external, &mut dropped)?;
            // a fast-path answer satisfies every hard constraint, so feasibility is only checked
            // (and conflicts only resolved) when neither fast path applies
            let shortcut = if fast {
                preferred(&items, &links).or_else(|| separable(&items, &links))
            } else {
                None
            };
            let times = match shortcut {
                Some(times) => times,
                None => match feasible(&items, &links, &constraints) {
                    Ok(()) => optimise(&items, &links),
                    Err(involved) => {
                        drop_one(block, &mut items, &involved, &constraints, &mut dropped)?;
                        continue;
                    }
                },
            };
            let mut times = times;
            spread_between_anchors(&items, &links, &mut times);
            // `times` holds each item's key times one item after the other; the results go into
            // a list of their own (collecting in place would shrink the items' allocation)
            let mut rest = times.as_slice();
            let mut behaviours = Vec::with_capacity(items.len());
            for it in items {
                let (t, after) = rest.split_at(it.len);
                rest = after;
                behaviours.push(scheduled(it, t, 0.0));
            }
            // document order (nothing to sort for one behaviour)
            if behaviours.len() > 1 {
                let mut pos = IdIndex::default();
                pos.fill(block.behaviours.iter().map(|b| b.id.as_str()));
                behaviours.sort_by_cached_key(|b| pos.get(&b.id).unwrap_or(usize::MAX));
            }
            return Ok(BlockSchedule {
                behaviours,
                dropped,
            });
        }
    }
}

mod fast;
mod feasible;
mod program;
mod spread;
use fast::{anchored_keys, preferred, separable};
use feasible::{drop_one, feasible, hard_system};
use program::optimise;
use spread::{spread_between_anchors, uniform_phases};

#[cfg(test)]
mod tests;
