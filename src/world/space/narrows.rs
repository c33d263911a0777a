//! Narrows: the gaps between obstacles too narrow for two people to pass each other in, such as
//! a door in a wall. Each is the shortest line across the gap, from the end of one obstacle (a
//! wall's end, a box's corner, a pillar's side) to the nearest point of another, open on both
//! sides. Walkers going opposite ways through one take turns (`crowd::doorway`); this module
//! only finds them, once, when the world's obstacles are indexed.

use glam::Vec2;

use super::distance::cross;
use super::obstacles::{Obstacle, Shape};

/// A gap at most this wide (m) is a narrow: two bodies of 0.25 m radius passing each other with
/// a hand's room between them and from the sides need about 1.4 m.
pub const WIDEST: f32 = 1.4;
/// A gap narrower than this (m) is no way through at all (a wall meeting another).
pub const CLOSED: f32 = 0.3;
/// How far on either side of a narrow the ground must be open for it to be a way through (m).
const OPEN: f32 = 0.4;

/// A gap from `a` to `b` (the shortest line across it).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Narrow {
    /// One side of the gap (x, z).
    pub a: Vec2,
    /// The other side.
    pub b: Vec2,
}

impl Narrow {
    /// Its middle.
    pub fn middle(&self) -> Vec2 {
        (self.a + self.b) / 2.0
    }

    /// How wide it is (m).
    pub fn width(&self) -> f32 {
        self.a.distance(self.b)
    }

    /// The unit normal across it: the way from its negative side to its positive one.
    pub fn normal(&self) -> Vec2 {
        (self.b - self.a).perp().normalize_or_zero()
    }

    /// How far `p` is on the positive side of its line (m; negative on the other side).
    pub fn side(&self, p: Vec2) -> f32 {
        (p - self.middle()).dot(self.normal())
    }

    /// Where the segment `p`–`q` goes through the gap: the fraction of the way from `p` and
    /// the way it goes (+1 from the negative side to the positive, −1 back).
    pub fn crossing(&self, p: Vec2, q: Vec2) -> Option<(f32, i8)> {
        let (r, s) = (q - p, self.b - self.a);
        let denom = cross(r, s);
        if denom.abs() < 1e-9 {
            return None;
        }
        let t = cross(self.a - p, s) / denom;
        let u = cross(self.a - p, r) / denom;
        let way = if r.dot(self.normal()) > 0.0 { 1 } else { -1 };
        ((0.0..=1.0).contains(&t) && (0.0..=1.0).contains(&u)).then_some((t, way))
    }
}

/// The points of an obstacle a gap can start from: a wall's ends, a box's corners.
fn ends(shape: &Shape) -> Vec<Vec2> {
    match *shape {
        Shape::Segment { a, b } => vec![a, b],
        Shape::Box { min, max } => vec![min, Vec2::new(max.x, min.y), max, Vec2::new(min.x, max.y)],
        Shape::Circle { .. } => Vec::new(),
    }
}

/// The narrows among `list`, where `near(lo, hi, margin)` gives the indices of the obstacles
/// that may come within `margin` of the box `lo`–`hi` (the obstacles' index). Each gap once.
pub fn find(list: &[Obstacle], near: impl Fn(Vec2, Vec2, f32) -> Vec<u32>) -> Vec<Narrow> {
    let mut found: Vec<Narrow> = Vec::new();
    // (only solid obstacles: a space kept by manners, such as a conversing group's, of no
    // height, is no door post, and a walker's own obstacles, the world's and such spaces, have
    // the same narrows in the same order)
    let solid = |k: u32| list[k as usize].height > 0.0;
    for (i, o) in list.iter().enumerate().filter(|(i, _)| solid(*i as u32)) {
        // (from a wall's end or a box's corner; from a pillar's side nearest the other)
        let starts: Vec<(Vec2, Option<f32>)> = match o.shape {
            Shape::Circle { centre, radius } => vec![(centre, Some(radius))],
            ref s => ends(s).into_iter().map(|e| (e, None)).collect(),
        };
        for (p, radius) in starts {
            for j in near(p, p, WIDEST + radius.unwrap_or(0.0)) {
                if j as usize == i || !solid(j) {
                    continue;
                }
                let (d, away) = list[j as usize].shape.distance(p);
                let on_other = p - away * d;
                let from = p - away * radius.unwrap_or(0.0);
                let gap = Narrow {
                    a: from,
                    b: on_other,
                };
                let width = gap.width();
                if !(CLOSED..=WIDEST).contains(&width) || !open(&gap, list, &near) {
                    continue;
                }
                let same = |n: &Narrow| {
                    (n.a.distance(gap.a) < 0.1 && n.b.distance(gap.b) < 0.1)
                        || (n.a.distance(gap.b) < 0.1 && n.b.distance(gap.a) < 0.1)
                };
                if !found.iter().any(same) {
                    found.push(gap);
                }
            }
        }
    }
    found
}

