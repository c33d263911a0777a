//! The engine registry: behaviour kind (namespace + element name) → engine. One engine may serve
//! several kinds; registering a kind again hands it to the newer engine. New kinds and engines
//! register from outside the core.

use super::Engine;
use crate::language::bml::{Behaviour, BUILTIN_KINDS};
use crate::planning::timing::{TimingModel, TimingModels};

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

/// An engine of a [`Registry`], as [`Registry::register`] returned it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct EngineId(usize);

/// Engines and the kinds each realizes.
#[derive(Default)]
pub struct Registry {
    engines: Vec<Box<dyn Engine>>,
    /// (kind, engine) for every registered kind, in registration order.
    kinds: Vec<(KindKey, EngineId)>,
    /// The engine of each built-in kind, by [`BehaviourKind::builtin_slot`]: found without
    /// comparing names.
    builtin: [Option<EngineId>; BUILTIN_KINDS.len()],
}

impl Registry {
    /// An empty registry (see `engines::default_registry` for the built-in engines).
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds `engine` for `kinds`; returns its id. Kinds registered before go to this engine.
    pub fn register(&mut self, engine: Box<dyn Engine>, kinds: &[KindKey]) -> EngineId {
        self.engines.push(engine);
        let index = EngineId(self.engines.len() - 1);
        for k in kinds {
            if let Some(slot) = BUILTIN_KINDS
                .iter()
                .position(|&(name, ns)| name == k.name && ns == k.ns)
            {
                self.builtin[slot] = Some(index);
            }
            match self.kinds.iter_mut().find(|(x, _)| x == k) {
                Some(known) => known.1 = index,
                None => self.kinds.push((k.clone(), index)),
            }
        }
        index
    }

    /// The engine that realizes `behaviour`'s kind.
    pub fn engine_for(&self, behaviour: &Behaviour) -> Option<EngineId> {
        if let Some(slot) = behaviour.kind.builtin_slot() {
            return self.builtin[slot];
        }
        // an extension kind: the few registered kinds compared in place
        let (name, ns) = (behaviour.kind.element_name(), behaviour.kind.namespace());
        self.kinds
            .iter()
            .find(|(k, _)| k.name == name && k.ns == ns)
            .map(|&(_, i)| i)
    }

    /// Number of engines.
    pub fn len(&self) -> usize {
        self.engines.len()
    }

    /// Whether no engine is registered.
    pub fn is_empty(&self) -> bool {
        self.engines.is_empty()
    }

    /// Engine `id`.
    pub fn engine(&self, id: EngineId) -> &dyn Engine {
        self.engines[id.0].as_ref()
    }

    /// The ids of every engine, in registration order.
    pub fn ids(&self) -> impl Iterator<Item = EngineId> {
        (0..self.engines.len()).map(EngineId)
    }

    /// Why the engine of `behaviour` would move nothing for it (see [`Engine::unanimated`]).
    pub fn unanimated(&self, behaviour: &Behaviour) -> Option<String> {
        self.engine(self.engine_for(behaviour)?)
            .unanimated(behaviour)
    }

    /// The body resources `behaviour` occupies on engine `id` (see [`Resources`](super::Resources)).
    pub fn resources(&self, id: EngineId, behaviour: &Behaviour) -> &'static [&'static str] {
        self.engine(id)
            .as_resources()
            .map_or(&[], |r| r.resources(behaviour))
    }

    /// The exclusive group of `behaviour` on engine `id` (see [`Resources`](super::Resources)).
    pub fn exclusive_group<'a>(
        &'a self,
        id: EngineId,
        behaviour: &'a Behaviour,
    ) -> Option<&'a str> {
        self.engine(id).as_resources()?.exclusive_group(behaviour)
    }

    /// Engine `id`, mutably.
    pub fn engine_mut(&mut self, id: EngineId) -> &mut dyn Engine {
        self.engines[id.0].as_mut()
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
        let mut v: Vec<&KindKey> = self.kinds.iter().map(|(k, _)| k).collect();
        v.sort();
        v
    }
}

/// The registry is the scheduler's source of timing models.
impl TimingModels for Registry {
    fn model(&self, behaviour: &Behaviour) -> Option<TimingModel> {
        self.engine_for(behaviour)
            .and_then(|i| self.engines[i.0].timing(behaviour))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engines::timing_only::TimingOnlyEngine;
    use crate::language::bml::{NS_BML, NS_BMLT};
    use crate::planning::timing::DefaultTimingModels;

    #[test]
    fn kinds_are_found_by_name_and_namespace_and_the_newest_registration_wins() {
        let models = DefaultTimingModels::default();
        let mut r = Registry::new();
        let engine = || Box::new(TimingOnlyEngine::motion(models));
        // names of equal length ("gesture", "posture", "x:gesture") and one name in two namespaces
        let a = r.register(
            engine(),
            &[
                KindKey::new(NS_BML, "gesture"),
                KindKey::new(NS_BML, "posture"),
                KindKey::new(NS_BML, "head"),
            ],
        );
        let b = r.register(
            engine(),
            &[
                KindKey::new("urn:x", "gesture"),
                KindKey::new(NS_BMLT, "keyframe"),
            ],
        );
        let c = r.register(engine(), &[KindKey::new(NS_BML, "posture")]);
        let block = crate::language::bml::load(
            r#"<bml xmlns="http://www.bml-initiative.org/bml/bml-1.0" xmlns:x="urn:x" xmlns:bmlt="http://hmi.ewi.utwente.nl/bmlt" id="b">
                <gesture id="g" lexeme="BEAT"/><posture id="p"><stance type="STANDING"/><pose part="WHOLEBODY" lexeme="NEUTRAL"/></posture>
                <head id="h" lexeme="NOD"/><x:gesture id="xg"/><bmlt:keyframe id="k"/><gaze id="z" target="t"/></bml>"#,
        )
        .unwrap()
        .block;
        let found: Vec<Option<EngineId>> =
            block.behaviours.iter().map(|b| r.engine_for(b)).collect();
        assert_eq!(found, [Some(a), Some(c), Some(a), Some(b), Some(b), None]);
        assert_eq!(r.kinds().len(), 5);
        // an extension kind registered again goes to the newer engine too
        let d = r.register(engine(), &[KindKey::new("urn:x", "gesture")]);
        assert_eq!(r.engine_for(&block.behaviours[3]), Some(d));
        assert_eq!(r.engine_for(&block.behaviours[4]), Some(b));
        assert_eq!(r.kinds().len(), 5);
    }
}
