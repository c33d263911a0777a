//! Behaviours and constraints prepared for a strategy: each behaviour with its timing model, and
//! each normalised constraint resolved to sync keys of those behaviours or to known times.

use smallvec::SmallVec;

use super::strategy::{Dropped, ExternalTimes, ScheduleError, ScheduledBehaviour};
use crate::language::bml::{Anchor, Behaviour, Block, Constraint, Relation, Source, SyncPoint};
use crate::language::feedback::KnownWarning;
use crate::planning::timing::{Flexibility, TimingModel, TimingModels};

/// A behaviour being scheduled.
pub(crate) struct Item<'b> {
    pub(crate) beh: &'b Behaviour,
    pub(crate) model: TimingModel,
    /// Number of keys that get times (a persistent end is left out).
    pub(crate) len: usize,
}

/// One side of a constraint, resolved.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Term {
    /// Key `k` of item `i`.
    Key(usize, usize),
    /// Block start (0) plus a known time.
    Fixed(f64),
}

/// A constraint over resolved terms: `left REL right + offset`.
pub(crate) struct Link {
    pub(crate) relation: Relation,
    pub(crate) left: Term,
    pub(crate) right: Term,
    pub(crate) offset: f64,
    /// Index of the constraint (in `extract`'s list) this link comes from.
    pub(crate) constraint: usize,
}

/// The behaviours of `block` that some engine models, in canonical order (by id); the others are
/// reported as dropped. A persistent behaviour's `end` is left out (infinite) unless a constraint
/// names it.
pub(crate) fn items<'b>(
    block: &'b Block,
    models: &dyn TimingModels,
    constraints: &[Constraint],
    dropped: &mut Vec<Dropped>,
) -> Vec<Item<'b>> {
    // positions of the behaviours, sorted by id
    let mut order: Vec<usize> = (0..block.behaviours.len()).collect();
    order.sort_by(|&a, &b| block.behaviours[a].id.cmp(&block.behaviours[b].id));
    let mut items = Vec::with_capacity(order.len());
    for beh in order.iter().map(|&i| &block.behaviours[i]) {
        let model = models.model(beh).map(|m| {
            let valid = m.check();
            (m, valid)
        });
        match model {
            Some((_, Err(why))) => dropped.push(self::dropped(
                (block, constraints),
                &beh.id,
                KnownWarning::InvalidTiming,
                format!(
                    "the engine's timing model for '{}' is invalid: {why}",
                    beh.id
                ),
                false,
            )),
            Some((model, Ok(()))) => {
                // a persistent behaviour has no end unless a constraint names it
                let end_named = || {
                    constraints.iter().any(|c| {
                        [&c.left, &c.right].iter().any(|a| {
                            matches!(a, Anchor::Point(SyncPoint::Local { behaviour, sync }) if *behaviour == beh.id && sync == "end")
                        })
                    })
                };
                let len = if model.persistent && !end_named() {
                    model.keys.len() - 1
                } else {
                    model.keys.len()
                };
                items.push(Item { beh, model, len });
            }
            None => dropped.push(self::dropped(
                (block, constraints),
                &beh.id,
                KnownWarning::BehaviorTypeNotSupported,
                format!("no engine realizes <{}>", beh.kind.element_name()),
                false,
            )),
        }
    }
    items
}

/// Up to this many ids are searched one by one (see [`IdIndex`]).
const ID_INDEX_LINEAR: usize = 16;

