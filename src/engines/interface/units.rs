//! The units an engine holds, ordered by start time, and macros for the core methods of an
//! engine that keeps its units in one.

use std::collections::BTreeMap;
use std::sync::Arc;

use super::{Unit, UnitKey};
use crate::planning::timing::SyncName;

/// The units an engine holds, each with its key (shared with frame outputs) and current global
/// sync times, in the order of their start times (ties: the order they were added). So frames
/// are deterministic, a unit that starts later is applied later (and wins where two overlap),
/// and the units that have started at some moment come first: a frame looks at those only.
/// Kept in a map ordered by start, so that adding one of thousands of units (a chain of 10 000
/// gestures, or several such blocks whose units interleave) costs a logarithm, not a shift of
/// the rest. A unit is found by key from the front: the units asked for (running, ending) are
/// the ones that have started, which come first.
#[derive(Debug, Clone)]
pub struct Units<T> {
    units: BTreeMap<Order, Held<T>>,
    /// How many units were ever added (the tie-break of equal starts).
    added: u64,
}

/// A unit's place: its start time (a unit without syncs sorts last), then when it was added.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Order {
    start: f64,
    added: u64,
}

impl Eq for Order {}

impl PartialOrd for Order {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Order {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.start
            .total_cmp(&other.start)
            .then(self.added.cmp(&other.added))
    }
}

#[derive(Debug, Clone)]
struct Held<T> {
    key: Arc<UnitKey>,
    syncs: SyncTimes,
    data: T,
}

impl<T> Held<T> {
    fn start(&self) -> f64 {
        self.syncs.first().map_or(f64::INFINITY, |s| s.1)
    }
}

/// A unit's (sync, global time) list, in sync order.
pub type SyncTimes = Vec<(SyncName, f64)>;

impl<T> Default for Units<T> {
    fn default() -> Self {
        Units {
            units: BTreeMap::new(),
            added: 0,
        }
    }
}

impl<T> Units<T> {
    /// No units.
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds a unit with the engine's own data `data`.
    pub fn add(&mut self, unit: Unit<'_>, data: T) {
        let held = Held {
            key: Arc::new(unit.key.clone()),
            syncs: unit.syncs,
            data,
        };
        self.insert(held);
    }

    fn insert(&mut self, held: Held<T>) {
        self.added += 1;
        let order = Order {
            start: held.start(),
            added: self.added,
        };
        self.units.insert(order, held);
    }

    /// Where the unit `key` is.
    fn find(&self, key: &UnitKey) -> Option<Order> {
        self.units
            .iter()
            .find(|(_, u)| *u.key == *key)
            .map(|(order, _)| *order)
    }

    /// Forgets a unit.
    pub fn remove(&mut self, key: &UnitKey) {
        if let Some(order) = self.find(key) {
            self.units.remove(&order);
        }
    }

    /// New sync times for a unit.
    pub fn retime(&mut self, key: &UnitKey, times: &[f64]) {
        let Some(order) = self.find(key) else {
            return;
        };
        let Some(mut held) = self.units.remove(&order) else {
            return;
        };
        for (s, t) in held.syncs.iter_mut().zip(times) {
            s.1 = *t;
        }
        self.insert(held);
    }

