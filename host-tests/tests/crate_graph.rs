//! The crate boundaries of docs/architecture.md, checked against the crate graph that
//! `cargo metadata` reports (issue 67, item 7), and the rule that only the engines' code
//! names the engine executables.
use serde_json::Value;
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// What a rule forbids.
enum Forbid {
    /// `from` (and everything it depends on, among the workspace's crates) never reaches
    /// one of `to`; `linked_only`: through normal dependencies alone (what is linked
    /// into the crate; its build scripts and tests run on the host).
    Path { from: &'static [&'static str], to: &'static [&'static str], linked_only: bool },
    /// No workspace crate but `allowed` depends on `to` directly (any kind of dependency).
    Dependents { to: &'static str, allowed: &'static [&'static str] },
}

/// The rules, each with the sentence of docs/architecture.md (or issue 67) it encodes.
const RULES: &[(&str, Forbid)] = &[
    (
        "the set knows no engine: the engines (FEBio, CalculiX, SLURM, the campaign runner, verification runs) depend on it, never the other way round",
        Forbid::Path { from: &["needle-set"], to: &["needle-fe", "needle-firmware-host"], linked_only: false },
    ),
    (
        "fit, plot, explore and the CLI's non-FE commands do not depend on the engines: needle-fit, needle-plot, needle-explore have no path to the engine crate",
        Forbid::Path {
            from: &["needle-fit", "needle-plot", "needle-explore"],
            to: &["needle-fe", "needle-firmware-host"],
            linked_only: false,
        },
    ),
    (
        "the library knows no std: needle-haptics, needle-contract and needle-fpu depend on no std-only workspace crate (a build dependency, the generator, runs on the host)",
        Forbid::Path {
            from: &["needle-haptics", "needle-contract", "needle-fpu"],
            to: &[
                "needle-stdx",
                "needle-set",
                "needle-codegen",
                "needle-fe",
                "needle-fit",
                "needle-calibrate",
                "needle-firmware-host",
                "needle-plot",
                "needle-explore",
                "needle-capi",
                "needle-wasm",
                "needle-cli",
            ],
            linked_only: true,
        },
    ),
    (
        "the engines are reached only through the FE commands: no workspace crate but needle-fe itself, the CLI and the tests depends on needle-fe",
        Forbid::Dependents { to: "needle-fe", allowed: &["needle-cli", "needle-host-tests"] },
    ),
];

/// Folders whose code must not name an engine's executable (the set and its readers).
const ENGINE_FREE: [&str; 4] = ["crates/set", "crates/fit", "crates/plot", "crates/explore"];

fn workspace_root() -> PathBuf {
    needle_stdx::workspace_root()
}

/// The workspace's crates and, for each, its workspace dependencies by kind.
#[derive(Default)]
struct Deps {
    normal: BTreeSet<String>,
    build: BTreeSet<String>,
    dev: BTreeSet<String>,
}

type Graph = BTreeMap<String, Deps>;

fn graph() -> Graph {
    let cargo = std::env::var_os("CARGO").unwrap_or_else(|| "cargo".into());
    let out = std::process::Command::new(cargo)
        .args(["metadata", "--format-version", "1", "--no-deps", "--offline"])
        .current_dir(workspace_root())
        .output()
        .expect("cargo metadata runs");
    assert!(out.status.success(), "cargo metadata: {}", String::from_utf8_lossy(&out.stderr));
    let meta: Value = serde_json::from_slice(&out.stdout).expect("cargo metadata's JSON");
    let packages = meta["packages"].as_array().expect("packages");
    let names: BTreeSet<String> = packages.iter().filter_map(|p| p["name"].as_str().map(String::from)).collect();
    let mut g = Graph::new();
    for p in packages {
        let name = p["name"].as_str().expect("name").to_string();
        let entry = g.entry(name).or_default();
        for d in p["dependencies"].as_array().expect("dependencies") {
            let dep = d["name"].as_str().expect("dependency name").to_string();
            if !names.contains(&dep) {
                continue;
            }
            match d["kind"].as_str() {
                None => entry.normal.insert(dep),
                Some("build") => entry.build.insert(dep),
                Some("dev") => entry.dev.insert(dep),
                Some(k) => panic!("{dep}: unknown dependency kind {k}"),
            };
        }
    }
    g
}

/// Everything `from` reaches: through normal dependencies alone (`linked_only`), or
/// through normal and build dependencies and `from`'s own dev dependencies (a test of the
/// crate links them).
fn reach(g: &Graph, from: &str, linked_only: bool) -> BTreeSet<String> {
    let next = |c: &str, origin: bool| -> Vec<String> {
        let Some(d) = g.get(c) else { return Vec::new() };
        let mut v: Vec<String> = d.normal.iter().cloned().collect();
        if !linked_only {
            v.extend(d.build.iter().cloned());
            if origin {
                v.extend(d.dev.iter().cloned());
            }
        }
        v
    };
    let mut seen = BTreeSet::new();
    let mut todo = next(from, true);
    while let Some(c) = todo.pop() {
        if seen.insert(c.clone()) {
            todo.extend(next(&c, false));
        }
    }
    seen
}

#[test]
fn the_crate_graph_keeps_the_documented_boundaries() {
    let g = graph();
    for c in ["needle-set", "needle-stdx", "needle-fe", "needle-fit", "needle-haptics", "needle-contract", "needle-cli"] {
        assert!(g.contains_key(c), "{c}: not a workspace crate in cargo metadata");
    }
    let mut broken = Vec::new();
    for (sentence, rule) in RULES {
        match rule {
            Forbid::Path { from, to, linked_only } => {
                for f in *from {
                    let r = reach(&g, f, *linked_only);
                    for t in *to {
                        if r.contains(*t) {
                            broken.push(format!("{f} reaches {t}: breaks \"{sentence}\""));
                        }
                    }
                }
            }
            Forbid::Dependents { to, allowed } => {
                for (c, d) in &g {
                    let any = d.normal.contains(*to) || d.build.contains(*to) || d.dev.contains(*to);
                    if c != to && any && !allowed.contains(&c.as_str()) {
                        broken.push(format!("{c} depends on {to}: breaks \"{sentence}\""));
                    }
                }
            }
        }
    }
    assert!(broken.is_empty(), "{}", broken.join("\n"));
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(rd) = std::fs::read_dir(dir) else { return };
    for e in rd.flatten() {
        let p = e.path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs" || x == "toml") {
            out.push(p);
        }
    }
}

