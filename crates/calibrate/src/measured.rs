//! The measured curve: axial force against needle position, from a CSV file or from two
//! columns of numbers.
use crate::limits::{MAX_BACKWARD_MM, MAX_CURVE_BYTES, MAX_FORCE_N, MAX_POINTS, MAX_SPAN_MM, MIN_SPAN_MM};
use anyhow::{bail, Context, Result};
use std::fmt;
use std::io::Read as _;
use std::path::Path;

/// One measured point, in the file's order (digitised drops can repeat a position).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Point {
    /// Needle (device) position along the insertion, mm.
    pub position_mm: f64,
    /// Axial force on the needle, N (positive resisting the insertion).
    pub force_n: f64,
    /// 1-based line of the point in its file (from columns: the 1-based row).
    pub line: usize,
}

/// The columns a measured file must have.
pub const COLUMNS: [&str; 2] = ["position_mm", "force_n"];

/// Fewest points a calibration takes.
pub const MIN_POINTS: usize = 10;

/// A curve refused at a known place: a value (its row and column) or a column of the
/// header. Displayed as `WHERE: PROBLEM`; carried inside the `anyhow` error so that
/// callers (the Python binding) can say the row and column.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CurveError {
    /// Where, as printed: `FILE:LINE` or `force_n[ROW]`.
    pub at: String,
    /// 1-based line of the file (None for columns given as numbers).
    pub line: Option<usize>,
    /// 0-based data row (None: the header, or the columns as a whole).
    pub row: Option<usize>,
    /// The column (None: the columns as a whole).
    pub column: Option<&'static str>,
    /// What is wrong.
    pub problem: String,
}

impl fmt::Display for CurveError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.at, self.problem)
    }
}

impl std::error::Error for CurveError {}

/// Reads `path`: a header naming `position_mm` and `force_n` (other columns, such as
/// `time_s`, are allowed and ignored), one point per row.
///
/// # Errors
/// Unreadable file, a missing or duplicated column, or a row whose value is not a
/// finite number: `FILE:LINE: column NAME: ...` (a [`CurveError`] inside); fewer than
/// [`MIN_POINTS`] points; more than [`MAX_CURVE_BYTES`] bytes or [`MAX_POINTS`] points
/// (refused while reading: memory stays bounded); numbers no insertion has
/// ([`check_units`]).
pub fn read_curve(path: &Path) -> Result<Vec<Point>> {
    let bytes = read_capped(path)?;
    let mut reader = csv::ReaderBuilder::new().trim(csv::Trim::All).from_reader(bytes.as_slice());
    let header = reader.headers().with_context(|| format!("{}:1: cannot read the header", path.display()))?.clone();
    let mut index = [0usize; 2];
    for (slot, name) in index.iter_mut().zip(COLUMNS) {
        *slot = column_index(&header, name, &COLUMNS).map_err(|problem| {
            let at = format!("{}:1", path.display());
            CurveError { at, line: Some(1), row: None, column: Some(name), problem }
        })?;
    }
    let mut points = Vec::new();
    for (row, record) in reader.records().enumerate() {
        let record = record.with_context(|| format!("{}: malformed CSV", path.display()))?;
        if row >= MAX_POINTS {
            let line = record.position().map_or(0, |p| p.line());
            bail!(
                "{}:{line}: more than {MAX_POINTS} points (the limit of a calibration: its time grows with the points); resample the curve (e.g. every k-th row)",
                path.display()
            );
        }
        let line = record.position().map_or(0, |p| p.line() as usize);
        let value = |i: usize, name: &'static str| -> Result<f64, CurveError> {
            let text = record.get(i).unwrap_or("");
            let shown: String = text.chars().take(40).collect();
            let refuse = |what: &str| CurveError {
                at: format!("{}:{line}", path.display()),
                line: Some(line),
                row: Some(row),
                column: Some(name),
                problem: format!("column {name}: {shown:?} is not {what}"),
            };
            let v: f64 = text.parse().map_err(|_| refuse("a number"))?;
            if v.is_finite() {
                Ok(v)
            } else {
                Err(refuse("finite"))
            }
        };
        let [ip, iforce] = index;
        points.push(Point { position_mm: value(ip, COLUMNS[0])?, force_n: value(iforce, COLUMNS[1])?, line });
    }
    enough(points, Some(&path.display().to_string()))
}

/// The curve from two columns of numbers (`position_mm[i]`, `force_n[i]`), checked like
/// a file's rows.
///
/// # Errors
/// The columns differ in length, a value is not finite (`force_n[ROW]: ...`, a
/// [`CurveError`] inside), there are fewer than [`MIN_POINTS`] or more than
/// [`MAX_POINTS`] points, or numbers no insertion has ([`check_units`]).
pub fn from_columns(position_mm: &[f64], force_n: &[f64]) -> Result<Vec<Point>> {
    if position_mm.len() != force_n.len() {
        let problem = format!("{} positions and {} forces: one force per position", position_mm.len(), force_n.len());
        return Err(CurveError { at: "position_mm, force_n".into(), line: None, row: None, column: None, problem }.into());
    }
    let mut points = Vec::with_capacity(position_mm.len());
    for (row, (&p, &f)) in position_mm.iter().zip(force_n).enumerate() {
        for (v, name) in [(p, COLUMNS[0]), (f, COLUMNS[1])] {
            if !v.is_finite() {
                let problem = format!("is {v}: every value must be finite");
                return Err(CurveError { at: format!("{name}[{row}]"), line: None, row: Some(row), column: Some(name), problem }.into());
            }
        }
        points.push(Point { position_mm: p, force_n: f, line: row + 1 });
    }
    enough(points, None)
}