/// Positions of ids in a list: a linear scan for the few behaviours of a typical block (no
/// allocation), a hash map for large ones.
#[derive(Default)]
pub(crate) struct IdIndex<'a> {
    /// The ids in list order, when there are at most [`ID_INDEX_LINEAR`].
    few: SmallVec<[(&'a str, usize); ID_INDEX_LINEAR]>,
    /// The position of each id (its first), when there are more.
    many: rustc_hash::FxHashMap<&'a str, usize>,
}

impl<'a> IdIndex<'a> {
    /// Indexes `ids` (replacing what was indexed). (Filled in place: a constructor that
    /// returned the index would copy its inline list.)
    pub(crate) fn fill(&mut self, ids: impl Iterator<Item = &'a str>) {
        self.few.clear();
        self.many.clear();
        self.few.extend(ids.enumerate().map(|(i, id)| (id, i)));
        if self.few.len() > ID_INDEX_LINEAR {
            for (id, i) in self.few.drain(..) {
                self.many.entry(id).or_insert(i);
            }
        }
    }

    /// The position of `id` (the first, if it occurs twice).
    pub(crate) fn get(&self, id: &str) -> Option<usize> {
        if self.many.is_empty() {
            self.few.iter().find(|(k, _)| *k == id).map(|(_, i)| *i)
        } else {
            self.many.get(id).copied()
        }
    }
}

/// A behaviour is required if it sits in `<required>` or a required constraint names it.
pub(crate) fn is_required(item: &Item, constraints: &[Constraint]) -> bool {
    item.beh.required
        || constraints.iter().any(|c| {
            c.required
                && [&c.left, &c.right]
                    .iter()
                    .any(|a| matches!(a, Anchor::Point(SyncPoint::Local { behaviour, .. }) if *behaviour == item.beh.id))
        })
}

/// Resolves constraints to terms. Returns the first behaviour that cannot be scheduled because a
/// constraint names a sync it lacks or an external time that is unknown.
pub(crate) fn resolve(
    block: &Block,
    items: &[Item],
    constraints: &[Constraint],
    external: &dyn ExternalTimes,
) -> (Vec<Link>, Option<(usize, KnownWarning, String)>) {
    let mut index = IdIndex::default();
    index.fill(items.iter().map(|it| it.beh.id.as_str()));
    let mut links = Vec::with_capacity(constraints.len());
    for (ci, c) in constraints.iter().enumerate() {
        let mut owner = None;
        let mut term = |a: &Anchor| -> Result<Option<Term>, (KnownWarning, String)> {
            let (behaviour, sync) = match a {
                Anchor::BlockStart => return Ok(Some(Term::Fixed(0.0))),
                Anchor::Point(SyncPoint::Local { behaviour, sync }) => (behaviour, sync),
                Anchor::Point(SyncPoint::External {
                    block: b,
                    behaviour,
                    sync,
                }) if *b == block.id => (behaviour, sync),
                Anchor::Point(p) => {
                    return external
                        .time(p)
                        .map(|t| Some(Term::Fixed(t)))
                        .ok_or_else(|| (KnownWarning::NoSuchTarget, external.why_unknown(p)));
                }
            };
            let Some(i) = index.get(behaviour) else {
                return Ok(None); // behaviour dropped or unsupported: the constraint lapses
            };
            owner.get_or_insert(i);
            match items[i].model.key(sync) {
                Some(k) if k < items[i].len => Ok(Some(Term::Key(i, k))),
                Some(_) => Err((
                    KnownWarning::CannotSatisfyConstraints,
                    format!("'{behaviour}:{sync}' is not scheduled (the behaviour persists)"),
                )),
                None => Err((
                    KnownWarning::CannotSatisfyConstraints,
                    format!(
                        "<{}> '{behaviour}' has no sync point '{sync}' in its timing model",
                        items[i].beh.kind.element_name()
                    ),
                )),
            }
        };
        let left = term(&c.left);
        let right = term(&c.right);
        match (left, right) {
            (Ok(Some(left)), Ok(Some(right))) => links.push(Link {
                relation: c.relation,
                left,
                right,
                offset: c.offset,
                constraint: ci,
            }),
            (Err((w, why)), _) | (_, Err((w, why))) => {
                let reason = format!("constraint '{c}': {why}");
                if let Some(i) = owner {
                    return (links, Some((i, w, reason)));
                }
            }
            _ => {}
        }
    }
    (links, None)
}

/// The result for one item: its keys' times (block-local, minus `shift`); keys without a time (a
/// persistent end) are infinite.
pub(crate) fn scheduled(item: Item, times: &[f64], shift: f64) -> ScheduledBehaviour {
    ScheduledBehaviour {
        id: item.beh.id.clone(),
        rigid: item.model.flexibility == Flexibility::Rigid,
        syncs: item
            .model
            .keys
            .into_iter()
            .enumerate()
            .map(|(k, key)| (key.name, times.get(k).map_or(f64::INFINITY, |v| v - shift)))
            .collect(),
    }
}

/// The behaviour a constraint side names within the block, if any.
fn named<'a>(a: &'a Anchor, block: &str) -> Option<&'a str> {
    match a {
        Anchor::Point(SyncPoint::Local { behaviour, .. }) => Some(behaviour),
        Anchor::Point(SyncPoint::External {
            block: b,
            behaviour,
            ..
        }) if *b == block => Some(behaviour),
        _ => None,
    }
}

