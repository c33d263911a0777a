//! Anticipators: sources of predicted times of events outside the realizer (a user's
//! end of speech, a metronome's ticks) that BML refers to as `anticipators:ID:SYNC±o`. The runtime
//! polls them; when a prediction changes, the pegs tied to it move without rescheduling.
//!
//! Built-ins: [`Metronome`] (ticks at a tempo that can change while behaviour runs) and
//! [`Scripted`] (predictions that change at given times, for tests and demos).

use std::sync::{Arc, Mutex, PoisonError};

/// A source of predicted event times.
pub trait Anticipator: Send {
    /// The id BML uses (`anticipators:ID:SYNC`).
    fn id(&self) -> &str;

    /// The current prediction (global time) of `sync`, if the anticipator knows it.
    fn predict(&self, sync: &str) -> Option<f64>;

    /// Brings the predictions up to global time `now`; true if any may have changed since the
    /// previous call.
    fn update(&mut self, now: f64) -> bool;

    /// Whether a block that hangs on it sends a new prediction when its predictions move its
    /// end (a stream's end, revised with every chunk); by default not: the plan follows
    /// silently.
    fn announces(&self) -> bool {
        false
    }

    /// The next time the predictions change by themselves (a script), if known. Changes made from
    /// outside (e.g. a new tempo) are picked up at the next update.
    fn next_change(&self) -> Option<f64> {
        None
    }
}

/// A stretch of steady tempo: from (fractional) tick number `tick` at global `time` on, one tick
/// every `period` seconds.
#[derive(Debug, Clone, Copy)]
struct Segment {
    tick: f64,
    time: f64,
    period: f64,
}

#[derive(Debug)]
struct Beat {
    /// Tempo segments in time order; the last one goes on.
    segments: Vec<Segment>,
    changed: bool,
}

/// Tempo changes remembered (older ticks keep the times of the oldest remembered segment).
const SEGMENTS: usize = 64;

/// A metronome: syncs `tick1`, `tick2`, … at a steady tempo from a start time. A clone is a
/// handle to the same metronome, so the host can keep one and change the tempo while the
/// realizer owns the other.
#[derive(Debug, Clone)]
pub struct Metronome {
    id: String,
    state: Arc<Mutex<Beat>>,
}

impl Metronome {
    /// A metronome whose `tick1` is at global time `start`, at `bpm` beats per minute.
    pub fn new(id: &str, start: f64, bpm: f64) -> Self {
        Metronome {
            id: id.to_string(),
            state: Arc::new(Mutex::new(Beat {
                segments: vec![Segment {
                    tick: 1.0,
                    time: start,
                    period: 60.0 / bpm.max(f64::MIN_POSITIVE),
                }],
                changed: false,
            })),
        }
    }

    /// Changes the tempo at global time `now`: ticks after `now` come at the new rate, ticks
    /// already past keep their times. Non-positive or non-finite tempos are ignored.
    pub fn set_tempo(&self, bpm: f64, now: f64) {
        if !(bpm.is_finite() && bpm > 0.0) {
            return;
        }
        let mut s = self.state.lock().unwrap_or_else(PoisonError::into_inner);
        let last = *s.segments.last().expect("a metronome has a segment");
        let now = now.max(last.time);
        s.segments.push(Segment {
            tick: last.tick + (now - last.time) / last.period,
            time: now,
            period: 60.0 / bpm,
        });
        if s.segments.len() > SEGMENTS {
            s.segments.remove(0);
        }
        s.changed = true;
    }

    /// Global time of tick `n` (1-based) at the current tempo.
    pub fn tick_time(&self, n: u32) -> f64 {
        let s = self.state.lock().unwrap_or_else(PoisonError::into_inner);
        let n = f64::from(n);
        let seg = s
            .segments
            .iter()
            .rev()
            .find(|g| g.tick <= n)
            .unwrap_or(&s.segments[0]);
        seg.time + (n - seg.tick) * seg.period
    }
}

impl Anticipator for Metronome {
    fn id(&self) -> &str {
        &self.id
    }

    fn predict(&self, sync: &str) -> Option<f64> {
        let n: u32 = sync.strip_prefix("tick")?.parse().ok().filter(|&n| n > 0)?;
        Some(self.tick_time(n))
    }

    fn update(&mut self, _now: f64) -> bool {
        let mut s = self.state.lock().unwrap_or_else(PoisonError::into_inner);
        std::mem::take(&mut s.changed)
    }
}

/// Predictions that change at scripted times: `(at, sync, predicted time)` entries, applied in
/// order once the clock reaches `at`.
#[derive(Debug, Clone)]
pub struct Scripted {
    id: String,
    current: Vec<(String, f64)>,
    script: Vec<(f64, String, f64)>,
    next: usize,
}

impl Scripted {
    /// An anticipator with initial predictions and a script of changes.
    pub fn new(id: &str, initial: &[(&str, f64)], script: &[(f64, &str, f64)]) -> Self {
        let mut script: Vec<(f64, String, f64)> = script
            .iter()
            .map(|&(at, s, t)| (at, s.to_string(), t))
            .collect();
        script.sort_by(|a, b| a.0.total_cmp(&b.0));
        Scripted {
            id: id.to_string(),
            current: initial.iter().map(|&(s, t)| (s.to_string(), t)).collect(),
            script,
            next: 0,
        }
    }
}

impl Anticipator for Scripted {
    fn id(&self) -> &str {
        &self.id
    }

    fn predict(&self, sync: &str) -> Option<f64> {
        self.current.iter().find(|(s, _)| s == sync).map(|p| p.1)
    }

    fn update(&mut self, now: f64) -> bool {
        let mut changed = false;
        while let Some((at, sync, t)) = self.script.get(self.next) {
            if *at > now {
                break;
            }
            match self.current.iter_mut().find(|(s, _)| s == sync) {
                Some(p) => p.1 = *t,
                None => self.current.push((sync.clone(), *t)),
            }
            self.next += 1;
            changed = true;
        }
        changed
    }

    fn next_change(&self) -> Option<f64> {
        self.script.get(self.next).map(|e| e.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_metronome_keeps_past_ticks_and_retimes_future_ones_on_a_tempo_change() {
        let m = Metronome::new("m", 1.0, 60.0);
        let mut owned: Box<dyn Anticipator> = Box::new(m.clone());
        assert_eq!(owned.predict("tick1"), Some(1.0));
        assert_eq!(owned.predict("tick3"), Some(3.0));
        assert_eq!(owned.predict("tock"), None);
        assert_eq!(owned.predict("tick0"), None);
        assert!(!owned.update(0.5));
        m.set_tempo(120.0, 2.5); // half way between tick2 and tick3
        assert!(owned.update(2.5));
        assert!(!owned.update(2.6));
        assert_eq!(owned.predict("tick2"), Some(2.0));
        assert_eq!(owned.predict("tick3"), Some(2.75));
        assert_eq!(owned.predict("tick5"), Some(3.75));
    }

    #[test]
    fn a_script_changes_predictions_at_its_times() {
        let mut s = Scripted::new(
            "stop",
            &[("stop", 5.0)],
            &[(2.0, "stop", 6.0), (1.0, "stop", 4.0)],
        );
        assert_eq!(s.next_change(), Some(1.0));
        assert!(!s.update(0.5));
        assert!(s.update(1.0));
        assert_eq!(s.predict("stop"), Some(4.0));
        assert_eq!(s.next_change(), Some(2.0));
        assert!(s.update(3.0));
        assert_eq!(s.predict("stop"), Some(6.0));
        assert_eq!(s.next_change(), None);
    }
}
