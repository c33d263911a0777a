//! The world the characters act in: named points (gaze, pointing and head-direction targets) that
//! the host places and moves, points that move by themselves along keyed paths, and where each
//! character stands. A character stands at the origin facing +z (y up, metres) unless the world
//! places it elsewhere; a placed character is itself a target, at its eyes, so characters can
//! look and point at each other. Each character's engines see the world from where it stands
//! ([`World::seen_from`]). A world can be read from a JSON world file.
//!
//! It is also the floor of what moves and looks in the world, below the engines and above the
//! characters: the geometry of space ([`space`]: obstacles, routes, distances), walking
//! ([`locomotion`]), walkers sharing space ([`crowd`]), synthetic vision ([`perception`]) and
//! the nets that sequence behaviour by watching the world ([`nets`]). The [`World`] itself sits
//! on top of them: it holds their shared state.

use std::collections::BTreeMap;
use std::sync::Arc;

use glam::Vec3;

pub mod crowd;
pub mod locomotion;
pub mod nets;
pub mod perception;
pub mod space;

mod file;

pub use crate::character::body::Placement;

/// Where a placed character is as a target: the point between the default adult's eyes, in its
/// own frame (`gaze::eyes_at_rest` of the adult, to the centimetre).
pub const CHARACTER_EYES: Vec3 = Vec3::new(0.0, 1.64, 0.09);

/// Named points in world coordinates, some of them moving along paths, and the characters'
/// placements.
///
/// Cloning is cheap (the maps are shared until one is changed), and so is a character's view of
/// it ([`seen_from_at`](Self::seen_from_at)): the view shares the maps and turns what is read
/// into its frame, so that a crowd's views cost nothing per frame beyond their reads.
#[derive(Debug, Clone, PartialEq)]
pub struct World {
    /// Points, in world coordinates.
    points: Arc<BTreeMap<String, Vec3>>,
    /// Points that move: their keys (time in seconds, position), in time order (shared: a
    /// world is copied every frame someone walks, its paths are not).
    paths: Arc<BTreeMap<String, Vec<(f64, Vec3)>>>,
    /// Where characters stand, in world coordinates (the others stand at the origin facing +z).
    characters: Arc<BTreeMap<String, Placement>>,
    /// Body radius of characters the world file gives one (m).
    radii: Arc<BTreeMap<String, f32>>,
    /// How the steering of characters the world file gives a combiner combines.
    combiners: Arc<BTreeMap<String, crate::world::locomotion::steering::Combine>>,
    /// Obstacles, in world coordinates (a view from a character has none).
    obstacles: Arc<crate::world::space::Obstacles>,
    /// The avoidance profile of characters the world file gives one.
    profiles: Arc<BTreeMap<String, crate::world::crowd::Profile>>,
    /// The avatar file of characters the world file gives one (as written there).
    avatars: Arc<BTreeMap<String, String>>,
    /// Groups of characters: declared in the world file or found there.
    groups: Arc<Vec<crate::world::crowd::group::Group>>,
    /// Every character as walkers see it this frame, in world coordinates (a view has none).
    crowd: Arc<crate::world::crowd::Crowd>,
    /// How characters see, if the world file says (`"vision"`).
    vision: Option<Arc<crate::world::perception::Vision>>,
    /// World variables' first values (the world file's `"variables"`).
    variables: Arc<BTreeMap<String, crate::language::feedback::world::VarValue>>,
    /// Whom each character has seen or remembers (sorted), for walkers that avoid only those
    /// (written by the realizer's sensing stage).
    known: Arc<BTreeMap<String, Vec<String>>>,
    /// The frame things are read and written in: the origin for the world itself, where a
    /// character stands for its view.
    frame: Placement,
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

/// A character's body radius unless the world file gives one (m).
pub const DEFAULT_RADIUS: f32 = 0.25;

/// How [`World::unknown_target`]'s sentence begins (engines that refuse a unit for an unknown
/// target report NO_SUCH_TARGET by it).
pub const UNKNOWN_TARGET: &str = "there is no target";

/// Most characters a world file may place (the most a crowd holds).
pub const MAX_CHARACTERS: usize = crate::world::crowd::snapshot::MAX_AGENTS;

/// Longest list of keys a path may have.
pub const MAX_PATH_KEYS: usize = 100_000;

pub use crate::world::space::MAX_COORDINATE;

impl World {
    /// A world without points.
    pub fn empty() -> Self {
        World {
            points: Default::default(),
            paths: Default::default(),
            characters: Default::default(),
            radii: Default::default(),
            combiners: Default::default(),
            obstacles: Default::default(),
            profiles: Default::default(),
            avatars: Default::default(),
            groups: Default::default(),
            crowd: Default::default(),
            vision: None,
            variables: Default::default(),
            known: Default::default(),
            frame: Placement::default(),
        }
    }

