//! Anticipators at run time: registering them, polling their predictions, and blocks that hang on
//! them following their pegs without rescheduling, losing behaviours whose timing broke.

use super::live::Phase;
use super::{BlockKey, BlockManager};
use crate::engines::interface::UnitKey;
use crate::language::feedback::KnownWarning;
use crate::planning::plan::anticipator::Anticipator;
use crate::planning::plan::to_pegs;

/// How far a block's predicted end must move for a new prediction to be sent (seconds).
const REVISION: f64 = 1e-3;

/// A behaviour (by position in its block) and the new global times of its syncs.
type Retimed = (usize, Vec<f64>);

impl BlockManager {
    /// Registers an anticipator (replacing one with the same id). Blocks scheduled from now on
    /// can refer to its syncs as `anticipators:ID:SYNC`.
    pub fn add_anticipator(&mut self, anticipator: Box<dyn Anticipator>) {
        self.touch();
        self.anticipators.retain(|a| a.id() != anticipator.id());
        self.anticipators.push(anticipator);
    }

    /// When a scripted prediction next changes, if a live block hangs on an anticipator.
    pub(super) fn next_prediction_change(&self) -> Option<f64> {
        if !self.blocks.iter().any(|b| b.pegs.is_some()) {
            return None;
        }
        self.anticipators
            .iter()
            .filter_map(|a| a.next_change())
            .filter(|t| t.is_finite())
            .reduce(f64::min)
    }

    /// Polls every anticipator at `t`; blocks hanging on one whose predictions changed follow
    /// their pegs.
    pub(super) fn update_anticipators(&mut self, t: f64) {
        let changed: Vec<String> = self
            .anticipators
            .iter_mut()
            .filter_map(|a| a.update(t).then(|| a.id().to_string()))
            .collect();
        if changed.is_empty() {
            return;
        }
        let announce = (self.anticipators.iter())
            .any(|a| a.announces() && changed.iter().any(|c| c == a.id()));
        self.touch();
        let hanging: Vec<BlockKey> = (self.blocks.with_keys())
            .filter(|(_, b)| b.pegs.is_some())
            .map(|(k, _)| k)
            .collect();
        for i in hanging {
            // following one block's pegs can end another that hung on the same anticipator
            if self.blocks.get(i).is_none() {
                continue;
            }
            let anticipators = &self.anticipators;
            let predict = |a: &str, sync: &str| {
                let x = anticipators.iter().find(|x| x.id() == a)?;
                x.predict(sync)
            };
            let before = self.blocks[i].predicted_end();
            let (moved, refused) = match self.blocks[i].pegs.as_mut() {
                Some(p) => p.follow(&changed, predict),
                None => (false, None),
            };
            if let Some(reason) = refused {
                self.warn(
                    self.blocks[i].id.clone(),
                    KnownWarning::InvalidTiming,
                    reason,
                );
            }
            if moved {
                self.follow_pegs(i, t);
                if announce {
                    self.announce_end(i, before);
                }
            }
        }
    }

    /// Sends block `i`'s prediction if its end moved from `before` (by more than
    /// [`REVISION`]).
    fn announce_end(&mut self, i: BlockKey, before: Option<f64>) {
        let Some(after) = self.blocks.get(i).map(|b| b.predicted_end()) else {
            return;
        };
        let moved = match (before, after) {
            (Some(a), Some(b)) => (a - b).abs() > REVISION,
            (a, b) => a.is_some() != b.is_some(),
        };
        if moved {
            self.predict(i, true);
        }
    }

    /// Block `i` takes its behaviours' times from its peg board at time `t`. Passed syncs stay,
    /// and so does a rigid behaviour that started (a speech already speaking). A behaviour whose
    /// timing broke (order, block start, a future sync moved into the past) leaves the plan with
    /// an INVALID_TIMING warning; if it was running, it ends now as its engine ends interrupted
    /// units.
    pub(super) fn follow_pegs(&mut self, i: BlockKey, t: f64) {
        let (updates, dropped) = self.judge_pegs(i, t);
        for (xi, global) in updates {
            self.retime_behaviour(i, xi, &global);
        }
        for xi in dropped {
            self.drop_broken(i, xi, t);
        }
        if self.blocks[i].started() {
            self.finish_if_done(i, t);
        }
    }

    /// The behaviours of block `i` that can take their new times from its pegs (with those
    /// global times), and those whose timing broke.
    fn judge_pegs(&self, i: BlockKey, t: f64) -> (Vec<Retimed>, Vec<usize>) {
        let b = &self.blocks[i];
        let (mut updates, mut dropped) = (Vec::new(), Vec::new());
        let Some(p) = b.pegs.as_ref() else {
            return (updates, dropped);
        };
        let invalid = to_pegs::invalid(&p.board, &p.plan);
        for (xi, x) in b.behaviours.iter().enumerate() {
            if !matches!(x.phase, Phase::Planned | Phase::Added | Phase::Running)
                || (x.rigid && x.phase == Phase::Running)
            {
                continue;
            }
            let Some(global) = p.plan.times(&p.board, &x.id) else {
                continue;
            };
            let into_past = b.started()
                && (global.iter().enumerate()).any(|(k, g)| k >= x.next && *g < t - 1e-9);
            let named: Vec<_> = (x.syncs.iter().zip(&global))
                .map(|((n, _), g)| (n.clone(), *g))
                .collect();
            let behaviour = &b.source.behaviours[x.index];
            let engine = self.registry.engine(x.engine);
            let engine_refuses = engine.check_timing(behaviour, &named).is_err();
            if invalid.contains(&x.id) || into_past || engine_refuses {
                dropped.push(xi);
            } else {
                updates.push((xi, global));
            }
        }
        (updates, dropped)
    }

    /// Behaviour `xi` of block `i` takes the global times `global` for its syncs still ahead.
    fn retime_behaviour(&mut self, i: BlockKey, xi: usize, global: &[f64]) {
        let b = &mut self.blocks[i];
        let (start, block_id) = (b.start, b.id.clone());
        let x = &mut b.behaviours[xi];
        for (k, s) in x.syncs.iter_mut().enumerate().skip(x.next) {
            if let Some(g) = global.get(k) {
                s.1 = g - start;
            }
        }
        if matches!(x.phase, Phase::Added | Phase::Running) {
            let key = UnitKey::new(block_id, x.id.clone());
            (self.registry.engine_mut(x.engine)).retime(&key, &x.global(start));
        }
    }

    /// Behaviour `xi` of block `i` no longer fits its constraints: a running one stops now,
    /// another leaves the plan; either way with a warning.
    fn drop_broken(&mut self, i: BlockKey, xi: usize, t: f64) {
        let block_id = self.blocks[i].id.clone();
        let x = &self.blocks[i].behaviours[xi];
        let behaviour = x.id.clone();
        let running = x.phase == Phase::Running;
        if running {
            self.interrupt_unit(i, xi, t);
        } else {
            if x.phase == Phase::Added {
                let key = UnitKey::new(block_id.clone(), x.id.clone());
                self.registry.engine_mut(x.engine).remove(&key);
            }
            self.blocks[i].behaviours[xi].phase = Phase::Removed;
        }
        let what = if running {
            "it stops now"
        } else {
            "it is dropped"
        };
        self.warn(
            format!("{block_id}:{behaviour}"),
            KnownWarning::InvalidTiming,
            format!(
                "'{behaviour}' no longer fits its constraints after an anticipator moved; {what}"
            ),
        );
    }
}
