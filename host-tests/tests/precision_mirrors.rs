//! The library's two precisions are mirrors, module for module: `src/float/` and
//! `src/fixed/` hold the same module names and nesting, except the modules that exist in
//! one precision by nature, each listed in its precision's `mod.rs` on a line
//! "precision-only: `name` because ...". The f32 modules are not at the crate's root
//! beside the shared vocabulary (a root module of the same name as one in either
//! precision fails), and `src/` has one module style: `x/mod.rs`, never `x.rs` beside
//! an `x/` folder.
mod source_walk;

use std::collections::BTreeSet;
use std::path::Path;

/// The module paths under `dir` (`a/b.rs` and `a/b/mod.rs` are `a::b`), without `dir`'s
/// own `mod.rs`.
fn modules(dir: &Path) -> BTreeSet<String> {
    source_walk::rust_files(dir, &|_| false)
        .iter()
        .filter_map(|f| {
            let rel = f.strip_prefix(dir).ok()?.with_extension("");
            let mut parts: Vec<String> = rel.components().map(|c| c.as_os_str().to_string_lossy().into_owned()).collect();
            if parts.last().is_some_and(|p| p == "mod") {
                parts.pop();
            }
            (!parts.is_empty()).then(|| parts.join("::"))
        })
        .collect()
}

/// The names on the "precision-only: `name` because ..." lines of `mod_rs`'s doc comment.
fn precision_only(mod_rs: &Path) -> BTreeSet<String> {
    let text = std::fs::read_to_string(mod_rs).unwrap_or_else(|e| panic!("{}: {e}", mod_rs.display()));
    let mut names = BTreeSet::new();
    for line in text.lines().filter(|l| l.starts_with("//!")) {
        let Some((_, rest)) = line.split_once("precision-only: `") else { continue };
        let (name, after) = rest.split_once('`').unwrap_or_else(|| panic!("{}: unclosed name in {line:?}", mod_rs.display()));
        assert!(after.trim_start().starts_with("because "), "{}: {line:?} gives no reason (\"because ...\")", mod_rs.display());
        names.insert(name.to_string());
    }
    names
}

#[test]
fn float_and_fixed_hold_the_same_modules_but_the_documented_ones() {
    let src = source_walk::workspace().join("src");
    let (float, fixed) = (modules(&src.join("float")), modules(&src.join("fixed")));
    let (float_only, fixed_only) = (precision_only(&src.join("float/mod.rs")), precision_only(&src.join("fixed/mod.rs")));
    assert!(!float.is_empty() && !fixed.is_empty(), "no modules found under {}", src.display());
    let found_float: BTreeSet<String> = float.difference(&fixed).cloned().collect();
    let found_fixed: BTreeSet<String> = fixed.difference(&float).cloned().collect();
    assert_eq!(
        found_float, float_only,
        "modules in src/float/ and not in src/fixed/ (left) against the precision-only lines of src/float/mod.rs (right)"
    );
    assert_eq!(
        found_fixed, fixed_only,
        "modules in src/fixed/ and not in src/float/ (left) against the precision-only lines of src/fixed/mod.rs (right)"
    );
}

#[test]
fn the_root_holds_no_module_of_either_precision() {
    let src = source_walk::workspace().join("src");
    let root: BTreeSet<String> = modules(&src).into_iter().filter(|m| !m.contains("::")).collect();
    for precision in ["float", "fixed"] {
        let top: BTreeSet<String> = modules(&src.join(precision)).into_iter().filter(|m| !m.contains("::")).collect();
        let both: Vec<&String> = root.intersection(&top).collect();
        assert!(both.is_empty(), "src/ and src/{precision}/ both hold {both:?}: a module of one precision belongs in its folder");
    }
}

#[test]
fn src_has_one_module_style() {
    let src = source_walk::workspace().join("src");
    for file in source_walk::rust_files(&src, &|_| false) {
        let beside = file.with_extension("");
        assert!(
            !beside.is_dir(),
            "{} sits beside the folder {}: src/ writes a module with children as x/mod.rs",
            file.display(),
            beside.display()
        );
        if let Some(dir) = file.parent().filter(|d| *d != src) {
            assert!(dir.join("mod.rs").is_file(), "{} has no mod.rs: src/ writes a module with children as x/mod.rs", dir.display());
        }
    }
}