    /// Whether some character's profile avoids only those it has seen (sight is then needed).
    pub fn wants_sight(&self) -> bool {
        self.profiles.values().any(|p| p.only_seen)
    }

    /// Whom character `id` has seen or remembers, once sight has looked (sorted).
    pub fn known(&self, id: &str) -> Option<&[String]> {
        self.known.get(id).map(Vec::as_slice)
    }

    /// Sets whom each character has seen or remembers.
    pub fn set_known(&mut self, known: BTreeMap<String, Vec<String>>) {
        self.known = Arc::new(known);
    }

    /// The world variables' first values (the world file's `"variables"`).
    pub fn variables(&self) -> &BTreeMap<String, crate::language::feedback::world::VarValue> {
        &self.variables
    }

    /// How characters see: the world file's `"vision"`, else the defaults.
    pub fn vision(&self) -> crate::world::perception::Vision {
        self.vision.as_deref().cloned().unwrap_or_default()
    }

    /// Character `id`'s avoidance profile (the defaults unless the world file names one).
    pub fn profile(&self, id: &str) -> crate::world::crowd::Profile {
        self.profiles.get(id).copied().unwrap_or_default()
    }

    /// Every character as walkers see it this frame (world coordinates; empty in a view).
    pub fn crowd(&self) -> &Arc<crate::world::crowd::Crowd> {
        &self.crowd
    }

    /// Sets the crowd walkers see; a group found among the characters standing at the start
    /// breaks up for good once the crowd says one of them is on a walk of its own.
    pub fn set_crowd(&mut self, crowd: crate::world::crowd::Crowd) {
        // (a group found among people who happened to stand so breaks up for good when one of
        // them walks off: met again elsewhere, its space was reckoned from where they stood
        // then, and held one who stood aside for a walker from going back to its place)
        let left = |g: &crate::world::crowd::group::Group| {
            g.found
                && (g.members.iter()).any(|m| crowd.index(m).is_some_and(|i| crowd.on_its_way(i)))
        };
        if self.groups.iter().any(left) {
            let kept = self.groups.iter().filter(|g| !left(g)).cloned().collect();
            self.groups = Arc::new(kept);
        }
        self.crowd = Arc::new(crowd);
    }

    /// The obstacles (world coordinates).
    pub fn obstacles(&self) -> &crate::world::space::Obstacles {
        &self.obstacles
    }

    /// The obstacles (shared).
    pub fn obstacles_shared(&self) -> &Arc<crate::world::space::Obstacles> {
        &self.obstacles
    }

    /// What character `id` walks round: the obstacles and the space of every conversing group
    /// it is not in whose members all stand, as those groups stand now (each a circle through
    /// its members' far sides),
    /// but for a space it already stands in (it walks out of that one; taken as an obstacle,
    /// it threw the character out of it 0.5 m in one frame).
    pub fn obstacles_for(&self, id: &str) -> Arc<crate::world::space::Obstacles> {
        use crate::world::space::obstacles::{Obstacle, Shape};
        let p = self.placement(id).position;
        let (here, radius) = (glam::Vec2::new(p.x, p.z), self.radius(id));
        // (a member on the move breaks the group up, or it walks on together: no standing
        // conversation to walk round)
        let moving = |m: &String| {
            (self.crowd.index(m)).is_some_and(|i| {
                self.crowd.agent(i).velocity.length() > crate::world::crowd::group::STILL
            })
        };
        let spaces: Vec<Obstacle> = (self.groups.iter())
            .filter(|g| g.members.binary_search_by(|m| m.as_str().cmp(id)).is_err())
            .filter(|g| !g.members.iter().any(moving))
            .filter_map(|g| {
                let members: Vec<_> = (g.members.iter())
                    .filter(|m| self.is_placed(m))
                    .map(|m| self.member(m))
                    .collect();
                g.space(&members)
            })
            .filter(|s| {
                here.distance(s.centre) >= s.outer + crate::world::crowd::group::PASSING + radius
            })
            .map(|s| Obstacle {
                shape: Shape::Circle {
                    centre: s.centre,
                    radius: s.outer + crate::world::crowd::group::PASSING,
                },
                height: 0.0,
            })
            .collect();
        if spaces.is_empty() {
            return self.obstacles.clone();
        }
        let mut all = self.obstacles.all().to_vec();
        all.extend(spaces);
        Arc::new(crate::world::space::Obstacles::new(all))
    }

