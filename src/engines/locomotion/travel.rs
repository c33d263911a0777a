//! The locomotion engine's travel: stepping the walker to each frame's time among the others
//! (starting the walks that are due, following their moments, pursuing a moving target), and,
//! standing, making room for a walker that asks (`locomotion::room`).

use std::sync::Arc;

use glam::{Vec2, Vec3};

use super::targets::resolve;
use super::LocomotionEngine;
use crate::engines::interface::{Revising, Revision, Travel, UnitKey};
use crate::world::locomotion::room::{back_to, make_room};
use crate::world::locomotion::walker;
use crate::world::{Placement, World};

impl Travel for LocomotionEngine {
    fn travel(
        &mut self,
        now: f64,
        world: &std::sync::Arc<World>,
        id: &str,
        at: Placement,
    ) -> Placement {
        if self.id != id {
            self.id = id.to_string();
        }
        // (shared, not copied: the world changes every frame someone walks)
        self.world = Some(world.clone());
        self.make_room(now, world, id, at);
        // a character that never walked and has no walk to start stands where it is placed
        if !self.walked && self.units.is_empty() {
            self.walker = None;
            self.at = at;
            return at;
        }
        // a new walker starts no later than the first walk
        let first = (self.units.all())
            .filter_map(|(syncs, u)| (!u.started).then(|| syncs.first().map(|s| s.1)).flatten())
            .fold(now, f64::min);
        self.walker(at, world, first);
        loop {
            // the next walk to start by now
            let next = (self.units.all())
                .filter(|(syncs, u)| !u.started && syncs.first().is_some_and(|s| s.1 <= now))
                .map(|(syncs, _)| syncs[0].1)
                .reduce(f64::min);
            let until = next.unwrap_or(now).min(now);
            // a walk is stepped no further than its deadline at a time: a huge jump of the
            // clock ends it there instead of simulating all of it
            let deadline = (self.current.as_ref()).map_or(f64::INFINITY, |k| self.fails_at(k));
            let stop = until.min(deadline + walker::STEP);
            // (a walker that avoids only those it has seen knows them by name)
            let known: Option<Vec<usize>> = (self.walker.as_ref())
                .filter(|w| w.profile.only_seen)
                .map(|_| {
                    let names = world.known(id).unwrap_or_default();
                    let mut k: Vec<usize> = names
                        .iter()
                        .filter_map(|n| world.crowd().index(n))
                        .collect();
                    k.sort_unstable();
                    k
                });
            let others = walker::Others {
                crowd: world.crowd(),
                me: world.crowd().index(id),
                known: known.as_deref(),
            };
            let ended = self
                .walker
                .as_mut()
                .and_then(|w| w.advance_among(stop, &self.obstacles, Some(others)));
            self.follow_moments(stop, ended);
            if stop < until {
                continue;
            }
            let Some(start) = next else { break };
            match self.unit_starting_at(start) {
                Some(k) => self.start_walk(k, world),
                None => break,
            }
        }
        // a moving target: pursue it
        let order =
            (self.current.as_ref()).and_then(|k| self.units.get(k).map(|u| u.order.clone()));
        if let (Some(o), Some(w)) = (order, self.walker.as_mut()) {
            let from = w.body().at;
            if let Some(goal) = resolve(world, id, &o.target, from) {
                let (place, settled) = self.settling.place(now, &goal);
                self.pursuit.observe(now, goal.face.unwrap_or(place));
                let aim = self.pursuit.aim(place, from, o.speed);
                w.retarget(aim, goal.face, &self.obstacles);
                if let (true, Some(t), Some(key)) = (settled, &goal.taken, &self.current) {
                    let why = format!(
                        "{key}: '{}' stands on the walk's goal '{}'; it stops beside them, outside their personal space",
                        t.by, o.target
                    );
                    self.warnings.push((key.clone(), why));
                }
            }
        }
        // (on whole seconds, which every host's frames meet alike)
        if (now - now.round()).abs() < 1e-6 {
            self.look_round(world);
        }
        let body = self.walker.as_ref().map(|w| w.body());
        self.at = match body {
            Some(b) => Placement {
                position: Vec3::new(b.at.x, at.position.y, b.at.y),
                facing: b.facing,
            },
            None => at,
        };
        self.at
    }

    fn moving(&self) -> bool {
        // (one that made room is "moving" until it is back: it decides to go back on the
        // crowd's grid, which is kept only while someone moves)
        self.current.is_some()
            || self.room.is_some()
            || (self.walker.as_ref()).is_some_and(|w| !w.gait.at_rest(w.body()))
    }

    fn on_its_way(&self) -> bool {
        self.current.is_some()
    }

