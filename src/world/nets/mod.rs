//! PaT-Nets (after the Penn framework of Granieri, Becket, Reich, Crabtree and Badler, §3.3 of
//! the crowd survey): finite-state nets that sequence behaviour by watching the world. A net
//! is in one state at a time; each frame, in parallel with the behaviours running, the
//! transitions from its state are tried in order and the first whose guard holds fires: its
//! actions send BML to the net's character, set world variables or start other nets, and the
//! net enters the transition's target. Nets belong to a character or to the world (a traffic
//! light), and a character may run several. A frame's guards all read the world as the frame
//! began — the variables as they were, what sensing saw in the previous frame — and the
//! actions take effect together after every net was tried, so that no result depends on the
//! order nets are tried in. The file format is read in [`mod@file`].

pub mod behaviour;
pub mod file;

use std::collections::BTreeMap;

use crate::language::feedback::world::{NetFeedback, VarFeedback, VarValue, WorldFeedback};

/// A net: its states (the first is where it starts) and transitions.
#[derive(Debug, Clone, PartialEq)]
pub struct Net {
    /// Its name.
    pub name: String,
    /// Its character (`None`: a world-level net).
    pub character: Option<String>,
    /// Its states.
    pub states: Vec<String>,
    /// Its transitions, tried in order.
    pub transitions: Vec<Transition>,
    /// Whether it waits for another net to start it.
    pub waits: bool,
}

/// A transition between two states (indices into the net's states).
#[derive(Debug, Clone, PartialEq)]
pub struct Transition {
    /// The state it leaves.
    pub from: usize,
    /// The state it enters.
    pub to: usize,
    /// When it fires.
    pub when: Guard,
    /// What it does when it fires.
    pub actions: Vec<Action>,
}

/// A condition on the world.
#[derive(Debug, Clone, PartialEq)]
pub enum Guard {
    /// The net has been in its state this long (s).
    After(f64),
    /// A sync point (`block:behaviour:sync`) or block progress (`block:start`, `block:end`)
    /// of the net's character (any character's for a world-level net) was reported.
    Sync(String),
    /// The net's character saw this at its last look.
    Sees(String),
    /// The net's character stands within this distance (m, on the ground) of a character or
    /// point.
    Near(String, f32),
    /// A world variable has this value.
    Var(String, VarValue),
    /// All of these.
    All(Vec<Guard>),
    /// Any of these.
    Any(Vec<Guard>),
    /// Not this.
    Not(Box<Guard>),
}

/// Something a transition does.
#[derive(Debug, Clone, PartialEq)]
pub enum Action {
    /// Sends a `<bml>` block to the net's character (a block naming a character goes to it).
    Bml(String),
    /// Sets a world variable.
    Set(String, VarValue),
    /// Starts another net from its first state (one running already goes on as it is).
    Start(String),
}

/// What guards read about the world.
pub trait Senses {
    /// Whether `character` saw `thing` at its last look.
    fn sees(&self, character: &str, thing: &str) -> bool;
    /// How far `character` stands from `thing` (m, on the ground), if both exist.
    fn distance(&self, character: &str, thing: &str) -> Option<f32>;
    /// Whether progress `id` of `character` (any character when `None`) was reported.
    fn reached(&self, character: Option<&str>, id: &str) -> bool;
}

/// What one step of the nets asks for.
#[derive(Debug, Default, Clone, PartialEq)]
pub struct Step {
    /// BML to perform: the net's character and the block's text, in net order.
    pub bml: Vec<(Option<String>, String)>,
    /// Transitions and variable changes to report.
    pub feedback: Vec<WorldFeedback>,
}

/// Every net and the world variables.
#[derive(Debug, Clone)]
pub struct Nets {
    nets: Vec<Net>,
    /// Per net: its state and when it entered it (`None`: not started).
    running: Vec<Option<(usize, f64)>>,
    variables: BTreeMap<String, VarValue>,
    /// Whether the nets have stepped yet (those running from the start enter their first
    /// state at the first step).
    begun: bool,
}

impl Nets {
    /// `nets` (as [`file::read`] checked them) over world variables starting at `variables`.
    pub fn new(nets: Vec<Net>, variables: BTreeMap<String, VarValue>) -> Nets {
        Nets {
            running: vec![None; nets.len()],
            nets,
            variables,
            begun: false,
        }
    }