/// Whether the gap's line is clear of every obstacle but at its ends, and the ground on both
/// sides of its middle is open (a gap into a corner is no way through).
fn open(gap: &Narrow, list: &[Obstacle], near: &impl Fn(Vec2, Vec2, f32) -> Vec<u32>) -> bool {
    let (m, n) = (gap.middle(), gap.normal());
    let inner = (
        gap.a + (gap.b - gap.a) * 0.05,
        gap.a + (gap.b - gap.a) * 0.95,
    );
    let line_clear = (near(inner.0.min(inner.1), inner.0.max(inner.1), 0.0).into_iter())
        .all(|k| list[k as usize].shape.segment_distance(inner.0, inner.1) > 1e-3);
    let side_clear =
        |p: Vec2| (near(p, p, 0.1).into_iter()).all(|k| list[k as usize].shape.distance(p).0 > 0.1);
    line_clear && side_clear(m + n * OPEN) && side_clear(m - n * OPEN)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::world::space::Obstacles;

    fn wall(a: (f32, f32), b: (f32, f32)) -> Obstacle {
        Obstacle::wall(Vec2::new(a.0, a.1), Vec2::new(b.0, b.1))
    }

    #[test]
    fn a_door_in_a_wall_is_one_narrow_across_it() {
        let o = Obstacles::new(vec![
            wall((0.0, -12.0), (0.0, -0.45)),
            wall((0.0, 0.45), (0.0, 12.0)),
        ]);
        let n = o.narrows();
        assert_eq!(n.len(), 1, "{n:?}");
        assert!((n[0].width() - 0.9).abs() < 1e-5);
        assert!(n[0].middle().length() < 1e-5);
        // a route from west to east goes through it, 2 m along a 4 m segment
        let (t, way) = n[0]
            .crossing(Vec2::new(-2.0, 0.1), Vec2::new(2.0, 0.1))
            .expect("through the door");
        assert!((t - 0.5).abs() < 1e-5);
        let back = n[0].crossing(Vec2::new(2.0, 0.1), Vec2::new(-2.0, 0.1));
        assert_eq!(back.map(|b| b.1), Some(-way));
        // a route past the wall's end does not
        assert!(n[0]
            .crossing(Vec2::new(-2.0, 13.0), Vec2::new(2.0, 13.0))
            .is_none());
    }

    #[test]
    fn wide_gaps_corners_and_walls_meeting_are_not_narrows() {
        // a 2 m gap; an L of two walls meeting; a 1 m gap into a dead end
        let wide = Obstacles::new(vec![
            wall((0.0, -5.0), (0.0, -1.0)),
            wall((0.0, 1.0), (0.0, 5.0)),
        ]);
        assert!(wide.narrows().is_empty());
        let corner = Obstacles::new(vec![
            wall((0.0, 0.0), (5.0, 0.0)),
            wall((0.0, 0.0), (0.0, 5.0)),
        ]);
        assert!(corner.narrows().is_empty());
    }

    #[test]
    fn a_gap_between_a_pillar_and_a_wall_is_a_narrow() {
        let o = Obstacles::new(vec![
            wall((-5.0, 0.0), (5.0, 0.0)),
            Obstacle {
                shape: Shape::Circle {
                    centre: Vec2::new(0.0, 1.5),
                    radius: 0.5,
                },
                height: 2.0,
            },
        ]);
        let n = o.narrows();
        assert_eq!(n.len(), 1, "{n:?}");
        assert!((n[0].width() - 1.0).abs() < 1e-5);
    }
}
