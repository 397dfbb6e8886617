//! The `golden` firmware's stiffness section against the set's
//! `golden-stiffness-f32.csv`: inputs and status exactly, every rate by its bits (NaN by
//! class), and the firmware's own count of rows whose `wrench_and_stiffness` wrench is
//! not `wrench`'s must be 0.
use super::comparison::{same_f32, Comparison};
use crate::fit::golden_stiffness::{header, RATE_COLUMNS};
use anyhow::bail;

/// Compares the stiffness section of the `golden` firmware's stdout `output` (after its
/// `needle-golden-stiffness rows=N` line) with the text `csv` of golden-stiffness-f32.csv.
///
/// # Errors
/// The section is missing, truncated or malformed, holds another number of rows, or
/// the firmware found a wrench that differs from `wrench`'s; differing rates are
/// [`Comparison::mismatches`].
pub fn compare(output: &str, csv: &str) -> anyhow::Result<Comparison> {
    let header = header();
    let mut want = csv.lines();
    if want.next() != Some(header.as_str()) {
        bail!("golden-stiffness-f32.csv: the first line is not the header {header:?}");
    }
    let want: Vec<&str> = want.collect();
    let mut got = output.lines().skip_while(|l| !l.starts_with("needle-golden-stiffness rows="));
    let banner = got.next().unwrap_or_default().to_string();
    if banner.is_empty() {
        bail!("the firmware printed no stiffness section (no `needle-golden-stiffness rows=` line)");
    }
    if banner != format!("needle-golden-stiffness rows={}", want.len()) {
        bail!("the firmware holds another number of poses than golden-stiffness-f32.csv's {}: {banner:?}", want.len());
    }
    let mut mismatches = Vec::new();
    for (i, w) in want.iter().enumerate() {
        let line = i + 2;
        let Some(g) = got.next() else {
            bail!("the firmware's stiffness output stops before golden-stiffness line {line}");
        };
        let wf: Vec<&str> = w.split(',').collect();
        let gf: Vec<&str> = g.split(',').collect();
        if wf.len() != 24 || gf.len() != 24 {
            bail!("golden-stiffness line {line}: {} fields in the file, {} from the firmware ({g:?}); expected 24", wf.len(), gf.len());
        }
        if wf[..5] != gf[..5] {
            bail!("firmware row for golden-stiffness line {line} has other inputs: {g:?} (golden {w:?})");
        }
        let mut diffs = Vec::new();
        if wf[5] != gf[5] {
            diffs.push(format!("status want {} got {}", wf[5], gf[5]));
        }
        for (name, (a, b)) in RATE_COLUMNS.iter().zip(wf[6..].iter().zip(&gf[6..])) {
            let (Some(x), Some(y)) = (needle_codegen::parse_bits(a), needle_codegen::parse_bits(b)) else {
                bail!("golden-stiffness line {line}, {name}: {a:?} / firmware {b:?} is not 0x and 8 hex digits");
            };
            if !same_f32(x, y) {
                diffs.push(format!("{name} want {a} ({:e}) got {b} ({:e})", f32::from_bits(x), f32::from_bits(y)));
            }
        }
        if !diffs.is_empty() {
            mismatches.push(format!("line {line} (pose {}): {}", wf[..5].join(","), diffs.join("; ")));
        }
    }
    let end = got.next().unwrap_or_default();
    let want_end = format!("needle-golden-stiffness end rows={} wrench_differs=0", want.len());
    if end != want_end {
        bail!("the firmware's stiffness output does not end with {want_end:?}: {end:?}");
    }
    Ok(Comparison { banner, rows: want.len(), mismatches })
}
