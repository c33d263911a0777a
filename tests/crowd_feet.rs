//! Feet in a crowd: in the plaza example (forty walkers crossing round a fountain, benches, a
//! conversing group and each other, some in tight curves), no planted foot slides
//! (`common/feet.rs` says how that is measured).

#[path = "common/feet.rs"]
mod feet;
#[path = "../examples/common/lcg.rs"]
#[allow(dead_code)]
mod lcg;
#[path = "../examples/common/trips.rs"]
#[allow(dead_code)]
mod trips;

use bml_realizer::realizer::Realizer;
use bml_realizer::world::World;
use feet::Slides;

const PLAZA: &str = "fixtures/examples/plaza";

/// The plaza's realizer with every walker's block sent.
fn plaza() -> Realizer {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(PLAZA);
    let text = std::fs::read_to_string(root.join("world.json")).unwrap();
    let mut r = Realizer::new();
    *r.world_mut() = World::from_json(&text).expect("the plaza's world").0;
    let mut files: Vec<_> = (std::fs::read_dir(&root).unwrap())
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "xml"))
        .collect();
    files.sort();
    for f in files {
        r.perform_bml(&std::fs::read_to_string(f).unwrap()).unwrap();
    }
    r
}

#[test]
fn planted_feet_do_not_slide_in_the_plaza() {
    let mut r = plaza();
    let mut slides = Slides::new();
    for i in 0..=(14.0 * 60.0) as u32 {
        let t = f64::from(i) / 60.0;
        slides.frame(t, &r.tick(t).poses);
    }
    let (worst, planted) = (slides.worst, slides.planted);
    eprintln!(
        "{planted} planted stretches; the worst slid {:.1} mm ({} at {:.2} s)",
        worst.0 * 1e3,
        worst.1,
        worst.2
    );
    assert!(planted > 1000, "{planted}");
    assert!(
        worst.0 < 0.01,
        "{} slid {:.1} cm at {:.2} s",
        worst.1,
        worst.0 * 100.0,
        worst.2
    );
}

/// Ten walkers a side taking turns at a 0.9 m door (`crowd_random door10`), at 30 fps: the
/// press at the door's mouth moves bodies, but a planted foot should stay where it was put
/// down. Not yet: a body pressed apart (at up to 1 m/s) drags its planted foot, w0004's ball
/// 2.9 cm at 7.7 s in the first press at the door (11.4 cm when the wall's push comes before
/// the bodies'). Run with `--ignored` to see it.
#[test]
#[ignore = "a body pressed apart at the door's mouth drags its planted foot 2.9 cm (bound 2 cm)"]
fn planted_feet_do_not_slide_at_a_narrow_door() {
    let scene = trips::passage("door10").expect("the scene");
    let mut r = trips::walking(&scene.starts, &scene.goals, &scene.walls);
    let mut slides = Slides::new();
    for i in 0..=(45.0 * 30.0) as u32 {
        let t = f64::from(i) / 30.0;
        slides.frame(t, &r.tick(t).poses);
    }
    let (worst, planted) = (slides.worst, slides.planted);
    eprintln!(
        "door: {planted} planted stretches; the worst slid {:.1} mm ({} at {:.2} s)",
        worst.0 * 1e3,
        worst.1,
        worst.2
    );
    assert!(planted > 500, "{planted}");
    assert!(
        worst.0 < 0.02,
        "{} slid {:.1} cm at {:.2} s",
        worst.1,
        worst.0 * 100.0,
        worst.2
    );
}
