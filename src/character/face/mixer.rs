//! Mixing face expressions, after the expression mixer of the IViHumans platform: each expression
//! is *activating* (start → attackPeak, its weight easing from 0 to its amount), *holding*
//! (attackPeak → relax) or *deactivating* (relax → end, easing back to 0), and the face is the
//! mix of all of them over the rest expression (the latest faceShift).
//!
//! Overlapping expressions combine per action unit by **maximum**: an AU intensity measures how
//! far one muscle contracts, and two expressions that ask the same muscle do not contract it
//! twice. A sum would overdrive (two 0.7 smiles saturate at 1), and a mean would let a neutral
//! expression halve a running one; the maximum keeps each expression's intended intensity, and
//! being the maximum of continuous envelopes it is continuous too.
//!
//! When the mix itself jumps — an expression interrupted halfway through its attack (it goes
//! to its release at once), an `amount` changed while it runs, a unit removed — the face shown
//! goes into a *fading buffer* and cross-fades to the new mix over [`FADE`] seconds, so no
//! weight ever jumps. On top, no weight changes faster than [`MAX_RATE`] per second: at 60
//! frames a second, at most `MAX_RATE / 60` ≈ 0.13 per frame.

/// How long the fading buffer cross-fades to the new mix (seconds).
pub const FADE: f64 = 0.2;
/// The fastest a weight changes (per second).
pub const MAX_RATE: f32 = 8.0;

/// Smooth 0 → 1 over `x` in 0..1 (half a cosine).
pub fn ease(x: f64) -> f64 {
    let x = x.clamp(0.0, 1.0);
    (1.0 - (std::f64::consts::PI * x).cos()) / 2.0
}

/// The weight (0–1) of an expression with pegs `start`, `attack_peak`, `relax`, `end` at time
/// `t`: easing in during the attack, 1 while it holds, easing out during the release.
pub fn envelope(t: f64, start: f64, attack_peak: f64, relax: f64, end: f64) -> f64 {
    if t <= start || t >= end {
        0.0
    } else if t < attack_peak {
        ease((t - start) / (attack_peak - start))
    } else if t <= relax {
        1.0
    } else {
        1.0 - ease((t - relax) / (end - relax))
    }
}

/// The fading buffer and rate limit between the mix and the face shown (one weight vector:
/// the action unit slots, then the direct blendshapes).
#[derive(Debug, Clone, Default)]
pub struct Fader {
    /// What was shown at the last frame, and when.
    shown: Vec<f32>,
    at: Option<f64>,
    /// The buffer: what was shown when the mix jumped, and when.
    buffer: Option<(Vec<f32>, f64)>,
}

impl Fader {
    /// The mix jumped at `now` (an interrupt, a changed amount): fade from what is shown.
    pub fn jump(&mut self, now: f64) {
        if self.at.is_some() {
            self.buffer = Some((self.shown.clone(), now));
        }
    }

    /// What to show at `now` for the mix `mix` (changed in place).
    pub fn show(&mut self, now: f64, mix: &mut [f32]) {
        if let Some((buffer, since)) = &self.buffer {
            let s = ease((now - since) / FADE) as f32;
            if s >= 1.0 {
                self.buffer = None;
            } else {
                for (m, b) in mix.iter_mut().zip(buffer) {
                    *m = b + (*m - b) * s;
                }
            }
        }
        if let Some(at) = self.at.filter(|_| self.shown.len() == mix.len()) {
            let step = MAX_RATE * (now - at).max(0.0) as f32;
            for (m, s) in mix.iter_mut().zip(&self.shown) {
                *m = m.clamp(s - step, s + step);
            }
        }
        self.shown.clear();
        self.shown.extend_from_slice(mix);
        self.at = Some(now);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_envelope_rises_holds_and_falls_monotonically() {
        let e = |t| envelope(t, 1.0, 1.3, 2.2, 2.5);
        assert_eq!(e(1.0), 0.0);
        assert_eq!(e(1.3), 1.0);
        assert_eq!(e(2.0), 1.0);
        assert_eq!(e(2.5), 0.0);
        let ts: Vec<f64> = (0..=300).map(|k| 1.0 + k as f64 * 0.005).collect();
        for w in ts.windows(2) {
            let (a, b) = (e(w[0]), e(w[1]));
            if w[1] <= 1.3 {
                assert!(b >= a);
            } else if w[0] >= 2.2 {
                assert!(b <= a);
            }
        }
    }

    #[test]
    fn a_jump_in_the_mix_is_faded_and_no_weight_moves_faster_than_the_bound() {
        let mut f = Fader::default();
        let mut shown = Vec::new();
        for k in 0..60 {
            let now = k as f64 / 60.0;
            // the mix jumps from 0.2 to 1.0 at frame 10
            let mut mix = vec![if k < 10 { 0.2 } else { 1.0 }];
            if k == 10 {
                f.jump(now);
            }
            f.show(now, &mut mix);
            shown.push(mix[0]);
        }
        assert_eq!(shown[9], 0.2);
        assert!((shown[59] - 1.0).abs() < 1e-6, "faded in: {shown:?}");
        let most = shown
            .windows(2)
            .map(|w| (w[1] - w[0]).abs())
            .fold(0.0, f32::max);
        assert!(most <= MAX_RATE / 60.0 + 1e-6, "{most}");
        assert!(most < 0.8 / 4.0, "spread over several frames: {shown:?}");
    }
}
