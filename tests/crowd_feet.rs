//! Feet in a crowd: in the plaza example (forty walkers crossing round a fountain, benches, a
//! conversing group and each other, some in tight curves), no planted foot slides. Each foot's
//! ankle and ball are placed by forward kinematics over the frames' poses; while the gait says
//! the foot is down and a point is on the ground (within 5 mm of its height standing), that
//! point must stay where it was put down.

use std::collections::HashMap;

use bml_realizer::body::Skeleton;
use bml_realizer::realizer::Realizer;
use bml_realizer::world::World;
use glam::Vec2;

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
    let s = Skeleton::adult();
    let points: Vec<(usize, usize)> = [
        "l_talocrural",
        "r_talocrural",
        "l_metatarsal",
        "r_metatarsal",
    ]
    .iter()
    .enumerate()
    .map(|(k, n)| (k % 2, s.joint(n).unwrap()))
    .collect();
    let mut r = plaza();
    // per (character, point): its height standing, and where it was put down
    let mut rest: HashMap<(String, usize), f32> = HashMap::new();
    let mut down: HashMap<(String, usize), Vec2> = HashMap::new();
    let (mut worst, mut planted) = ((0f32, String::new(), 0.0), 0);
    for i in 0..=(14.0 * 60.0) as u32 {
        let t = f64::from(i) / 60.0;
        let frame = r.tick(t);
        for p in &frame.poses {
            let Some(contacts) = p.contacts else { continue };
            let id = p.character.clone().unwrap_or_default();
            let world = p.pose.world(&s);
            for &(side, joint) in &points {
                let at = world.positions[joint];
                let key = (id.clone(), joint);
                let ground = *rest.entry(key.clone()).or_insert(at.y);
                if contacts[side] && at.y - ground < 0.005 {
                    let from = *down.entry(key).or_insert_with(|| {
                        planted += 1;
                        Vec2::new(at.x, at.z)
                    });
                    let slide = from.distance(Vec2::new(at.x, at.z));
                    if slide > worst.0 {
                        worst = (slide, format!("{id} {}", s.joints()[joint].name), t);
                    }
                } else {
                    down.remove(&key);
                }
            }
        }
    }
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
