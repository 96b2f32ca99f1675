//! The crate's layers hold: every import points down the list in `crate/lib.rs` (`## Layers`),
//! and no two top-level modules import each other (directly or round a longer circle).
//!
//! A module is a top-level unit of `crate/`: a file `crate/x.rs` or a folder `crate/x/`. An
//! import is any path `crate::x…` (or `$crate::x…` in a macro, or `crate::{x…, y…}`) outside
//! comments and string literals; `super::` never leaves a unit. Names the crate root re-exports
//! (`crate::Error`, `crate::Mode`, …) count as imports of the module they come from.
//!
//! `LAYERS_CRATE=/path/to/crate [LAYERS_LIST=/path/to/list.rs] cargo test --test layers --
//! --nocapture` checks another tree (against another list): how the report on the tree before
//! the moves was made.
#![cfg(not(target_arch = "wasm32"))]

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The layers, top (ground) first: each a name and its modules.
fn parse_layers(lib_rs: &str) -> Result<Vec<(String, Vec<String>)>, String> {
    let doc: Vec<&str> = lib_rs
        .lines()
        .filter_map(|l| l.trim_start().strip_prefix("//!"))
        .map(str::trim)
        .collect();
    let start = doc
        .iter()
        .position(|l| *l == "## Layers")
        .ok_or("crate/lib.rs has no `## Layers` section")?;
    let open = start
        + doc[start..]
            .iter()
            .position(|l| l.starts_with("```"))
            .ok_or("the `## Layers` section has no ``` block")?;
    let mut layers = Vec::new();
    for line in &doc[open + 1..] {
        if line.starts_with("```") {
            return Ok(layers);
        }
        let mut words = line.split_whitespace();
        if let Some(name) = words.next() {
            layers.push((name.to_string(), words.map(String::from).collect()));
        }
    }
    Err("the `## Layers` block is not closed".into())
}

/// `source` without comments and the contents of string literals (kept: line breaks).
fn code_only(source: &str) -> String {
    let b = source.as_bytes();
    let mut out = String::with_capacity(source.len());
    let mut i = 0;
    while i < b.len() {
        let rest = &source[i..];
        if rest.starts_with("//") {
            let end = rest.find('\n').map_or(b.len(), |n| i + n);
            i = end;
        } else if let Some(body) = rest.strip_prefix("/*") {
            let end = body.find("*/").map_or(b.len(), |n| i + 2 + n + 2);
            out.extend(source[i..end].chars().filter(|&c| c == '\n'));
            i = end;
        } else if rest.starts_with("'\"'") {
            i += 3;
        } else if b[i] == b'"' || rest.starts_with("r#\"") {
            let (close, skip) = if b[i] == b'"' { ("\"", 1) } else { ("\"#", 3) };
            let mut j = i + skip;
            while j < b.len() && !b[j..].starts_with(close.as_bytes()) {
                if b[j] == b'\\' && close == "\"" {
                    j += 1;
                }
                if b.get(j) == Some(&b'\n') {
                    out.push('\n');
                }
                j += 1;
            }
            out.push_str("\"\"");
            i = (j + close.len()).min(b.len());
        } else {
            let c = rest.chars().next().unwrap_or(' ');
            out.push(c);
            i += c.len_utf8();
        }
    }
    out
}

fn ident(s: &str) -> &str {
    let end = s
        .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
        .unwrap_or(s.len());
    &s[..end]
}

/// The first path segments after each `crate::` in `code`, with their line numbers.
fn crate_paths(code: &str) -> Vec<(usize, String)> {
    let mut found = Vec::new();
    for (n, line) in code.lines().enumerate() {
        let mut rest = line;
        while let Some(at) = rest.find("crate::") {
            let before = rest[..at].chars().next_back();
            rest = &rest[at + "crate::".len()..];
            if before.is_some_and(|c| c.is_ascii_alphanumeric() || c == '_') {
                continue; // `input_crate::…` and the like
            }
            if let Some(group) = rest.strip_prefix('{') {
                // `crate::{a::b, c}`: the first segment of each top-level item.
                let mut depth = 0;
                let mut item_start = true;
                for (k, c) in group.char_indices() {
                    match c {
                        '{' => depth += 1,
                        '}' if depth == 0 => break,
                        '}' => depth -= 1,
                        ',' if depth == 0 => item_start = true,
                        c if item_start && (c.is_ascii_alphabetic() || c == '_') => {
                            found.push((n + 1, ident(&group[k..]).to_string()));
                            item_start = false;
                        }
                        _ => {}
                    }
                }
            } else {
                let name = ident(rest);
                if !name.is_empty() {
                    found.push((n + 1, name.to_string()));
                }
            }
        }
    }
    found
}

