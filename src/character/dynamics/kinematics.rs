//! A joint's angular velocity and acceleration from its rotations sampled every `h` seconds:
//! the samples are first put on one hemisphere (q and −q are one rotation; each sample is turned
//! to the sign closer to its neighbour, so differences stay small), then the central differences
//! ṗ ≈ (p(t+h) − p(t−h)) / 2h and p̈ ≈ (p(t+h) − 2p(t) + p(t−h)) / h² give ω = 2 p⁻¹ṗ and
//! ω̇ = 2 vec(p⁻¹p̈), both in the joint's own (child) frame — the frame the inverse dynamics
//! takes. The scalar part of 2 p⁻¹p̈ is −|ω|²/2, a check on the step.

use glam::{DQuat, DVec3};

/// `samples` with every one on the hemisphere of the one before (non-negative dot products).
pub fn same_hemisphere(samples: &[DQuat]) -> Vec<DQuat> {
    let mut out: Vec<DQuat> = Vec::with_capacity(samples.len());
    for &q in samples {
        let q = match out.last() {
            Some(prev) if prev.dot(q) < 0.0 => -q,
            _ => q,
        };
        out.push(q);
    }
    out
}

/// The angular velocity and acceleration (child frame) at the middle of three samples `h`
/// seconds apart, and the scalar part of 2 p⁻¹p̈ (which should be −|ω|²/2).
pub fn derivatives(before: DQuat, now: DQuat, after: DQuat, h: f64) -> (DVec3, DVec3, f64) {
    let fixed = same_hemisphere(&[now, before, after]);
    let (p, a, b) = (fixed[0], fixed[1], fixed[2]);
    let dp = (b - a) * (0.5 / h);
    let ddp = (b - p * 2.0 + a) * (1.0 / (h * h));
    let inv = p.inverse();
    let w = (inv * dp) * 2.0;
    let dw = (inv * ddp) * 2.0;
    (
        DVec3::new(w.x, w.y, w.z),
        DVec3::new(dw.x, dw.y, dw.z),
        dw.w,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn about_a_fixed_axis_the_rates_match_the_analytic_ones() {
        let axis = DVec3::new(1.0, 2.0, -0.5).normalize();
        let h = 0.003;
        let th = |t: f64| (2.0 * std::f64::consts::PI * t).sin();
        let q = |t: f64| DQuat::from_axis_angle(axis, th(t));
        let two_pi = 2.0 * std::f64::consts::PI;
        let (peak_w, peak_dw) = (two_pi, two_pi * two_pi);
        for k in 1..300 {
            let t = k as f64 * h;
            let (w, dw, s) = derivatives(q(t - h), q(t), q(t + h), h);
            let want_w = axis * two_pi * (two_pi * t).cos();
            let want_dw = axis * -two_pi * two_pi * (two_pi * t).sin();
            assert!(
                (w - want_w).length() < 1e-3 * peak_w,
                "{t}: {w} vs {want_w}"
            );
            assert!((dw - want_dw).length() < 1e-3 * peak_dw);
            assert!((s + want_w.length_squared() / 2.0).abs() < 1e-3 * peak_w * peak_w / 2.0);
        }
    }

    #[test]
    fn sign_flips_do_not_change_the_rates() {
        let q = |t: f64| DQuat::from_axis_angle(DVec3::Y, 0.4 * t);
        let h = 0.01;
        let flipped = same_hemisphere(&[q(0.0), -q(h), q(2.0 * h), -q(3.0 * h)]);
        assert!(flipped.windows(2).all(|w| w[0].dot(w[1]) >= 0.0));
        let (w1, _, _) = derivatives(q(0.0), q(h), q(2.0 * h), h);
        let (w2, _, _) = derivatives(-q(0.0), q(h), -q(2.0 * h), h);
        assert!((w1 - w2).length() < 1e-12 && (w1 - DVec3::Y * 0.4).length() < 1e-6);
    }

    #[test]
    fn a_coning_motion_gives_the_body_frame_angular_velocity() {
        // q(t) = Rz(ct) · Rx(β): a body tilted by β spinning about the parent's z. Its angular
        // velocity is c about world z, which in the body frame is Rx(β)⁻¹ · (0, 0, c).
        let (c, beta, h) = (1.7, 0.6, 0.002);
        let q = |t: f64| DQuat::from_rotation_z(c * t) * DQuat::from_rotation_x(beta);
        for k in 1..100 {
            let t = k as f64 * 0.013;
            let (w, dw, _) = derivatives(q(t - h), q(t), q(t + h), h);
            let want = DQuat::from_rotation_x(beta).inverse() * DVec3::new(0.0, 0.0, c);
            assert!((w - want).length() < 1e-5, "{w} vs {want}");
            assert!(dw.length() < 1e-4, "constant in the body frame: {dw}");
        }
    }
}
