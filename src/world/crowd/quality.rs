//! How well a crowd walked, from where everyone was at every step: collisions (pairs that ever
//! overlapped, the deepest overlap), arrival time and path length against the straight line,
//! the least-effort energy of SteerBench (∫ e_s + e_w·|v|² dt with e_s = 2.23, e_w = 1.26,
//! against the least energy for the straight line, 2·√(e_s·e_w) per metre), and heading
//! reversals (each time a walker's turning changes direction after it turned more than 2° the
//! other way: the wobble of a walker that cannot make up its mind); walkers that came into a
//! wall or into a conversing group's space. A walker whose goal is its start stands (a group's
//! member): it counts in collisions, not in the walkers' means.

use glam::Vec2;

use super::group::Space;
use crate::world::space::Obstacles;

/// SteerBench's energy per second of standing (e_s) and per m²/s² (e_w).
pub const E_S: f32 = 2.23;
/// See [`E_S`].
pub const E_W: f32 = 1.26;
/// A turn smaller than this (rad) before the turning changes direction is no reversal.
pub const REVERSAL_TURN: f32 = 0.035;

/// One walker's track: its place at every step (the first the start), its goal, its preferred
/// speed, its radius and when it arrived (s).
#[derive(Debug, Clone)]
pub struct Track {
    /// Its place at every step.
    pub at: Vec<Vec2>,
    /// Its goal.
    pub goal: Vec2,
    /// Its preferred speed (m/s).
    pub speed: f32,
    /// Its radius (m).
    pub radius: f32,
    /// When it arrived.
    pub arrived: Option<f64>,
    /// When it gave up (it said it could not reach its goal).
    pub gave_up: Option<f64>,
}

/// The measures of one run (means over walkers unless named otherwise; time, energy and
/// reversals over those that arrived).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Quality {
    /// Pairs that overlapped at some step.
    pub collisions: usize,
    /// The deepest overlap (m).
    pub deepest: f32,
    /// Walkers that did not arrive.
    pub stranded: usize,
    /// Of those, the walkers that gave up, saying they could not reach their goal.
    pub gave_up: usize,
    /// Arrival time over the straight line's time at the preferred speed (mean, and worst).
    pub time_ratio: f32,
    /// See `time_ratio`.
    pub worst_time_ratio: f32,
    /// Path length over the straight line (mean).
    pub path_ratio: f32,
    /// Energy over the straight line's least energy (mean).
    pub energy_ratio: f32,
    /// Heading reversals per walker.
    pub reversals: f32,
    /// Walkers whose body came more than [`TOLERANCE`] into a wall.
    pub through_walls: usize,
    /// Walkers whose body came more than [`TOLERANCE`] into a conversing group's space.
    pub into_groups: usize,
}

/// How far a body may come into a wall or a group's space unnoticed (m).
pub const TOLERANCE: f32 = 0.01;

impl Track {
    /// Whether it stands (its goal is its start).
    pub fn stands(&self) -> bool {
        self.at[0].distance(self.goal) < 1e-3
    }
}

/// Measures `tracks` sampled every `dt` seconds among `walls` and the groups' `spaces`.
pub fn measure(tracks: &[Track], dt: f32, walls: &Obstacles, spaces: &[Space]) -> Quality {
    let mut q = Quality::default();
    let steps = tracks.iter().map(|t| t.at.len()).min().unwrap_or(0);
    let widest = tracks.iter().map(|t| t.radius).fold(0.0, f32::max);
    let mut pairs = std::collections::BTreeSet::new();
    let mut near = Vec::new();
    for k in 0..steps {
        let agents: Vec<super::Agent> = (tracks.iter())
            .map(|t| super::Agent {
                at: t.at[k],
                velocity: Vec2::ZERO,
                radius: t.radius,
            })
            .collect();
        let crowd = super::Crowd::unnamed(0.0, agents);
        for (i, t) in tracks.iter().enumerate() {
            crowd.near(t.at[k], t.radius + widest, &mut near);
            for &j in near.iter().filter(|&&j| j > i) {
                let overlap = t.radius + tracks[j].radius - t.at[k].distance(tracks[j].at[k]);
                if overlap > 1e-3 {
                    q.deepest = q.deepest.max(overlap);
                    pairs.insert((i, j));
                }
            }
        }
    }
    q.collisions = pairs.len();
    let walkers: Vec<&Track> = tracks.iter().filter(|t| !t.stands()).collect();
    let n = walkers.len().max(1) as f32;
    let n_arrived = walkers
        .iter()
        .filter(|t| t.arrived.is_some())
        .count()
        .max(1) as f32;
    for t in &walkers {
        let into = |p: &Vec2| {
            walls
                .nearest(*p, t.radius)
                .is_some_and(|(d, _)| d < t.radius - TOLERANCE)
        };
        q.through_walls += usize::from(t.at.iter().any(into));
        let into = |p: &Vec2| {
            (spaces.iter()).any(|s| p.distance(s.centre) < s.outer + t.radius - TOLERANCE)
        };
        q.into_groups += usize::from(t.at.iter().any(into));
    }
    for t in walkers {
        let straight = t.at[0].distance(t.goal).max(1e-3);
        let path: f32 = t.at.windows(2).map(|w| w[0].distance(w[1])).sum();
        q.path_ratio += path / straight / n;
        let Some(arrived) = t.arrived else {
            q.stranded += 1;
            q.gave_up += usize::from(t.gave_up.is_some());
            continue;
        };
        let ratio = arrived as f32 / (straight / t.speed);
        q.time_ratio += ratio / n_arrived;
        q.worst_time_ratio = q.worst_time_ratio.max(ratio);
        let moving = ((arrived as f32 / dt).round() as usize).min(t.at.len() - 1);
        let energy: f32 = (t.at[..=moving].windows(2))
            .map(|w| (E_S + E_W * (w[1].distance(w[0]) / dt).powi(2)) * dt)
            .sum();
        q.energy_ratio += energy / (2.0 * (E_S * E_W).sqrt() * straight) / n_arrived;
        q.reversals += reversals(&t.at, dt) as f32 / n_arrived;
    }
    q
}

