//! Anticipators at run time: registering them, polling their predictions, and blocks that hang on
//! them following their pegs without rescheduling, losing behaviours whose timing broke.

use super::live::Phase;
use super::{BlockKey, BlockManager};
use crate::bml;
use crate::engine::UnitKey;
use crate::feedback::KnownWarning;
use crate::plan::anticipator::Anticipator;
use crate::plan::to_pegs;

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
        self.touch();
        let ids: Vec<bml::Id> = self
            .blocks
            .iter()
            .filter(|b| b.pegs.is_some())
            .map(|b| b.id.clone())
            .collect();
        for id in ids {
            let Some(i) = self.blocks.find(&id) else {
                continue;
            };
            let anticipators = &self.anticipators;
            let predict = |a: &str, sync: &str| {
                let x = anticipators.iter().find(|x| x.id() == a)?;
                x.predict(sync)
            };
            let (moved, refused) = match self.blocks[i].pegs.as_mut() {
                Some(p) => p.follow(&changed, predict),
                None => (false, None),
            };
            if let Some(reason) = refused {
                self.warn(id.clone(), KnownWarning::InvalidTiming, reason);
            }
            if moved {
                self.follow_pegs(i, t);
            }
        }
    }

    /// Block `i` takes its behaviours' times from its peg board at time `t`. Passed syncs stay,
    /// and so does a rigid behaviour that started (a speech already speaking). A behaviour whose
    /// timing broke (order, block start, a future sync moved into the past) leaves the plan with
    /// an INVALID_TIMING warning; if it was running, it ends now as its engine ends interrupted
    /// units.
    pub(super) fn follow_pegs(&mut self, i: BlockKey, t: f64) {
        let block_id = self.blocks[i].id.clone();
        let Some(p) = self.blocks[i].pegs.as_ref() else {
            return;
        };
        let invalid = to_pegs::invalid(&p.board, &p.plan);
        let start = self.blocks[i].start;
        let started = self.blocks[i].started();
        let (mut dropped, mut updates) = (Vec::new(), Vec::new());
        for (xi, x) in self.blocks[i].behaviours.iter().enumerate() {
            if !matches!(x.phase, Phase::Planned | Phase::Added | Phase::Running)
                || (x.rigid && x.phase == Phase::Running)
            {
                continue;
            }
            let Some(global) = p.plan.times(&p.board, &x.id) else {
                continue;
            };
            let into_past = started
                && global
                    .iter()
                    .enumerate()
                    .any(|(k, g)| k >= x.next && *g < t - 1e-9);
            let named: Vec<_> = x
                .syncs
                .iter()
                .zip(&global)
                .map(|((n, _), g)| (n.clone(), *g))
                .collect();
            let behaviour = &self.blocks[i].source.behaviours[x.index];
            let engine_refuses = self
                .registry
                .engine(x.engine)
                .check_timing(behaviour, &named)
                .is_err();
            if invalid.contains(&x.id) || into_past || engine_refuses {
                dropped.push(xi);
            } else {
                updates.push((xi, global));
            }
        }
        for (xi, global) in updates {
            let x = &mut self.blocks[i].behaviours[xi];
            for (k, s) in x.syncs.iter_mut().enumerate().skip(x.next) {
                if let Some(g) = global.get(k) {
                    s.1 = g - start;
                }
            }
            if matches!(x.phase, Phase::Added | Phase::Running) {
                let key = UnitKey::new(block_id.clone(), x.id.clone());
                self.registry
                    .engine_mut(x.engine)
                    .retime(&key, &x.global(start));
            }
        }
        for xi in dropped {
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
            self.warn(
                format!("{block_id}:{behaviour}"),
                KnownWarning::InvalidTiming,
                format!(
                    "'{behaviour}' no longer fits its constraints after an anticipator moved; {}",
                    if running {
                        "it stops now"
                    } else {
                        "it is dropped"
                    }
                ),
            );
        }
        if self.blocks[i].started() {
            self.finish_if_done(i, t);
        }
    }
}
