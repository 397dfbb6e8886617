//! FE result files `fe/<pose>.csv`: one row per depth, the reaction wrench on the needle.
//! Format: coeffs/README.md, "FE result files".

pub use crate::results_error::CsvError;
use anyhow::{bail, Context, Result};
use needle_contract::COMPONENT_COUNT;
use std::io::Write;
use std::path::Path;

/// The header line of every FE result file (the contract's [`FE_COLUMNS`](needle_contract::FE_COLUMNS)).
pub fn header() -> String {
    needle_contract::FE_COLUMNS.join(",")
}

/// One row: depth (mm) and the wrench (N, N·mm) about the needle's reference point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Row {
    /// Depth along the needle axis, mm.
    pub depth_mm: f64,
    /// fx_n, fy_n, fz_n, mx_nmm, my_nmm, mz_nmm.
    pub wrench: [f64; COMPONENT_COUNT],
}

impl Row {
    /// The axial force `fy_n`, N.
    #[must_use]
    pub fn fy_n(&self) -> f64 {
        self.wrench[needle_contract::FY]
    }
}

/// The largest |Fy| of `rows` (N; 0 for none): the scale of relative errors
/// ([`needle_contract::error_scales`]).
pub fn peak_fy_n<'a>(rows: impl IntoIterator<Item = &'a Row>) -> f64 {
    rows.into_iter().map(|r| r.fy_n().abs()).fold(0.0, f64::max)
}

/// The CSV text of a result (header and rows, `\n` line ends, shortest round-trip numbers).
pub fn to_csv(rows: &[Row]) -> String {
    let mut s = String::with_capacity(64 * (rows.len() + 1));
    s.push_str(&header());
    s.push('\n');
    for r in rows {
        s.push_str(&format!("{}", r.depth_mm));
        for v in r.wrench {
            // normalise -0 to 0 so that the files do not depend on the sign of a zero sum
            let v = if v == 0.0 { 0.0 } else { v };
            s.push_str(&format!(",{v}"));
        }
        s.push('\n');
    }
    s
}

/// Parse the CSV text of a result; `path` is only used in messages.
///
/// # Errors
/// [`CsvError`]: no header or another one, a row without one field per column of
/// `FE_COLUMNS` (7), a field that is not a finite number; the message has `path:line` and
/// the offending value (cut after [`MAX_ECHO_CHARS`](crate::results_error::MAX_ECHO_CHARS)
/// characters).
pub fn parse_csv(text: &str, path: &Path) -> std::result::Result<Vec<Row>, CsvError> {
    const FIELDS: usize = needle_contract::FE_COLUMNS.len();
    let mut lines = text.lines().enumerate();
    let header = header();
    match lines.next() {
        Some((_, h)) if h.trim() == header => {}
        Some((_, h)) => return Err(CsvError::Header { path: path.into(), found: h.into(), expected: header }),
        None => return Err(CsvError::Empty { path: path.into(), expected: header }),
    }
    let mut rows = Vec::new();
    for (i, line) in lines {
        let n = i + 1;
        if line.trim().is_empty() {
            continue;
        }
        let fields: Vec<&str> = line.split(',').collect();
        if fields.len() != FIELDS {
            return Err(CsvError::FieldCount { path: path.into(), line: n, found: fields.len(), expected: FIELDS, text: line.into() });
        }
        let mut v = [0.0f64; FIELDS];
        for (k, (slot, f)) in v.iter_mut().zip(&fields).enumerate() {
            let at = |text: &str| (path.to_path_buf(), n, k + 1, text.to_string());
            let x: f64 = f.trim().parse().map_err(|_| {
                let (path, line, field, text) = at(f);
                CsvError::NotANumber { path, line, field, text }
            })?;
            if !x.is_finite() {
                let (path, line, field, text) = at(f);
                return Err(CsvError::NotFinite { path, line, field, text });
            }
            *slot = x;
        }
        rows.push(Row { depth_mm: v[0], wrench: std::array::from_fn(|c| v[1 + c]) });
    }
    Ok(rows)
}

/// The CSV text of a ramp-and-hold result (`crate::visco`): a `time_s` column (s) before
/// the columns of [`to_csv`], one time per row.
pub fn to_timed_csv(times_s: &[f64], rows: &[Row]) -> String {
    let plain = to_csv(rows);
    let mut s = String::with_capacity(plain.len() + 24 * (rows.len() + 1));
    for (i, line) in plain.lines().enumerate() {
        match i.checked_sub(1).map(|k| times_s.get(k)) {
            None => s.push_str(crate::visco::TIME_COLUMN),
            Some(t) => s.push_str(&format!("{}", t.copied().unwrap_or(f64::NAN))),
        }
        s.push(',');
        s.push_str(line);
        s.push('\n');
    }
    s
}

