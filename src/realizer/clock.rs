//! Clocks that drive a realizer: a virtual clock for tests and the CLI (time moves only when told,
//! so runs are deterministic) and a wall clock for real-time use.

use std::cell::Cell;
use std::time::Instant;

/// A source of the global time in seconds.
pub trait Clock {
    /// The current time.
    fn now(&self) -> f64;
}

/// Time that moves only when told to.
#[derive(Debug, Default)]
pub struct VirtualClock {
    t: Cell<f64>,
}

impl VirtualClock {
    /// A clock at time 0.
    pub fn new() -> Self {
        Self::default()
    }

    /// Moves the clock forward by `secs` (negative or non-finite values are ignored).
    pub fn advance(&self, secs: f64) {
        if secs.is_finite() && secs > 0.0 {
            self.t.set(self.t.get() + secs);
        }
    }

    /// Sets the time, never backwards.
    pub fn set(&self, t: f64) {
        if t.is_finite() && t > self.t.get() {
            self.t.set(t);
        }
    }
}

impl Clock for VirtualClock {
    fn now(&self) -> f64 {
        self.t.get()
    }
}

/// Seconds since the clock was made.
#[derive(Debug, Clone, Copy)]
pub struct WallClock {
    origin: Instant,
}

impl Default for WallClock {
    fn default() -> Self {
        WallClock {
            origin: Instant::now(),
        }
    }
}

impl WallClock {
    /// A clock at 0 now.
    pub fn new() -> Self {
        Self::default()
    }
}

impl Clock for WallClock {
    fn now(&self) -> f64 {
        self.origin.elapsed().as_secs_f64()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_virtual_clock_moves_only_forward_and_only_when_told() {
        let c = VirtualClock::new();
        assert_eq!(c.now(), 0.0);
        c.advance(1.5);
        c.advance(-3.0);
        c.advance(f64::NAN);
        assert_eq!(c.now(), 1.5);
        c.set(1.0);
        assert_eq!(c.now(), 1.5);
        c.set(2.25);
        assert_eq!(c.now(), 2.25);
    }

    #[test]
    fn the_wall_clock_advances() {
        let c = WallClock::new();
        let a = c.now();
        std::thread::sleep(std::time::Duration::from_millis(2));
        assert!(c.now() > a);
    }
}
