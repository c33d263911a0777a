//! Feasibility: the hard constraints of a block (rigid timing, sync order, duration bounds, phase
//! limits, links, nothing before the block's start) as one difference system; a contradictory
//! cycle names the constraints and behaviours in conflict, and the non-required behaviour that
//! brought the most of them is dropped.

use super::*;

/// Drops the non-required behaviour that brought the most conflicting constraints (a behaviour's
/// own sync is the left side of its attributes; ties by id), or fails the block if only required
/// behaviours are involved.
pub(super) fn drop_one(
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
pub(super) struct Involved {
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
pub(super) fn hard_system(items: &[Item], links: &[Link]) -> (DiffSystem, Vec<usize>) {
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

pub(super) fn feasible(
    items: &[Item],
    links: &[Link],
    constraints: &[Constraint],
) -> Result<(), Involved> {
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
