//! `needle eval --poses FILE.csv`: the library's wrench for every row of a pose file.
//!
//! Input: a CSV file with a header naming the columns `x_mm`, `z_mm`, `theta_x_deg`,
//! `theta_z_deg`, `depth_mm` (any order, other columns ignored), one pose per row.
//! Every row must hold five numbers (NaN and infinities are numbers: the library
//! answers them with the error status); a row that does not is reported as
//! `FILE:LINE: column NAME: "TEXT" is not a number` (a field longer than
//! [`MAX_ECHO_CHARS`] is cut, its length given), the bad rows are counted and the first
//! [`MAX_LISTED`] problems listed, and nothing is written. A header naming a pose column
//! twice is refused (which one would be meant?). Output: one row per input row, in input
//! order.

use anyhow::{bail, Context, Result};
use needle_haptics::{wrench, Evaluation, Pose};
use std::fmt::Write as _;
use std::path::Path;

/// Input columns, in the order of [`Pose`]'s fields.
pub const POSE_COLUMNS: [&str; 5] = ["x_mm", "z_mm", "theta_x_deg", "theta_z_deg", "depth_mm"];

/// Output header of the CSV form.
pub const OUTPUT_HEADER: &str = "x_mm,z_mm,theta_x_deg,theta_z_deg,depth_mm,fx_n,fy_n,fz_n,mx_nmm,my_nmm,mz_nmm,status";

/// Most problems listed in one error message (the count of bad rows is always given).
pub const MAX_LISTED: usize = 20;

/// Most characters of a bad field echoed in a message.
pub const MAX_ECHO_CHARS: usize = 40;

/// `text` as a message shows it: quoted, cut after [`MAX_ECHO_CHARS`] characters with
/// its length in bytes.
fn echo(text: &str) -> String {
    needle_set::results_error::echo_cut(text, MAX_ECHO_CHARS)
}

/// The pose columns' indices in `header` (in [`POSE_COLUMNS`] order).
///
/// # Errors
/// A missing column, or one named twice (`FILE:1: ...`).
pub fn pose_columns(header: &csv::StringRecord, path: &Path) -> Result<[usize; 5]> {
    let mut idx = [0usize; 5];
    for (slot, name) in idx.iter_mut().zip(POSE_COLUMNS) {
        let mut at = header.iter().enumerate().filter(|(_, h)| *h == name).map(|(i, _)| i);
        *slot = at
            .next()
            .with_context(|| format!("{}:1: no column {name:?} in the header (need {})", path.display(), POSE_COLUMNS.join(", ")))?;
        if let Some(again) = at.next() {
            bail!("{}:1: column {name:?} appears twice in the header (columns {} and {})", path.display(), *slot + 1, again + 1);
        }
    }
    Ok(idx)
}

/// One row's pose from the fields at `idx` (`field(i)` gives field `i`; ASCII white
/// space around a number is ignored), or the row's problems pushed to `bad` as
/// `FILE:LINE: column NAME: ...` (the field echoed trimmed).
pub fn parse_row<'a>(
    field: impl Fn(usize) -> Option<&'a [u8]>,
    len: usize,
    idx: &[usize; 5],
    at: (&Path, u64),
    bad: &mut Vec<String>,
) -> Option<Pose> {
    let (path, line) = at;
    let mut v = [0f32; 5];
    let mut ok = true;
    for ((slot, &i), name) in v.iter_mut().zip(idx).zip(POSE_COLUMNS) {
        match field(i) {
            Some(bytes) => match std::str::from_utf8(bytes.trim_ascii()).ok().and_then(|t| t.parse::<f32>().ok()) {
                Some(x) => *slot = x,
                None => {
                    let t = String::from_utf8_lossy(bytes.trim_ascii());
                    bad.push(format!("{}:{line}: column {name}: {} is not a number", path.display(), echo(&t)));
                    ok = false;
                }
            },
            None => {
                bad.push(format!("{}:{line}: column {name}: missing ({len} fields in the row)", path.display()));
                ok = false;
            }
        }
    }
    ok.then(|| Pose { x_mm: v[0], z_mm: v[1], theta_x_deg: v[2], theta_z_deg: v[3], depth_mm: v[4] })
}

/// The error for `bad_rows` bad rows with their `problems` (the first [`MAX_LISTED`]
/// listed, the rest counted).
pub fn bad_rows_error(bad_rows: usize, problems: &[String]) -> anyhow::Error {
    let shown = problems.iter().take(MAX_LISTED).cloned().collect::<Vec<_>>().join("\n");
    let more =
        if problems.len() > MAX_LISTED { format!("\n... and {} more problem(s)", problems.len() - MAX_LISTED) } else { String::new() };
    anyhow::anyhow!("{bad_rows} bad row(s), nothing evaluated:\n{shown}{more}")
}

/// Parse the pose file `text` (named `path` in messages).
///
/// # Errors
/// No header or a missing column; rows that are not five numbers (all listed, by line).
pub fn parse_poses(text: &str, path: &Path) -> Result<Vec<Pose>> {
    let mut rdr = csv::ReaderBuilder::new().trim(csv::Trim::All).flexible(true).from_reader(text.as_bytes());
    let header = rdr.headers().with_context(|| format!("{}:1: cannot read the header", path.display()))?.clone();
    let idx = pose_columns(&header, path)?;
    let mut poses = Vec::new();
    let mut bad: Vec<String> = Vec::new();
    let mut bad_rows = 0usize;
    for rec in rdr.records() {
        let rec = match rec {
            Ok(r) => r,
            Err(e) => {
                let line = e.position().map_or(0, |p| p.line());
                bad.push(format!("{}:{line}: {e}", path.display()));
                bad_rows += 1;
                continue;
            }
        };
        let line = rec.position().map_or(0, |p| p.line());
        match parse_row(|i| rec.get(i).map(str::as_bytes), rec.len(), &idx, (path, line), &mut bad) {
            Some(p) => poses.push(p),
            None => bad_rows += 1,
        }
    }
    if bad_rows > 0 {
        return Err(bad_rows_error(bad_rows, &bad));
    }
    Ok(poses)
}

/// Evaluate every pose with the library.
pub fn evaluate(poses: &[Pose]) -> Vec<Evaluation> {
    poses.iter().map(wrench).collect()
}

/// The CSV form: [`OUTPUT_HEADER`], then per pose the inputs, the six components
/// (shortest decimal that reads back to the same f32) and the status byte in hex.
pub fn to_csv(poses: &[Pose], evals: &[Evaluation]) -> String {
    let mut s = String::with_capacity(poses.len() * 160);
    s.push_str(OUTPUT_HEADER);
    s.push('\n');
    for (p, e) in poses.iter().zip(evals) {
        push_pose_wrench_status(&mut s, p, &e.wrench, e.status);
        s.push('\n');
    }
    s
}

/// One row's shared columns, without a line end: the five pose inputs, the six wrench
/// components (each the shortest decimal that reads back to the same f32) and the status
/// byte in hex (`0x..`), comma-separated (also the scripted insertion's rows).
pub fn push_pose_wrench_status(s: &mut String, p: &Pose, w: &needle_haptics::Wrench, status: needle_haptics::Status) {
    let w = w.to_array();
    let _ = write!(
        s,
        "{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:?},{:#04x}",
        p.x_mm,
        p.z_mm,
        p.theta_x_deg,
        p.theta_z_deg,
        p.depth_mm,
        w[0],
        w[1],
        w[2],
        w[3],
        w[4],
        w[5],
        status.bits()
    );
}
