//! The assertion vocabulary of RealizerTester's handler (catalogue §1.3) with its exact semantics:
//! first-match lookup, 0.1 s for equalities, strict inequalities without epsilon, subsequence
//! order. Every check returns a [`Failure`] that names the block, behaviour, sync and the times
//! seen.

use std::fmt;

use crate::record::{Recorder, SyncProgress};

/// The handler's epsilon: "2 frames in 20fps realizer execution".
pub const SYNC_EPSILON: f64 = 0.1;

/// A failed assertion, with what was expected and what was seen.
#[derive(Debug, Clone, PartialEq)]
pub struct Failure(pub String);

impl fmt::Display for Failure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

/// The outcome of a check.
pub type Check = Result<(), Failure>;

fn fail<T>(msg: impl Into<String>) -> Result<T, Failure> {
    Err(Failure(msg.into()))
}

/// `B:beh:S` split into its parts.
fn parts(id: &str) -> (&str, &str, &str) {
    let mut it = id.splitn(3, ':');
    (
        it.next().unwrap_or(""),
        it.next().unwrap_or(""),
        it.next().unwrap_or(""),
    )
}

impl Recorder {
    /// The first sync entry for `B:beh:S`, or a failure listing the syncs seen (the original's
    /// `BMLSyncPointNotFoundException`).
    pub fn need_sync(&self, id: &str) -> Result<&SyncProgress, Failure> {
        let (b, beh, s) = parts(id);
        self.sync(b, beh, s).ok_or_else(|| {
            let seen: Vec<String> = self
                .syncs
                .iter()
                .filter(|x| x.bml_id == b && x.behaviour_id == beh)
                .map(|x| x.sync_id.clone())
                .collect();
            Failure(format!(
                "no sync feedback {id}; syncs of {b}:{beh}: {seen:?}"
            ))
        })
    }

    /// NoExc: no exception.
    pub fn no_exceptions(&self) -> Check {
        match self.exceptions.first() {
            None => Ok(()),
            Some(e) => fail(format!(
                "expected no exceptions, got {}: {e}",
                self.exceptions.len()
            )),
        }
    }

    /// NoWarn: no warning.
    pub fn no_warnings(&self) -> Check {
        if self.warnings.is_empty() {
            return Ok(());
        }
        let list: Vec<String> = self
            .warnings
            .iter()
            .map(|w| format!("{}:{} {}", w.bml_id, w.modified_behaviours[0], w.text))
            .collect();
        fail(format!("expected no warnings, got {list:?}"))
    }

    /// NoDupSyncs: no two sync entries for the same `B:beh:S`.
    pub fn no_duplicate_syncs(&self) -> Check {
        for (i, a) in self.syncs.iter().enumerate() {
            if self.syncs[..i].iter().any(|b| {
                a.bml_id == b.bml_id && a.behaviour_id == b.behaviour_id && a.sync_id == b.sync_id
            }) {
                return fail(format!(
                    "sync feedback {}:{}:{} arrived twice",
                    a.bml_id, a.behaviour_id, a.sync_id
                ));
            }
        }
        Ok(())
    }

    /// NoDup: NoDupSyncs, and no block started or stopped twice.
    pub fn no_duplicate_feedback(&self) -> Check {
        self.no_duplicate_syncs()?;
        for (what, ids) in [
            (
                "start",
                self.starts.iter().map(|s| &s.bml_id).collect::<Vec<_>>(),
            ),
            (
                "end",
                self.stops.iter().map(|s| &s.bml_id).collect::<Vec<_>>(),
            ),
        ] {
            for (i, id) in ids.iter().enumerate() {
                if ids[..i].contains(id) {
                    return fail(format!("block {id} reported {what} twice"));
                }
            }
        }
        Ok(())
    }

    /// Starts[…]: the block-start list is exactly `ids`, in order.
    pub fn block_starts(&self, ids: &[&str]) -> Check {
        let seen: Vec<&str> = self.starts.iter().map(|s| s.bml_id.as_str()).collect();
        if seen == ids {
            Ok(())
        } else {
            fail(format!("expected block starts {ids:?}, got {seen:?}"))
        }
    }

