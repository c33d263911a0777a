//! Whether planted feet stay where they were put down, for the tests that walk: each foot's
//! ankle and ball placed by forward kinematics over the frames' poses; while the gait says the
//! foot is down and a point is on the ground (within 5 mm of its height standing), that point
//! must stay where it was put down.

use std::collections::HashMap;

use bml_realizer::character::body::Skeleton;
use bml_realizer::engines::interface::CharacterPose;
use glam::Vec2;

/// The planted points watched so far.
pub struct Slides {
    skeleton: Skeleton,
    /// (foot: 0 left, 1 right; joint) of each point watched.
    points: Vec<(usize, usize)>,
    /// Per (character, joint): its height standing, and where it was put down.
    rest: HashMap<(String, usize), f32>,
    down: HashMap<(String, usize), Vec2>,
    /// The worst slide (m), of which character's joint, when (s).
    pub worst: (f32, String, f64),
    /// How many times a point was put down.
    pub planted: usize,
}

impl Slides {
    /// Nothing watched yet, on the default adult.
    pub fn new() -> Slides {
        let skeleton = Skeleton::adult();
        let points = [
            "l_talocrural",
            "r_talocrural",
            "l_metatarsal",
            "r_metatarsal",
        ]
        .iter()
        .enumerate()
        .map(|(k, n)| (k % 2, skeleton.joint(n).unwrap()))
        .collect();
        Slides {
            skeleton,
            points,
            rest: HashMap::new(),
            down: HashMap::new(),
            worst: (0.0, String::new(), 0.0),
            planted: 0,
        }
    }

    /// Watches the planted points of `poses` at time `t`.
    pub fn frame(&mut self, t: f64, poses: &[CharacterPose]) {
        for p in poses {
            let Some(contacts) = p.contacts else { continue };
            let id = p.character.clone().unwrap_or_default();
            let world = p.pose.world(&self.skeleton);
            for &(side, joint) in &self.points {
                let at = world.positions[joint];
                let key = (id.clone(), joint);
                let ground = *self.rest.entry(key.clone()).or_insert(at.y);
                if contacts[side] && at.y - ground < 0.005 {
                    let from = *self.down.entry(key).or_insert_with(|| {
                        self.planted += 1;
                        Vec2::new(at.x, at.z)
                    });
                    let slide = from.distance(Vec2::new(at.x, at.z));
                    if slide > self.worst.0 {
                        let name = &self.skeleton.joints()[joint].name;
                        self.worst = (slide, format!("{id} {name}"), t);
                    }
                } else {
                    self.down.remove(&key);
                }
            }
        }
    }
}
