//! A small deterministic generator (xorshift64) for the motion's randomness — steering's wander
//! and dithering, the jitter of a walker's avoidance samples — so that the same seed gives the
//! same motion on every run and machine.

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
