//! A crowd of roots only: discs that walk to their goals choosing their velocities among each
//! other as the realizer's walkers do (the same [`Avoider`] and push-out, routes round the same
//! obstacles), without bodies or the walker's urgent re-choice between two regular ones. It
//! serves where whole bodies would cost too much (ten thousand people at 30 Hz) and as the
//! avoidance layer measured on its own, beside other algorithms, in `benches/crowd.rs` and
//! `examples/crowd_quality.rs`. A step reads one snapshot of everyone
//! and moves everyone from it, on all cores, in a fixed order: the result is the same on any
//! number of threads.

use std::sync::Arc;

use glam::Vec2;
use rayon::prelude::*;

use super::avoid::{progress, DECIDE_PERIOD, NEIGHBOUR_RADIUS};
use super::negotiate::{self, Standing};
use super::{Agent, Avoider, Crowd, Profile};
use crate::world::space::{path, Obstacles};

/// Most a mover's velocity changes in a second (m/s²), as a walker's steering allows.
pub const MAX_ACCELERATION: f32 = 2.0;
/// Within this of its goal a mover slows linearly (m).
pub const SLOW_RADIUS: f32 = 1.0;
/// Within this of its goal a mover has arrived (m).
pub const ARRIVED: f32 = 0.05;
/// Kept from obstacles beyond the radius when routing (m), as walkers do.
pub const ROUTE_MARGIN: f32 = 0.1;
/// Within this of a point of its route a mover goes on to the next (m).
pub const REACH: f32 = 0.45;
/// Shortest time between two plans of a mover's route (s).
pub const REPLAN_PERIOD: f64 = 1.0;
/// A walker that has come no nearer its goal by [`PROGRESS`] for this long gives up (s).
pub const GIVE_UP: f64 = 60.0;
/// What counts as coming nearer the goal (m).
pub const PROGRESS: f32 = 0.1;
/// One standing this far from its place goes back to it when nobody asks it for room (m).
pub const DISPLACED: f32 = 0.06;
/// Below this fraction of its preferred speed a fully impatient walker is stuck.
pub const STILL: f32 = 0.1;
/// Fewest movers stepped on several threads.
const PARALLEL_MOVERS: usize = 64;

/// One disc walking to its goal.
#[derive(Debug, Clone)]
pub struct Mover {
    /// Where it is (x, z).
    pub at: Vec2,
    /// Its velocity.
    pub velocity: Vec2,
    /// Where it goes.
    pub goal: Vec2,
    /// Its radius (m).
    pub radius: f32,
    /// Its preferred speed (m/s).
    pub speed: f32,
    /// When it arrived.
    pub arrived: Option<f64>,
    /// When it gave up: it came no nearer its goal for [`GIVE_UP`] seconds (it then stands).
    pub gave_up: Option<f64>,
    /// Walking: the standing (or stuck) person it asks to make room (looks at), while they
    /// shut its way.
    pub looking_at: Option<usize>,
    /// Standing or stuck: the spot it steps aside to while a walker asks for room, and (standing)
    /// whether it has left its place (it goes back when nobody asks any more).
    aside: Option<Vec2>,
    stepped: bool,
    /// Its least distance to its goal so far, and when that last shrank by [`PROGRESS`].
    best: (f32, f64),
    avoider: Avoider,
    chosen: Option<Vec2>,
    /// The points to walk through (the last is the goal), and the one sought now.
    route: Vec<Vec2>,
    next: usize,
    /// When it last planned its route again.
    replanned: f64,
}

impl Mover {
    /// A mover standing at `at`, going to `goal`.
    pub fn new(at: Vec2, goal: Vec2, radius: f32, speed: f32) -> Mover {
        Mover {
            at,
            velocity: Vec2::ZERO,
            goal,
            radius,
            speed,
            // one whose goal is where it stands has arrived (a group's member, standing)
            arrived: (at.distance(goal) < ARRIVED).then_some(0.0),
            gave_up: None,
            looking_at: None,
            aside: None,
            stepped: false,
            best: (at.distance(goal), 0.0),
            avoider: Avoider::starting_at(at),
            chosen: None,
            route: vec![goal],
            next: 0,
            replanned: f64::NEG_INFINITY,
        }
    }

