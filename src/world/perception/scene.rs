//! What sight rays meet: the world's obstacles (upright prisms from the ground to their
//! height), the characters' bodies (a capsule per limb, from each character's pose) and the
//! world's named points (small spheres). A ray sees the first thing it meets; obstacles only
//! hide. To keep a pass cheap, a viewer first sorts what lies within its range into bins of
//! direction around it ([`Sieve`]); each ray then tests only the few things in its bin, nearest
//! first, and stops at the first hit nearer than anything left.

use std::sync::Arc;

use glam::{Vec2, Vec3};

use crate::character::body::{Pose, Skeleton};
use crate::world::space::obstacles::{Obstacle, Shape};
use crate::world::space::Obstacles;

/// The radius of a named point as something to see (m).
pub const POINT_RADIUS: f32 = 0.1;

/// The limbs of a body as capsules: from joint, to joint, radius (m). The head is the last.
const LIMBS: [(&str, &str, f32); 13] = [
    ("sacroiliac", "vc7", 0.16),
    ("vc7", "l_shoulder", 0.07),
    ("vc7", "r_shoulder", 0.07),
    ("l_shoulder", "l_elbow", 0.055),
    ("r_shoulder", "r_elbow", 0.055),
    ("l_elbow", "l_wrist", 0.045),
    ("r_elbow", "r_wrist", 0.045),
    ("l_hip", "l_knee", 0.08),
    ("r_hip", "r_knee", 0.08),
    ("l_knee", "l_talocrural", 0.06),
    ("r_knee", "r_talocrural", 0.06),
    ("vc7", "skullbase", 0.06),
    ("skullbase", "skullbase", 0.11),
];

/// How far the head's capsule reaches above the skull base, along the head (m).
const HEAD_HEIGHT: f32 = 0.16;

/// A capsule: the points within `r` of segment `a`–`b`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Capsule {
    /// One end of its axis.
    pub a: Vec3,
    /// The other end.
    pub b: Vec3,
    /// Its radius.
    pub r: f32,
}

/// What a thing is made of.
#[derive(Debug, Clone, PartialEq)]
enum Form {
    /// A character's limbs.
    Body(Vec<Capsule>),
    /// A named point.
    Point(Vec3),
}

/// Something that can be seen: a character or a named point.
#[derive(Debug, Clone, PartialEq)]
pub struct Thing {
    /// Its name.
    pub id: String,
    /// Where it is (a character: between its eyes; a point: the point).
    pub at: Vec3,
    form: Form,
    /// A bounding upright cylinder: centre (x, z), radius, lowest and highest y.
    bound: (Vec2, f32, f32, f32),
}

/// A character as a viewer: where its eyes are and where they look.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Eyes {
    /// Between the eyes (world).
    pub at: Vec3,
    /// The gaze (unit, world).
    pub ahead: Vec3,
}

/// Everything rays can meet at one moment.
#[derive(Debug, Clone, Default)]
pub struct Scene {
    things: Vec<Thing>,
    /// For each thing that is a character: its eyes.
    eyes: Vec<Option<Eyes>>,
    obstacles: Arc<Obstacles>,
}