    /// Sets the obstacles.
    pub fn set_obstacles(&mut self, obstacles: crate::world::space::Obstacles) {
        self.obstacles = Arc::new(obstacles);
    }

    /// The avatar file the world file gives character `id` (as written there; a host resolves a
    /// relative one against the world file's directory).
    pub fn avatar(&self, id: &str) -> Option<&str> {
        self.avatars.get(id).map(String::as_str)
    }

    /// Character `id`'s body radius ([`DEFAULT_RADIUS`] unless the world file gives one).
    pub fn radius(&self, id: &str) -> f32 {
        self.radii.get(id).copied().unwrap_or(DEFAULT_RADIUS)
    }

    /// How character `id`'s steering behaviours combine (prioritised unless the world file
    /// says otherwise).
    pub fn combiner(&self, id: &str) -> crate::world::locomotion::steering::Combine {
        (self.combiners.get(id).copied())
            .unwrap_or(crate::world::locomotion::steering::Combine::Prioritised)
    }

    /// Places character `id` (the default character is `""`). A point of the same name keeps
    /// its place as a target; the character is a target where no point has its name.
    pub fn place(&mut self, id: &str, at: Placement) -> Result<(), String> {
        if !(at.position.is_finite() && at.facing.is_finite()) {
            return Err(format!(
                "character '{id}': its position and facing must be finite numbers"
            ));
        }
        let at = Placement {
            position: self.frame.to_world(at.position),
            facing: at.facing + self.frame.facing,
        };
        Arc::make_mut(&mut self.characters).insert(id.to_string(), at);
        Ok(())
    }

    /// Takes character `id` out of the world (it stands nowhere, and is no one's obstacle).
    pub fn unplace(&mut self, id: &str) {
        if self.characters.contains_key(id) {
            Arc::make_mut(&mut self.characters).remove(id);
        }
    }

    /// Where character `id` stands (the origin facing +z unless placed).
    pub fn placement(&self, id: &str) -> Placement {
        let at = self.characters.get(id).copied().unwrap_or_default();
        self.local(at)
    }

    /// A placement in world coordinates, in this world's frame.
    fn local(&self, at: Placement) -> Placement {
        if self.frame.is_origin() {
            return at;
        }
        Placement {
            position: self.frame.to_local(at.position),
            facing: at.facing - self.frame.facing,
        }
    }

    /// Whether character `id` is placed.
    pub fn is_placed(&self, id: &str) -> bool {
        self.characters.contains_key(id)
    }

    /// Whether there is a point named `name` (a character's place is not one).
    pub fn has_point(&self, name: &str) -> bool {
        self.points.contains_key(name)
    }

    /// Every placed character, by id.
    pub fn placements(&self) -> impl Iterator<Item = (&str, Placement)> {
        self.characters
            .iter()
            .map(|(k, v)| (k.as_str(), self.local(*v)))
    }

    /// The world as character `id` sees it now: every point and placement in its own frame
    /// (where it stands is the origin, the way it faces +z). The paths stay behind: a point on
    /// a path is where the path has it now, and it is this world that moves along them (a view
    /// is made again when it does).
    pub fn seen_from(&self, id: &str) -> World {
        self.seen_from_at(self.placement(id))
    }

    /// The world as seen by a character standing at `from` (see [`seen_from`](Self::seen_from)).
    pub fn seen_from_at(&self, from: Placement) -> World {
        World {
            points: self.points.clone(),
            paths: Default::default(),
            radii: self.radii.clone(),
            combiners: self.combiners.clone(),
            obstacles: Default::default(),
            profiles: self.profiles.clone(),
            avatars: self.avatars.clone(),
            groups: self.groups.clone(),
            crowd: Default::default(),
            vision: self.vision.clone(),
            variables: self.variables.clone(),
            known: self.known.clone(),
            characters: self.characters.clone(),
            // `from` is given in this world's frame
            frame: Placement {
                position: self.frame.to_world(from.position),
                facing: self.frame.facing + from.facing,
            },
        }
    }

    /// Places (or moves) point `name`.
    pub fn set(&mut self, name: &str, at: Vec3) {
        let at = self.frame.to_world(at);
        Arc::make_mut(&mut self.points).insert(name.to_string(), at);
    }

