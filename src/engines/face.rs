//! The face engine: `face` (by lexeme, in the attribute or the `<lexeme>` child form, or by AU),
//! `faceLexeme`, `faceFacs` (`au`, `side`), `faceShift` and BMLT `facemorph`, as FACS action
//! units and ARKit blendshapes of the character's face (`face::model`). An expression's weight
//! follows its envelope — easing in from start to attackPeak, holding to relax, easing out to
//! end — times its `amount` (`intensity` for a facemorph), which `parametervaluechange` can
//! change while it runs. A faceShift changes the rest expression for good: from start to end
//! the face moves from the old rest expression to the new one, and stays there. Expressions
//! combine with each other and the rest expression by maximum per AU, through a fading buffer
//! (`face::mixer`). Lexemes, AUs and blendshapes the face model lacks play their timing only,
//! with a warning that says so.

use crate::character::face::mixer::{ease, envelope, Fader};
use crate::character::face::model::{morph_index, ARKIT};
use crate::character::face::{Face, FaceModel};
use crate::engines::interface::{Engine, EngineError, Unit, UnitKey, Units};
use crate::language::bml::{Behaviour, BehaviourKind, Side};
use crate::planning::timing::{DefaultTimingModels, SyncName, TimingModel, TimingModels};

/// Amount when a behaviour gives none.
pub const DEFAULT_AMOUNT: f64 = 1.0;

/// What a face unit moves: weights of the mix vector (AU slots, then the 52 blendshapes).
#[derive(Debug, Clone)]
struct FaceUnit {
    targets: Vec<(usize, f32)>,
    amount: f64,
    /// A faceShift: moves the rest expression instead of coming and going.
    shift: bool,
    /// A faceShift that has begun moving the rest expression.
    begun: bool,
}

/// The rest expression, on its way from one faceShift's expression to the next one's.
#[derive(Debug, Clone, Default)]
struct Rest {
    from: Vec<f32>,
    to: Vec<f32>,
    start: f64,
    end: f64,
}

impl Rest {
    fn at(&self, t: f64, out: &mut [f32]) {
        let s = if self.end > self.start {
            ease((t - self.start) / (self.end - self.start)) as f32
        } else {
            f32::from(t >= self.start)
        };
        for (k, o) in out.iter_mut().enumerate() {
            let (a, b) = (self.from.get(k).copied(), self.to.get(k).copied());
            *o = a.unwrap_or(0.0) + (b.unwrap_or(0.0) - a.unwrap_or(0.0)) * s;
        }
    }
}

fn sync(syncs: &[(SyncName, f64)], name: &str) -> Option<f64> {
    syncs.iter().find(|s| s.0 == name).map(|s| s.1)
}

/// The face engine (see the module documentation).
#[derive(Debug)]
pub struct FaceEngine {
    models: DefaultTimingModels,
    model: &'static FaceModel,
    units: Units<FaceUnit>,
    rest: Rest,
    fader: Fader,
    /// The last time the face was shown.
    now: f64,
    /// Scratch space for the mix (AU slots, then blendshapes).
    mix: Vec<f32>,
}

impl Default for FaceEngine {
    fn default() -> Self {
        FaceEngine {
            models: DefaultTimingModels::default(),
            model: FaceModel::default_model(),
            units: Units::new(),
            rest: Rest::default(),
            fader: Fader::default(),
            now: f64::NEG_INFINITY,
            mix: Vec::new(),
        }
    }
}

/// What is wrong with a face behaviour's target (it then plays its timing only).
type Unbound = String;

/// A face behaviour's reading: the weights it moves at amount 1 (or why it moves none), its
/// amount, and whether it is a faceShift.
type Look = (Result<Vec<(usize, f32)>, Unbound>, f64, bool);

impl FaceEngine {
    fn slots(&self) -> usize {
        2 * self.model.aus.len()
    }

