//! Standard encounters to measure crowd avoidance on, named after SteerBench's test cases and
//! written here (positions in metres on the ground, x and z): head-on, crossing, overtaking,
//! four-way confusion, two oncoming groups, and circles whose walkers all swap to the opposite
//! side. Each is a list of walkers (start, goal, preferred speed), all of radius 0.25 m.

use glam::Vec2;

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

/// Every scene by name.
pub fn all() -> Vec<(&'static str, Vec<Walk>)> {
    let group = |x0: f32, z0: f32, dz: f32| {
        (0..5).map(move |k| {
            let (x, z) = (x0 + (k % 3) as f32 * 0.8 - 0.8, z0 + (k / 3) as f32 * dz);
            walk((x, z), (x, z - 14.0 * dz.signum()), 1.3)
        })
    };
    vec![
        (
            "head-on",
            vec![
                walk((0.0, -5.0), (0.0, 5.0), 1.3),
                walk((0.0, 5.0), (0.0, -5.0), 1.3),
            ],
        ),
        (
            "crossing",
            vec![
                walk((-5.0, 0.0), (5.0, 0.0), 1.3),
                walk((0.0, -5.0), (0.0, 5.0), 1.3),
            ],
        ),
        (
            "overtaking",
            vec![
                walk((0.0, -3.0), (0.0, 4.0), 0.7),
                walk((0.0, -5.0), (0.0, 8.0), 1.5),
            ],
        ),
        (
            "four-way confusion",
            vec![
                walk((-5.0, 0.0), (5.0, 0.0), 1.3),
                walk((5.0, 0.0), (-5.0, 0.0), 1.3),
                walk((0.0, -5.0), (0.0, 5.0), 1.3),
                walk((0.0, 5.0), (0.0, -5.0), 1.3),
            ],
        ),
        (
            "oncoming groups",
            group(0.0, -7.0, -1.0).chain(group(0.2, 7.0, 1.0)).collect(),
        ),
        ("circle of 24", circle(24, 6.0)),
        ("circle of 250", circle(250, 25.0)),
    ]
}
