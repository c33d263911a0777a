//! A procedural human gait, driven by the distance walked. One phase runs through a gait cycle
//! (two steps); it advances by distance / stride, so that steps are as long as human walking
//! makes them at that speed (the walk ratio, below) and no foot slides. Each foot is either
//! planted, fixed on the ground in world coordinates, or swinging from where it lifted off to
//! where it will land; a planted foot rolls over its heel after heel strike and over the ball of
//! the foot before toe-off, about points that stay fixed on the ground. The pose is made at
//! render time: the pelvis over the feet (its height capped so that every planted foot stays
//! within reach), rotation, list and sideways sway of the pelvis with a counter-rotation of the
//! trunk, the arms swinging against the legs, and two-link IK from each hip to its ankle.
//! When the walker stands, stepping goes on at a slow cadence until both feet are planted
//! beside each other, square to the facing; then the phase stops.
//!
//! Cadence and step length follow the *walk ratio* (step length / cadence), which stays close
//! to 0.0061 m per step/min across walking speeds in healthy adults (Sekiya & Nagasaki 1998,
//! Gait & Posture 7:225–227): at speed v, cadence = √(60 v / W) steps/min and step length =
//! W × cadence, which gives 113 steps/min and 0.69 m at 1.3 m/s. Running takes 150 + 10 v
//! steps/min (180 at 3 m/s), with a flight phase (stance 38 % of the cycle).

use glam::{Quat, Vec2, Vec3};

pub use super::knee::{stance_knee, KNEE_RATE, STANDING_KNEE};

/// A planted foot further than this (m) from where it would stand beside the body is out of
/// the leg's reach (at 1.3 m/s a foot leaves the ground 0.58 m behind).
pub const OUT_OF_REACH: f32 = 0.7;
/// A planted foot further behind the body than this (m) … see `Gait::hurry`.
pub const STRAIN_BEHIND: f32 = 0.45;
/// … and turned against it by more than this (rad) strains the hip.
pub const STRAIN_TWIST: f32 = 0.3;
/// Slowest walk that hurries its steps (m/s).
pub const HURRY_SPEED: f32 = 0.6;
/// Strain (m × rad beyond both) a step bears at its own pace: rounding the table of the
/// example room at 1.27 m/s reaches up to about 0.01 (hurried there, the walk ended 0.3 s
/// later and the head led the turns less); the plaza's dragged foot bore 0.013–0.016.
pub const STRAIN_FREE: f32 = 0.011;
/// Each this much strain beyond [`STRAIN_FREE`] adds one cadence to the stepping.
pub const STRAIN_PER_CADENCE: f32 = 0.003;
/// People's own walking speed (m/s), WALK's: the norms the gait's speed-scaled sizes start from.
pub const OWN_PACE: f32 = 1.3;
/// The walk ratio (m per step/min).
pub const WALK_RATIO: f32 = 0.0061;
/// Slowest cadence of stepping (steps/min): turning on the spot, closing the feet.
pub const MIN_CADENCE: f32 = 80.0;
/// Cadence of stepping on the spot (steps/min): turning, closing the feet.
pub const SPOT_CADENCE: f32 = 110.0;
/// Half the distance between the feet (m): the hips' half width.
pub const HALF_WIDTH: f32 = 0.09;
/// A foot counts as placed where it belongs when within this (m) and [`SETTLED_YAW`].
pub const SETTLED: f32 = 0.04;
/// … and turned within this (rad).
pub const SETTLED_YAW: f32 = 0.12;

/// Cadence (steps per minute) at `speed` (m/s).
pub fn cadence(speed: f32, running: bool) -> f32 {
    if running {
        150.0 + 10.0 * speed
    } else {
        (60.0 * speed.max(0.0) / WALK_RATIO).sqrt().max(MIN_CADENCE)
    }
}

/// Step length (m) at `speed`: speed × 60 / cadence.
pub fn step_length(speed: f32, running: bool) -> f32 {
    speed.max(0.0) * 60.0 / cadence(speed, running)
}

/// A foot: planted somewhere or swinging.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Foot {
    /// On the ground: the ankle's ground point (x, z) and the foot's heading (rad about +y).
    Planted {
        /// Where (x, z).
        at: Vec2,
        /// Its heading.
        yaw: f32,
    },
    /// In the air since lifting off at `from` with heading `from_yaw`.
    Swing {
        /// Where it lifted off.
        from: Vec2,
        /// Its heading then.
        from_yaw: f32,
        /// The foot's phase when it lifted: the stance's end, or later for a foot that stayed
        /// down into its swing's phase (it lifts flat, and swings in what is left).
        since: f32,
    },
}

