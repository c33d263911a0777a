//! Where a walk goes: a locomotion target read against the world. A target is `x,z` in world
//! metres, a placed character (the walk stops [`SOCIAL_DISTANCE`] from them, on the walker's
//! side, turned to face them), or a point of the world (one moving along a path is where the
//! path has it now). A place someone has stood on for a while is taken: the walk stops beside
//! them.

use glam::Vec2;

use crate::world::World;

/// How far from another character a walk to them stops (m).
pub const SOCIAL_DISTANCE: f32 = 1.2;

/// `x,z` in metres, if `target` is written so.
pub fn coordinates(target: &str) -> Option<Vec2> {
    let (x, z) = target.split_once(',')?;
    let (x, z) = (x.trim().parse::<f32>().ok()?, z.trim().parse::<f32>().ok()?);
    let limit = crate::world::MAX_COORDINATE as f32;
    (x.is_finite() && z.is_finite() && x.abs() <= limit && z.abs() <= limit)
        .then(|| Vec2::new(x, z))
}

/// Where a walk goes.
#[derive(Debug, Clone, PartialEq)]
pub struct Goal {
    /// Where it stops (x, z).
    pub at: Vec2,
    /// What it turns to face there, if anything.
    pub face: Option<Vec2>,
    /// Who stands on that place now, and where beside them the walk would stop instead.
    pub taken: Option<Taken>,
}

/// A walk's goal someone stands on.
#[derive(Debug, Clone, PartialEq)]
pub struct Taken {
    /// Who stands there.
    pub by: String,
    /// Where beside them the walker would stop (x, z).
    pub beside: Vec2,
}

/// How long someone must have stood on a walk's goal before the walker settles beside them
/// (s): one pausing there in a throng, to let another pass, is waited for.
pub const PATIENCE: f64 = 2.0;

/// Whether a walk waits for the one on its goal or settles beside them: who has stood there
/// since when, for the walk under way.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Settling {
    /// (who, since when) stands on the goal.
    standing: Option<(String, f64)>,
    /// Whether the walk has settled beside them.
    settled: bool,
}

impl Settling {
    /// Where the walk goes at `now` for `goal` as resolved now: its place, or beside the one
    /// standing on it once they have stood there [`PATIENCE`]; and whether it settled just now.
    pub fn place(&mut self, now: f64, goal: &Goal) -> (Vec2, bool) {
        let Some(t) = &goal.taken else {
            *self = Settling::default();
            return (goal.at, false);
        };
        let since = match &self.standing {
            Some((who, since)) if *who == t.by => *since,
            _ => {
                *self = Settling {
                    standing: Some((t.by.clone(), now)),
                    settled: false,
                };
                now
            }
        };
        if now - since < PATIENCE {
            return (goal.at, false);
        }
        let just = !self.settled;
        self.settled = true;
        (t.beside, just)
    }
}

/// Where a walk to `target` goes in `world` for walker `me` standing at `from`, and what it
/// faces there; `None` for a target the world does not have. A place (coordinates or a point)
/// on which someone stands is taken ([`beside_whoever_stands`], [`Settling`]).
pub fn resolve(world: &World, me: &str, target: &str, from: Vec2) -> Option<Goal> {
    if let Some(p) = coordinates(target) {
        return Some(beside_whoever_stands(world, me, p, from));
    }
    let is_character = target != me && world.is_placed(target) && !world.has_point(target);
    if is_character {
        let p = world.placement(target).position;
        let them = Vec2::new(p.x, p.z);
        let away = (from - them).normalize_or(Vec2::Y);
        return Some(Goal {
            at: them + away * SOCIAL_DISTANCE,
            face: Some(them),
            taken: None,
        });
    }
    let p = world.get(target)?;
    Some(beside_whoever_stands(world, me, Vec2::new(p.x, p.z), from))
}

/// How far beyond each other's personal space (the bodies widened by the walker's profile,
/// as its avoidance keeps them) a walker stops beside one standing on its goal (m).
pub const BESIDE_GAP: f32 = 0.05;
/// A character on a walk's goal slower than this (m/s), and on no walk of its own, stands there.
pub const STANDING_SPEED: f32 = 0.2;
/// A walker looks whether someone stands on its goal once it is this near it (m): from afar,
/// one standing there now (as everyone does before they set off) may well be gone by then.
pub const NOTICE: f32 = 2.0;

