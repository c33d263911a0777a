//! Time to contact between two discs moving at constant velocities: the first time t ≥ 0 at
//! which their centres are `reach` apart. Solved as the thesis does (the smaller root of
//! ‖Δx + Δv t‖ = R), never by crossing the two path lines, which finds crossings the two never
//! occupy at the same time.

use glam::Vec2;

use super::snapshot::Agent;

/// The first time (s) at which discs whose centres differ by `dx` (other − me) and whose
/// velocities differ by `dv` (other − me) come within `reach` of each other; `Some(0.0)` when
/// they are within it and closing in, `None` when they never touch (or are within it and moving
/// apart).
pub fn time_to_contact(dx: Vec2, dv: Vec2, reach: f32) -> Option<f32> {
    Approach::new(dx, dv).time_to(reach)
}

/// Two discs' relative place and velocity, kept to ask [`time_to_contact`] at several reaches
/// without computing the same products again.
#[derive(Debug, Clone, Copy)]
pub struct Approach {
    /// ‖Δx‖².
    dd: f32,
    /// 2 Δx·Δv.
    b: f32,
    /// ‖Δv‖².
    a: f32,
}

impl Approach {
    /// The approach of discs differing by `dx` in place and `dv` in velocity (other − me).
    pub fn new(dx: Vec2, dv: Vec2) -> Approach {
        Approach {
            dd: dx.dot(dx),
            b: 2.0 * dx.dot(dv),
            a: dv.dot(dv),
        }
    }

    /// The first time they come within `reach`, as [`time_to_contact`] says.
    pub fn time_to(&self, reach: f32) -> Option<f32> {
        let (a, b) = (self.a, self.b);
        let c = self.dd - reach * reach;
        if c <= 0.0 {
            // already within reach: a contact now unless they part
            return (b < 0.0).then_some(0.0);
        }
        if a < 1e-9 || b >= 0.0 {
            // same velocity, or moving apart
            return None;
        }
        let disc = b * b - 4.0 * a * c;
        if disc < 0.0 {
            return None;
        }
        let t = (-b - disc.sqrt()) / (2.0 * a);
        (t >= 0.0).then_some(t)
    }
}

/// Overlaps shrink with this time constant (s) when bodies are pushed apart.
pub const PUSH_TIME: f32 = 0.02;
/// Slowest bodies are pushed apart (m/s) while they overlap by more than that covers.
pub const PUSH_SPEED: f32 = 1.0;

/// Kept between bodies beyond their radii when they are pressed apart (m): a walker's pelvis
/// sways about 2 cm to each side of its track, and the others' places are a moment old.
pub const PUSH_MARGIN: f32 = 0.04;

/// A body of `radius` at `at` moved out of the `others` it overlaps (within their radii plus
/// [`PUSH_MARGIN`]) in `dt`: by a share of the summed overlap that takes it out with time
/// constant [`PUSH_TIME`], at least [`PUSH_SPEED`] × `dt` (never past the overlap). A shallow
/// overlap parts gently, a deep one quickly, and nobody jumps in one step however short the
/// step (in a press of people, moving out of one body at once may lead into the next).
pub fn pushed_out(at: Vec2, radius: f32, others: impl IntoIterator<Item = Agent>, dt: f32) -> Vec2 {
    pushed_out_at_most(at, radius, others, dt, f32::INFINITY)
}

/// [`pushed_out`], never faster than `fastest` (m/s): a person in a press is moved by its own
/// feet, not flung; an overlap deeper than that covers takes longer to part.
pub fn pushed_out_at_most(
    at: Vec2,
    radius: f32,
    others: impl IntoIterator<Item = Agent>,
    dt: f32,
    fastest: f32,
) -> Vec2 {
    let mut push = Vec2::ZERO;
    for o in others {
        let d = at - o.at;
        let reach = radius + o.radius + PUSH_MARGIN;
        let l = d.length();
        if l < reach {
            push += if l > 1e-6 { d / l } else { Vec2::X } * (reach - l);
        }
    }
    let depth = push.length();
    if depth < 1e-9 {
        return at;
    }
    let share = 1.0 - (-dt / PUSH_TIME).exp();
    let step = (depth * share).max((PUSH_SPEED * dt).min(depth));
    at + push / depth * step.min(fastest * dt)
}