/// Names the crate root brings in with `use m::…` (re-exports and aliases) → module `m`.
fn root_names(lib_rs: &str) -> BTreeMap<String, String> {
    let code = code_only(lib_rs);
    let mut names = BTreeMap::new();
    for stmt in code.split(';') {
        let stmt = stmt.trim();
        let Some(path) = stmt
            .strip_prefix("pub use ")
            .or_else(|| stmt.strip_prefix("use "))
            .or_else(|| stmt.rsplit_once("\nuse ").map(|(_, p)| p))
            .or_else(|| stmt.rsplit_once("\npub use ").map(|(_, p)| p))
        else {
            continue;
        };
        let module = ident(path).to_string();
        let Some(tail) = path[module.len()..].strip_prefix("::") else {
            continue;
        };
        let items = tail.trim_start_matches('{').trim_end_matches('}');
        for item in items.split(',') {
            let name = match item.split_once(" as ") {
                Some((_, alias)) => alias.trim(),
                None => item.trim().rsplit("::").next().unwrap_or(""),
            };
            if !name.is_empty() {
                names.insert(name.to_string(), module.clone());
            }
        }
    }
    names
}

/// Every violation of `layers` by `files` (path relative to `crate/`, source). `lib_rs` is the
/// crate root (its re-exports resolve `crate::Name`).
fn check(
    layers: &[(String, Vec<String>)],
    lib_rs: &str,
    files: &[(String, String)],
) -> Vec<String> {
    let mut level = BTreeMap::new();
    for (i, (layer, modules)) in layers.iter().enumerate() {
        for m in modules {
            level.insert(m.clone(), (i, layer.clone()));
        }
    }
    let roots = root_names(lib_rs);
    let mut problems = Vec::new();
    // unit → (target → first place)
    let mut edges: BTreeMap<String, BTreeMap<String, String>> = BTreeMap::new();
    for (path, source) in files {
        let unit = path
            .split('/')
            .next()
            .unwrap_or("")
            .trim_end_matches(".rs")
            .to_string();
        if !level.contains_key(&unit) {
            problems.push(format!(
                "crate/{path}: module `{unit}` is not in the layer list"
            ));
            continue;
        }
        for (line, name) in crate_paths(&code_only(source)) {
            let target = if level.contains_key(&name) {
                name
            } else if let Some(m) = roots.get(&name) {
                m.clone()
            } else {
                problems.push(format!(
                    "crate/{path}:{line}: `crate::{name}` is neither a listed module nor a root re-export"
                ));
                continue;
            };
            if target != unit {
                edges
                    .entry(unit.clone())
                    .or_default()
                    .entry(target)
                    .or_insert(format!("crate/{path}:{line}"));
            }
        }
    }
    for (from, targets) in &edges {
        for (to, place) in targets {
            let (lf, nf) = &level[from];
            let (lt, nt) = &level[to];
            if lt > lf {
                problems.push(format!(
                    "up: {from} ({nf}) imports {to} ({nt}), a higher layer, at {place}"
                ));
            }
        }
    }
    for circle in circles(&edges) {
        let mut text = format!("circle: {}", circle.join(" ↔ "));
        for from in &circle {
            for to in &circle {
                if let Some(place) = edges.get(from).and_then(|t| t.get(to)) {
                    text += &format!("\n    {from} → {to} at {place}");
                }
            }
        }
        problems.push(text);
    }
    problems
}

/// The strongly connected components of more than one module (Tarjan's algorithm would do;
/// the graph has ~25 nodes, so reachability by search is plenty).
fn circles(edges: &BTreeMap<String, BTreeMap<String, String>>) -> Vec<Vec<String>> {
    let reach = |from: &str| -> BTreeSet<String> {
        let mut seen = BTreeSet::new();
        let mut stack = vec![from.to_string()];
        while let Some(n) = stack.pop() {
            for t in edges.get(&n).into_iter().flat_map(|t| t.keys()) {
                if seen.insert(t.clone()) {
                    stack.push(t.clone());
                }
            }
        }
        seen
    };
    let nodes: BTreeSet<&String> = edges.keys().collect();
    let reaches: BTreeMap<&String, BTreeSet<String>> =
        nodes.iter().map(|n| (*n, reach(n))).collect();
    let mut done = BTreeSet::new();
    let mut out = Vec::new();
    for n in &nodes {
        if done.contains(*n) {
            continue;
        }
        let comp: Vec<String> = nodes
            .iter()
            .filter(|m| reaches[*n].contains(**m) && reaches[**m].contains(*n))
            .map(|m| (*m).clone())
            .collect();
        if comp.len() > 1 {
            done.extend(comp.iter().cloned());
            out.push(comp);
        }
    }
    out
}