    /// Every unit with its key, in start order.
    pub fn keyed(&self) -> impl Iterator<Item = (&SyncTimes, &T, &UnitKey)> + '_ {
        self.units.values().map(|u| (&u.syncs, &u.data, &*u.key))
    }

    /// Every unit with its key, in start order, the data mutable.
    pub fn keyed_mut(&mut self) -> impl Iterator<Item = (&SyncTimes, &mut T, &UnitKey)> + '_ {
        self.units
            .values_mut()
            .map(|u| (&u.syncs, &mut u.data, &*u.key))
    }

    /// A unit's data.
    pub fn get(&self, key: &UnitKey) -> Option<&T> {
        self.units
            .values()
            .find(|u| *u.key == *key)
            .map(|u| &u.data)
    }

    /// A unit's sync times and data.
    pub fn get_mut(&mut self, key: &UnitKey) -> Option<(&mut SyncTimes, &mut T)> {
        self.units
            .values_mut()
            .find(|u| *u.key == *key)
            .map(|u| (&mut u.syncs, &mut u.data))
    }

    /// How many units.
    pub fn len(&self) -> usize {
        self.units.len()
    }

    /// Whether there are none.
    pub fn is_empty(&self) -> bool {
        self.units.is_empty()
    }

    /// Every unit's sync times and data, in start order.
    pub fn all(&self) -> impl Iterator<Item = (&SyncTimes, &T)> + '_ {
        self.units.values().map(|u| (&u.syncs, &u.data))
    }

    /// Every unit's sync times and data, the data mutable (engines that compile a unit lazily).
    pub fn all_mut(&mut self) -> impl Iterator<Item = (&SyncTimes, &mut T)> + '_ {
        self.units.values_mut().map(|u| (&u.syncs, &mut u.data))
    }

    /// The units that have started by `now` (start ≤ now), in start order: what a frame at `now`
    /// can show, without looking at the units still to come.
    pub fn started(&self, now: f64) -> impl Iterator<Item = (&SyncTimes, &T)> + '_ {
        self.units
            .values()
            .take_while(move |u| u.start() <= now)
            .map(|u| (&u.syncs, &u.data))
    }

    /// The units that have started by `now` (start ≤ now), in start order, the data mutable:
    /// what a frame at `now` can show.
    pub fn started_mut(&mut self, now: f64) -> impl Iterator<Item = (&SyncTimes, &mut T)> + '_ {
        self.units
            .values_mut()
            .take_while(move |u| u.start() <= now)
            .map(|u| (&u.syncs, &mut u.data))
    }

    /// Appends to `out` the sound of every unit running at `now` that has one: `clip` gives a
    /// unit's samples and volume (0–1); the unit plays from its first sync to its last.
    pub fn playing(
        &self,
        now: f64,
        out: &mut Vec<crate::character::sound::Playing>,
        clip: impl Fn(&T) -> Option<(Arc<crate::character::voice::Audio>, f32)>,
    ) {
        for u in self.units.values().take_while(|u| u.start() <= now) {
            let (Some(start), Some(stop)) = (u.syncs.first(), u.syncs.last()) else {
                continue;
            };
            let Some((audio, volume)) = clip(&u.data).filter(|_| now < stop.1) else {
                continue;
            };
            out.push(crate::character::sound::Playing {
                id: u.key.to_string(),
                start: start.1,
                stop: stop.1,
                volume,
                audio,
            });
        }
    }

    /// The units running at `now` (start ≤ now < end) with their progress (0 at start, 1 at end;
    /// 0 for a unit without a finite end), in start order.
    pub fn running(&self, now: f64) -> impl Iterator<Item = (&Arc<UnitKey>, f64, &T)> + '_ {
        let started = self.units.values().take_while(move |u| u.start() <= now);
        started.filter_map(move |u| {
            let (start, end) = (u.syncs.first()?.1, u.syncs.last()?.1);
            if now >= end {
                return None;
            }
            let p = if end.is_finite() {
                (now - start) / (end - start)
            } else {
                0.0
            };
            Some((&u.key, p.clamp(0.0, 1.0), &u.data))
        })
    }
}

/// `Engine::retime` and `Engine::len` for an engine that keeps its units in `self.units`
/// ([`Units`]).
#[macro_export]
macro_rules! units_retime_len {
    () => {
        fn retime(
            &mut self,
            key: &$crate::engines::interface::UnitKey,
            syncs: &[($crate::planning::timing::SyncName, f64)],
        ) {
            let times: Vec<f64> = syncs.iter().map(|s| s.1).collect();
            self.units.retime(key, &times);
        }

        fn len(&self) -> usize {
            self.units.len()
        }
    };
}

