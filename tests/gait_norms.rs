//! The realized gait held against published human norms, as a gait laboratory measures people
//! (`tests/common/gait_lab.rs`: forward kinematics of the frames, the realizer's own foot
//! contacts as the force plate): each measure's mean over the steady cycles within its band
//! (about the published mean ± 2 SD) at STROLL, WALK and RUN. The laboratory's own measures are
//! checked first on poses whose angles are known.

#[path = "common/gait_lab.rs"]
mod gait_lab;

use bml_realizer::character::body::{Pose, Skeleton};
use gait_lab::{bands, cycles, means, record, sample, MEASURES, WALKS};
use glam::Quat;

const FPS: f64 = 120.0;

/// A pose of the adult with the left hip, knee and ankle turned about their x axes (rad).
fn posed(hip: f32, knee: f32, ankle: f32) -> Pose {
    let s = Skeleton::adult();
    let mut pose = Pose::rest(&s);
    for (name, angle) in [("l_hip", hip), ("l_knee", knee), ("l_talocrural", ankle)] {
        pose.rotations[s.joint(name).unwrap()] = Quat::from_rotation_x(angle);
    }
    pose
}

#[test]
fn the_laboratory_measures_known_angles_with_their_signs() {
    let s = Skeleton::adult();
    let rest = sample(&s, &Pose::rest(&s), [true, true]);
    assert!(rest.knee.abs() < 0.5 && rest.hip.abs() < 0.5 && rest.ankle.abs() < 0.5);
    // the skeleton's conventions: the hip flexes about −x, the knee about +x, toes-up is −x
    let m = sample(&s, &posed(-0.5, 0.6, -0.2), [true, false]);
    assert!((m.hip - 28.65).abs() < 0.5, "hip flexion {}", m.hip);
    assert!((m.knee - 34.38).abs() < 0.5, "knee flexion {}", m.knee);
    // dorsiflexion is positive (the old measure had its sign turned: toe-off read as +16°)
    assert!(
        (m.ankle - 11.46).abs() < 0.5,
        "ankle dorsiflexion {}",
        m.ankle
    );
    let toes_down = sample(&s, &posed(0.0, 0.0, 0.3), [true, true]);
    assert!((toes_down.ankle + 17.19).abs() < 0.5, "{}", toes_down.ankle);
}

#[test]
fn the_laboratory_finds_the_realizer_s_stance_and_cadence() {
    let samples = record("WALK", 30.0, 18.0, FPS);
    let cycles = cycles(&samples);
    assert!(cycles.len() >= 8, "{} steady cycles", cycles.len());
    let m = means(&cycles, FPS);
    // stance 60 % of the cycle, two steps at 113 steps/min (the walk ratio at 1.3 m/s)
    assert!((m[16] - 60.0).abs() < 1.5, "stance {}", m[16]);
    assert!((m[17] - 20.0).abs() < 1.5, "double support {}", m[17]);
    assert!((m[18] - 120.0 / 113.0).abs() < 0.03, "cycle {} s", m[18]);
}

#[test]
fn the_gait_is_within_people_s_norms_at_stroll_walk_and_run() {
    let mut out = Vec::new();
    for (manner, distance, seconds) in WALKS {
        let m = means(&cycles(&record(manner, distance, seconds, FPS)), FPS);
        for &(k, lo, hi, source) in bands(manner) {
            if !(lo..=hi).contains(&m[k]) {
                out.push(format!(
                    "{manner} {}: {:.1} outside [{lo}, {hi}] ({source})",
                    MEASURES[k], m[k]
                ));
            }
        }
    }
    assert!(out.is_empty(), "{}", out.join("\n"));
}
