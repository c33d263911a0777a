//! Walkers whose profile says `onlySeen` avoid only those they have seen or remember: at a
//! junction hidden by a wall, `a` walks exactly as if `b` were not there until it sees `b`;
//! with the default profile it already makes way for `b`, whom it could not see.

use bml_realizer::language::feedback::{Feedback, WorldFeedback};
use bml_realizer::realizer::Realizer;
use bml_realizer::world::World;
use glam::Vec2;

const NS: &str = r#"xmlns="http://www.bml-initiative.org/bml/bml-1.0""#;

/// A frame: its time, where `a` is, where `b` is.
type Sample = (f64, Vec2, Option<Vec2>);

/// `a` walks north along x = 0, `b` (when there) west along z = 0.5, a wall along x = 1 from
/// z = −5 to 0 between them until they meet.
fn run(only_seen: bool, with_b: bool) -> (Vec<Sample>, Option<f64>) {
    let profile = if only_seen {
        r#", "profile": "looking""#
    } else {
        ""
    };
    let b = if with_b {
        format!(r#", "b": {{"position": [6, 0, 0.5], "facing": -90{profile}}}"#)
    } else {
        String::new()
    };
    let world = format!(
        r#"{{"characters": {{"a": {{"position": [0, 0, -6], "facing": 0{profile}}}{b}}},
            "profiles": {{"looking": {{"onlySeen": true}}}},
            "obstacles": [{{"segment": [1, -5, 1, 0], "height": 2.2}}]}}"#
    );
    let mut r = Realizer::new().with_idle(false);
    *r.world_mut() = World::from_json(&world).unwrap().0;
    r.perform_bml(&format!(
        r#"<bml {NS} id="wa" characterId="a"><locomotion id="l" target="0,6"/></bml>"#
    ))
    .unwrap();
    if with_b {
        r.perform_bml(&format!(
            r#"<bml {NS} id="wb" characterId="b"><locomotion id="l" target="-6,0.5"/></bml>"#
        ))
        .unwrap();
    }
    if only_seen {
        r.set_perception(Some(r.world().vision()), true).unwrap();
    }
    let mut path = Vec::new();
    let mut saw = None;
    for k in 1..=(12 * 60) {
        let t = f64::from(k) / 60.0;
        let frame = r.tick(t);
        for f in &frame.feedback {
            if let Feedback::World(WorldFeedback::Perception(p)) = f {
                if p.character_id == "a" && p.appeared.iter().any(|s| s == "b") {
                    saw.get_or_insert(t);
                }
            }
        }
        let at = |id: &str| {
            frame
                .character(id)
                .map(|p| Vec2::new(p.pose.root.x, p.pose.root.z))
        };
        if let Some(pa) = at("a") {
            path.push((t, pa, at("b")));
        }
    }
    (path, saw)
}

#[test]
fn a_walker_that_avoids_only_what_it_has_seen_ignores_the_unseen_until_it_appears() {
    let (alone, _) = run(true, false);
    let (seeing, saw) = run(true, true);
    let saw = saw.expect("a sees b");
    // until a sees b (and the next decision), a walks as if alone
    let diverged = (alone.iter().zip(&seeing))
        .find(|(x, y)| x.1.distance(y.1) > 1e-4)
        .map(|(x, _)| x.0);
    eprintln!("a saw b at {saw:.3} s; its walk left the lone walk at {diverged:?}");
    assert!(
        diverged.is_none_or(|t| t >= saw),
        "{diverged:?} before {saw}"
    );
    // the default: a makes way earlier, for someone behind the wall
    let (knowing, _) = run(false, true);
    let (plain, _) = run(false, false);
    let early = (plain.iter().zip(&knowing))
        .find(|(x, y)| x.1.distance(y.1) > 1e-4)
        .map(|(x, _)| x.0);
    eprintln!("knowing everyone, its walk left the lone walk at {early:?}");
    assert!(early.is_some_and(|t| t < saw), "{early:?}");
    // and nobody walks through anybody
    let closest = (seeing.iter())
        .filter_map(|(_, a, b)| b.map(|b| a.distance(b)))
        .fold(f32::INFINITY, f32::min);
    assert!(closest >= 0.48, "closest {closest}");
}