/// The part of `Engine` shared by engines whose units of one behaviour kind (`$kind`, a
/// variant of `BehaviourKind`) persist until they are ended or replaced (the noise and physical
/// engines): `remove`, `retime`, `len`, `play` under the name `$name`, `interrupt` at once,
/// `name`, and `timing` (a persistent span for that kind, nothing for others).
#[macro_export]
macro_rules! units_persistent {
    ($name:literal, $kind:ident) => {
        $crate::units_remove!();
        $crate::units_retime_len!();
        $crate::units_play!($name);
        $crate::units_interrupt!($crate::engines::interface::stop_now);

        fn name(&self) -> &'static str {
            $name
        }

        fn timing(
            &self,
            behaviour: &$crate::language::bml::Behaviour,
        ) -> Option<$crate::planning::timing::TimingModel> {
            // persistent: it runs until it is ended or replaced
            matches!(
                behaviour.kind,
                $crate::language::bml::BehaviourKind::$kind(_)
            )
            .then($crate::planning::timing::TimingModel::persistent_span)
        }
    };
}

/// `Parameters` for an engine whose units keep their named parameters in a `params` field
/// ([`named_param`](crate::engines::interface::named_param)), its units in `self.units`:
/// `$owner` names them in errors (`noise`, `controller`).
#[macro_export]
macro_rules! units_named_params {
    ($engine:ty, $owner:literal) => {
        impl $crate::engines::interface::Parameters for $engine {
            fn parameter(
                &self,
                key: &$crate::engines::interface::UnitKey,
                name: &str,
            ) -> Option<f64> {
                $crate::engines::interface::named_param(&self.units.get(key)?.params, name)
            }

            fn set_parameter(
                &mut self,
                key: &$crate::engines::interface::UnitKey,
                name: &str,
                value: f64,
                _now: f64,
            ) -> Result<Option<Vec<f64>>, $crate::engines::interface::EngineError> {
                let params = self.units.get_mut(key).map(|(_, u)| &mut u.params);
                $crate::engines::interface::set_named_param(key, $owner, params, name, value)
            }
        }
    };
}

/// `Engine::remove` for an engine that keeps its units in `self.units`.
#[macro_export]
macro_rules! units_remove {
    () => {
        fn remove(&mut self, key: &$crate::engines::interface::UnitKey) {
            self.units.remove(key);
        }
    };
}

/// `Engine::play` showing each running unit's progress under the engine name `$name` (or, with
/// `field f`, the name in the engine's field `f`).
#[macro_export]
macro_rules! units_play {
    (field $f:ident) => {
        fn play(&mut self, now: f64, frame: &mut $crate::engines::interface::Frame) {
            for (key, progress, _) in self.units.running(now) {
                frame.outputs.push($crate::engines::interface::Output {
                    key: key.clone(),
                    engine: self.$f,
                    progress,
                    params: Vec::new(),
                });
            }
        }
    };
    ($name:expr) => {
        fn play(&mut self, now: f64, frame: &mut $crate::engines::interface::Frame) {
            for (key, progress, _) in self.units.running(now) {
                frame.outputs.push($crate::engines::interface::Output {
                    key: key.clone(),
                    engine: $name,
                    progress,
                    params: Vec::new(),
                });
            }
        }
    };
}

/// `Engine::interrupt` with the timing `$how` ([`relax_now`](super::relax_now) or [`stop_now`](super::stop_now)), keeping the
/// engine's own copy of the unit's times.
#[macro_export]
macro_rules! units_interrupt {
    ($how:path) => {
        fn interrupt(
            &mut self,
            key: &$crate::engines::interface::UnitKey,
            now: f64,
            syncs: &[($crate::planning::timing::SyncName, f64)],
        ) -> Vec<f64> {
            let times = $how(now, syncs);
            self.units.retime(key, &times);
            times
        }
    };
}
