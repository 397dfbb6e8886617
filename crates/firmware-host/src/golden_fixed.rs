//! The `golden` firmware's fixed-point section against the set's `golden-fixed.csv`:
//! inputs, status and every wrench integer exactly.
use super::comparison::{Comparison, Section};

/// The fixed-point golden file's header line.
pub const HEADER: &str = needle_fit::golden_fixed::HEADER;

/// Compares the fixed-point section of the `golden` firmware's stdout `output` (after its
/// `needle-golden-fixed rows=N` line) with the text `csv` of golden-fixed.csv.
///
/// # Errors
/// The section is missing, truncated or malformed, or holds another number of rows;
/// differing values are [`Comparison::mismatches`].
pub fn compare(output: &str, csv: &str) -> anyhow::Result<Comparison> {
    let section = Section { file: "golden-fixed.csv", tag: "needle-golden-fixed", header: HEADER, fields: 12, end_suffix: "" };
    section.compare(output, csv, |_, want, got| {
        Ok(HEADER
            .split(',')
            .zip(want.iter().zip(got))
            .skip(5)
            .filter(|(_, (w, g))| w != g)
            .map(|(name, (w, g))| format!("{name} want {w} got {g}"))
            .collect())
    })
}
