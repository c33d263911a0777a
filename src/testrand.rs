//! The deterministic generator of the tests that check code on many generated inputs
//! (xorshift64: the same sequence on every run and machine).

/// Xorshift64 state (any seed but 0).
pub(crate) struct XorShift(pub(crate) u64);

impl XorShift {
    /// The next 64 bits.
    pub(crate) fn next_u64(&mut self) -> u64 {
        let mut x = self.0;
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        self.0 = x;
        x
    }
}