/// Behaviour `id` of `block` leaves the schedule with `warning`. Every drop goes through here:
/// its reason is followed by the constraints of other behaviours that refer to `id` (their sync
/// attributes, and `<constraint>` elements between `id` and another behaviour) that the reason
/// does not name already, since dropping `id` lifts them and the behaviours they tied move
/// freely. `contradiction`: the reason is constraints that contradict each other.
pub(crate) fn dropped(
    (block, constraints): (&Block, &[Constraint]),
    id: &crate::language::bml::Id,
    warning: KnownWarning,
    reason: String,
    contradiction: bool,
) -> Dropped {
    Dropped {
        behaviour: id.clone(),
        warning,
        reason: with_lifted(reason, id, block, constraints),
        contradiction,
    }
}

fn with_lifted(reason: String, id: &str, block: &Block, constraints: &[Constraint]) -> String {
    let lifted: Vec<String> = constraints
        .iter()
        .filter(|c| {
            let (l, r) = (named(&c.left, &block.id), named(&c.right, &block.id));
            let other = |a: Option<&str>| a.is_some_and(|b| b != id);
            match c.source {
                Source::Attribute { .. } => other(l) && r == Some(id),
                Source::Element { .. } => {
                    (l == Some(id) && other(r)) || (r == Some(id) && other(l))
                }
            }
        })
        .map(|c| c.to_string())
        .filter(|c| !reason.contains(c.as_str()))
        .collect();
    if lifted.is_empty() {
        return reason;
    }
    format!(
        "{reason}; these constraints of other behaviours on '{id}' no longer hold: {}",
        lifted.join("; ")
    )
}

/// Resolves the constraints, dropping each behaviour that names a sync it lacks or an unknown
/// external time (the block fails if that behaviour is required).
pub(crate) fn resolve_all(
    block: &Block,
    items: &mut Vec<Item>,
    constraints: &[Constraint],
    external: &dyn ExternalTimes,
    dropped: &mut Vec<Dropped>,
) -> Result<Vec<Link>, ScheduleError> {
    loop {
        let (links, unusable) = resolve(block, items, constraints, external);
        let Some((i, warning, reason)) = unusable else {
            return Ok(links);
        };
        if is_required(&items[i], constraints) {
            return Err(ScheduleError {
                reason,
                contradiction: false,
            });
        }
        let id = &items[i].beh.id;
        let drop = self::dropped((block, constraints), id, warning, reason, false);
        dropped.push(drop);
        items.remove(i);
    }
}

#[cfg(test)]
mod tests {
    use super::IdIndex;

    /// Both ways of looking up (a scan for a few ids, a binary search for many) give the position
    /// of the first occurrence, and nothing for an id that is not there.
    #[test]
    fn id_index_finds_the_first_position_for_few_and_many_ids() {
        for n in [3usize, 16, 17, 40] {
            let mut ids: Vec<String> = (0..n).map(|i| format!("b{}", n - i)).collect();
            ids.push("b2".into()); // a second "b2", after the first
            let mut index = IdIndex::default();
            index.fill(ids.iter().map(String::as_str));
            for (i, id) in ids.iter().enumerate().take(n) {
                assert_eq!(index.get(id), Some(i), "{id} of {n}");
            }
            assert_eq!(index.get("b2"), Some(n - 2), "first b2 of {n}");
            assert_eq!(index.get("b0"), None);
            assert_eq!(index.get("c1"), None);
        }
    }
}