    /// The weights `b` moves at amount 1, its amount, and whether it is a faceShift; `None`
    /// for other kinds.
    fn look(&self, b: &Behaviour) -> Option<Look> {
        let amount = |a: Option<f64>| a.unwrap_or(DEFAULT_AMOUNT);
        Some(match &b.kind {
            BehaviourKind::Face(f) => match (&f.lexeme, f.au) {
                (Some(l), _) => (self.lexeme(l), amount(f.amount), false),
                (None, Some(au)) => (self.au(au, f.side), amount(f.amount), false),
                (None, None) => (
                    Err("it names neither a lexeme nor an au".into()),
                    0.0,
                    false,
                ),
            },
            BehaviourKind::FaceLexeme(f) => (self.lexeme(&f.lexeme), amount(f.amount), false),
            BehaviourKind::FaceShift(f) => (self.lexeme(&f.lexeme), amount(f.amount), true),
            BehaviourKind::FaceFacs(f) => (self.au(f.au, f.side), amount(f.amount), false),
            BehaviourKind::FaceMorph(m) => {
                let slot = (morph_index(&m.target_name))
                    .map(|i| vec![(self.slots() + i, 1.0)])
                    .ok_or_else(|| {
                        format!(
                            "'{}' is not one of the 52 ARKit blendshapes (browInnerUp, jawOpen, mouthSmileLeft, …)",
                            m.target_name
                        )
                    });
                (slot, m.intensity.unwrap_or(1.0), false)
            }
            _ => return None,
        })
    }

    fn lexeme(&self, name: &str) -> Result<Vec<(usize, f32)>, Unbound> {
        self.model.lexeme(name).map(<[_]>::to_vec).ok_or_else(|| {
            let bound: Vec<&str> = self.model.lexemes().collect();
            format!(
                "the face model has no lexeme '{name}' (it has {})",
                bound.join(", ")
            )
        })
    }

    fn au(&self, au: u32, side: Option<Side>) -> Result<Vec<(usize, f32)>, Unbound> {
        let slots = self
            .model
            .slots(au, side.unwrap_or(Side::Both))
            .ok_or_else(|| {
                let known: Vec<String> = self
                    .model
                    .aus
                    .iter()
                    .map(|a| a.number.to_string())
                    .collect();
                format!(
                    "the face model has no AU {au} (it has AUs {})",
                    known.join(", ")
                )
            })?;
        Ok(slots.into_iter().map(|s| (s, 1.0)).collect())
    }

    /// Starts moving the rest expression for every faceShift that has begun by `now`.
    fn begin_shifts(&mut self, now: f64) {
        let n = self.slots() + ARKIT.len();
        for (syncs, u) in self.units.started_mut(now) {
            let (Some(start), Some(end)) = (sync(syncs, "start"), sync(syncs, "end")) else {
                continue;
            };
            if !u.shift || u.begun || start > now {
                continue;
            }
            u.begun = true;
            let mut from = vec![0.0; n];
            self.rest.at(start, &mut from);
            let mut to = vec![0.0; n];
            for &(k, w) in &u.targets {
                to[k] = (w * u.amount as f32).clamp(0.0, 1.0);
            }
            self.rest = Rest {
                from,
                to,
                start,
                end,
            };
        }
    }
}

impl Engine for FaceEngine {
    crate::units_play!("face");