/// Parse a ramp-and-hold result ([`to_timed_csv`]): the times, s, and the rows.
///
/// # Errors
/// As [`parse_csv`], or a row without its time (messages with `path:line`).
pub fn parse_timed_csv(text: &str, path: &Path) -> Result<(Vec<f64>, Vec<Row>)> {
    let mut times = Vec::new();
    let mut plain = String::with_capacity(text.len());
    for (i, line) in text.lines().enumerate() {
        if line.trim().is_empty() {
            continue;
        }
        let Some((t, rest)) = line.split_once(',') else {
            bail!("{}:{}: no {} column: {line:?}", path.display(), i + 1, crate::visco::TIME_COLUMN);
        };
        if i == 0 {
            if t.trim() != crate::visco::TIME_COLUMN {
                bail!("{}:1: first column {t:?}, expected {:?}", path.display(), crate::visco::TIME_COLUMN);
            }
        } else {
            let v: f64 = t.trim().parse().with_context(|| format!("{}:{}: time {t:?} s is not a number", path.display(), i + 1))?;
            if !v.is_finite() {
                bail!("{}:{}: time {t:?} s is not finite", path.display(), i + 1);
            }
            times.push(v);
        }
        plain.push_str(rest);
        plain.push('\n');
    }
    let rows = parse_csv(&plain, path)?;
    Ok((times, rows))
}

/// SHA-256 of a result file's bytes, 64 hex digits: the manifest's `csv_sha256`.
#[must_use]
pub fn content_sha256(bytes: &[u8]) -> String {
    use sha2::{Digest, Sha256};
    crate::spec::hex(&Sha256::digest(bytes))
}

/// Read an FE result file.
///
/// # Errors
/// As [`parse_csv`], or the file cannot be read.
pub fn read_csv(path: &Path) -> Result<Vec<Row>> {
    let text = std::fs::read_to_string(path).with_context(|| format!("{}: cannot read", path.display()))?;
    Ok(parse_csv(&text, path)?)
}

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
    std::fs::create_dir_all(dir).with_context(|| format!("{}: cannot create", dir.display()))?;
    let tmp = temporary_of(path)?;
    let result = (|| -> Result<T> {
        let f = std::fs::File::create(&tmp).with_context(|| format!("{}: cannot create", tmp.display()))?;
        let mut w = std::io::BufWriter::with_capacity(1 << 20, f);
        let value = write(&mut w)?;
        let f = w.into_inner().map_err(|e| e.into_error()).with_context(|| format!("{}: cannot write", tmp.display()))?;
        f.sync_all().with_context(|| format!("{}: cannot sync", tmp.display()))?;
        Ok(value)
    })();
    match result {
        Ok(v) => {
            if let Err(e) = std::fs::rename(&tmp, path) {
                let _ = std::fs::remove_file(&tmp);
                anyhow::bail!("{}: cannot rename to {}: {e}", tmp.display(), path.display());
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
            anyhow::bail!("{}: cannot rename to {}: {e}", tmp.display(), path.display());
        }
    }
    Ok(())
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
    std::fs::create_dir_all(dir).with_context(|| format!("{}: cannot create", dir.display()))?;
    let tmp = temporary_of(path)?;
    let written = (|| -> Result<()> {
        let mut f = std::fs::File::create(&tmp).with_context(|| format!("{}: cannot create", tmp.display()))?;
        f.write_all(bytes).with_context(|| format!("{}: cannot write", tmp.display()))?;
        f.sync_all().with_context(|| format!("{}: cannot sync", tmp.display()))?;
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

    /// Each kind of bad result file is its own [`CsvError`], at its line and field; a
    /// huge bad field is cut in the message.
    #[test]
    fn each_bad_result_file_is_its_own_error() {
        let p = Path::new("fe/x+02.csv");
        let h = header();
        let ok = format!("{h}\n0,0,0,0,0,0,0\n0.3,1e-3,2,3,4,5,6\n");
        assert_eq!(parse_csv(&ok, p).expect("a good file").len(), 2);
        assert!(matches!(parse_csv("", p), Err(CsvError::Empty { .. })));
        assert!(matches!(parse_csv("depth_mm,fy_n\n", p), Err(CsvError::Header { .. })));
        let rows = |row: &str| parse_csv(&format!("{h}\n0,0,0,0,0,0,0\n{row}\n"), p);
        assert!(matches!(rows("0.3,1,2"), Err(CsvError::FieldCount { line: 3, found: 3, expected: 7, .. })));
        assert!(matches!(rows("0.3,1,x,3,4,5,6"), Err(CsvError::NotANumber { line: 3, field: 3, .. })));
        assert!(matches!(rows("0.3,1,2,inf,4,5,6"), Err(CsvError::NotFinite { line: 3, field: 4, .. })));
        let huge = "9".repeat(1 << 20) + "x";
        let e = rows(&format!("0.3,{huge},2,3,4,5,6")).expect_err("not a number");
        assert!(matches!(e, CsvError::NotANumber { field: 2, .. }));
        assert!(e.to_string().len() < 300, "the field is cut: {} bytes of message", e.to_string().len());
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