/// A move of a body of `radius` at `at` without the part that would take it nearer to anyone
/// it touches (nearer than their two radii): it slides along them,
/// as a person in a press does, rather than walking into them to be pushed out again. Several
/// touches are taken in turn, three rounds, so that one wedged between two all but stops (the
/// little left is pressed apart again). For a velocity; a step is [`stepped_along`].
pub fn slid_along(at: Vec2, radius: f32, step: Vec2, others: &[Agent]) -> Vec2 {
    along(at, radius, step, others, |gap| (gap < 0.0).then_some(0.0))
}

/// A step of a body of `radius` from `at` that ends no nearer to anyone than their two radii:
/// it goes up to them and slides along them ([`slid_along`] for one already touching). (Only
/// one touching was slid along before: a body 3 cm away stepped 3 cm into the other, and roots
/// came 0.448 m apart in a press.)
pub fn stepped_along(at: Vec2, radius: f32, step: Vec2, others: &[Agent]) -> Vec2 {
    along(at, radius, step, others, |gap| Some(gap.max(0.0)))
}

/// `m` without the part that takes the body at `at` further toward anyone than `room` allows
/// given the gap between the two bodies (`None`: as far as it goes; `Some(x)`: `x` at most).
fn along(
    at: Vec2,
    radius: f32,
    mut m: Vec2,
    others: &[Agent],
    room: impl Fn(f32) -> Option<f32>,
) -> Vec2 {
    for _ in 0..3 {
        let mut slid = false;
        for o in others {
            let d = at - o.at;
            let l = d.length();
            if l <= 1e-6 || l > radius + o.radius + m.length() {
                continue;
            }
            let Some(allowed) = room(l - radius - o.radius) else {
                continue;
            };
            let into = m.dot(d / l);
            if into < -allowed {
                m -= d / l * (into + allowed);
                slid = true;
            }
        }
        if !slid {
            break;
        }
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn head_on_crossing_and_parting_discs() {
        // 10 m apart, closing at 2 m/s, touching at 1 m: 4.5 s
        let t = time_to_contact(Vec2::new(0.0, 10.0), Vec2::new(0.0, -2.0), 1.0).unwrap();
        assert!((t - 4.5).abs() < 1e-5, "{t}");
        // passing 2 m to the side never comes within 1 m
        assert_eq!(
            time_to_contact(Vec2::new(2.0, 10.0), Vec2::new(0.0, -2.0), 1.0),
            None
        );
        // moving apart, or side by side at one velocity
        assert_eq!(
            time_to_contact(Vec2::new(0.0, 3.0), Vec2::new(0.0, 1.0), 1.0),
            None
        );
        assert_eq!(time_to_contact(Vec2::new(0.5, 3.0), Vec2::ZERO, 1.0), None);
        // within reach: now if closing, never if parting
        assert_eq!(
            time_to_contact(Vec2::new(0.0, 0.5), Vec2::new(0.0, -1.0), 1.0),
            Some(0.0)
        );
        assert_eq!(
            time_to_contact(Vec2::new(0.0, 0.5), Vec2::new(0.0, 1.0), 1.0),
            None
        );
        // paths that cross, but at different times: no contact (line crossing would say yes)
        // (me at 1 m/s along +z; the other from 5 m left, 2 m ahead at 5 m/s along +x: it
        // crosses (0, 2) at 1 s when I am at (0, 1), never nearer than 0.98 m)
        let dv = Vec2::new(5.0, 0.0) - Vec2::new(0.0, 1.0);
        assert_eq!(time_to_contact(Vec2::new(-5.0, 2.0), dv, 0.5), None);
        assert!(time_to_contact(Vec2::new(-5.0, 2.0), dv, 1.0).is_some());
    }

    #[test]
    fn overlapping_bodies_part_with_the_time_constant_and_never_beyond_the_margin() {
        let other = |x: f32| Agent {
            at: Vec2::new(x, 0.0),
            velocity: Vec2::ZERO,
            radius: 0.25,
        };
        let dt = 1.0 / 240.0;
        // clear of each other: nothing moves
        assert_eq!(pushed_out(Vec2::ZERO, 0.25, [other(1.0)], dt), Vec2::ZERO);
        // 4 cm inside the reach (0.5 + the margin): out by the share of a 20 ms time constant
        let at = pushed_out(Vec2::ZERO, 0.25, [other(0.5)], dt);
        let share = 1.0 - (-dt / PUSH_TIME).exp();
        assert!((at.x + 0.04 * share).abs() < 1e-6 && at.y == 0.0, "{at}");
        // a second of it: at the reach, not past it
        let mut at = Vec2::ZERO;
        for _ in 0..240 {
            at = pushed_out(at, 0.25, [other(0.5)], dt);
        }
        assert!((at.x + 0.04).abs() < 1e-5, "{at}");
        // squeezed between two: the pushes cancel, nobody is flung out
        let at = pushed_out(Vec2::ZERO, 0.25, [other(0.4), other(-0.4)], dt);
        assert!(at.length() < 1e-6, "{at}");
        // 24 cm inside: out at once unbounded, at most 0.6 m/s × dt bounded
        let at = pushed_out(Vec2::ZERO, 0.25, [other(0.3)], 0.1);
        assert!((at.x + 0.24).abs() < 0.01, "{at}");
        let at = pushed_out_at_most(Vec2::ZERO, 0.25, [other(0.3)], 0.1, 0.6);
        assert!((at.x + 0.06).abs() < 1e-6, "{at}");
    }

    #[test]
    fn a_move_into_one_touched_slides_along_them_and_a_wedged_one_stops() {
        let other = |x: f32, z: f32| Agent {
            at: Vec2::new(x, z),
            velocity: Vec2::ZERO,
            radius: 0.25,
        };
        let step = Vec2::new(0.01, 0.01);
        // nobody touched: the move as it was
        assert_eq!(slid_along(Vec2::ZERO, 0.25, step, &[other(2.0, 0.0)]), step);
        // one touched on the right (+x): only the move along them is left
        let m = slid_along(Vec2::ZERO, 0.25, step, &[other(0.49, 0.0)]);
        assert!(m.x.abs() < 1e-7 && (m.y - 0.01).abs() < 1e-7, "{m}");
        // moving away from one touched: untouched
        let away = Vec2::new(-0.01, 0.0);
        assert_eq!(
            slid_along(Vec2::ZERO, 0.25, away, &[other(0.49, 0.0)]),
            away
        );
        // wedged between one on the right and one ahead-left: all but stopped
        let wedge = [other(0.49, 0.0), other(-0.29, 0.39)];
        let m = slid_along(Vec2::ZERO, 0.25, step, &wedge);
        assert!(m.length() < 0.1 * step.length(), "{m}");
    }

    #[test]
    fn a_step_toward_one_near_ends_at_their_body() {
        let other = Agent {
            at: Vec2::new(0.53, 0.0),
            velocity: Vec2::ZERO,
            radius: 0.25,
        };
        // 3 cm apart, a step of 5 cm straight at them goes the 3 cm (slid_along, which only
        // looks at who is touched already, let it in 2 cm)
        let step = Vec2::new(0.05, 0.0);
        let m = stepped_along(Vec2::ZERO, 0.25, step, &[other]);
        assert!((m.x - 0.03).abs() < 1e-6 && m.y.abs() < 1e-7, "{m}");
        assert_eq!(slid_along(Vec2::ZERO, 0.25, step, &[other]), step);
        // a step past them keeps its way along them
        let m = stepped_along(Vec2::ZERO, 0.25, Vec2::new(0.05, 0.05), &[other]);
        assert!(
            (m.x - 0.03).abs() < 1e-6 && (m.y - 0.05).abs() < 1e-7,
            "{m}"
        );
        // one out of reach of the step is not looked at
        let far = Agent {
            at: Vec2::new(0.6, 0.0),
            ..other
        };
        assert_eq!(stepped_along(Vec2::ZERO, 0.25, step, &[far]), step);
    }
}
