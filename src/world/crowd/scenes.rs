//! Standard encounters to measure crowd avoidance on, named after SteerBench's test cases and
//! written here (positions in metres on the ground, x and z): head-on, crossing, overtaking,
//! four-way confusion, two oncoming groups, two ways through a doorway and along a hallway, a
//! bottleneck, a conversing group across the path, and circles whose walkers all swap to the
//! opposite side. Each is a list of walkers (start, goal, preferred speed), all of radius
//! 0.25 m, with the walls they walk round and the spaces of the groups that stand there.

use glam::Vec2;

use super::group::Space;
use crate::world::space::obstacles::{Obstacle, Obstacles, Shape};

/// A scene: who walks where, among which walls, round which conversing groups.
#[derive(Debug, Clone, PartialEq)]
pub struct Scene {
    /// Its name.
    pub name: &'static str,
    /// The walkers; a walker whose goal is its start stands (a group's member).
    pub walks: Vec<Walk>,
    /// The walls.
    pub walls: Vec<Obstacle>,
    /// The spaces of conversing groups.
    pub spaces: Vec<Space>,
}

fn scene(name: &'static str, walks: Vec<Walk>) -> Scene {
    Scene {
        name,
        walks,
        walls: Vec::new(),
        spaces: Vec::new(),
    }
}

impl Scene {
    /// What its walkers walk round: the walls, and each group's space as a circle.
    pub fn obstacles(&self) -> Obstacles {
        let spaces = self.spaces.iter().map(|s| Obstacle {
            shape: Shape::Circle {
                centre: s.centre,
                radius: s.outer,
            },
            height: 0.0,
        });
        Obstacles::new(self.walls.iter().copied().chain(spaces).collect())
    }
}

fn wall(a: (f32, f32), b: (f32, f32)) -> Obstacle {
    Obstacle {
        shape: Shape::Segment {
            a: Vec2::from(a),
            b: Vec2::from(b),
        },
        height: 2.0,
    }
}

/// One walker of a scene: where it starts, where it goes, how fast it likes to walk (m/s).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Walk {
    /// Start.
    pub from: Vec2,
    /// Goal.
    pub to: Vec2,
    /// Preferred speed (m/s).
    pub speed: f32,
}

fn walk(from: (f32, f32), to: (f32, f32), speed: f32) -> Walk {
    Walk {
        from: Vec2::from(from),
        to: Vec2::from(to),
        speed,
    }
}

/// `n` walkers evenly on a circle of radius `r`, each going to the opposite point.
pub fn circle(n: usize, r: f32) -> Vec<Walk> {
    (0..n)
        .map(|k| {
            let a = std::f32::consts::TAU * k as f32 / n as f32;
            let p = (r * a.sin(), r * a.cos());
            walk(p, (-p.0, -p.1), 1.3)
        })
        .collect()
}

/// Walkers in a doorway's two ways: a wall across z = 0 with a door 1.2 m wide in the middle,
/// three going each way.
fn doorway() -> Scene {
    let walks = (0..3)
        .flat_map(|k| {
            let x = k as f32 - 1.0;
            [
                walk((x, -5.0 - 0.3 * k as f32), (-x, 5.0), 1.3),
                walk((x + 0.2, 5.0 + 0.3 * k as f32), (-x, -5.0), 1.3),
            ]
        })
        .collect();
    Scene {
        walls: vec![wall((-8.0, 0.0), (-0.6, 0.0)), wall((0.6, 0.0), (8.0, 0.0))],
        ..scene("doorway two-way", walks)
    }
}

/// A hallway 3 m wide and 20 m long, four walking each way.
fn hallway() -> Scene {
    let walks = (0..4)
        .flat_map(|k| {
            let (x, z) = (0.8 * (k % 2) as f32 - 0.4, -9.0 + 1.2 * (k / 2) as f32);
            [
                walk((x, z), (x, -z), 1.3),
                walk((0.1 - x, -z), (0.1 - x, z), 1.3),
            ]
        })
        .collect();
    Scene {
        walls: vec![
            wall((-1.5, -10.0), (-1.5, 10.0)),
            wall((1.5, -10.0), (1.5, 10.0)),
        ],
        ..scene("hallway two-way", walks)
    }
}

/// Twenty people leaving a room through a gap 1 m wide in a wall across z = 0.
fn bottleneck() -> Scene {
    let walks = (0..20)
        .map(|k| {
            let (x, z) = ((k % 5) as f32 - 2.0, -3.0 - (k / 5) as f32);
            walk((x, z), (2.0 * x, 6.0 + 2.0 * (k / 5) as f32), 1.3)
        })
        .collect();
    Scene {
        walls: vec![wall((-8.0, 0.0), (-0.5, 0.0)), wall((0.5, 0.0), (8.0, 0.0))],
        ..scene("bottleneck", walks)
    }
}

/// Three people conversing round the origin on a ring of 0.9 m, and six walking across them
/// from two sides.
fn conversing_group() -> Scene {
    let mut walks: Vec<Walk> = (0..3)
        .map(|k| {
            let a = (30.0 + 120.0 * k as f32).to_radians();
            let at = (0.9 * a.sin(), 0.9 * a.cos());
            walk(at, at, 1.3)
        })
        .collect();
    for k in 0..3 {
        let d = k as f32 - 1.0;
        walks.push(walk((d, -6.0 - k as f32), (-d, 6.0), 1.3));
        walks.push(walk((-6.0 - k as f32, d), (6.0, -d), 1.3));
    }
    let space = Space {
        centre: Vec2::ZERO,
        inner: 0.65,
        outer: 1.15,
    };
    Scene {
        spaces: vec![space],
        ..scene("conversing group", walks)
    }
}

/// Every scene.
pub fn all() -> Vec<Scene> {
    let group = |x0: f32, z0: f32, dz: f32| {
        (0..5).map(move |k| {
            let (x, z) = (x0 + (k % 3) as f32 * 0.8 - 0.8, z0 + (k / 3) as f32 * dz);
            walk((x, z), (x, z - 14.0 * dz.signum()), 1.3)
        })
    };
    vec![
        scene(
            "head-on",
            vec![
                walk((0.0, -5.0), (0.0, 5.0), 1.3),
                walk((0.0, 5.0), (0.0, -5.0), 1.3),
            ],
        ),
        scene(
            "crossing",
            vec![
                walk((-5.0, 0.0), (5.0, 0.0), 1.3),
                walk((0.0, -5.0), (0.0, 5.0), 1.3),
            ],
        ),
        scene(
            "overtaking",
            vec![
                walk((0.0, -3.0), (0.0, 4.0), 0.7),
                walk((0.0, -5.0), (0.0, 8.0), 1.5),
            ],
        ),
        scene(
            "four-way confusion",
            vec![
                walk((-5.0, 0.0), (5.0, 0.0), 1.3),
                walk((5.0, 0.0), (-5.0, 0.0), 1.3),
                walk((0.0, -5.0), (0.0, 5.0), 1.3),
                walk((0.0, 5.0), (0.0, -5.0), 1.3),
            ],
        ),
        scene(
            "oncoming groups",
            group(0.0, -7.0, -1.0).chain(group(0.2, 7.0, 1.0)).collect(),
        ),
        doorway(),
        hallway(),
        bottleneck(),
        conversing_group(),
        scene("circle of 24", circle(24, 6.0)),
        scene("circle of 250", circle(250, 25.0)),
    ]
}
