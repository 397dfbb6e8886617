//! Atomic file writes: a temporary beside the file, synced, then renamed over it, so a
//! reader never sees half a file; several files that belong together all or nothing.

use anyhow::{Context, Result};
use std::io::Write;
use std::path::Path;

/// Write `bytes` to `path` atomically: a temporary file in the same folder, flushed and
/// synced, then renamed over `path`. A crash leaves either the old file or the new one;
/// a failed write removes its temporary; stale temporaries of `path` from processes that
/// are gone are removed first.
///
/// Only a regular file (or nothing) at `path` is replaced: a symlink, a FIFO, a device
/// or a folder there is refused, untouched (the rename would replace a symlink with a
/// regular file, and the data would not reach what it points to).
///
/// # Errors
/// The folder cannot be written; `path` is not a regular file.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    write_all_atomic(&[(path, bytes)])
}

/// [`write_atomic`] for output written as it is made: `write` gets a buffered writer on
/// a temporary in `path`'s folder; when it returns `Ok` the temporary is flushed,
/// synced and renamed over `path`; when it fails (or the flush does) the temporary is
/// removed and `path` is left as it was: nothing written. Memory stays bounded by what
/// `write` holds.
///
/// # Errors
/// As [`write_atomic`], or `write`'s error.
pub fn write_atomic_streamed<T>(path: &Path, write: impl FnOnce(&mut dyn Write) -> Result<T>) -> Result<T> {
    refuse_special(path).context("nothing written")?;
    remove_stale_temporaries(path);
    let dir = path.parent().with_context(|| format!("{}: no parent folder", path.display()))?;
    create_folder(dir)?;
    let tmp = temporary_of(path)?;
    let result = (|| -> Result<T> {
        let f = std::fs::File::create(&tmp).with_context(|| format!("{}: cannot create (its temporary beside it)", path.display()))?;
        let mut w = std::io::BufWriter::with_capacity(1 << 20, f);
        let value = write(&mut w)?;
        let f = w.into_inner().map_err(|e| e.into_error()).with_context(|| format!("{}: cannot write", path.display()))?;
        f.sync_all().with_context(|| format!("{}: cannot sync", path.display()))?;
        Ok(value)
    })();
    match result {
        Ok(v) => {
            if let Err(e) = std::fs::rename(&tmp, path) {
                let _ = std::fs::remove_file(&tmp);
                anyhow::bail!("{}: cannot replace it with the new file: {e}", path.display());
            }
            Ok(v)
        }
        Err(e) => {
            let _ = std::fs::remove_file(&tmp);
            Err(e.context("nothing written"))
        }
    }
}

/// [`write_atomic`] for several files that belong together (the C headers, a set's
/// figures): every path is checked and every temporary written and synced before the
/// first rename, so a failure (a full disk, a refused path) leaves every old file as it
/// was and no new one beside them ("nothing written"); the renames then replace them all
/// (they stay in their folders and do not fail on a checked target; a crash between two
/// of them can leave the first ones new).
///
/// # Errors
/// As [`write_atomic`], for any of the files; then none is replaced.
pub fn write_all_atomic(files: &[(&Path, &[u8])]) -> Result<()> {
    for (path, _) in files {
        refuse_special(path).context("nothing written")?;
    }
    let mut written: Vec<(std::path::PathBuf, &Path)> = Vec::with_capacity(files.len());
    for (path, bytes) in files {
        // temporaries of `path` left by a killed process go first
        remove_stale_temporaries(path);
        match write_temporary(path, bytes) {
            Ok(tmp) => written.push((tmp, path)),
            Err(e) => {
                for (tmp, _) in &written {
                    let _ = std::fs::remove_file(tmp);
                }
                return Err(e.context("nothing written"));
            }
        }
    }
    for (i, (tmp, path)) in written.iter().enumerate() {
        if let Err(e) = std::fs::rename(tmp, path) {
            for (t, _) in written.iter().skip(i) {
                let _ = std::fs::remove_file(t);
            }
            anyhow::bail!("{}: cannot replace it with the new file: {e}", path.display());
        }
    }
    Ok(())
}

