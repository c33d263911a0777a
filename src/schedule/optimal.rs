//! The `Optimal` scheduling strategy for one block. Every constraint kind is honoured, behaviours
//! keep their preferred timing as far as the constraints allow, ungrounded clusters start as early
//! as possible, and the result does not depend on the order of behaviours in the block.
//!
//! 1. Feasibility: every sync key becomes a variable of a difference system (explicit constraints,
//!    sync order, duration bounds, phase limits, rigid internal timing, nothing before block
//!    start). A contradictory cycle names the constraints in conflict; a behaviour involved that
//!    is not required is dropped and the rest tried again. If only required behaviours are
//!    involved, the block fails.
//! 2. Fast path: with every behaviour at its preferred timing (one variable per behaviour), the least
//!    solution of the difference system, if there is one, has zero deviation and the earliest starts.
//!    No LP is needed.
//! 3. Second fast path: if the `at` constraints fix the distances between the constrained keys of
//!    every behaviour constrained at two or more keys, the deviation splits into one term per
//!    behaviour; each such behaviour takes its own best timing and everything else keeps its
//!    preferred timing. Taken only where that is provably the linear program's answer (each best
//!    timing unique, every bound kept); `LinearProgram` is the same strategy without fast paths,
//!    to check them against.
//! 4. Otherwise a linear program (good_lp + microlp) first minimises the total deviation from
//!    preferred timing, measured as stretch `|σ − 1| · duration` plus non-uniformity
//!    `2 · Σ |phase − σ · preferred phase|` (a persistent behaviour's at a thousandth: it has no
//!    length of its own to keep). It then minimises the sum of all sync times with the deviation
//!    kept at that minimum. The program is built in a canonical order (behaviours sorted by id), so the
//!    same block in any order gives the same program and the same answer.
//! 5. Whichever step answered, the keys between two constrained keys of a stretchable behaviour
//!    are spaced in proportion to their preferred timing (thesis §8.3.2), which the deviation
//!    leaves open.

use good_lp::solvers::WithTimeLimit;
use good_lp::{
    constraint, microlp, variable, Expression, ProblemVariables, Solution, SolverModel, Variable,
};

use super::diff::{DiffSystem, EPSILON};
use super::links::{self, is_required, items, resolve_all, scheduled, IdIndex, Item, Link, Term};
use super::offsets::Offsets;
use super::strategy::{
    BlockSchedule, Dropped, ExternalTimes, ScheduleError, SchedulingStrategy, MAX_SCHEDULED_TIME,
};
use crate::bml::{extract, Block, Constraint, Relation};
use crate::feedback::KnownWarning;
use crate::timing::{Flexibility, TimingModels, MIN_DURATION};

/// Cost of one second of non-uniform phase change relative to one second of uniform stretch: above
/// 1, so a behaviour that must change length stretches all its phases alike (as Elckerlyc's
/// linear stretch does) instead of putting the change into one phase.
pub const NON_UNIFORM_WEIGHT: f64 = 2.0;

/// Weight of a persistent behaviour's deviation (a physical controller, noise) against everyone
/// else's. Such a behaviour has no length of its own: its nominal second only places an end that
/// a constraint names without fixing it (`start="c:end"`). Counted in full, tying its end to a
/// gesture's (`end="g:end"`) made stretching the controller cost as much as squeezing the gesture,
/// and the tie went to the earlier times: the gesture squeezed into the controller's second.
pub const PERSISTENT_WEIGHT: f64 = 1e-3;

/// The optimal strategy (see the module documentation).
#[derive(Debug, Clone, Copy, Default)]
pub struct Optimal;

impl SchedulingStrategy for Optimal {
    fn name(&self) -> &'static str {
        "optimal"
    }

    fn schedule(
        &self,
        block: &Block,
        models: &dyn TimingModels,
        external: &dyn ExternalTimes,
    ) -> Result<BlockSchedule, ScheduleError> {
        schedule(block, models, external, true)
    }
}

