//! What a run's exit code says: 0 when every block was parsed and scheduled whole; 1 when a
//! block could not be parsed, or when one of its behaviours (or the whole block) was dropped
//! because its constraints cannot all hold (`CANNOT_SATISFY_CONSTRAINTS`) — the blocks
//! `bmlr validate` calls invalid. The run itself goes on in both cases, as the realizer does.

use std::collections::BTreeSet;
use std::process::ExitCode;

use bml_realizer::language::feedback::{Feedback, KnownWarning, WarningType};

/// Counts of what went wrong in a run.
#[derive(Debug, Default)]
pub struct Outcome {
    /// Blocks (or input lines) that could not be parsed.
    pub unparsed: usize,
    /// Blocks with behaviours dropped for constraints that cannot all hold.
    pub unscheduled: BTreeSet<String>,
}

impl Outcome {
    /// Notes the blocks that `feedback` says could not be scheduled whole.
    pub fn note(&mut self, feedback: &[Feedback]) {
        for f in feedback {
            if let Feedback::Warning(w) = f {
                if w.kind == WarningType::Known(KnownWarning::CannotSatisfyConstraints) {
                    let block = w.id.split(':').next().unwrap_or(&w.id);
                    self.unscheduled.insert(block.to_string());
                }
            }
        }
    }

    /// Success, or exit 1 after a line on stderr for each kind of failure.
    pub fn exit(&self, command: &str) -> ExitCode {
        let blocks = |n: usize| format!("{n} block{}", if n == 1 { "" } else { "s" });
        if self.unparsed > 0 {
            let n = blocks(self.unparsed);
            eprintln!("bmlr {command}: {n} could not be parsed (see the warnings)");
        }
        if !self.unscheduled.is_empty() {
            let ids: Vec<&str> = self.unscheduled.iter().map(String::as_str).collect();
            eprintln!(
                "bmlr {command}: {} ({}) lost behaviours to constraints that cannot all hold \
                 (CANNOT_SATISFY_CONSTRAINTS; see the warnings)",
                blocks(ids.len()),
                ids.join(", ")
            );
        }
        if self.unparsed > 0 || !self.unscheduled.is_empty() {
            ExitCode::from(1)
        } else {
            ExitCode::SUCCESS
        }
    }
}
