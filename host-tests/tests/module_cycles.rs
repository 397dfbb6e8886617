//! The module import graph of every crate of the workspace has no cycle.
//!
//! A module is a source file (`a/b.rs` and `a/b/mod.rs` are `a::b`); module A depends on
//! module B when A's file names a path `crate::...` or `super::...` that resolves to B or
//! an item in B (imports, `use` trees with braces, and paths in code alike). Edges between
//! a module and its own ancestors are structure, not imports, and are left out. Cycles are
//! the strongly connected components with more than one module (Tarjan).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The crates' source folders, from the workspace root.
const CRATES: [&str; 16] = [
    "src",
    "crates/contract/src",
    "crates/fpu/src",
    "crates/stdx/src",
    "crates/set/src",
    "crates/codegen/src",
    "crates/capi/src",
    "crates/wasm/src",
    "crates/fe/src",
    "crates/fit/src",
    "crates/firmware-host/src",
    "crates/plot/src",
    "crates/explore/src",
    "crates/calibrate/src",
    "crates/cli/src",
    "crates/bindings-python/src",
];

type Graph = BTreeMap<String, BTreeSet<String>>;

fn files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(rd) = std::fs::read_dir(dir) else { return };
    for e in rd.flatten() {
        let p = e.path();
        if p.is_dir() {
            files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// `a/b.rs` and `a/b/mod.rs` -> `a::b`; `lib.rs`, `main.rs` -> `` (the crate root).
fn module_of(root: &Path, file: &Path) -> String {
    let rel = file.strip_prefix(root).unwrap_or(file).with_extension("");
    let mut parts: Vec<String> = rel.components().map(|c| c.as_os_str().to_string_lossy().into_owned()).collect();
    if matches!(parts.last().map(String::as_str), Some("mod" | "lib" | "main")) {
        parts.pop();
    }
    parts.join("::")
}

fn is_ident(c: char) -> bool {
    c.is_ascii_alphanumeric() || c == '_'
}

/// The paths of a `use` tree or plain path starting at `s` (after `crate::`/`super::`):
/// `a::b`, `a::{b, c::d}` -> ["a::b"] or ["a::b", "a::c::d"] (prefix is the path so far).
fn paths(s: &str, prefix: &str, out: &mut Vec<String>) -> usize {
    let mut i = 0;
    let b = s.as_bytes();
    let mut cur = prefix.to_string();
    loop {
        let start = i;
        while i < b.len() && is_ident(b[i] as char) {
            i += 1;
        }
        if i > start {
            if !cur.is_empty() {
                cur.push_str("::");
            }
            cur.push_str(&s[start..i]);
        }
        if s[i..].starts_with("::{") {
            i += 3;
            loop {
                while i < b.len() && (b[i] as char).is_whitespace() {
                    i += 1;
                }
                if i >= b.len() || b[i] == b'}' {
                    i += 1;
                    return i;
                }
                i += paths(&s[i..], &cur, out);
                while i < b.len() && (b[i] as char).is_whitespace() {
                    i += 1;
                }
                if i < b.len() && b[i] == b',' {
                    i += 1;
                }
            }
        } else if s[i..].starts_with("::") {
            i += 2;
        } else {
            // `as name`, `;`, `(`, `<`...: the path ends
            out.push(cur);
            return i;
        }
    }
}

/// The longest module of `modules` that `path` starts with.
fn resolve(path: &str, modules: &BTreeSet<String>) -> Option<String> {
    let parts: Vec<&str> = path.split("::").collect();
    (1..=parts.len()).rev().map(|n| parts[..n].join("::")).find(|m| modules.contains(m))
}

fn is_ancestor(a: &str, b: &str) -> bool {
    a.is_empty() || b.starts_with(&format!("{a}::"))
}

/// The dependency graph of the crate whose sources are in `root`.
fn graph(root: &Path) -> Graph {
    let mut fs = Vec::new();
    files(root, &mut fs);
    let modules: BTreeSet<String> = fs.iter().map(|f| module_of(root, f)).collect();
    let mut g = Graph::new();
    for f in &fs {
        let me = module_of(root, f);
        let text = std::fs::read_to_string(f).unwrap_or_default();
        let code: String = text.lines().filter(|l| !l.trim_start().starts_with("//")).collect::<Vec<_>>().join("\n");
        let mut found = Vec::new();
        for (at, _) in code.match_indices("crate::") {
            let before = code[..at].chars().last();
            if before.is_some_and(|c| is_ident(c) || c == '$') {
                continue;
            }
            paths(&code[at + 7..], "", &mut found);
        }
        let parent = me.rsplit_once("::").map(|(p, _)| p.to_string()).unwrap_or_default();
        for (at, _) in code.match_indices("super::") {
            if code[..at].chars().last().is_some_and(is_ident) {
                continue;
            }
            // `super` inside an inline `mod tests` is the file's own module
            let mut v = Vec::new();
            paths(&code[at + 7..], &parent, &mut v);
            found.extend(v);
        }
        let deps = g.entry(me.clone()).or_default();
        for p in found {
            if let Some(m) = resolve(&p, &modules) {
                if m != me && !is_ancestor(&m, &me) && !is_ancestor(&me, &m) {
                    deps.insert(m);
                }
            }
        }
    }
    g
}

/// Strongly connected components with more than one module.
fn cycles(g: &Graph) -> Vec<Vec<String>> {
    struct T<'a> {
        g: &'a Graph,
        index: BTreeMap<&'a str, usize>,
        low: BTreeMap<&'a str, usize>,
        stack: Vec<&'a str>,
        on: BTreeSet<&'a str>,
        out: Vec<Vec<String>>,
    }
    fn visit<'a>(t: &mut T<'a>, v: &'a str) {
        let i = t.index.len();
        t.index.insert(v, i);
        t.low.insert(v, i);
        t.stack.push(v);
        t.on.insert(v);
        if let Some(ws) = t.g.get(v) {
            for w in ws {
                let w = w.as_str();
                if !t.index.contains_key(w) {
                    visit(t, w);
                    let lw = t.low[w];
                    let lv = t.low.get_mut(v).expect("low");
                    *lv = (*lv).min(lw);
                } else if t.on.contains(w) {
                    let iw = t.index[w];
                    let lv = t.low.get_mut(v).expect("low");
                    *lv = (*lv).min(iw);
                }
            }
        }
        if t.low[v] == t.index[v] {
            let mut comp = Vec::new();
            while let Some(w) = t.stack.pop() {
                t.on.remove(w);
                comp.push(w.to_string());
                if w == v {
                    break;
                }
            }
            if comp.len() > 1 {
                comp.sort();
                t.out.push(comp);
            }
        }
    }
    let mut t = T { g, index: BTreeMap::new(), low: BTreeMap::new(), stack: Vec::new(), on: BTreeSet::new(), out: Vec::new() };
    for v in g.keys() {
        if !t.index.contains_key(v.as_str()) {
            visit(&mut t, v);
        }
    }
    t.out
}

