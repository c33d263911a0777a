//! A second-order Butterworth low-pass for stored motion (keyframes, motion capture), run forward
//! and then backward (zero phase). Two passes square the magnitude response, so the cut-off of
//! each pass is corrected by C = (2^{1/n} − 1)^{1/4} (0.802 for n = 2 passes; applied to the
//! pre-warped frequency): the pair is at 1/√2 (−3 dB) at the asked cut-off. Coefficients by the
//! bilinear transform with frequency pre-warping.

/// A second-order low-pass: b0 b1 b2 over 1 a1 a2.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Butterworth {
    b: [f64; 3],
    a: [f64; 2],
}

/// The correction of the cut-off for a forward–backward pair of passes.
pub fn correction(passes: u32) -> f64 {
    (2f64.powf(1.0 / f64::from(passes)) - 1.0).powf(0.25)
}

impl Butterworth {
    /// A low-pass at `cutoff` Hz for samples at `rate` Hz, corrected for a forward–backward pair
    /// (the pair is −3 dB at `cutoff`).
    pub fn zero_phase(cutoff: f64, rate: f64) -> Butterworth {
        // the correction applies to the pre-warped frequency
        Butterworth::warped((std::f64::consts::PI * cutoff / rate).tan() / correction(2))
    }

    /// One pass at `cutoff` Hz (−3 dB there) for samples at `rate` Hz.
    pub fn single(cutoff: f64, rate: f64) -> Butterworth {
        Butterworth::warped((std::f64::consts::PI * cutoff / rate).tan())
    }

    /// One pass with the pre-warped cut-off `k` = tan(π f_c / rate).
    fn warped(k: f64) -> Butterworth {
        let s2 = std::f64::consts::SQRT_2;
        let norm = 1.0 / (1.0 + s2 * k + k * k);
        let b0 = k * k * norm;
        Butterworth {
            b: [b0, 2.0 * b0, b0],
            a: [2.0 * (k * k - 1.0) * norm, (1.0 - s2 * k + k * k) * norm],
        }
    }

    /// One pass over `x` (the state starts at the first sample, so a constant stays constant).
    fn pass(&self, x: &[f64]) -> Vec<f64> {
        let Some(&first) = x.first() else {
            return Vec::new();
        };
        let (mut x1, mut x2, mut y1, mut y2) = (first, first, first, first);
        x.iter()
            .map(|&x0| {
                let y0 = self.b[0] * x0 + self.b[1] * x1 + self.b[2] * x2
                    - self.a[0] * y1
                    - self.a[1] * y2;
                (x2, x1, y2, y1) = (x1, x0, y1, y0);
                y0
            })
            .collect()
    }

    /// `x` filtered forward and then backward: no phase shift.
    pub fn filtfilt(&self, x: &[f64]) -> Vec<f64> {
        let mut y = self.pass(x);
        y.reverse();
        let mut y = self.pass(&y);
        y.reverse();
        y
    }

    /// The magnitude of one pass at `f` Hz for samples at `rate` Hz.
    pub fn gain(&self, f: f64, rate: f64) -> f64 {
        let w = 2.0 * std::f64::consts::PI * f / rate;
        let z = |k: f64| (w * k).cos();
        let zs = |k: f64| -(w * k).sin();
        let num = (
            self.b[0] + self.b[1] * z(1.0) + self.b[2] * z(2.0),
            self.b[1] * zs(1.0) + self.b[2] * zs(2.0),
        );
        let den = (
            1.0 + self.a[0] * z(1.0) + self.a[1] * z(2.0),
            self.a[0] * zs(1.0) + self.a[1] * zs(2.0),
        );
        (num.0.hypot(num.1)) / (den.0.hypot(den.1))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_pair_is_minus_3_db_at_its_cut_off_with_unit_dc_gain_and_no_phase() {
        assert!((correction(2) - 0.802).abs() < 5e-4);
        let rate = 200.0;
        let f = Butterworth::zero_phase(20.0, rate);
        assert!((f.gain(0.0, rate) - 1.0).abs() < 1e-12, "DC gain 1");
        let pair = f.gain(20.0, rate).powi(2);
        assert!(
            (pair - std::f64::consts::FRAC_1_SQRT_2).abs() < 1e-6,
            "pair at the cut-off: {pair}"
        );
        // a sinusoid below the cut-off keeps its phase (its peaks stay where they were)
        let x: Vec<f64> = (0..2000)
            .map(|k| (2.0 * std::f64::consts::PI * 3.0 * k as f64 / rate).sin())
            .collect();
        let y = f.filtfilt(&x);
        let (mid, n) = (800, 400);
        let lag = |d: i64| -> f64 {
            (mid..mid + n)
                .map(|k| x[k] * y[(k as i64 + d) as usize])
                .sum()
        };
        let best = (-5..=5).max_by(|&a, &b| lag(a).total_cmp(&lag(b))).unwrap();
        assert_eq!(best, 0, "zero phase");
        let constant = f.filtfilt(&[0.7; 50]);
        assert!(constant.iter().all(|v| (v - 0.7).abs() < 1e-12));
    }
}
