//! The world file (`--world`): points, paths, characters with their radii, steering and
//! avoidance profiles, obstacles and conversing groups, read and checked into a [`World`]. Every
//! error names the field it is about.

use std::collections::BTreeMap;
use std::sync::Arc;

use glam::{Vec2, Vec3};
use serde::Deserialize;

use super::{Placement, World, MAX_CHARACTERS, MAX_COORDINATE};
use crate::world::crowd::group::{self, Group, GroupFile, Member};

/// The world file: `{"points": {"user": [0, 1.6, 1.5]}, "paths": {"walker": {"keys": [[0, [1,
/// 1.6, 2]], [4, [-1, 1.6, 2]]]}}, "characters": {"Bob": {"position": [1, 0, 2], "facing":
/// -150}}, "obstacles": [...]}` (`facing` in degrees about +y from facing +z).
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct WorldFile {
    #[serde(default)]
    points: BTreeMap<String, [f64; 3]>,
    #[serde(default)]
    paths: BTreeMap<String, PathFile>,
    #[serde(default)]
    characters: BTreeMap<String, CharacterFile>,
    #[serde(default)]
    obstacles: Vec<crate::world::space::obstacles::ObstacleFile>,
    #[serde(default)]
    profiles: BTreeMap<String, crate::world::crowd::Profile>,
    #[serde(default)]
    groups: Vec<crate::world::crowd::group::GroupFile>,
    /// How characters see (when sight is on).
    #[serde(default)]
    vision: Option<crate::world::perception::Vision>,
    /// Named world values that nets read and write, with their first values.
    #[serde(default, alias = "lights")]
    variables: BTreeMap<String, crate::language::feedback::world::VarValue>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PathFile {
    keys: Vec<(f64, [f64; 3])>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CharacterFile {
    position: [f64; 3],
    /// Degrees about +y from facing +z.
    #[serde(default)]
    facing: f64,
    /// Body radius (m).
    #[serde(default)]
    radius: Option<f64>,
    /// How its steering behaviours combine: `prioritised` (default), `weighted`, `dithering`.
    #[serde(default)]
    steering: Option<String>,
    /// The name of its avoidance profile (in `profiles`).
    #[serde(default)]
    profile: Option<String>,
    /// Its avatar file (glTF/GLB/VRM; relative to the world file).
    #[serde(default)]
    avatar: Option<String>,
}

fn vec3(name: &str, v: [f64; 3]) -> Result<Vec3, String> {
    if v.iter().all(|c| c.abs() <= MAX_COORDINATE) {
        Ok(Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32))
    } else {
        Err(format!(
            "'{name}': coordinates must be numbers of at most {MAX_COORDINATE} m"
        ))
    }
}

impl World {
    /// The default scene with the points, paths, characters and obstacles of a world file (its
    /// points win over the default ones of the same name). Returns the world and how many
    /// obstacles the file lists. The error says what is wrong.
    pub fn from_json(text: &str) -> Result<(World, usize), String> {
        let file: WorldFile = crate::data::from_json(text)?;
        let mut w = World::default();
        for (name, at) in file.points {
            w.set(&name, vec3(&name, at)?);
        }
        for (name, path) in file.paths {
            let keys = path
                .keys
                .into_iter()
                .map(|(t, at)| Ok((t, vec3(&name, at)?)))
                .collect::<Result<Vec<_>, String>>()?;
            w.set_path(&name, keys)?;
        }
        if file.characters.len() > MAX_CHARACTERS {
            return Err(format!(
                "characters: at most {MAX_CHARACTERS} characters, not {}",
                file.characters.len()
            ));
        }
        for (name, p) in &file.profiles {
            p.check().map_err(|e| format!("profiles.{name}: {e}"))?;
        }
        for (name, c) in file.characters {
            let at = vec3(&name, c.position)?;
            if let Some(p) = c.profile.as_deref() {
                let Some(profile) = file.profiles.get(p) else {
                    let known: Vec<&str> = file.profiles.keys().map(String::as_str).collect();
                    return Err(format!(
                        "character '{name}': profile '{p}' is not among the world's profiles ({})",
                        known.join(", ")
                    ));
                };
                Arc::make_mut(&mut w.profiles).insert(name.clone(), *profile);
            }
            if !c.facing.is_finite() || c.facing.abs() > MAX_COORDINATE {
                return Err(format!(
                    "character '{name}': its facing must be a finite number of degrees"
                ));
            }
            w.place(&name, Placement::new(at, c.facing as f32))?;
            if let Some(a) = c.avatar.as_deref() {
                if a.is_empty() || a.len() > 4096 {
                    return Err(format!(
                        "character '{name}': its avatar must name a file (1 to 4096 bytes)"
                    ));
                }
                Arc::make_mut(&mut w.avatars).insert(name.clone(), a.to_string());
            }
            if let Some(r) = c.radius {
                if !(r > 0.0 && r <= 10.0) {
                    return Err(format!(
                        "character '{name}': its radius must be above 0 and at most 10 m"
                    ));
                }
                Arc::make_mut(&mut w.radii).insert(name.clone(), r as f32);
            }
            if let Some(c) = c.steering.as_deref() {
                use crate::world::locomotion::steering::Combine;
                let combine = match c {
                    "prioritised" => Combine::Prioritised,
                    "weighted" => Combine::WeightedSum,
                    "dithering" => Combine::Dithering,
                    other => {
                        return Err(format!(
                            "character '{name}': steering '{other}' is not one of prioritised, weighted, dithering"
                        ))
                    }
                };
                Arc::make_mut(&mut w.combiners).insert(name.clone(), combine);
            }
        }
        if file.obstacles.len() > crate::world::space::obstacles::MAX_OBSTACLES {
            return Err(format!(
                "obstacles: at most {} obstacles, not {}",
                crate::world::space::obstacles::MAX_OBSTACLES,
                file.obstacles.len()
            ));
        }
        let list = (file.obstacles.iter().enumerate())
            .map(|(i, o)| o.obstacle(i))
            .collect::<Result<Vec<_>, String>>()?;
        w.variables = Arc::new(file.variables);
        if let Some(v) = file.vision {
            v.check()?;
            w.vision = Some(Arc::new(v));
        }
        let n = list.len();
        w.set_obstacles(crate::world::space::Obstacles::new(list));
        w.add_groups(file.groups)?;
        Ok((w, n))
    }

    /// Adds the world file's declared `groups` and the conversing groups found among the
    /// characters it places (all of them stand at the start; see [`crate::world::crowd::group`]); a
    /// character is in one group at most, declared groups first.
    fn add_groups(&mut self, declared: Vec<GroupFile>) -> Result<(), String> {
        if declared.len() > MAX_CHARACTERS / 2 {
            return Err(format!(
                "groups: at most {} groups, not {}",
                MAX_CHARACTERS / 2,
                declared.len()
            ));
        }
        let mut taken: BTreeMap<String, usize> = BTreeMap::new();
        let mut groups = Vec::new();
        for (i, g) in declared.into_iter().enumerate() {
            let g = g.group(i, |id| self.characters.contains_key(id))?;
            for m in &g.members {
                if let Some(j) = taken.insert(m.clone(), i) {
                    return Err(format!(
                        "groups[{i}]: member '{m}' is already in groups[{j}]"
                    ));
                }
            }
            groups.push(g);
        }
        let free: Vec<String> = (self.characters.keys())
            .filter(|id| !taken.contains_key(*id))
            .cloned()
            .collect();
        let members: Vec<Member> = free.iter().map(|id| self.member(id)).collect();
        groups.extend(group::found(&free, &members));
        self.groups = Arc::new(groups);
        Ok(())
    }

    /// Character `id` as a member of a group: where it stands and faces, its radius.
    pub(crate) fn member(&self, id: &str) -> Member {
        let at = self.placement(id);
        let f = at.facing;
        Member {
            at: Vec2::new(at.position.x, at.position.z),
            facing: Vec2::new(f.sin(), f.cos()),
            radius: self.radius(id),
        }
    }

    /// The groups of the world: declared and found.
    pub fn groups(&self) -> &[Group] {
        &self.groups
    }
}
