//! The files a command will write, checked before its work (`needle calibrate`,
//! `needle calibrate-published`, `needle insertion-paths`): each can be written, none is
//! one of the set's own files ([`SET_OWN_FILES`]) or an input, no two are the same, and an existing one is
//! replaced only when asked (`--force`). The command then writes them all or nothing
//! (`needle_stdx::fs::write_all_atomic`).
use anyhow::{bail, Result};
use std::path::{Component, Path, PathBuf};

/// The files of a set that no command but its own writes (`needle fit`, `needle fe`):
/// the model, the campaign, the unsolved region, the depth extension, the goldens, the
/// README; and everything under `fe/` (the measured curves under `measured/` are
/// protected as inputs: `needle calibrate-published --sampled-out` writes one there).
pub const SET_OWN_FILES: [&str; 9] = [
    "model.toml",
    "campaign.toml",
    "unsolved.toml",
    "depth-extension.toml",
    "golden-f32.csv",
    "golden-fixed.csv",
    "golden-stiffness-f32.csv",
    "golden-stiffness-fixed.csv",
    "README.md",
];

/// The folders of a set whose files no output may replace.
pub const SET_OWN_FOLDERS: [&str; 1] = ["fe"];

/// One planned output: the option that names it (for messages) and the path.
pub struct Planned<'a> {
    /// The option, e.g. `--out`.
    pub option: &'a str,
    /// Where it will be written.
    pub path: &'a Path,
}

/// Checks `outputs` before any work: writable ([`needle_stdx::fs::check_writable`]), not
/// one of `set`'s own files ([`SET_OWN_FILES`], [`SET_OWN_FOLDERS`]) nor one of `inputs`
/// (option, path), no two the same, and not an existing file unless `force`.
///
/// # Errors
/// The first output refused, with its option, its path and the way out.
pub fn check(outputs: &[Planned<'_>], set: Option<&Path>, inputs: &[(&str, &Path)], force: bool) -> Result<()> {
    let set_root = set.map(resolve);
    for (k, out) in outputs.iter().enumerate() {
        let here = resolve(out.path);
        if let Some(root) = &set_root {
            if let Ok(inside) = here.strip_prefix(root) {
                let first = inside.components().next().map(|c| c.as_os_str().to_string_lossy().into_owned()).unwrap_or_default();
                let own_file = inside.components().count() == 1 && SET_OWN_FILES.contains(&first.as_str());
                let own_folder = inside.components().count() > 1 && SET_OWN_FOLDERS.contains(&first.as_str());
                if own_file || own_folder {
                    bail!(
                        "{} {}: is the set's own {} (written only by needle fit / needle fe): choose another path; nothing written",
                        out.option,
                        out.path.display(),
                        inside.display()
                    );
                }
            }
        }
        for (option, input) in inputs {
            if resolve(input) == here {
                bail!("{} {}: is the input {option}: an output never replaces its input; nothing written", out.option, out.path.display());
            }
        }
        for earlier in outputs.iter().take(k) {
            if resolve(earlier.path) == here {
                bail!(
                    "{} and {} both name {}: each output needs its own file; nothing written",
                    earlier.option,
                    out.option,
                    out.path.display()
                );
            }
        }
        needle_stdx::fs::check_writable(out.path).map_err(|e| anyhow::anyhow!("{} {e:#}; nothing written", out.option))?;
        if !force && std::fs::symlink_metadata(out.path).is_ok() {
            bail!("{} {}: exists; --force replaces it (nothing written)", out.option, out.path.display());
        }
    }
    Ok(())
}

/// `path` absolute, with `.` and `..` and the symbolic links of the part that exists
/// resolved (the rest appended), so that two names of one file compare equal.
#[must_use]
pub fn resolve(path: &Path) -> PathBuf {
    let absolute = if path.is_absolute() { path.to_path_buf() } else { std::env::current_dir().unwrap_or_default().join(path) };
    let mut existing = absolute.as_path();
    let mut rest: Vec<Component<'_>> = Vec::new();
    loop {
        if let Ok(real) = std::fs::canonicalize(existing) {
            let mut out = real;
            for c in rest.iter().rev() {
                match c {
                    Component::ParentDir => {
                        out.pop();
                    }
                    Component::CurDir => {}
                    other => out.push(other.as_os_str()),
                }
            }
            return out;
        }
        match (existing.parent(), existing.components().next_back()) {
            (Some(parent), Some(last)) => {
                rest.push(last);
                existing = parent;
            }
            _ => return absolute,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_names_of_one_file_resolve_equal() {
        let d = tempfile::tempdir().expect("tempdir");
        std::fs::create_dir(d.path().join("a")).expect("mkdir");
        let one = resolve(&d.path().join("a/../a/./x.toml"));
        let two = resolve(&d.path().join("a/x.toml"));
        assert_eq!(one, two);
        assert_eq!(resolve(&d.path().join("new/deeper/../y.svg")), resolve(&d.path().join("new/y.svg")));
    }
}
