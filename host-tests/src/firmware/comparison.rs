//! The outcome of comparing a firmware run with a golden file (f32 and fixed point).

/// Result of comparing one firmware run with the golden file.
#[derive(Debug)]
pub struct Comparison {
    /// The firmware's first line (target, set, fe_sha256, rows).
    pub banner: String,
    /// Rows compared.
    pub rows: usize,
    /// Rows that differ, one description each (`line N: ...`, line of the golden file).
    pub mismatches: Vec<String>,
}

/// `true` when the golden bits `want` and the printed `got` are the same value under the
/// contract: NaN matches NaN of any payload, anything else compares by bits.
#[must_use]
pub fn same_f32(want: u32, got: u32) -> bool {
    if f32::from_bits(want).is_nan() {
        f32::from_bits(got).is_nan()
    } else {
        want == got
    }
}
