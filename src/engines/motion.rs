//! Shapes the motion engines share: the minimum-jerk profile, the go–hold–return envelope of a
//! behaviour that moves toward a target between `start` and `ready` and back between `relax` and
//! `end` (a shift moves over its whole span and stays), the most recently finished shift, and the
//! hands a gesture mode occupies.

use crate::engines::interface::Units;
use crate::language::bml::Mode;
use crate::planning::timing::SyncName;

/// Minimum-jerk profile: 0 at 0, 1 at 1, zero velocity and acceleration at both ends.
pub fn min_jerk(u: f64) -> f64 {
    let u = u.clamp(0.0, 1.0);
    u * u * u * (10.0 - 15.0 * u + 6.0 * u * u)
}

/// The time of sync `name`.
pub fn at(syncs: &[(SyncName, f64)], name: &str) -> Option<f64> {
    syncs.iter().find(|s| s.0 == name).map(|s| s.1)
}

/// How far a behaviour is toward its target at `t` (0..1), `None` outside `start..end`: a
/// minimum-jerk rise from `start` that arrives after `lead` of the way to `ready` (1 = at
/// `ready`), 1 until `relax`, a minimum-jerk return by `end`. A `shift` rises over
/// `start..end` and stays.
pub fn envelope(syncs: &[(SyncName, f64)], t: f64, shift: bool, lead: f64) -> Option<f64> {
    let (start, end) = (at(syncs, "start")?, at(syncs, "end")?);
    if t < start || t >= end {
        return None;
    }
    let (ready, relax) = if shift {
        (end, f64::INFINITY)
    } else {
        (at(syncs, "ready")?, at(syncs, "relax")?)
    };
    if t < ready {
        let span = (ready - start) * lead;
        return Some(if span > 0.0 {
            min_jerk((t - start) / span)
        } else {
            1.0
        });
    }
    if t < relax {
        return Some(1.0);
    }
    Some(if end > relax {
        1.0 - min_jerk((t - relax) / (end - relax))
    } else {
        0.0
    })
}

/// The data of the shift (as `is_shift` says) that ended last by `now`, if any: its target
/// becomes the rest state.
pub fn finished_shift<T>(units: &Units<T>, now: f64, is_shift: impl Fn(&T) -> bool) -> Option<&T> {
    units
        .all()
        .filter_map(|(syncs, u)| Some((at(syncs, "end")?, u)))
        .filter(|(end, u)| *end <= now && is_shift(u))
        .max_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, u)| u)
}

/// The sides a gesture authored for the right arm plays on for a mode: `false` as authored,
/// `true` mirrored onto the left (the right hand when no mode is given).
pub fn sides(mode: Option<Mode>) -> &'static [bool] {
    match mode {
        Some(Mode::LeftHand) => &[true],
        Some(Mode::BothHands) => &[false, true],
        Some(Mode::RightHand) | None => &[false],
    }
}

/// The hands a gesture mode occupies (the right hand when none is given).
pub fn hands(mode: Option<Mode>) -> &'static [&'static str] {
    match mode {
        Some(Mode::LeftHand) => &["left_hand"],
        Some(Mode::BothHands) => &["left_hand", "right_hand"],
        Some(Mode::RightHand) | None => &["right_hand"],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn syncs(v: &[(&'static str, f64)]) -> Vec<(SyncName, f64)> {
        v.iter()
            .map(|&(n, t)| (crate::language::bml::Id::new_static(n), t))
            .collect()
    }

    #[test]
    fn minimum_jerk_starts_and_ends_at_rest() {
        assert_eq!(min_jerk(0.0), 0.0);
        assert_eq!(min_jerk(1.0), 1.0);
        assert!((min_jerk(0.5) - 0.5).abs() < 1e-12);
        let v = |u: f64| (min_jerk(u + 1e-6) - min_jerk(u)) / 1e-6;
        assert!(v(0.0) < 1e-4 && v(0.999_998) < 1e-3 && v(0.5) > 1.8);
    }

    #[test]
    fn the_envelope_goes_holds_and_returns() {
        let s = syncs(&[("start", 1.0), ("ready", 2.0), ("relax", 4.0), ("end", 5.0)]);
        assert_eq!(envelope(&s, 0.5, false, 1.0), None);
        assert_eq!(envelope(&s, 1.0, false, 1.0), Some(0.0));
        assert!((envelope(&s, 1.5, false, 1.0).unwrap() - 0.5).abs() < 1e-12);
        assert_eq!(
            envelope(&s, 1.5, false, 0.5),
            Some(1.0),
            "a lead of a half arrives at 1.5"
        );
        assert_eq!(envelope(&s, 3.0, false, 1.0), Some(1.0));
        assert!((envelope(&s, 4.5, false, 1.0).unwrap() - 0.5).abs() < 1e-12);
        assert_eq!(envelope(&s, 5.0, false, 1.0), None);
        // a shift: start..end, no ready or relax needed
        let shift = syncs(&[("start", 0.0), ("end", 2.0)]);
        assert!((envelope(&shift, 1.0, true, 1.0).unwrap() - 0.5).abs() < 1e-12);
        assert_eq!(
            envelope(&shift, 1.0, false, 1.0),
            None,
            "not a shift: needs ready"
        );
    }
}
