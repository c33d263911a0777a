//! The control engine: `wait` (holds its block open), BMLA/BMLT `interrupt` and `activate` (act on
//! blocks when their `start` passes) and `parametervaluechange` (starts a parameter trajectory on
//! another behaviour). It moves nothing; its work is the actions it hands the runtime.

use std::collections::HashMap;

use crate::engines::interface::{Action, Engine, EngineError, ParameterChange, Unit, UnitKey};
use crate::language::bml::{Behaviour, BehaviourKind};
use crate::planning::timing::{DefaultTimingModels, TimingModel, TimingModels};

/// What a control unit does when it starts.
#[derive(Debug, Clone)]
enum Control {
    Wait,
    Interrupt {
        target: String,
        include: Vec<String>,
        exclude: Vec<String>,
    },
    Activate(String),
    Change {
        target: UnitKey,
        param: String,
        initial: Option<f64>,
        target_value: f64,
        kind: crate::language::bml::TrajectoryType,
        end: f64,
    },
}

/// The control engine (see the module documentation).
#[derive(Debug, Default)]
pub struct ControlEngine {
    models: DefaultTimingModels,
    units: HashMap<UnitKey, Control>,
}

impl Engine for ControlEngine {
    fn name(&self) -> &'static str {
        "control"
    }

    fn timing(&self, behaviour: &Behaviour) -> Option<TimingModel> {
        match behaviour.kind {
            BehaviourKind::Wait(_)
            | BehaviourKind::Interrupt(_)
            | BehaviourKind::Activate(_)
            | BehaviourKind::ParameterValueChange(_) => self.models.model(behaviour),
            _ => None,
        }
    }

    fn add(&mut self, unit: Unit<'_>) -> Result<(), EngineError> {
        let end = unit.syncs.last().map_or(0.0, |s| s.1);
        let control = match &unit.behaviour.kind {
            BehaviourKind::Wait(_) => Control::Wait,
            BehaviourKind::Interrupt(i) => Control::Interrupt {
                target: i.target.clone(),
                include: i.include.clone(),
                exclude: i.exclude.clone(),
            },
            BehaviourKind::Activate(a) => Control::Activate(a.target.clone()),
            BehaviourKind::ParameterValueChange(p) => Control::Change {
                target: UnitKey::new(
                    p.target_block.as_deref().unwrap_or(&unit.key.block),
                    &p.target_behaviour,
                ),
                param: p.param_id.clone(),
                initial: p.trajectory.initial_value,
                target_value: p.trajectory.target_value,
                kind: p.trajectory.kind,
                end,
            },
            other => {
                return Err(EngineError(format!(
                    "the control engine cannot realize <{}>",
                    other.element_name()
                )))
            }
        };
        self.units.insert(unit.key.clone(), control);
        Ok(())
    }

    fn remove(&mut self, key: &UnitKey) {
        self.units.remove(key);
    }

    fn len(&self) -> usize {
        self.units.len()
    }

    fn as_control(&mut self) -> Option<&mut dyn crate::engines::interface::Control> {
        Some(self)
    }
}

impl crate::engines::interface::Control for ControlEngine {
    fn sync_passed(&mut self, key: &UnitKey, sync: &str, time: f64, actions: &mut Vec<Action>) {
        if sync != "start" {
            return;
        }
        let Some(control) = self.units.get(key) else {
            return;
        };
        actions.push(match control.clone() {
            Control::Wait => return,
            Control::Interrupt {
                target,
                include,
                exclude,
            } => Action::Interrupt {
                by: key.clone(),
                target,
                include,
                exclude,
            },
            Control::Activate(target) => Action::Activate {
                by: key.clone(),
                target,
            },
            Control::Change {
                target,
                param,
                initial,
                target_value,
                kind,
                end,
            } => Action::ChangeParameter(ParameterChange {
                target,
                param,
                initial,
                target_value,
                kind,
                start: time,
                end,
                by: key.clone(),
            }),
        });
    }
}