    /// Makes `name` a point that moves along `keys` (time in seconds, position): linearly
    /// between keys, resting at the first before it and at the last after it. Keys must be
    /// in time order with finite times; at least one, at most [`MAX_PATH_KEYS`].
    pub fn set_path(&mut self, name: &str, keys: Vec<(f64, Vec3)>) -> Result<(), String> {
        if keys.is_empty() || keys.len() > MAX_PATH_KEYS {
            return Err(format!(
                "path '{name}' needs 1 to {MAX_PATH_KEYS} keys, not {}",
                keys.len()
            ));
        }
        if keys.iter().any(|k| !k.0.is_finite()) || keys.windows(2).any(|w| w[1].0 < w[0].0) {
            return Err(format!(
                "path '{name}': key times must be finite and in increasing order"
            ));
        }
        let keys: Vec<(f64, Vec3)> = (keys.into_iter())
            .map(|(t, p)| (t, self.frame.to_world(p)))
            .collect();
        Arc::make_mut(&mut self.points).insert(name.to_string(), keys[0].1);
        Arc::make_mut(&mut self.paths).insert(name.to_string(), keys);
        Ok(())
    }

    /// Whether some point that moves along a path is elsewhere at time `t` than it is now.
    pub fn moves_at(&self, t: f64) -> bool {
        self.paths
            .iter()
            .any(|(name, keys)| self.points.get(name) != Some(&along(keys, t)))
    }

    /// Puts every point that has a path where its path is at time `t`.
    pub fn move_to(&mut self, t: f64) {
        let points = Arc::make_mut(&mut self.points);
        for (name, keys) in self.paths.iter() {
            if let Some(p) = points.get_mut(name) {
                *p = along(keys, t);
            }
        }
    }

    /// Removes point `name` (and its path).
    pub fn remove(&mut self, name: &str) {
        if self.points.contains_key(name) {
            Arc::make_mut(&mut self.points).remove(name);
        }
        if self.paths.contains_key(name) {
            Arc::make_mut(&mut self.paths).remove(name);
        }
    }

    /// Where point `name` is; a placed character without a point of its name is a target at
    /// its eyes ([`CHARACTER_EYES`]).
    pub fn get(&self, name: &str) -> Option<Vec3> {
        (self.points.get(name).copied())
            .or_else(|| (self.characters.get(name)).map(|c| c.to_world(CHARACTER_EYES)))
            .map(|p| self.frame.to_local(p))
    }

    /// Every point, by name.
    pub fn points(&self) -> impl Iterator<Item = (&str, Vec3)> {
        (self.points.iter()).map(|(k, v)| (k.as_str(), self.frame.to_local(*v)))
    }

    /// Every point that moves along a path, with its keys (time, position) in time order.
    pub fn paths(&self) -> impl Iterator<Item = (&str, &[(f64, Vec3)])> {
        self.paths.iter().map(|(k, v)| (k.as_str(), v.as_slice()))
    }