    /// Plans its route round `obstacles` (keeping its radius and [`ROUTE_MARGIN`]).
    pub fn route_round(&mut self, obstacles: &Obstacles) -> Result<(), path::PathError> {
        let route = path::plan(obstacles, self.at, self.goal, self.radius + ROUTE_MARGIN)?;
        self.route = route.into_iter().skip(1).collect();
        if self.route.is_empty() {
            self.route.push(self.goal);
        }
        self.next = 0;
        Ok(())
    }

    /// Goes on along its route: past every point it is within [`REACH`] of, or from which the
    /// point after it is in sight with its body's clearance. Pushed by others to where the
    /// point it seeks is out of sight, it plans its route again from there (at most every
    /// [`REPLAN_PERIOD`]).
    pub fn follow(&mut self, obstacles: &Obstacles, time: f64) {
        let aim = self.route.get(self.next).copied().unwrap_or(self.goal);
        let lost = !obstacles.is_empty()
            && self.arrived.is_none()
            && !obstacles.segment_clear(self.at, aim, 0.5 * self.radius);
        if lost && time >= self.replanned + REPLAN_PERIOD {
            self.replanned = time;
            let _ = self.route_round(obstacles);
        }
        while self.next + 1 < self.route.len() {
            let after = self.route[self.next + 1];
            let reached = self.at.distance(self.route[self.next]) <= REACH;
            if !(reached || obstacles.segment_clear(self.at, after, self.radius)) {
                break;
            }
            self.next += 1;
        }
    }

    /// The velocity it wants: toward the point of its route it seeks, slowing in the last
    /// [`SLOW_RADIUS`] before its goal.
    pub fn desired(&self) -> Vec2 {
        if self.standing() || self.aside.is_some() {
            // stepping aside for a walker, or back to its place
            let spot = match (self.aside, self.stepped) {
                (Some(spot), _) => spot,
                (None, true) => self.goal,
                (None, false) => return Vec2::ZERO,
            };
            let d = spot - self.at;
            let l = d.length();
            if l < ARRIVED {
                return Vec2::ZERO;
            }
            return d / l * negotiate::STEP_SPEED * (l / 0.3).min(1.0);
        }
        let aim = self.route.get(self.next).copied().unwrap_or(self.goal);
        let d = aim - self.at;
        let l = d.length();
        if l < 1e-6 {
            return Vec2::ZERO;
        }
        let last = self.next + 1 >= self.route.len();
        d / l
            * self.speed
            * if last {
                (l / SLOW_RADIUS).min(1.0)
            } else {
                1.0
            }
    }

    /// Marks it arrived at `time` if it is within [`ARRIVED`] of its goal, or within its radius
    /// of it and fully impatient (its spot is crowded: it stands as near as it can); it then
    /// stands.
    pub fn arrive_if_there(&mut self, time: f64) {
        let d = self.at.distance(self.goal);
        let near_enough = d < self.radius && self.avoider.impatience() >= 1.0;
        if self.arrived.is_none() && (d < ARRIVED || near_enough) {
            self.arrived = Some(time);
            self.velocity = Vec2::ZERO;
            self.chosen = None;
            self.looking_at = None;
        }
    }

    /// Whether it stands: arrived, or given up.
    pub fn standing(&self) -> bool {
        self.arrived.is_some() || self.gave_up.is_some()
    }

    /// Whether it is stuck: walking, but held back so long that it is fully impatient, and
    /// standing still. Others may then ask it for room as they ask those standing.
    pub fn stuck(&self) -> bool {
        !self.standing()
            && self.aside.is_none()
            && self.avoider.impatience() >= 1.0
            && self.velocity.length() < STILL * self.speed
    }

    /// Gives up when it has come no nearer its goal for [`GIVE_UP`] seconds up to `time`.
    fn keep_trying(&mut self, time: f64) {
        let d = self.at.distance(self.goal);
        if d < self.best.0 - PROGRESS {
            self.best = (d, time);
        } else if !self.standing() && time - self.best.1 > GIVE_UP {
            self.gave_up = Some(time);
            self.looking_at = None;
            self.chosen = None;
        }
    }

