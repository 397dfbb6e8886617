//! Specifications and code comments carry no dates (issue 37, item 5): the format
//! (`coeffs/README.md`), the architecture (`docs/architecture.md`) and the comments of
//! the sources say what is true now; dated history goes to `docs/measurement-notebook.md` and
//! measured figures to the set's README. A date is `YYYY-MM-DD` not followed by `T` (an
//! RFC 3339 timestamp in a format example is not history). Test modules aside (a file
//! stops at its first `#[cfg(test)]` at the start of a line).
mod source_walk;

use source_walk::{rust_files, workspace};

/// The dates in `text` (`YYYY-MM-DD` with a plausible month and day, not followed by `T`).
fn dates(text: &str) -> Vec<String> {
    let b = text.as_bytes();
    let mut out = Vec::new();
    for i in 0..b.len().saturating_sub(9) {
        let w = &b[i..i + 10];
        let digits = |r: std::ops::Range<usize>| r.into_iter().all(|k| w[k].is_ascii_digit());
        let prev_digit = i > 0 && b[i - 1].is_ascii_digit();
        if prev_digit || !(digits(0..4) && w[4] == b'-' && digits(5..7) && w[7] == b'-' && digits(8..10)) {
            continue;
        }
        let month = (w[5] - b'0') * 10 + (w[6] - b'0');
        let day = (w[8] - b'0') * 10 + (w[9] - b'0');
        let timestamp = b.get(i + 10) == Some(&b'T');
        if (1..=12).contains(&month) && (1..=31).contains(&day) && !timestamp {
            out.push(String::from_utf8_lossy(w).into_owned());
        }
    }
    out
}

/// The comment lines of a Rust source (`//`, `//!`, `///` and trailing comments) before
/// its test module, with their line numbers.
fn comments(text: &str) -> Vec<(usize, &str)> {
    text.lines()
        .enumerate()
        .take_while(|(_, l)| !l.starts_with("#[cfg(test)]"))
        .filter_map(|(i, l)| l.find("//").map(|k| (i + 1, &l[k..])))
        .collect()
}

#[test]
fn the_detector_finds_dates_and_leaves_timestamps() {
    assert_eq!(dates("measured 2026-11-27: 46 steps"), vec!["2026-11-27"]);
    assert!(dates("finished `2025-01-31T12:00:00Z`").is_empty());
    assert!(dates("version 12026-11-27 and 2026-13-01").is_empty());
    assert_eq!(comments("let a = 1; // on 2026-11-27\n#[cfg(test)]\n// 2026-11-28"), vec![(1, "// on 2026-11-27")]);
}

#[test]
fn specs_and_code_comments_carry_no_dates() {
    let ws = workspace();
    let mut found = Vec::new();
    for doc in ["coeffs/README.md", "docs/architecture.md"] {
        let text = std::fs::read_to_string(ws.join(doc)).unwrap_or_else(|e| panic!("{doc}: {e}"));
        for (i, line) in text.lines().enumerate() {
            for d in dates(line) {
                found.push(format!("{doc}:{}: {d}", i + 1));
            }
        }
    }
    // this file's own examples are dates on purpose
    let this = |p: &std::path::Path| p.ends_with("host-tests/tests/no_dates.rs");
    let files: Vec<_> = ["src", "crates", "host-tests", "examples"].iter().flat_map(|d| rust_files(&ws.join(d), &this)).collect();
    assert!(files.len() > 100, "found {} source files: the walk is wrong", files.len());
    for f in &files {
        let text = std::fs::read_to_string(f).unwrap_or_else(|e| panic!("{}: {e}", f.display()));
        for (line, c) in comments(&text) {
            for d in dates(c) {
                found.push(format!("{}:{line}: {d}", f.strip_prefix(&ws).unwrap_or(f).display()));
            }
        }
    }
    assert!(
        found.is_empty(),
        "{} date(s) in specs or comments (history goes to docs/measurement-notebook.md):\n{}",
        found.len(),
        found.join("\n")
    );
}