/// The gait state of one walker: the cycle phase and both feet (left, right).
#[derive(Debug, Clone, PartialEq)]
pub struct Gait {
    /// Phase through the cycle, [0, 1): the left foot strikes at 0, the right at ½.
    pub phase: f32,
    /// Left and right foot.
    pub feet: [Foot; 2],
    /// Whether running (flight phase).
    pub running: bool,
    /// The speed the walker goes at (for step lengths), m/s.
    pub speed: f32,
    /// Heading of travel (x, z), unit.
    pub heading: Vec2,
    /// Where the body will stop, while it slows down for good: feet land no further.
    pub stop_at: Option<Vec2>,
    /// How much the body walks (0 standing, 1 walking from 0.6 m/s): the size of the pelvis
    /// motion, the arm swing and the feet's rolls, following the speed within about 0.25 s
    /// so that it never jumps.
    pub amount: f32,
    /// How fast the body turns (rad/s, positive to the left): a foot lands turned ahead by
    /// half its stance's turn, so that the leg twists as little one way as the other.
    pub turn_rate: f32,
    /// The least bend of each knee (rad) the pelvis is lowered to: following
    /// [`stance_knee`] at the foot's phase, no faster than [`KNEE_RATE`].
    pub knee: [f32; 2],
}

/// Where the walker's body is: its ground position and facing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Body {
    /// Root on the ground (x, z).
    pub at: Vec2,
    /// Facing, radians about +y from +z.
    pub facing: f32,
}

/// The unit vector of heading `yaw` (radians about +y from +z), as (x, z).
pub fn forward(yaw: f32) -> Vec2 {
    Vec2::new(yaw.sin(), yaw.cos())
}

/// `a − b` wrapped into (−π, π].
pub fn angle_diff(a: f32, b: f32) -> f32 {
    crate::character::body::limits::wrap(a - b)
}

/// Most the body turns away from a planted foot's heading while walking (rad): the hip's
/// twist (45°) less the pelvis's own rotation in the stride and a margin (at 30° the body turned in
/// jerks round a table: the head no longer led its turns).
pub const MAX_STANCE_TWIST: f32 = 0.6;

/// The least of its swing (fraction of a cycle) a foot that stayed down into its swing's phase
/// must have left to lift; with less it waits for its next stance.
const LATE_LIFT: f32 = 0.2;

/// How far ahead of a landing foot the body is, in stances' lengths, when it lands.
const LANDING_LEAD: f32 = 0.42;
/// How far the body may pass a planted foot ahead of the foot's phase before the stepping
/// quickens (m).
const AHEAD_FREE: f32 = 0.08;
/// Each this much further (m) adds one cadence to the stepping.
const AHEAD_PER_CADENCE: f32 = 0.1;

/// Side of each foot: +1 left (+x when facing +z), −1 right.
const SIDE: [f32; 2] = [1.0, -1.0];
/// Phase offset of each foot.
const OFFSET: [f32; 2] = [0.0, 0.5];

impl Gait {
    /// Standing at `body` with both feet planted beside each other.
    pub fn standing(body: Body) -> Gait {
        let mut g = Gait {
            phase: 0.05,
            feet: [Foot::Planted {
                at: Vec2::ZERO,
                yaw: 0.0,
            }; 2],
            running: false,
            speed: 0.0,
            heading: forward(body.facing),
            stop_at: None,
            amount: 0.0,
            turn_rate: 0.0,
            knee: [STANDING_KNEE; 2],
        };
        for k in 0..2 {
            g.feet[k] = Foot::Planted {
                at: standing_spot(body, k),
                yaw: body.facing,
            };
        }
        g
    }

    /// The stance fraction of the cycle.
    pub fn stance(&self) -> f32 {
        if self.running {
            0.38
        } else {
            0.6
        }
    }

    /// Foot `k`'s own phase: 0 at its heel strike, stance until [`stance`](Self::stance).
    pub fn foot_phase(&self, k: usize) -> f32 {
        (self.phase + 1.0 - OFFSET[k]).fract()
    }

    /// The length of one cycle (two steps) at the current speed, m.
    pub fn stride(&self) -> f32 {
        let spot = SPOT_CADENCE - (SPOT_CADENCE - MIN_CADENCE) * (self.speed / 0.3).min(1.0);
        2.0 * self.speed * 60.0 / cadence(self.speed, self.running).max(spot)
    }

