//! The nets file (`--nets NETS.json`): PaT-Nets as data, read and checked before anything runs.
//! Every error names the field it is about: a transition to a state the net does not have, a
//! guard or action that is not one of the known ones, BML that cannot be read, a guard that
//! needs the net's character in a world-level net, a cycle of nets starting each other.

use std::collections::BTreeMap;

use serde::Deserialize;

use super::{Action, Guard, Net, Transition};
use crate::language::feedback::world::VarValue;

/// Most nets a file may hold, states a net may have, transitions and actions.
pub const MAX_NETS: usize = 10_000;
/// Most states or transitions of one net.
pub const MAX_STATES: usize = 1_000;
/// Deepest nesting of `all`/`any`/`not`.
pub const MAX_GUARD_DEPTH: usize = 32;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct NetsFile {
    nets: BTreeMap<String, NetFile>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct NetFile {
    #[serde(default)]
    character: Option<String>,
    states: Vec<String>,
    #[serde(default)]
    transitions: Vec<TransitionFile>,
    /// Whether it waits for another net to start it (it runs from the start otherwise).
    #[serde(default)]
    waits: bool,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct TransitionFile {
    from: String,
    to: String,
    when: GuardFile,
    #[serde(default, rename = "do")]
    actions: Vec<ActionFile>,
}

#[derive(Deserialize)]
#[serde(rename_all = "lowercase", deny_unknown_fields)]
enum GuardFile {
    After(f64),
    Sync(String),
    Sees(String),
    Near((String, f64)),
    Var((String, VarValue)),
    All(Vec<GuardFile>),
    Any(Vec<GuardFile>),
    Not(Box<GuardFile>),
}

#[derive(Deserialize)]
#[serde(rename_all = "lowercase", deny_unknown_fields)]
enum ActionFile {
    Bml(String),
    Set((String, VarValue)),
    Net(String),
}

/// Reads and checks a nets file; the error names the field.
pub fn read(text: &str, limits: &crate::language::bml::Limits) -> Result<Vec<Net>, String> {
    let file: NetsFile = crate::data::from_json(text)?;
    if file.nets.len() > MAX_NETS {
        return Err(format!(
            "nets: at most {MAX_NETS} nets, not {}",
            file.nets.len()
        ));
    }
    let mut nets = Vec::new();
    for (name, n) in &file.nets {
        nets.push(net(name, n, limits).map_err(|e| format!("nets.{name}.{e}"))?)
    }
    check_starts(&nets)?;
    Ok(nets)
}

fn net(name: &str, n: &NetFile, limits: &crate::language::bml::Limits) -> Result<Net, String> {
    if n.states.is_empty() || n.states.len() > MAX_STATES {
        return Err(format!("states: 1 to {MAX_STATES} states"));
    }
    if n.transitions.len() > MAX_STATES {
        return Err(format!("transitions: at most {MAX_STATES}"));
    }
    let state = |field: String, s: &str| -> Result<usize, String> {
        (n.states.iter().position(|x| x == s)).ok_or_else(|| {
            format!(
                "{field}: '{s}' is not one of its states ({})",
                n.states.join(", ")
            )
        })
    };
    let mut transitions = Vec::new();
    for (i, t) in n.transitions.iter().enumerate() {
        let at = format!("transitions[{i}]");
        let from = state(format!("{at}.from"), &t.from)?;
        let to = state(format!("{at}.to"), &t.to)?;
        let when = guard(&t.when, n.character.is_some(), 0).map_err(|e| format!("{at}.when{e}"))?;
        let mut actions = Vec::new();
        for (k, a) in t.actions.iter().enumerate() {
            let field = format!("{at}.do[{k}]");
            actions.push(match a {
                ActionFile::Bml(text) => {
                    let checked = crate::language::bml::Checked::new(text, limits);
                    if !checked.is_valid() {
                        let why: Vec<String> = (checked.diagnostics.iter())
                            .filter(|d| d.is_error())
                            .map(|d| d.message.clone())
                            .collect();
                        return Err(format!("{field}.bml: not a BML block: {}", why.join("; ")));
                    }
                    let named = checked.block.as_ref().and_then(|b| b.character_id.clone());
                    if n.character.is_none() && named.is_none() {
                        return Err(format!(
                            "{field}.bml: a world-level net sends BML only with a characterId"
                        ));
                    }
                    Action::Bml(text.clone())
                }
                ActionFile::Set((var, value)) => Action::Set(var.clone(), value.clone()),
                ActionFile::Net(other) => Action::Start(other.clone()),
            });
        }
        transitions.push(Transition {
            from,
            to,
            when,
            actions,
        });
    }
    Ok(Net {
        name: name.to_string(),
        character: n.character.clone(),
        states: n.states.clone(),
        transitions,
        waits: n.waits,
    })
}

fn guard(g: &GuardFile, has_character: bool, depth: usize) -> Result<Guard, String> {
    if depth > MAX_GUARD_DEPTH {
        return Err(format!(": nested deeper than {MAX_GUARD_DEPTH}"));
    }
    let needs = |key: &str, what: &str| -> Result<(), String> {
        if has_character {
            Ok(())
        } else {
            Err(format!(
                ".{key}: a world-level net has no character to {what}"
            ))
        }
    };
    let list = |gs: &[GuardFile], key: &str| -> Result<Vec<Guard>, String> {
        (gs.iter().enumerate())
            .map(|(i, g)| guard(g, has_character, depth + 1).map_err(|e| format!(".{key}[{i}]{e}")))
            .collect()
    };
    Ok(match g {
        GuardFile::After(s) if !(s.is_finite() && *s >= 0.0) => {
            return Err(format!(".after: {s} is not a duration in seconds"))
        }
        GuardFile::After(s) => Guard::After(*s),
        GuardFile::Sync(id) => {
            let parts = id.split(':').count();
            if !(2..=3).contains(&parts) || id.split(':').any(str::is_empty) {
                return Err(format!(
                    ".sync: '{id}' is not block:sync or block:behaviour:sync"
                ));
            }
            Guard::Sync(id.clone())
        }
        GuardFile::Sees(x) => {
            needs("sees", "see")?;
            Guard::Sees(x.clone())
        }
        GuardFile::Near((x, m)) => {
            needs("near", "be near")?;
            if !(m.is_finite() && *m >= 0.0) {
                return Err(format!(".near: {m} is not a distance in metres"));
            }
            Guard::Near(x.clone(), *m as f32)
        }
        GuardFile::Var((name, value)) => Guard::Var(name.clone(), value.clone()),
        GuardFile::All(gs) => Guard::All(list(gs, "all")?),
        GuardFile::Any(gs) => Guard::Any(list(gs, "any")?),
        GuardFile::Not(g) => Guard::Not(Box::new(
            guard(g, has_character, depth + 1).map_err(|e| format!(".not{e}"))?,
        )),
    })
}

/// Every net a `net` action starts exists, and no nets start each other in a cycle.
fn check_starts(nets: &[Net]) -> Result<(), String> {
    let index: BTreeMap<&str, usize> = (nets.iter().enumerate())
        .map(|(i, n)| (n.name.as_str(), i))
        .collect();
    let mut graph = petgraph::graphmap::DiGraphMap::<usize, ()>::new();
    for (i, n) in nets.iter().enumerate() {
        graph.add_node(i);
        for (t, tr) in n.transitions.iter().enumerate() {
            for (k, a) in tr.actions.iter().enumerate() {
                if let Action::Start(other) = a {
                    let Some(&j) = index.get(other.as_str()) else {
                        return Err(format!(
                            "nets.{}.transitions[{t}].do[{k}].net: there is no net '{other}'",
                            n.name
                        ));
                    };
                    graph.add_edge(i, j, ());
                }
            }
        }
    }
    if let Err(cycle) = petgraph::algo::toposort(&graph, None) {
        let names: Vec<&str> = (cycle_through(&graph, cycle.node_id()).into_iter())
            .map(|i| nets[i].name.as_str())
            .collect();
        return Err(match names.as_slice() {
            [n] | [n, _] => format!("nets.{n}: the net starts itself (a cycle of one)"),
            _ => format!(
                "nets.{}: nets start each other in a cycle: {}",
                names[0],
                names.join(" → ")
            ),
        });
    }
    Ok(())
}

/// The shortest cycle from `start` back to it: its nodes in order, `start` first and last
/// (just `start` if it lies on none).
fn cycle_through(graph: &petgraph::graphmap::DiGraphMap<usize, ()>, start: usize) -> Vec<usize> {
    let back = |from: usize| petgraph::algo::astar(graph, from, |n| n == start, |_| 1, |_| 0);
    (graph.neighbors(start).filter_map(back))
        .min_by_key(|(steps, _)| *steps)
        .map_or(vec![start], |(_, path)| {
            std::iter::once(start).chain(path).collect()
        })
}
