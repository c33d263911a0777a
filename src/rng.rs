//! A small deterministic generator (xorshift64) for the motion's randomness — steering's wander
//! and dithering, the jitter of a walker's avoidance samples — so that the same seed gives the
//! same motion on every run and machine; and stateless numbers by index ([`unit()`]), for the idle
//! layer's blinks and saccades, whose k-th moment any frame can make on its own.

/// The generator's state (any seed; 0 counts as 1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rng(pub u64);

impl Rng {
    /// A number in [0, 1).
    pub fn next_f32(&mut self) -> f32 {
        let mut x = self.0.max(1);
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        self.0 = x;
        (x >> 40) as f32 / (1u64 << 24) as f32
    }

    /// Moves on by `n` numbers without making them (where a caller knows it will not use
    /// them, but the numbers after them must stay the same).
    pub fn skip(&mut self, n: usize) {
        for _ in 0..n {
            self.next_f32();
        }
    }
}

/// The `k`-th number in [0, 1) of the stream `seed` (splitmix64 of seed + k × the golden
/// ratio): stateless, so that any number of a stream can be made on its own, in any order.
pub fn unit(seed: u64, k: u64) -> f64 {
    let mut z = seed.wrapping_add(k.wrapping_mul(0x9E37_79B9_7F4A_7C15));
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^= z >> 31;
    (z >> 11) as f64 / (1u64 << 53) as f64
}

/// Two independent standard normal numbers from two uniform ones in [0, 1) (Box and Muller's
/// transform).
pub fn normals(u: f64, v: f64) -> (f64, f64) {
    let r = (-2.0 * u.max(1e-300).ln()).sqrt();
    let a = std::f64::consts::TAU * v;
    (r * a.cos(), r * a.sin())
}

/// The 64-bit FNV-1a hash of `text`: a seed per name, the same on every run and platform.
pub fn fnv1a(text: &str) -> u64 {
    (text.bytes()).fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_by_index_are_uniform_and_normals_are_standard() {
        let n = 20_000;
        let us: Vec<f64> = (0..n).map(|k| unit(7, k)).collect();
        assert!(us.iter().all(|u| (0.0..1.0).contains(u)));
        let mean = us.iter().sum::<f64>() / n as f64;
        assert!((mean - 0.5).abs() < 0.01, "{mean}");
        let zs: Vec<f64> = (0..n).map(|k| normals(unit(1, k), unit(2, k)).0).collect();
        let m = zs.iter().sum::<f64>() / n as f64;
        let sd = (zs.iter().map(|z| (z - m).powi(2)).sum::<f64>() / n as f64).sqrt();
        assert!(
            m.abs() < 0.03 && (sd - 1.0).abs() < 0.03,
            "mean {m}, sd {sd}"
        );
        assert_eq!(fnv1a(""), 0xcbf2_9ce4_8422_2325);
        assert_ne!(fnv1a("anna"), fnv1a("bob"));
    }
}