    fn agent(&self) -> Agent {
        Agent {
            at: self.at,
            velocity: self.velocity,
            radius: self.radius,
        }
    }
}

/// Many movers stepped together.
#[derive(Debug, Clone)]
pub struct Sim {
    /// The time (s).
    pub time: f64,
    /// Everyone, in a fixed order.
    pub movers: Vec<Mover>,
    /// How everyone avoids others.
    pub profile: Profile,
    /// What everyone walks round.
    pub obstacles: Arc<Obstacles>,
    steps: u64,
    decide_all: bool,
}

impl Sim {
    /// The movers at time 0, with the default profile.
    pub fn new(movers: Vec<Mover>) -> Sim {
        Sim {
            time: 0.0,
            movers,
            profile: Profile::default(),
            obstacles: Arc::default(),
            steps: 0,
            decide_all: false,
        }
    }

    /// The movers at time 0 among `obstacles`, each with its route round them; those that
    /// have none go straight (and are counted as not arrived, as they will not).
    pub fn among(mut movers: Vec<Mover>, obstacles: Arc<Obstacles>) -> Sim {
        for m in &mut movers {
            let _ = m.route_round(&obstacles);
        }
        Sim {
            obstacles,
            ..Sim::new(movers)
        }
    }

    /// Makes every mover choose its velocity in the next step (not only its share of them),
    /// to measure the choice itself.
    pub fn force_decisions(&mut self) {
        self.decide_all = true;
    }

    /// Whether everyone has arrived.
    pub fn all_arrived(&self) -> bool {
        self.movers.iter().all(|m| m.arrived.is_some())
    }

    /// Whether everyone stands: arrived, or given up.
    pub fn all_standing(&self) -> bool {
        self.movers.iter().all(Mover::standing)
    }

    /// Moves everyone on by `dt` seconds, each choosing from where all were before the step.
    pub fn step(&mut self, dt: f32) {
        let mut crowd = Crowd::unnamed(self.time, self.movers.iter().map(Mover::agent).collect());
        let still: Vec<bool> = (self.movers.iter())
            .map(|m| m.standing() || m.stuck())
            .collect();
        // who asks whom to make room
        crowd.set_ask_pairs(
            (self.movers.iter().enumerate())
                .filter(|(_, m)| !m.standing())
                .filter_map(|(i, m)| m.looking_at.map(|t| (t, i))),
        );
        let every = ((DECIDE_PERIOD / f64::from(dt)).round() as u64).max(1);
        let (steps, profile, time, all) = (self.steps, self.profile, self.time, self.decide_all);
        self.decide_all = false;
        let walls = &*self.obstacles;
        let one = |(i, m): (usize, &mut Mover)| {
            let decide = all || (steps + i as u64).is_multiple_of(every);
            let world = World {
                crowd: &crowd,
                walls,
                profile: &profile,
                still: &still,
            };
            step_one(m, i, world, decide, every as f32 * dt, dt, time);
        };
        if self.movers.len() >= PARALLEL_MOVERS {
            self.movers.par_iter_mut().enumerate().for_each(one);
        } else {
            self.movers.iter_mut().enumerate().for_each(one);
        }
        self.steps += 1;
        self.time += f64::from(dt);
    }
}

/// What every mover's step reads: the snapshot of everyone, the walls, the profile.
#[derive(Clone, Copy)]
struct World<'a> {
    crowd: &'a Crowd,
    walls: &'a Obstacles,
    profile: &'a Profile,
    /// Per mover, whether it stands or is stuck (may be asked for room).
    still: &'a [bool],
}

