//! The control laws against the seed's piecewise formulas, and order independence.

use super::*;
use proptest::prelude::*;
use std::f32::consts::PI;

#[test]
fn attract_follows_its_piecewise_law() {
    // within both thresholds: nothing
    assert_eq!(attract(0.1, 1.0, 0.2, 1.5, 2.0, 3.0), (0.0, 0.0));
    // beyond them: proportional to the excess, towards the threshold
    assert_eq!(
        attract(0.5, 4.0, 0.2, 1.5, 2.0, 3.0),
        (2.0 * (0.5 - 0.2), 3.0 * (4.0 - 1.5))
    );
    assert_eq!(
        attract(-0.5, 1.5, 0.2, 1.5, 2.0, 3.0),
        (2.0 * (-0.5 + 0.2), 0.0)
    );
    // at the thresholds exactly: nothing
    assert_eq!(attract(0.2, 1.5, 0.2, 1.5, 2.0, 3.0), (0.0, 0.0));
    assert_eq!(attract(-0.2, 1.5, 0.2, 1.5, 2.0, 3.0), (0.0, 0.0));
}

#[test]
fn avoid_follows_its_piecewise_law_with_the_distance_label_corrected() {
    // beyond the threshold: nothing
    assert_eq!(avoid(0.3, 2.1, 2.0, 1.5, 4.0), (0.0, 0.0));
    // within it: turn to put the thing behind, and Δd = k_d (t_d − d)
    let (dt, dd) = avoid(0.3, 1.5, 2.0, 1.5, 4.0);
    assert!((dt - 1.5 * (PI - 0.3)).abs() < 1e-6);
    assert_eq!(dd, 4.0 * (2.0 - 1.5));
    let (dt, _) = avoid(-0.3, 1.5, 2.0, 1.5, 4.0);
    assert!((dt - 1.5 * (-PI + 0.3)).abs() < 1e-6);
    // θ = 0 counts as the left side
    assert!((avoid(0.0, 1.0, 2.0, 1.0, 1.0).0 - PI).abs() < 1e-6);
}

#[test]
fn sensors_read_bearing_and_distance_in_the_agent_s_frame() {
    let obstacles = Obstacles::default();
    let walkers = [Vec2::new(1.0, 1.0), Vec2::new(-3.0, 0.0)];
    let env = Surroundings {
        at: Vec2::ZERO,
        heading: 0.0,
        obstacles: &obstacles,
        walkers: &walkers,
    };
    // a point to the left (+x, facing +z): positive bearing
    let (t, d) = sense(&Sensor::Location(Vec2::new(2.0, 0.0)), &env);
    assert!((t - PI / 2.0).abs() < 1e-6 && (d - 2.0).abs() < 1e-6);
    let (t, d) = sense(
        &Sensor::Line(Vec2::new(-5.0, 3.0), Vec2::new(5.0, 3.0)),
        &env,
    );
    assert!(t.abs() < 1e-6 && (d - 3.0).abs() < 1e-6);
    // the walker ahead-left is in a ±60° field; the one to the right is not
    let (t, d) = sense(
        &Sensor::Walkers {
            range: 5.0,
            half_field: PI / 3.0,
        },
        &env,
    );
    assert!((t - PI / 4.0).abs() < 1e-6 && (d - 2f32.sqrt()).abs() < 1e-6);
    let none = sense(
        &Sensor::Walkers {
            range: 1.0,
            half_field: PI / 3.0,
        },
        &env,
    );
    assert_eq!(none.1, f32::INFINITY);
}

/// A random net: sensors, controls each reading a sensor, one walk node reading controls.
fn net_strategy() -> impl Strategy<Value = BehaviourNet> {
    let sensor = prop_oneof![
        (-9.0f32..9.0, -9.0f32..9.0).prop_map(|(x, z)| Sensor::Location(Vec2::new(x, z))),
        (-9.0f32..9.0, -9.0f32..9.0, -9.0f32..9.0, -9.0f32..9.0)
            .prop_map(|(a, b, c, d)| Sensor::Line(Vec2::new(a, b), Vec2::new(c, d))),
        (0.5f32..8.0, 0.2f32..3.0)
            .prop_map(|(range, half_field)| Sensor::Walkers { range, half_field }),
    ];
    (
        prop::collection::vec(sensor, 1..6),
        prop::collection::vec(
            (
                any::<bool>(),
                any::<prop::sample::Index>(),
                0.0f32..1.0,
                0.1f32..3.0,
                0.0f32..3.0,
                0.0f32..3.0,
            ),
            1..8,
        ),
    )
        .prop_map(|(sensors, controls)| {
            let ns = sensors.len();
            let mut nodes: Vec<Node> = sensors.into_iter().map(Node::Sense).collect();
            let mut inputs = Vec::new();
            for (attracts, which, t_theta, t_d, k_theta, k_d) in controls {
                let input = which.index(ns);
                inputs.push(nodes.len());
                nodes.push(if attracts {
                    Node::Attract {
                        input,
                        t_theta,
                        t_d,
                        k_theta,
                        k_d,
                    }
                } else {
                    Node::Avoid {
                        input,
                        t_d,
                        k_theta,
                        k_d,
                    }
                });
            }
            nodes.push(Node::Walk { inputs });
            BehaviourNet::new(nodes).expect("a well-formed net")
        })
}

proptest! {
    #[test]
    fn shuffling_the_evaluation_order_gives_bit_identical_outputs(
        mut net in net_strategy(),
        x in -5.0f32..5.0, z in -5.0f32..5.0, heading in -3.0f32..3.0,
        walkers in prop::collection::vec((-6.0f32..6.0, -6.0f32..6.0), 0..6),
        seed in any::<u64>(),
    ) {
        let walkers: Vec<Vec2> = walkers.into_iter().map(|(a, b)| Vec2::new(a, b)).collect();
        let obstacles = Obstacles::default();
        let env = Surroundings { at: Vec2::new(x, z), heading, obstacles: &obstacles, walkers: &walkers };
        let n = net.nodes().len();
        // every step's outputs, from rest, nodes evaluated in `order`
        let mut run = |order: &[usize]| -> Vec<Vec<[u32; 3]>> {
            net.rest();
            (0..3)
                .map(|_| {
                    net.step(order, &env);
                    (0..n).map(|i| net.output(i).map(f32::to_bits)).collect()
                })
                .collect()
        };
        let forward: Vec<usize> = (0..n).collect();
        let reference = run(&forward);
        // a shuffled order, the reverse order
        let mut order = forward.clone();
        let mut rng = crate::rng::Rng(seed);
        for i in (1..n).rev() {
            order.swap(i, (rng.next_f32() * (i + 1) as f32) as usize % (i + 1));
        }
        let reverse: Vec<usize> = forward.iter().rev().copied().collect();
        for order in [order, reverse] {
            prop_assert_eq!(&run(&order), &reference);
        }
    }
}
