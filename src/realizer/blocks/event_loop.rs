//! The event loop: the heap of every live behaviour's next sync, passing syncs in time order up
//! to the requested time, engines' control actions, running parameter changes, and the frame's
//! poses.

use super::*;
use crate::engines::interface::EngineError;

/// A behaviour's next sync in the heap of [`BlockManager::next_sync`], ordered by time (in whole
/// nanoseconds, so that float noise makes ties), then block arrival, then document order.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub(super) struct Due {
    pub(super) ns: i64,
    pub(super) seq: u64,
    pub(super) index: usize,
    /// The behaviour's position in its block, and the sync's position in the behaviour.
    pub(super) xi: usize,
    pub(super) k: usize,
    /// The block's handle (`seq` orders; this finds it).
    pub(super) block: BlockKey,
}

/// A global time in whole nanoseconds.
pub(super) fn due_ns(t: f64) -> i64 {
    (t * 1e9).round() as i64
}

impl BlockManager {
    /// The next sync point due: (global time, block, behaviour index). Ties (times within
    /// a nanosecond: float noise of the solver) go to the earlier block, then document order.
    ///
    /// Every live behaviour's next sync waits in a heap. It is rebuilt after a change of the plan
    /// ([`touch`](Self::touch)); a sync that passes without consequences for other behaviours
    /// only queues the behaviour's next one ([`queue_next`](Self::queue_next)). An entry whose
    /// behaviour has moved on is dropped when it comes up. So an event costs a heap operation,
    /// not a scan of every live behaviour (a chain of 10 000 behaviours passes 70 000 syncs).
    pub(super) fn next_sync(&self) -> Option<(f64, BlockKey, usize)> {
        if self.due_stale.get() {
            self.rebuild_due();
        }
        let mut due = self.due.borrow_mut();
        while let Some(&Reverse(d)) = due.peek() {
            if let Some((t, bi)) = self.still_due(d) {
                return Some((t, bi, d.xi));
            }
            due.pop();
        }
        None
    }

    /// The plan changed (blocks, phases or sync times): the heap of next syncs is rebuilt.
    pub(super) fn touch(&self) {
        self.due_stale.set(true);
    }

    /// The entry of behaviour `xi` of block `bi`'s next sync, if it has one to report.
    pub(super) fn due_of(&self, bi: BlockKey, xi: usize) -> Option<Due> {
        let b = &self.blocks[bi];
        let x = &b.behaviours[xi];
        let live = b.started() && matches!(x.phase, Phase::Added | Phase::Running);
        let local = x.syncs.get(x.next).filter(|_| live)?.1;
        Some(Due {
            ns: due_ns(b.start + local),
            seq: b.seq,
            index: x.index,
            xi,
            k: x.next,
            block: bi,
        })
    }

    /// Queues the next sync of behaviour `xi` of block `bi` (after one of its syncs passed).
    pub(super) fn queue_next(&self, bi: BlockKey, xi: usize) {
        if let Some(d) = self.due_of(bi, xi) {
            self.due.borrow_mut().push(Reverse(d));
        }
    }

    pub(super) fn rebuild_due(&self) {
        let mut all = Vec::new();
        for (bi, b) in self.blocks.with_keys() {
            if b.started() {
                all.extend((0..b.behaviours.len()).filter_map(|xi| self.due_of(bi, xi)));
            }
        }
        *self.due.borrow_mut() = BinaryHeap::from(all.into_iter().map(Reverse).collect::<Vec<_>>());
        self.due_stale.set(false);
    }

    /// Whether an entry still stands for its behaviour's next sync: its global time and its
    /// block.
    pub(super) fn still_due(&self, d: Due) -> Option<(f64, BlockKey)> {
        let bi = d.block;
        self.blocks.get(bi)?;
        let now = self.due_of(bi, d.xi)?;
        (now == d).then(|| {
            let b = &self.blocks[bi];
            (b.start + b.behaviours[d.xi].syncs[d.k].1, bi)
        })
    }

