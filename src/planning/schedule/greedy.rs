//! `SortedGreedy`: the baseline strategy, Elckerlyc's sorted form of the SmartBody algorithm
//! (thesis §7.3.5).
//!
//! Behaviours are sorted into three groups:
//! 1. rigid behaviours with an absolute `at`;
//! 2. all others except the completely flexible ones. Here a rigid behaviour linked at two or more of
//!    its sync points to other behaviours goes first; the rest keep document order;
//! 3. the completely flexible ones (parametervaluechange).
//!
//! Each behaviour is then timed from the sync times already fixed by earlier ones:
//! - no known time: it starts at block start with its preferred timing;
//! - one known time: preferred timing aligned to it;
//! - several: linear stretch between them.
//!
//! A behaviour whose timing comes out invalid is dropped. Finally the block is shifted so that nothing
//! precedes its start (SmartBody's normalisation). `before`/`after` constraints are not supported
//!, and the result depends on behaviour order (thesis Ex. 28b and 29b fail). It is kept as the
//! reference the `Optimal` strategy is measured and tested against.

use super::diff::EPSILON;
use super::links::{self, is_required, items, resolve_all, scheduled, Item, Link, Term};
use super::strategy::{
    BlockSchedule, ExternalTimes, ScheduleError, ScheduledBehaviour, SchedulingStrategy,
};
use crate::language::bml::{extract, Behaviour, BehaviourKind, Block, Relation};
use crate::language::feedback::KnownWarning;
use crate::planning::timing::{Flexibility, TimingModel, TimingModels};

/// The sorted greedy baseline (see the module documentation).
#[derive(Debug, Clone, Copy, Default)]
pub struct SortedGreedy;

impl SchedulingStrategy for SortedGreedy {
    fn name(&self) -> &'static str {
        "sorted-greedy"
    }

    fn schedule(
        &self,
        block: &Block,
        models: &dyn TimingModels,
        external: &dyn ExternalTimes,
    ) -> Result<BlockSchedule, ScheduleError> {
        let constraints = extract(block);
        if let Some(c) = constraints.iter().find(|c| c.relation != Relation::At) {
            return Err(ScheduleError {
                reason: format!("'{c}': the sorted greedy strategy supports only at-constraints"),
                contradiction: false,
            });
        }
        let mut dropped = Vec::new();
        let mut items = items(block, models, &constraints, &mut dropped);
        let links = resolve_all(block, &mut items, &constraints, external, &mut dropped)?;
        let doc = |beh: &Behaviour| {
            block
                .behaviours
                .iter()
                .position(|b| std::ptr::eq(b, beh))
                .unwrap_or(usize::MAX)
        };
        let mut order: Vec<usize> = (0..items.len()).collect();
        order.sort_by_key(|&i| (group(&items, &links, i), doc(items[i].beh)));

        let mut times: Vec<Option<Vec<f64>>> = vec![None; items.len()];
        for &i in &order {
            let placed = known(&items, &links, &times, i)
                .and_then(|k| place(&items[i].model, items[i].len, &k));
            match placed {
                Some(t) => times[i] = Some(t),
                None if is_required(&items[i], &constraints) => {
                    return Err(ScheduleError {
                        reason: format!(
                            "required '{}' cannot be timed from the behaviours before it",
                            items[i].beh.id
                        ),
                        contradiction: true,
                    });
                }
                None => {
                    let id = &items[i].beh.id;
                    let reason = format!(
                        "'{id}' cannot be timed from the behaviours scheduled before it (sorted greedy)"
                    );
                    let warning = KnownWarning::CannotSatisfyConstraints;
                    dropped.push(links::dropped(
                        (block, &constraints),
                        id,
                        warning,
                        reason,
                        true,
                    ));
                }
            }
        }
        // shift so that nothing precedes the block start
        let earliest = times
            .iter()
            .flatten()
            .flatten()
            .copied()
            .fold(0.0_f64, f64::min);
        let mut behaviours: Vec<(usize, ScheduledBehaviour)> = items
            .into_iter()
            .zip(times)
            .filter_map(|(it, t)| {
                let t = t?;
                Some((doc(it.beh), scheduled(it, &t, earliest)))
            })
            .collect();
        behaviours.sort_by_key(|(d, _)| *d);
        Ok(BlockSchedule {
            behaviours: behaviours.into_iter().map(|(_, b)| b).collect(),
            dropped,
        })
    }
}