/// [`Optimal`] without its fast paths: every block that needs any behaviour to stretch goes
/// through the linear program. The same answers, slower; a reference to check the fast paths by.
#[derive(Debug, Clone, Copy, Default)]
pub struct LinearProgram;

impl SchedulingStrategy for LinearProgram {
    fn name(&self) -> &'static str {
        "linear-program"
    }

    fn schedule(
        &self,
        block: &Block,
        models: &dyn TimingModels,
        external: &dyn ExternalTimes,
    ) -> Result<BlockSchedule, ScheduleError> {
        schedule(block, models, external, false)
    }
}

/// The optimal schedule of `block`; `fast` allows the fast paths.
fn schedule(
    block: &Block,
    models: &dyn TimingModels,
    external: &dyn ExternalTimes,
    fast: bool,
) -> Result<BlockSchedule, ScheduleError> {
    {
        let mut dropped = Vec::new();
        let constraints = extract(block);
        let mut items = items(block, models, &constraints, &mut dropped);
        loop {
            let links = resolve_all(block, &mut items, &constraints, external, &mut dropped)?;
            // a fast-path answer satisfies every hard constraint, so feasibility is only checked
            // (and conflicts only resolved) when neither fast path applies
            let shortcut = if fast {
                preferred(&items, &links).or_else(|| separable(&items, &links))
            } else {
                None
            };
            let times = match shortcut {
                Some(times) => times,
                None => match feasible(&items, &links, &constraints) {
                    Ok(()) => optimise(&items, &links),
                    Err(involved) => {
                        drop_one(block, &mut items, &involved, &constraints, &mut dropped)?;
                        continue;
                    }
                },
            };
            let mut times = times;
            spread_between_anchors(&items, &links, &mut times);
            // `times` holds each item's key times one item after the other; the results go into
            // a list of their own (collecting in place would shrink the items' allocation)
            let mut rest = times.as_slice();
            let mut behaviours = Vec::with_capacity(items.len());
            for it in items {
                let (t, after) = rest.split_at(it.len);
                rest = after;
                behaviours.push(scheduled(it, t, 0.0));
            }
            // document order (nothing to sort for one behaviour)
            if behaviours.len() > 1 {
                let mut pos = IdIndex::default();
                pos.fill(block.behaviours.iter().map(|b| b.id.as_str()));
                behaviours.sort_by_cached_key(|b| pos.get(&b.id).unwrap_or(usize::MAX));
            }
            return Ok(BlockSchedule {
                behaviours,
                dropped,
            });
        }
    }
}

/// Drops the non-required behaviour that brought the most conflicting constraints (a behaviour's
/// own sync is the left side of its attributes; ties by id), or fails the block if only required
/// behaviours are involved.
fn drop_one(
    block: &Block,
    items: &mut Vec<Item>,
    involved: &Involved,
    constraints: &[Constraint],
    dropped: &mut Vec<Dropped>,
) -> Result<(), ScheduleError> {
    let text = involved.texts.join("; ");
    let candidate = involved
        .items
        .iter()
        .copied()
        .filter(|&i| !is_required(&items[i], constraints))
        .max_by_key(|&i| (involved.owned(i), &items[i].beh.id));
    let Some(i) = candidate else {
        return Err(ScheduleError {
            reason: format!("required behaviours cannot satisfy: {text}"),
            contradiction: true,
        });
    };
    // constraints that would stretch a behaviour beyond its bounds make its timing invalid
    let warning = if involved.bounded.contains(&i) {
        KnownWarning::InvalidTiming
    } else {
        KnownWarning::CannotSatisfyConstraints
    };
    let id = &items[i].beh.id;
    let reason = format!("'{id}' dropped: these constraints contradict each other: {text}");
    dropped.push(links::dropped(
        (block, constraints),
        id,
        warning,
        reason,
        true,
    ));
    items.remove(i);
    Ok(())
}

/// The behaviours and constraint texts of a conflict.
struct Involved {
    items: Vec<usize>,
    texts: Vec<String>,
    /// For each conflicting explicit constraint, the item on its left side.
    owners: Vec<usize>,
    /// Items whose own minimum or maximum duration is part of the conflict.
    bounded: Vec<usize>,
}

