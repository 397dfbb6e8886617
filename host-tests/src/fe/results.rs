//! FE result files `fe/<pose>.csv`: one row per depth, the reaction wrench on the needle.
//! Format: coeffs/README.md, "FE result files".

use anyhow::{bail, Context, Result};
use std::io::Write;
use std::path::Path;

/// The header line of every FE result file.
pub const HEADER: &str = "depth_mm,fx_n,fy_n,fz_n,mx_nmm,my_nmm,mz_nmm";

/// One row: depth (mm) and the wrench (N, N·mm) about the needle's reference point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Row {
    /// Depth along the needle axis, mm.
    pub depth_mm: f64,
    /// fx_n, fy_n, fz_n, mx_nmm, my_nmm, mz_nmm.
    pub wrench: [f64; 6],
}

/// The CSV text of a result (header and rows, `\n` line ends, shortest round-trip numbers).
pub fn to_csv(rows: &[Row]) -> String {
    let mut s = String::with_capacity(64 * (rows.len() + 1));
    s.push_str(HEADER);
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
/// Wrong header, a row without 7 fields, a field that is not a finite number: the
/// message has `path:line` and the offending value.
pub fn parse_csv(text: &str, path: &Path) -> Result<Vec<Row>> {
    let mut lines = text.lines().enumerate();
    match lines.next() {
        Some((_, h)) if h.trim() == HEADER => {}
        Some((_, h)) => bail!("{}:1: header is {h:?}, expected {HEADER:?}", path.display()),
        None => bail!("{}:1: empty file, expected the header {HEADER:?}", path.display()),
    }
    let mut rows = Vec::new();
    for (i, line) in lines {
        let n = i + 1;
        if line.trim().is_empty() {
            continue;
        }
        let fields: Vec<&str> = line.split(',').collect();
        if fields.len() != 7 {
            bail!("{}:{n}: {} fields, expected 7: {line:?}", path.display(), fields.len());
        }
        let mut v = [0.0f64; 7];
        for (k, f) in fields.iter().enumerate() {
            let x: f64 = f
                .trim()
                .parse()
                .with_context(|| format!("{}:{n}: field {} = {f:?} is not a number", path.display(), k + 1))?;
            if !x.is_finite() {
                bail!("{}:{n}: field {} = {f:?} is not finite", path.display(), k + 1);
            }
            v[k] = x;
        }
        rows.push(Row { depth_mm: v[0], wrench: [v[1], v[2], v[3], v[4], v[5], v[6]] });
    }
    Ok(rows)
}

/// Read an FE result file.
///
/// # Errors
/// As [`parse_csv`], or the file cannot be read.
pub fn read_csv(path: &Path) -> Result<Vec<Row>> {
    let text = std::fs::read_to_string(path).with_context(|| format!("{}: cannot read", path.display()))?;
    parse_csv(&text, path)
}

/// Write `bytes` to `path` atomically: a temporary file in the same folder, flushed and
/// synced, then renamed over `path`. A crash leaves either the old file or the new one.
///
/// # Errors
/// The folder cannot be written.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<()> {
    let dir = path.parent().with_context(|| format!("{}: no parent folder", path.display()))?;
    std::fs::create_dir_all(dir).with_context(|| format!("{}: cannot create", dir.display()))?;
    let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("out");
    let tmp = dir.join(format!(".{name}.{}.tmp", std::process::id()));
    {
        let mut f = std::fs::File::create(&tmp).with_context(|| format!("{}: cannot create", tmp.display()))?;
        f.write_all(bytes).with_context(|| format!("{}: cannot write", tmp.display()))?;
        f.sync_all().with_context(|| format!("{}: cannot sync", tmp.display()))?;
    }
    std::fs::rename(&tmp, path).with_context(|| format!("{}: cannot rename to {}", tmp.display(), path.display()))?;
    Ok(())
}
