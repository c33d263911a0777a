//! The source's floors (`docs/architecture.md`) kept: no code of a floor uses a floor above it,
//! and no two rooms of a floor use each other. Read from the source as text: every `crate::`
//! path outside tests and comments is an arrow from the room of its file to the room it names.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The floors, from the bottom up.
const FLOORS: [&str; 7] = [
    "language",
    "character",
    "planning",
    "world",
    "engines",
    "realizer",
    "ports",
];

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The code of a file without its comments, its test module and the one-release aliases of
/// old paths (`#[doc(hidden)] pub use`), which are names, not uses.
fn code(text: &str) -> String {
    let text = match text.find("#[cfg(test)]\nmod tests {") {
        Some(i) => &text[..i],
        None => text,
    };
    let mut out = String::new();
    let mut hidden = false;
    for line in text.lines() {
        let line = line.split("//").next().unwrap_or("");
        if line.trim() == "#[doc(hidden)]" {
            hidden = true;
            continue;
        }
        if hidden && line.trim_start().starts_with("pub use") {
            hidden = !line.contains(';');
            continue;
        }
        hidden = false;
        out.push_str(line);
        out.push('\n');
    }
    out
}

/// The room a module path names: its floor and the room in it (`world/crowd`), or the floor
/// alone where the path names the floor's own module.
fn room(src: &Path, parts: &[&str]) -> Option<String> {
    let floor = *parts.first()?;
    if !FLOORS.contains(&floor) {
        return None;
    }
    match parts.get(1).filter(|r| **r != "mod") {
        Some(r)
            if src.join(floor).join(r).is_dir()
                || src.join(floor).join(format!("{r}.rs")).is_file() =>
        {
            Some(format!("{floor}/{r}"))
        }
        _ => Some(floor.to_string()),
    }
}

/// Every module path in `text` that starts at the crate (`crate::a::b`, 0) or climbs from the
/// file's module (`super::super::a`, 2), with how far it climbs.
fn paths(text: &str) -> Vec<(Vec<&str>, usize)> {
    let word = |c: char| c.is_alphanumeric() || c == '_' || c == ':';
    let mut out = Vec::new();
    for (i, _) in text.match_indices("crate::") {
        let before = text[..i].chars().next_back();
        if before.is_some_and(|c| c.is_alphanumeric() || c == '_' || c == '$') {
            continue;
        }
        let rest = &text[i + "crate::".len()..];
        let path = rest.split(|c: char| !word(c)).next().unwrap_or("");
        out.push((path.split("::").collect(), 0));
    }
    for (i, _) in text.match_indices("super::") {
        let before = text[..i].chars().next_back();
        if before.is_some_and(|c| c.is_alphanumeric() || c == '_' || c == ':') {
            continue;
        }
        let rest = &text[i..];
        let path = rest.split(|c: char| !word(c)).next().unwrap_or("");
        let parts: Vec<&str> = path.split("::").collect();
        let supers = parts.iter().take_while(|p| **p == "super").count();
        out.push((parts[supers..].to_vec(), supers));
    }
    out
}

/// Every arrow: (from room, to room) → the files it is in.
fn arrows(src: &Path) -> BTreeMap<(String, String), BTreeSet<String>> {
    let mut files = Vec::new();
    rust_files(src, &mut files);
    let mut arrows = BTreeMap::<(String, String), BTreeSet<String>>::new();
    for file in files {
        let rel = file.strip_prefix(src).unwrap();
        let parts: Vec<&str> = rel.iter().map(|p| p.to_str().unwrap()).collect();
        if parts[0] == "bin" || parts.last() == Some(&"tests.rs") {
            continue;
        }
        let module: Vec<&str> = parts.iter().map(|p| p.trim_end_matches(".rs")).collect();
        let Some(from) = room(src, &module) else {
            continue;
        };
        let text = code(&std::fs::read_to_string(&file).unwrap());
        // the module the file is (a `mod.rs` is its folder's), for `super::` paths
        let here = match module.split_last() {
            Some((&"mod", folder)) => folder,
            _ => &module[..],
        };
        for (path, supers) in paths(&text) {
            // `crate::` paths start at the root, `super::` ones that many modules up from here
            let base = match supers {
                0 => &[][..],
                n => &here[..here.len().saturating_sub(n)],
            };
            let full: Vec<&str> = base.iter().copied().chain(path).collect();
            if let Some(to) = room(src, &full) {
                if to != from {
                    let at = rel.display().to_string();
                    arrows.entry((from.clone(), to)).or_default().insert(at);
                }
            }
        }
    }
    arrows
}

fn floor_of(room: &str) -> usize {
    let floor = room.split('/').next().unwrap();
    FLOORS.iter().position(|f| *f == floor).unwrap()
}

#[test]
fn no_floor_uses_a_floor_above_it() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let up: Vec<String> = arrows(&src)
        .into_iter()
        .filter(|((from, to), _)| floor_of(to) > floor_of(from))
        .map(|((from, to), files)| format!("{from} → {to} in {files:?}"))
        .collect();
    assert!(up.is_empty(), "arrows up a floor:\n{}", up.join("\n"));
}

#[test]
fn no_two_rooms_use_each_other() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let arrows = arrows(&src);
    let both: Vec<String> = (arrows.keys())
        .filter(|(from, to)| from < to && arrows.contains_key(&(to.clone(), from.clone())))
        .map(|(a, b)| format!("{a} ↔ {b}"))
        .collect();
    assert!(
        both.is_empty(),
        "rooms that use each other:\n{}",
        both.join("\n")
    );
}

#[test]
fn the_reading_finds_an_arrow_up_and_a_circle() {
    // a made-up tree: the character floor naming the world, the world naming the character
    let dir = std::env::temp_dir().join(format!("bmlr-layers-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("character/body")).unwrap();
    std::fs::create_dir_all(dir.join("world/space")).unwrap();
    std::fs::write(
        dir.join("character/body/mod.rs"),
        "use crate::world::space::Obstacles;\n// crate::ports::x in a comment\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("world/space/mod.rs"),
        "use crate::character::body::Pose;\n#[doc(hidden)]\npub use crate::ports::old;\n",
    )
    .unwrap();
    let found = arrows(&dir);
    let _ = std::fs::remove_dir_all(&dir);
    let keys: Vec<(String, String)> = found.into_keys().collect();
    assert_eq!(
        keys,
        [
            ("character/body".to_string(), "world/space".to_string()),
            ("world/space".to_string(), "character/body".to_string()),
        ]
    );
}
