//! The unit tests of `physical`.

use super::*;
use glam::Vec3;

/// Handed back 0.8 m below the kinematic pose while falling at 3 m/s: the way back keeps
/// part of the speed and carries the body on at most 15 % (0.12 m; measured 0.04 m)
/// further; uncapped, it went on another 0.38 m (through the floor for a pelvis less than
/// that above it).
#[test]
fn the_way_back_carries_a_falling_body_on_only_a_little() {
    let offset = |time: f64, y: f32| Offset {
        time,
        root: Vec3::new(0.0, y, 0.0),
        turns: vec![Vec3::ZERO; 3],
    };
    let release = Release::new(&offset(1.0, -0.8), Some(&offset(1.0 - 0.01, -0.77)));
    assert!(
        (release.duration - 1.2).abs() < 1e-6,
        "{}",
        release.duration
    );
    let rest = Pose::rest(&Skeleton::adult());
    let mut lowest: f32 = 0.0;
    for k in 0..=120 {
        let mut pose = rest.clone();
        release.apply(1.0 + k as f64 * 0.01, &mut pose);
        lowest = lowest.min(pose.root.y - rest.root.y);
    }
    assert!(lowest >= -0.8 * 1.15 - 1e-4, "it went down to {lowest} m");
    assert!(lowest < -0.82, "it stopped at once: {lowest} m");
    // the speed at the hand-over is kept, within the cap
    assert!(release.rate.root.y < -0.5, "{}", release.rate.root);
}
