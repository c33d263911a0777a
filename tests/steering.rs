//! The steering laws checked against their definitions (IViHumans platform thesis, steering
//! behaviours): the vehicle's truncations, no vertical force, arrive's linear deceleration and
//! floor speed and its stop, walk-to-velocity's force, stop, follow-points, and the combiners.

use bml_realizer::world::locomotion::steering::{
    ArriveParams, Behaviour, Combine, Context, Part, Rng, Steering, Vehicle, STOP_EPSILON,
};
use glam::Vec3;

fn vehicle() -> Vehicle {
    Vehicle::new(Vec3::ZERO, 2.0, 4.0, 1.5)
}

#[test]
fn the_vehicle_truncates_force_then_speed() {
    let mut v = vehicle();
    // a huge force is cut to max_force: a = 4 / 2 = 2 m/s² for 0.1 s
    v.step(Vec3::new(0.0, 0.0, 1000.0), 0.1);
    assert!((v.velocity.z - 0.2).abs() < 1e-6, "{}", v.velocity);
    assert!((v.position.z - 0.02).abs() < 1e-6);
    // many steps: never faster than max_speed
    for _ in 0..100 {
        v.step(Vec3::new(3.0, 0.0, 3.0), 0.1);
        assert!(v.velocity.length() <= 1.5 + 1e-6);
    }
}

#[test]
fn no_behaviour_pushes_up_or_down_or_changes_vertical_speed() {
    let mut rng = Rng(9);
    let target = Vec3::new(3.0, 5.0, -2.0);
    let params = ArriveParams {
        slow_radius: 2.0,
        stop_radius: 0.05,
        floor_speed: 0.2,
    };
    let all = [
        Behaviour::Seek(target),
        Behaviour::Flee {
            from: target,
            panic: 100.0,
        },
        Behaviour::Arrive { target, params },
        Behaviour::Pursue {
            position: target,
            velocity: Vec3::new(1.0, 1.0, 0.0),
        },
        Behaviour::Evade {
            position: target,
            velocity: Vec3::new(1.0, 1.0, 0.0),
        },
        Behaviour::WalkTo(Vec3::new(1.0, 7.0, 1.0)),
        Behaviour::Stop,
    ];
    for b in all {
        let mut v = vehicle();
        v.velocity = Vec3::new(0.3, 0.7, 0.2); // climbing stairs, say
        let mut b = b;
        let f = b.force(&mut v, Context::default(), &mut rng).unwrap();
        assert_eq!(f.y, 0.0, "{b:?}");
        assert!(f.length() <= v.max_force + 1e-6);
        v.step(f, 0.1);
        assert_eq!(v.velocity.y, 0.7, "{b:?}");
    }
}

#[test]
fn arrive_slows_linearly_not_below_its_floor_and_stops_inside_its_radius() {
    let params = ArriveParams {
        slow_radius: 2.0,
        stop_radius: 0.05,
        floor_speed: 0.2,
    };
    let mut rng = Rng(1);
    let mut desired = |d: f32| {
        // with the vehicle at rest the force is the desired velocity
        let mut v = Vehicle::new(Vec3::ZERO, 1.0, 100.0, 1.5);
        let mut b = Behaviour::Arrive {
            target: Vec3::new(0.0, 0.0, d),
            params,
        };
        b.force(&mut v, Context::default(), &mut rng).map(|f| f.z)
    };
    assert!((desired(5.0).unwrap() - 1.5).abs() < 1e-5);
    assert!((desired(1.0).unwrap() - 0.75).abs() < 1e-5); // half way in: half speed
    assert!((desired(0.5).unwrap() - 0.375).abs() < 1e-5);
    assert!((desired(0.1).unwrap() - 0.2).abs() < 1e-5); // the floor
                                                         // inside the stop radius: stopped at once, and done
    let mut v = Vehicle::new(Vec3::new(0.0, 0.0, 0.97), 1.0, 100.0, 1.5);
    v.velocity = Vec3::new(0.0, 0.0, 0.2);
    let mut b = Behaviour::Arrive {
        target: Vec3::new(0.0, 0.0, 1.0),
        params,
    };
    assert_eq!(b.force(&mut v, Context::default(), &mut rng), None);
    assert_eq!(v.velocity, Vec3::ZERO);
}

#[test]
fn walk_to_is_the_velocity_difference_and_stop_ends_at_rest() {
    let mut rng = Rng(1);
    let mut v = Vehicle::new(Vec3::ZERO, 1.0, 100.0, 5.0);
    v.velocity = Vec3::new(1.0, 0.0, 0.5);
    let mut walk = Behaviour::WalkTo(Vec3::new(0.0, 0.0, 2.0));
    let f = walk.force(&mut v, Context::default(), &mut rng).unwrap();
    assert!((f - Vec3::new(-1.0, 0.0, 1.5)).length() < 1e-6);
    let mut stop = Behaviour::Stop;
    let mut steps = 0;
    while let Some(f) = stop.force(&mut v, Context::default(), &mut rng) {
        v.step(f, 0.1);
        steps += 1;
        assert!(steps < 1000);
    }
    assert!(v.speed() < STOP_EPSILON);
}

