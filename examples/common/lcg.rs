//! A small deterministic generator for the examples' scenes: the same seed gives the same
//! scene on every run and machine (the figures in the docs were measured on these scenes).

/// A linear congruential generator (Knuth's MMIX constants).
pub struct Lcg(pub u64);

impl Lcg {
    /// The next number in [0, 1).
    pub fn unit(&mut self) -> f32 {
        self.0 = (self.0)
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }
}
