//! A press of whole-body walkers on random trips (the scenes of the `crowd_random` example,
//! smaller): judged from every frame's roots, as a user would see them. Bodies stay people in
//! the press: no two roots within 0.45 m, no root moved faster than 2.5 m/s between frames, the
//! hips never drop 10 cm between frames. (Before bodies slid along whoever they touched and
//! were pressed apart at 1 m/s at most, and before groups that walk off held no space, this
//! scene at 10 fps brought roots within 0.40 m and dropped the hips 6.9 cm in a frame; at
//! 30 fps roots came within 0.36 m and were shoved at 6.4 m/s.) Who did not arrive within
//! 0.3 m in 40 s is printed, not yet asserted: in a press this dense (100 in 14 × 14 m) all
//! 100 arrive at 10 and at 30 fps now (14 did not before). Smaller random scenes are held to everyone
//! arriving too (the proptest below).

use bml_realizer::language::feedback::Feedback;
use glam::{Vec2, Vec3};

#[path = "../examples/common/lcg.rs"]
mod lcg;
#[path = "../examples/common/trips.rs"]
mod trips;
use trips::{id, trips, SETTLE};

/// What the frames of one scene showed.
struct Seen {
    closest: f32,
    fastest: f32,
    drop: f32,
    stranded: Vec<String>,
}

/// `n` walkers in a `side` m square, ticked at `fps` for at most `until` s.
fn press(n: usize, side: f32, fps: f64, seed: u64, until: f64) -> Seen {
    let (mut r, goals) = trips(n, side, seed);
    let ground = |p: Vec3| Vec2::new(p.x, p.z);
    let mut seen = Seen {
        closest: f32::MAX,
        fastest: 0.0,
        drop: 0.0,
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
    for k in 0..n {
        let off = last[k].map_or(f32::MAX, |p| ground(p).distance(goals[k]));
        if off > 0.3 || !ended[k] {
            seen.stranded.push(format!("{} {off:.2} m off", id(k)));
        }
    }
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
