//! `<locomotion bmlt:planner="footsteps">`: the seed's wall-and-goal scene walked by footsteps
//! chosen one at a time, through the realizer: round the wall's end without zig-zag, arriving
//! within 0.3 m, with the gait's planted feet staying where they were put down.

#[path = "common/feet.rs"]
mod feet;

use bml_realizer::language::feedback::Feedback;
use bml_realizer::realizer::Realizer;
use bml_realizer::world::crowd::quality::sideways_reversals;
use bml_realizer::world::World;
use feet::Slides;
use glam::Vec2;

const WORLD: &str = r#"{"characters": {"w": {"position": [0, 0, 0], "facing": 0}},
                       "obstacles": [{"segment": [-4, 5, 3, 5], "height": 2.0}]}"#;

fn block(planner: &str) -> String {
    format!(
        r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" xmlns:bmlt="http://hmi.ewi.utwente.nl/bmlt" id="fw" characterId="w"><locomotion id="l" target="4,10" bmlt:planner="{planner}"/></bml>"#
    )
}

/// The walk at 60 fps: the root's ground positions, the worst slide of a planted foot point
/// (m), and the feedback.
fn walk(planner: &str) -> (Vec<Vec2>, f32, Vec<Feedback>) {
    let mut r = Realizer::new().with_idle(false);
    *r.world_mut() = World::from_json(WORLD).unwrap().0;
    r.perform_bml(&block(planner)).unwrap();
    let mut slides = Slides::new();
    let (mut roots, mut feedback) = (Vec::new(), Vec::new());
    for i in 1..=(20 * 60) {
        let t = f64::from(i) / 60.0;
        let frame = r.tick(t);
        feedback.extend(frame.feedback.iter().cloned());
        if let Some(p) = frame.character("w") {
            roots.push(Vec2::new(p.pose.root.x, p.pose.root.z));
        }
        slides.frame(t, &frame.poses);
        if r.next_event().is_none() {
            break;
        }
    }
    (roots, slides.worst.0, feedback)
}

/// Changes of direction of the root's sideways motion (across the straight line to the goal),
/// over the path averaged across a gait cycle (the pelvis sways with every step), ignoring
/// sideways speeds under 5 cm/s.
fn reversals(roots: &[Vec2]) -> usize {
    let across = Vec2::new(10.0, -4.0).normalize();
    let w = 32;
    let smooth: Vec<Vec2> = (w..roots.len().saturating_sub(w))
        .map(|k| roots[k - w..k + w].iter().copied().sum::<Vec2>() / (2 * w) as f32)
        .collect();
    sideways_reversals(&smooth, across, 0.05 / 60.0)
}

#[test]
fn the_wall_and_goal_scene_is_walked_by_footsteps_without_zig_zag_or_sliding() {
    let (_, steered, _) = walk("steering");
    eprintln!("steering: worst slide {:.1} mm", steered * 1e3);
    let (roots, slide, feedback) = walk("footsteps");
    let end = *roots.last().unwrap();
    let goal = Vec2::new(4.0, 10.0);
    eprintln!(
        "footsteps: ended {:.3} m from the goal, {} reversals, worst slide {:.1} mm",
        end.distance(goal),
        reversals(&roots),
        slide * 1e3
    );
    assert!(end.distance(goal) <= 0.3, "ended at {end}");
    assert!(reversals(&roots) <= 2, "{} reversals", reversals(&roots));
    assert!(slide < 0.01, "a planted foot slid {:.1} mm", slide * 1e3);
    // never through the wall
    assert!(
        roots.iter().all(|p| p.y < 4.75 || p.x > 3.0),
        "through the wall"
    );
    assert!(
        feedback
            .iter()
            .any(|f| matches!(f, Feedback::BlockProgress(b) if b.sync.as_str() == "end")),
        "the block ends"
    );
    assert!(
        !feedback.iter().any(|f| matches!(f, Feedback::Warning(_))),
        "{feedback:?}"
    );
    // its sync points in order, the final deceleration before the end (found when the way to
    // the goal, not a route, is short: it was at the end before)
    let at = |sync: &str| {
        (feedback.iter())
            .find_map(|f| match f {
                Feedback::SyncPointProgress(p) if p.sync.as_str() == sync => Some(p.global_time),
                _ => None,
            })
            .unwrap_or_else(|| panic!("no {sync}"))
    };
    let (start, ready, relax, end) = (at("start"), at("ready"), at("relax"), at("end"));
    eprintln!("start {start:.3} ready {ready:.3} relax {relax:.3} end {end:.3}");
    assert!(
        start < ready && ready < relax && relax + 0.5 < end,
        "{start} {ready} {relax} {end}"
    );
}

#[test]
fn an_unknown_planner_is_named_and_the_walk_steers() {
    let (roots, _, feedback) = walk("teleport");
    let warned = feedback
        .iter()
        .any(|f| matches!(f, Feedback::Warning(w) if w.text.contains("bmlt:planner 'teleport'")));
    assert!(warned, "{feedback:?}");
    assert!(roots.last().unwrap().distance(Vec2::new(4.0, 10.0)) <= 0.3);
}
