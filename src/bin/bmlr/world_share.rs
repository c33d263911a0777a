//! One world over many realizers on a broker, shared by area. The floor is cut into cells
//! (`--cell`, 10 m); 20 times a second this realizer publishes each of its characters' root
//! state (once a second for one standing still) on the topic of the cell it stands in
//! (`PREFIX/world/CELL/CHARACTER`) and listens to
//! the cells within a walker's avoidance range of its characters, moving its subscriptions as
//! they walk. The characters of other realizers it hears of are placed in its world
//! (`Realizer::place_remote`), so that its walkers go round them, look at them and answer their
//! asks for room exactly as for its own. A character that crosses into another cell is handed
//! over cleanly: its state goes on the new cell's topic, and once more on the old one's saying
//! where it went (`"moved"`), so that a realizer that does not listen to the new cell lets it go
//! at once; one not heard of for a while (its realizer gone, or out of range) is let go too,
//! like a character the world file placed for another realizer that never shows up.

use std::collections::{BTreeMap, BTreeSet};
use std::fmt;

use bml_realizer::ports::broker::{
    Cell, RootState, DEFAULT_CHARACTER, PUBLISH_PERIOD, REST_PERIOD, STALE,
};
use bml_realizer::realizer::clock::Clock;
use bml_realizer::realizer::Realizer;

use crate::brokered::{Brokered, Server};

/// What the sharing has done, said on stderr when serving ends.
#[derive(Debug, Default, Clone, Copy)]
pub struct Counts {
    /// States heard on the world topics (the realizer's own included: it listens to the cells
    /// its characters stand in).
    pub heard: u64,
    /// States published (and hand-overs).
    pub published: u64,
    /// The most cells listened to at once.
    pub most_cells: usize,
    /// States heard but dropped: this realizer fell behind reading them.
    pub dropped: u64,
}

impl fmt::Display for Counts {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "heard {} states, published {}, listened to {} cells at most, dropped {}",
            self.heard, self.published, self.most_cells, self.dropped
        )
    }
}

/// The shared world as this realizer keeps it.
pub struct Sharing {
    /// The other realizers' characters: their last state and when it arrived (local clock).
    pub others: BTreeMap<String, (RootState, f64)>,
    /// Characters the world file places for other realizers (not `--characters`) not heard of
    /// yet: let go if none is heard of within [`STALE`] s of the start.
    unheard: BTreeSet<String>,
    /// Each of this realizer's characters' last published state (its cell is where that put
    /// it), and when (local clock).
    sent: BTreeMap<String, (RootState, f64)>,
    /// The cells listened to now.
    listened: BTreeSet<Cell>,
    /// When this realizer last published its characters' states.
    published: f64,
    /// Characters whose state could not be read (said once each on stderr).
    bad_states: BTreeSet<String>,
    /// What was heard and sent.
    pub counts: Counts,
}

impl Sharing {
    /// Nothing heard yet; the world file's characters for other realizers on trial.
    pub fn new(args: &Brokered, realizer: &Realizer) -> Sharing {
        let unheard = match args.characters.is_empty() {
            // (without --characters, any placed character may become this realizer's)
            true => BTreeSet::new(),
            false => (realizer.world().placements())
                .map(|(id, _)| id.to_string())
                .filter(|id| !id.is_empty() && !args.characters.contains(id))
                .collect(),
        };
        Sharing {
            others: BTreeMap::new(),
            unheard,
            sent: BTreeMap::new(),
            listened: BTreeSet::new(),
            published: f64::NEG_INFINITY,
            bad_states: BTreeSet::new(),
            counts: Counts::default(),
        }
    }
}

impl Server {
    /// Places the other realizers' characters where they are now, as far as their states
    /// tell, and lets go of those not heard of for [`STALE`] s.
    pub(crate) fn place_others(&mut self, now: f64) {
        let stale: Vec<String> = (self.sharing.others.iter())
            .filter(|(_, (_, heard))| now - heard > STALE)
            .map(|(id, _)| id.clone())
            .chain(
                (self.sharing.unheard.iter())
                    .filter(|_| now > STALE)
                    .cloned(),
            )
            .collect();
        for id in stale {
            self.let_go(&id);
        }
        for (id, (state, heard)) in &self.sharing.others {
            let placed = self
                .realizer
                .place_remote(id, state.placement_after(now - heard));
            if placed.is_ok() {
                // (an ask heard more than a second ago is over: its realizer may be gone)
                let asks = state.asks.as_deref().filter(|_| now - heard < 1.0);
                let _ = self.realizer.remote_asks(id, asks);
            }
        }
    }

    /// Takes another realizer's character out of this world.
    fn let_go(&mut self, id: &str) {
        self.sharing.others.remove(id);
        self.sharing.unheard.remove(id);
        let _ = self.realizer.forget_remote(id);
    }