#[test]
fn the_detector_finds_a_cycle_and_reads_use_trees() {
    let mut out = Vec::new();
    paths("fe::{spec::{self, Campaign}, deck, manifest::MANIFEST};", "", &mut out);
    assert_eq!(out, ["fe::spec::self", "fe::spec::Campaign", "fe::deck", "fe::manifest::MANIFEST"]);
    let g: Graph = [("a", vec!["b"]), ("b", vec!["c"]), ("c", vec!["a"]), ("d", vec!["a"])]
        .into_iter()
        .map(|(k, v)| (k.to_string(), v.into_iter().map(String::from).collect()))
        .collect();
    assert_eq!(cycles(&g), vec![vec!["a".to_string(), "b".into(), "c".into()]]);
}

#[test]
fn no_crate_of_the_workspace_has_an_import_cycle() {
    let ws = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut all = Vec::new();
    let (mut edges, mut modules) = (0, 0);
    for c in CRATES {
        let g = graph(&ws.join(c));
        assert!(!g.is_empty(), "{c}: no module found");
        modules += g.len();
        edges += g.values().map(BTreeSet::len).sum::<usize>();
        for cy in cycles(&g) {
            let inside: Vec<String> =
                cy.iter().flat_map(|a| g[a].iter().filter(|b| cy.contains(b)).map(move |b| format!("{a} -> {b}"))).collect();
            all.push(format!("{c}: {} ({})", cy.join(" <-> "), inside.join(", ")));
        }
    }
    assert!(modules > 100 && edges > 100, "{modules} modules, {edges} import edges: the reader found too few");
    // every Rust crate (a folder with a Cargo.toml; the CHAI3D binding is C++ built by CMake)
    for e in std::fs::read_dir(ws.join("crates")).expect("read crates/").flatten() {
        let src = format!("crates/{}/src", e.file_name().to_string_lossy());
        let rust = e.path().join("Cargo.toml").is_file();
        assert!(!rust || !ws.join(&src).is_dir() || CRATES.contains(&src.as_str()), "{src} is not in CRATES");
    }
    assert!(all.is_empty(), "{} import cycle(s):\n{}", all.len(), all.join("\n"));
}

/// `graph` with every module folded into its top-level module (`launcher::slurm` ->
/// `launcher`): a cycle through a folder's children and an outside module
/// (`campaign -> launcher`, `launcher::slurm -> campaign`) shows up here.
fn top_level(g: &Graph) -> Graph {
    let top = |m: &str| m.split("::").next().unwrap_or_default().to_string();
    let mut out = Graph::new();
    for (a, bs) in g {
        let ta = top(a);
        let deps = out.entry(ta.clone()).or_default();
        for b in bs {
            let tb = top(b);
            if tb != ta && !ta.is_empty() && !tb.is_empty() {
                deps.insert(tb);
            }
        }
    }
    out
}

#[test]
fn no_crate_has_an_import_cycle_between_its_top_level_modules() {
    let folded: Graph = [("campaign", vec!["launcher"]), ("launcher::slurm", vec!["campaign"])]
        .into_iter()
        .map(|(k, v)| (k.to_string(), v.into_iter().map(String::from).collect()))
        .collect();
    assert!(cycles(&folded).is_empty(), "file by file, no cycle");
    assert_eq!(cycles(&top_level(&folded)), vec![vec!["campaign".to_string(), "launcher".into()]]);
    let ws = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut all = Vec::new();
    for c in CRATES {
        let g = top_level(&graph(&ws.join(c)));
        for cy in cycles(&g) {
            let inside: Vec<String> =
                cy.iter().flat_map(|a| g[a].iter().filter(|b| cy.contains(b)).map(move |b| format!("{a} -> {b}"))).collect();
            all.push(format!("{c}: {} ({})", cy.join(" <-> "), inside.join(", ")));
        }
    }
    assert!(all.is_empty(), "{} import cycle(s):\n{}", all.len(), all.join("\n"));
}
