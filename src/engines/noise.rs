//! The noise engine: BMLT `noise` as Perlin noise on one joint, added on top of what the other
//! engines set (an additive layer), e.g. a slight idle sway of the head:
//!
//! ```xml
//! <bmlt:noise id="n1" type="perlin" joint="skullbase" start="0" end="10">
//!   <bmlt:parameter name="basefreqx" value="0.5"/>
//!   <bmlt:parameter name="baseamplitudex" value="3"/>
//! </bmlt:noise>
//! ```
//!
//! Each axis (x pitch, y yaw, z roll, in the joint's frame) turns by
//! `baseamplitude · Σₖ persistenceᵏ · perlin(basefreq · 2ᵏ · (t − start))` degrees over `octaves`
//! octaves, fading in and out over `fade` seconds (minimum jerk) so that the joint never jumps.
//! Parameters (defaults): `basefreqx/y/z` (1 Hz), `baseamplitudex/y/z` (2°, 2°, 0°),
//! `persistence` (0.5), `octaves` (2), `fade` (0.3 s); they can change while it runs. The only
//! `type` is `perlin`. Noise has no natural end: without a constrained end it runs until
//! its block is interrupted or replaced.

use glam::{EulerRot, Quat};

use crate::character::body::{Pose, Skeleton};
use crate::engines::interface::{
    named_param, named_params, Engine, EngineError, Params, Steering, Unit, Units,
};
use crate::engines::motion::min_jerk;
use crate::engines::procedural::perlin;
use crate::language::bml::{Behaviour, BehaviourKind};
use crate::world::World;

/// Parameter names and defaults.
const PARAMS: &[(&str, f64)] = &[
    ("basefreqx", 1.0),
    ("basefreqy", 1.0),
    ("basefreqz", 1.0),
    ("baseamplitudex", 2.0),
    ("baseamplitudey", 2.0),
    ("baseamplitudez", 0.0),
    ("persistence", 0.5),
    ("octaves", 2.0),
    ("fade", 0.3),
];

#[derive(Debug, Clone)]
struct NoiseUnit {
    joint: String,
    /// [`PARAMS`] with the behaviour's values, in that order.
    params: Params,
}

impl NoiseUnit {
    fn value(&self, name: &str) -> f64 {
        named_param(&self.params, name).unwrap_or(0.0)
    }

    /// The rotation (degrees about x, y, z) `dt` seconds after the start.
    fn angles(&self, dt: f64) -> [f64; 3] {
        let octaves = self.value("octaves").clamp(1.0, 8.0) as u32;
        let persistence = self.value("persistence");
        let mut out = [0.0; 3];
        // PARAMS: three frequencies, then three amplitudes
        for (axis, out) in out.iter_mut().enumerate() {
            let (f, a) = (self.params[axis].1, self.params[axis + 3].1);
            let mut sum = 0.0;
            for k in 0..octaves {
                let scale = 2f64.powi(k as i32);
                sum += persistence.powi(k as i32)
                    * perlin(f * scale * dt, (axis * 8) as f64 + k as f64);
            }
            *out = a * sum;
        }
        out
    }
}

/// The noise engine (see the module documentation).
#[derive(Debug, Default)]
pub struct NoiseEngine {
    units: Units<NoiseUnit>,
}

impl Engine for NoiseEngine {
    crate::units_persistent!("noise", Noise);

    fn add(&mut self, unit: Unit<'_>) -> Result<(), EngineError> {
        let BehaviourKind::Noise(n) = &unit.behaviour.kind else {
            return Err(EngineError("the noise engine realizes bmlt:noise".into()));
        };
        let fail = |why: String| EngineError(format!("{}: {why}", unit.key));
        if !n.kind.eq_ignore_ascii_case("perlin") {
            return Err(fail(format!(
                "noise type '{}' is not supported (perlin)",
                n.kind
            )));
        }
        let params = named_params("noise", PARAMS.iter().copied(), &n.params).map_err(fail)?;
        let joint = n.joint.clone();
        self.units.add(unit, NoiseUnit { joint, params });
        Ok(())
    }

    fn as_motion(&mut self) -> Option<&mut dyn crate::engines::interface::Motion> {
        Some(self)
    }

    fn as_parameters(&mut self) -> Option<&mut dyn crate::engines::interface::Parameters> {
        Some(self)
    }
}

impl crate::engines::interface::Motion for NoiseEngine {
    fn steers(&self, behaviour: &Behaviour, skeleton: &Skeleton) -> Option<Steering> {
        let BehaviourKind::Noise(n) = &behaviour.kind else {
            return None;
        };
        Some(Steering::kinematic(skeleton, [n.joint.as_str()], true))
    }

    fn animate(&mut self, now: f64, skeleton: &Skeleton, _world: &World, pose: &mut Pose) {
        for (syncs, u) in self.units.all() {
            let (Some(start), Some(end)) = (syncs.first().map(|s| s.1), syncs.last().map(|s| s.1))
            else {
                continue;
            };
            if now < start || now > end {
                continue;
            }
            let Some(j) = skeleton.joint(&u.joint) else {
                continue;
            };
            let fade = u.value("fade").max(0.0);
            let w = if fade > 0.0 {
                min_jerk((now - start) / fade).min(min_jerk((end - now) / fade))
            } else {
                1.0
            };
            let [x, y, z] = u.angles(now - start);
            let q = Quat::from_euler(
                EulerRot::XYZ,
                (w * x).to_radians() as f32,
                (w * y).to_radians() as f32,
                (w * z).to_radians() as f32,
            );
            pose.rotate(j, q);
        }
    }
}

crate::units_named_params!(NoiseEngine, "noise");