    /// Stops[…]: the block-end list is exactly `ids`, in order.
    pub fn block_stops(&self, ids: &[&str]) -> Check {
        let seen: Vec<&str> = self.stops.iter().map(|s| s.bml_id.as_str()).collect();
        if seen == ids {
            Ok(())
        } else {
            fail(format!("expected block ends {ids:?}, got {seen:?}"))
        }
    }

    /// Blocks[…]: Starts[…] and Stops[…].
    pub fn block_starts_and_stops(&self, ids: &[&str]) -> Check {
        self.block_starts(ids)?;
        self.block_stops(ids)
    }

    fn syncs_of(&self, block: &str, behaviour: &str) -> Vec<&str> {
        self.syncs
            .iter()
            .filter(|s| s.bml_id == block && s.behaviour_id == behaviour)
            .map(|s| s.sync_id.as_str())
            .collect()
    }

    /// Order(B:beh: …): `expected` is a subsequence of the syncs of `B:beh` in arrival order.
    /// The original's quirk is kept: after a match the cursor stays, so a repeated expected id
    /// matches the same entry.
    pub fn syncs_in_order(&self, block: &str, behaviour: &str, expected: &[&str]) -> Check {
        let seen = self.syncs_of(block, behaviour);
        if expected.len() > seen.len() {
            return fail(format!(
                "{block}:{behaviour}: expected syncs {expected:?} in order, got only {seen:?}"
            ));
        }
        let mut cursor = 0;
        for e in expected {
            match seen[cursor..].iter().position(|s| s == e) {
                Some(p) => cursor += p,
                None => {
                    return fail(format!(
                        "{block}:{behaviour}: expected syncs {expected:?} in order, got {seen:?} ('{e}' missing or out of order)"
                    ))
                }
            }
        }
        Ok(())
    }

    /// Only(B:beh: …): the syncs of `B:beh` are exactly `expected`, in order.
    pub fn only_these_syncs_in_order(
        &self,
        block: &str,
        behaviour: &str,
        expected: &[&str],
    ) -> Check {
        let seen = self.syncs_of(block, behaviour);
        if seen == expected {
            Ok(())
        } else {
            fail(format!(
                "{block}:{behaviour}: expected exactly the syncs {expected:?}, got {seen:?}"
            ))
        }
    }

    /// Rel(B:beh:S = t): the block-relative time is within 0.1 s of `t`.
    pub fn relative_sync_time(&self, id: &str, t: f64) -> Check {
        let s = self.need_sync(id)?;
        if (s.bml_block_time - t).abs() <= SYNC_EPSILON {
            Ok(())
        } else {
            fail(format!(
                "{id}: expected block time {t} (±{SYNC_EPSILON}), got {}",
                s.bml_block_time
            ))
        }
    }

    /// Link(A [+oa] = B [+ob]): global times (plus offsets) within 0.1 s.
    pub fn linked_syncs(&self, a: &str, oa: f64, b: &str, ob: f64) -> Check {
        let (sa, sb) = (self.need_sync(a)?, self.need_sync(b)?);
        let (ga, gb) = (sa.time_stamp + oa, sb.time_stamp + ob);
        if (ga - gb).abs() <= SYNC_EPSILON {
            Ok(())
        } else {
            fail(format!(
                "{a} (+{oa}) at {ga} and {b} (+{ob}) at {gb} differ by {:.3} s (more than {SYNC_EPSILON})",
                (ga - gb).abs()
            ))
        }
    }

    /// RelBefore(B:beh:S < t): strictly before, no epsilon.
    pub fn sync_before_relative_time(&self, id: &str, t: f64) -> Check {
        let s = self.need_sync(id)?;
        if s.bml_block_time < t {
            Ok(())
        } else {
            fail(format!(
                "{id}: expected block time < {t}, got {}",
                s.bml_block_time
            ))
        }
    }

    /// RelAfter(B:beh:S > t): strictly after, no epsilon.
    pub fn sync_after_relative_time(&self, id: &str, t: f64) -> Check {
        let s = self.need_sync(id)?;
        if s.bml_block_time > t {
            Ok(())
        } else {
            fail(format!(
                "{id}: expected block time > {t}, got {}",
                s.bml_block_time
            ))
        }
    }