impl Involved {
    /// How many of the conflicting constraints item `i` stands on the left side of.
    fn owned(&self, i: usize) -> usize {
        self.owners.iter().filter(|&&o| o == i).count()
    }
}

/// Adds the hard constraints of every item (rigid timing, order, durations, not before block start)
/// and every link to a difference system over all keys; variable 0 is the block start.
fn hard_system(items: &[Item], links: &[Link]) -> (DiffSystem, Vec<usize>) {
    let mut s = DiffSystem::new();
    let block = s.var(0.0);
    let mut base = Vec::with_capacity(items.len());
    for (i, it) in items.iter().enumerate() {
        base.push(s.len());
        let tag = links.len() + i;
        let first = s.len();
        for _ in 0..it.len {
            let v = s.var(f64::MIN / 4.0);
            s.at_least(v, block, 0.0, tag);
        }
        let keys = &it.model.keys;
        let phase_tag = links.len() + 2 * items.len() + i;
        for (k, key) in keys.iter().enumerate().take(it.len).skip(1) {
            match it.model.flexibility {
                Flexibility::Rigid => s.equal(first + k, first, key.at, tag),
                Flexibility::Stretchable { .. } => {
                    // sync points keep their order; a phase no longer than its limit
                    s.at_least(first + k, first + k - 1, 0.0, tag);
                    if key.max_phase.is_finite() {
                        s.at_most(first + k, first + k - 1, key.max_phase, phase_tag);
                    }
                }
            }
        }
        if let (
            Flexibility::Stretchable {
                min_duration,
                max_duration,
            },
            true,
        ) = (it.model.flexibility, it.len == keys.len())
        {
            // real duration bounds have their own tags: a conflict through them is invalid
            // timing; the least duration of every model only keeps the end after the start
            let (end, bound) = (first + it.len - 1, links.len() + items.len() + i);
            let min_tag = if min_duration > MIN_DURATION {
                bound
            } else {
                tag
            };
            s.at_least(end, first, min_duration, min_tag);
            if max_duration.is_finite() {
                s.at_most(end, first, max_duration, bound);
            }
        }
    }
    let var = |t: Term| -> (usize, f64) {
        match t {
            Term::Key(i, k) => (base[i] + k, 0.0),
            Term::Fixed(t) => (block, t),
        }
    };
    for (tag, l) in links.iter().enumerate() {
        let ((a, ao), (b, bo)) = (var(l.left), var(l.right));
        let offset = l.offset + bo - ao; // a REL b + offset
        s.relate(a, l.relation, b, offset, tag);
    }
    (s, base)
}

fn feasible(items: &[Item], links: &[Link], constraints: &[Constraint]) -> Result<(), Involved> {
    let (s, _) = hard_system(items, links);
    match s.solve() {
        Ok(_) => Ok(()),
        Err(conflict) => {
            let mut involved = Involved {
                items: Vec::new(),
                texts: Vec::new(),
                owners: Vec::new(),
                bounded: Vec::new(),
            };
            for tag in conflict.tags() {
                if tag < links.len() {
                    let l = &links[tag];
                    let text = constraints[l.constraint].to_string();
                    if !involved.texts.contains(&text) {
                        involved.texts.push(text);
                        if let Term::Key(i, _) = l.left {
                            involved.owners.push(i);
                        }
                    }
                    for t in [l.left, l.right] {
                        if let Term::Key(i, _) = t {
                            involved.items.push(i);
                        }
                    }
                } else if tag < links.len() + items.len() {
                    let i = tag - links.len();
                    involved
                        .texts
                        .push(format!("the timing of '{}'", items[i].beh.id));
                    involved.items.push(i);
                } else if tag >= links.len() + 2 * items.len() {
                    let i = tag - links.len() - 2 * items.len();
                    let text = format!(
                        "the phase limits of '{}' (preparation and retraction)",
                        items[i].beh.id
                    );
                    if !involved.texts.contains(&text) {
                        involved.texts.push(text);
                    }
                    involved.items.push(i);
                    involved.bounded.push(i);
                } else {
                    let i = tag - links.len() - items.len();
                    if let Flexibility::Stretchable {
                        min_duration,
                        max_duration,
                    } = items[i].model.flexibility
                    {
                        let text = format!(
                            "the duration of '{}' ({} to {} s)",
                            items[i].beh.id, min_duration, max_duration
                        );
                        if !involved.texts.contains(&text) {
                            involved.texts.push(text);
                        }
                    }
                    involved.items.push(i);
                    involved.bounded.push(i);
                }
            }
            involved.items.sort_unstable();
            involved.items.dedup();
            Err(involved)
        }
    }
}

