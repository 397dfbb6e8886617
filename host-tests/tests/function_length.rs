//! No function of the workspace's sources is over [`MAX_LINES`] lines (issue 37: "no
//! function over 80 lines in `crates/` and `src/`, tests aside"): a function that long
//! is a list of steps that want names.
//!
//! A function runs from its `fn` line to the first line after it that is its own
//! indentation followed by `}` (rustfmt's layout); a `fn` line that closes its body on
//! the same line is one line long, a declaration without a body (`;`) is not counted.
//! Tests aside: a file stops at its first `#[cfg(test)]` at the start of a line, and
//! files named `*_tests.rs` (test modules kept in their own file) are skipped.
mod source_walk;

use source_walk::{rust_files, workspace};

/// The longest a function may be, lines.
const MAX_LINES: usize = 80;

/// `(name, first line, lines)` of every function with a body in `text`.
fn functions(text: &str) -> Vec<(String, usize, usize)> {
    let lines: Vec<&str> = text.lines().collect();
    let end = lines.iter().position(|l| l.starts_with("#[cfg(test)]")).unwrap_or(lines.len());
    let mut out = Vec::new();
    let mut i = 0;
    while i < end {
        let line = lines[i];
        let indent = &line[..line.len() - line.trim_start().len()];
        let Some(name) = fn_name(line.trim_start()) else {
            i += 1;
            continue;
        };
        // the signature may go on over several lines; it ends with `{`, `;` or a
        // one-line body
        let mut j = i;
        while j < end && !(lines[j].trim_end().ends_with('{') || lines[j].trim_end().ends_with(';') || lines[j].trim_end().ends_with('}')) {
            j += 1;
        }
        let sig_end = lines.get(j).map(|l| l.trim_end()).unwrap_or("");
        if sig_end.ends_with(';') || (sig_end.ends_with('}') && !sig_end.trim_start().starts_with('}')) {
            i = j + 1;
            if sig_end.ends_with('}') {
                out.push((name, i, j + 2 - i));
            }
            continue;
        }
        let close = format!("{indent}}}");
        let last = (j + 1..end).find(|&k| lines[k].trim_end() == close).unwrap_or(end.saturating_sub(1));
        out.push((name, i + 1, last - i + 1));
        i = last + 1;
    }
    out
}

/// The name of the function a trimmed line starts, if it does (`pub`, `pub(crate)`,
/// `const`, `unsafe`, `extern "C"` and `async` allowed before `fn`).
fn fn_name(t: &str) -> Option<String> {
    let mut rest = t;
    loop {
        let before = rest;
        for prefix in ["pub(crate) ", "pub(super) ", "pub ", "const ", "unsafe ", "async ", "extern \"C\" "] {
            if let Some(r) = rest.strip_prefix(prefix) {
                rest = r;
            }
        }
        if rest == before {
            break;
        }
    }
    let r = rest.strip_prefix("fn ")?;
    let name: String = r.chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect();
    (!name.is_empty()).then_some(name)
}

#[test]
fn the_measure_counts_bodies_and_skips_declarations_and_tests() {
    let text = "fn one() -> u8 { 1 }\n\
                pub(crate) fn three(\n    a: u8,\n) -> u8 {\n    a\n}\n\
                trait T {\n    fn declared(&self);\n    fn default(&self) {\n        let _ = 1;\n    }\n}\n\
                #[cfg(test)]\nmod tests {\n    fn in_tests() {}\n}\n";
    let f = functions(text);
    let by_name: Vec<(&str, usize)> = f.iter().map(|(n, _, l)| (n.as_str(), *l)).collect();
    assert_eq!(by_name, vec![("one", 1), ("three", 5), ("default", 3)]);
}

#[test]
fn no_function_is_over_80_lines() {
    let ws = workspace();
    // test modules kept in their own file
    let tests_file = |p: &std::path::Path| p.to_string_lossy().ends_with("_tests.rs");
    let mut files = rust_files(&ws.join("src"), &tests_file);
    let Ok(crates) = std::fs::read_dir(ws.join("crates")) else { panic!("{}: cannot list", ws.join("crates").display()) };
    for c in crates.flatten() {
        files.extend(rust_files(&c.path().join("src"), &tests_file));
    }
    assert!(files.len() > 100, "found {} source files: the walk is wrong", files.len());
    let mut long = Vec::new();
    for f in &files {
        let text = std::fs::read_to_string(f).unwrap_or_else(|e| panic!("{}: {e}", f.display()));
        for (name, line, n) in functions(&text) {
            if n > MAX_LINES {
                long.push(format!("{}:{line}: fn {name}: {n} lines", f.strip_prefix(&ws).unwrap_or(f).display()));
            }
        }
    }
    assert!(long.is_empty(), "{} function(s) over {MAX_LINES} lines:\n{}", long.len(), long.join("\n"));
}
