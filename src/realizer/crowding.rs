//! The crowd as the realizer keeps it: who is in the world (placed by it or realized here),
//! and the snapshot walkers among others read, made on a fixed grid of times whatever the
//! host's frames, with each character's velocity since the last one.

use super::Realizer;

/// How often walkers among others see where the others are (s): every 0.05 s of global time,
/// on a grid of its multiples, so that no result depends on the host's frames.
pub const CROWD_PERIOD: f64 = crate::world::crowd::snapshot::PERIOD;

/// The index of the crowd grid time at or before `t` (a time within a millionth of a period
/// of a grid time counts as on it: `k * 0.1 / 0.1` may fall just short of `k`).
pub(super) fn grid_index(t: f64) -> i64 {
    (t / CROWD_PERIOD + 1e-6).floor() as i64
}

/// The `k`th crowd grid time.
pub(super) fn grid_time(k: i64) -> f64 {
    k as f64 * CROWD_PERIOD
}

impl Realizer {
    /// Every character: those the world places (in its order), then those realized here that
    /// it does not place (in id order).
    pub(super) fn everyone(&self) -> impl Iterator<Item = &str> + '_ {
        let placed = self.world.placements().map(|(id, _)| id);
        let unplaced = (self.characters.keys())
            .filter(|id| !self.world.is_placed(id))
            .map(String::as_str);
        placed.chain(unplaced)
    }

    /// Whether someone walks among others (the crowd is then kept on its grid).
    pub(super) fn among_others_moving(&mut self) -> bool {
        self.world.crowd().len() > 1 && self.characters.values_mut().any(|m| m.moving())
    }

    /// The crowd walkers see from `now` on: every character placed in the world or realized
    /// here, where it now stands, with its velocity since the last crowd. Kept empty while
    /// there is no one to avoid.
    pub(super) fn update_crowd(&mut self, now: f64) {
        if self.everyone().count() < 2 {
            if !self.world.crowd().is_empty() {
                std::sync::Arc::make_mut(&mut self.world).set_crowd(Default::default());
            }
            return;
        }
        // velocities over the time since the last crowd (the crowd made again at the same
        // time — a host ticking twice at one time — keeps them)
        let last = self.world.crowd().clone();
        let dt = (now - last.time) as f32;
        let agent = |id: &str, at: crate::world::Placement| {
            let here = glam::Vec2::new(at.position.x, at.position.z);
            let velocity = (last.index(id)).map_or(glam::Vec2::ZERO, |i| {
                let before = last.agent(i);
                if dt > 1e-6 {
                    (here - before.at) / dt
                } else {
                    before.velocity
                }
            });
            let agent = crate::world::crowd::Agent {
                at: here,
                velocity,
                radius: self.world.radius(id),
            };
            (id.to_string(), agent)
        };
        // (those the world does not place stand at the origin)
        let agents: Vec<(String, crate::world::crowd::Agent)> = (self.everyone())
            .map(|id| agent(id, self.world.placement(id)))
            .collect();
        let mut crowd = crate::world::crowd::Crowd::new(now, agents);
        let asking: Vec<(usize, glam::Vec2)> = (self.characters.iter_mut())
            .filter_map(|(id, m)| Some((crowd.index(id)?, m.asking()?)))
            .collect();
        crowd.set_asks(asking);
        // who walks somewhere of its own, and who is off its place making room
        let (mut going, mut aside) = (Vec::new(), Vec::new());
        for (id, m) in self.characters.iter_mut() {
            let Some(i) = crowd.index(id) else { continue };
            if m.on_its_way() {
                going.push(i);
            }
            if m.making_room() {
                aside.push(i);
            }
        }
        crowd.set_on_their_way(going);
        crowd.set_aside(aside);
        let ways: Vec<(usize, glam::Vec2)> = (self.characters.iter_mut())
            .filter_map(|(id, m)| Some((crowd.index(id)?, m.heading()?)))
            .collect();
        crowd.set_ways(ways);
        // who is coming to a narrow door, and whose turn it is there
        let narrows = self.world.obstacles().narrows();
        if !narrows.is_empty() {
            let passing: Vec<(usize, crate::world::crowd::doorway::Passing)> =
                (self.characters.iter_mut())
                    .filter_map(|(id, m)| Some((crowd.index(id)?, m.passing()?)))
                    .collect();
            crowd.set_passing(passing);
            let turns = crate::world::crowd::doorway::turns(last.turns(), &crowd, narrows);
            crowd.set_turns(turns);
        }
        // (walkers of other realizers asking someone here)
        let remote = (self.remote_asks.iter())
            .filter_map(|(who, asked)| Some((crowd.index(asked)?, crowd.index(who)?)));
        let pairs: Vec<(usize, usize)> = crowd.ask_pairs().chain(remote).collect();
        crowd.set_ask_pairs(pairs);
        // one placed by the world file alone, asked to make room, becomes a character here
        // (standing, with the engines that can move it aside)
        let asked: Vec<String> = (0..crowd.len())
            .filter(|&i| crowd.askers(i).next().is_some())
            .map(|i| crowd.id(i).to_string())
            .filter(|id| !self.characters.contains_key(id) && !self.remote.contains(id))
            .collect();
        std::sync::Arc::make_mut(&mut self.world).set_crowd(crowd);
        // (as of the crowd's time, not the frame's: the same whatever the host's frames)
        for id in asked {
            self.manager_at(Some(id), now);
        }
    }
}