    /// Whether foot `k` is planted where it belongs for a body standing at `body`.
    fn settled(&self, k: usize, body: Body) -> bool {
        match self.feet[k] {
            Foot::Planted { at, yaw } => {
                at.distance(standing_spot(body, k)) < SETTLED
                    && angle_diff(yaw, body.facing).abs() < SETTLED_YAW
            }
            Foot::Swing { .. } => false,
        }
    }

    /// Whether planted foot `k` stays down rather than take its next step: it is where it
    /// belongs and the body stands, or the body is about to stop (within 0.1 m) where the
    /// foot already belongs.
    fn stays(&self, k: usize, body: Body) -> bool {
        let standing = self.speed < 0.05 && self.settled(k, body);
        let stopping = self
            .stop_at
            .is_some_and(|at| at.distance(body.at) < 0.1 && self.settled(k, Body { at, ..body }));
        standing || stopping
    }

    /// `facing` turned back, if need be, to within [`MAX_STANCE_TWIST`] of every planted
    /// foot's heading: a body turning in a tight curve turns over its planted foot only as far
    /// as the hip twists, and the rest of the turn waits for the next step (beyond it the hip's
    /// limit held the leg back and swung the planted foot round: seen in the plaza, a ball of
    /// the foot sliding 10 cm).
    pub fn within_stance_twist(&self, facing: f32) -> f32 {
        let mut out = facing;
        for foot in self.feet {
            if let Foot::Planted { yaw, .. } = foot {
                let off = angle_diff(out, yaw);
                if off.abs() > MAX_STANCE_TWIST {
                    out = yaw + off.signum() * MAX_STANCE_TWIST;
                }
            }
        }
        out
    }

    /// How much quicker than its cadence the walker steps (1 or more): a planted foot both
    /// left far behind the body (beyond [`STRAIN_BEHIND`]) and twisted against it (beyond
    /// [`STRAIN_TWIST`]) lifts sooner, before the hip runs out of range. Either alone is a
    /// normal step: at 1.3 m/s a foot is 0.58 m behind at toe-off, and round a corner the body
    /// turns 34° over it; a walker speeding up out of a 30° turn over a foot 0.55 m behind
    /// could no longer reach it, and dragged it 8 cm (seen in the plaza).
    fn hurry(&self, body: Body) -> f32 {
        let behind = self.behind_its_phase(body);
        // (only walking on: stopping and turning on the spot the feet close at their own pace)
        if self.speed < HURRY_SPEED {
            return behind;
        }
        let strain = (self.feet.iter())
            .filter_map(|foot| match *foot {
                Foot::Planted { at, yaw } => {
                    let behind = (body.at - at).dot(self.heading) - STRAIN_BEHIND;
                    let twist = angle_diff(body.facing, yaw).abs() - STRAIN_TWIST;
                    Some(behind.max(0.0) * twist.max(0.0))
                }
                Foot::Swing { .. } => None,
            })
            .fold(0.0f32, f32::max);
        behind.max(1.0 + (strain - STRAIN_FREE).max(0.0) / STRAIN_PER_CADENCE)
    }

    /// How much quicker than its cadence the walker steps (1 or more) because a planted foot is
    /// further behind the body than its phase says: a foot lands [`LANDING_LEAD`] of a stance
    /// ahead and is passed at the cadence's pace, but a body speeding up (setting off, after a
    /// turn on the spot) passes it sooner; stepping at the slow cadence of its speed, the walker
    /// left the foot 0.55 m behind while its phase still stood in mid-stance, and the pelvis sank
    /// 20 cm to reach it. Each [`AHEAD_PER_CADENCE`] beyond [`AHEAD_FREE`] adds one cadence.
    fn behind_its_phase(&self, body: Body) -> f32 {
        let (stride, beta) = (self.stride(), self.stance());
        let ahead = (0..2)
            .filter_map(|k| match self.feet[k] {
                Foot::Planted { at, .. } if self.foot_phase(k) < beta => {
                    let expected = stride * (self.foot_phase(k) - LANDING_LEAD * beta);
                    Some((body.at - at).dot(self.heading) - expected)
                }
                _ => None,
            })
            .fold(0.0f32, f32::max);
        1.0 + (ahead - AHEAD_FREE).max(0.0) / AHEAD_PER_CADENCE
    }

