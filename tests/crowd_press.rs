//! A press of whole-body walkers on random trips (the scenes of the `crowd_random` example,
//! smaller): judged from every frame's roots, as a user would see them. Bodies stay people in
//! the press: no two roots within 0.45 m, no root moved faster than 2.5 m/s between frames, the
//! hips never drop 10 cm between frames. (Before bodies slid along whoever they touched and
//! were pressed apart at 1 m/s at most, and before groups that walk off held no space, this
//! scene at 10 fps brought roots within 0.40 m and dropped the hips 6.9 cm in a frame; at
//! 30 fps roots came within 0.36 m and were shoved at 6.4 m/s.) Who did not arrive within
//! 0.3 m in 40 s is printed, not yet asserted: in a press this dense (100 in 14 × 14 m) all
//! 100 arrive at 10 and at 30 fps now (14 did not before). Smaller random scenes are held to everyone
//! arriving too (the proptest below), and so are ten walkers a side crossing through a narrow
//! door, who take turns there.

use bml_realizer::language::feedback::Feedback;
use bml_realizer::realizer::Realizer;
use bml_realizer::world::space::distance::point_segment;
use glam::{Vec2, Vec3};

#[path = "../examples/common/lcg.rs"]
mod lcg;
#[path = "../examples/common/trips.rs"]
mod trips;
use trips::{id, trips, walking, SETTLE};

/// What the frames of one scene showed.
#[derive(Debug)]
struct Seen {
    closest: f32,
    fastest: f32,
    drop: f32,
    /// The nearest a root came to a wall (m).
    nearest_wall: f32,
    stranded: Vec<String>,
}

/// `n` walkers in a `side` m square, ticked at `fps` for at most `until` s.
fn press(n: usize, side: f32, fps: f64, seed: u64, until: f64) -> Seen {
    let (r, goals) = trips(n, side, seed);
    judge(r, &goals, &[], fps, until)
}

/// The walkers `w0000`… of `r` bound for `goals` among `walls` (segments [x1, z1, x2, z2]),
/// ticked at `fps` until every walk has ended (and [`SETTLE`] more) or for at most `until` s.
fn judge(mut r: Realizer, goals: &[Vec2], walls: &[[f32; 4]], fps: f64, until: f64) -> Seen {
    let n = goals.len();
    let ground = |p: Vec3| Vec2::new(p.x, p.z);
    let mut seen = Seen {
        closest: f32::MAX,
        fastest: 0.0,
        drop: 0.0,
        nearest_wall: f32::MAX,
        stranded: Vec::new(),
    };
    let mut ended = vec![false; n];
    let mut all_ended = None;
    let mut last: Vec<Option<Vec3>> = vec![None; n];
    for frame in 0..=(until * fps) as u32 {
        let f = r.tick(f64::from(frame) / fps);
        for fb in &f.feedback {
            if let Feedback::BlockProgress(p) = fb {
                if p.sync == "end" {
                    let k: usize = p.block.trim_start_matches('b').parse().expect("bN");
                    ended[k] = true;
                }
            }
        }
        let roots: Vec<Vec3> = (0..n)
            .map(|k| f.character(&id(k)).expect("a pose").pose.root)
            .collect();
        for (k, p) in roots.iter().enumerate() {
            for q in &roots[k + 1..] {
                seen.closest = seen.closest.min(ground(*p).distance(ground(*q)));
            }
            for [a, b, c, d] in walls {
                let (d, _) = point_segment(ground(*p), Vec2::new(*a, *b), Vec2::new(*c, *d));
                seen.nearest_wall = seen.nearest_wall.min(d);
            }
            if let Some(q) = last[k] {
                let v = ground(*p).distance(ground(q)) * fps as f32;
                seen.fastest = seen.fastest.max(v);
                seen.drop = seen.drop.max(q.y - p.y);
            }
            last[k] = Some(*p);
        }
        // (once every walk has ended, those who stepped aside for a late one go back)
        let t = f64::from(frame) / fps;
        if ended.iter().all(|&e| e) && *all_ended.get_or_insert(t) + SETTLE <= t {
            break;
        }
    }
    seen.stranded = trips::stranded(&last, goals, &ended);
    seen
}