    /// Moves time to `to`: every sync point up to then passes in time order with its feedback and
    /// consequences (control actions, block ends, blocks that were waiting), then parameter
    /// changes apply, every engine plays into `frame` and moves the body, whose pose joins the
    /// frame.
    pub fn advance(&mut self, to: f64, world: &std::sync::Arc<World>, frame: &mut Frame) {
        self.set_world(world);
        let to = to.max(self.now);
        // changes made from outside since the last frame (e.g. a new tempo)
        self.update_anticipators(self.now);
        let mut last_change = f64::NEG_INFINITY;
        // a walking character moves up to each sync point before it passes (its walk's sync
        // points follow what happens, and a walk that a sync point starts begins then, whatever
        // the host's frames), and on to `to` at the end
        let mut traveled = f64::NEG_INFINITY;
        loop {
            if let Some((t, _, _)) = self.next_sync().filter(|s| s.0 <= to && s.0 > traveled) {
                traveled = t.max(self.now);
                self.travel(traveled);
                continue;
            }
            let sync = self.next_sync().filter(|s| s.0 <= to);
            // an anticipator that keeps announcing the same change is not asked again
            let change = self
                .next_prediction_change()
                .filter(|&c| c <= to && c > last_change);
            if let Some(c) = change {
                last_change = c;
            }
            match (sync, change) {
                // a prediction changing at the same moment as a sync applies first
                (Some((ts, _, _)), Some(tc)) if tc <= ts => {
                    self.now = self.now.max(tc);
                    self.update_anticipators(tc);
                }
                (None, Some(tc)) => {
                    self.now = self.now.max(tc);
                    self.update_anticipators(tc);
                }
                (Some((t, bi, xi)), _) => {
                    self.now = t;
                    if self.pass_sync(bi, xi, t) {
                        self.touch();
                    } else if self.blocks.get(bi).is_some() {
                        self.queue_next(bi, xi);
                    }
                }
                // (and on to `to`, where a walk may turn out to have ended earlier than
                // predicted: its end then passes in this frame)
                (None, None) if traveled < to => {
                    traveled = to;
                    self.travel(to);
                }
                (None, None) => break,
            }
        }
        self.now = to;
        self.update_anticipators(to);
        self.apply_changes(to);
        self.hear_utterance(to);
        self.predict_poses(to);
        self.attend();
        let mut pose = self.base_pose(to);
        let mut face = crate::character::face::Face::neutral(
            crate::character::face::FaceModel::default_model(),
        );
        let mut warnings = Vec::new();
        for e in self.registry.engines_mut() {
            e.play(to, frame);
            if let Some(m) = e.as_motion() {
                m.animate(to, &self.skeleton, &self.world, &mut pose);
            }
            if let Some(x) = e.as_expression() {
                x.express(to, &mut face);
            }
            warnings.extend(e.take_warnings());
        }
        for (key, text) in warnings {
            self.warn(key.to_string(), KnownWarning::ExecutionFailure, text);
        }
        let clamped =
            (self.assembler).finish(to, &self.skeleton, &self.placement, &mut pose, &mut face);
        let (sounds, events) = self.sounds(to);
        let contacts = self.contacts();
        frame.poses.push(CharacterPose {
            character: self.character.clone(),
            pose,
            clamped,
            face,
            sounds,
            events,
            contacts,
        });
        for (engine, key) in std::mem::take(&mut self.retiring) {
            self.registry.engine_mut(engine).remove(&key);
        }
    }

    /// What plays at `now`, and the sounds that started or stopped since the last frame.
    fn sounds(
        &mut self,
        now: f64,
    ) -> (
        Vec<crate::character::sound::Playing>,
        Vec<crate::character::sound::SoundEvent>,
    ) {
        let mut sounds = Vec::new();
        for e in self.registry.engines_mut() {
            if let Some(s) = e.as_sound() {
                s.sounds(now, &mut sounds);
            }
        }
        let mut events = Vec::new();
        for p in &sounds {
            if !self.playing.contains(&p.id) {
                let offset = (now - p.start).max(0.0);
                events.push(crate::character::sound::SoundEvent {
                    start: true,
                    id: p.id.clone(),
                    offset,
                });
            }
        }
        for id in &self.playing {
            if !sounds.iter().any(|p| p.id == *id) {
                events.push(crate::character::sound::SoundEvent {
                    start: false,
                    id: id.clone(),
                    offset: 0.0,
                });
            }
        }
        self.playing = sounds.iter().map(|p| p.id.clone()).collect();
        (sounds, events)
    }

    /// Gives every engine that asks for them the poses the predictable units will have at the
    /// times it names.
    pub(super) fn predict_poses(&mut self, now: f64) {
        let ids: Vec<_> = self.registry.ids().collect();
        for i in ids {
            let engine = self.registry.engine_mut(i);
            let Some(times) = engine.as_prediction().map(|p| p.prediction_times(now)) else {
                continue;
            };
            if times.is_empty() {
                continue;
            }
            let poses = times
                .into_iter()
                .map(|t| {
                    let mut pose = self.base_pose(t);
                    for e in self.registry.engines_mut() {
                        if let Some(p) = e.as_prediction() {
                            p.predict(t, &self.skeleton, &self.world, &mut pose);
                        }
                    }
                    (t, pose)
                })
                .collect();
            if let Some(p) = self.registry.engine_mut(i).as_prediction() {
                p.predicted(poses);
            }
        }
    }