    /// Whether foot `k`, planted `at`, is further than [`OUT_OF_REACH`] (or three quarters of
    /// a stride, when walking fast) from where it would stand beside the body: further than
    /// any step leaves it.
    fn out_of_reach(&self, k: usize, at: Vec2, body: Body) -> bool {
        at.distance(standing_spot(body, k)) > OUT_OF_REACH.max(0.75 * self.stride())
    }

    /// Whether the walker stands: both feet planted where they belong and no speed.
    pub fn at_rest(&self, body: Body) -> bool {
        self.speed < 0.02 && self.settled(0, body) && self.settled(1, body)
    }

    /// Where swinging foot `k` will land at its phase's end, `left` cycles from now: ahead of
    /// the body by the distance it will cover until then and a little less than half a
    /// stance, beside the line of travel; beside the stopping point when that is nearer.
    pub fn landing(&self, k: usize, body: Body, left: f32) -> Vec2 {
        let stride = self.stride();
        let lead = (left.max(0.0) * stride + self.stance() * stride * LANDING_LEAD).min(0.55);
        if let Some(stop) = self.stop_at {
            if stop.distance(body.at) < lead + 0.05 {
                return standing_spot(
                    Body {
                        at: stop,
                        facing: body.facing,
                    },
                    k,
                );
            }
        }
        let side = Vec2::new(body.facing.cos(), -body.facing.sin()) * (SIDE[k] * HALF_WIDTH);
        body.at + self.heading * lead + side
    }

    /// The heading a foot lands with: the body's, turned ahead by half a stance of turning.
    pub fn landing_yaw(&self, body: Body) -> f32 {
        let stance_time =
            self.stance() * 120.0 / cadence(self.speed, self.running).max(SPOT_CADENCE);
        body.facing + self.turn_rate * stance_time * 0.5
    }

    /// Advances the gait by `dt` seconds for a body at `body` moving at `velocity` (x, z).
    pub fn step(&mut self, dt: f32, body: Body, velocity: Vec2) {
        self.speed = velocity.length();
        let target = smooth(self.speed / 0.6);
        self.amount += (target - self.amount) * (1.0 - (-dt / 0.25).exp());
        self.bend_the_knees(dt);
        if self.speed > 0.05 {
            self.heading = velocity / self.speed;
        } else {
            self.heading = forward(body.facing);
        }
        if self.at_rest(body) {
            return;
        }
        // on the spot (turning, closing the feet) quicker steps than the slowest walk
        let spot = SPOT_CADENCE - (SPOT_CADENCE - MIN_CADENCE) * (self.speed / 0.3).min(1.0);
        let cycles_per_s = cadence(self.speed, self.running).max(spot) / 120.0 * self.hurry(body);
        let before = [self.foot_phase(0), self.foot_phase(1)];
        self.phase = (self.phase + cycles_per_s * dt).fract();
        for (k, &was) in before.iter().enumerate() {
            let now = self.foot_phase(k);
            let beta = self.stance();
            // a foot lifts as its phase enters the swing, or later in the swing when it stayed
            // down until then (setting off from standing: the foot whose phase stood in its swing
            // stayed planted a whole cycle, and the body ran 0.6 m ahead of it), unless too
            // little of the swing is left to make one
            let lifts = now >= beta && (was < beta || 1.0 - now > LATE_LIFT);
            let lands = now < was; // wrapped: heel strike
            let other_planted = matches!(self.feet[1 - k], Foot::Planted { .. });
            match self.feet[k] {
                // a planted foot the body has left out of the leg's reach (pushed in a press of
                // people) lifts at once and steps after it, while the other foot stands
                Foot::Planted { at, yaw } if other_planted && self.out_of_reach(k, at, body) => {
                    self.feet[k] = Foot::Swing {
                        from: at,
                        from_yaw: yaw,
                        since: now,
                    };
                }
                // a foot already where it belongs stays down while the body stands, or
                // where it will belong when the body, nearly there, stops
                Foot::Planted { at, yaw } if lifts && !self.stays(k, body) => {
                    self.feet[k] = Foot::Swing {
                        from: at,
                        from_yaw: yaw,
                        since: if was < beta { beta } else { now },
                    };
                }
                Foot::Swing { .. } if lands => {
                    self.feet[k] = Foot::Planted {
                        at: self.landing(k, body, 0.0),
                        yaw: self.landing_yaw(body),
                    };
                }
                _ => {}
            }
        }
    }
}

