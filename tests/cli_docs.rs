//! Every `sh` example in `docs/cli.md` runs, and its output contains the lines shown, in order
//! (`...` stands for lines left out). Commands run from the repository root with `bmlr` on the
//! PATH; stdout and stderr are read together.

use std::process::Command;

const DOC: &str = include_str!("../docs/cli.md");

/// (command, expected lines) of every `$ ` line in every `sh` block.
fn examples() -> Vec<(String, Vec<String>)> {
    let mut out = Vec::new();
    let mut in_sh = false;
    for line in DOC.lines() {
        if line.starts_with("```") {
            in_sh = line == "```sh";
            continue;
        }
        if !in_sh {
            continue;
        }
        if let Some(cmd) = line.strip_prefix("$ ") {
            out.push((cmd.to_string(), Vec::new()));
        } else if let Some((_, expected)) = out.last_mut() {
            expected.push(line.to_string());
        }
    }
    out
}

#[test]
fn every_cli_example_gives_the_output_shown() {
    let bin = std::path::Path::new(env!("CARGO_BIN_EXE_bmlr"));
    let path = format!(
        "{}:{}",
        bin.parent().unwrap().display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let examples = examples();
    assert!(examples.len() >= 12, "{}", examples.len());
    for (cmd, expected) in examples {
        let out = Command::new("sh")
            .arg("-c")
            .arg(format!("{cmd} 2>&1"))
            .env("PATH", &path)
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .output()
            .unwrap();
        let text = String::from_utf8_lossy(&out.stdout);
        let mut lines = text.lines();
        for e in expected.iter().filter(|e| e.as_str() != "...") {
            assert!(
                lines.any(|l| l.starts_with(e.as_str())),
                "`{cmd}`: expected a line starting with\n{e}\nin order in\n{text}"
            );
        }
    }
}
