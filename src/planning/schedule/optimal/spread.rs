//! Spacing the keys between two constrained keys of a stretchable behaviour in proportion to their
//! preferred timing (the phases between constrained keys scaled uniformly), which the deviation
//! leaves open.

use super::*;

/// Spaces the keys between two constrained keys of each stretchable behaviour in proportion to
/// their preferred timing (thesis §8.3.2: the phases between constrained keys are scaled
/// uniformly), a phase that would pass its limit held at the limit and the rest scaled alike.
/// The deviation the program minimises does not tell how a span's change is shared among its
/// phases, and the earliest times would take it all out of the first phase (a gesture
/// compressed between stroke and end would jump from stroke to strokeEnd in no time). Only keys
/// no constraint names move, within their spans, so every constraint still holds.
pub(super) fn spread_between_anchors(items: &[Item], links: &[Link], times: &mut [f64]) {
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
pub(super) fn uniform_phases(
    keys: &[crate::planning::timing::SyncKey],
    length: f64,
) -> Option<Vec<f64>> {
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
