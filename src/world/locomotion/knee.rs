//! The knees' least bend through the gait: the bend below which the pelvis is lowered over a
//! planted foot, following people's stance curve by the foot's phase (nearly straight at heel
//! strike and at mid-stance walking, with a loading flexion between; bent most at mid-stance
//! running), held as gait state that moves toward its curve at a person's pace, and blended in
//! from the standing bend by how much the body walks, so that setting off, stopping and
//! stepping on the spot bend the knees as a standing body does.

use super::gait::{smooth, Foot, Gait, OWN_PACE};

/// The least knee bend (rad) of a leg standing still or stepping slowly: a leg held at 98.5 %
/// of its reach, where a straight knee's turn changes the leg's length too little to follow a
/// foot's small moves.
pub const STANDING_KNEE: f32 = 0.347;
/// Fastest the least knee bend follows its curve (rad/s): people's fastest stance change, the
/// bend toward toe-off, is about 2.5 rad/s walking and 3 running; a faster change (a foot
/// landing, a body setting off) is spread over frames instead of lifting the pelvis at once.
pub const KNEE_RATE: f32 = 4.0;

/// The least bend (rad) of a planted knee at `x` of its stance (0 heel strike, 1 toe-off), as
/// people bend it (Kadaba 1990, Perry 1992, Schwartz 2008 by speed; Novacheck 1998 running):
/// walking, nearly straight at heel strike, a loading flexion larger with `speed` by a tenth of
/// the stance, nearly straight again at mid-stance, then bending toward the swing; running,
/// bent at contact, most bent at mid-stance, less at toe-off.
pub fn stance_knee(x: f32, running: bool, speed: f32) -> f32 {
    let keys: &[(f32, f32)] = if running {
        &[(0.0, 20.0), (0.45, 40.0), (1.0, 22.0)]
    } else {
        let loading = 6.0 + 10.0 * (speed / OWN_PACE).clamp(0.0, 1.2);
        &[(0.0, 0.0), (0.2, loading), (0.6, 0.0), (1.0, 4.0)]
    };
    let x = x.clamp(0.0, 1.0);
    let mut out = keys[0].1;
    for w in keys.windows(2) {
        let ((x0, y0), (x1, y1)) = (w[0], w[1]);
        if x >= x0 {
            out = y0 + (y1 - y0) * smooth((x - x0) / (x1 - x0));
        }
    }
    out.to_radians()
}

impl Gait {
    /// Moves each knee's least bend toward its curve: [`stance_knee`] at a planted foot's
    /// phase, its heel strike's for a swinging one; as much as the body walks (`amount`), the
    /// standing bend otherwise.
    pub(super) fn bend_the_knees(&mut self, dt: f32) {
        for k in 0..2 {
            let x = match self.feet[k] {
                Foot::Planted { .. } => self.foot_phase(k) / self.stance(),
                Foot::Swing { .. } => 0.0,
            };
            let curve = stance_knee(x, self.running, self.speed);
            let target = STANDING_KNEE + (curve - STANDING_KNEE) * self.amount;
            let most = KNEE_RATE * dt;
            self.knee[k] += (target - self.knee[k]).clamp(-most, most);
        }
    }
}
