//! Named numeric parameters of units, and changes of a parameter over time.

use super::{EngineError, UnitKey};
use crate::language::bml::TrajectoryType;

/// Named numeric parameters of a unit, in a fixed order: `(name, value)`.
pub type Params = Vec<(String, f64)>;

/// `defaults` with the `<parameter>`s a behaviour gives applied: an unknown name or a value that is
/// not a finite number is refused, naming `owner` and the parameters it has.
pub fn named_params(
    owner: &str,
    defaults: impl IntoIterator<Item = (impl Into<String>, f64)>,
    given: &[crate::language::bml::Param],
) -> Result<Params, String> {
    let mut params: Params = defaults.into_iter().map(|(n, v)| (n.into(), v)).collect();
    for p in given {
        let Some(slot) = params.iter_mut().find(|x| x.0 == p.name) else {
            let known: Vec<&str> = params.iter().map(|x| x.0.as_str()).collect();
            return Err(format!(
                "{owner} has no parameter '{}' (it has {known:?})",
                p.name
            ));
        };
        slot.1 = p
            .value
            .trim()
            .parse::<f64>()
            .ok()
            .filter(|v| v.is_finite())
            .ok_or_else(|| format!("parameter '{}' = '{}' is not a number", p.name, p.value))?;
    }
    Ok(params)
}

/// [`Parameters::set_parameter`](super::Parameters::set_parameter) for a unit `key` whose parameters are `params` (of `owner`), if it
/// is running: a finite value for a name it has.
pub fn set_named_param(
    key: &UnitKey,
    owner: &str,
    params: Option<&mut Params>,
    name: &str,
    value: f64,
) -> Result<Option<Vec<f64>>, EngineError> {
    let params = params.ok_or_else(|| EngineError(format!("{key} is not running")))?;
    let slot = params
        .iter_mut()
        .find(|p| p.0 == name)
        .ok_or_else(|| EngineError(format!("{key}: {owner} has no parameter '{name}'")))?;
    if !value.is_finite() {
        return Err(EngineError(format!(
            "{key}: {name} = {value} is not finite"
        )));
    }
    slot.1 = value;
    Ok(None)
}

/// The value of parameter `name` among `params`.
pub fn named_param(params: &[(String, f64)], name: &str) -> Option<f64> {
    params.iter().find(|p| p.0 == name).map(|p| p.1)
}

/// A change of a parameter of a running behaviour over time (BMLA `parametervaluechange`).
#[derive(Debug, Clone, PartialEq)]
pub struct ParameterChange {
    /// The behaviour whose parameter changes.
    pub target: UnitKey,
    /// Parameter name, e.g. `volume`.
    pub param: String,
    /// Start value; `None` reads the target's value when the change starts.
    pub initial: Option<f64>,
    /// Value reached at `end` and held afterwards.
    pub target_value: f64,
    /// Linear or instant.
    pub kind: TrajectoryType,
    /// Global time the change starts.
    pub start: f64,
    /// Global time the target value is reached.
    pub end: f64,
    /// The behaviour that asked for the change (for warnings).
    pub by: UnitKey,
}

impl ParameterChange {
    /// The value at global time `t` starting from `from`: linear or instant, held after `end`.
    pub fn value_at(&self, from: f64, t: f64) -> f64 {
        match self.kind {
            TrajectoryType::Instant => self.target_value,
            TrajectoryType::Linear => {
                let span = self.end - self.start;
                let alpha = if span > 0.0 {
                    ((t - self.start) / span).clamp(0.0, 1.0)
                } else {
                    1.0
                };
                from + alpha * (self.target_value - from)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::language::bml::TrajectoryType;

    #[test]
    fn named_parameters_take_given_values_and_refuse_unknown_names_and_non_numbers() {
        let given = |n: &str, v: &str| crate::language::bml::Param {
            name: n.into(),
            value: v.into(),
        };
        let defaults = [("a", 1.0), ("b", 2.0)];
        let p = named_params("unit 'u'", defaults, &[given("b", " 5 ")]).unwrap();
        assert_eq!(p, [("a".to_string(), 1.0), ("b".to_string(), 5.0)]);
        let e = named_params("unit 'u'", defaults, &[given("c", "1")]).unwrap_err();
        assert_eq!(e, r#"unit 'u' has no parameter 'c' (it has ["a", "b"])"#);
        let e = named_params("unit 'u'", defaults, &[given("a", "inf")]).unwrap_err();
        assert_eq!(e, "parameter 'a' = 'inf' is not a number");
        let key = UnitKey::new("b", "u");
        let mut p = p;
        assert_eq!(set_named_param(&key, "u", Some(&mut p), "a", 7.0), Ok(None));
        assert_eq!(named_param(&p, "a"), Some(7.0));
        let err = |r: Result<Option<Vec<f64>>, EngineError>| r.unwrap_err().0;
        assert_eq!(
            err(set_named_param(&key, "u", None, "a", 1.0)),
            "b:u is not running"
        );
        assert_eq!(
            err(set_named_param(&key, "u", Some(&mut p), "z", 1.0)),
            "b:u: u has no parameter 'z'"
        );
        assert_eq!(
            err(set_named_param(&key, "u", Some(&mut p), "a", f64::NAN)),
            "b:u: a = NaN is not finite"
        );
        assert_eq!(
            named_param(&p, "a"),
            Some(7.0),
            "refused values change nothing"
        );
    }

    #[test]
    fn parameter_trajectories_follow_s63_to_s65() {
        let mut c = ParameterChange {
            target: UnitKey::new("b", "s"),
            param: "volume".into(),
            initial: Some(0.0),
            target_value: 100.0,
            kind: TrajectoryType::Linear,
            start: 1.0,
            end: 3.0,
            by: UnitKey::new("b", "p"),
        };
        assert_eq!(c.value_at(0.0, 1.0), 0.0);
        assert_eq!(c.value_at(0.0, 2.5), 75.0);
        assert_eq!(c.value_at(0.0, 9.0), 100.0); // held after the end
        c.kind = TrajectoryType::Instant;
        assert_eq!(c.value_at(0.0, 1.0), 100.0);
    }
}