impl Thing {
    /// A character's body in pose `pose` (world coordinates) of `skeleton`.
    pub fn body(id: &str, skeleton: &Skeleton, pose: &Pose) -> (Thing, Eyes) {
        let w = pose.world(skeleton);
        let at = |name: &str| {
            skeleton
                .joint(name)
                .map(|i| (w.positions[i], w.orientations[i]))
        };
        let mut capsules = Vec::with_capacity(LIMBS.len());
        for (a, b, r) in LIMBS {
            let (Some((pa, qa)), Some((pb, _))) = (at(a), at(b)) else {
                continue;
            };
            let pb = if a == b {
                pa + qa * Vec3::Y * HEAD_HEIGHT
            } else {
                pb
            };
            capsules.push(Capsule { a: pa, b: pb, r });
        }
        let root = pose.root;
        let eyes = match (at("l_eyeball_joint"), at("r_eyeball_joint")) {
            (Some((l, q)), Some((r, _))) => Eyes {
                at: (l + r) / 2.0,
                ahead: (q * Vec3::Z).normalize(),
            },
            // (a skeleton without eyes looks from the head, ahead of the root)
            _ => Eyes {
                at: root + Vec3::Y * 0.7,
                ahead: (pose.rotations.first().copied().unwrap_or_default() * Vec3::Z).normalize(),
            },
        };
        if capsules.is_empty() {
            capsules.push(Capsule {
                a: root.with_y(0.2),
                b: root.with_y(1.6),
                r: 0.2,
            });
        }
        let centre = Vec2::new(root.x, root.z);
        let (mut radius, mut lo, mut hi) = (0.0f32, f32::INFINITY, f32::NEG_INFINITY);
        for c in &capsules {
            for p in [c.a, c.b] {
                radius = radius.max((Vec2::new(p.x, p.z) - centre).length() + c.r);
                lo = lo.min(p.y - c.r);
                hi = hi.max(p.y + c.r);
            }
        }
        let thing = Thing {
            id: id.to_string(),
            at: eyes.at,
            form: Form::Body(capsules),
            bound: (centre, radius, lo, hi),
        };
        (thing, eyes)
    }

    /// A named point.
    pub fn point(id: &str, at: Vec3) -> Thing {
        Thing {
            id: id.to_string(),
            at,
            form: Form::Point(at),
            bound: (
                Vec2::new(at.x, at.z),
                POINT_RADIUS,
                at.y - POINT_RADIUS,
                at.y + POINT_RADIUS,
            ),
        }
    }

    /// Where a ray from `o` along unit `d` first meets it (distance), if it does.
    fn hit(&self, o: Vec3, d: Vec3) -> Option<f32> {
        let (c, r, lo, hi) = self.bound;
        upright(o, d, lo, hi, |o2, d2| circle(o2, d2, c, r))?;
        match &self.form {
            Form::Point(p) => sphere(o, d, *p, POINT_RADIUS),
            Form::Body(capsules) => (capsules.iter())
                .filter_map(|c| capsule(o, d, c))
                .min_by(f32::total_cmp),
        }
    }
}

impl Scene {
    /// A scene of `things` (characters carry their eyes) among `obstacles`.
    pub fn new(things: Vec<(Thing, Option<Eyes>)>, obstacles: Arc<Obstacles>) -> Scene {
        let (things, eyes) = things.into_iter().unzip();
        Scene {
            things,
            eyes,
            obstacles,
        }
    }

    /// Its things.
    pub fn things(&self) -> &[Thing] {
        &self.things
    }

    /// The eyes of thing `i`, if it is a character.
    pub fn eyes(&self, i: usize) -> Option<Eyes> {
        self.eyes.get(i).copied().flatten()
    }
}

/// Bins of direction (about +y) around a viewer.
const BINS: usize = 64;

/// Something a viewer's rays may meet: a thing or an obstacle, and how near it may be.
#[derive(Debug, Clone, Copy)]
struct Candidate {
    near: f32,
    thing: Option<u32>,
    obstacle: u32,
}

/// What lies within a viewer's range, binned by direction around it (each bin nearest first).
pub struct Sieve<'a> {
    scene: &'a Scene,
    bins: Vec<Vec<Candidate>>,
    /// Everything, nearest first (for rays straight up or down).
    all: Vec<Candidate>,
    range: f32,
}

fn bin_of(azimuth: f32) -> usize {
    let u = (azimuth + std::f32::consts::PI) / std::f32::consts::TAU;
    ((u * BINS as f32).floor() as isize).rem_euclid(BINS as isize) as usize
}