    /// The nets.
    pub fn nets(&self) -> &[Net] {
        &self.nets
    }

    /// The state net `name` is in, if it runs.
    pub fn state(&self, name: &str) -> Option<&str> {
        let i = self.nets.iter().position(|n| n.name == name)?;
        let (s, _) = self.running[i]?;
        Some(&self.nets[i].states[s])
    }

    /// The world variables.
    pub fn variables(&self) -> &BTreeMap<String, VarValue> {
        &self.variables
    }

    /// Whether any guard reads what characters see.
    pub fn use_sight(&self) -> bool {
        fn sees(g: &Guard) -> bool {
            match g {
                Guard::Sees(_) => true,
                Guard::All(gs) | Guard::Any(gs) => gs.iter().any(sees),
                Guard::Not(g) => sees(g),
                _ => false,
            }
        }
        (self.nets.iter()).any(|n| n.transitions.iter().any(|t| sees(&t.when)))
    }

    /// Whether a running net can still change state (it then wants to be stepped every
    /// frame).
    pub fn active(&self) -> bool {
        !self.begun
            || (self.running.iter().zip(&self.nets))
                .any(|(r, n)| r.is_some_and(|(s, _)| n.transitions.iter().any(|t| t.from == s)))
    }

    /// One step at `now`: every running net tries the transitions from its state (guards read
    /// `senses` and the variables as they were), then the actions take effect together.
    pub fn step(&mut self, now: f64, senses: &dyn Senses) -> Step {
        if !self.begun {
            self.begun = true;
            for (r, n) in self.running.iter_mut().zip(&self.nets) {
                if !n.waits {
                    *r = Some((0, now));
                }
            }
        }
        let mut step = Step::default();
        let mut sets: Vec<(String, VarValue)> = Vec::new();
        let mut starts: Vec<String> = Vec::new();
        for (i, net) in self.nets.iter().enumerate() {
            let Some((state, entered)) = self.running[i] else {
                continue;
            };
            let ctx = Context {
                net,
                entered,
                now,
                variables: &self.variables,
                senses,
            };
            let Some(t) = (net.transitions.iter()).find(|t| t.from == state && ctx.holds(&t.when))
            else {
                continue;
            };
            self.running[i] = Some((t.to, now));
            step.feedback.push(WorldFeedback::Net(NetFeedback {
                net: net.name.clone(),
                character_id: net.character.clone(),
                from: net.states[t.from].clone(),
                to: net.states[t.to].clone(),
                time: now,
            }));
            for a in &t.actions {
                match a {
                    Action::Bml(text) => step.bml.push((net.character.clone(), text.clone())),
                    Action::Set(name, value) => sets.push((name.clone(), value.clone())),
                    Action::Start(other) => starts.push(other.clone()),
                }
            }
        }
        for (name, value) in sets {
            if self.variables.get(&name) != Some(&value) {
                self.variables.insert(name.clone(), value.clone());
                step.feedback.push(WorldFeedback::Var(VarFeedback {
                    name,
                    value,
                    time: now,
                }));
            }
        }
        for name in starts {
            if let Some(i) = self.nets.iter().position(|n| n.name == name) {
                if self.running[i].is_none() {
                    self.running[i] = Some((0, now));
                }
            }
        }
        step
    }
}

/// What a net's guards are evaluated against.
struct Context<'a> {
    net: &'a Net,
    entered: f64,
    now: f64,
    variables: &'a BTreeMap<String, VarValue>,
    senses: &'a dyn Senses,
}

impl Context<'_> {
    fn holds(&self, g: &Guard) -> bool {
        let character = self.net.character.as_deref();
        match g {
            Guard::After(s) => self.now - self.entered >= s - 1e-9,
            Guard::Sync(id) => self.senses.reached(character, id),
            Guard::Sees(x) => character.is_some_and(|c| self.senses.sees(c, x)),
            Guard::Near(x, m) => character
                .and_then(|c| self.senses.distance(c, x))
                .is_some_and(|d| d <= *m),
            Guard::Var(name, v) => self.variables.get(name) == Some(v),
            Guard::All(gs) => gs.iter().all(|g| self.holds(g)),
            Guard::Any(gs) => gs.iter().any(|g| self.holds(g)),
            Guard::Not(g) => !self.holds(g),
        }
    }
}

#[cfg(test)]
mod tests;