/// Every behaviour at its preferred timing: one variable per behaviour start. `None` if the
/// constraints need some behaviour to stretch. The times of each item's keys, item after item
/// (as from all the strategies below).
fn preferred(items: &[Item], links: &[Link]) -> Option<Vec<f64>> {
    if pinned_apart(items, links) {
        return None;
    }
    at_preferred_timing(items, links)
}

/// [`preferred`] without the shortcut: the least solution over the block start (node 0) and
/// each item's start (item i's is node i + 1).
fn at_preferred_timing(items: &[Item], links: &[Link]) -> Option<Vec<f64>> {
    let var = |t: Term| -> (usize, f64) {
        match t {
            Term::Key(i, k) => (i + 1, items[i].model.keys[k].at),
            Term::Fixed(t) => (0, t),
        }
    };
    let mut groups = Offsets::default();
    groups.reset(items.len() + 1);
    join_at_links(&mut groups, links, var)?;
    let starts = (1..=items.len()).map(|v| (v, 0.0));
    let x = least_solution(links, var, starts, &mut groups)?;
    let mut times = Vec::with_capacity(items.iter().map(|it| it.len).sum());
    for (i, it) in items.iter().enumerate() {
        times.extend(it.model.keys[..it.len].iter().map(|k| x[i + 1] + k.at));
    }
    Some(times)
}

/// Joins the nodes that each `at` link ties (`node` gives a term's node and its distance from
/// it); `None` if two of them contradict each other.
fn join_at_links(
    groups: &mut Offsets,
    links: &[Link],
    node: impl Fn(Term) -> (usize, f64),
) -> Option<()> {
    for l in links.iter().filter(|l| l.relation == Relation::At) {
        // left = right + offset  =>  value(a) + oa = value(b) + ob + offset
        let ((a, oa), (b, ob)) = (node(l.left), node(l.right));
        groups.join(a, b, ob + l.offset - oa).then_some(())?;
    }
    Some(())
}

/// The least solution of a fast path over `groups.len()` nodes (node 0 the block start, at 0):
/// the links (through `node`, as in [`join_at_links`], which `groups` has been through) and, for
/// item i, `value(node) >= bound` for the i-th `(node, bound)` of `starts` (nothing before the
/// block). With only `at` links the joined groups hold it; otherwise the difference system is
/// searched. `None` if there is none, or if the block start would have to move.
fn least_solution(
    links: &[Link],
    node: impl Fn(Term) -> (usize, f64),
    starts: impl Iterator<Item = (usize, f64)>,
    groups: &mut Offsets,
) -> Option<Vec<f64>> {
    let n = groups.len();
    if links.iter().all(|l| l.relation == Relation::At) {
        let mut x = vec![0.0; n];
        groups.least(starts, &mut x)?;
        return Some(x);
    }
    let mut s = DiffSystem::with_capacity(n, 2 * links.len() + n);
    for v in 0..n {
        s.var(if v == 0 { 0.0 } else { f64::MIN / 4.0 });
    }
    for (tag, l) in links.iter().enumerate() {
        let ((a, oa), (b, ob)) = (node(l.left), node(l.right));
        s.relate(a, l.relation, b, l.offset + ob - oa, tag);
    }
    for (i, (v, bound)) in starts.enumerate() {
        s.at_least(v, 0, bound, links.len() + i);
    }
    let x = s.into_least()?;
    (x[0] <= EPSILON).then_some(x)
}

