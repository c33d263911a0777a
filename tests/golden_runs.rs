//! Realizations that must not change unnoticed: `bmlr run` of every documented example (in the
//! example world) and of every RealizerTester core file, and `bmlr plan` of each core file,
//! compared byte for byte with the logs in `fixtures/runs/`. A refactoring keeps them; an
//! intended change rewrites them with `BMLR_BLESS=1 cargo test --test golden_runs`, and the diff
//! of the logs goes into its commit for review.

mod common;
use common::bmlr;

use std::path::Path;

/// Compares (or, blessing, writes) the log `name` with what `args` print.
fn check(name: &str, args: &[&str], failures: &mut Vec<String>) {
    let (code, out, err) = bmlr(args, "");
    let got = format!("{out}exit {code}\n");
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fixtures/runs")
        .join(name);
    if std::env::var_os("BMLR_BLESS").is_some() {
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(&path, &got).unwrap();
        return;
    }
    let want = std::fs::read_to_string(&path).unwrap_or_default();
    if got != want {
        let line = got
            .lines()
            .zip(want.lines())
            .position(|(a, b)| a != b)
            .map_or(got.lines().count().min(want.lines().count()), |i| i);
        failures.push(format!(
            "{name} ({}) differs from line {}:\n  now:  {}\n  log:  {}\n{err}",
            args.join(" "),
            line + 1,
            got.lines().nth(line).unwrap_or("(end)"),
            want.lines().nth(line).unwrap_or("(end)"),
        ));
    }
}

/// The `.xml` files of `dir`, sorted.
fn xml_files(dir: &str) -> Vec<String> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files: Vec<String> = std::fs::read_dir(root.join(dir))
        .unwrap()
        .filter_map(|e| {
            let name = e.ok()?.file_name().to_string_lossy().into_owned();
            name.ends_with(".xml").then(|| format!("{dir}/{name}"))
        })
        .collect();
    files.sort();
    files
}

/// The world an example is written for: the one its comment names ("with room.json"), else the
/// example world.
fn example_world(path: &str) -> String {
    let text = std::fs::read_to_string(path).unwrap_or_default();
    let named = text.split("with ").nth(1).and_then(|rest| {
        let word = rest.split(|c: char| c.is_whitespace() || c == ':').next()?;
        word.ends_with(".json").then(|| word.to_string())
    });
    format!(
        "fixtures/examples/{}",
        named.as_deref().unwrap_or("world.json")
    )
}

fn stem(path: &str) -> &str {
    let name = path.rsplit('/').next().unwrap_or(path);
    name.strip_suffix(".xml").unwrap_or(name)
}

#[test]
fn the_examples_realize_as_logged() {
    let mut failures = Vec::new();
    for f in xml_files("fixtures/examples") {
        let world = example_world(&f);
        let args = ["run", f.as_str(), "--world", world.as_str()];
        check(
            &format!("examples/{}.xml.log", stem(&f)),
            &args,
            &mut failures,
        );
        let args = ["run", "--format", "jsonl", f.as_str()];
        check(
            &format!("examples/{}.jsonl", stem(&f)),
            &args,
            &mut failures,
        );
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn the_realizertester_core_files_realize_and_plan_as_logged() {
    let mut failures = Vec::new();
    for f in xml_files("fixtures/realizertester/bml-1/core") {
        check(
            &format!("core/{}.xml.log", stem(&f)),
            &["run", &f],
            &mut failures,
        );
        check(
            &format!("core/{}.plan", stem(&f)),
            &["plan", &f],
            &mut failures,
        );
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