    fn making_room(&self) -> bool {
        self.current.is_none() && self.room.is_some()
    }

    fn asking(&self) -> Option<Vec2> {
        self.walker.as_ref().and_then(|w| w.asking)
    }

    fn passing(&self) -> Option<crate::world::crowd::doorway::Passing> {
        (self.walker.as_ref()).and_then(|w| w.passing.filter(|_| self.current.is_some()))
    }

    fn heading(&self) -> Option<Vec2> {
        (self.walker.as_ref()).and_then(|w| w.heading.filter(|_| self.current.is_some()))
    }

    fn attending(&self) -> Option<(Vec2, f32)> {
        self.walker.as_ref().and_then(|w| w.attending())
    }

    fn contacts(&self) -> Option<[bool; 2]> {
        let w = self.walker.as_ref().filter(|_| self.walked)?;
        Some(
            w.gait
                .feet
                .map(|f| matches!(f, crate::world::locomotion::gait::Foot::Planted { .. })),
        )
    }
}

impl LocomotionEngine {
    /// Standing (no walk of its own under way), makes room for a walker who asks it, or goes
    /// back once nobody asks (`locomotion::room`); such a walk sends no feedback.
    fn make_room(&mut self, now: f64, world: &World, id: &str, at: Placement) {
        // (decided on the crowd's grid of times only, as the asks are: the same whatever the
        // host's frames)
        if !crate::world::crowd::snapshot::on_grid(now) {
            return;
        }
        if let Some(w) = self.walker.as_mut() {
            w.watching = None;
        }
        if self.current.is_some() {
            self.room = None;
            return;
        }
        let crowd = world.crowd();
        let Some(me) = crowd.index(id) else {
            return;
        };
        // (making room, it watches the walker it makes room for while that one is near)
        let watched = (self.room.as_ref())
            .and_then(|r| crowd.index(r.walker.as_deref()?))
            .map(|i| crowd.agent(i).at)
            .filter(|p| {
                self.room
                    .as_ref()
                    .is_some_and(|r| p.distance(r.home.at) < 2.5)
            });
        if self.room.is_none() && crowd.askers(me).next().is_none() {
            self.back_to_place(world, id, at, now);
            return;
        }
        let obstacles = world.obstacles_for(id);
        let w = self.walker(at, world, now);
        let (body, radius, walking) = (w.body(), w.radius, w.moments().is_some());
        if self.room.as_ref().is_some_and(|r| !r.aside) && !walking {
            // back at its place
            self.room = None;
            return;
        }
        let me = (me, body, radius);
        let walk = make_room(&mut self.room, now, me, crowd, &obstacles);
        let w = self.walker.as_mut().expect("made above");
        w.watching = watched;
        if let Some(walk) = walk {
            if w.start(walk, &obstacles).is_ok() {
                self.obstacles = obstacles;
                self.walked = true;
            }
        }
    }

    /// Standing, asked by nobody, and pressed off the place its last walk arrived at: it steps
    /// back to it (`locomotion::room::back_to`); such a walk sends no feedback.
    fn back_to_place(&mut self, world: &World, id: &str, at: Placement, now: f64) {
        let Some(place) = self.place else {
            return;
        };
        let w = self.walker(at, world, now);
        if w.moments().is_some() {
            return;
        }
        let Some((room, walk)) = back_to(place, w.body()) else {
            return;
        };
        let obstacles = world.obstacles_for(id);
        if w.start(walk, &obstacles).is_ok() {
            self.obstacles = obstacles;
            self.room = Some(room);
        }
    }

    /// Walking, looks round again at what it walks round (groups stand, walk off and form):
    /// when that changed since the walk's route was planned, plans it again.
    fn look_round(&mut self, world: &World) {
        let Some(w) = self.walker.as_ref() else {
            return;
        };
        let Some(walk) = w.walk().cloned() else {
            return;
        };
        let now = self.round(world, w, &walk);
        if Arc::ptr_eq(&now, &self.obstacles) || *now == *self.obstacles {
            return;
        }
        let w = self.walker.as_mut().expect("looked at above");
        if w.reroute(&now) {
            self.obstacles = now;
        }
    }

    /// The key of the unstarted unit starting at `start` (the first added of several).
    fn unit_starting_at(&self, start: f64) -> Option<UnitKey> {
        (self.units.keyed())
            .find(|(syncs, u, _)| !u.started && syncs.first().is_some_and(|s| s.1 == start))
            .map(|(_, _, k)| k.clone())
    }
}

impl Revising for LocomotionEngine {
    fn take_revisions(&mut self, _now: f64) -> Vec<Revision> {
        std::mem::take(&mut self.revisions)
    }
}
