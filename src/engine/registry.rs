//! The engine registry: behaviour kind (namespace + element name) → engine. One engine may serve
//! several kinds; registering a kind again hands it to the newer engine. New kinds and engines
//! register from outside the core (S76).

use std::collections::HashMap;

use super::timing::{TimingModel, TimingModels};
use super::Engine;
use crate::bml::Behaviour;

/// A behaviour kind as written: namespace URI and element name.
#[derive(Debug, Clone, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct KindKey {
    /// Namespace URI (the canonical BMLA namespace for the control behaviours).
    pub ns: String,
    /// Element local name.
    pub name: String,
}

impl KindKey {
    /// The kind `{ns}name`.
    pub fn new(ns: &str, name: &str) -> Self {
        KindKey {
            ns: ns.to_string(),
            name: name.to_string(),
        }
    }

    /// The kind of a behaviour.
    pub fn of(b: &Behaviour) -> Self {
        KindKey::new(b.kind.namespace(), b.kind.element_name())
    }
}

/// Engines and the kinds each realizes.
#[derive(Default)]
pub struct Registry {
    engines: Vec<Box<dyn Engine>>,
    kinds: HashMap<KindKey, usize>,
}

impl Registry {
    /// An empty registry (see `engines::default_registry` for the built-in engines).
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds `engine` for `kinds`; returns its index. Kinds registered before go to this engine.
    pub fn register(&mut self, engine: Box<dyn Engine>, kinds: &[KindKey]) -> usize {
        self.engines.push(engine);
        let index = self.engines.len() - 1;
        for k in kinds {
            self.kinds.insert(k.clone(), index);
        }
        index
    }

    /// The index of the engine that realizes `behaviour`'s kind.
    pub fn engine_for(&self, behaviour: &Behaviour) -> Option<usize> {
        // a lookup without allocating a key: kinds are few, compare in place
        let (ns, name) = (behaviour.kind.namespace(), behaviour.kind.element_name());
        self.kinds
            .iter()
            .find(|(k, _)| k.name == name && k.ns == ns)
            .map(|(_, &i)| i)
    }

    /// Number of engines.
    pub fn len(&self) -> usize {
        self.engines.len()
    }

    /// Whether no engine is registered.
    pub fn is_empty(&self) -> bool {
        self.engines.is_empty()
    }

    /// Engine `i`.
    pub fn engine(&self, i: usize) -> &dyn Engine {
        self.engines[i].as_ref()
    }

    /// Engine `i`, mutably.
    pub fn engine_mut(&mut self, i: usize) -> &mut dyn Engine {
        self.engines[i].as_mut()
    }

    /// Every engine.
    pub fn engines_mut(&mut self) -> impl Iterator<Item = &mut (dyn Engine + 'static)> {
        self.engines.iter_mut().map(|e| e.as_mut())
    }

    /// Every engine.
    pub fn engines(&self) -> impl Iterator<Item = &(dyn Engine + 'static)> {
        self.engines.iter().map(|e| e.as_ref())
    }

    /// The registered kinds, sorted.
    pub fn kinds(&self) -> Vec<&KindKey> {
        let mut v: Vec<&KindKey> = self.kinds.keys().collect();
        v.sort();
        v
    }
}

/// The registry is the scheduler's source of timing models.
impl TimingModels for Registry {
    fn model(&self, behaviour: &Behaviour) -> Option<TimingModel> {
        self.engine_for(behaviour)
            .and_then(|i| self.engines[i].timing(behaviour))
    }
}
