//! Obstacles on the ground plane (the world file's `obstacles`): circles, axis-aligned boxes and
//! wall segments, each with a height. Distances are measured in the horizontal plane (x, z);
//! inside a circle or a box the distance is negative. A bucket grid over their bounds answers
//! "what is near this point or this segment" without looking at every obstacle, so that a
//! thousand obstacles cost a walker only the few near it.

use glam::Vec2;
use serde::Deserialize;

use super::distance::{point_segment, segment_segment};
use super::narrows::Narrow;

/// One obstacle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Shape {
    /// Centre and radius.
    Circle {
        /// Centre (x, z).
        centre: Vec2,
        /// Radius (m).
        radius: f32,
    },
    /// An axis-aligned box.
    Box {
        /// Smallest corner (x, z).
        min: Vec2,
        /// Largest corner (x, z).
        max: Vec2,
    },
    /// A wall segment (no thickness).
    Segment {
        /// One end (x, z).
        a: Vec2,
        /// The other end.
        b: Vec2,
    },
}

/// An obstacle: its shape and height (m; what sight rays test against).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Obstacle {
    /// Its shape on the ground.
    pub shape: Shape,
    /// Its height (2 m by default).
    pub height: f32,
}

impl Obstacle {
    /// A wall from `a` to `b`, 2 m high.
    pub fn wall(a: Vec2, b: Vec2) -> Obstacle {
        Obstacle {
            shape: Shape::Segment { a, b },
            height: 2.0,
        }
    }
}

impl Shape {
    /// Signed distance from `p` (negative inside a circle or box) and the unit direction from
    /// the obstacle toward `p` at its nearest point.
    pub fn distance(&self, p: Vec2) -> (f32, Vec2) {
        match *self {
            Shape::Circle { centre, radius } => {
                let d = p - centre;
                (d.length() - radius, d.normalize_or(Vec2::X))
            }
            Shape::Box { min, max } => {
                let c = (min + max) / 2.0;
                let h = (max - min) / 2.0;
                let q = (p - c).abs() - h;
                let outside = q.max(Vec2::ZERO);
                let d = outside.length() + q.x.max(q.y).min(0.0);
                let s = (p - c).signum();
                let dir = if q.x > 0.0 || q.y > 0.0 {
                    (outside * s).normalize_or(Vec2::X)
                } else if q.x > q.y {
                    Vec2::new(s.x, 0.0)
                } else {
                    Vec2::new(0.0, s.y)
                };
                (d, dir)
            }
            Shape::Segment { a, b } => {
                let (d, q) = point_segment(p, a, b);
                (d, (p - q).normalize_or(Vec2::X))
            }
        }
    }

    /// The least distance between segment `ab` and the obstacle (≤ 0 when the segment touches
    /// or enters it).
    pub fn segment_distance(&self, a: Vec2, b: Vec2) -> f32 {
        match *self {
            Shape::Circle { centre, radius } => point_segment(centre, a, b).0 - radius,
            Shape::Box { min, max } => {
                if self.distance(a).0 <= 0.0 || self.distance(b).0 <= 0.0 {
                    return self.distance(a).0.min(self.distance(b).0);
                }
                let c = [min, Vec2::new(max.x, min.y), max, Vec2::new(min.x, max.y)];
                (0..4)
                    .map(|i| segment_segment(a, b, c[i], c[(i + 1) % 4]))
                    .fold(f32::INFINITY, f32::min)
            }
            Shape::Segment { a: c, b: d } => segment_segment(a, b, c, d),
        }
    }

    /// The bounds (min, max corners).
    pub fn bounds(&self) -> (Vec2, Vec2) {
        match *self {
            Shape::Circle { centre, radius } => (centre - radius, centre + radius),
            Shape::Box { min, max } => (min, max),
            Shape::Segment { a, b } => (a.min(b), a.max(b)),
        }
    }
}

/// The world file's form of an obstacle.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ObstacleFile {
    circle: Option<[f64; 3]>,
    #[serde(rename = "box")]
    rect: Option<[f64; 4]>,
    segment: Option<[f64; 4]>,
    height: Option<f64>,
}

/// Most obstacles a world may hold.
pub const MAX_OBSTACLES: usize = 100_000;

