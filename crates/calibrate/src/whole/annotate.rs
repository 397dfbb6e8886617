//! Each fitted value's uncertainty written beside it in the tissue file, as a TOML
//! comment on its line (the format's reader ignores comments: the values are the file's).

/// `text` (a stack as [`needle_codegen::tissue::Stack::to_toml`] writes it) with, on the
/// line of each `key` of layer `k`, the comment `notes[k]`'s note for it.
#[must_use]
pub fn annotate(text: &str, notes: &[Vec<(&'static str, String)>]) -> String {
    let mut out = String::with_capacity(text.len() * 2);
    let mut layer: Option<usize> = None;
    let (mut prony_seen, mut shaft_seen) = (false, false);
    for line in text.lines() {
        if line.trim() == "[[layer]]" {
            layer = Some(layer.map_or(0, |k| k + 1));
            (prony_seen, shaft_seen) = (false, false);
        }
        out.push_str(line);
        let key = line.split(" = ").next().unwrap_or("").trim();
        // the note of a table array on its first table's header
        let (prony_table, shaft_table) =
            (line.trim() == "[[layer.prony]]" && !prony_seen, line.trim() == "[[layer.shaft_prony]]" && !shaft_seen);
        let wanted = if prony_table {
            "prony"
        } else if shaft_table {
            "shaft_prony"
        } else {
            key
        };
        if let Some(note) = layer.and_then(|k| notes.get(k)).and_then(|n| n.iter().find(|(k, _)| *k == wanted)) {
            if !line.trim_start().starts_with('#') && !line.trim().is_empty() && (prony_table || shaft_table || line.contains(" = ")) {
                out.push_str("  # ");
                out.push_str(&note.1);
                prony_seen |= wanted == "prony";
                shaft_seen |= wanted == "shaft_prony";
            }
        }
        out.push('\n');
    }
    out
}