    /// SyncAfterSync(A > B): block-relative times, strict (even across blocks).
    pub fn sync_after_sync(&self, a: &str, b: &str) -> Check {
        let (sa, sb) = (self.need_sync(a)?, self.need_sync(b)?);
        if sa.bml_block_time > sb.bml_block_time {
            Ok(())
        } else {
            fail(format!(
                "expected {a} ({}) after {b} ({})",
                sa.bml_block_time, sb.bml_block_time
            ))
        }
    }

    /// SyncBeforeSync(A < B): block-relative times, strict.
    pub fn sync_before_sync(&self, a: &str, b: &str) -> Check {
        let (sa, sb) = (self.need_sync(a)?, self.need_sync(b)?);
        if sa.bml_block_time < sb.bml_block_time {
            Ok(())
        } else {
            fail(format!(
                "expected {a} ({}) before {b} ({})",
                sa.bml_block_time, sb.bml_block_time
            ))
        }
    }

    /// Dur>0(B): the block's stop is strictly after its start.
    pub fn duration_greater_than_zero(&self, block: &str) -> Check {
        let (Some(s), Some(e)) = (self.start(block), self.stop(block)) else {
            return fail(format!("{block}: no start or end feedback"));
        };
        if e.time_stamp > s.time_stamp {
            Ok(())
        } else {
            fail(format!(
                "{block}: ends at {} which is not after its start at {}",
                e.time_stamp, s.time_stamp
            ))
        }
    }

    /// After(prev → next [≤ d]): `next` starts at or after `prev` stops, and within `d` if given.
    pub fn after_block(&self, prev: &str, next: &str, d: Option<f64>) -> Check {
        let Some(stop) = self.stop(prev) else {
            return fail(format!("No end feedback for {prev}"));
        };
        let Some(start) = self.start(next) else {
            return fail(format!("No start feedback for {next}"));
        };
        let gap = start.time_stamp - stop.time_stamp;
        if gap < 0.0 {
            return fail(format!(
                "{next} starts at {} before {prev} ends at {}",
                start.time_stamp, stop.time_stamp
            ));
        }
        match d {
            Some(d) if gap.abs() > d => fail(format!(
                "{next} starts {gap:.3} s after {prev} ends (at most {d} allowed)"
            )),
            _ => Ok(()),
        }
    }

    /// StartAtStop(Bs = Be): `Bs` starts within 0.1 s of `Be`'s stop.
    pub fn block_start_linked_to_block_stop(&self, starts: &str, stops: &str) -> Check {
        let (Some(s), Some(e)) = (self.start(starts), self.stop(stops)) else {
            return fail(format!(
                "No start feedback for {starts} or no end feedback for {stops}"
            ));
        };
        if (s.time_stamp - e.time_stamp).abs() <= SYNC_EPSILON {
            Ok(())
        } else {
            fail(format!(
                "{starts} starts at {} but {stops} ends at {}",
                s.time_stamp, e.time_stamp
            ))
        }
    }

    /// SyncAtStart(B:beh:S = Bref): the sync's global time within 0.1 s of `Bref`'s start.
    pub fn sync_linked_to_block_start(&self, id: &str, block: &str) -> Check {
        let s = self.need_sync(id)?;
        let Some(b) = self.start(block) else {
            return fail(format!("No start feedback for {block}"));
        };
        if (s.time_stamp - b.time_stamp).abs() <= SYNC_EPSILON {
            Ok(())
        } else {
            fail(format!(
                "{id} at {} but {block} starts at {}",
                s.time_stamp, b.time_stamp
            ))
        }
    }

    /// RelNonNeg: every sync's block time is ≥ 0.
    pub fn valid_sync_times(&self) -> Check {
        match self.syncs.iter().find(|s| s.bml_block_time < 0.0) {
            None => Ok(()),
            Some(s) => fail(format!(
                "{}:{}:{} has negative block time {}",
                s.bml_id, s.behaviour_id, s.sync_id, s.bml_block_time
            )),
        }
    }

    /// FeedbackFor(B: behs): the behaviours with syncs in `block` are exactly `behaviours`.
    pub fn feedback_for_behaviours(&self, block: &str, behaviours: &[&str]) -> Check {
        let mut seen: Vec<&str> = self
            .syncs
            .iter()
            .filter(|s| s.bml_id == block)
            .map(|s| s.behaviour_id.as_str())
            .collect();
        seen.sort_unstable();
        seen.dedup();
        let mut want = behaviours.to_vec();
        want.sort_unstable();
        if seen == want {
            Ok(())
        } else {
            fail(format!("{block}: feedback for {seen:?}, expected {want:?}"))
        }
    }
}

