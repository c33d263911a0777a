//! How one walker avoids others: the thesis' profile parameters (its Ch. 5 "profiles": α, β,
//! δ, η, the time-to-contact thresholds, the angle spans, `incr` and the distortion), plus a
//! deviation weight the thesis' list leaves out, a field of view and the side-keeping cost. The
//! thesis gives its cost and range formulas only as figures; the values and the cost here are
//! this realizer's reconstruction (see `avoid` for the cost).

use serde::Deserialize;

/// Avoidance parameters of one character (a world file's `profiles` entry; the defaults when
/// absent).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields, default, rename_all = "camelCase")]
pub struct Profile {
    /// Weight of the change of velocity from the previous choice (effort).
    pub alpha: f32,
    /// Weight of the change of speed from the previous choice (effort).
    pub beta: f32,
    /// Weight of the deviation from the desired velocity (angle, and speed below it).
    pub gamma: f32,
    /// Weight of the collision risk (how soon the first contact comes).
    pub delta: f32,
    /// Weight of a conversing group's space (below `delta`: real bodies win).
    pub eta: f32,
    /// Contacts sooner than this (s) are imminent: the widest ranges.
    pub tc_min: f32,
    /// Contacts sooner than this (s) give the middle ranges.
    pub tc_mid: f32,
    /// Contacts later than this (s) are ignored.
    pub tc_max: f32,
    /// Half the heading span (degrees) considered for contacts between `tc_min` and `tc_mid`.
    pub delta_mid: f32,
    /// Half the heading span (degrees) for imminent contacts (the thesis: 52°, a 104° span).
    pub delta_max: f32,
    /// Radii are widened by this factor for the contacts (personal space over body space).
    pub incr: f32,
    /// Random jitter of each sample, as a fraction of the sample spacing.
    pub distortion: f32,
    /// The field of view (degrees) in which others are noticed (those within 1 m always are).
    pub field_of_view: f32,
    /// Extra cost of turning to the other side from the one chosen while a contact lasts.
    pub keep_side: f32,
    /// Whether it avoids only those it has seen or remembers (synthetic vision: turned on
    /// for the world when a profile asks for it); off by default: it knows where everyone is.
    pub only_seen: bool,
}

impl Default for Profile {
    fn default() -> Self {
        Profile {
            alpha: 0.3,
            beta: 0.2,
            gamma: 0.5,
            delta: 1.0,
            eta: 0.8,
            tc_min: 1.0,
            tc_mid: 3.0,
            tc_max: 8.0,
            delta_mid: 25.0,
            delta_max: 52.0,
            incr: 1.5,
            distortion: 0.1,
            field_of_view: 200.0,
            keep_side: 0.3,
            only_seen: false,
        }
    }
}

impl Profile {
    /// Checks every value: finite, weights ≥ 0, 0 < tcMin ≤ tcMid ≤ tcMax ≤ 30 s, angles in
    /// (0, 90], 1 ≤ incr ≤ 4, distortion in [0, 0.5], field of view in (0, 360]. The error names
    /// the field.
    pub fn check(&self) -> Result<(), String> {
        let fields = [
            ("alpha", self.alpha, 0.0, 100.0),
            ("beta", self.beta, 0.0, 100.0),
            ("gamma", self.gamma, 0.0, 100.0),
            ("delta", self.delta, 0.0, 100.0),
            ("eta", self.eta, 0.0, 100.0),
            ("keepSide", self.keep_side, 0.0, 100.0),
            ("tcMin", self.tc_min, 0.01, 30.0),
            ("tcMid", self.tc_mid, 0.01, 30.0),
            ("tcMax", self.tc_max, 0.01, 30.0),
            ("deltaMid", self.delta_mid, 0.1, 90.0),
            ("deltaMax", self.delta_max, 0.1, 90.0),
            ("incr", self.incr, 1.0, 4.0),
            ("distortion", self.distortion, 0.0, 0.5),
            ("fieldOfView", self.field_of_view, 1.0, 360.0),
        ];
        for (name, v, lo, hi) in fields {
            if !(v.is_finite() && (lo..=hi).contains(&v)) {
                return Err(format!(
                    "'{name}' is {v}: it must be a number from {lo} to {hi}"
                ));
            }
        }
        if !(self.tc_min <= self.tc_mid && self.tc_mid <= self.tc_max) {
            return Err("the times must keep tcMin ≤ tcMid ≤ tcMax".into());
        }
        if self.delta_mid > self.delta_max {
            return Err("'deltaMid' must not exceed 'deltaMax'".into());
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid_and_bad_values_are_named() {
        assert_eq!(Profile::default().check(), Ok(()));
        let p: Profile = serde_json::from_str(r#"{"incr": 2.0, "tcMax": 6}"#).unwrap();
        assert_eq!((p.incr, p.tc_max, p.alpha), (2.0, 6.0, 0.3));
        let bad = Profile {
            alpha: -1.0,
            ..Profile::default()
        };
        assert!(bad.check().unwrap_err().contains("alpha"));
        let bad = Profile {
            tc_min: f32::NAN,
            ..Profile::default()
        };
        assert!(bad.check().unwrap_err().contains("tcMin"));
        let bad = Profile {
            tc_min: 5.0,
            ..Profile::default()
        };
        assert!(bad.check().unwrap_err().contains("tcMid"));
        assert!(serde_json::from_str::<Profile>(r#"{"speed": 1}"#).is_err());
    }
}
