//! Characters that move about the world: before a frame's sync points pass, the engines that
//! move the whole character (locomotion) step it to the frame's time. Where it then stands is
//! its placement (its engines see the world from there), and the sync times those engines
//! revise are taken into the plan: through the block's pegs, so that what is tied to them
//! follows, or, for an interrupted unit, for that unit alone. Whom the walk attends to (the one
//! it asks for room, the walker it makes room for) is passed on to the engines that look.

use super::live::Phase;
use super::BlockManager;
use crate::engines::interface::{Revision, UnitKey};
use crate::planning::plan::pegs::SyncAddr;

impl BlockManager {
    /// Where the character stands now (world frame).
    pub fn placement(&self) -> crate::world::Placement {
        self.placement
    }

    /// Steps the engines that move the character to `to`, and takes every engine's revisions
    /// of its units' sync times (a walk's, a streamed speech's).
    pub(super) fn travel(&mut self, to: f64) {
        let id = self.character.as_deref().unwrap_or("");
        let (mut at, mut revisions) = (self.placement, Vec::new());
        for e in self.registry.engines_mut() {
            if let Some(t) = e.as_travel() {
                at = t.travel(to, &self.shared, id, at);
            }
            if let Some(r) = e.as_revising() {
                revisions.extend(r.take_revisions(to));
            }
        }
        if at != self.placement {
            // (the first placement, from the world, is no move)
            self.moved |= self.placement != crate::world::Placement::default();
            self.placement = at;
            self.world = std::sync::Arc::new(self.shared.seen_from_at(at));
        }
        for r in revisions {
            self.revise(r);
        }
    }

    /// Whether an engine moves the character about now.
    pub fn moving(&mut self) -> bool {
        (self.registry.engines_mut()).any(|e| e.as_travel().is_some_and(|t| t.moving()))
    }

    /// Whether an engine walks the character somewhere of its own.
    pub fn on_its_way(&mut self) -> bool {
        (self.registry.engines_mut()).any(|e| e.as_travel().is_some_and(|t| t.on_its_way()))
    }

    /// Whether an engine has the character off its place to make room for someone.
    pub fn making_room(&mut self) -> bool {
        (self.registry.engines_mut()).any(|e| e.as_travel().is_some_and(|t| t.making_room()))
    }

    /// Where the person stands whom the character asks to make room, if anyone.
    pub fn asking(&mut self) -> Option<glam::Vec2> {
        (self.registry.engines_mut()).find_map(|e| e.as_travel().and_then(|t| t.asking()))
    }

    /// The narrow door the character's walk goes through next, if one is near.
    pub fn passing(&mut self) -> Option<crate::world::crowd::doorway::Passing> {
        (self.registry.engines_mut()).find_map(|e| e.as_travel().and_then(|t| t.passing()))
    }

    /// The way the character's walk goes now, if it walks among others.
    pub fn heading(&mut self) -> Option<glam::Vec2> {
        (self.registry.engines_mut()).find_map(|e| e.as_travel().and_then(|t| t.heading()))
    }

    /// Tells the engines that look ([`Attend`](crate::engines::interface::Attend)) whom the character's
    /// travel attends to now, at their eyes in the character's frame.
    pub(super) fn attend(&mut self) {
        let cue = (self.registry.engines_mut())
            .find_map(|e| e.as_travel().and_then(|t| t.attending()))
            .map(|(at, weight)| crate::engines::interface::Attention {
                at: (self.placement).to_local(glam::Vec3::new(
                    at.x,
                    crate::world::CHARACTER_EYES.y,
                    at.y,
                )),
                weight,
            });
        for e in self.registry.engines_mut() {
            if let Some(a) = e.as_attend() {
                a.attend(cue);
            }
        }
    }

    /// Whether each foot is on the ground, if an engine moves the character's feet.
    pub fn contacts(&mut self) -> Option<[bool; 2]> {
        (self.registry.engines_mut()).find_map(|e| e.as_travel().and_then(|t| t.contacts()))
    }

    /// Takes new times of a unit into the plan (see the module documentation).
    fn revise(&mut self, r: Revision) {
        let Some(i) = self.blocks.find(&r.unit.block) else {
            return;
        };
        let Some(xi) = (self.blocks[i].behaviours.iter()).position(|x| x.id == r.unit.behaviour)
        else {
            return;
        };
        let x = &self.blocks[i].behaviours[xi];
        if !matches!(x.phase, Phase::Planned | Phase::Added | Phase::Running) {
            return;
        }
        let now = self.now;
        let on_pegs = r.others_follow && self.blocks[i].pegs.is_some();
        if on_pegs {
            let block = self.blocks[i].id.to_string();
            let (next, names): (usize, Vec<String>) =
                (x.next, x.syncs.iter().map(|s| s.0.to_string()).collect());
            if let Some(p) = self.blocks[i].pegs.as_mut() {
                for (k, name) in names.iter().enumerate().skip(next) {
                    let addr = SyncAddr::new(&block, &r.unit.behaviour, name);
                    if let (Some(peg), Some(&t)) = (p.board.peg_of(&addr), r.times.get(k)) {
                        if (p.board.global(peg) - t).abs() > 1e-9 {
                            let _ = p.board.move_to(peg, t);
                        }
                    }
                }
            }
            self.follow_pegs(i, now);
        } else {
            let start = self.blocks[i].start;
            let x = &mut self.blocks[i].behaviours[xi];
            x.retime(&r.times, start, now);
            let global = x.global(start);
            let (engine, key) = (x.engine, UnitKey::new(r.unit.block.clone(), x.id.clone()));
            self.registry.engine_mut(engine).retime(&key, &global);
        }
        self.touch();
        if self.blocks.get(i).is_some() && self.blocks[i].started() {
            self.predict(i, true);
        }
    }
}
