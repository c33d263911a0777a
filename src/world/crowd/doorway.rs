//! Taking turns at a narrow (a door too narrow for two to pass each other in,
//! `space::narrows`): the way through belongs to one direction at a time. Whoever comes to a
//! free door first has it for its direction; those coming the other way wait for their turn in
//! a queue on their right of the door's axis, held back from its mouth, so that the ones coming
//! through walk out past them on their own right. The door passes to the waiting side once
//! nobody follows on the side that has it, or after [`LONGEST`] while the other side waits,
//! when those already in it are through (its `closing`). The realizer decides the turns on the
//! crowd's grid of times from where everyone is and which way they are going through, so that
//! every walker sees the same turn; each walker reads its own from the crowd.

use glam::Vec2;

use super::snapshot::Crowd;
use crate::world::space::narrows::Narrow;

/// A walker whose route goes through a narrow within this (m along the route) is coming to it.
pub const APPROACH: f32 = 8.0;
/// A walker within this of the door (m along its route) claims a turn for its way.
pub const QUEUE: f32 = 4.0;
/// The side that has the door keeps it while one of its own is within this of the door (m).
pub const FOLLOW: f32 = 2.5;
/// A walker this near the door (m along its route) with the turn goes on through even when
/// the turn is closing.
pub const COMMITTED: f32 = 1.0;
/// Where the first waiter stands: this far back from the door's line (m)…
pub const HOLD: f32 = 1.4;
/// … and this far to its right of the door's axis (m): the way out is left free.
pub const ASIDE: f32 = 0.75;
/// Waiters queue this many abreast, this far apart (m).
pub const ABREAST: usize = 3;
/// Between waiters in the queue (m).
pub const SPACING: f32 = 0.7;
/// A side keeps the door at most this long while the other waits (s).
pub const LONGEST: f64 = 8.0;

/// A walker's way through a narrow: which one (its index in the obstacles' narrows), which way
/// (+1 to the narrow's positive side, −1 to its negative side), and how far along its route
/// (m) the door is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Passing {
    /// The narrow.
    pub narrow: u32,
    /// The way it goes through.
    pub way: i8,
    /// How far along its route the door is (m).
    pub distance: f32,
}

/// Whose turn it is at a narrow.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Turn {
    /// The way that may go through (0: free to whoever comes).
    pub way: i8,
    /// Since when (s).
    pub since: f64,
    /// Those of `way` already in the door go through; no more begin.
    pub closing: bool,
}

impl Passing {
    /// The first narrow the route (from where the walker stands) goes through within
    /// [`APPROACH`] of its way.
    pub fn on(route: &[Vec2], narrows: &[Narrow]) -> Option<Passing> {
        let mut along = 0.0;
        for seg in route.windows(2) {
            let (p, q) = (seg[0], seg[1]);
            let through = (narrows.iter().enumerate())
                .filter_map(|(n, g)| g.crossing(p, q).map(|(t, way)| (t, way, n)))
                .min_by(|a, b| a.0.total_cmp(&b.0));
            if let Some((t, way, n)) = through {
                let distance = along + t * p.distance(q);
                return (distance <= APPROACH).then_some(Passing {
                    narrow: n as u32,
                    way,
                    distance,
                });
            }
            along += p.distance(q);
            if along > APPROACH {
                break;
            }
        }
        None
    }

    /// Whether the turn lets this walker go on through.
    pub fn may_go(&self, turn: Turn) -> bool {
        turn.way == 0
            || (turn.way == self.way && (!turn.closing || self.distance < COMMITTED))
            // (one already in the door's line goes on out rather than back against those
            // coming)
            || self.distance < 0.2
    }

    /// Where the `rank`th waiter (0 the nearest the door) of this way stands at `narrow`.
    pub fn waiting_spot(&self, narrow: &Narrow, rank: usize) -> Vec2 {
        let into = narrow.normal() * f32::from(self.way);
        // (facing +z the right hand is −x)
        let right = Vec2::new(-into.y, into.x);
        let (row, column) = (rank / ABREAST, rank % ABREAST);
        narrow.middle() - into * (HOLD + row as f32 * SPACING)
            + right * (ASIDE + column as f32 * SPACING)
    }
}

