//! The `golden` firmware's stiffness section against the set's
//! `golden-stiffness-f32.csv`: inputs and status exactly, every rate by its bits (NaN by
//! class), and the firmware's own count of rows whose `wrench_and_stiffness` wrench is
//! not `wrench`'s must be 0.
use super::comparison::{same_f32, Comparison, Section};
use anyhow::bail;
use needle_fit::golden::stiffness_float32::{header, rate_columns};

/// Compares the stiffness section of the `golden` firmware's stdout `output` (after its
/// `needle-golden-stiffness rows=N` line) with the text `csv` of golden-stiffness-f32.csv.
///
/// # Errors
/// The section is missing, truncated or malformed, holds another number of rows, or
/// the firmware found a wrench that differs from `wrench`'s; differing rates are
/// [`Comparison::mismatches`].
pub fn compare(output: &str, csv: &str) -> anyhow::Result<Comparison> {
    let header = header();
    let columns = rate_columns(false);
    let section = Section {
        file: "golden-stiffness-f32.csv",
        tag: "needle-golden-stiffness",
        header: &header,
        fields: 6 + columns.len(),
        end_suffix: " wrench_differs=0",
    };
    section.compare(output, csv, |line, want, got| {
        let mut diffs = Vec::new();
        if want.get(5) != got.get(5) {
            diffs.push(format!("status want {:?} got {:?}", want.get(5), got.get(5)));
        }
        for (name, (a, b)) in columns.iter().zip(want.iter().zip(got).skip(6)) {
            let (Some(x), Some(y)) = (needle_codegen::parse_bits(a), needle_codegen::parse_bits(b)) else {
                bail!("golden-stiffness-f32.csv line {line}, {name}: {a:?} / firmware {b:?} is not 0x and 8 hex digits");
            };
            if !same_f32(x, y) {
                diffs.push(format!("{name} want {a} ({:e}) got {b} ({:e})", f32::from_bits(x), f32::from_bits(y)));
            }
        }
        Ok(diffs)
    })
}