#[test]
fn follow_points_seeks_each_then_arrives_at_the_last() {
    let mut rng = Rng(1);
    let pts = vec![
        Vec3::new(0.0, 0.0, 2.0),
        Vec3::new(2.0, 0.0, 2.0),
        Vec3::new(2.0, 0.0, 4.0),
    ];
    let mut b = Behaviour::FollowPoints {
        points: pts.clone(),
        next: 0,
        reach: 0.3,
        params: ArriveParams {
            slow_radius: 1.0,
            stop_radius: 0.05,
            floor_speed: 0.1,
        },
    };
    let mut v = Vehicle::new(Vec3::ZERO, 1.0, 3.0, 1.2);
    let mut nearest = [f32::INFINITY; 3];
    for _ in 0..3000 {
        let Some(f) = b.force(&mut v, Context::default(), &mut rng) else {
            break;
        };
        v.step(f, 0.01);
        for (n, p) in nearest.iter_mut().zip(&pts) {
            *n = n.min(v.position.distance(*p));
        }
    }
    assert!(nearest[0] < 0.35 && nearest[1] < 0.35, "{nearest:?}");
    assert!(v.position.distance(pts[2]) <= 0.05 + 1e-4 && v.speed() == 0.0);
}

#[test]
fn the_combiners_follow_their_definitions() {
    let east = Behaviour::WalkTo(Vec3::new(3.0, 0.0, 0.0));
    let north = Behaviour::WalkTo(Vec3::new(0.0, 0.0, 4.0));
    let ctx = Context::default();
    let at_rest = || Vehicle::new(Vec3::ZERO, 1.0, 4.0, 10.0);
    // weighted sum, truncated: 0.5 × (3, 0) + (0, 4) = (1.5, 4) → length 4
    let mut s = Steering::new(Combine::WeightedSum, 1);
    let mut half = Part::new(east.clone());
    half.weight = 0.5;
    s.add(half);
    s.add(Part::new(north.clone()));
    let f = s.force(&mut at_rest(), ctx);
    assert!((f.length() - 4.0).abs() < 1e-5);
    assert!((f.normalize() - Vec3::new(1.5, 0.0, 4.0).normalize()).length() < 1e-5);
    // prioritised: the higher one (east, 3) first, then what fits of north (1 of 4)
    let mut p = Steering::new(Combine::Prioritised, 1);
    let mut first = Part::new(east.clone());
    first.priority = 2;
    p.add(Part::new(north.clone()));
    p.add(first);
    let f = p.force(&mut at_rest(), ctx);
    assert!((f - Vec3::new(3.0, 0.0, 1.0)).length() < 1e-5, "{f}");
    // dithering: the first evaluated non-zero force wins; probability 0 is never evaluated
    let mut d = Steering::new(Combine::Dithering, 1);
    let mut never = Part::new(east);
    never.priority = 5;
    never.probability = 0.0;
    d.add(never);
    d.add(Part::new(north));
    for _ in 0..20 {
        assert_eq!(d.force(&mut at_rest(), ctx), Vec3::new(0.0, 0.0, 4.0));
    }
}

#[test]
fn pursuit_heads_for_where_the_target_will_be_and_catches_it_sooner_than_seek() {
    // a target crossing at 1 m/s, 5 m ahead; pursuer and seeker at 2 m/s
    let chase = |pursue: bool| {
        let mut rng = Rng(3);
        let mut v = Vehicle::new(Vec3::ZERO, 1.0, 8.0, 2.0);
        let (mut target, vel) = (Vec3::new(-3.0, 0.0, 5.0), Vec3::new(1.0, 0.0, 0.0));
        for step in 0..2000 {
            let mut b = if pursue {
                Behaviour::Pursue {
                    position: target,
                    velocity: vel,
                }
            } else {
                Behaviour::Seek(target)
            };
            let f = b.force(&mut v, Context::default(), &mut rng).unwrap();
            v.step(f, 0.01);
            target += vel * 0.01;
            if v.position.distance(target) < 0.2 {
                return step;
            }
        }
        2000
    };
    let (p, s) = (chase(true), chase(false));
    assert!(p < s, "pursuit {p} steps, seek {s}");
    // and the first force of pursuit points ahead of the target (toward +x of it)
    let mut v = Vehicle::new(Vec3::ZERO, 1.0, 100.0, 2.0);
    let mut b = Behaviour::Pursue {
        position: Vec3::new(0.0, 0.0, 5.0),
        velocity: Vec3::new(1.0, 0.0, 0.0),
    };
    let f = b.force(&mut v, Context::default(), &mut Rng(1)).unwrap();
    assert!(f.x > 0.5, "{f}");
    // evade runs from where the target will be
    let mut e = Behaviour::Evade {
        position: Vec3::new(0.0, 0.0, 5.0),
        velocity: Vec3::new(1.0, 0.0, 0.0),
    };
    let f = e.force(&mut v, Context::default(), &mut Rng(1)).unwrap();
    assert!(f.x < -0.3 && f.z < 0.0, "{f}");
}

#[test]
fn a_follower_pushed_past_a_point_goes_on_rather_than_back() {
    let mut rng = Rng(1);
    let pts: Vec<Vec3> = (1..=3)
        .map(|k| Vec3::new(0.0, 0.0, 2.0 * k as f32))
        .collect();
    let mut b = Behaviour::FollowPoints {
        points: pts,
        next: 1,
        reach: 0.3,
        params: ArriveParams {
            slow_radius: 1.0,
            stop_radius: 0.05,
            floor_speed: 0.1,
        },
    };
    // pushed aside a metre, half a metre beyond the point it sought
    let mut v = Vehicle::new(Vec3::new(1.0, 0.0, 4.5), 1.0, 3.0, 1.2);
    let f = b.force(&mut v, Context::default(), &mut rng).unwrap();
    assert!(f.z > 0.0, "turned back: {f}");
}