/// Creates folder `dir` and its parents; a file in the way is named as such (not "File
/// exists").
///
/// # Errors
/// A part of `dir` is a file, or the folder cannot be created.
pub fn create_folder(dir: &Path) -> Result<()> {
    if let Some(file) = dir.ancestors().find(|a| std::fs::metadata(a).is_ok_and(|m| !m.is_dir())) {
        anyhow::bail!("{}: cannot create: {} is a file, not a folder", dir.display(), file.display());
    }
    std::fs::create_dir_all(dir).with_context(|| format!("{}: cannot create", dir.display()))
}

/// Checks, before any work, that [`write_atomic`] could write `path`: it is a regular
/// file or nothing, no file is in the way of its folder, and the folder (or the nearest
/// one that exists) takes a new file (a probe file made and removed). Nothing is left.
///
/// # Errors
/// As [`write_atomic`] would fail (the path, the reason).
pub fn check_writable(path: &Path) -> Result<()> {
    refuse_special(path)?;
    let dir = path.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
    if let Some(file) = dir.ancestors().find(|a| std::fs::metadata(a).is_ok_and(|m| !m.is_dir())) {
        anyhow::bail!("{}: is a file, not a folder, so {} cannot be written", file.display(), path.display());
    }
    let existing = dir.ancestors().find(|a| a.is_dir()).unwrap_or(Path::new("."));
    let probe = existing.join(format!(".needle-probe.{}.tmp", std::process::id()));
    match std::fs::File::create(&probe) {
        Ok(_) => {
            let _ = std::fs::remove_file(&probe);
            Ok(())
        }
        Err(e) => anyhow::bail!("{}: cannot be written: folder {}: {e}", path.display(), existing.display()),
    }
}

/// Refuses a path where something other than a regular file is (module rule of
/// [`write_atomic`]).
fn refuse_special(path: &Path) -> Result<()> {
    if let Ok(meta) = std::fs::symlink_metadata(path) {
        let t = meta.file_type();
        if !t.is_file() {
            let what = if t.is_symlink() {
                "a symbolic link"
            } else if t.is_dir() {
                "a folder"
            } else {
                "not a regular file (a FIFO, socket or device)"
            };
            anyhow::bail!("{}: is {what}; only a regular file is replaced (write to a regular path)", path.display());
        }
    }
    Ok(())
}

/// The temporary of `path` for this process: `.<name>.<pid>.tmp` beside it.
fn temporary_of(path: &Path) -> Result<std::path::PathBuf> {
    let dir = path.parent().with_context(|| format!("{}: no parent folder", path.display()))?;
    let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("out");
    Ok(dir.join(format!(".{name}.{}.tmp", std::process::id())))
}

/// Write `bytes` to the temporary of `path` (synced); removed again on failure.
fn write_temporary(path: &Path, bytes: &[u8]) -> Result<std::path::PathBuf> {
    let dir = path.parent().with_context(|| format!("{}: no parent folder", path.display()))?;
    create_folder(dir)?;
    let tmp = temporary_of(path)?;
    let written = (|| -> Result<()> {
        let mut f = std::fs::File::create(&tmp).with_context(|| format!("{}: cannot create (its temporary beside it)", path.display()))?;
        f.write_all(bytes).with_context(|| format!("{}: cannot write", path.display()))?;
        f.sync_all().with_context(|| format!("{}: cannot sync", path.display()))?;
        Ok(())
    })();
    if let Err(e) = written {
        let _ = std::fs::remove_file(&tmp);
        return Err(e);
    }
    Ok(tmp)
}