/// The walk to `goal` of walker `me` coming from `from`, and whether another character stands
/// so near it that the two bodies would overlap: who, and the place just outside that one's
/// personal space ([`BESIDE_GAP`]) on the walker's side; looked at only within [`NOTICE`] of
/// the goal. (Walking round someone who stands on one's goal for ever, a walker
/// gave up after 20 s with "has not arrived".) Who stands where is read from the crowd the
/// walkers see (`crowd::snapshot`), which knows how fast each goes.
fn beside_whoever_stands(world: &World, me: &str, goal: Vec2, from: Vec2) -> Goal {
    let mine = world.radius(me);
    let free = Goal {
        at: goal,
        face: None,
        taken: None,
    };
    if from.distance(goal) > NOTICE {
        return free;
    }
    let widen = world.profile(me).incr.max(1.0);
    let crowd = world.crowd();
    let on_it = |id: &str, them: crate::world::crowd::Agent| {
        let reach = mine + them.radius;
        let off = them.at.distance(goal);
        (id != me && them.velocity.length() < STANDING_SPEED && off < reach).then(|| OnGoal {
            off,
            by: id.to_string(),
            at: them.at,
            reach: reach * widen,
        })
    };
    let mut near = Vec::new();
    crowd.near(goal, mine + MAX_RADIUS, &mut near);
    let standing = (near.iter())
        // (one on a walk of its own that stands there waits, and one that stepped aside for
        // someone goes back: neither takes the place; a walker settled beside one who had
        // stepped onto its goal for a moment, 0.64 m from it, and stood there when it left)
        .filter(|&&i| !crowd.on_its_way(i) && !crowd.is_aside(i))
        .filter_map(|&i| on_it(crowd.id(i), crowd.agent(i)))
        .min_by(|a, b| a.off.total_cmp(&b.off).then_with(|| a.by.cmp(&b.by)));
    match standing {
        None => free,
        Some(on) => {
            let away = (from - on.at).normalize_or((goal - on.at).normalize_or(Vec2::Y));
            Goal {
                taken: Some(Taken {
                    beside: on.at + away * (on.reach + BESIDE_GAP),
                    by: on.by,
                }),
                ..free
            }
        }
    }
}

/// One standing on a walker's goal: how far from it (m), who, where, and how far the walker
/// keeps from them (the two radii, widened to the walker's personal space).
struct OnGoal {
    off: f32,
    by: String,
    at: Vec2,
    reach: f32,
}

/// The largest body radius of one standing on a goal that is looked for (m): people's are
/// about 0.25. (A world file may give radii up to 10 m; a wider body on the goal is only gone
/// round.) Looking further would visit everyone within 10 m of every goal in every frame.
pub const MAX_RADIUS: f32 = 1.0;

/// Longest lead a pursuit takes (s): a target seen moving is aimed at where it will be in the
/// time the walker needs to reach it, at most this.
pub const MAX_LEAD: f32 = 3.0;
/// A target seen moving faster than this (m/s) between two looks has jumped (a host placing
/// it, a path's jump): it is aimed at where it is, not led.
pub const MAX_TARGET_SPEED: f32 = 12.0;
/// How long the estimate of a target's velocity takes to follow a change (s): frame-to-frame
/// differences are noisy (a path's corners, a host's jumps), the low-pass keeps the aim steady.
pub const VELOCITY_SMOOTHING: f64 = 0.3;

/// Reynolds' pursuit of a moving target: its velocity estimated from where it is seen, frame
/// by frame, and the point a pursuer aims at (where the target will be when the pursuer could
/// reach it). A target that stops is aimed at where it stands.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Pursuit {
    last: Option<(f64, Vec2)>,
    velocity: Vec2,
}

impl Pursuit {
    /// The target is at `at` at time `t`.
    pub fn observe(&mut self, t: f64, at: Vec2) {
        if let Some((t0, p0)) = self.last {
            let dt = t - t0;
            if dt <= 0.0 {
                return;
            }
            let seen = (at - p0) / dt as f32;
            if !seen.is_finite() || seen.length() > MAX_TARGET_SPEED {
                self.velocity = Vec2::ZERO;
                self.last = Some((t, at));
                return;
            }
            let k = 1.0 - (-dt / VELOCITY_SMOOTHING).exp();
            self.velocity += (seen - self.velocity) * k as f32;
            if !self.velocity.is_finite() {
                self.velocity = Vec2::ZERO;
            }
        }
        self.last = Some((t, at));
    }

    /// The target's estimated velocity (m/s).
    pub fn velocity(&self) -> Vec2 {
        self.velocity
    }