/// Whether some behaviour has two keys set `at` fixed times that its preferred timing cannot
/// meet (the usual `start="0" end="5"`): then it must stretch, and [`preferred`] has no answer.
/// An exact shortcut, found without building a difference system.
fn pinned_apart(items: &[Item], links: &[Link]) -> bool {
    // (item, the start that the fixed time implies for it)
    let mut starts = Vec::new();
    for l in links.iter().filter(|l| l.relation == Relation::At) {
        // left = right + offset
        let implied = match (l.left, l.right) {
            (Term::Key(i, k), Term::Fixed(t)) => (i, k, t + l.offset),
            (Term::Fixed(t), Term::Key(i, k)) => (i, k, t - l.offset),
            _ => continue,
        };
        let (i, k, at) = implied;
        starts.push((i, at - items[i].model.keys[k].at));
    }
    if starts.len() < 2 {
        return false;
    }
    starts.sort_unstable_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)));
    starts
        .windows(2)
        .any(|w| w[0].0 == w[1].0 && w[1].1 - w[0].1 > EPSILON)
}

/// Second fast path, for blocks where the `at` constraints fix the distances between the
/// constrained keys of every behaviour constrained at two or more keys. The deviation of such a
/// block is then a sum over behaviours, each depending only on its own fixed distances, so each
/// behaviour's best timing (see [`best_timing`]) is found on its own; everything else keeps its
/// preferred timing, and the least solution of the constraints between them gives the earliest
/// times. That is the linear program's answer whenever each behaviour's best timing is unique and
/// the block's constraints and bounds admit it; otherwise `None`, and the LP decides.
fn separable(items: &[Item], links: &[Link]) -> Option<Vec<f64>> {
    let anchors = anchored_keys(items, links);
    let multi = |i: usize| {
        matches!(items[i].model.flexibility, Flexibility::Stretchable { .. })
            && anchors[i].len() >= 2
    };
    // nodes: 0 = block; one per anchor of a multi-anchor item, one (its start) for any other
    let mut base = Vec::with_capacity(items.len());
    let mut n = 1;
    for (i, a) in anchors.iter().enumerate() {
        base.push(n);
        n += if multi(i) { a.len() } else { 1 };
    }
    let node = |i: usize, k: usize| -> (usize, f64) {
        if multi(i) {
            let j = anchors[i].iter().position(|&a| a == k).unwrap_or(0);
            (base[i] + j, 0.0)
        } else {
            (base[i], items[i].model.keys[k].at)
        }
    };
    let term = |t: Term| match t {
        Term::Key(i, k) => node(i, k),
        Term::Fixed(v) => (0, v),
    };
    let mut groups = Offsets::default();
    groups.reset(n);
    join_at_links(&mut groups, links, term)?;
    // each multi-anchor item's key times relative to its first anchor
    let mut shapes: Vec<Vec<f64>> = vec![Vec::new(); items.len()];
    for i in (0..items.len()).filter(|&i| multi(i)) {
        let (root, first) = groups.find(base[i]);
        let mut at = Vec::with_capacity(anchors[i].len());
        for v in base[i]..base[i] + anchors[i].len() {
            let (r, o) = groups.find(v);
            if r != root {
                return None; // a distance the `at` constraints leave open
            }
            at.push(o - first);
        }
        shapes[i] = best_timing(&items[i], &anchors[i], &at)?;
    }
    // nothing before the block: a stretched item's start lies before its first anchor
    let starts = (0..items.len()).map(|i| (base[i], shapes[i].first().map_or(0.0, |s| -s)));
    let x = least_solution(links, term, starts, &mut groups)?;
    let mut times = Vec::with_capacity(items.iter().map(|it| it.len).sum());
    for (i, it) in items.iter().enumerate() {
        let at = x[base[i]];
        if multi(i) {
            times.extend(shapes[i].iter().map(|s| at + s));
        } else {
            times.extend(it.model.keys[..it.len].iter().map(|k| at + k.at));
        }
    }
    Some(times)
}

