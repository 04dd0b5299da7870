//! The source tree holds what ARCHITECTURE.md and `src/lib.rs` claim of it: every file under 500
//! lines, and the modules in chain order — a module uses only the modules above it in
//! `src/lib.rs`'s table (comments and tests aside), so the table is a true reading order and the
//! house has no cycle. Nothing here builds Shoal: it reads the files.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The most lines a source file may have (the brief's limit: a file a newcomer reads whole).
const MAX_LINES: usize = 499;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// Every `.rs` file under `dir`, sorted.
fn rust_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        let Ok(entries) = std::fs::read_dir(&d) else { continue };
        for entry in entries {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == "rs") {
                out.push(path);
            }
        }
    }
    out.sort();
    out
}

#[test]
fn every_source_file_is_under_500_lines() {
    let mut long = Vec::new();
    for dir in ["src", "tests"] {
        for file in rust_files(&root().join(dir)) {
            let lines = std::fs::read_to_string(&file).unwrap().lines().count();
            if lines > MAX_LINES {
                long.push(format!("{} ({lines} lines)", file.strip_prefix(root()).unwrap().display()));
            }
        }
    }
    assert!(long.is_empty(), "files of 500 lines or more (split them by what they do): {long:?}");
}

/// The modules in `src/lib.rs`'s table, in its order (`app` and `cli` last).
fn module_order() -> Vec<String> {
    let lib = std::fs::read_to_string(root().join("src/lib.rs")).unwrap();
    lib.lines()
        .filter_map(|l| l.strip_prefix("//! | "))
        .filter_map(|l| l.split(" |").next())
        // A module's cell names it in backticks (the header's "module" does not).
        .filter(|m| m.starts_with('[') || m.starts_with('`'))
        .map(|m| m.trim_matches(|c| c == '[' || c == ']' || c == '`').to_string())
        .filter(|m| !m.is_empty() && m.chars().all(|c| c.is_ascii_lowercase() || c == '_'))
        .collect()
}

/// The text of `file` a dependency can be in: neither comments nor the tests at its end.
fn code(file: &Path) -> String {
    let text = std::fs::read_to_string(file).unwrap();
    // Cut at the test module (`#[cfg(test)]` on a helper function mid-file is not the end).
    let body = text.split("#[cfg(test)]\nmod ").next().unwrap_or_default();
    body.lines().filter(|l| !l.trim_start().starts_with("//")).collect::<Vec<_>>().join("\n")
}

/// The files of top-level module `m`: `src/m.rs` and everything under `src/m/`.
fn files_of(m: &str) -> Vec<PathBuf> {
    let src = root().join("src");
    let mut files = rust_files(&src.join(m));
    let single = src.join(format!("{m}.rs"));
    if single.is_file() {
        files.push(single);
    }
    files
}

/// The top-level modules named right after a `crate::`: `engine` of `engine::run`, and each of
/// a group, `colormap` and `engine` of `{colormap::viridis, engine::Engine}`.
fn used_modules(after: &str) -> Vec<String> {
    let word =
        |s: &str| -> String { s.trim_start().chars().take_while(|c| c.is_ascii_alphanumeric() || *c == '_').collect() };
    let Some(group) = after.strip_prefix('{') else { return vec![word(after)] };
    let (mut depth, mut names, mut start) = (0i32, Vec::new(), 0usize);
    for (k, c) in group.char_indices() {
        match c {
            '{' => depth += 1,
            '}' if depth == 0 => {
                names.push(word(&group[start..k]));
                break;
            }
            '}' => depth -= 1,
            ',' if depth == 0 => {
                names.push(word(&group[start..k]));
                start = k + 1;
            }
            _ => {}
        }
    }
    names
}

#[test]
fn each_module_uses_only_the_modules_above_it_in_lib_rs() {
    let order = module_order();
    assert!(order.len() > 30 && order.last().map(String::as_str) == Some("cli"), "the table: {order:?}");
    let rank: BTreeMap<&str, usize> = order.iter().enumerate().map(|(i, m)| (m.as_str(), i)).collect();
    // Every module in the crate is in the table.
    let lib = std::fs::read_to_string(root().join("src/lib.rs")).unwrap();
    for line in lib.lines() {
        if let Some(m) = line.trim().strip_prefix("pub mod ").and_then(|m| m.strip_suffix(';')) {
            assert!(rank.contains_key(m), "`{m}` is not in src/lib.rs's table");
        }
    }
    let mut wrong = Vec::new();
    for (i, m) in order.iter().enumerate() {
        for file in files_of(m) {
            let text = code(&file);
            for (at, _) in text.match_indices("crate::") {
                for used in used_modules(&text[at + 7..]) {
                    if rank.get(used.as_str()).is_some_and(|&k| k > i) {
                        wrong.push(format!("{} uses `{used}`", file.strip_prefix(root()).unwrap().display()));
                    }
                }
            }
        }
    }
    wrong.sort();
    wrong.dedup();
    assert!(wrong.is_empty(), "uses of a module below in src/lib.rs's table (move the code, or the table): {wrong:#?}");
}

#[test]
fn a_group_import_names_each_module() {
    assert_eq!(used_modules("engine::Engine;"), ["engine"]);
    assert_eq!(
        used_modules("{colormap::viridis, engine::{Engine, RunConfig}, units};"),
        ["colormap", "engine", "units"]
    );
}

/// The modules of ARCHITECTURE.md's table, in its order (a row may name several).
fn architecture_order() -> Vec<String> {
    let text = std::fs::read_to_string(root().join("docs/ARCHITECTURE.md")).unwrap();
    let table = text.split("| module | what it holds |").nth(1).expect("ARCHITECTURE.md has its module table");
    let mut out = Vec::new();
    for line in table.lines().skip(2).take_while(|l| l.starts_with("| ")) {
        let cell = line.split('|').nth(1).unwrap_or_default();
        out.extend(cell.split(',').map(|m| m.trim().trim_matches('`').to_string()));
    }
    out
}

#[test]
fn architecture_md_lists_the_modules_in_lib_rs_order() {
    let order = module_order();
    let rank: BTreeMap<&str, usize> = order.iter().enumerate().map(|(i, m)| (m.as_str(), i)).collect();
    let listed = architecture_order();
    assert!(listed.len() > 30, "ARCHITECTURE.md's table: {listed:?}");
    let ranks: Vec<(String, usize)> = listed
        .iter()
        .map(|m| {
            (
                m.clone(),
                *rank.get(m.as_str()).unwrap_or_else(|| panic!("ARCHITECTURE.md names `{m}`, not in src/lib.rs")),
            )
        })
        .collect();
    let out_of_order: Vec<String> =
        ranks.windows(2).filter(|w| w[1].1 < w[0].1).map(|w| format!("`{}` after `{}`", w[1].0, w[0].0)).collect();
    assert!(out_of_order.is_empty(), "ARCHITECTURE.md's table is not in src/lib.rs's order: {out_of_order:?}");
}