    fn name(&self) -> &'static str {
        "face"
    }

    fn timing(&self, behaviour: &Behaviour) -> Option<TimingModel> {
        let _ = self.look(behaviour)?;
        self.models.model(behaviour)
    }

    fn unanimated(&self, behaviour: &Behaviour) -> Option<String> {
        let (Err(why), _, _) = self.look(behaviour)? else {
            return None;
        };
        Some(format!(
            "{} '{}': {why}; it plays its timing only",
            behaviour.kind.element_name(),
            behaviour.id
        ))
    }

    fn add(&mut self, unit: Unit<'_>) -> Result<(), EngineError> {
        let (targets, amount, shift) = self
            .look(unit.behaviour)
            .ok_or_else(|| EngineError("the face engine realizes face behaviours only".into()))?;
        let data = FaceUnit {
            targets: targets.unwrap_or_default(),
            amount,
            shift,
            begun: false,
        };
        self.units.add(unit, data);
        Ok(())
    }

    fn remove(&mut self, key: &UnitKey) {
        // a unit taken away before its end leaves a jump in the mix
        let now = self.now;
        let early = (self.units.get_mut(key))
            .is_some_and(|(syncs, u)| !u.shift && sync(syncs, "end").is_some_and(|e| e > now));
        if early {
            self.fader.jump(self.now);
        }
        self.units.remove(key);
    }

    fn retime(&mut self, key: &UnitKey, syncs: &[(SyncName, f64)]) {
        let times: Vec<f64> = syncs.iter().map(|s| s.1).collect();
        if syncs.first().is_some_and(|s| s.1 < self.now) {
            self.fader.jump(self.now);
        }
        self.units.retime(key, &times);
    }

    fn interrupt(&mut self, key: &UnitKey, now: f64, syncs: &[(SyncName, f64)]) -> Vec<f64> {
        let times = crate::engines::interface::relax_now(now, syncs);
        self.fader.jump(now);
        self.units.retime(key, &times);
        times
    }

    fn len(&self) -> usize {
        self.units.len()
    }

    fn as_expression(&mut self) -> Option<&mut dyn crate::engines::interface::Expression> {
        Some(self)
    }

    fn as_parameters(&mut self) -> Option<&mut dyn crate::engines::interface::Parameters> {
        Some(self)
    }
}

impl crate::engines::interface::Expression for FaceEngine {
    fn express(&mut self, now: f64, face: &mut Face) {
        self.begin_shifts(now);
        let slots = self.slots();
        let mut mix = std::mem::take(&mut self.mix);
        mix.resize(slots + ARKIT.len(), 0.0);
        self.rest.at(now, &mut mix);
        for (syncs, u) in self.units.started(now) {
            let pegs = (
                sync(syncs, "start"),
                sync(syncs, "attackPeak"),
                sync(syncs, "relax"),
                sync(syncs, "end"),
            );
            let (Some(start), Some(peak), Some(relax), Some(end), false) =
                (pegs.0, pegs.1, pegs.2, pegs.3, u.shift)
            else {
                continue;
            };
            let w = (envelope(now, start, peak, relax, end) * u.amount) as f32;
            for &(k, weight) in &u.targets {
                mix[k] = mix[k].max((w * weight).clamp(0.0, 1.0));
            }
        }
        self.fader.show(now, &mut mix);
        for (k, &w) in mix.iter().enumerate() {
            if k < slots {
                face.raise(k, w);
            } else {
                face.raise_morph(k - slots, w);
            }
        }
        self.mix = mix;
        self.now = now;
    }
}

impl crate::engines::interface::Parameters for FaceEngine {
    fn parameter(&self, key: &UnitKey, name: &str) -> Option<f64> {
        let u = self.units.get(key)?;
        matches!(name, "amount" | "intensity").then_some(u.amount)
    }

    fn set_parameter(
        &mut self,
        key: &UnitKey,
        name: &str,
        value: f64,
        now: f64,
    ) -> Result<Option<Vec<f64>>, EngineError> {
        if !matches!(name, "amount" | "intensity") || !value.is_finite() {
            return Err(EngineError(format!(
                "a face behaviour's amount (or a facemorph's intensity) can change, to a number; not {name}={value}"
            )));
        }
        let (_, u) = (self.units.get_mut(key))
            .ok_or_else(|| EngineError(format!("{key} is not running")))?;
        u.amount = value.clamp(0.0, 1.0);
        self.fader.jump(now);
        Ok(None)
    }
}