/// Group 1, 2 or 3; inside group 2, rigid behaviours linked at two or more sync points first
///, encoded as 2 versus 3 (and the flexible group as 4).
fn group(items: &[Item], links: &[Link], i: usize) -> u8 {
    let it = &items[i];
    if matches!(it.beh.kind, BehaviourKind::ParameterValueChange(_)) {
        return 4;
    }
    let rigid = it.model.flexibility == Flexibility::Rigid;
    let mine = |t: Term| matches!(t, Term::Key(j, _) if j == i);
    let absolute = links.iter().any(|l| {
        (mine(l.left) && matches!(l.right, Term::Fixed(_)))
            || (mine(l.right) && matches!(l.left, Term::Fixed(_)))
    });
    if rigid && absolute {
        return 1;
    }
    let mut linked_keys: Vec<usize> = Vec::new();
    for l in links {
        for (a, b) in [(l.left, l.right), (l.right, l.left)] {
            if let (Term::Key(j, k), Term::Key(other, _)) = (a, b) {
                if j == i && other != i && !linked_keys.contains(&k) {
                    linked_keys.push(k);
                }
            }
        }
    }
    if rigid && linked_keys.len() >= 2 {
        2
    } else {
        3
    }
}

/// Times of item `i`'s keys fixed by absolute constraints or by behaviours already timed; `None` if
/// two of them disagree.
fn known(
    items: &[Item],
    links: &[Link],
    times: &[Option<Vec<f64>>],
    i: usize,
) -> Option<Vec<(usize, f64)>> {
    let value = |t: Term| match t {
        Term::Fixed(v) => Some(v),
        Term::Key(j, k) => times[j].as_ref().map(|t| t[k]),
    };
    let mut known: Vec<(usize, f64)> = Vec::new();
    for l in links {
        // left = right + offset
        let found = match (l.left, l.right) {
            (Term::Key(j, k), other) if j == i && other != l.left => {
                value(other).map(|v| (k, v + l.offset))
            }
            (other, Term::Key(j, k)) if j == i => value(other).map(|v| (k, v - l.offset)),
            _ => None,
        };
        if let Some((k, v)) = found {
            if k >= items[i].len {
                continue;
            }
            match known.iter().find(|(kk, _)| *kk == k) {
                Some((_, w)) if (w - v).abs() > EPSILON => return None,
                Some(_) => {}
                None => known.push((k, v)),
            }
        }
    }
    known.sort_by_key(|k| k.0);
    Some(known)
}

/// The engine's "resolve unknown from known" step: all keys from the known ones.
fn place(model: &TimingModel, len: usize, known: &[(usize, f64)]) -> Option<Vec<f64>> {
    let p: Vec<f64> = model.keys[..len].iter().map(|k| k.at).collect();
    let t: Vec<f64> = match (known, model.flexibility) {
        ([], _) => p.clone(),
        ([(k, v), ..], Flexibility::Rigid) => {
            let start = v - p[*k];
            if known
                .iter()
                .any(|(k, v)| (start + p[*k] - v).abs() > EPSILON)
            {
                return None;
            }
            p.iter().map(|x| start + x).collect()
        }
        ([(k, v)], _) => p.iter().map(|x| v - p[*k] + x).collect(),
        (_, _) => {
            let (&(k0, t0), &(k1, t1)) = (known.first()?, known.last()?);
            let span = p[k1] - p[k0];
            if span <= 0.0 {
                return None;
            }
            let scale = (t1 - t0) / span;
            (0..len)
                .map(|k| {
                    if k <= k0 {
                        t0 - scale * (p[k0] - p[k])
                    } else if k >= k1 {
                        t1 + scale * (p[k] - p[k1])
                    } else {
                        let j = known.iter().rposition(|(kk, _)| *kk <= k).unwrap_or(0);
                        let ((ka, ta), (kb, tb)) = (known[j], known[j + 1]);
                        if p[kb] > p[ka] {
                            ta + (p[k] - p[ka]) / (p[kb] - p[ka]) * (tb - ta)
                        } else {
                            ta
                        }
                    }
                })
                .collect()
        }
    };
    let ordered = t.windows(2).all(|w| w[1] >= w[0] - EPSILON);
    let lasts = len < model.keys.len() || t[len - 1] > t[0];
    (ordered && lasts).then_some(t)
}