/// Spaces the keys between two constrained keys of each stretchable behaviour in proportion to
/// their preferred timing (thesis §8.3.2: the phases between constrained keys are scaled
/// uniformly), a phase that would pass its limit held at the limit and the rest scaled alike.
/// The deviation the program minimises does not tell how a span's change is shared among its
/// phases, and the earliest times would take it all out of the first phase (a gesture
/// compressed between stroke and end would jump from stroke to strokeEnd in no time). Only keys
/// no constraint names move, within their spans, so every constraint still holds.
fn spread_between_anchors(items: &[Item], links: &[Link], times: &mut [f64]) {
    let anchors = anchored_keys(items, links);
    let mut first = 0;
    for (it, anchors) in items.iter().zip(&anchors) {
        let t = &mut times[first..first + it.len];
        first += it.len;
        if !matches!(it.model.flexibility, Flexibility::Stretchable { .. }) {
            continue;
        }
        for w in anchors
            .windows(2)
            .filter(|w| w[1] > w[0] + 1 && w[1] < it.len)
        {
            let keys = &it.model.keys[w[0]..=w[1]];
            if let Some(phases) = uniform_phases(keys, t[w[1]] - t[w[0]]) {
                // the anchors stay exactly where they are
                for (i, x) in phases[..phases.len() - 1].iter().enumerate() {
                    t[w[0] + 1 + i] = t[w[0] + i] + x;
                }
            }
        }
    }
}

/// The phases between the first and the last of `keys` scaled by one factor to add up to
/// `length`, those that would pass their limit held at it (with no preferred length at all,
/// equal phases). `None` if the limits leave no such phases.
fn uniform_phases(keys: &[crate::timing::SyncKey], length: f64) -> Option<Vec<f64>> {
    let preferred: Vec<f64> = keys.windows(2).map(|w| w[1].at - w[0].at).collect();
    let limits: Vec<f64> = keys[1..].iter().map(|k| k.max_phase).collect();
    if preferred.iter().sum::<f64>() <= EPSILON {
        let each = length / preferred.len() as f64;
        return limits
            .iter()
            .all(|m| each <= m + EPSILON)
            .then(|| vec![each; preferred.len()]);
    }
    let mut capped = vec![false; preferred.len()];
    loop {
        let held: f64 = (limits.iter().zip(&capped))
            .filter(|x| *x.1)
            .map(|x| x.0)
            .sum();
        let free: f64 = (preferred.iter().zip(&capped))
            .filter(|x| !*x.1)
            .map(|x| x.0)
            .sum();
        if free <= EPSILON {
            return None;
        }
        let scale = ((length - held) / free).max(0.0);
        let mut changed = false;
        for k in 0..preferred.len() {
            if !capped[k] && scale * preferred[k] > limits[k] {
                capped[k] = true;
                changed = true;
            }
        }
        if !changed {
            let phases: Vec<f64> = (0..preferred.len())
                .map(|k| {
                    if capped[k] {
                        limits[k]
                    } else {
                        scale * preferred[k]
                    }
                })
                .collect();
            let total: f64 = phases.iter().sum();
            return ((total - length).abs() <= EPSILON).then_some(phases);
        }
    }
}

/// Per item, the keys that some link names, in key order.
fn anchored_keys(items: &[Item], links: &[Link]) -> Vec<Vec<usize>> {
    let mut anchors = vec![Vec::new(); items.len()];
    for l in links {
        for t in [l.left, l.right] {
            if let Term::Key(i, k) = t {
                anchors[i].push(k);
            }
        }
    }
    for a in &mut anchors {
        a.sort_unstable();
        a.dedup();
    }
    anchors
}