    /// Where a pursuer at `from` going at `speed` aims for a target whose goal is `goal`: the
    /// goal moved on by the target's velocity over the time to reach it (at most
    /// [`MAX_LEAD`]); the goal itself when the target is about still.
    pub fn aim(&self, goal: Vec2, from: Vec2, speed: f32) -> Vec2 {
        if self.velocity.length() < 0.05 {
            return goal;
        }
        let lead = (from.distance(goal) / speed.max(0.1)).min(MAX_LEAD);
        goal + self.velocity * lead
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_walk_settles_beside_one_who_stood_on_its_goal_for_its_patience_and_says_so_once() {
        let goal = |by: Option<&str>| Goal {
            at: Vec2::new(0.0, 5.0),
            face: None,
            taken: by.map(|b| Taken {
                by: b.to_string(),
                beside: Vec2::new(0.0, 4.2),
            }),
        };
        let mut s = Settling::default();
        assert_eq!(s.place(0.0, &goal(None)), (Vec2::new(0.0, 5.0), false));
        // Bob stands there from 1 s: waited for until 3 s
        assert_eq!(s.place(1.0, &goal(Some("Bob"))).0, Vec2::new(0.0, 5.0));
        assert_eq!(s.place(2.9, &goal(Some("Bob"))).0, Vec2::new(0.0, 5.0));
        // Carl takes his place at 2.9: the patience starts again
        assert_eq!(s.place(2.95, &goal(Some("Carl"))).0, Vec2::new(0.0, 5.0));
        assert_eq!(s.place(4.9, &goal(Some("Carl"))).0, Vec2::new(0.0, 5.0));
        assert_eq!(
            s.place(4.95, &goal(Some("Carl"))),
            (Vec2::new(0.0, 4.2), true)
        );
        assert_eq!(
            s.place(5.0, &goal(Some("Carl"))),
            (Vec2::new(0.0, 4.2), false)
        );
        // he leaves: the place is the walk's again
        assert_eq!(s.place(5.1, &goal(None)), (Vec2::new(0.0, 5.0), false));
    }

    #[test]
    fn one_standing_on_the_goal_takes_it_but_one_waiting_on_its_own_walk_does_not() {
        use crate::world::crowd::{Agent, Crowd};
        let bob = Agent {
            at: Vec2::new(0.1, 5.0),
            velocity: Vec2::ZERO,
            radius: 0.25,
        };
        let mut world = World::default();
        let mut crowd = Crowd::new(0.0, [("Bob".to_string(), bob)]);
        world.set_crowd(crowd.clone());
        let goal = beside_whoever_stands(&world, "w", Vec2::new(0.0, 5.0), Vec2::new(0.0, 3.5));
        let taken = goal.taken.expect("Bob stands on it");
        assert_eq!(taken.by, "Bob");
        assert!(taken.beside.y < 5.0 - 0.5, "{}", taken.beside);
        // Bob waits there on a walk of his own: the place is still the walk's
        crowd.set_on_their_way([0]);
        world.set_crowd(crowd);
        let goal = beside_whoever_stands(&world, "w", Vec2::new(0.0, 5.0), Vec2::new(0.0, 3.5));
        assert!(goal.taken.is_none());
    }

    #[test]
    fn pursuit_learns_a_steady_velocity_and_leads_by_the_time_to_reach() {
        let mut p = Pursuit::default();
        for k in 0..120 {
            let t = k as f64 / 60.0;
            p.observe(t, Vec2::new(t as f32, 5.0));
        }
        assert!(p.velocity().distance(Vec2::X) < 0.02, "{}", p.velocity());
        // 5 m away at 1 m/s: 5 s, capped at the longest lead
        let aim = p.aim(Vec2::new(2.0, 5.0), Vec2::new(2.0, 0.0), 1.0);
        assert!(aim.distance(Vec2::new(2.0 + MAX_LEAD, 5.0)) < 0.1, "{aim}");
        // 1 m away at 2 m/s: half a second ahead
        let aim = p.aim(Vec2::new(2.0, 5.0), Vec2::new(2.0, 4.0), 2.0);
        assert!(aim.distance(Vec2::new(2.5, 5.0)) < 0.02, "{aim}");
        // it stops: the aim comes back to where it stands
        for k in 120..300 {
            p.observe(k as f64 / 60.0, Vec2::new(2.0, 5.0));
        }
        assert_eq!(
            p.aim(Vec2::new(2.0, 5.0), Vec2::ZERO, 1.0),
            Vec2::new(2.0, 5.0)
        );
    }
}
