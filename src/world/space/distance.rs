//! Distances on the ground plane (x, z) between points and segments: the helpers that
//! obstacles, routes, sight and the behaviour nets' sensors measure with.

use glam::Vec2;

/// The distance from `p` to segment `ab`, and the nearest point on it.
pub fn point_segment(p: Vec2, a: Vec2, b: Vec2) -> (f32, Vec2) {
    let ab = b - a;
    let t = if ab.length_squared() > 0.0 {
        ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0)
    } else {
        0.0
    };
    let q = a + ab * t;
    (p.distance(q), q)
}

/// The z component of the 3-D cross product of two ground vectors.
pub fn cross(a: Vec2, b: Vec2) -> f32 {
    a.x * b.y - a.y * b.x
}

/// Whether segments `ab` and `cd` cross or touch.
pub fn segments_cross(a: Vec2, b: Vec2, c: Vec2, d: Vec2) -> bool {
    let (d1, d2) = (cross(b - a, c - a), cross(b - a, d - a));
    let (d3, d4) = (cross(d - c, a - c), cross(d - c, b - c));
    if ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0))
        && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0))
    {
        return true;
    }
    let on = |p: Vec2, q: Vec2, r: Vec2| point_segment(r, p, q).0 < 1e-6;
    on(a, b, c) || on(a, b, d) || on(c, d, a) || on(c, d, b)
}

/// The distance between segments `ab` and `cd` (0 when they cross).
pub fn segment_segment(a: Vec2, b: Vec2, c: Vec2, d: Vec2) -> f32 {
    if segments_cross(a, b, c, d) {
        return 0.0;
    }
    let m = point_segment(a, c, d).0.min(point_segment(b, c, d).0);
    m.min(point_segment(c, a, b).0)
        .min(point_segment(d, a, b).0)
}
