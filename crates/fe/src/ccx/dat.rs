//! Reader of CalculiX's `.dat` file: the nodal reaction forces (`RF`) that a deck asks
//! for with `*NODE PRINT, NSET=<set>` at the end of every step.
//!
//! In the `.dat` file each request gives one block per output time:
//!
//! ```text
//!  forces (fx,fy,fz) for set NPRINT and time  0.1000000E+01
//!
//!    1000001  1.234567E-05 -2.000000E-04  0.000000E+00
//!    ...
//! ```
//!
//! Blocks are separated by blank lines; ccx prints other blocks in the same file
//! (`total force ...` with `TOTALS=YES`, displacements, contact statistics, other sets),
//! which this reader skips. Numbers are Fortran `E` format; a three-digit exponent
//! drops the `E` (`0.123457-100`), and `NaN` / `Infinity` are passed through as such so
//! that the caller can refuse them with the pose's name.

use anyhow::{bail, Result};

/// The reaction forces of one node set at one output time.
#[derive(Debug, Clone, PartialEq)]
pub struct StepRf {
    /// Total time of the output (step k of the campaign's decks ends at total time k).
    pub total_time: f64,
    /// `(node number, [RFx, RFy, RFz])` in the order ccx printed them; forces in N.
    pub nodes: Vec<(u32, [f64; 3])>,
}

/// The header text that opens a reaction force block, lower case.
const FORCES_HEADER: &str = "forces (fx,fy,fz) for set ";

/// Read every `forces (fx,fy,fz) for set <set>` block of a `.dat` file, in file order.
///
/// The set name is compared case-insensitively (ccx prints it in upper case). Blocks of
/// other sets and every other kind of block are skipped.
///
/// # Errors
/// - a header line whose time is not a number;
/// - a line inside a block of `set` that starts with a node number but is not
///   `node fx fy fz` with three numbers (for example a Fortran overflow `*********`);
/// - a block of `set` without any node line;
/// - no block of `set` at all (the message lists the sets that do have blocks).
///
/// Each message has the 1-based line number and the line's text.
pub fn parse_rf(text: &str, set: &str) -> Result<Vec<StepRf>> {
    let want = set.trim().to_ascii_lowercase();
    let mut out = Vec::new();
    let mut other_sets: Vec<String> = Vec::new();
    // The block being read: (header line number, total time, nodes).
    let mut current: Option<(usize, StepRf)> = None;

    for (i, line) in text.lines().enumerate() {
        let n = i + 1;
        let trimmed = line.trim();
        if let Some((hline, mut block)) = current.take() {
            if trimmed.is_empty() {
                if block.nodes.is_empty() {
                    // the blank line between the header and the first node line
                    current = Some((hline, block));
                } else {
                    out.push(block);
                }
                continue;
            }
            let first = trimmed.split_whitespace().next().unwrap_or("");
            if first.bytes().all(|b| b.is_ascii_digit()) {
                let node = parse_node_line(trimmed).map_err(|why| {
                    anyhow::anyhow!("line {n}: {why} in the forces block of set {set} (header at line {hline}): {line:?}")
                })?;
                block.nodes.push(node);
                current = Some((hline, block));
                continue;
            }
            // Any other text ends the block; the line may be the next header.
            if block.nodes.is_empty() {
                bail!("line {hline}: the forces block of set {set} has no node lines before line {n}: {line:?}");
            }
            out.push(block);
        }
        let lower = trimmed.to_ascii_lowercase();
        let Some(rest) = lower.strip_prefix(FORCES_HEADER) else {
            continue;
        };
        let Some((name, time_text)) = rest.split_once(" and time") else {
            bail!("line {n}: a forces header without \"and time\": {line:?}");
        };
        let name = name.trim();
        if name != want {
            if !other_sets.iter().any(|s| s == name) {
                other_sets.push(name.to_string());
            }
            continue;
        }
        let time_text = time_text.trim();
        let total_time =
            parse_fortran(time_text).ok_or_else(|| anyhow::anyhow!("line {n}: time {time_text:?} is not a number: {line:?}"))?;
        current = Some((n, StepRf { total_time, nodes: Vec::new() }));
    }
    if let Some((h, b)) = current.take() {
        if b.nodes.is_empty() {
            bail!("line {h}: the forces block of set {set} at the end of the file has no node lines");
        }
        out.push(b);
    }
    if out.is_empty() {
        if other_sets.is_empty() {
            bail!("no \"forces (fx,fy,fz) for set {set}\" block: the file has no reaction force block at all");
        }
        bail!(
            "no \"forces (fx,fy,fz) for set {set}\" block; forces are printed for set(s) {}",
            other_sets.iter().map(|s| s.to_ascii_uppercase()).collect::<Vec<_>>().join(", ")
        );
    }
    Ok(out)
}

/// `node fx fy fz` -> `(node, [fx, fy, fz])`, or why not.
fn parse_node_line(trimmed: &str) -> std::result::Result<(u32, [f64; 3]), String> {
    let fields: Vec<&str> = trimmed.split_whitespace().collect();
    let [node, fx, fy, fz] = fields.as_slice() else {
        return Err(format!("{} fields, expected 4 (node fx fy fz)", fields.len()));
    };
    let node: u32 = node.parse().map_err(|_| format!("node number {node:?} is not a u32"))?;
    let mut f = [0.0; 3];
    for (slot, (text, name)) in f.iter_mut().zip([(fx, "fx"), (fy, "fy"), (fz, "fz")]) {
        *slot = parse_fortran(text).ok_or_else(|| format!("{name} = {text:?} is not a number"))?;
    }
    Ok((node, f))
}

/// Parse a Fortran real: `1.234E-05`, `0.1000000E+01`, `-1.5D+02`, the exponent-only form
/// `0.123457-100` that `E13.6` prints for three-digit exponents, `NaN`, `Infinity`.
pub fn parse_fortran(s: &str) -> Option<f64> {
    let s = s.trim();
    if s.is_empty() {
        return None;
    }
    if let Ok(v) = s.parse::<f64>() {
        return Some(v);
    }
    let d_to_e = s.replace(['D', 'd'], "E");
    if let Ok(v) = d_to_e.parse::<f64>() {
        return Some(v);
    }
    // Mantissa followed directly by a signed exponent: insert the E before the sign.
    let bytes = s.as_bytes();
    let pos = (1..bytes.len())
        .rev()
        .find(|&k| matches!(bytes.get(k), Some(b'+' | b'-')) && bytes.get(k - 1).is_some_and(|b| b.is_ascii_digit() || *b == b'.'))?;
    let (mantissa, exponent) = s.split_at(pos);
    if !exponent[1..].bytes().all(|b| b.is_ascii_digit()) || exponent.len() < 2 {
        return None;
    }
    format!("{mantissa}E{exponent}").parse().ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fortran_numbers() {
        assert_eq!(parse_fortran("0.1000000E+01"), Some(1.0));
        assert_eq!(parse_fortran("-2.5E-01"), Some(-0.25));
        assert_eq!(parse_fortran("1.5D+02"), Some(150.0));
        assert_eq!(parse_fortran("0.123457-100"), Some(0.123457e-100));
        assert_eq!(parse_fortran("-0.5+101"), Some(-0.5e101));
        assert!(parse_fortran("NaN").is_some_and(f64::is_nan));
        assert_eq!(parse_fortran("Infinity"), Some(f64::INFINITY));
        assert_eq!(parse_fortran("*************"), None);
        assert_eq!(parse_fortran("1.0E"), None);
        assert_eq!(parse_fortran("-"), None);
        assert_eq!(parse_fortran(""), None);
    }
}
