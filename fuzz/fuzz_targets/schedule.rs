//! Fuzz target for the scheduler: any block that loads must schedule (or fail with a reason)
//! without panicking, and a schedule must hold every constraint between scheduled behaviours, keep
//! each behaviour's sync order and place nothing before the block start.
#![no_main]

use bml_realizer::language::bml::{self, Anchor, Relation, SyncPoint};
use bml_realizer::planning::schedule::{NoExternal, Optimal, SchedulingStrategy, SortedGreedy};
use bml_realizer::planning::timing::DefaultTimingModels;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(parsed) = bml::load(text) else { return };
    let block = parsed.block;
    let models = DefaultTimingModels::default();
    let _ = SortedGreedy.schedule(&block, &models, &NoExternal);
    let Ok(s) = Optimal.schedule(&block, &models, &NoExternal) else {
        return;
    };
    let tol = |x: f64| 1e-6 * (1.0 + x.abs());
    for b in &s.behaviours {
        let t: Vec<f64> = b.syncs.iter().map(|(_, t)| *t).collect();
        assert!(
            t.iter().all(|x| *x >= -tol(*x)),
            "{} before block start: {t:?}\n{text}",
            b.id
        );
        assert!(
            t.windows(2).all(|w| w[1] >= w[0] - tol(w[0])),
            "{} out of order: {t:?}\n{text}",
            b.id
        );
    }
    for c in bml::extract(&block) {
        let time = |a: &Anchor| match a {
            Anchor::BlockStart => Some(0.0),
            Anchor::Point(SyncPoint::Local { behaviour, sync }) => s.time(behaviour, sync),
            _ => None,
        };
        let (Some(l), Some(r)) = (time(&c.left), time(&c.right)) else {
            continue;
        };
        if !(l.is_finite() && r.is_finite()) {
            continue;
        }
        let r = r + c.offset;
        let ok = match c.relation {
            Relation::At => (l - r).abs() <= tol(r),
            Relation::Before => l <= r + tol(r),
            Relation::After => l >= r - tol(r),
        };
        assert!(ok, "{c} violated: {l} vs {r}\n{text}");
    }
});