    /// Reports the next sync of behaviour `xi` of block `bi`, passed at `t`, and what follows
    /// from it. Returns whether the plan changed beyond that behaviour (an action, a block that
    /// ended or started).
    pub(super) fn pass_sync(&mut self, bi: BlockKey, xi: usize, t: f64) -> bool {
        let (block_id, beh_id, sync, local, engine, last, skipped) = {
            let b = &mut self.blocks[bi];
            let x = &mut b.behaviours[xi];
            let (name, local) = x.syncs[x.next].clone();
            let skipped = x.next < x.skip_before;
            x.next += 1;
            x.phase = Phase::Running;
            (
                b.id.clone(),
                x.id.clone(),
                name,
                local,
                x.engine,
                x.next == x.syncs.len(),
                skipped,
            )
        };
        self.sync_feedback(&block_id, &beh_id, &sync, local, t, skipped);
        let key = UnitKey::new(block_id.clone(), beh_id.clone());
        let mut actions = Vec::new();
        if let Some(control) = self.registry.engine_mut(engine).as_control() {
            control.sync_passed(&key, &sync, t, &mut actions);
        }
        if last {
            self.blocks[bi].behaviours[xi].phase = Phase::Ended;
            self.retiring.push((engine, key.clone()));
        }
        let mut changed = !actions.is_empty();
        if self.blocks[bi].update_subsiding() {
            self.start_ready(t);
            changed = true;
        }
        for a in actions {
            self.act(a, t);
        }
        if let Some(bi) = self.blocks.find(&block_id) {
            changed |= self.finish_if_done(bi, t);
        }
        changed
    }

    pub(super) fn act(&mut self, action: Action, t: f64) {
        match action {
            Action::Interrupt {
                by,
                target,
                include,
                exclude,
            } => self.interrupt_behaviours(&by, &target, &include, &exclude, t),
            Action::Activate { by, target } => self.activate(&target, t, &by.to_string()),
            Action::ChangeParameter(mut c) => {
                let engine = self
                    .blocks
                    .find(&c.target.block)
                    .and_then(|i| self.blocks[i].behaviour(&c.target.behaviour))
                    .filter(|x| matches!(x.phase, Phase::Added | Phase::Running))
                    .map(|x| x.engine);
                let Some(engine) = engine else {
                    self.warn(
                        c.by.to_string(),
                        KnownWarning::NoSuchTarget,
                        format!(
                            "cannot change '{}' of {}: it is not in the running plan",
                            c.param, c.target
                        ),
                    );
                    return;
                };
                if c.initial.is_none() {
                    // start from the target's current value
                    c.initial = (self.registry.engine_mut(engine).as_parameters())
                        .and_then(|p| p.parameter(&c.target, &c.param));
                    if c.initial.is_none() {
                        self.warn(
                            c.by.to_string(),
                            KnownWarning::ExecutionFailure,
                            format!("{} has no parameter '{}'", c.target, c.param),
                        );
                        return;
                    }
                }
                self.changes.push(c);
                self.apply_changes(t);
            }
        }
    }

    /// Sets every running parameter change's value at `t`; changes past their end are done (the
    /// value stays).
    pub(super) fn apply_changes(&mut self, t: f64) {
        if !self.changes.is_empty() {
            self.touch(); // a change may retime its target
        }
        let changes = std::mem::take(&mut self.changes);
        for c in changes {
            let found = self.blocks.find(&c.target.block).and_then(|bi| {
                let xi = self.blocks[bi]
                    .behaviours
                    .iter()
                    .position(|x| x.id == c.target.behaviour)?;
                Some((bi, xi))
            });
            let Some((bi, xi)) = found else { continue };
            let x = &self.blocks[bi].behaviours[xi];
            if !matches!(x.phase, Phase::Added | Phase::Running) {
                continue; // the target ended: nothing to change any more
            }
            let value = c.value_at(c.initial.unwrap_or(c.target_value), t.max(c.start));
            let engine = x.engine;
            let set = match self.registry.engine_mut(engine).as_parameters() {
                Some(p) => p.set_parameter(&c.target, &c.param, value, t),
                None => Err(EngineError(format!(
                    "{} has no parameter '{}' that can change while it runs",
                    c.target, c.param
                ))),
            };
            match set {
                Ok(retimed) => {
                    if let Some(times) = retimed {
                        let start = self.blocks[bi].start;
                        self.blocks[bi].behaviours[xi].retime(&times, start, t);
                    }
                    if t < c.end {
                        self.changes.push(c);
                    }
                }
                Err(e) => self.warn(c.by.to_string(), KnownWarning::ExecutionFailure, e.0),
            }
        }
    }
}