#[cfg(test)]
mod tests {
    //! Every helper has a case where it must fail, and does; plus the handler self-tests of the
    //! original (`BMLRealizerHandlerTest`).
    use super::*;
    use crate::record::{PerformanceStart, PerformanceStop, Warning};

    fn sync(id: &str, rel: f64, global: f64) -> SyncProgress {
        let (b, beh, s) = parts(id);
        SyncProgress {
            bml_id: b.into(),
            behaviour_id: beh.into(),
            sync_id: s.into(),
            bml_block_time: rel,
            time_stamp: global,
        }
    }

    fn blocks(r: &mut Recorder, start: (&str, f64), stop: (&str, f64)) {
        r.starts.push(PerformanceStart {
            character_id: None,
            bml_id: start.0.into(),
            time_stamp: start.1,
        });
        r.stops.push(PerformanceStop {
            character_id: None,
            bml_id: stop.0.into(),
            time_stamp: stop.1,
        });
    }

    fn gesture(r: &mut Recorder, syncs: &[&str]) {
        for (i, s) in syncs.iter().enumerate() {
            r.syncs
                .push(sync(&format!("bml1:g1:{s}"), i as f64, i as f64));
        }
    }

    #[test]
    fn order_fails_when_a_sync_is_missing() {
        let mut r = Recorder::new();
        gesture(&mut r, &["start", "ready", "stroke", "end"]);
        assert!(r
            .syncs_in_order("bml1", "g1", &["start", "relax", "end"])
            .is_err());
    }

    #[test]
    fn order_passes_with_an_interleaved_relax_and_fails_reversed() {
        let mut r = Recorder::new();
        gesture(&mut r, &["start", "stroke", "relax", "end"]);
        r.syncs_in_order("bml1", "g1", &["start", "stroke", "end"])
            .unwrap();
        assert!(r.syncs_in_order("bml1", "g1", &["end", "start"]).is_err());
        // the original's quirk: a repeated id matches the same entry
        r.syncs_in_order("bml1", "g1", &["stroke", "stroke"])
            .unwrap();
        // more expected than seen fails at once
        assert!(r
            .syncs_in_order("bml1", "g1", &["start", "start", "start", "start", "start"])
            .is_err());
    }

    #[test]
    fn only_fails_with_an_interleaved_sync_and_passes_without() {
        let mut r = Recorder::new();
        gesture(&mut r, &["start", "stroke", "relax", "end"]);
        assert!(r
            .only_these_syncs_in_order("bml1", "g1", &["start", "stroke", "end"])
            .is_err());
        r.only_these_syncs_in_order("bml1", "g1", &["start", "stroke", "relax", "end"])
            .unwrap();
    }

    #[test]
    fn after_block_as_in_the_handler_self_test() {
        let case = |stop: f64, start: f64, d: Option<f64>| {
            let mut r = Recorder::new();
            blocks(&mut r, ("bml2", start), ("bml1", stop));
            r.after_block("bml1", "bml2", d)
        };
        case(1.0, 1.0, None).unwrap();
        case(1.0, 1.1, None).unwrap();
        case(1.0, 1.0, Some(0.1)).unwrap();
        case(1.0, 1.1, Some(0.5)).unwrap();
        assert!(case(1.0, 1.6, Some(0.5)).is_err(), "too late");
        assert!(case(1.0, 0.9, Some(0.5)).is_err(), "before");
        assert!(case(1.0, 0.9, None).is_err(), "before, no bound");
    }

    #[test]
    fn equalities_allow_a_tenth_of_a_second_and_no_more() {
        let mut r = Recorder::new();
        r.syncs.push(sync("b:s:start", 1.0, 1.0));
        r.syncs.push(sync("b:n:start", 1.09, 1.09));
        r.syncs.push(sync("b:n:end", 1.11, 1.11));
        // as JUnit's assertEquals(expected, actual, 0.1): |1.1 - 1.0| is a hair above 0.1 in
        // floating point, so the suite's "0.1" means "up to just below 0.1"
        r.relative_sync_time("b:s:start", 1.09).unwrap();
        let e = r.relative_sync_time("b:s:start", 1.11).unwrap_err();
        assert_eq!(e.0, "b:s:start: expected block time 1.11 (±0.1), got 1");
        r.linked_syncs("b:s:start", 0.0, "b:n:start", 0.0).unwrap();
        assert!(r.linked_syncs("b:s:start", 0.0, "b:n:end", 0.0).is_err());
        r.linked_syncs("b:s:start", 0.1, "b:n:end", 0.0).unwrap();
        let missing = r.relative_sync_time("b:s:relax", 0.0).unwrap_err();
        assert_eq!(
            missing.0,
            r#"no sync feedback b:s:relax; syncs of b:s: ["start"]"#
        );
    }