    /// Keeps another realizer's state of `character` (not one served here); one that says
    /// the character moved to a cell not listened to lets it go.
    pub(crate) fn hear_state(&mut self, character: String, payload: &[u8]) {
        self.sharing.counts.heard += 1;
        if self.args.characters.contains(&character) || self.is_ours(&character) {
            return;
        }
        match RootState::from_json(payload) {
            Ok(state) => {
                let gone = (state.moved.as_deref())
                    .map(|c| Cell::parse(c).is_none_or(|c| !self.sharing.listened.contains(&c)));
                match gone {
                    Some(true) => self.let_go(&character),
                    // (its state on the new cell's topic comes too)
                    Some(false) => {}
                    None => {
                        self.sharing.unheard.remove(&character);
                        let heard = self.clock.now();
                        self.sharing.others.insert(character, (state, heard));
                    }
                }
            }
            Err(e) => {
                if self.sharing.bad_states.insert(character.clone()) {
                    eprintln!("bmlr serve: the world state of '{character}' is not a root state ({e}); ignored");
                }
            }
        }
    }

    /// Whether `character` (a topic level) is one this realizer has made.
    fn is_ours(&self, character: &str) -> bool {
        let id = if character == DEFAULT_CHARACTER {
            ""
        } else {
            character
        };
        self.realizer.character(id).is_some() && !self.realizer.is_remote(id)
    }

    /// Every [`PUBLISH_PERIOD`]: publishes where this realizer's characters stand and moves
    /// its subscriptions after them.
    pub(crate) fn share(&mut self, now: f64) {
        if now - self.sharing.published < PUBLISH_PERIOD {
            return;
        }
        self.sharing.published = now;
        let places = self.publish_states(now);
        let listened = (self.args.cells).listened(&places, &self.sharing.listened);
        let before = std::mem::replace(&mut self.sharing.listened, listened.clone());
        for cell in before.difference(&listened) {
            let filter = self.destination(self.args.topics.world_cell(*cell));
            self.args.wire.unlisten(&filter);
        }
        for cell in listened.difference(&before) {
            let filter = self.destination(self.args.topics.world_cell(*cell));
            self.args.wire.listen(&filter);
        }
        self.args.wire.flush();
        let counts = &mut self.sharing.counts;
        counts.most_cells = counts.most_cells.max(listened.len());
    }

    /// Publishes where this realizer's characters stand (those it has made, and the
    /// `--characters` the world places), each on its cell's topic, and hands over those that
    /// changed cells; where they stand (x, z).
    fn publish_states(&mut self, now: f64) -> Vec<(f32, f32)> {
        let world = self.realizer.world().clone();
        let mut ours: BTreeSet<String> = (self.realizer.characters())
            .map(|(id, _)| id.to_string())
            .filter(|id| !id.is_empty() && !self.realizer.is_remote(id))
            .collect();
        ours.extend(
            (self.args.characters.iter())
                .filter(|c| world.is_placed(c))
                .cloned(),
        );
        let crowd = world.crowd();
        let mut places = Vec::new();
        for id in ours.into_iter().filter(|id| world.is_placed(id)) {
            let velocity = crowd.index(&id).map_or(glam::Vec3::ZERO, |i| {
                let v = crowd.agent(i).velocity;
                glam::Vec3::new(v.x, 0.0, v.y)
            });
            let at = world.placement(&id);
            places.push((at.position.x, at.position.z));
            let state = RootState {
                asks: self.realizer.asks(&id).map(str::to_string),
                ..RootState::new(now, at, velocity)
            };
            let cell = self.args.cells.of(at.position.x, at.position.z);
            // the cell its last state put it in, and whether it has stood still since
            let last = (self.sharing.sent.get(&id)).map(|(before, when)| {
                let left = self.args.cells.of(before.position[0], before.position[2]);
                (left, state.at_rest_as(before) && now - when < REST_PERIOD)
            });
            if let Some((left, resting)) = last {
                if left != cell {
                    let moved = RootState {
                        moved: Some(cell.to_string()),
                        ..state.clone()
                    };
                    self.send_state(left, &id, moved);
                } else if resting {
                    // (one standing still is said again only every REST_PERIOD)
                    continue;
                }
            }
            self.sharing.sent.insert(id.clone(), (state.clone(), now));
            self.send_state(cell, &id, state);
        }
        places
    }

    fn send_state(&mut self, cell: Cell, id: &str, state: RootState) {
        let topic = self.destination(self.args.topics.world(cell, id));
        self.args
            .wire
            .send_state(&topic, state.to_json().into_bytes());
        self.sharing.counts.published += 1;
    }
}
