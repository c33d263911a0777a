//! The fast paths that answer without a linear program: every behaviour at its preferred timing
//! (the least solution of the difference system), and, where the `at` constraints fix each
//! constrained behaviour's span, each behaviour at its own best timing, taken only where that is
//! provably the program's answer.

use super::*;

/// Every behaviour at its preferred timing: one variable per behaviour start. `None` if the
/// constraints need some behaviour to stretch. The times of each item's keys, item after item
/// (as from all the strategies below).
pub(super) fn preferred(items: &[Item], links: &[Link]) -> Option<Vec<f64>> {
    if pinned_apart(items, links) {
        return None;
    }
    at_preferred_timing(items, links)
}

/// [`preferred`] without the shortcut: the least solution over the block start (node 0) and
/// each item's start (item i's is node i + 1).
pub(super) fn at_preferred_timing(items: &[Item], links: &[Link]) -> Option<Vec<f64>> {
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
pub(super) fn join_at_links(
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
pub(super) fn least_solution(
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
pub(super) fn pinned_apart(items: &[Item], links: &[Link]) -> bool {
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
pub(super) fn separable(items: &[Item], links: &[Link]) -> Option<Vec<f64>> {
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

/// Per item, the keys that some link names, in key order.
pub(super) fn anchored_keys(items: &[Item], links: &[Link]) -> Vec<Vec<usize>> {
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
pub(super) fn best_timing(item: &Item, anchors: &[usize], at: &[f64]) -> Option<Vec<f64>> {
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
pub(super) struct Spans {
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
pub(super) fn within_bounds(item: &Item, offsets: &[f64]) -> bool {
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
