//! The world the characters act in: named points (gaze and pointing targets) that the host places
//! and moves every frame. Characters stand at the origin facing +z (y up, metres).

use std::collections::BTreeMap;

use glam::Vec3;

/// Named points in world coordinates.
#[derive(Debug, Clone, PartialEq)]
pub struct World {
    points: BTreeMap<String, Vec3>,
}

impl Default for World {
    /// A small default scene: `bluebox` (the target of the RealizerTester files), a `speaker`
    /// and a `user` in front of the character.
    fn default() -> Self {
        let mut w = World::empty();
        w.set("bluebox", Vec3::new(0.6, 1.2, 1.2));
        w.set("speaker", Vec3::new(-0.4, 1.6, 1.5));
        w.set("user", Vec3::new(0.0, 1.6, 1.5));
        w
    }
}

impl World {
    /// A world without points.
    pub fn empty() -> Self {
        World {
            points: BTreeMap::new(),
        }
    }

    /// Places (or moves) point `name`.
    pub fn set(&mut self, name: &str, at: Vec3) {
        self.points.insert(name.to_string(), at);
    }

    /// Removes point `name`.
    pub fn remove(&mut self, name: &str) {
        self.points.remove(name);
    }

    /// Where point `name` is.
    pub fn get(&self, name: &str) -> Option<Vec3> {
        self.points.get(name).copied()
    }

    /// Every point, by name.
    pub fn points(&self) -> impl Iterator<Item = (&str, Vec3)> {
        self.points.iter().map(|(k, v)| (k.as_str(), *v))
    }
}
