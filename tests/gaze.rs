//! Gaze judged through the frames: a gaze that takes over from another turns the head on from
//! where it is (no jump back to rest), and a whole-body gaze at a target straight behind ends with
//! the eyes on it.

use bml_realizer::character::body::{Pose, Skeleton};
use bml_realizer::realizer::Realizer;
use glam::Vec3;

const NS: &str = r#"xmlns="http://www.bml-initiative.org/bml/bml-1.0""#;

fn frames(r: &mut Realizer, from: f64, to: f64, out: &mut Vec<(f64, Pose)>) {
    let mut k = (from * 60.0).round() as u32;
    while f64::from(k) / 60.0 <= to + 1e-9 {
        let t = f64::from(k) / 60.0;
        out.push((t, r.tick(t).poses[0].pose.clone()));
        k += 1;
    }
}

/// Where the head faces (the skull's +z in the world).
fn head(s: &Skeleton, p: &Pose) -> Vec3 {
    p.world(s).orientations[s.joint("skullbase").unwrap()] * Vec3::Z
}

#[test]
fn a_gaze_that_takes_over_mid_turn_turns_the_head_on_from_where_it_is() {
    let mut r = Realizer::new();
    r.world_mut().set("left", Vec3::new(2.0, 1.6, 1.0));
    r.world_mut().set("right", Vec3::new(-2.0, 1.6, 1.0));
    r.perform_bml(&format!(
        r#"<bml {NS} id="b1"><gaze id="g" target="left" influence="HEAD" start="0" ready="1" end="6"/></bml>"#
    ))
    .unwrap();
    let mut out = Vec::new();
    frames(&mut r, 0.0, 0.6, &mut out);
    // half way through the first turn, another gaze takes over
    r.perform_bml(&format!(
        r#"<bml {NS} id="b2" composition="REPLACE"><gaze id="g" target="right" influence="HEAD" start="0" ready="1" end="4"/></bml>"#
    ))
    .unwrap();
    frames(&mut r, 0.6 + 1.0 / 60.0, 3.0, &mut out);
    let s = Skeleton::adult();
    let worst = out
        .windows(2)
        .map(|w| {
            (
                head(&s, &w[0].1)
                    .angle_between(head(&s, &w[1].1))
                    .to_degrees(),
                w[1].0,
            )
        })
        .fold((0.0f32, 0.0), |a, b| if b.0 > a.0 { b } else { a });
    assert!(
        worst.0 < 4.0,
        "the head turned {}° in one frame at {}",
        worst.0,
        worst.1
    );
    // and it ends on the new target
    let last = &out.last().unwrap().1;
    assert!(head(&s, last).x < -0.3, "{}", head(&s, last));
}

#[test]
fn a_whole_body_gaze_straight_behind_ends_with_the_eyes_on_the_target() {
    // just left, exactly behind and just right of the eyes' line
    for x in [0.02, 0.0, -0.02] {
        whole_body_gaze_behind(x);
    }
}

fn whole_body_gaze_behind(x: f32) {
    let mut r = Realizer::new();
    r.world_mut().set("behind", Vec3::new(x, 1.6, -3.0));
    r.perform_bml(&format!(
        r#"<bml {NS} id="b1"><gaze id="g" target="behind" influence="WHOLE" start="0" ready="1" end="4"/></bml>"#
    ))
    .unwrap();
    let mut out = Vec::new();
    frames(&mut r, 0.0, 3.0, &mut out);
    let s = Skeleton::adult();
    let p = &out.iter().find(|f| f.0 >= 2.5).unwrap().1;
    let w = p.world(&s);
    for eye in ["l_eyeball_joint", "r_eyeball_joint"] {
        let e = s.joint(eye).unwrap();
        let looks = w.orientations[e] * Vec3::Z;
        let to = Vec3::new(x, 1.6, -3.0) - w.positions[e];
        let off = looks.angle_between(to).to_degrees();
        assert!(
            off < 6.0,
            "x = {x}: {eye} looks {off}° away from the target"
        );
    }
}
