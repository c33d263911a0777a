//! The seed's wall-and-goal scene, walked by footsteps; the budget and the stagger.

use super::*;
use crate::world::space::{Obstacle, Obstacles, Shape};

/// The scene of the seed's figure 1: the goal beyond a wall, the straight way to it blocked
/// near the wall's end.
fn wall() -> Obstacles {
    Obstacles::new(vec![Obstacle {
        shape: Shape::Segment {
            a: Vec2::new(-4.0, 5.0),
            b: Vec2::new(3.0, 5.0),
        },
        height: 2.0,
    }])
}

const GOAL: Vec2 = Vec2::new(4.0, 10.0);

/// Arriving: within this of the goal (m).
const ARRIVE: f32 = 0.3;

/// Walks from the origin facing +z to `GOAL` with the whole fan (or `samples`); the steps,
/// until no step lowers the energy (or 200 steps).
pub(super) fn walk(obstacles: &Obstacles, samples: usize) -> Vec<Footstep> {
    let (mut net, w) = walking_net(GOAL, ARRIVE, 1.5, 1.0);
    let fan = Fan::new(0.69, 0.8, 9);
    let mut feet = Feet::standing(Vec2::ZERO, 0.0);
    let mut here = (Vec2::ZERO, 0.0);
    let mut steps = Vec::new();
    for _ in 0..200 {
        let env = Surroundings {
            at: here.0,
            heading: here.1,
            obstacles,
            walkers: &[],
        };
        let Some(s) = choose(&mut net, w, &feet, &fan, samples, &env, 0.25) else {
            break;
        };
        steps.push(s);
        feet = feet.after(&s);
        here = (s.body, s.heading);
        // arrived: the trailing foot closes beside the one just planted
        if feet.body().distance(GOAL) <= ARRIVE {
            steps.push(Footstep {
                at: feet.body() * 2.0 - feet.planted,
                heading: feet.heading,
                body: feet.body(),
                energy: 0.0,
            });
            break;
        }
    }
    steps
}

/// How often the body's sideways motion (across the straight line from start to goal)
/// changes direction, ignoring wobbles under 2 cm.
fn reversals(path: &[Vec2]) -> usize {
    let across = Vec2::new(GOAL.y, -GOAL.x).normalize();
    crate::world::crowd::quality::sideways_reversals(path, across, 0.02)
}

#[test]
fn the_wall_and_goal_scene_is_walked_without_zig_zag_and_arrives() {
    let steps = walk(&wall(), usize::MAX);
    let path: Vec<Vec2> = steps.iter().map(|s| s.body).collect();
    let end = *path.last().expect("it walks");
    assert!(
        end.distance(GOAL) <= 0.3,
        "stopped at {end}, {} from the goal",
        end.distance(GOAL)
    );
    assert!(
        reversals(&path) <= 2,
        "{} reversals: {path:?}",
        reversals(&path)
    );
    // it went round the wall's end, never through the wall, keeping clear of it
    let o = wall();
    for s in &steps {
        assert!(
            o.clearance(s.body, 2.0) >= 0.25,
            "{:?} too near the wall",
            s.body
        );
    }
    // each step lands a fan length ahead of the foot planted before it, a hip width to
    // the other side (left and right in turn); the last closes the feet
    let fan = Fan::new(0.69, 0.8, 9);
    let mut side = 1.0;
    for w in steps[..steps.len() - 1].windows(2) {
        let (planted, step) = (w[0].at, w[1]);
        let (ahead, left) = axes(step.heading);
        let length = (step.at - planted).dot(ahead);
        let across = (step.at - planted).dot(left);
        assert!(
            fan.lengths.iter().any(|l| (l - length).abs() < 1e-4),
            "a step of {length} m"
        );
        assert!(
            (across - side * 2.0 * HALF_WIDTH).abs() < 1e-4,
            "{across} m aside"
        );
        side = -side;
    }
}

/// The seed's naive motor: each step turns by the net's summed Δθ where the agent stands
/// (within the fan's turns) and takes a medium step: following the field's gradient from
/// where it is instead of sampling where it could be.
fn naive_walk(obstacles: &Obstacles) -> Vec<Vec2> {
    let (mut net, w) = walking_net(GOAL, ARRIVE, 1.5, 1.0);
    let mut feet = Feet::standing(Vec2::ZERO, 0.0);
    let mut here = (Vec2::ZERO, 0.0f32);
    let mut path = Vec::new();
    for _ in 0..40 {
        let env = Surroundings {
            at: here.0,
            heading: here.1,
            obstacles,
            walkers: &[],
        };
        let turn = net.settle(&env)[w][0].clamp(-0.8, 0.8);
        let (at, heading) = feet.candidate(0.69, turn);
        if !obstacles.segment_clear(feet.planted, at, 0.01) {
            break;
        }
        let body = (feet.planted + at) / 2.0;
        feet = feet.after(&Footstep {
            at,
            heading,
            body,
            energy: 0.0,
        });
        here = (body, heading);
        path.push(body);
        if body.distance(GOAL) <= ARRIVE {
            break;
        }
    }
    path
}

#[test]
fn following_the_field_where_the_agent_stands_does_not_get_round_the_wall_where_the_fan_does() {
    // the summed turn where the agent stands: attraction and the wall's repulsion cancel and
    // it walks into the wall (the seed's discontinuity at the threshold); sampling the fan
    // of where it could stand goes round
    let naive = naive_walk(&wall());
    let end = *naive.last().unwrap();
    assert!(end.distance(GOAL) > 3.0, "the naive motor got to {end}");
    let fan = walk(&wall(), usize::MAX);
    assert!(fan.last().unwrap().body.distance(GOAL) <= ARRIVE);
}

#[test]
fn a_budget_lowers_the_samples_and_agents_are_staggered() {
    assert_eq!(allot(10_000, 10, 27), 27);
    assert_eq!(allot(100, 10, 27), 10);
    assert_eq!(allot(10, 10, 27), 3);
    let starts: Vec<f64> = (0..4).map(|i| stagger(i, 4, 0.5)).collect();
    assert_eq!(starts, [0.0, 0.125, 0.25, 0.375]);
}