impl<'a> Sieve<'a> {
    /// The sieve of thing `viewer` (left out) of `scene`, looking from `eye` up to `range`.
    pub fn new(scene: &'a Scene, viewer: usize, eye: Vec3, range: f32) -> Sieve<'a> {
        let mut bins = vec![Vec::new(); BINS];
        let mut all = Vec::new();
        let eye2 = Vec2::new(eye.x, eye.z);
        let mut place = |centre: Vec2, radius: f32, c: Candidate| {
            let to = centre - eye2;
            let d = to.length();
            if d - radius > range {
                return;
            }
            let c = Candidate {
                near: (d - radius).max(0.0),
                ..c
            };
            all.push(c);
            if d <= radius * 1.01 {
                bins.iter_mut().for_each(|b| b.push(c));
                return;
            }
            let mid = to.x.atan2(to.y);
            let half = (radius / d).min(1.0).asin() + 1e-3;
            let (a, b) = (bin_of(mid - half), bin_of(mid + half));
            let mut k = a;
            loop {
                bins[k].push(c);
                if k == b {
                    break;
                }
                k = (k + 1) % BINS;
            }
        };
        for (i, t) in scene.things.iter().enumerate() {
            if i != viewer {
                let (c, r, ..) = t.bound;
                let thing = Some(i as u32);
                place(
                    c,
                    r,
                    Candidate {
                        near: 0.0,
                        thing,
                        obstacle: 0,
                    },
                );
            }
        }
        let lo = eye2 - Vec2::splat(range);
        let hi = eye2 + Vec2::splat(range);
        for k in scene.obstacles.near_box(lo, hi, 0.0) {
            let (a, b) = scene.obstacles.all()[k as usize].shape.bounds();
            let (c, r) = ((a + b) / 2.0, (b - a).length() / 2.0);
            place(
                c,
                r,
                Candidate {
                    near: 0.0,
                    thing: None,
                    obstacle: k,
                },
            );
        }
        let by_near = |a: &Candidate, b: &Candidate| a.near.total_cmp(&b.near);
        bins.iter_mut().for_each(|b| b.sort_by(by_near));
        all.sort_by(by_near);
        Sieve {
            scene,
            bins,
            all,
            range,
        }
    }

    /// The thing a ray from `o` along unit `d` sees first (index into the scene), if any:
    /// none when an obstacle comes first or nothing is within range.
    pub fn first(&self, o: Vec3, d: Vec3) -> Option<usize> {
        let flat = Vec2::new(d.x, d.z);
        let list = if flat.length_squared() < 1e-6 {
            &self.all
        } else {
            &self.bins[bin_of(flat.x.atan2(flat.y))]
        };
        let mut best: (f32, Option<usize>) = (self.range, None);
        for c in list {
            if c.near > best.0 {
                break;
            }
            let t = match c.thing {
                Some(i) => self.scene.things[i as usize].hit(o, d),
                None => prism(o, d, &self.scene.obstacles.all()[c.obstacle as usize]),
            };
            if let Some(t) = t.filter(|t| *t < best.0) {
                best = (t, c.thing.map(|i| i as usize));
            }
        }
        best.1
    }
}

/// Where a ray meets an obstacle (from the ground to its height).
pub fn prism(o: Vec3, d: Vec3, ob: &Obstacle) -> Option<f32> {
    upright(o, d, 0.0, ob.height, |o2, d2| match ob.shape {
        Shape::Circle { centre, radius } => circle(o2, d2, centre, radius),
        Shape::Box { min, max } => slab(o2, d2, min, max),
        Shape::Segment { a, b } => wall(o2, d2, a, b),
    })
}

/// The ray's meeting with an upright solid between heights `lo` and `hi` whose ground shape
/// `shape` gives the interval of ray distances inside it (from the horizontal parts of the
/// ray): the first distance ≥ 0 inside both.
fn upright(
    o: Vec3,
    d: Vec3,
    lo: f32,
    hi: f32,
    shape: impl Fn(Vec2, Vec2) -> Option<(f32, f32)>,
) -> Option<f32> {
    let (y0, y1) = if d.y.abs() < 1e-9 {
        if o.y < lo || o.y > hi {
            return None;
        }
        (f32::NEG_INFINITY, f32::INFINITY)
    } else {
        let (a, b) = ((lo - o.y) / d.y, (hi - o.y) / d.y);
        (a.min(b), a.max(b))
    };
    let (s0, s1) = shape(Vec2::new(o.x, o.z), Vec2::new(d.x, d.z))?;
    let (enter, exit) = (y0.max(s0), y1.min(s1));
    (enter <= exit && exit >= 0.0).then_some(enter.max(0.0))
}

/// The distances along a ground ray inside circle (`c`, `r`).
fn circle(o: Vec2, d: Vec2, c: Vec2, r: f32) -> Option<(f32, f32)> {
    let oc = o - c;
    let a = d.length_squared();
    let c2 = oc.length_squared() - r * r;
    if a < 1e-12 {
        return (c2 <= 0.0).then_some((f32::NEG_INFINITY, f32::INFINITY));
    }
    let b = oc.dot(d);
    let disc = b * b - a * c2;
    if disc < 0.0 {
        return None;
    }
    let s = disc.sqrt();
    Some(((-b - s) / a, (-b + s) / a))
}

/// The distances along a ground ray inside the box `min`–`max`.
fn slab(o: Vec2, d: Vec2, min: Vec2, max: Vec2) -> Option<(f32, f32)> {
    let (mut t0, mut t1) = (f32::NEG_INFINITY, f32::INFINITY);
    for k in 0..2 {
        if d[k].abs() < 1e-12 {
            if o[k] < min[k] || o[k] > max[k] {
                return None;
            }
        } else {
            let (a, b) = ((min[k] - o[k]) / d[k], (max[k] - o[k]) / d[k]);
            t0 = t0.max(a.min(b));
            t1 = t1.min(a.max(b));
        }
    }
    (t0 <= t1).then_some((t0, t1))
}

/// The distance along a ground ray to the wall `a`–`b` (no thickness).
fn wall(o: Vec2, d: Vec2, a: Vec2, b: Vec2) -> Option<(f32, f32)> {
    let e = b - a;
    let den = d.perp_dot(e);
    if den.abs() < 1e-12 {
        return None;
    }
    let ao = a - o;
    let t = ao.perp_dot(e) / den;
    let s = ao.perp_dot(d) / den;
    (0.0..=1.0).contains(&s).then_some((t, t))
}

/// Where a ray first meets sphere (`c`, `r`) (0 when it starts inside).
fn sphere(o: Vec3, d: Vec3, c: Vec3, r: f32) -> Option<f32> {
    let oc = o - c;
    let b = oc.dot(d);
    let c2 = oc.length_squared() - r * r;
    let h = b * b - c2;
    if h < 0.0 {
        return None;
    }
    let s = h.sqrt();
    if -b + s < 0.0 {
        return None;
    }
    Some((-b - s).max(0.0))
}

/// Where a ray first meets a capsule (the side of its cylinder, else one of its end spheres).
fn capsule(o: Vec3, d: Vec3, c: &Capsule) -> Option<f32> {
    let ba = c.b - c.a;
    let oa = o - c.a;
    let baba = ba.dot(ba);
    if baba < 1e-10 {
        return sphere(o, d, c.a, c.r);
    }
    let (bard, baoa, rdoa) = (ba.dot(d), ba.dot(oa), d.dot(oa));
    let k2 = baba - bard * bard;
    let k1 = baba * rdoa - baoa * bard;
    let k0 = baba * oa.dot(oa) - baoa * baoa - c.r * c.r * baba;
    let h = k1 * k1 - k2 * k0;
    if h < 0.0 {
        return None;
    }
    if k2.abs() > 1e-10 {
        let t = (-k1 - h.sqrt()) / k2;
        let y = baoa + t * bard;
        if t >= 0.0 && y > 0.0 && y < baba {
            return Some(t);
        }
    }
    // the ends: the nearer hit of the two spheres
    [sphere(o, d, c.a, c.r), sphere(o, d, c.b, c.r)]
        .into_iter()
        .flatten()
        .min_by(f32::total_cmp)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rays_meet_each_solid_where_geometry_says() {
        let o = Vec3::new(0.0, 1.6, 0.0);
        let ahead = Vec3::Z;
        let wall2 = |h: f32| Obstacle {
            shape: Shape::Segment {
                a: Vec2::new(-1.0, 2.0),
                b: Vec2::new(1.0, 2.0),
            },
            height: h,
        };
        assert_eq!(prism(o, ahead, &wall2(2.0)), Some(2.0));
        // a wall lower than the eyes: a level ray passes over it, a ray down meets it
        assert_eq!(prism(o, ahead, &wall2(1.0)), None);
        let down = Vec3::new(0.0, -0.5, 1.0).normalize();
        assert!(prism(o, down, &wall2(1.0)).is_some());
        let pillar = Obstacle {
            shape: Shape::Circle {
                centre: Vec2::new(0.0, 3.0),
                radius: 0.5,
            },
            height: 2.0,
        };
        assert!((prism(o, ahead, &pillar).unwrap() - 2.5).abs() < 1e-5);
        let block = Obstacle {
            shape: Shape::Box {
                min: Vec2::new(-0.5, 4.0),
                max: Vec2::new(0.5, 5.0),
            },
            height: 2.0,
        };
        assert!((prism(o, ahead, &block).unwrap() - 4.0).abs() < 1e-5);
        let cap = Capsule {
            a: Vec3::new(0.0, 0.5, 3.0),
            b: Vec3::new(0.0, 2.5, 3.0),
            r: 0.25,
        };
        assert!((capsule(o, ahead, &cap).unwrap() - 2.75).abs() < 1e-4);
        // just beside it: missed
        assert!(capsule(o + Vec3::X * 0.26, ahead, &cap).is_none());
        // over its top end: the end sphere
        let over = Vec3::new(0.0, 2.6, 0.0);
        let chord = (0.25f32 * 0.25 - 0.1 * 0.1).sqrt();
        assert!((capsule(over, ahead, &cap).unwrap() - (3.0 - chord)).abs() < 1e-4);
        assert!((sphere(o, ahead, Vec3::new(0.0, 1.6, 5.0), 0.1).unwrap() - 4.9).abs() < 1e-5);
    }

    #[test]
    fn a_ray_sees_the_nearest_thing_and_not_what_an_obstacle_hides() {
        let wall = Obstacle {
            shape: Shape::Segment {
                a: Vec2::new(-1.0, 3.0),
                b: Vec2::new(0.0, 3.0),
            },
            height: 2.0,
        };
        let things = vec![
            (Thing::point("eye_owner", Vec3::new(0.0, 1.6, 0.0)), None),
            (Thing::point("near", Vec3::new(0.5, 1.6, 2.0)), None),
            (Thing::point("behind", Vec3::new(1.5, 1.6, 6.0)), None),
            (Thing::point("clear", Vec3::new(2.5, 1.6, 6.0)), None),
            (Thing::point("hidden", Vec3::new(-0.5, 1.6, 6.0)), None),
        ];
        let scene = Scene::new(things, Arc::new(Obstacles::new(vec![wall])));
        let eye = Vec3::new(0.0, 1.6, 0.0);
        let sieve = Sieve::new(&scene, 0, eye, 30.0);
        let to = |p: Vec3| (p - eye).normalize();
        assert_eq!(sieve.first(eye, to(Vec3::new(0.5, 1.6, 2.0))), Some(1));
        // "behind" is behind "near" on this ray
        assert_eq!(sieve.first(eye, to(Vec3::new(1.5, 1.6, 6.0))), Some(1));
        assert_eq!(sieve.first(eye, to(Vec3::new(2.5, 1.6, 6.0))), Some(3));
        // the wall hides "hidden"
        assert_eq!(sieve.first(eye, to(Vec3::new(-0.5, 1.6, 6.0))), None);
        // the viewer never sees itself
        assert_eq!(sieve.first(eye, Vec3::Y), None);
        // out of range
        let short = Sieve::new(&scene, 0, eye, 5.0);
        assert_eq!(short.first(eye, to(Vec3::new(2.5, 1.6, 6.0))), None);
    }
}