    #[test]
    fn inequalities_are_strict() {
        let mut r = Recorder::new();
        r.syncs.push(sync("b:s:start", 1.0, 1.0));
        r.syncs.push(sync("b:s:end", 2.0, 2.0));
        r.sync_before_relative_time("b:s:start", 1.0001).unwrap();
        assert!(r.sync_before_relative_time("b:s:start", 1.0).is_err());
        r.sync_after_relative_time("b:s:end", 1.9999).unwrap();
        assert!(r.sync_after_relative_time("b:s:end", 2.0).is_err());
        r.sync_after_sync("b:s:end", "b:s:start").unwrap();
        assert!(r.sync_after_sync("b:s:start", "b:s:end").is_err());
        assert!(r.sync_after_sync("b:s:start", "b:s:start").is_err());
        r.sync_before_sync("b:s:start", "b:s:end").unwrap();
        assert!(r.sync_before_sync("b:s:end", "b:s:start").is_err());
    }

    #[test]
    fn block_lists_need_exact_order_and_no_duplicates() {
        let mut r = Recorder::new();
        blocks(&mut r, ("bml1", 0.0), ("bml1", 2.0));
        blocks(&mut r, ("bml2", 2.0), ("bml2", 3.0));
        r.block_starts_and_stops(&["bml1", "bml2"]).unwrap();
        assert!(r.block_starts(&["bml2", "bml1"]).is_err());
        assert!(r.block_stops(&["bml1"]).is_err());
        r.no_duplicate_feedback().unwrap();
        r.duration_greater_than_zero("bml1").unwrap();
        r.block_start_linked_to_block_stop("bml2", "bml1").unwrap();
        blocks(&mut r, ("bml3", 2.2), ("bml1", 4.0));
        assert!(r.no_duplicate_feedback().is_err(), "bml1 ended twice");
        assert!(r.block_start_linked_to_block_stop("bml3", "bml1").is_err());
        let mut z = Recorder::new();
        blocks(&mut z, ("b", 1.0), ("b", 1.0));
        assert!(z.duration_greater_than_zero("b").is_err());
        assert!(z.duration_greater_than_zero("x").is_err());
    }

    #[test]
    fn duplicate_syncs_warnings_exceptions_and_negative_times_fail() {
        let mut r = Recorder::new();
        r.syncs.push(sync("b:s:start", 0.0, 0.0));
        r.no_duplicate_syncs().unwrap();
        r.valid_sync_times().unwrap();
        r.syncs.push(sync("b:s:start", 0.5, 0.5));
        assert!(r.no_duplicate_syncs().is_err());
        r.syncs.push(sync("b:t:start", -0.01, 0.0));
        assert!(r.valid_sync_times().is_err());
        r.sync_linked_to_block_start("b:t:start", "b").unwrap_err(); // no start of b
        blocks(&mut r, ("b", 0.05), ("b", 1.0));
        r.sync_linked_to_block_start("b:t:start", "b").unwrap();
        blocks(&mut r, ("c", 0.2), ("c", 1.0));
        assert!(r.sync_linked_to_block_start("b:t:start", "c").is_err());
        r.no_warnings().unwrap();
        r.warnings.push(Warning {
            character_id: None,
            bml_id: "b".into(),
            modified_behaviours: vec!["s".into()],
            text: "INVALID_TIMING: x".into(),
        });
        assert!(r.no_warnings().is_err());
        r.no_exceptions().unwrap();
        r.exceptions.push("boom".into());
        assert!(r.no_exceptions().is_err());
        r.feedback_for_behaviours("b", &["s", "t"]).unwrap();
        assert!(r.feedback_for_behaviours("b", &["s"]).is_err());
    }
}
