//! The `golden` firmware's fixed-point sections against the set's `golden-fixed.csv`
//! (inputs, status and every wrench integer exactly) and `golden-stiffness-fixed.csv`
//! (inputs, status and every rate exactly; the firmware's own count of rows whose
//! `fixed::wrench_and_stiffness` wrench is not `fixed::wrench`'s must be 0).
use super::comparison::{Comparison, Section};

pub use needle_fit::golden::fixed::header;

/// The differing integer fields of one row (after the five inputs), named by `header`.
fn integer_diffs(header: &str, want: &[&str], got: &[&str]) -> Vec<String> {
    header
        .split(',')
        .zip(want.iter().zip(got))
        .skip(5)
        .filter(|(_, (w, g))| w != g)
        .map(|(name, (w, g))| format!("{name} want {w} got {g}"))
        .collect()
}

/// Compares the fixed-point section of the `golden` firmware's stdout `output` (after its
/// `needle-golden-fixed rows=N` line) with the text `csv` of golden-fixed.csv.
///
/// # Errors
/// The section is missing, truncated or malformed, or holds another number of rows;
/// differing values are [`Comparison::mismatches`].
pub fn compare(output: &str, csv: &str) -> anyhow::Result<Comparison> {
    let header = header();
    let section = Section { file: "golden-fixed.csv", tag: "needle-golden-fixed", header: &header, fields: 12, end_suffix: "" };
    section.compare(output, csv, |_, want, got| Ok(integer_diffs(&header, want, got)))
}

/// Compares the fixed-point stiffness section of the `golden` firmware's stdout `output`
/// (after its `needle-golden-stiffness-fixed rows=N` line) with the text `csv` of
/// golden-stiffness-fixed.csv.
///
/// # Errors
/// The section is missing, truncated or malformed, holds another number of rows, or the
/// firmware found a wrench that differs from `fixed::wrench`'s; differing rates are
/// [`Comparison::mismatches`].
pub fn compare_stiffness(output: &str, csv: &str) -> anyhow::Result<Comparison> {
    let header = needle_fit::golden::stiffness_fixed::header();
    let section = Section {
        file: needle_fit::GOLDEN_STIFFNESS_FIXED_FILE,
        tag: "needle-golden-stiffness-fixed",
        header: &header,
        fields: header.split(',').count(),
        end_suffix: " wrench_differs=0",
    };
    section.compare(output, csv, |_, want, got| Ok(integer_diffs(&header, want, got)))
}
