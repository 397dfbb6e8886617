//! Where a key is in campaign.toml's text, for `file:line` in messages.

/// The 1-based line of `key = ...` inside the `[section]` table of `text` (0 when not
/// found), for `file:line` in messages.
pub fn key_line(text: &str, section: &str, key: &str) -> usize {
    let header = format!("[{section}]");
    let mut inside = false;
    for (i, line) in text.lines().enumerate() {
        let t = line.trim();
        if t.starts_with('[') {
            inside = t == header;
            if inside && key.is_empty() {
                return i + 1;
            }
            continue;
        }
        if inside && t.split('=').next().map(str::trim) == Some(key) {
            return i + 1;
        }
    }
    0
}

/// The shipped set's `campaign.toml`, the 1-based line of `key` in its `[section]` and
/// that line's text: for tests (here and in the engines') that edit one line of the shipped
/// spec. Panics when the file or the key is missing (a test helper).
#[doc(hidden)]
#[must_use]
pub fn shipped_key(section: &str, key: &str) -> (String, usize, String) {
    let path = needle_stdx::workspace_root().join("coeffs/default/campaign.toml");
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let line = key_line(&text, section, key);
    assert!(line > 0, "the shipped campaign.toml has [{section}] {key}");
    let shipped = text.lines().nth(line - 1).unwrap_or_default().to_string();
    (text, line, shipped)
}