    /// The sentence for a target the world does not have, listing the points it has.
    /// It starts with [`UNKNOWN_TARGET`].
    pub fn unknown_target(&self, target: &str) -> String {
        let known: Vec<&str> = (self.points.keys().chain(self.characters.keys()))
            .map(String::as_str)
            .collect();
        format!(
            "{UNKNOWN_TARGET} '{target}' in the world (it has {}; add points with --world or Realizer::world_mut)",
            known.join(", ")
        )
    }
}

/// The position along `keys` (time order, at least one) at time `t`.
fn along(keys: &[(f64, Vec3)], t: f64) -> Vec3 {
    let after = keys.partition_point(|k| k.0 <= t);
    match (after.checked_sub(1).map(|i| keys[i]), keys.get(after)) {
        (None, _) => keys[0].1,
        (Some(k), None) => k.1,
        (Some((t0, p0)), Some(&(t1, p1))) => {
            let a = if t1 > t0 { (t - t0) / (t1 - t0) } else { 1.0 };
            p0.lerp(p1, a as f32)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_path_point_moves_linearly_between_its_keys_and_rests_outside_them() {
        let text = r#"{"points": {"lamp": [0, 2, 1]},
            "paths": {"walker": {"keys": [[1, [1, 1.6, 2]], [5, [-1, 1.6, 2]]]}}}"#;
        let (mut w, obstacles) = World::from_json(text).unwrap();
        assert_eq!(obstacles, 0);
        assert_eq!(w.get("lamp"), Some(Vec3::new(0.0, 2.0, 1.0)));
        assert!(w.get("bluebox").is_some(), "the default scene stays");
        for (t, x) in [
            (0.0, 1.0),
            (1.0, 1.0),
            (2.0, 0.5),
            (3.0, 0.0),
            (5.0, -1.0),
            (9.0, -1.0),
        ] {
            w.move_to(t);
            let p = w.get("walker").unwrap();
            assert!(
                (p.x - x).abs() < 1e-6 && (p.y - 1.6).abs() < 1e-6,
                "{t}: {p}"
            );
        }
        // resting after its last key (at 9 s now), it no longer moves; inside its keys it does
        assert!(!w.moves_at(9.0) && !w.moves_at(20.0));
        assert!(w.moves_at(3.0));
    }

    #[test]
    fn bad_world_files_say_what_is_wrong() {
        for (text, says) in [
            (r#"{"points": {"a": [0, 1]}}"#, "expected"),
            (
                r#"{"paths": {"w": {"keys": [[2, [0, 0, 0]], [1, [0, 0, 0]]]}}}"#,
                "increasing",
            ),
            (r#"{"paths": {"w": {"keys": []}}}"#, "1 to"),
            (r#"{"pionts": {}}"#, "unknown field"),
        ] {
            let e = World::from_json(text).unwrap_err();
            assert!(e.contains(says), "{text}: {e}");
        }
    }

    use proptest::prelude::*;

    fn point() -> impl Strategy<Value = Vec3> {
        (-20.0f32..20.0, -1.0f32..3.0, -20.0f32..20.0).prop_map(|(x, y, z)| Vec3::new(x, y, z))
    }

    proptest! {
        /// Seen from a placed character, every point, moving point and other character is where
        /// its placement takes the world point into its frame; and back again.
        #[test]
        fn the_world_seen_from_a_character_is_the_world_in_its_frame(
            at in point(), facing in -720.0f32..720.0, p in point(), other in point(),
            other_facing in -180.0f32..180.0,
        ) {
            let mut w = World::empty();
            w.set("p", p);
            w.set_path("walker", vec![(0.0, p), (1.0, other)]).unwrap();
            let me = Placement::new(Vec3::new(at.x, 0.0, at.z), facing);
            w.place("me", me).unwrap();
            w.place("you", Placement::new(Vec3::new(other.x, 0.0, other.z), other_facing)).unwrap();
            let seen = w.seen_from("me");
            for name in ["p", "walker", "you"] {
                let (world, local) = (w.get(name).unwrap(), seen.get(name).unwrap());
                prop_assert!(local.distance(me.to_local(world)) < 1e-4, "{}", name);
                prop_assert!(me.to_world(local).distance(world) < 1e-4, "{}", name);
            }
            // the character itself is at its own frame's eyes
            prop_assert!(seen.get("me").unwrap().distance(CHARACTER_EYES) < 1e-4);
            // a point on a path, once the world has moved it, is seen where it went
            w.move_to(0.5);
            let moved = w.seen_from("me").get("walker").unwrap();
            prop_assert!(moved.distance(me.to_local(p.lerp(other, 0.5))) < 1e-4);
            // a view of a view is the view from the placement they compose to, and what is
            // placed in a view is placed in its frame
            let you = seen.placement("you");
            let twice = seen.seen_from_at(you);
            let direct = w.seen_from("you");
            prop_assert!(twice.get("p").unwrap().distance(direct.get("p").unwrap()) < 1e-3);
            let mut view = w.seen_from("me");
            view.set("q", Vec3::Z);
            view.place("them", Placement::new(Vec3::X, 30.0)).unwrap();
            let them = view.placement("them");
            prop_assert!(view.get("q").unwrap().distance(Vec3::Z) < 1e-4);
            prop_assert!(them.position.distance(Vec3::X) < 1e-4);
            prop_assert!((them.facing - 30f32.to_radians()).abs() < 1e-4);
        }
    }

    #[test]
    fn a_world_file_places_characters_and_refuses_far_coordinates() {
        let (w, _) =
            World::from_json(r#"{"characters": {"Bob": {"position": [1, 0, 2], "facing": 90}}}"#)
                .unwrap();
        let bob = w.placement("Bob");
        assert!(
            bob.to_world(Vec3::Z).distance(Vec3::new(2.0, 0.0, 2.0)) < 1e-6,
            "facing 90 faces +x"
        );
        assert!(w.placement("Alice").is_origin());
        for bad in [
            r#"{"characters": {"Bob": {"position": [1e300, 0, 2]}}}"#,
            r#"{"points": {"far": [0, 1e10, 0]}}"#,
            r#"{"characters": {"Bob": {"position": [0, 0, 0], "facing": 1e300}}}"#,
        ] {
            let e = World::from_json(bad).unwrap_err();
            assert!(e.contains("Bob") || e.contains("far"), "{bad}: {e}");
        }
    }
}