/// The timing of a stretchable item whose keys `anchors` (in key order) must lie at `at` (seconds
/// from the first of them) that the linear program would choose: the key times relative to the
/// first anchor, or `None` where that choice is not provably unique or breaks a bound.
///
/// The item's deviation is `|σ − 1| · D + 2 · Σ |phase − σ · preferred phase|` (D its preferred
/// duration), each phase at most its limit. For a given σ the best phases are known in closed
/// form (see [`Spans::cost`]), so the best σ minimises a convex piecewise-linear function of σ,
/// whose least value lies at one of its kinks. At that σ, a phase outside the anchors is σ times
/// its preferred length (or its limit); the phases between two anchors are scaled alike to make
/// up their fixed distance ([`uniform_phases`]), which costs the deviation the same as any other
/// split of the change.
fn best_timing(item: &Item, anchors: &[usize], at: &[f64]) -> Option<Vec<f64>> {
    let keys = &item.model.keys[..item.len];
    let phase = |k: usize| (keys[k].at - keys[k - 1].at, keys[k].max_phase);
    let (a0, last) = (anchors[0], anchors[anchors.len() - 1]);
    let spans = Spans {
        d: item.model.preferred_duration().max(EPSILON),
        outer: (1..=a0).chain(last + 1..keys.len()).map(phase).collect(),
        inner: anchors
            .windows(2)
            .zip(at.windows(2))
            .map(|(k, t)| (t[1] - t[0], (k[0] + 1..=k[1]).map(phase).collect()))
            .collect(),
    };
    let sigma = spans.unique_best_scale()?;
    let fitted = |k: usize| {
        let (p, max) = phase(k);
        (sigma * p).min(max)
    };
    let mut offsets = vec![0.0; keys.len()];
    for k in (0..a0).rev() {
        offsets[k] = offsets[k + 1] - fitted(k + 1);
    }
    for (j, w) in anchors.windows(2).enumerate() {
        // the span's phases scaled alike to its fixed distance (None: the limits cannot make
        // it up)
        let phases = uniform_phases(&keys[w[0]..=w[1]], at[j + 1] - at[j])?;
        offsets[w[0]] = at[j];
        for (i, x) in phases.iter().enumerate() {
            offsets[w[0] + 1 + i] = offsets[w[0] + i] + x;
        }
        offsets[w[1]] = at[j + 1];
    }
    for k in last + 1..keys.len() {
        offsets[k] = offsets[k - 1] + fitted(k);
    }
    within_bounds(item, &offsets).then_some(offsets)
}

/// One behaviour's phases for [`best_timing`]: (preferred length, limit) of each phase outside
/// its anchors, and for each span between two consecutive anchors its fixed distance and its
/// phases.
struct Spans {
    d: f64,
    outer: Vec<(f64, f64)>,
    inner: Vec<(f64, Vec<(f64, f64)>)>,
}

impl Spans {
    /// The least deviation at scale σ (infinite where the limits cannot make up a distance). A
    /// phase costs nothing at `min(σ · p, limit)` and twice what it must exceed its limit by
    /// otherwise; a span's phases start there and change by what their distance needs, at 2 per
    /// second.
    fn cost(&self, s: f64) -> f64 {
        let over = |&(p, max): &(f64, f64)| 2.0 * (s * p - max).max(0.0);
        let mut cost = (s - 1.0).abs() * self.d + self.outer.iter().map(over).sum::<f64>();
        for (l, phases) in &self.inner {
            let fitted: f64 = phases.iter().map(|&(p, max)| (s * p).min(max)).sum();
            let room: f64 = phases.iter().map(|p| p.1).sum();
            if *l > room + EPSILON {
                return f64::INFINITY;
            }
            cost += phases.iter().map(over).sum::<f64>() + 2.0 * (l - fitted).abs();
        }
        cost
    }

