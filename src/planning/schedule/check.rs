//! The timing check behind `bmlr validate`: what the scheduler would refuse in a block, as
//! diagnostics. The block is scheduled with `Optimal` and the given timing models; each behaviour
//! it would drop because its constraints contradict each other (or stretch it beyond its bounds)
//! becomes an error at that behaviour, naming the constraints, and so does a required block that
//! cannot be scheduled at all; a behaviour whose phases the schedule squeezes below what a person
//! can perform becomes a warning. References to other blocks and anticipators are not known here:
//! behaviours that use them are left out of the check, not reported.

use super::optimal::Optimal;
use super::performable::squeezed;
use super::strategy::{NoExternal, SchedulingStrategy};
use crate::language::bml::{Block, Code, Diagnostic};
use crate::planning::timing::TimingModels;

/// Errors for the constraints of `block` that no timing satisfies.
pub fn timing_diagnostics(block: &Block, models: &dyn TimingModels) -> Vec<Diagnostic> {
    let error =
        |pos, message: String| Diagnostic::error(Code::ContradictoryConstraints, pos, message);
    match Optimal.schedule(block, models, &NoExternal) {
        Err(e) if e.contradiction => {
            vec![error(
                block.pos,
                format!("the block cannot be scheduled: {}", e.reason),
            )]
        }
        Err(_) => Vec::new(),
        Ok(schedule) => {
            let pos = |id: &crate::language::bml::Id| {
                (block.behaviours.iter())
                    .find(|b| b.id == *id)
                    .map_or(block.pos, |b| b.pos)
            };
            let refused = (schedule.dropped.iter())
                .filter(|d| d.contradiction)
                .map(|d| {
                    error(
                        pos(&d.behaviour),
                        format!("refused at run time: {}", d.reason),
                    )
                });
            let squeezed = squeezed(block, &schedule)
                .into_iter()
                .map(|s| Diagnostic::warning(Code::SqueezedPhase, pos(&s.behaviour), s.sentence()));
            refused.chain(squeezed).collect()
        }
    }
}