#[test]
fn bodies_in_a_press_stay_people() {
    for fps in [10.0, 30.0] {
        let seen = press(100, 14.0, fps, 1, 40.0);
        let what = format!(
            "at {fps} fps: closest {:.3} m, fastest {:.2} m/s, hip drop {:.1} cm, stranded {:?}",
            seen.closest,
            seen.fastest,
            seen.drop * 100.0,
            seen.stranded
        );
        eprintln!("{what}");
        assert!(seen.closest >= 0.45, "{what}");
        assert!(seen.fastest <= 2.5, "{what}");
        assert!(seen.drop <= 0.1, "{what}");
    }
}

#[test]
fn one_near_its_goal_with_someone_standing_beyond_it_walks_on() {
    // found by the proptest below: w0000, 0.35 m from its goal, foresaw running into w0002
    // standing 1.3 m beyond it, and stood still until its walk gave up (its contacts now end
    // where it stops)
    let seen = press(10, 6.497674, 10.0, 13523512388356260687, 40.0);
    assert!(seen.stranded.is_empty(), "stranded {:?}", seen.stranded);
    assert!(seen.closest >= 0.45, "closest {}", seen.closest);
}

/// Ten walkers a side cross through a door too narrow for two to pass each other in (0.9 m,
/// in a wall along x = 0): they take turns, and everyone gets through, no root nearer a wall
/// than 0.23 m (a body against the wall, its pelvis swaying). Without the turns nobody got
/// through: those nearer the door crowded its mouth on both sides, each side waiting for the
/// other, until the walks gave up (14 of 20 stood 7 to 9 m off their goals).
#[test]
fn ten_a_side_take_turns_at_a_narrow_door_and_all_get_through() {
    let scene = trips::passage("door10").expect("the scene");
    for fps in [10.0, 30.0] {
        let r = walking(&scene.starts, &scene.goals, &scene.walls);
        let seen = judge(r, &scene.goals, &scene.walls, fps, 120.0);
        let what = format!("{fps} fps: {seen:?}");
        eprintln!("{what}");
        assert!(seen.stranded.is_empty(), "{what}");
        assert!(seen.closest >= 0.45, "{what}");
        assert!(seen.nearest_wall >= 0.23, "{what}");
        assert!(seen.fastest <= 2.5, "{what}");
        assert!(seen.drop <= 0.1, "{what}");
    }
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig { cases: 16, ..Default::default() })]

    /// Small random scenes, any frame rate: everyone arrives within 0.3 m, and bodies stay
    /// people on the way. Its first runs found (the cases kept in
    /// `crowd_press.proptest-regressions`): a walker creeping round one standing on its line
    /// at 5 cm/s until its walk gave up (it turned on the spot toward its goal, then steered
    /// round again, and swung between the two); one who had stepped aside kept from going
    /// back by the space of a group found at the start among people long gone; and one pressed
    /// on while its feet closed, going back only to where the press had left it, 0.54 m off.
    #[test]
    fn everyone_arrives_in_small_random_scenes(
        n in 2usize..=10,
        side in 4.0f32..10.0,
        fps in proptest::sample::select(vec![10.0, 30.0, 60.0, 120.0]),
        seed in proptest::prelude::any::<u64>(),
    ) {
        let seen = press(n, side, fps, seed, 40.0);
        let what = format!(
            "{n} in {side} m at {fps} fps: closest {:.3} m, fastest {:.2} m/s, hip drop {:.1} cm, stranded {:?}",
            seen.closest,
            seen.fastest,
            seen.drop * 100.0,
            seen.stranded
        );
        proptest::prop_assert!(seen.stranded.is_empty(), "{}", what);
        proptest::prop_assert!(seen.closest >= 0.45, "{}", what);
        proptest::prop_assert!(seen.fastest <= 2.5, "{}", what);
        proptest::prop_assert!(seen.drop <= 0.1, "{}", what);
    }
}
