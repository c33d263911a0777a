//! The realizer's nets stage: each tick, after sensing and before any character moves, the
//! PaT-Nets are stepped against the world as the previous frame left it (what characters saw,
//! where they stand, the progress reported so far); world variables are set and nets started
//! at once, and the BML they send is performed once the characters have stepped to the
//! tick's time (its blocks start then and move from the next frame). Transitions and variable
//! changes are reported. Off until a host gives nets ([`Realizer::set_nets`]).

use std::collections::{BTreeSet, VecDeque};

use crate::language::feedback::Feedback;
use crate::world::nets::{Nets, Senses};

use super::Realizer;

/// How often nets are stepped when the realizer runs from event to event (Hz): a frame.
pub const NET_RATE: f64 = 60.0;

/// Most progress ids remembered for `sync` guards (the oldest are forgotten first).
pub const MAX_REACHED: usize = 100_000;

/// What the nets stage keeps between ticks.
pub(super) struct Netting {
    nets: Nets,
    report: bool,
    /// Progress reported so far: (character, `block:behaviour:sync` or `block:sync`).
    reached: BTreeSet<(String, String)>,
    order: VecDeque<(String, String)>,
    /// BML the last step sent, performed once the characters have stepped to the tick's time
    /// (so that its blocks start then, not at the tick before).
    pending: Vec<(Option<String>, String)>,
}

/// The world as the nets' guards read it.
struct View<'a> {
    realizer: &'a Realizer,
    reached: &'a BTreeSet<(String, String)>,
}

impl View<'_> {
    fn position(&self, id: &str) -> Option<glam::Vec2> {
        let r = self.realizer;
        let at = if r.world.is_placed(id) || r.characters.contains_key(id) {
            r.world.placement(id).position
        } else {
            r.world.get(id)?
        };
        Some(glam::Vec2::new(at.x, at.z))
    }
}

impl Senses for View<'_> {
    fn sees(&self, character: &str, thing: &str) -> bool {
        self.realizer.seen(character).iter().any(|s| s == thing)
    }

    fn distance(&self, character: &str, thing: &str) -> Option<f32> {
        Some(self.position(character)?.distance(self.position(thing)?))
    }

    fn reached(&self, character: Option<&str>, id: &str) -> bool {
        match character {
            Some(c) => self.reached.contains(&(c.to_string(), id.to_string())),
            None => self.reached.iter().any(|(_, r)| r == id),
        }
    }
}

impl Realizer {
    /// Runs `nets` (`None`: none) from the next tick; `report` sends their transitions and
    /// variable changes as feedback. Nets whose guards read sight turn it on (with the world's
    /// vision settings) if it is off.
    pub fn set_nets(&mut self, nets: Option<Nets>, report: bool) -> Result<(), String> {
        let Some(nets) = nets else {
            self.netting = None;
            return Ok(());
        };
        if nets.use_sight() && self.sensing.is_none() {
            let vision = self.world.vision();
            self.set_perception(Some(vision), false)?;
        }
        self.netting = Some(Box::new(Netting {
            nets,
            report,
            reached: BTreeSet::new(),
            order: VecDeque::new(),
            pending: Vec::new(),
        }));
        Ok(())
    }

    /// The nets, when there are some.
    pub fn nets(&self) -> Option<&Nets> {
        self.netting.as_ref().map(|n| &n.nets)
    }

    /// When the nets next want a step, while they can still change: the next frame.
    pub(super) fn nets_wake(&self) -> Option<f64> {
        let n = self.netting.as_ref()?;
        n.nets
            .active()
            .then(|| ((self.now * NET_RATE + 1e-6).floor() + 1.0) / NET_RATE)
    }

    /// The nets stage of a tick at `now`.
    pub(super) fn run_nets(&mut self, now: f64) {
        let Some(mut n) = self.netting.take() else {
            return;
        };
        let step = {
            let view = View {
                realizer: self,
                reached: &n.reached,
            };
            n.nets.step(now, &view)
        };
        if n.report && !step.feedback.is_empty() {
            let from = self.unframed.len();
            self.unframed
                .extend(step.feedback.into_iter().map(Feedback::World));
            self.deliver(from);
        }
        n.pending = step.bml;
        self.netting = Some(n);
    }

    /// Performs the BML the nets sent this tick (the characters are at the tick's time now).
    pub(super) fn perform_nets_bml(&mut self) {
        let Some(pending) = self
            .netting
            .as_mut()
            .map(|n| std::mem::take(&mut n.pending))
        else {
            return;
        };
        for (character, text) in pending {
            let mut checked = crate::language::bml::Checked::new(&text, &self.limits);
            if let Some(b) = checked.block.as_mut().filter(|b| b.character_id.is_none()) {
                b.character_id = character;
            }
            // (a refused block is reported as warning feedback)
            let _ = self.perform_checked(checked, Some("nets"));
        }
    }

    /// Remembers the progress in `feedback` for `sync` guards.
    pub(super) fn note_progress(&mut self, feedback: &[Feedback]) {
        let Some(n) = self.netting.as_mut() else {
            return;
        };
        for f in feedback {
            let id = match f {
                Feedback::SyncPointProgress(p) => format!("{}:{}:{}", p.block, p.behaviour, p.sync),
                Feedback::BlockProgress(p) => format!("{}:{}", p.block, p.sync),
                _ => continue,
            };
            let key = (f.character_id().unwrap_or("").to_string(), id);
            if n.reached.insert(key.clone()) {
                n.order.push_back(key);
            }
            while n.order.len() > MAX_REACHED {
                if let Some(old) = n.order.pop_front() {
                    n.reached.remove(&old);
                }
            }
        }
    }
}