/// How many of those going through `narrow` the same way as `p` are nearer the door (ties by
/// index): the walker `me`'s place in the queue.
pub fn rank(crowd: &Crowd, me: usize, p: Passing) -> usize {
    (crowd.passing().iter())
        .filter(|(i, q)| {
            *i as usize != me
                && q.narrow == p.narrow
                && q.way == p.way
                && (q.distance, *i as usize) < (p.distance, me)
        })
        .count()
}

/// The turns at every one of `narrows` at the crowd's time, from the `last` ones and the
/// crowd's walkers going through (`Crowd::passing`).
pub fn turns(last: &[Turn], crowd: &Crowd, narrows: &[Narrow]) -> Vec<Turn> {
    (narrows.iter().enumerate())
        .map(|(n, narrow)| {
            let before = last.get(n).copied().unwrap_or_default();
            next(before, crowd, n as u32, narrow)
        })
        .collect()
}

/// The turn at one narrow after `before`.
fn next(before: Turn, crowd: &Crowd, n: u32, narrow: &Narrow) -> Turn {
    let now = crowd.time;
    let coming = || (crowd.passing().iter()).filter(move |(_, p)| p.narrow == n);
    let within = |way: i8, d: f32| coming().any(|(_, p)| p.way == way && p.distance < d);
    // (someone in the door itself, going through one way)
    let inside = |way: i8| {
        let mut found = Vec::new();
        crowd.near(narrow.middle(), narrow.width() / 2.0 + 0.5, &mut found);
        found.into_iter().any(|i| {
            let a = crowd.agent(i);
            narrow.side(a.at).abs() < 0.5 && a.velocity.dot(narrow.normal()) * f32::from(way) > 0.1
        })
    };
    let busy = |way: i8| within(way, COMMITTED) || inside(way);
    let w = before.way;
    if w == 0 {
        // free: the one nearest the door has it for its way
        return (coming().filter(|(_, p)| p.distance < QUEUE))
            .min_by(|a, b| (a.1.distance.total_cmp(&b.1.distance)).then(a.0.cmp(&b.0)))
            .map_or(before, |(_, p)| Turn {
                way: p.way,
                since: now,
                closing: false,
            });
    }
    let others_wait = within(-w, QUEUE);
    let ours_follow = within(w, FOLLOW);
    let hand_over =
        before.closing || (others_wait && (!ours_follow || now - before.since > LONGEST));
    if !hand_over {
        return if ours_follow || busy(w) || others_wait {
            before
        } else {
            Turn::default()
        };
    }
    if busy(w) {
        return Turn {
            closing: true,
            ..before
        };
    }
    if others_wait {
        Turn {
            way: -w,
            since: now,
            closing: false,
        }
    } else {
        Turn::default()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::world::crowd::Agent;

    /// A door in a wall along x = 0 (its positive side east).
    fn door() -> Narrow {
        Narrow {
            a: Vec2::new(0.0, 0.45),
            b: Vec2::new(0.0, -0.45),
        }
    }

    /// A crowd at `time` of walkers at `places` (standing), of whom those given go through
    /// the door: (index, way, distance along the route).
    fn crowd(time: f64, places: &[(f32, f32)], going: &[(usize, i8, f32)]) -> Crowd {
        let agents = (places.iter())
            .map(|&(x, z)| Agent {
                at: Vec2::new(x, z),
                velocity: Vec2::ZERO,
                radius: 0.25,
            })
            .collect();
        let mut c = Crowd::unnamed(time, agents);
        c.set_passing(going.iter().map(|&(i, way, distance)| {
            (
                i,
                Passing {
                    narrow: 0,
                    way,
                    distance,
                },
            )
        }));
        c
    }

    #[test]
    fn the_door_is_east_side_of_the_normal() {
        assert!(door().normal().x > 0.99, "{:?}", door().normal());
    }

    #[test]
    fn the_nearer_has_the_door_and_the_other_waits_on_its_right() {
        // one 2 m west going east, one 3 m east going west
        let c = crowd(
            0.0,
            &[(-2.0, 0.0), (3.0, 0.0)],
            &[(0, 1, 2.0), (1, -1, 3.0)],
        );
        let t = turns(&[], &c, &[door()]);
        assert_eq!(t[0].way, 1);
        let (east, west) = (c.passing()[0].1, c.passing()[1].1);
        assert!(east.may_go(t[0]));
        assert!(!west.may_go(t[0]));
        // the one going west (facing −x, its right hand −z) waits back east of the door, on
        // its right of the door's axis
        let spot = west.waiting_spot(&door(), 0);
        assert!(
            (spot.x - HOLD).abs() < 1e-5 && (spot.y + ASIDE).abs() < 1e-5,
            "{spot}"
        );
        // the second in the queue beside the first, the fourth behind
        let fourth = west.waiting_spot(&door(), ABREAST);
        assert!((fourth.x - HOLD - SPACING).abs() < 1e-5, "{fourth}");
    }

    #[test]
    fn the_door_passes_to_the_waiting_side_once_nobody_follows() {
        let first = crowd(
            0.0,
            &[(-2.0, 0.0), (3.0, 0.0)],
            &[(0, 1, 2.0), (1, -1, 3.0)],
        );
        let t = turns(&[], &first, &[door()]);
        // the east-goer is through (no longer coming), the other still waits
        let later = crowd(2.0, &[(1.0, 0.0), (1.4, 0.75)], &[(1, -1, 1.4)]);
        let t = turns(&t, &later, &[door()]);
        assert_eq!((t[0].way, t[0].closing), (-1, false), "{t:?}");
    }

    #[test]
    fn a_side_that_keeps_coming_hands_over_after_the_longest_turn() {
        // both sides keep someone near the door
        let going = [(0, 1, 1.8), (1, -1, 1.4)];
        let c = |time| crowd(time, &[(-1.8, 0.0), (1.4, 0.75)], &going);
        let mut t = turns(&[], &c(0.0), &[door()]);
        assert_eq!(t[0].way, -1, "the nearer first");
        t = turns(&t, &c(LONGEST - 1.0), &[door()]);
        assert_eq!(t[0].way, -1, "kept while its side follows");
        t = turns(&t, &c(LONGEST + 0.1), &[door()]);
        assert_eq!((t[0].way, t[0].closing), (1, false), "{t:?}");
    }

    #[test]
    fn one_already_in_the_door_goes_through_before_the_turn_passes() {
        // the east side's turn is up, but one of them is half a metre from the door
        let going = [(0, 1, 1.8), (1, -1, 0.5)];
        let c = crowd(LONGEST + 0.2, &[(-1.8, 0.0), (0.5, 0.0)], &going);
        let before = Turn {
            way: -1,
            since: 0.0,
            closing: false,
        };
        let t = turns(&[before], &c, &[door()]);
        assert!(t[0].closing && t[0].way == -1, "{t:?}");
        assert!(c.passing()[1].1.may_go(t[0]), "the one in the door goes on");
        assert!(!c.passing()[0].1.may_go(t[0]), "the other side still waits");
        // through, the door passes
        let after = crowd(LONGEST + 1.0, &[(-1.8, 0.0), (-1.0, 0.0)], &going[..1]);
        assert_eq!(turns(&t, &after, &[door()])[0].way, 1);
    }

    #[test]
    fn a_free_door_with_nobody_coming_stays_free() {
        let c = crowd(
            0.0,
            &[(-6.0, 0.0), (6.0, 0.0)],
            &[(0, 1, 6.0), (1, -1, 6.0)],
        );
        assert_eq!(turns(&[], &c, &[door()])[0], Turn::default());
    }

    #[test]
    fn a_route_through_the_door_is_found_with_its_way_and_distance() {
        let route = [
            Vec2::new(-3.0, 1.0),
            Vec2::new(-0.5, 0.0),
            Vec2::new(4.0, 0.0),
        ];
        let p = Passing::on(&route, &[door()]).expect("through");
        assert_eq!(p.way, 1);
        assert!(
            (p.distance - (route[0].distance(route[1]) + 0.5)).abs() < 1e-4,
            "{p:?}"
        );
        let back: Vec<Vec2> = route.iter().rev().copied().collect();
        assert_eq!(Passing::on(&back, &[door()]).map(|p| p.way), Some(-1));
        // beyond APPROACH along the route the door is not yet near
        let far = [Vec2::new(-9.0, 0.0), Vec2::new(4.0, 0.0)];
        assert!(Passing::on(&far, &[door()]).is_none());
    }
}