fn rust_files(dir: &Path, base: &Path, out: &mut Vec<(String, String)>) {
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.expect("directory entry").path())
        .collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            rust_files(&p, base, out);
        } else if p.extension().is_some_and(|e| e == "rs") {
            let rel = p.strip_prefix(base).expect("under crate/");
            let rel = rel.to_string_lossy().replace('\\', "/");
            if rel != "lib.rs" {
                let text = std::fs::read_to_string(&p).expect("readable source");
                out.push((rel, text));
            }
        }
    }
}

#[test]
fn every_import_points_down_and_no_two_modules_import_each_other() {
    let here = Path::new(env!("CARGO_MANIFEST_DIR")).join("crate");
    let list_file = std::env::var_os("LAYERS_LIST").map_or(here.join("lib.rs"), PathBuf::from);
    let list = std::fs::read_to_string(list_file).expect("the layer list");
    let layers = parse_layers(&list).expect("the layer list");
    let dir = std::env::var_os("LAYERS_CRATE").map_or(here, PathBuf::from);
    let lib_rs = std::fs::read_to_string(dir.join("lib.rs")).expect("lib.rs");
    let mut files = Vec::new();
    rust_files(&dir, &dir, &mut files);
    let problems = check(&layers, &lib_rs, &files);
    println!("{} files, {} layers checked", files.len(), layers.len());
    for p in &problems {
        println!("{p}");
    }
    assert!(
        problems.is_empty(),
        "{} layer problems (see crate/lib.rs, `## Layers`):\n{}",
        problems.len(),
        problems.join("\n")
    );
}

/// The list as crate/lib.rs writes it.
const LIST: &str = "//! ## Layers\n//!\n//! ```text\n//! ground  error mode\n//! design  design\n//! motion  command profile\n//! ```\n";

fn files(list: &[(&str, &str)]) -> Vec<(String, String)> {
    list.iter()
        .map(|(p, s)| (p.to_string(), s.to_string()))
        .collect()
}

#[test]
fn the_list_is_read_from_the_module_doc() {
    let layers = parse_layers(LIST).unwrap();
    assert_eq!(layers.len(), 3);
    assert_eq!(
        layers[2],
        ("motion".into(), vec!["command".into(), "profile".into()])
    );
    assert!(parse_layers("//! no list").is_err());
    // This repository's own list names every module once.
    let ours = parse_layers(include_str!("../crate/lib.rs")).unwrap();
    let all: Vec<&String> = ours.iter().flat_map(|(_, m)| m).collect();
    let unique: BTreeSet<&&String> = all.iter().collect();
    assert_eq!(all.len(), unique.len());
}

#[test]
fn the_checker_accepts_downward_imports_and_ignores_comments_and_strings() {
    let layers = parse_layers(LIST).unwrap();
    let ok = files(&[
        ("error.rs", "pub struct Error;"),
        ("mode.rs", "use crate::error::Error;\n// crate::design is only named here\nconst S: &str = \"crate::command\";"),
        ("design/mod.rs", "use crate::{error::Error, mode::Mode};\nuse super::x;"),
        ("command.rs", "use crate::profile::P;\nuse crate::Error;"),
        ("profile.rs", "use crate::design::D;"),
    ]);
    let lib = "pub use error::{Error, Result};";
    assert_eq!(check(&layers, lib, &ok), Vec::<String>::new());
}

#[test]
fn the_checker_catches_an_upward_import() {
    let layers = parse_layers(LIST).unwrap();
    let bad = files(&[
        ("error.rs", ""),
        ("mode.rs", "fn f() { crate::design::go() }"),
        ("design/mod.rs", ""),
    ]);
    let problems = check(&layers, "", &bad);
    assert_eq!(problems.len(), 1, "{problems:?}");
    assert!(problems[0].starts_with("up: mode (ground) imports design (design)"));
    assert!(problems[0].ends_with("crate/mode.rs:1"));
}

#[test]
fn the_checker_catches_two_modules_importing_each_other() {
    let layers = parse_layers(LIST).unwrap();
    let bad = files(&[
        ("command.rs", "use crate::profile::ProfileSpec;"),
        ("profile.rs", "\nuse crate::command::{Knot, Piecewise};"),
    ]);
    let problems = check(&layers, "", &bad);
    assert_eq!(problems.len(), 1, "{problems:?}");
    assert!(problems[0].starts_with("circle: command ↔ profile"));
    assert!(problems[0].contains("profile → command at crate/profile.rs:2"));
}

#[test]
fn the_checker_catches_an_unlisted_module_and_an_unknown_root_name() {
    let layers = parse_layers(LIST).unwrap();
    let bad = files(&[("wasm.rs", ""), ("mode.rs", "use crate::Nowhere;")]);
    let problems = check(&layers, "", &bad);
    assert_eq!(problems.len(), 2, "{problems:?}");
    assert!(problems[0].contains("module `wasm` is not in the layer list"));
    assert!(problems[1].contains("`crate::Nowhere` is neither"));
}
