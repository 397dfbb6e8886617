//! `docs/architecture.md`'s code map (§6) matches the tree: a newcomer finds where a
//! feature goes from the document alone (issue 67). Each table's first column names the
//! paths of its rows in backticks:
//! - "The top level": every entry of the repository's root (but `target` and hidden
//!   folders not listed) is named, and every named path exists;
//! - "`src/`": every module of the library's root (file or folder) is named, and every
//!   named module exists;
//! - "`crates/`": every folder of `crates/` is named, and every named crate exists.

// a test binary uses only `workspace` of the shared walker
#[allow(dead_code)]
mod source_walk;

use std::collections::BTreeSet;
use std::path::Path;

/// The first cells of the table under the heading `heading` of §6, split into the names
/// written in backticks (`a`, `b/` and `c.rs` give a, b/ and c.rs).
fn first_cells(doc: &str, heading: &str) -> Vec<String> {
    let map = doc.split("\n## 6.").nth(1).and_then(|s| s.split("\n## 7.").next()).expect("architecture.md has §6 and §7");
    let section = map.split("\n### ").find(|s| s.starts_with(heading)).unwrap_or_else(|| panic!("§6 has a table {heading:?}"));
    let mut names = Vec::new();
    for line in section.lines().filter(|l| l.starts_with("| ") && !l.starts_with("| ---")).skip(1) {
        let cell = line.split('|').nth(1).unwrap_or_default();
        names.extend(cell.split('`').skip(1).step_by(2).map(str::to_string));
    }
    assert!(!names.is_empty(), "the table {heading:?} names nothing");
    names
}

/// The entries of `dir` (folders with a trailing `/`), hidden ones only when `hidden`.
fn entries(dir: &Path, hidden: bool) -> BTreeSet<String> {
    std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .filter_map(Result::ok)
        .filter_map(|e| {
            let name = e.file_name().to_string_lossy().into_owned();
            let folder = e.file_type().is_ok_and(|t| t.is_dir());
            (hidden || !name.starts_with('.')).then(|| if folder { format!("{name}/") } else { name })
        })
        .collect()
}

/// Every entry of `tree` is in `named` and every name in `named` is in `tree`.
fn matches(what: &str, named: &BTreeSet<String>, tree: &BTreeSet<String>) {
    let missing: Vec<&String> = tree.difference(named).collect();
    let stale: Vec<&String> = named.difference(tree).collect();
    assert!(
        missing.is_empty() && stale.is_empty(),
        "docs/architecture.md §6 ({what}): not in the code map: {missing:?}; in the code map but not in the tree: {stale:?}"
    );
}

fn doc() -> String {
    std::fs::read_to_string(source_walk::workspace().join("docs/architecture.md")).expect("docs/architecture.md")
}

#[test]
fn the_top_level_table_names_every_entry_of_the_root() {
    let root = source_walk::workspace();
    let named: BTreeSet<String> = first_cells(&doc(), "The top level").into_iter().collect();
    let mut tree = entries(&root, false);
    tree.remove("target/");
    // the hidden folders are in the tree only where the map names them
    tree.extend(entries(&root, true).into_iter().filter(|e| e.starts_with('.') && named.contains(e)));
    matches("the top level", &named, &tree);
}

#[test]
fn the_library_table_names_every_module_of_src() {
    let root = source_walk::workspace().join("src");
    let named: BTreeSet<String> = first_cells(&doc(), "`src/`")
        .into_iter()
        .map(|n| if n.ends_with('/') || n.ends_with(".rs") { n } else { format!("{n}.rs") })
        .collect();
    let tree: BTreeSet<String> = entries(&root, false)
        .into_iter()
        // a module `x.rs` beside its folder `x/` is one module, named `x/`
        .filter(|e| !(e.ends_with(".rs") && root.join(e.trim_end_matches(".rs")).is_dir()))
        .collect();
    matches("src/", &named, &tree);
}

#[test]
fn the_crates_table_names_every_crate() {
    let root = source_walk::workspace().join("crates");
    let named: BTreeSet<String> =
        first_cells(&doc(), "`crates/`").into_iter().filter(|n| !n.starts_with("needle-")).map(|n| format!("{n}/")).collect();
    matches("crates/", &named, &entries(&root, false));
}