impl ObstacleFile {
    /// The obstacle, or why it is not one (`index` names it).
    pub fn obstacle(&self, index: usize) -> Result<Obstacle, String> {
        let at = |what: &str| format!("obstacles[{index}]: {what}");
        let all: Vec<f64> = [
            self.circle.map(|c| c.to_vec()),
            self.rect.map(|c| c.to_vec()),
            self.segment.map(|c| c.to_vec()),
        ]
        .into_iter()
        .flatten()
        .flatten()
        .chain(self.height)
        .collect();
        if all
            .iter()
            .any(|v| !v.is_finite() || v.abs() > super::MAX_COORDINATE)
        {
            return Err(at("its numbers must be finite and at most 1e9 m"));
        }
        let v = |x: f64, z: f64| Vec2::new(x as f32, z as f32);
        let shape = match (self.circle, self.rect, self.segment) {
            (Some([x, z, r]), None, None) if r > 0.0 => Shape::Circle {
                centre: v(x, z),
                radius: r as f32,
            },
            (Some(_), None, None) => return Err(at("a circle's radius must be positive")),
            (None, Some([x0, z0, x1, z1]), None) if x1 >= x0 && z1 >= z0 => Shape::Box {
                min: v(x0, z0),
                max: v(x1, z1),
            },
            (None, Some(_), None) => return Err(at("a box is [xmin, zmin, xmax, zmax]")),
            (None, None, Some([x0, z0, x1, z1])) => Shape::Segment {
                a: v(x0, z0),
                b: v(x1, z1),
            },
            _ => {
                return Err(at(
                    "give exactly one of \"circle\": [x, z, r], \"box\": [xmin, zmin, xmax, zmax], \"segment\": [x1, z1, x2, z2]",
                ))
            }
        };
        let height = self.height.unwrap_or(2.0);
        if height <= 0.0 {
            return Err(at("its height must be positive"));
        }
        Ok(Obstacle {
            shape,
            height: height as f32,
        })
    }
}

/// Side of a bucket of the grid index (m).
const BUCKET: f32 = 2.0;

/// The obstacles of a world, with a bucket grid over their bounds.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Obstacles {
    list: Vec<Obstacle>,
    /// Bucket (i, j) → obstacles whose bounds overlap it; sorted by key.
    buckets: std::collections::BTreeMap<(i32, i32), Vec<u32>>,
    /// Obstacles too large for buckets (more than 64 × 64 of them), tested always.
    large: Vec<u32>,
    /// The gaps between them too narrow for two to pass in (`space::narrows`).
    narrows: Vec<Narrow>,
}

fn bucket(p: Vec2) -> (i32, i32) {
    let b = |v: f32| (v / BUCKET).floor().clamp(-1e8, 1e8) as i32;
    (b(p.x), b(p.y))
}

impl Obstacles {
    /// The index of `list`.
    pub fn new(list: Vec<Obstacle>) -> Obstacles {
        let mut o = Obstacles {
            list,
            ..Obstacles::default()
        };
        for (i, ob) in o.list.iter().enumerate() {
            let (lo, hi) = ob.shape.bounds();
            let (a, b) = (bucket(lo), bucket(hi));
            if (b.0 - a.0) as i64 * (b.1 - a.1) as i64 > 64 * 64 {
                o.large.push(i as u32);
                continue;
            }
            for x in a.0..=b.0 {
                for z in a.1..=b.1 {
                    o.buckets.entry((x, z)).or_default().push(i as u32);
                }
            }
        }
        o.narrows = super::narrows::find(&o.list, |lo, hi, m| o.near_box(lo, hi, m));
        o
    }

    /// The gaps between the obstacles too narrow for two people to pass each other in.
    pub fn narrows(&self) -> &[Narrow] {
        &self.narrows
    }

    /// Every obstacle.
    pub fn all(&self) -> &[Obstacle] {
        &self.list
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.list.is_empty()
    }

    /// Indices of the obstacles whose bounds may come within `margin` of the box `lo`–`hi`
    /// (each once, in order).
    pub fn near_box(&self, lo: Vec2, hi: Vec2, margin: f32) -> Vec<u32> {
        let (a, b) = (bucket(lo - margin), bucket(hi + margin));
        let mut out = self.large.clone();
        if (b.0 - a.0) as i64 * (b.1 - a.1) as i64 > self.buckets.len() as i64 {
            out.extend(self.buckets.values().flatten());
        } else {
            for x in a.0..=b.0 {
                for z in a.1..=b.1 {
                    if let Some(v) = self.buckets.get(&(x, z)) {
                        out.extend(v);
                    }
                }
            }
        }
        out.sort_unstable();
        out.dedup();
        out
    }

