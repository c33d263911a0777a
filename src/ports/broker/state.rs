//! A character's root state as realizers sharing one world publish it on
//! `PREFIX/world/CELL/ID`: JSON `{"time": s, "position": [x, y, z], "velocity": [x, y, z],
//! "facing": degrees}`; while a walker held back asks someone to make room, `"asks": ID`; and
//! once, on the topic of the cell a character has just left, `"moved": CELL` (the cell it is in
//! now: a realizer that does not listen to that one lets the character go) (world
//! frame, metres, y up; `facing` about +y from +z, as in the world file; `time` is the sender's
//! clock, for reading only: clocks of different realizers have different origins, so a
//! receiver ages a state from when it arrived). A state is moved on along its velocity for at
//! most [`EXTRAPOLATE`] seconds; older, the character stands where that left it, and one not
//! heard of for [`STALE`] seconds is taken out of the world (its realizer is gone, or it walked
//! out of the cells listened to).

use glam::Vec3;
use serde::{Deserialize, Serialize};

use crate::world::Placement;

/// The longest a state is moved on along its velocity (s).
pub const EXTRAPOLATE: f64 = 0.5;

/// How long a character of another realizer stays in the world after its last state (s).
pub const STALE: f64 = 3.0;

/// How often a realizer publishes its characters' states (s): 20 Hz.
pub const PUBLISH_PERIOD: f64 = 0.05;

/// How often a character at rest has its state published (s): one standing still where its
/// last state put it, asking nobody, is said again only this often, to show it is still
/// there (well within [`STALE`]); any change is published at once, on the next
/// [`PUBLISH_PERIOD`].
pub const REST_PERIOD: f64 = 1.0;

/// One character's root state.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RootState {
    /// The sender's clock (s).
    pub time: f64,
    /// Where its root stands (m).
    pub position: [f32; 3],
    /// How fast it moves (m/s).
    pub velocity: [f32; 3],
    /// Its heading (degrees about +y from +z).
    pub facing: f32,
    /// The character it asks to make room (a walker held back), if it asks anyone: the realizer
    /// that moves that one has it step aside as if a walker of its own asked.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub asks: Option<String>,
    /// On the topic of the cell the character has just left: the cell it is in now.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub moved: Option<String>,
}

impl RootState {
    /// The state of a character placed at `at` moving at `velocity`, at `time`.
    pub fn new(time: f64, at: Placement, velocity: Vec3) -> RootState {
        RootState {
            time,
            position: at.position.to_array(),
            velocity: velocity.to_array(),
            facing: at.facing.to_degrees(),
            asks: None,
            moved: None,
        }
    }

    /// Reads a payload; `Err` says why it is not a state.
    pub fn from_json(payload: &[u8]) -> Result<RootState, String> {
        let s: RootState = serde_json::from_slice(payload).map_err(|e| e.to_string())?;
        let finite = s.time.is_finite()
            && s.position.iter().chain(&s.velocity).all(|v| v.is_finite())
            && s.facing.is_finite();
        if !finite {
            return Err("a number is not finite".into());
        }
        Ok(s)
    }

    /// Whether this state, sent after `before`, tells a receiver nothing new: the character
    /// stood still at `before`'s place and facing (within 1 mm and 0.1°) and still does, and
    /// asks nobody.
    pub fn at_rest_as(&self, before: &RootState) -> bool {
        let still = |v: &[f32; 3]| v.iter().all(|c| c.abs() < 1e-3);
        let near = (self.position.iter().zip(&before.position)).all(|(a, b)| (a - b).abs() < 1e-3);
        still(&self.velocity)
            && still(&before.velocity)
            && near
            && (self.facing - before.facing).abs() < 0.1
            && self.asks.is_none()
            && before.asks.is_none()
            && self.moved.is_none()
    }

    /// The payload.
    pub fn to_json(&self) -> String {
        serde_json::to_string(self).expect("numbers are finite")
    }

    /// Where it stands `age` seconds after it was sent (moved on along its velocity for at
    /// most [`EXTRAPOLATE`] s).
    pub fn placement_after(&self, age: f64) -> Placement {
        let t = age.clamp(0.0, EXTRAPOLATE) as f32;
        Placement {
            position: Vec3::from(self.position) + Vec3::from(self.velocity) * t,
            facing: self.facing.to_radians(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_state_round_trips_and_is_moved_on_for_half_a_second_at_most() {
        let at = Placement::new(Vec3::new(1.0, 0.0, 2.0), 90.0);
        let s = RootState::new(3.5, at, Vec3::new(1.0, 0.0, 0.0));
        let back = RootState::from_json(s.to_json().as_bytes()).unwrap();
        assert_eq!(back, s);
        assert!((back.placement_after(0.2).position.x - 1.2).abs() < 1e-6);
        assert!((back.placement_after(9.0).position.x - 1.5).abs() < 1e-6);
        assert!((back.placement_after(0.0).facing - at.facing).abs() < 1e-6);
        assert!(RootState::from_json(br#"{"time": 1}"#).is_err());
        assert!(RootState::from_json(b"not json").is_err());
        let asking = RootState {
            asks: Some("s3".into()),
            ..s.clone()
        };
        assert!(asking.to_json().contains(r#""asks":"s3""#));
        assert_eq!(
            RootState::from_json(asking.to_json().as_bytes()).unwrap(),
            asking
        );
        assert!(!s.to_json().contains("asks"));
        let nan = br#"{"time": 0, "position": [0, 0, 0], "velocity": [0, 0, 0], "facing": 1e999}"#;
        assert!(RootState::from_json(nan).is_err());
    }

    #[test]
    fn only_a_character_standing_where_it_stood_is_at_rest() {
        let at = Placement::new(Vec3::new(1.0, 0.0, 2.0), 90.0);
        let still = RootState::new(1.0, at, Vec3::ZERO);
        let later = RootState {
            time: 1.5,
            ..still.clone()
        };
        assert!(later.at_rest_as(&still));
        let walking = RootState::new(1.0, at, Vec3::new(1.0, 0.0, 0.0));
        assert!(!later.at_rest_as(&walking), "it has just stopped");
        assert!(!walking.at_rest_as(&still), "it has set off");
        let stepped = Placement::new(Vec3::new(1.01, 0.0, 2.0), 90.0);
        assert!(!RootState::new(1.5, stepped, Vec3::ZERO).at_rest_as(&still));
        let turned = Placement::new(at.position, 91.0);
        assert!(!RootState::new(1.5, turned, Vec3::ZERO).at_rest_as(&still));
        let asking = RootState {
            asks: Some("s3".into()),
            ..later.clone()
        };
        assert!(!asking.at_rest_as(&still), "an ask is said at 20 Hz");
        let moved = RootState {
            moved: Some("0_1".into()),
            ..later
        };
        assert!(!moved.at_rest_as(&still));
    }
}
