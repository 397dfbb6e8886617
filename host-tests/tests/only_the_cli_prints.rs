//! Issue 67, item 7: **only the CLI prints** (docs/architecture.md, section 2). No crate
//! but `crates/cli` writes to the terminal: no `println!`, `print!`, `eprintln!`,
//! `eprint!` or `dbg!`, no `std::io::stdout()` or `stderr()`, in the library (`src/`) or
//! any other crate's `src/`. What a library crate has to say goes through
//! `needle_stdx::report` (`outln!`, `noteln!`, ...), whose sink the `needle` binary
//! installs. Tests (`tests/`, a file's `#[cfg(test)]` part), examples, benches and build
//! scripts may print. [`ALLOWED`] lists what may still touch the terminal, each with its
//! reason; it can only shrink (an entry that no longer matches fails the test).

// a test binary uses only some of the shared walker
#[allow(dead_code)]
mod source_walk;

use std::path::Path;

/// (file, what it may contain, why): the exceptions.
const ALLOWED: [(&str, &str, &str); 1] = [(
    "crates/fe/src/progress_bar.rs",
    "io::stderr()",
    "the campaign's progress bar (indicatif) draws itself on stderr when stderr is a terminal, redrawn 4 times a second; \
     its plain lines (CI, a log) go through needle_stdx::report",
)];

/// What writes to the terminal.
const PRINTS: [&str; 7] = ["println!", "print!", "eprintln!", "eprint!", "dbg!", "io::stdout()", "io::stderr()"];

/// `line` uses `what` as a macro or a call (not as part of a longer name, e.g.
/// `needle_stdx::outln!` or `writeln!`).
fn uses(line: &str, what: &str) -> bool {
    line.match_indices(what).any(|(i, _)| {
        let before = line[..i].chars().next_back();
        what.starts_with("io::") || !before.is_some_and(|c| c.is_alphanumeric() || c == '_' || c == ':')
    })
}

/// Every (file:line, what) of `file` outside comments and its `#[cfg(test)]` part.
fn prints(ws: &Path, file: &Path) -> Vec<(String, &'static str)> {
    let text = std::fs::read_to_string(file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
    let rel = file.strip_prefix(ws).unwrap_or(file).to_string_lossy().into_owned();
    let mut out = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let code = line.trim_start();
        if code.starts_with("#[cfg(test)]") {
            break;
        }
        if code.starts_with("//") {
            continue;
        }
        let code = code.split(" //").next().unwrap_or(code);
        for what in PRINTS {
            if uses(code, what) {
                out.push((format!("{rel}:{}", n + 1), what));
            }
        }
    }
    out
}

#[test]
fn only_the_cli_prints() {
    let ws = source_walk::workspace();
    let ws = ws.canonicalize().unwrap_or(ws);
    let mut dirs = vec![ws.join("src")];
    for e in std::fs::read_dir(ws.join("crates")).expect("crates/").flatten() {
        if e.file_name() != "cli" && e.path().join("src").is_dir() {
            dirs.push(e.path().join("src"));
        }
    }
    let mut found = Vec::new();
    for dir in &dirs {
        for file in source_walk::rust_files(dir, &|p| p.file_name().is_some_and(|n| n == "build.rs")) {
            found.extend(prints(&ws, &file));
        }
    }
    assert!(dirs.len() > 10, "the walk sees the library and the crates ({} folders)", dirs.len());
    let mut used = vec![false; ALLOWED.len()];
    let offending: Vec<String> = found
        .iter()
        .filter(|(at, what)| {
            let k = ALLOWED.iter().position(|(file, allowed, _)| at.starts_with(&format!("{file}:")) && what == allowed);
            k.map(|k| used[k] = true).is_none()
        })
        .map(|(at, what)| format!("{at}: {what}"))
        .collect();
    assert!(
        offending.is_empty(),
        "only the CLI prints: send the text through needle_stdx::report (outln!, noteln!, ...) instead:\n{}",
        offending.join("\n")
    );
    let stale: Vec<&str> = ALLOWED.iter().zip(&used).filter(|(_, u)| !**u).map(|((f, _, _), _)| *f).collect();
    assert!(stale.is_empty(), "ALLOWED names what no longer prints, remove it: {stale:?}");
}

/// The scan sees a print, and not a name that merely ends like one.
#[test]
fn the_scan_sees_a_print() {
    for (line, hits) in [
        ("    println!(\"x\");", true),
        ("eprint!(\"{x}\")", true),
        ("let _ = dbg!(x);", true),
        ("std::io::stderr().write_all(b)", true),
        ("needle_stdx::outln!(\"x\");", false),
        ("writeln!(s, \"x\")", false),
        ("crate::noteln!(\"x\")", false),
    ] {
        assert_eq!(PRINTS.iter().any(|w| uses(line, w)), hits, "{line}");
    }
}