/// The index of the one column `name` of `header`; the problem, naming the columns
/// `needed`, when it is missing or repeated.
pub(crate) fn column_index(header: &csv::StringRecord, name: &str, needed: &[&str]) -> Result<usize, String> {
    let found: Vec<usize> = header.iter().enumerate().filter(|(_, h)| *h == name).map(|(i, _)| i).collect();
    match found.as_slice() {
        [i] => Ok(*i),
        [] => Err(format!("no column {name:?} (the header has {:?}; needed: {needed:?})", header.iter().collect::<Vec<_>>())),
        _ => Err(format!("column {name:?} appears {} times", found.len())),
    }
}

fn enough(points: Vec<Point>, file: Option<&str>) -> Result<Vec<Point>> {
    let what = file.unwrap_or("the curve");
    if points.len() < MIN_POINTS {
        bail!("{what}: {} points: a calibration needs at least {MIN_POINTS}", points.len());
    }
    if points.len() > MAX_POINTS {
        bail!(
            "{what}: {} points: more than {MAX_POINTS} (the limit of a calibration: its time grows with the points); resample the curve",
            points.len()
        );
    }
    check_units(&points, file)?;
    Ok(points)
}

/// The bytes of `path`, at most [`MAX_CURVE_BYTES`] (a larger file, or an endless stream,
/// is refused without reading it all).
fn read_capped(path: &Path) -> Result<Vec<u8>> {
    let file = std::fs::File::open(path).with_context(|| format!("{}: cannot read", path.display()))?;
    let meta = file.metadata().with_context(|| format!("{}: cannot read", path.display()))?;
    if meta.is_dir() {
        bail!("{}: is a folder: --curve names a CSV file", path.display());
    }
    let too_big = |size: String| {
        anyhow::anyhow!(
            "{}: {size}: a curve file is at most {MAX_CURVE_BYTES} bytes ({} MiB; at most {MAX_POINTS} points): resample the curve (e.g. every k-th row)",
            path.display(),
            MAX_CURVE_BYTES >> 20
        )
    };
    if meta.is_file() && meta.len() > MAX_CURVE_BYTES {
        return Err(too_big(format!("{} bytes", meta.len())));
    }
    let mut bytes = Vec::new();
    file.take(MAX_CURVE_BYTES + 1).read_to_end(&mut bytes).with_context(|| format!("{}: cannot read", path.display()))?;
    if bytes.len() as u64 > MAX_CURVE_BYTES {
        return Err(too_big(format!("more than {MAX_CURVE_BYTES} bytes (a stream that does not end?)")));
    }
    Ok(bytes)
}

/// Refuses a curve whose numbers no needle insertion has (the unit sanity check of
/// [`crate::limits`]): positions all equal or spanning less than
/// [`MIN_SPAN_MM`] or more than [`MAX_SPAN_MM`], a force beyond [`MAX_FORCE_N`] (by
/// its line), rows out of order (a step back of more than [`MAX_BACKWARD_MM`]).
///
/// # Errors
/// The first such problem, with where and the likely cause.
pub fn check_units(points: &[Point], file: Option<&str>) -> Result<()> {
    let what = file.unwrap_or("the curve");
    // a file's point is named by its line, a column's by its index
    let refuse = |row: usize, column: &'static str, problem: String| -> anyhow::Error {
        let line = points.get(row).map_or(0, |p| p.line);
        let (at, line) = match file {
            Some(path) => (format!("{path}:{line}"), Some(line)),
            None => (format!("{column}[{row}]"), None),
        };
        CurveError { at, line, row: Some(row), column: Some(column), problem }.into()
    };
    if let Some((row, p)) = points.iter().enumerate().find(|(_, p)| p.force_n.abs() > MAX_FORCE_N) {
        let problem = format!(
            "column force_n: {} N is beyond +-{MAX_FORCE_N} N, more than any needle insertion (a spike of the sensor? forces in mN?)",
            p.force_n
        );
        return Err(refuse(row, COLUMNS[1], problem));
    }
    let (lo, hi) = points.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| (lo.min(p.position_mm), hi.max(p.position_mm)));
    let span = hi - lo;
    if span == 0.0 {
        bail!("{what}: every position is {lo} mm: an insertion moves the needle (column position_mm)");
    }
    if span < MIN_SPAN_MM {
        bail!("{what}: positions span {span} mm, less than {MIN_SPAN_MM} mm: no insertion with a puncture is this short (positions in metres? the column is position_mm)");
    }
    if span > MAX_SPAN_MM {
        bail!("{what}: positions span {span} mm, more than {MAX_SPAN_MM} mm: no needle insertion is this long (positions in micrometres? the column is position_mm)");
    }
    for (row, pair) in points.windows(2).enumerate() {
        let [a, b] = pair else { continue };
        if a.position_mm - b.position_mm > MAX_BACKWARD_MM {
            let problem = format!(
                "column position_mm: {} mm after {} mm, a step back of more than {MAX_BACKWARD_MM} mm: the rows must be in the order of the insertion (shuffled or sorted by force?)",
                b.position_mm, a.position_mm
            );
            return Err(refuse(row + 1, COLUMNS[0], problem));
        }
    }
    Ok(())
}
