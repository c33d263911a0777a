//! The repository stands on its own: code comments and docs cite nothing a reader of the
//! repository cannot see (design sections, requirement ids, spec files, issue numbers), and the
//! README lists every subcommand `bmlr --help` knows, and every code block of the README and docs
//! closes (so that they render).

use std::path::Path;

/// Every file under `dir` whose name ends in one of `exts`.
fn files(dir: &Path, exts: &[&str], out: &mut Vec<std::path::PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            files(&path, exts, out);
        } else if exts.iter().any(|e| path.to_string_lossy().ends_with(e)) {
            out.push(path);
        }
    }
}

/// Whether `line` names a requirement id such as S63 or A54: one of R, S, A, O and one to three
/// digits, standing alone.
fn has_requirement_id(line: &str) -> bool {
    let b = line.as_bytes();
    (0..b.len()).any(|i| {
        let alone_before = i == 0 || !b[i - 1].is_ascii_alphanumeric() && b[i - 1] != b'_';
        let digits = b[i + 1..].iter().take_while(|c| c.is_ascii_digit()).count();
        let alone_after = b
            .get(i + 1 + digits)
            .is_none_or(|c| !c.is_ascii_alphanumeric() && *c != b'_');
        alone_before && b"RSAO".contains(&b[i]) && (1..=3).contains(&digits) && alone_after
    })
}

#[test]
fn comments_and_docs_cite_only_what_the_repository_holds() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut paths = Vec::new();
    for dir in [
        "src",
        "tests",
        "benches",
        "realizer-tests/src",
        "docs",
        "bml-schemas",
        "examples",
    ] {
        files(&root.join(dir), &[".rs", ".md", ".xsd"], &mut paths);
    }
    paths.push(root.join("README.md"));
    // this file names such ids as examples of what it looks for
    paths.retain(|p| !p.ends_with("tests/repo_self_contained.rs"));
    let outside = [
        "DESIGN §",
        "DESIGN.md",
        "spec/",
        "shared/",
        "seeds/",
        "issue #",
    ];
    let mut found = Vec::new();
    for path in &paths {
        let text = std::fs::read_to_string(path).unwrap();
        let rust = path.extension().is_some_and(|e| e == "rs");
        for (n, line) in text.lines().enumerate() {
            // in Rust files only comments are prose; string literals may hold ids as data
            let prose = if rust {
                match line.find("//") {
                    Some(i) => &line[i..],
                    None => continue,
                }
            } else {
                line
            };
            if outside.iter().any(|o| prose.contains(o)) || has_requirement_id(prose) {
                found.push(format!("{}:{}: {}", path.display(), n + 1, line.trim()));
            }
        }
    }
    assert!(found.is_empty(), "{}", found.join("\n"));
}

#[test]
fn the_requirement_id_check_finds_ids_and_only_ids() {
    for (line, id) in [
        ("// the rule (S63)", true),
        ("/// A54: the predictor", true),
        ("// R33 ties", true),
        ("// s1_start and S-curves", false),
        ("// AS54 or S1234", false),
        ("// 3D and SVG", false),
    ] {
        assert_eq!(has_requirement_id(line), id, "{line}");
    }
}

#[test]
fn the_readme_lists_every_subcommand() {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_bmlr"))
        .arg("--help")
        .output()
        .unwrap();
    let help = String::from_utf8(out.stdout).unwrap();
    let readme = include_str!("../README.md");
    let commands: Vec<&str> = help
        .lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        .filter_map(|l| l.split_whitespace().next())
        .filter(|c| *c != "help")
        .collect();
    assert!(commands.len() >= 7, "{help}");
    for c in commands {
        assert!(
            readme.contains(&format!("`bmlr {c}")),
            "README lacks bmlr {c}"
        );
    }
    assert!(readme.contains("cargo install --path ."));
}

/// Where a Markdown file's fenced code blocks break: a closing fence with text after it (which
/// Markdown reads as no fence, so the rest of the file becomes code), or a block left open.
fn broken_fences(text: &str) -> Vec<String> {
    let mut open: Option<usize> = None;
    let mut broken = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let t = line.trim_start();
        if !t.starts_with("```") {
            continue;
        }
        match open {
            None => open = Some(n + 1),
            Some(_) if t.trim_end() == "```" => open = None,
            Some(from) => {
                broken.push(format!(
                    "line {}: a closing fence with text after it (block from line {from})",
                    n + 1
                ));
                open = None;
            }
        }
    }
    if let Some(from) = open {
        broken.push(format!("the block from line {from} never closes"));
    }
    broken
}

#[test]
fn every_code_block_of_the_readme_and_docs_closes() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut md = vec![root.join("README.md")];
    files(&root.join("docs"), &["md"], &mut md);
    let mut bad = Vec::new();
    for path in md {
        let text = std::fs::read_to_string(&path).unwrap();
        for b in broken_fences(&text) {
            bad.push(format!("{}: {b}", path.display()));
        }
    }
    assert!(bad.is_empty(), "{bad:#?}");
    // the check itself: the form the README once had
    assert_eq!(broken_fences("```rust\nx\n``` See docs.\n").len(), 1);
    assert!(broken_fences("```\nx\n```\n").is_empty());
}