/// Where foot `k` stands when the body stands at `body`.
pub fn standing_spot(body: Body, k: usize) -> Vec2 {
    body.at + Vec2::new(body.facing.cos(), -body.facing.sin()) * (SIDE[k] * HALF_WIDTH)
}

/// Where a foot is in one frame: its ankle (world, m) and orientation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FootPose {
    /// The ankle joint's position.
    pub ankle: Vec3,
    /// The foot's orientation (heading, then pitch: positive lifts the toes).
    pub yaw: f32,
    /// Pitch (rad; positive: toes up).
    pub pitch: f32,
    /// Whether it is on the ground.
    pub planted: bool,
}

/// Height of the ankle joint above the ground with the foot flat (m).
pub const ANKLE_HEIGHT: f32 = 0.05;
/// The heel's contact point behind the ankle (m).
pub const HEEL_BACK: f32 = 0.05;
/// The ball of the foot ahead of the ankle (m).
pub const BALL_AHEAD: f32 = 0.12;

/// The ankle when the foot, flat with its ankle over `at`, is pitched by `pitch` about a point
/// on its sole `pivot_ahead` metres ahead of the ankle.
fn rolled(at: Vec2, yaw: f32, pitch: f32, pivot_ahead: f32) -> Vec3 {
    let f = forward(yaw);
    let pivot = Vec3::new(at.x, 0.0, at.y) + Vec3::new(f.x, 0.0, f.y) * pivot_ahead;
    let ankle_rel = Vec3::new(-f.x, 0.0, -f.y) * pivot_ahead + Vec3::Y * ANKLE_HEIGHT;
    // toes up turns the foot about its own left axis
    let axis = Vec3::new(f.y, 0.0, -f.x);
    pivot + Quat::from_axis_angle(axis, -pitch) * ankle_rel
}

impl Gait {
    /// How far foot `k` is through its swing (0 lifting, 1 landing); 0 when planted.
    pub fn swing_progress(&self, k: usize) -> f32 {
        match self.feet[k] {
            Foot::Swing { since, .. } => {
                ((self.foot_phase(k) - since) / (1.0 - since).max(1e-3)).clamp(0.0, 1.0)
            }
            Foot::Planted { .. } => 0.0,
        }
    }

    /// Foot `k` in this frame for a body at `body`; `amount` (0–1) scales the heel and toe
    /// rolls (none while stepping slowly).
    pub fn foot_pose(&self, k: usize, body: Body, amount: f32) -> FootPose {
        let psi = self.foot_phase(k);
        let beta = self.stance();
        let (strike, toe_off) = (
            0.25 * amount,
            if self.running { 0.8 } else { 0.85 } * amount,
        );
        match self.feet[k] {
            Foot::Planted { at, yaw } => {
                let heel = beta * 0.12;
                let roll = beta * 0.5;
                let (ankle, pitch) = if psi < heel {
                    let p = strike * (1.0 - smooth(psi / heel));
                    (rolled(at, yaw, p, -HEEL_BACK), p)
                } else if psi >= roll && psi < beta {
                    let p = -toe_off * smooth((psi - roll) / (beta - roll));
                    (rolled(at, yaw, p, BALL_AHEAD), p)
                } else {
                    (Vec3::new(at.x, ANKLE_HEIGHT, at.y), 0.0)
                };
                FootPose {
                    ankle,
                    yaw,
                    pitch,
                    planted: true,
                }
            }
            Foot::Swing {
                from,
                from_yaw,
                since,
            } => {
                let s = self.swing_progress(k);
                // (a foot lifting late lifts flat)
                let toe_off = if since > beta { 0.0 } else { toe_off };
                let to = self.landing(k, body, 1.0 - psi);
                // (stepping slowly, setting off, it lifts before it goes)
                let e = smooth(s.powf(1.0 - (1.0 - SWING_LEAD) * amount));
                let yaw = from_yaw + angle_diff(self.landing_yaw(body), from_yaw) * e;
                // (rising on a little and held into the first half of the swing: people's
                // ankle is most toes-down just after the toe-off)
                let push = 0.5 * (std::f32::consts::PI * (s / 0.3).min(1.0)).sin();
                let pitch = -toe_off * (1.0 - smooth(s / 0.5) + push) + strike * smooth(s);
                // the foot rises most early in its swing, while the knee bends (people's knee
                // peaks at about 70 % of the cycle, a third into the swing), and passes low
                // (lower slower: people's swing knee bends less at a slow walk; stepping on
                // the spot or setting off, as high as ever)
                let lift = if self.running {
                    0.18
                } else {
                    let walking = 0.05 + 0.03 * (self.speed / OWN_PACE).min(1.0);
                    0.11 + (walking - 0.11) * amount
                };
                let clearance = lift * swing_lift(s) * (0.3 + 0.7 * amount);
                // (the rise on is about the ball, which stays where it left the floor)
                let start = rolled(from, from_yaw, -toe_off * (1.0 + push), BALL_AHEAD);
                let end = rolled(to, self.landing_yaw(body), strike, -HEEL_BACK);
                let flat = start.lerp(end, e);
                FootPose {
                    ankle: flat + Vec3::Y * clearance,
                    yaw,
                    pitch,
                    planted: false,
                }
            }
        }
    }
}

