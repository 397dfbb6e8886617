//! The measured curve: axial force against needle position, from a CSV file.
use anyhow::{bail, Context, Result};
use std::path::Path;

/// One measured point, in the file's order (digitised drops can repeat a position).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Point {
    /// Needle (device) position along the insertion, mm.
    pub position_mm: f64,
    /// Axial force on the needle, N (positive resisting the insertion).
    pub force_n: f64,
    /// 1-based line of the point in its file.
    pub line: usize,
}

/// The columns a measured file must have.
pub const COLUMNS: [&str; 2] = ["position_mm", "force_n"];

/// Reads `path`: a header naming `position_mm` and `force_n` (other columns, such as
/// `time_s`, are allowed and ignored), one point per row.
///
/// # Errors
/// Unreadable file, a missing or duplicated column, or a row whose value is not a
/// finite number: `FILE:LINE: column NAME: ...`; fewer than 10 points.
pub fn read_curve(path: &Path) -> Result<Vec<Point>> {
    let mut reader =
        csv::ReaderBuilder::new().trim(csv::Trim::All).from_path(path).with_context(|| format!("{}: cannot read", path.display()))?;
    let header = reader.headers().with_context(|| format!("{}:1: cannot read the header", path.display()))?.clone();
    let mut index = [0usize; 2];
    for (slot, name) in index.iter_mut().zip(COLUMNS) {
        let found: Vec<usize> = header.iter().enumerate().filter(|(_, h)| *h == name).map(|(i, _)| i).collect();
        match found.as_slice() {
            [i] => *slot = *i,
            [] => bail!(
                "{}:1: no column {name:?} (the header has {:?}; needed: {:?})",
                path.display(),
                header.iter().collect::<Vec<_>>(),
                COLUMNS
            ),
            _ => bail!("{}:1: column {name:?} appears {} times", path.display(), found.len()),
        }
    }
    let mut points = Vec::new();
    for record in reader.records() {
        let record = record.with_context(|| format!("{}: malformed CSV", path.display()))?;
        let line = record.position().map_or(0, |p| p.line() as usize);
        let value = |i: usize, name: &str| -> Result<f64> {
            let text = record.get(i).unwrap_or("");
            let shown: String = text.chars().take(40).collect();
            let v: f64 =
                text.parse().map_err(|_| anyhow::anyhow!("{}:{line}: column {name}: {shown:?} is not a number", path.display()))?;
            if !v.is_finite() {
                bail!("{}:{line}: column {name}: {shown:?} is not finite", path.display());
            }
            Ok(v)
        };
        let [ip, iforce] = index;
        points.push(Point { position_mm: value(ip, COLUMNS[0])?, force_n: value(iforce, COLUMNS[1])?, line });
    }
    if points.len() < 10 {
        bail!("{}: {} points: a calibration needs at least 10", path.display(), points.len());
    }
    Ok(points)
}
