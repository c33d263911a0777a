//! What the broker tests share: a mosquitto started on a free loopback port, realizer
//! processes killed when dropped, and planners built on `bml_realizer::ports::broker::Link`.
#![allow(dead_code)]

use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use bml_realizer::ports::broker::{BrokerUrl, Inbound, Link, LinkOptions};

pub const NS: &str = r#"xmlns="http://www.bml-initiative.org/bml/bml-1.0""#;

// (the mosquitto starter is its own file, so that the examples can share it too)
#[path = "mosquitto.rs"]
mod mosquitto;
#[allow(unused_imports)] // (free_port: not every test that shares this kit needs it)
pub use mosquitto::{free_port, Broker};

/// A realizer process, killed when dropped (also when a test fails).
pub struct Served(pub Child);

impl Served {
    pub fn kill(&mut self) -> std::io::Result<()> {
        self.0.kill()
    }

    pub fn wait(&mut self) -> std::io::Result<std::process::ExitStatus> {
        self.0.wait()
    }
}

impl Drop for Served {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// A realizer serving `characters` (all when empty) on the broker, as `name`.
pub fn realizer(broker: &Broker, name: &str, characters: &[&str], extra: &[&str]) -> Served {
    let url = broker.url();
    let mut args = vec!["serve", "--mqtt", &url, "--name", name];
    let list = characters.join(",");
    if !characters.is_empty() {
        args.extend(["--characters", &list]);
    }
    args.extend(extra);
    Served(
        Command::new(env!("CARGO_BIN_EXE_bmlr"))
            .args(&args)
            .stdout(Stdio::null())
            .stderr(Stdio::inherit())
            .spawn()
            .expect("bmlr runs"),
    )
}

/// A planner: a link subscribed to every feedback and presence topic.
pub fn planner(broker: &Broker, id: &str) -> Link {
    planner_on(broker, id, &["bml/+/feedback", "bml/realizers/+"])
}

/// A planner subscribed to `topics`.
pub fn planner_on(broker: &Broker, id: &str, topics: &[&str]) -> Link {
    Link::connect(LinkOptions {
        url: BrokerUrl::parse(&broker.url()).unwrap(),
        client_id: id.into(),
        subscriptions: topics.iter().map(|t| t.to_string()).collect(),
        presence: None,
        inbox: 100_000,
        start_tries: 3,
    })
    .expect("the planner connects")
}

/// Everything `link` hears for `secs`, or until `done` says so.
pub fn hear(
    link: &Link,
    secs: f64,
    done: impl Fn(&[(String, String)]) -> bool,
) -> Vec<(String, String)> {
    let until = Instant::now() + Duration::from_secs_f64(secs);
    let mut heard = Vec::new();
    while Instant::now() < until && !done(&heard) {
        if let Some(Inbound::Message { topic, payload }) =
            link.recv_timeout(Duration::from_millis(20))
        {
            heard.push((topic, String::from_utf8_lossy(&payload).into_owned()));
        }
    }
    heard
}

/// Waits until every realizer of `names` has said it is online (fails the test if one does not
/// within 10 s).
pub fn until_online(link: &Link, names: &[&str]) {
    let all = |h: &[(String, String)]| names.iter().all(|n| online(h, n, "online"));
    let heard = hear(link, 10.0, all);
    assert!(all(&heard), "not all of {names:?} online: {heard:?}");
}

pub fn online(heard: &[(String, String)], name: &str, state: &str) -> bool {
    let topic = format!("bml/realizers/{name}");
    heard.iter().any(|(t, p)| *t == topic && p == state)
}

pub fn ended(heard: &[(String, String)], character: &str, block: &str) -> bool {
    let topic = format!("bml/{character}/feedback");
    let id = format!(r#"id="{block}:end""#);
    heard
        .iter()
        .any(|(t, p)| *t == topic && p.contains("blockProgress") && p.contains(&id))
}

pub fn block(id: &str) -> String {
    format!(r#"<bml {NS} id="{id}"><head id="h" lexeme="NOD" start="0" end="0.3"/></bml>"#)
}

/// The Python named by `$var` (else `python3`) if it can import `module`: the peers' libraries
/// are installed in a venv for the tests (`.ci/run` makes one).
pub fn python_with(var: &str, module: &str) -> Option<String> {
    let python = std::env::var(var).unwrap_or_else(|_| "python3".into());
    let ok = Command::new(&python)
        .args(["-c", &format!("import {module}")])
        .output()
        .is_ok_and(|o| o.status.success());
    ok.then_some(python)
}

/// Runs the peer `script` (in tests/peers/, printing `ok …` per check and `N failed` at the
/// end) with `python` against the broker at `address`: it must pass, with at least `checks`
/// checks. `who` names the peer in messages.
pub fn run_peer(python: &str, script: &str, address: &str, who: &str, checks: usize) {
    let peer = format!("{}/tests/peers/{script}", env!("CARGO_MANIFEST_DIR"));
    let out = Command::new(python)
        .args([&peer, address])
        .output()
        .expect("the peer runs");
    let said = String::from_utf8_lossy(&out.stdout);
    eprintln!("{said}{}", String::from_utf8_lossy(&out.stderr));
    assert!(
        out.status.success(),
        "the {who} peer's checks failed:\n{said}"
    );
    assert!(
        said.contains("0 failed") && said.matches("ok ").count() >= checks,
        "{said}"
    );
}