/// How often a path's sideways motion (along `across`, a unit vector) changes direction, steps
/// that move less than `ignore` (m) sideways left out: the zig-zag of a walk that should go
/// straight.
pub fn sideways_reversals(path: &[Vec2], across: Vec2, ignore: f32) -> usize {
    let mut sign = 0.0f32;
    let mut count = 0;
    for w in path.windows(2) {
        let v = (w[1] - w[0]).dot(across);
        if v.abs() < ignore {
            continue;
        }
        if sign != 0.0 && v.signum() != sign {
            count += 1;
        }
        sign = v.signum();
    }
    count
}

/// Heading reversals along `at`, headings sampled every 0.1 s while moving faster than 0.1 m/s.
fn reversals(at: &[Vec2], dt: f32) -> usize {
    let every = ((0.1 / dt).round() as usize).max(1);
    let headings: Vec<f32> = (at.windows(every + 1).step_by(every))
        .map(|w| w[every] - w[0])
        .filter(|d| d.length() > 0.1 * every as f32 * dt)
        .map(|d| d.x.atan2(d.y))
        .collect();
    let (mut count, mut turned, mut sign) = (0, 0.0f32, 0.0f32);
    for w in headings.windows(2) {
        let d = crate::character::body::limits::wrap(w[1] - w[0]);
        if d.abs() < 1e-4 {
            continue;
        }
        if d.signum() == sign || sign == 0.0 {
            turned += d.abs();
        } else {
            if turned > REVERSAL_TURN {
                count += 1;
            }
            turned = d.abs();
        }
        sign = d.signum();
    }
    count
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_straight_walk_at_the_best_speed_costs_the_least_and_a_zigzag_reverses() {
        let dt = 0.1;
        let best = (E_S / E_W).sqrt();
        let line: Vec<Vec2> = (0..=100)
            .map(|k| Vec2::new(0.0, k as f32 * best * dt))
            .collect();
        let goal = *line.last().unwrap();
        let t = Track {
            at: line.clone(),
            goal,
            speed: best,
            radius: 0.25,
            arrived: Some(10.0),
            gave_up: None,
        };
        let q = measure(std::slice::from_ref(&t), dt, &Obstacles::default(), &[]);
        assert!((q.energy_ratio - 1.0).abs() < 1e-3, "{q:?}");
        assert!((q.time_ratio - 1.0).abs() < 1e-3 && (q.path_ratio - 1.0).abs() < 1e-3);
        assert_eq!(q.reversals, 0.0);
        // weaving 5 cm each side every half second: reversals, a longer path, more energy
        let zig: Vec<Vec2> = (line.iter().enumerate())
            .map(|(k, p)| *p + Vec2::X * 0.05 * (k as f32 * std::f32::consts::PI / 5.0).sin())
            .collect();
        let q = measure(
            &[Track {
                at: zig,
                ..t.clone()
            }],
            dt,
            &Obstacles::default(),
            &[],
        );
        assert!(q.reversals >= 15.0, "{q:?}");
        assert!(q.path_ratio > 1.0 && q.energy_ratio > 1.0);
        // two walkers through each other: one collision, as deep as their diameters
        let other: Vec<Vec2> = line.iter().rev().copied().collect();
        let q = measure(
            &[
                t.clone(),
                Track {
                    at: other,
                    goal: line[0],
                    ..t
                },
            ],
            dt,
            &Obstacles::default(),
            &[],
        );
        assert_eq!(q.collisions, 1);
        assert!((q.deepest - 0.5).abs() < 0.07, "{q:?}");
    }
}
