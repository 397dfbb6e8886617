//! The golden vectors (coeffs/README.md, "Golden vectors"): the poses and the expected
//! bits of each of the library's evaluators, from this crate's own implementations
//! ([`crate::eval`]). One module per file: [`float32`] (`golden-f32.csv`), [`fixed`]
//! (`golden-fixed.csv`), [`stiffness_float32`] (`golden-stiffness-f32.csv`),
//! [`stiffness_fixed`] (`golden-stiffness-fixed.csv`); here, what they share: the grid
//! every pose list starts with and the rows' layout.

pub mod error;
pub mod fixed;
pub mod float32;
pub mod stiffness_fixed;
pub mod stiffness_float32;

pub use error::GoldenCsvError;
use std::path::Path;

/// Every pose with one of the five `levels[i]` for each input `i` (x, z, theta_x,
/// theta_z, depth), input 0 varying slowest: 5^5 poses in file order. Both golden files
/// start with this grid.
pub fn grid<T: Copy>(levels: &[[T; 5]]) -> Vec<[T; 5]> {
    let mut out = Vec::with_capacity(3125);
    for &x in &levels[0] {
        for &z in &levels[1] {
            for &tx in &levels[2] {
                for &tz in &levels[3] {
                    for &d in &levels[4] {
                        out.push([x, z, tx, tz, d]);
                    }
                }
            }
        }
    }
    out
}

/// The layout every golden file shares: `header`, then rows of `fields` fields (as many
/// as the header has) `5 pose values, status (0x + 2 hex digits), the outputs`. `values`
/// reads the pose and the outputs of one row from its fields; its second argument is
/// the row's `path:line` for messages.
///
/// # Errors
/// Wrong header, a row with another number of fields, a malformed status, or `values`'
/// error.
#[allow(clippy::type_complexity)]
pub(crate) fn parse_rows<P, W>(
    text: &str,
    path: &Path,
    header: &str,
    values: impl Fn(&[&str], &str) -> Result<(P, W), GoldenCsvError>,
) -> Result<Vec<(P, u8, W)>, GoldenCsvError> {
    let fields = header.split(',').count();
    let p = path.display();
    let mut lines = text.lines();
    if lines.next() != Some(header) {
        return Err(GoldenCsvError::Header { path: p.to_string(), expected: header.to_string() });
    }
    let mut rows = Vec::new();
    for (n, line) in lines.enumerate() {
        let at = format!("{p}:{}", n + 2);
        let f: Vec<&str> = line.split(',').collect();
        if f.len() != fields {
            return Err(GoldenCsvError::FieldCount { at, found: f.len(), expected: fields });
        }
        let status = f[5]
            .strip_prefix("0x")
            .filter(|h| h.len() == 2)
            .and_then(|h| u8::from_str_radix(h, 16).ok())
            .ok_or_else(|| GoldenCsvError::Status { at: at.clone(), value: f[5].to_string() })?;
        let (pose, wrench) = values(&f, &at)?;
        rows.push((pose, status, wrench));
    }
    Ok(rows)
}