    /// The nearest obstacle within `margin` of `p`: its signed distance and the direction
    /// from it toward `p`.
    pub fn nearest(&self, p: Vec2, margin: f32) -> Option<(f32, Vec2)> {
        (self.near_box(p, p, margin).into_iter())
            .map(|i| self.list[i as usize].shape.distance(p))
            .filter(|(d, _)| *d < margin)
            .min_by(|a, b| a.0.total_cmp(&b.0))
    }

    /// The least distance from `p` to any obstacle (infinite when none is within `margin`).
    pub fn clearance(&self, p: Vec2, margin: f32) -> f32 {
        self.nearest(p, margin).map_or(f32::INFINITY, |n| n.0)
    }

    /// Whether the segment `ab` keeps at least `clearance` from every obstacle.
    pub fn segment_clear(&self, a: Vec2, b: Vec2, clearance: f32) -> bool {
        (self.near_box(a.min(b), a.max(b), clearance).into_iter())
            .all(|i| self.list[i as usize].shape.segment_distance(a, b) >= clearance)
    }

    /// `p` moved out of every obstacle it is nearer than `radius` to (a few passes, so that
    /// corners between two obstacles are left too).
    pub fn push_out(&self, mut p: Vec2, radius: f32) -> Vec2 {
        for _ in 0..4 {
            let Some((d, away)) = self.nearest(p, radius) else {
                return p;
            };
            if d >= radius {
                return p;
            }
            p += away * (radius - d + 1e-4);
        }
        p
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn distances_to_each_shape() {
        let c = Shape::Circle {
            centre: Vec2::ZERO,
            radius: 1.0,
        };
        assert!((c.distance(Vec2::new(3.0, 0.0)).0 - 2.0).abs() < 1e-6);
        assert!((c.distance(Vec2::ZERO).0 + 1.0).abs() < 1e-6);
        let b = Shape::Box {
            min: Vec2::new(-1.0, -1.0),
            max: Vec2::new(1.0, 1.0),
        };
        assert!((b.distance(Vec2::new(4.0, 5.0)).0 - 5.0).abs() < 1e-5);
        assert!((b.distance(Vec2::new(0.5, 0.0)).0 + 0.5).abs() < 1e-6);
        assert_eq!(b.distance(Vec2::new(0.5, 0.0)).1, Vec2::X);
        let s = Shape::Segment {
            a: Vec2::new(0.0, -1.0),
            b: Vec2::new(0.0, 1.0),
        };
        assert!((s.distance(Vec2::new(-2.0, 3.0)).0 - 8f32.sqrt()).abs() < 1e-5);
        // a segment across the box touches it; one beside it keeps its distance
        assert!(b.segment_distance(Vec2::new(-3.0, 0.0), Vec2::new(3.0, 0.0)) <= 0.0);
        let d = b.segment_distance(Vec2::new(-3.0, 2.5), Vec2::new(3.0, 2.5));
        assert!((d - 1.5).abs() < 1e-5, "{d}");
        assert!(s.segment_distance(Vec2::new(-1.0, 0.0), Vec2::new(1.0, 0.0)) == 0.0);
    }

    #[test]
    fn the_index_finds_what_is_near_and_push_out_leaves_obstacles() {
        let list: Vec<Obstacle> = (0..1000)
            .map(|i| Obstacle {
                shape: Shape::Circle {
                    centre: Vec2::new((i % 40) as f32 * 3.0, (i / 40) as f32 * 3.0),
                    radius: 0.5,
                },
                height: 2.0,
            })
            .collect();
        let o = Obstacles::new(list);
        assert!(o.near_box(Vec2::splat(30.0), Vec2::splat(30.0), 1.0).len() < 10);
        let p = o.push_out(Vec2::new(30.2, 30.1), 0.25);
        assert!(o.clearance(p, 1.0) >= 0.25 - 1e-3, "{p}");
        assert!(o.segment_clear(Vec2::new(1.5, -5.0), Vec2::new(1.5, 100.0), 0.9));
        assert!(!o.segment_clear(Vec2::new(0.0, -5.0), Vec2::new(0.0, 100.0), 0.1));
    }
}