    /// Where the cost may kink: σ = 0 and 1, where a phase reaches its limit, and where a span's
    /// fitted phases add up to its distance.
    fn kinks(&self) -> Vec<f64> {
        let mut out = vec![0.0, 1.0];
        let all = self
            .outer
            .iter()
            .chain(self.inner.iter().flat_map(|s| &s.1));
        out.extend(
            all.filter(|p| p.0 > EPSILON && p.1.is_finite())
                .map(|p| p.1 / p.0),
        );
        for (l, phases) in &self.inner {
            // the fitted sum is linear between the points where phases reach their limits
            let mut ends: Vec<f64> = phases
                .iter()
                .filter(|p| p.0 > EPSILON && p.1.is_finite())
                .map(|p| p.1 / p.0)
                .collect();
            ends.push(f64::INFINITY);
            ends.sort_by(f64::total_cmp);
            let mut from = 0.0;
            for to in ends {
                let mid = if to.is_finite() {
                    (from + to) / 2.0
                } else {
                    from + 1.0
                };
                let free: f64 = phases.iter().filter(|p| mid * p.0 < p.1).map(|p| p.0).sum();
                let capped: f64 = phases
                    .iter()
                    .filter(|p| mid * p.0 >= p.1)
                    .map(|p| p.1)
                    .sum();
                if free > EPSILON {
                    let s = (l - capped) / free;
                    if s >= from - EPSILON && s <= to + EPSILON {
                        out.push(s.max(0.0));
                    }
                }
                from = to;
            }
        }
        out.sort_by(f64::total_cmp);
        out.dedup_by(|a, b| (*a - *b).abs() <= EPSILON);
        out
    }

    /// The σ ≥ 0 of least cost, if only one has it: `None` when the least cost is reached on a
    /// whole interval (a tie the LP may break either way) or nowhere.
    fn unique_best_scale(&self) -> Option<f64> {
        let kinks = self.kinks();
        let (i, &best) = kinks
            .iter()
            .enumerate()
            .min_by(|a, b| self.cost(*a.1).total_cmp(&self.cost(*b.1)))?;
        let least = self.cost(best);
        if !least.is_finite() {
            return None;
        }
        // the cost is linear between kinks: look half-way to the neighbours
        let scale = self.d + self.outer.len() as f64 + self.inner.len() as f64;
        let rises = |s: f64| self.cost(s) > least + 1e-9 * scale * (s - best).abs().max(1e-3);
        let left = i == 0 || rises((kinks[i - 1] + best) / 2.0);
        let right = rises(kinks.get(i + 1).map_or(best + 1.0, |n| (best + n) / 2.0));
        (left && right).then_some(best)
    }
}

/// Whether key times (`offsets`, any origin) keep the item's order, duration bounds and phase
/// limits.
fn within_bounds(item: &Item, offsets: &[f64]) -> bool {
    let keys = &item.model.keys;
    let ordered = offsets
        .windows(2)
        .zip(keys.windows(2))
        .all(|(t, k)| t[1] - t[0] >= -EPSILON && t[1] - t[0] <= k[1].max_phase + EPSILON);
    let duration = offsets[offsets.len() - 1] - offsets[0];
    let bounded = match item.model.flexibility {
        Flexibility::Stretchable {
            min_duration,
            max_duration,
        } if item.len == keys.len() => {
            duration >= min_duration - EPSILON && duration <= max_duration + EPSILON
        }
        _ => true,
    };
    ordered && bounded
}

/// The longest the linear program may take before the earliest feasible times are used instead.
/// No block within the limits comes near it (the slowest seen take milliseconds); it is there so
/// that no input can hold the realizer, should the simplex stall.
const LP_TIME_LIMIT_SECS: f64 = 2.0;

/// Whether the numbers of a block's system are within what the simplex handles: no time, offset
/// or duration further than [`MAX_SCHEDULED_TIME`] from zero. Beyond that a behaviour is dropped
/// after scheduling anyway, and such magnitudes next to ones of 1e-9 s can make the simplex stall.
fn tame(items: &[Item], links: &[Link]) -> bool {
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
fn optimise(items: &[Item], links: &[Link]) -> Vec<f64> {
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
struct Program {
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
fn earliest(items: &[Item], links: &[Link]) -> Vec<f64> {
    let (s, base) = hard_system(items, links);
    let x = s.solve().unwrap_or_default();
    items
        .iter()
        .zip(&base)
        .flat_map(|(it, &b)| (b..b + it.len).map(|v| x.get(v).copied().unwrap_or(0.0)))
        .collect()
}

#[cfg(test)]
mod tests;