/// The swing's lift at `s` of it (0 to 1), highest halfway.
fn swing_lift(s: f32) -> f32 {
    (std::f32::consts::PI * s.clamp(0.0, 1.0)).sin()
}

/// The swinging foot comes forward early: its way along is smoothstep of its progress to this
/// power (it passes under the hip about 40 % into the swing; halfway, the knee peaked late).
const SWING_LEAD: f32 = 0.75;

/// Smoothstep on [0, 1].
pub fn smooth(x: f32) -> f32 {
    let x = x.clamp(0.0, 1.0);
    x * x * (3.0 - 2.0 * x)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_walk_ratio_gives_human_cadence_and_steps() {
        // 1.3 m/s: about 115 steps/min and 0.7 m steps
        let c = cadence(1.3, false);
        assert!((c - 115.0).abs() < 5.0, "{c}");
        assert!((step_length(1.3, false) - 0.7).abs() < 0.03);
        // slower: both shrink
        assert!(cadence(0.8, false) < c && step_length(0.8, false) < 0.6);
        // running at 3 m/s: 180 steps/min, 1 m steps
        assert!((cadence(3.0, true) - 180.0).abs() < 1e-3);
        assert!((step_length(3.0, true) - 1.0).abs() < 1e-3);
    }

    #[test]
    fn a_walking_gait_alternates_its_feet_and_plants_each_for_good() {
        let body = Body {
            at: Vec2::ZERO,
            facing: 0.0,
        };
        let mut g = Gait::standing(body);
        assert!(g.at_rest(body));
        let (mut b, dt, v) = (body, 1.0 / 240.0, Vec2::new(0.0, 1.3));
        let mut plants: Vec<(usize, Vec2)> = Vec::new();
        for _ in 0..(240 * 5) {
            b.at += v * dt;
            let was = g.feet;
            g.step(dt, b, v);
            for (k, (before, after)) in was.into_iter().zip(g.feet).enumerate() {
                if let (Foot::Swing { .. }, Foot::Planted { at, .. }) = (before, after) {
                    plants.push((k, at));
                }
                // a planted foot never moves
                if let (Foot::Planted { at: a, .. }, Foot::Planted { at: c, .. }) = (before, after)
                {
                    assert_eq!(a, c);
                }
            }
        }
        assert!(plants.len() >= 8, "{plants:?}");
        for w in plants.windows(2).skip(2) {
            assert_ne!(w[0].0, w[1].0, "feet alternate");
            let step = w[1].1.y - w[0].1.y;
            assert!((step - 0.69).abs() < 0.08, "{step}");
        }
    }

    #[test]
    fn a_foot_the_body_is_pushed_away_from_lifts_and_steps_after_it() {
        let body = Body {
            at: Vec2::ZERO,
            facing: 0.0,
        };
        let mut g = Gait::standing(body);
        // pushed 0.8 m to the side in a press, not walking: the foot left furthest behind
        // lifts at once (it stayed down, and the pelvis sank to reach it)
        let pushed = Body {
            at: Vec2::new(0.8, 0.0),
            ..body
        };
        g.step(1.0 / 60.0, pushed, Vec2::ZERO);
        let swinging = (g.feet.iter())
            .filter(|f| matches!(f, Foot::Swing { .. }))
            .count();
        assert_eq!(swinging, 1, "{:?}", g.feet);
        // and both feet end beside the body
        for _ in 0..240 {
            g.step(1.0 / 60.0, pushed, Vec2::ZERO);
        }
        assert!(g.at_rest(pushed), "{:?}", g.feet);
    }
}
