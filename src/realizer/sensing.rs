//! The realizer's sensing stage: at the start of each tick, before any character moves, the
//! characters whose time has come look at the world as the previous frame left it (their
//! bodies in their last poses, the others placed by the world at rest), and what they see
//! changes is reported. Off until a host turns it on ([`Realizer::set_perception`]).

use std::collections::BTreeMap;

use crate::character::body::Pose;
use crate::engines::interface::Frame;
use crate::language::feedback::Feedback;
use crate::world::perception::{Perception, Remembered, Scene, Thing, Vision};

use super::Realizer;

/// What the sensing stage keeps between ticks.
pub(super) struct Sensing {
    perception: Perception,
    /// Whether changes are reported as feedback.
    report: bool,
    /// Each character's pose in the last frame (world coordinates).
    poses: BTreeMap<String, Pose>,
}

impl Realizer {
    /// Turns synthetic vision on with `vision` (`None`: off); `report` sends perception
    /// feedback (what a character sees, when it changes). `Err` names the bad setting.
    pub fn set_perception(&mut self, vision: Option<Vision>, report: bool) -> Result<(), String> {
        self.sensing = match vision {
            None => None,
            Some(v) => {
                v.check()?;
                Some(Box::new(Sensing {
                    perception: Perception::new(v),
                    report,
                    poses: BTreeMap::new(),
                }))
            }
        };
        Ok(())
    }

    /// The characters' sight, when it is on.
    pub fn perception(&self) -> Option<&Perception> {
        self.sensing.as_ref().map(|s| &s.perception)
    }

    /// What `character` saw at its last look (empty when sight is off or before its first).
    pub fn seen(&self, character: &str) -> &[String] {
        self.perception().map_or(&[], |p| p.seen(character))
    }

    /// What `character` remembers having seen, oldest first.
    pub fn remembered(&self, character: &str) -> Vec<Remembered> {
        self.perception()
            .map_or_else(Vec::new, |p| p.remembered(character))
    }

    /// The scene as the previous frame left it: every character (its last pose, or at rest
    /// where the world places it) and every named point, among the world's obstacles.
    fn scene(&self, poses: &BTreeMap<String, Pose>) -> Scene {
        let mut ids: Vec<&str> = self.everyone().collect();
        ids.sort_unstable();
        let mut things = Vec::with_capacity(ids.len());
        for id in ids {
            let skeleton = self
                .characters
                .get(id)
                .map_or(&self.skeleton, |m| m.skeleton());
            let body = match poses.get(id) {
                Some(pose) => Thing::body(id, skeleton, pose),
                None => {
                    let at = self.world.placement(id);
                    let mut pose = Pose::rest(skeleton);
                    pose.root = at.to_world(pose.root);
                    pose.rotations[0] = at.rotation() * pose.rotations[0];
                    Thing::body(id, skeleton, &pose)
                }
            };
            things.push((body.0, Some(body.1)));
        }
        for (name, at) in self.world.points() {
            if !self.world.is_placed(name) && !self.characters.contains_key(name) {
                things.push((Thing::point(name, at), None));
            }
        }
        Scene::new(things, self.world.obstacles_shared().clone())
    }

    /// The sensing stage of a tick at `now` (before the characters step).
    pub(super) fn sense(&mut self, now: f64) {
        // walkers that avoid only those they have seen need sight
        if self.sensing.is_none() && self.world.wants_sight() {
            let vision = self.world.vision();
            // (the world file's vision settings were checked when it was read)
            let _ = self.set_perception(Some(vision), false);
        }
        let Some(mut s) = self.sensing.take() else {
            return;
        };
        // (the scene is made only when someone looks or someone new is to be met)
        if !s.perception.due(now, self.everyone().count()) {
            self.sensing = Some(s);
            return;
        }
        let scene = self.scene(&s.poses);
        let mut changes = Vec::new();
        s.perception.sense(now, &scene, &mut changes);
        if self.world.wants_sight() {
            let known = (scene.things().iter().enumerate())
                .filter(|(i, _)| scene.eyes(*i).is_some())
                .map(|(_, t)| {
                    let mut ids: Vec<String> = s.perception.seen(&t.id).to_vec();
                    ids.extend(s.perception.remembered(&t.id).into_iter().map(|r| r.id));
                    ids.sort();
                    ids.dedup();
                    (t.id.clone(), ids)
                })
                .collect();
            self.world_mut().set_known(known);
        }
        if s.report {
            self.unframed
                .extend(changes.into_iter().map(Feedback::World));
        }
        self.sensing = Some(s);
    }

    /// Keeps the frame's poses for the next look.
    pub(super) fn keep_poses(&mut self, frame: &Frame) {
        if let Some(s) = self.sensing.as_mut() {
            for p in &frame.poses {
                let id = p.character.clone().unwrap_or_default();
                s.poses.insert(id, p.pose.clone());
            }
        }
    }
}
