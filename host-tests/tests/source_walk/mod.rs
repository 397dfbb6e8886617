//! The workspace's Rust sources for the tests that read them as text (function lengths,
//! dates in comments): a shared walk, so both read the same files.
use std::path::{Path, PathBuf};

/// The workspace's root folder.
pub fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// Every `.rs` file under `dir`, recursively, without `target` folders and without the
/// files `skip` accepts; sorted.
pub fn rust_files(dir: &Path, skip: &dyn Fn(&Path) -> bool) -> Vec<PathBuf> {
    let mut out = Vec::new();
    walk(dir, skip, &mut out);
    out.sort();
    out
}

fn walk(dir: &Path, skip: &dyn Fn(&Path) -> bool, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    for e in entries.flatten() {
        let p = e.path();
        if p.is_dir() {
            if p.file_name().is_some_and(|n| n != "target") {
                walk(&p, skip, out);
            }
        } else if p.extension().is_some_and(|x| x == "rs") && !skip(&p) {
            out.push(p);
        }
    }
}
