//! The linear program for blocks where some behaviour must stretch (good_lp with microlp): first
//! the least deviation from the preferred timing, then, within it, the earliest times; built in a
//! canonical order so that the same block in any order gives the same answer, bounded in time, the
//! earliest feasible times its fallback.

use super::*;
use good_lp::solvers::WithTimeLimit;
use good_lp::{
    constraint, microlp, variable, Expression, ProblemVariables, Solution, SolverModel, Variable,
};

/// The longest the linear program may take before the earliest feasible times are used instead.
/// No block within the limits comes near it (the slowest seen take milliseconds); it is there so
/// that no input can hold the realizer, should the simplex stall.
pub(super) const LP_TIME_LIMIT_SECS: f64 = 2.0;

/// Whether the numbers of a block's system are within what the simplex handles: no time, offset
/// or duration further than [`MAX_SCHEDULED_TIME`] from zero. Beyond that a behaviour is dropped
/// after scheduling anyway, and such magnitudes next to ones of 1e-9 s can make the simplex stall.
pub(super) fn tame(items: &[Item], links: &[Link]) -> bool {
    let small = |v: f64| v.abs() <= MAX_SCHEDULED_TIME;
    let term = |t: Term| !matches!(t, Term::Fixed(v) if !small(v));
    let links_small = links
        .iter()
        .all(|l| small(l.offset) && term(l.left) && term(l.right));
    links_small
        && items
            .iter()
            .all(|it| it.model.keys.iter().all(|k| small(k.at)))
}

/// The two-stage linear program for blocks where some behaviour must stretch: first the least
/// deviation from the preferred timing, then, within it, the earliest times.
pub(super) fn optimise(items: &[Item], links: &[Link]) -> Vec<f64> {
    if !tame(items, links) {
        return earliest(items, links);
    }
    // the hard system is feasible, so both stages have solutions; fall back to the earliest
    // feasible times if the LP solver gives up numerically
    let Some((least_deviation, _)) = Program::new(items, links).solve(None) else {
        return earliest(items, links);
    };
    let bound = least_deviation + 1e-7 * (1.0 + least_deviation);
    match Program::new(items, links).solve(Some(bound)) {
        Some((_, times)) => times,
        None => earliest(items, links),
    }
}

/// The linear program of one block: a variable per key of every item, the hard constraints
/// (timing models, links) and the deviation from the preferred timing.
pub(super) struct Program {
    vars: ProblemVariables,
    /// `t[i][k]`: the time of key `k` of item `i`.
    t: Vec<Vec<Variable>>,
    constraints: Vec<good_lp::Constraint>,
    deviation: Expression,
}

impl Program {
    fn new(items: &[Item], links: &[Link]) -> Program {
        let mut vars = ProblemVariables::new();
        let t = (items.iter())
            .map(|it| (0..it.len).map(|_| vars.add(variable().min(0.0))).collect())
            .collect();
        let mut p = Program {
            vars,
            t,
            constraints: Vec::new(),
            deviation: Expression::from(0.0),
        };
        for (i, it) in items.iter().enumerate() {
            match it.model.flexibility {
                Flexibility::Rigid => p.rigid(i, it),
                Flexibility::Stretchable {
                    min_duration,
                    max_duration,
                } => p.stretchable(i, it, min_duration, max_duration),
            }
        }
        p.links(links);
        p
    }

    /// A rigid item keeps its keys' distances.
    fn rigid(&mut self, i: usize, it: &Item) {
        let (t, keys) = (&self.t[i], &it.model.keys);
        for k in 1..it.len {
            self.constraints
                .push(constraint!(t[k] - t[0] == keys[k].at));
        }
    }

    /// A stretchable item: keys in order, phases and duration within bounds; its deviation is
    /// how far its duration is from the preferred one (a uniform stretch `sigma`) plus, weighted,
    /// how unevenly its phases stretch.
    fn stretchable(&mut self, i: usize, it: &Item, min_duration: f64, max_duration: f64) {
        let (t, keys) = (self.t[i].clone(), &it.model.keys);
        for k in 1..it.len {
            self.constraints.push(constraint!(t[k] - t[k - 1] >= 0.0));
            if keys[k].max_phase.is_finite() {
                let max = keys[k].max_phase;
                self.constraints.push(constraint!(t[k] - t[k - 1] <= max));
            }
        }
        if it.len == keys.len() {
            let end = it.len - 1;
            self.constraints
                .push(constraint!(t[end] - t[0] >= min_duration));
            if max_duration.is_finite() {
                self.constraints
                    .push(constraint!(t[end] - t[0] <= max_duration));
            }
        }
        let weight = if it.model.persistent {
            PERSISTENT_WEIGHT
        } else {
            1.0
        };
        let sigma = self.vars.add(variable().min(0.0));
        let stretch = self.vars.add(variable().min(0.0));
        let duration = it.model.preferred_duration().max(EPSILON);
        self.constraints
            .push(constraint!(stretch >= (sigma - 1.0) * duration));
        self.constraints
            .push(constraint!(stretch >= (1.0 - sigma) * duration));
        self.deviation += weight * stretch;
        for k in 1..it.len {
            let p = keys[k].at - keys[k - 1].at;
            let d = self.vars.add(variable().min(0.0));
            self.constraints
                .push(constraint!(d >= t[k] - t[k - 1] - sigma * p));
            self.constraints
                .push(constraint!(d >= sigma * p - (t[k] - t[k - 1])));
            self.deviation += weight * NON_UNIFORM_WEIGHT * d;
        }
    }

    /// The links between keys and fixed times.
    fn links(&mut self, links: &[Link]) {
        for l in links {
            let term = |x: Term| -> Expression {
                match x {
                    Term::Key(i, k) => self.t[i][k].into(),
                    Term::Fixed(v) => Expression::from(v),
                }
            };
            let (a, b) = (term(l.left), term(l.right) + l.offset);
            self.constraints.push(match l.relation {
                Relation::At => constraint!(a == b),
                Relation::Before => constraint!(a <= b),
                Relation::After => constraint!(a >= b),
            });
        }
    }

    /// Without a bound: the least deviation. With one: the earliest times whose deviation stays
    /// within it. Returns the objective's value and every key's time (items in order).
    fn solve(mut self, deviation_bound: Option<f64>) -> Option<(f64, Vec<f64>)> {
        let objective: Expression = match deviation_bound {
            None => self.deviation.clone(),
            Some(bound) => {
                self.constraints
                    .push(constraint!(self.deviation.clone() <= bound));
                self.t.iter().flatten().map(|&v| Expression::from(v)).sum()
            }
        };
        let mut problem = (self.vars.minimise(objective.clone()))
            .using(microlp)
            .with_time_limit(LP_TIME_LIMIT_SECS);
        for c in self.constraints {
            problem = problem.with(c);
        }
        let solution = problem.solve().ok()?;
        let value = solution.eval(&objective);
        let times = self
            .t
            .iter()
            .flatten()
            .map(|&v| solution.value(v))
            .collect();
        Some((value, times))
    }
}

/// The least solution of the hard system (every key as early as possible).
pub(super) fn earliest(items: &[Item], links: &[Link]) -> Vec<f64> {
    let (s, base) = hard_system(items, links);
    let x = s.solve().unwrap_or_default();
    items
        .iter()
        .zip(&base)
        .flat_map(|(it, &b)| (b..b + it.len).map(|v| x.get(v).copied().unwrap_or(0.0)))
        .collect()
}