/// Remove temporaries `.<name>.<pid>.tmp` of `path` left by processes that are gone
/// (a crash or kill between write and rename). Linux: a pid is alive while `/proc/<pid>`
/// exists; elsewhere only this process's own temporary is kept.
pub fn remove_stale_temporaries(path: &Path) {
    let (Some(dir), Some(name)) = (path.parent(), path.file_name().and_then(|n| n.to_str())) else { return };
    let prefix = format!(".{name}.");
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    for e in entries.flatten() {
        let file = e.file_name();
        let Some(rest) = file.to_str().and_then(|f| f.strip_prefix(&prefix)).and_then(|r| r.strip_suffix(".tmp")) else { continue };
        let Ok(pid) = rest.parse::<u32>() else { continue };
        let alive = pid == std::process::id() || (cfg!(target_os = "linux") && Path::new(&format!("/proc/{pid}")).exists());
        if !alive {
            let _ = std::fs::remove_file(e.path());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Issue 66: an error names the file asked for, never its temporary
    /// (`.x.toml.<pid>.tmp`): here the temporary's name is taken by a folder.
    #[test]
    fn message_a_failed_write_names_the_file_not_its_temporary() {
        let d = tempfile::tempdir().expect("tempdir");
        let path = d.path().join("x.toml");
        std::fs::create_dir(temporary_of(&path).expect("temporary")).expect("a folder in the way");
        let e = format!("{:#}", write_atomic(&path, b"new").expect_err("the temporary cannot be made"));
        assert!(e.contains("x.toml: cannot create") && !e.contains(".x.toml."), "{e}");
        let e = format!("{:#}", write_atomic_streamed(&path, |w| Ok(w.write_all(b"x")?)).expect_err("the same"));
        assert!(e.contains("x.toml: cannot create") && !e.contains(".x.toml."), "{e}");
    }

    /// Issue 66: a file where a folder of the path must be is named as such, not "File
    /// exists (os error 17)".
    #[test]
    fn message_a_file_in_the_way_of_a_folder_is_named() {
        let d = tempfile::tempdir().expect("tempdir");
        std::fs::write(d.path().join("plain"), "x").expect("write");
        let path = d.path().join("plain/sub/x.svg");
        let e = format!("{:#}", write_atomic(&path, b"new").expect_err("a file in the way"));
        assert!(e.contains("is a file, not a folder") && !e.contains("os error 17"), "{e}");
        let e = format!("{:#}", check_writable(&path).expect_err("a file in the way"));
        assert!(e.contains("is a file, not a folder"), "{e}");
        check_writable(&d.path().join("new/deeper/x.svg")).expect("a folder to be made");
        assert!(!d.path().join("new").exists(), "the check makes nothing");
    }

    /// A failure while writing the second file (its folder cannot be made: a file is in
    /// the way) leaves the first file's old content and no temporary of either.
    #[test]
    fn write_all_atomic_replaces_all_or_nothing() {
        let d = tempfile::tempdir().expect("tempdir");
        let first = d.path().join("a.txt");
        std::fs::write(&first, "old").expect("write");
        std::fs::write(d.path().join("blocker"), "a file, not a folder").expect("write");
        let second = d.path().join("blocker").join("b.txt");
        let e = write_all_atomic(&[(&first, b"new"), (&second, b"new")]).expect_err("the second cannot be written");
        assert!(format!("{e:#}").contains("cannot create"), "{e:#}");
        assert_eq!(std::fs::read_to_string(&first).expect("read"), "old");
        let mut names: Vec<String> =
            std::fs::read_dir(d.path()).expect("dir").map(|e| e.expect("e").file_name().to_string_lossy().into_owned()).collect();
        names.sort();
        assert_eq!(names, ["a.txt", "blocker"], "no temporary left");
        let third = d.path().join("c.txt");
        write_all_atomic(&[(&first, b"new"), (&third, b"new")]).expect("both writable");
        assert_eq!(
            (std::fs::read_to_string(&first).expect("a"), std::fs::read_to_string(&third).expect("c")),
            ("new".into(), "new".into())
        );
    }
}
