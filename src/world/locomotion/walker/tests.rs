//! The walker's tests: a walk reaches its goal, its moments in order, and its rehearsal
//! agrees with the walk.

use super::*;

#[test]
fn a_walk_reaches_its_goal_and_reports_its_moments_in_order() {
    let mut w = Walker::new(Vec2::ZERO, 0.0, 0.25, 0.0);
    let walk = Walk {
        goal: Vec2::new(0.0, 5.0),
        speed: 1.3,
        running: false,
        face: None,
        stepping: false,
        footsteps: false,
    };
    let o = Obstacles::default();
    w.start(walk.clone(), &o).unwrap();
    let mut ended = None;
    for k in 1..2000 {
        if let Some(m) = w.advance(k as f64 / 60.0, &o) {
            ended = Some(m);
            break;
        }
    }
    let m = ended.expect("the walk ends");
    let (s, r, x, e) = (
        m.start.unwrap(),
        m.ready.unwrap(),
        m.relax.unwrap(),
        m.end.unwrap(),
    );
    assert!(s <= r && r < x && x < e, "{m:?}");
    assert!(
        w.body().at.distance(Vec2::new(0.0, 5.0)) < 0.1,
        "{:?}",
        w.body()
    );
    // about 5 m at 1.3 m/s plus speeding up and slowing down
    assert!(e > 4.0 && e < 7.5, "{e}");
    // the rehearsal from the start predicts the same moments
    let fresh = Walker::new(Vec2::ZERO, 0.0, 0.25, 0.0);
    let p = fresh.rehearse(walk.clone(), &o, 60.0).unwrap();
    assert_eq!(p.end, m.end);
    // a walk longer than the rehearsal: it stops at the limit, with no end
    let far = Walk {
        goal: Vec2::new(0.0, 1e4),
        ..walk
    };
    let p = fresh.rehearse(far, &o, 10.0).unwrap();
    assert_eq!((p.ready.is_some(), p.end), (true, None));
    let relax = p.relax.unwrap();
    assert!((relax - 1e4 / 1.3).abs() < 5.0, "{relax}");
}
