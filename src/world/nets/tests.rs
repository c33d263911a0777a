//! Reading nets files and stepping nets against a made-up world.

use super::*;

struct World {
    seen: Vec<(&'static str, &'static str)>,
    reached: Vec<&'static str>,
}

impl Senses for World {
    fn sees(&self, c: &str, x: &str) -> bool {
        self.seen.iter().any(|(a, b)| *a == c && *b == x)
    }
    fn distance(&self, _: &str, _: &str) -> Option<f32> {
        Some(1.0)
    }
    fn reached(&self, _: Option<&str>, id: &str) -> bool {
        self.reached.contains(&id)
    }
}

fn read(text: &str) -> Result<Vec<Net>, String> {
    file::read(text, &crate::language::bml::Limits::default())
}

#[test]
fn bad_files_are_refused_naming_the_field() {
    let cases = [
        (
            r#"{"nets": {"a": {"states": ["x"], "transitions": [{"from": "x", "to": "y", "when": {"after": 1}}]}}}"#,
            "nets.a.transitions[0].to: 'y' is not one of its states",
        ),
        (
            r#"{"nets": {"a": {"states": ["x"], "transitions": [{"from": "x", "to": "x", "when": {"soon": 1}}]}}}"#,
            "unknown variant `soon`",
        ),
        (
            r#"{"nets": {"a": {"states": ["x"], "transitions": [{"from": "x", "to": "x", "when": {"after": 1}, "do": [{"net": "b"}]}]},
                     "b": {"states": ["x"], "waits": true, "transitions": [{"from": "x", "to": "x", "when": {"after": 1}, "do": [{"net": "a"}]}]}}}"#,
            "nets start each other in a cycle",
        ),
        (
            r#"{"nets": {"a": {"states": ["x"], "transitions": [{"from": "x", "to": "x", "when": {"sees": "b"}}]}}}"#,
            "nets.a.transitions[0].when.sees: a world-level net has no character to see",
        ),
        (
            r#"{"nets": {"a": {"character": "c", "states": ["x"], "transitions": [{"from": "x", "to": "x", "when": {"after": 0}, "do": [{"bml": "<bml"}]}]}}}"#,
            "nets.a.transitions[0].do[0].bml: not a BML block",
        ),
        (
            r#"{"nets": {"a": {"states": ["x"], "transitions": [{"from": "x", "to": "x", "when": {"after": 1}, "do": [{"net": "nope"}]}]}}}"#,
            "there is no net 'nope'",
        ),
        (r#"{"nets": {"a": {"states": []}}}"#, "nets.a.states"),
        (r#"{"nets": {"a": "#, "EOF"),
    ];
    for (text, expected) in cases {
        let e = read(text).unwrap_err();
        assert!(e.contains(expected), "{e}\n(expected {expected})");
    }
}

#[test]
fn a_cycle_of_nets_starting_each_other_is_named_whole() {
    let net = |name: &str, starts: &str| {
        format!(
            r#""{name}": {{"states": ["x"], "transitions": [{{"from": "x", "to": "x", "when": {{"after": 1}}, "do": [{{"net": "{starts}"}}]}}]}}"#
        )
    };
    let text = format!(
        r#"{{"nets": {{{}, {}, {}, {}}}}}"#,
        net("ping", "pong"),
        net("pong", "pang"),
        net("pang", "ping"),
        net("watcher", "ping")
    );
    let e = read(&text).unwrap_err();
    let ways = [
        "nets.ping: nets start each other in a cycle: ping → pong → pang → ping",
        "nets.pong: nets start each other in a cycle: pong → pang → ping → pong",
        "nets.pang: nets start each other in a cycle: pang → ping → pong → pang",
    ];
    assert!(ways.contains(&e.as_str()), "{e}");
    let alone = r#"{"nets": {"echo": {"states": ["x"], "transitions": [{"from": "x", "to": "x", "when": {"after": 1}, "do": [{"net": "echo"}]}]}}}"#;
    let e = read(alone).unwrap_err();
    assert_eq!(e, "nets.echo: the net starts itself (a cycle of one)");
}

#[test]
fn guards_read_the_frame_as_it_began_and_actions_take_effect_together() {
    // `b` waits for the variable `a` sets; it sees the change one step later, whatever the
    // order the nets are tried in
    for (first, second) in [("a", "b"), ("b", "a")] {
        let set = r#"{"states": ["s", "t"], "transitions": [{"from": "s", "to": "t", "when": {"after": 1}, "do": [{"set": ["go", true]}]}]}"#;
        let wait = r#"{"states": ["s", "t"], "transitions": [{"from": "s", "to": "t", "when": {"var": ["go", true]}}]}"#;
        let (na, nb) = if first == "a" {
            (set, wait)
        } else {
            (wait, set)
        };
        let text = format!(r#"{{"nets": {{"{first}": {na}, "{second}": {nb}}}}}"#);
        let mut nets = Nets::new(read(&text).unwrap(), BTreeMap::new());
        let w = World {
            seen: vec![],
            reached: vec![],
        };
        let setter = if first == "a" { first } else { second };
        let waiter = if first == "a" { second } else { first };
        nets.step(0.0, &w);
        let s = nets.step(1.0, &w);
        assert_eq!(nets.state(setter), Some("t"));
        assert_eq!(
            nets.state(waiter),
            Some("s"),
            "the change is seen only at the next step"
        );
        assert_eq!(s.feedback.len(), 2, "{s:?}");
        nets.step(1.1, &w);
        assert_eq!(nets.state(waiter), Some("t"));
    }
}

#[test]
fn sight_and_progress_guards_and_started_nets() {
    let text = r#"{"nets": {
        "look": {"character": "c", "states": ["idle", "looking"], "transitions": [
            {"from": "idle", "to": "looking", "when": {"all": [{"sees": "d"}, {"not": {"sync": "b1:end"}}]},
             "do": [{"bml": "<bml xmlns=\"http://www.bml-initiative.org/bml/bml-1.0\" id=\"g\"><gaze id=\"z\" target=\"d\"/></bml>"}, {"net": "later"}]}]},
        "later": {"states": ["a", "b"], "waits": true, "transitions": [{"from": "a", "to": "b", "when": {"after": 0.5}}]}}}"#;
    let mut nets = Nets::new(read(text).unwrap(), BTreeMap::new());
    let mut w = World {
        seen: vec![],
        reached: vec![],
    };
    assert!(nets.step(0.0, &w).bml.is_empty());
    assert_eq!(nets.state("later"), None);
    w.seen.push(("c", "d"));
    let s = nets.step(0.1, &w);
    assert_eq!(s.bml.len(), 1);
    assert_eq!(s.bml[0].0.as_deref(), Some("c"));
    assert_eq!(nets.state("later"), Some("a"));
    nets.step(0.5, &w);
    assert_eq!(nets.state("later"), Some("a"));
    nets.step(0.6, &w);
    assert_eq!(nets.state("later"), Some("b"));
    assert!(!nets.active(), "no transition leaves either net's state");
}