/// One mover's step from the snapshot (where it is index `me`).
fn step_one(m: &mut Mover, me: usize, w: World, decide: bool, period: f32, dt: f32, time: f64) {
    let World {
        crowd,
        walls,
        profile,
        ..
    } = w;
    m.follow(walls, time);
    if w.still[me] || m.aside.is_some() {
        make_room(m, me, w);
    }
    let desired = m.desired();
    let mut near = Vec::new();
    // everyone within sight when choosing, only those it may touch otherwise
    let decide = decide && !m.standing();
    let reach = if decide {
        NEIGHBOUR_RADIUS
    } else {
        2.0 * m.radius + 1.0
    };
    crowd.near(m.at, reach, &mut near);
    let others = near.iter().filter(|&&i| i != me).map(|&i| crowd.agent(i));
    if decide {
        m.avoider.wait(period, m.velocity, desired, m.speed);
        let heading = if m.velocity.length() > 0.05 {
            m.velocity.x.atan2(m.velocity.y)
        } else {
            let d = m.goal - m.at;
            d.x.atan2(d.y)
        };
        let v = (m.avoider).choose(
            m.agent(),
            desired,
            heading,
            m.speed,
            others.clone(),
            walls,
            profile,
        );
        m.chosen = m.avoider.avoiding.then_some(v);
        ask_for_room(m, me, desired, w);
    }
    let target = m.chosen.filter(|_| m.arrived.is_none()).unwrap_or(desired);
    m.velocity += (target - m.velocity).clamp_length_max(MAX_ACCELERATION * dt);
    m.at = super::contact::pushed_out(m.at + m.velocity * dt, m.radius, others, dt);
    if (m.arrived.is_none() || m.stepped) && !walls.is_empty() {
        let free = walls.push_out(m.at, m.radius);
        // a wall stops what goes into it: the velocity others see slides along the wall
        // (kept, walkers pressed against a wall seemed to their neighbours to move on through
        // it, and were squeezed into them)
        let normal = (free - m.at).normalize_or_zero();
        m.velocity -= normal * m.velocity.dot(normal).min(0.0);
        m.at = free;
    }
    m.arrive_if_there(time + f64::from(dt));
    if m.stepped && m.aside.is_none() && m.at.distance(m.goal) < ARRIVED {
        m.stepped = false;
    }
    m.keep_trying(time + f64::from(dt));
}

/// A walker held back (going its way at below half its speed) looks for someone standing (or
/// stuck) who shuts its way, and asks them for room ([`negotiate::blocker`]).
fn ask_for_room(m: &mut Mover, me: usize, desired: Vec2, w: World) {
    m.looking_at = None;
    let held = progress(m.velocity, desired) < 0.5 * m.speed;
    if !held || desired.length() < 1e-3 || m.aside.is_some() {
        return;
    }
    let mut near = Vec::new();
    w.crowd.near(m.at, negotiate::LOOKAHEAD + 1.0, &mut near);
    let standing: Vec<Standing> = (near.into_iter())
        .filter(|&i| i != me && w.still[i])
        .map(|index| {
            let a = w.crowd.agent(index);
            Standing {
                index,
                at: a.at,
                radius: a.radius,
            }
        })
        .collect();
    // stuck itself, it asks whoever stands on its line, room beside them or not: its
    // avoidance found no way round them
    let insist = m.stuck();
    let way = desired.normalize();
    m.looking_at = negotiate::blocker(m.at, way, m.radius, &standing, w.walls, insist);
}

