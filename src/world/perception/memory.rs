//! What a character remembers having seen (after IViHumans' vision memories, thesis §3.1.7):
//! one entry per thing, from the last pass that saw it, in the order things were seen. Three
//! bounds, any of them or none: by count (at most N entries: beyond it exactly the oldest go),
//! by time (only what was seen in the last C milliseconds stays) and by passes (only what the
//! last C passes saw stays). The thesis has one memory class per bound; here one memory takes
//! any mix of them.

use std::collections::VecDeque;

use glam::Vec3;
use serde::Deserialize;

/// The bounds of a memory (all optional; the defaults keep 64 entries for 30 s).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, rename_all = "camelCase")]
pub struct MemoryLimits {
    /// Most entries.
    pub count: Option<usize>,
    /// Longest an entry is kept (milliseconds).
    pub millis: Option<f64>,
    /// Most passes an entry outlives (1: only the last pass's).
    pub passes: Option<u64>,
}

impl Default for MemoryLimits {
    fn default() -> Self {
        MemoryLimits {
            count: Some(64),
            millis: Some(30_000.0),
            passes: None,
        }
    }
}

/// Most entries any memory holds, whatever its limits say.
pub const MAX_ENTRIES: usize = 4096;

/// One thing remembered.
#[derive(Debug, Clone, PartialEq)]
pub struct Remembered {
    /// Its name (a character or a world point).
    pub id: String,
    /// When it was last seen (global seconds).
    pub time: f64,
    /// The pass that last saw it (the viewer's count, from 0).
    pub pass: u64,
    /// Where it was then (world, metres).
    pub at: Vec3,
}

/// A bounded memory.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Memory {
    limits: MemoryLimits,
    /// Oldest first.
    entries: VecDeque<Remembered>,
}

impl Memory {
    /// An empty memory with `limits`.
    pub fn new(limits: MemoryLimits) -> Memory {
        Memory {
            limits,
            entries: VecDeque::new(),
        }
    }

    /// Records what pass `pass` saw at `time` (in the order seen) and forgets what the limits
    /// no longer allow.
    pub fn record(&mut self, pass: u64, time: f64, seen: &[(String, Vec3)]) {
        for (id, at) in seen {
            if let Some(i) = self.entries.iter().position(|e| e.id == *id) {
                self.entries.remove(i);
            }
            self.entries.push_back(Remembered {
                id: id.clone(),
                time,
                pass,
                at: *at,
            });
        }
        self.forget(pass, time);
    }

    /// Forgets the oldest entries beyond the limits, as of pass `pass` at `time`.
    pub fn forget(&mut self, pass: u64, time: f64) {
        let count = self.limits.count.unwrap_or(MAX_ENTRIES).min(MAX_ENTRIES);
        while self.entries.len() > count {
            self.entries.pop_front();
        }
        if let Some(ms) = self.limits.millis {
            while (self.entries.front()).is_some_and(|e| (time - e.time) * 1000.0 > ms + 1e-6) {
                self.entries.pop_front();
            }
        }
        if let Some(passes) = self.limits.passes {
            while (self.entries.front()).is_some_and(|e| pass.saturating_sub(e.pass) >= passes) {
                self.entries.pop_front();
            }
        }
    }

    /// What it remembers, oldest first.
    pub fn entries(&self) -> impl Iterator<Item = &Remembered> {
        self.entries.iter()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn seen(ids: &[&str]) -> Vec<(String, Vec3)> {
        ids.iter().map(|i| (i.to_string(), Vec3::ZERO)).collect()
    }

    fn ids(m: &Memory) -> Vec<&str> {
        m.entries().map(|e| e.id.as_str()).collect()
    }

    fn limits(count: Option<usize>, millis: Option<f64>, passes: Option<u64>) -> MemoryLimits {
        MemoryLimits {
            count,
            millis,
            passes,
        }
    }

    #[test]
    fn by_count_exactly_the_oldest_beyond_capacity_go() {
        let mut m = Memory::new(limits(Some(3), None, None));
        m.record(0, 0.0, &seen(&["a", "b"]));
        m.record(1, 0.1, &seen(&["c"]));
        assert_eq!(ids(&m), ["a", "b", "c"]);
        m.record(2, 0.2, &seen(&["d"]));
        assert_eq!(ids(&m), ["b", "c", "d"]);
        // seen again: it becomes the newest, nothing else goes
        m.record(3, 0.3, &seen(&["b"]));
        assert_eq!(ids(&m), ["c", "d", "b"]);
        m.record(4, 0.4, &seen(&["e", "f"]));
        assert_eq!(ids(&m), ["b", "e", "f"]);
    }

    #[test]
    fn by_time_only_the_last_c_milliseconds_stay() {
        let mut m = Memory::new(limits(None, Some(250.0), None));
        m.record(0, 0.0, &seen(&["a"]));
        m.record(1, 0.1, &seen(&["b"]));
        m.record(2, 0.25, &seen(&["c"]));
        // a is exactly 250 ms old: kept
        assert_eq!(ids(&m), ["a", "b", "c"]);
        m.record(3, 0.3, &seen(&[]));
        assert_eq!(ids(&m), ["b", "c"]);
        m.forget(4, 0.351);
        assert_eq!(ids(&m), ["c"]);
    }

    #[test]
    fn by_passes_only_the_last_c_passes_stay() {
        let mut m = Memory::new(limits(None, None, Some(2)));
        m.record(0, 0.0, &seen(&["a"]));
        m.record(1, 9.0, &seen(&["b"]));
        assert_eq!(ids(&m), ["a", "b"]);
        m.record(2, 9.1, &seen(&["c"]));
        assert_eq!(ids(&m), ["b", "c"]);
        m.record(3, 9.2, &seen(&[]));
        assert_eq!(ids(&m), ["c"]);
    }
}
