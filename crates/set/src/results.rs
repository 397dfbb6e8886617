//! FE result files `fe/<pose>.csv`: one row per depth, the reaction wrench on the needle.
//! Format: coeffs/README.md, "FE result files".

pub use crate::results_error::CsvError;
use anyhow::{bail, Context, Result};
use needle_contract::COMPONENT_COUNT;
use std::path::Path;

/// Header of a ramp-and-hold result's first column: the time, s, before the FE result's
/// columns ([`to_timed_csv`]).
pub const TIME_COLUMN: &str = "time_s";

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

/// The CSV text of a ramp-and-hold result (`needle_fe::visco`): a `time_s` column (s) before
/// the columns of [`to_csv`], one time per row.
pub fn to_timed_csv(times_s: &[f64], rows: &[Row]) -> String {
    let plain = to_csv(rows);
    let mut s = String::with_capacity(plain.len() + 24 * (rows.len() + 1));
    for (i, line) in plain.lines().enumerate() {
        match i.checked_sub(1).map(|k| times_s.get(k)) {
            None => s.push_str(TIME_COLUMN),
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
            bail!("{}:{}: no {} column: {line:?}", path.display(), i + 1, TIME_COLUMN);
        };
        if i == 0 {
            if t.trim() != TIME_COLUMN {
                bail!("{}:1: first column {t:?}, expected {:?}", path.display(), TIME_COLUMN);
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
}
