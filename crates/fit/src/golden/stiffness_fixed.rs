//! `golden-stiffness-fixed.csv` (coeffs/README.md, "Fixed-point stiffness"): for every
//! pose of `golden-fixed.csv`, in the same order, the status and the 18 integer rates of
//! this crate's own fixed-point implementation ([`crate::eval::fixed::eval_rates`]).

use crate::contract::COMPONENT_COUNT;
use crate::eval::fixed::eval_rates;
use crate::fixed_formats::TablesFixed;
use crate::golden::fixed::poses;
use crate::golden::stiffness_float32::rate_columns;
use crate::golden::GoldenCsvError;
use anyhow::{anyhow, Result};
use std::fmt::Write as _;
use std::path::Path;

/// The header line: the five Q16.16 inputs, `status`, then the 18 rates in µN/mm and
/// µN·mm/mm ([`rate_columns`] with `micro`).
pub fn header() -> String {
    format!("{},status,{}", needle_contract::FIXED_INPUTS.join(","), rate_columns(true).join(","))
}

/// The text of golden-stiffness-fixed.csv for the tables `t`.
///
/// # Errors
/// An intermediate of a pose leaves the contract's range (the tables are wrong).
pub fn to_csv(t: &TablesFixed) -> Result<String> {
    let poses = poses(&t.unsolved);
    let mut s = String::with_capacity(160 * (poses.len() + 1));
    s.push_str(&header());
    s.push('\n');
    for p in poses {
        let (_, rates, status) = eval_rates(t, p).map_err(|e| anyhow!("fixed-point stiffness at {p:?}: {e}"))?;
        for v in p {
            let _ = write!(s, "{v},");
        }
        let _ = write!(s, "0x{status:02x}");
        for v in rates.iter().flatten() {
            let _ = write!(s, ",{v}");
        }
        s.push('\n');
    }
    Ok(s)
}

/// One row: the Q16.16 pose, the status and the rates `[by_depth, by_x, by_z]`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FixedStiffnessRow {
    /// `[x, z, theta_x, theta_z, depth]`, Q16.16.
    pub pose: [i32; 5],
    /// Status byte.
    pub status: u8,
    /// `[by_depth, by_x, by_z]`, each `[fx, fy, fz, mx, my, mz]` (µN/mm, µN·mm/mm).
    pub rates: [[i32; COMPONENT_COUNT]; 3],
}

/// Parse golden-stiffness-fixed.csv text; `path` is only used in messages.
///
/// # Errors
/// Wrong header, a row without 24 fields, a malformed field (`path:line` in the message).
pub fn parse_csv(text: &str, path: &Path) -> Result<Vec<FixedStiffnessRow>, GoldenCsvError> {
    crate::golden::parse_rows(text, path, &header(), |field, at| {
        let int = |s: &str| s.parse::<i32>().map_err(|_| GoldenCsvError::int(at, s));
        let mut pose = [0; 5];
        for (d, s) in pose.iter_mut().zip(field) {
            *d = int(s)?;
        }
        let mut rates = [[0; COMPONENT_COUNT]; 3];
        for (d, s) in rates.iter_mut().flatten().zip(field.iter().skip(6)) {
            *d = int(s)?;
        }
        Ok((pose, rates))
    })
    .map(|rows| rows.into_iter().map(|(pose, status, rates)| FixedStiffnessRow { pose, status, rates }).collect())
}