/// One standing steps aside for a walker within [`negotiate::TRIGGER`] that asks it for room
/// (to where [`negotiate::aside`] finds), and stays there while it is asked.
fn make_room(m: &mut Mover, me: usize, w: World) {
    let asking = (w.crowd.askers(me))
        // of two stuck walkers who ask each other, the later in the crowd's order makes room
        .filter(|&i| !(m.looking_at == Some(i) && me < i))
        .map(|i| w.crowd.agent(i))
        .find(|a| a.at.distance(m.at) <= negotiate::TRIGGER);
    let Some(walker) = asking else {
        if w.crowd.askers(me).next().is_none() {
            m.aside = None;
            // pressed from its place (by one stepping aside, or passing): back when free
            m.stepped |= m.arrived.is_some() && m.at.distance(m.goal) > DISPLACED;
        }
        return;
    };
    if m.aside.is_some() {
        return;
    }
    let spot = negotiate::aside_in(w.crowd, (me, m.at, m.radius), walker, w.walls);
    if spot.is_some() {
        m.aside = spot;
        m.stepped = true;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A walker whose place is ringed by eight people standing 0.8 m apart (gaps of 0.3 m).
    fn hemmed_in() -> Sim {
        let mut movers = vec![Mover::new(Vec2::new(0.0, -4.0), Vec2::ZERO, 0.25, 1.3)];
        for (x, z) in [
            (-1, -1),
            (0, -1),
            (1, -1),
            (-1, 0),
            (1, 0),
            (-1, 1),
            (0, 1),
            (1, 1),
        ] {
            let at = Vec2::new(x as f32, z as f32) * 0.8;
            movers.push(Mover::new(at, at, 0.25, 1.3));
        }
        Sim::new(movers)
    }

    #[test]
    fn one_standing_in_the_way_steps_aside_when_asked_and_goes_back() {
        let mut s = hemmed_in();
        let (mut asked, mut deepest) = (None, 0f32);
        while !(s.movers[0].standing() && s.movers.iter().all(|m| !m.stepped)) && s.time < 40.0 {
            s.step(1.0 / 30.0);
            asked = asked.or(s.movers[0].looking_at);
            for (i, a) in s.movers.iter().enumerate() {
                for b in &s.movers[i + 1..] {
                    deepest = deepest.max(a.radius + b.radius - a.at.distance(b.at));
                }
            }
        }
        let walker = &s.movers[0];
        assert!(walker.arrived.is_some(), "{walker:?}");
        assert_eq!(
            asked,
            Some(2),
            "it asks the one in front of its place, at (0, -0.8)"
        );
        assert!(deepest <= 0.01, "bodies {deepest} m into each other");
        for m in &s.movers[1..] {
            assert!(m.at.distance(m.goal) < 0.06, "{m:?} is not back");
        }
    }

    #[test]
    fn a_walker_that_cannot_reach_its_place_gives_up_and_says_so() {
        // its place ringed twice, packed tight: nobody can step aside
        let mut movers = vec![Mover::new(Vec2::new(0.0, -4.0), Vec2::ZERO, 0.25, 1.3)];
        for k in 0..16 {
            let a = std::f32::consts::TAU * k as f32 / 16.0;
            let at = Vec2::new(a.sin(), a.cos()) * 0.6;
            movers.push(Mover::new(at * 1.9, at * 1.9, 0.25, 1.3));
            movers.push(Mover::new(at, at, 0.25, 1.3));
        }
        let mut s = Sim::new(movers);
        while !s.all_standing() && s.time < 100.0 {
            s.step(1.0 / 30.0);
        }
        let walker = &s.movers[0];
        assert!(
            walker.arrived.is_none() && walker.gave_up.is_some(),
            "{walker:?}"
        );
        assert!(walker.gave_up.unwrap() < 100.0);
    }

    #[test]
    fn a_pair_head_on_passes_and_arrives_and_threads_change_nothing() {
        let pair = || {
            Sim::new(vec![
                Mover::new(Vec2::new(0.0, -5.0), Vec2::new(0.0, 5.0), 0.25, 1.3),
                Mover::new(Vec2::new(0.0, 5.0), Vec2::new(0.0, -5.0), 0.25, 1.3),
            ])
        };
        let mut s = pair();
        let mut closest = f32::INFINITY;
        while !s.all_arrived() && s.time < 30.0 {
            s.step(1.0 / 30.0);
            closest = closest.min(s.movers[0].at.distance(s.movers[1].at));
        }
        assert!(s.all_arrived(), "{:?}", s.movers);
        assert!(closest > 0.5, "{closest}");
        // a crowd big enough for threads gives what one thread gives
        let many = |n: usize| {
            let mut movers = Vec::new();
            for k in 0..n {
                let a = std::f32::consts::TAU * k as f32 / n as f32;
                let p = Vec2::new(a.sin(), a.cos()) * 12.0;
                movers.push(Mover::new(p, -p, 0.25, 1.3));
            }
            Sim::new(movers)
        };
        let (mut a, mut b) = (many(80), many(80));
        for _ in 0..60 {
            a.step(1.0 / 30.0);
        }
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        pool.install(|| {
            for _ in 0..60 {
                b.step(1.0 / 30.0);
            }
        });
        for (x, y) in a.movers.iter().zip(&b.movers) {
            assert_eq!(x.at, y.at);
        }
    }
}