/// Whether `line` names an engine's executable: FEBio's `febio4`, SLURM's `sbatch` or
/// `squeue` anywhere; CalculiX's `ccx` as a command (started, or its command line), not
/// the engine's name in the spec.
fn names_an_executable(line: &str) -> bool {
    let l = line.to_ascii_lowercase();
    l.contains("febio4")
        || l.contains("sbatch")
        || l.contains("squeue")
        || l.contains("ccx -i")
        || (l.contains("command::new") && (l.contains("ccx") || l.contains("febio")))
}

#[test]
fn only_the_engines_name_the_engine_executables() {
    let root = workspace_root();
    let mut found = Vec::new();
    let mut files = 0;
    for dir in ENGINE_FREE {
        let mut fs = Vec::new();
        rust_files(&root.join(dir), &mut fs);
        assert!(!fs.is_empty(), "{dir}: no source found");
        files += fs.len();
        for f in fs {
            let text = std::fs::read_to_string(&f).unwrap_or_else(|e| panic!("{}: {e}", f.display()));
            for (i, line) in text.lines().enumerate() {
                if names_an_executable(line) {
                    found.push(format!("{}:{}: {}", f.display(), i + 1, line.trim()));
                }
            }
        }
    }
    assert!(files > 20, "{files} files read: the walk found too few");
    assert!(found.is_empty(), "engine executables named outside the engines:\n{}", found.join("\n"));
    // the check can fail: the engine's own code names them
    let mut fe = Vec::new();
    rust_files(&root.join("crates/fe/src"), &mut fe);
    let named = fe.iter().filter(|f| std::fs::read_to_string(f).unwrap_or_default().lines().any(names_an_executable)).count();
    assert!(named > 0, "the rule finds no executable in crates/fe either: it checks nothing");
}

/// "Inside the CLI only `commands/fe/` names the engines" (docs/architecture.md §6): the
/// CLI's other commands read a set through `needle_set`, never through `needle_fe`.
#[test]
fn inside_the_cli_only_the_fe_commands_use_the_engine_crate() {
    let src = workspace_root().join("crates/cli/src");
    let fe = src.join("commands/fe");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    assert!(files.iter().any(|f| f.starts_with(&fe)), "the walk finds the fe commands");
    let offenders: Vec<String> = files
        .iter()
        .filter(|f| !f.starts_with(&fe))
        .filter(|f| std::fs::read_to_string(f).is_ok_and(|t| t.contains("needle_fe")))
        .map(|f| f.display().to_string())
        .collect();
    assert!(offenders.is_empty(), "CLI modules outside commands/fe/ use needle_fe: {offenders:?}");
    let uses = files.iter().filter(|f| f.starts_with(&fe)).any(|f| std::fs::read_to_string(f).is_ok_and(|t| t.contains("needle_fe")));
    assert!(uses, "commands/fe/ uses needle_fe (else this check cannot fail)");
}
