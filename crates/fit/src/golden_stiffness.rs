//! `golden-stiffness-f32.csv` (coeffs/README.md, "Stiffness"): for every pose of
//! `golden-f32.csv`, in the same order, the status and the 18 rates of this crate's own
//! evaluator ([`super::eval_rate_f32`]): by depth, by x, by z, each fx .. mz.

use super::eval_f32::Tables32;
use super::eval_rate_f32::eval_rates;
use super::golden::poses;
use super::model_file::{hex32, parse_hex32};
use anyhow::Result;
use std::fmt::Write as _;
use std::path::Path;

/// Columns after the five inputs and the status: rate of each component (fx .. mz) by
/// depth, by x, by z; N/mm for forces, N·mm/mm for moments.
pub const RATE_COLUMNS: [&str; 18] = [
    "dfx_ddepth_n_per_mm",
    "dfy_ddepth_n_per_mm",
    "dfz_ddepth_n_per_mm",
    "dmx_ddepth_nmm_per_mm",
    "dmy_ddepth_nmm_per_mm",
    "dmz_ddepth_nmm_per_mm",
    "dfx_dx_n_per_mm",
    "dfy_dx_n_per_mm",
    "dfz_dx_n_per_mm",
    "dmx_dx_nmm_per_mm",
    "dmy_dx_nmm_per_mm",
    "dmz_dx_nmm_per_mm",
    "dfx_dz_n_per_mm",
    "dfy_dz_n_per_mm",
    "dfz_dz_n_per_mm",
    "dmx_dz_nmm_per_mm",
    "dmy_dz_nmm_per_mm",
    "dmz_dz_nmm_per_mm",
];

/// The header line: the five inputs, `status`, then [`RATE_COLUMNS`].
pub fn header() -> String {
    format!("x_mm,z_mm,theta_x_deg,theta_z_deg,depth_mm,status,{}", RATE_COLUMNS.join(","))
}

/// The text of golden-stiffness-f32.csv for the f32 tables `t`.
pub fn to_csv(t: &Tables32) -> String {
    let poses = poses();
    let mut s = String::with_capacity(256 * (poses.len() + 1));
    s.push_str(&header());
    s.push('\n');
    for p in poses {
        let (rates, status) = eval_rates(t, p);
        for v in p {
            let _ = write!(s, "{},", hex32(v));
        }
        let _ = write!(s, "0x{status:02x}");
        for v in rates.iter().flatten() {
            let _ = write!(s, ",{}", hex32(*v));
        }
        s.push('\n');
    }
    s
}

/// One row: the pose, the status and the rates `[by_depth, by_x, by_z]`, as stored bits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StiffnessRow {
    /// `[x_mm, z_mm, theta_x_deg, theta_z_deg, depth_mm]`.
    pub pose: [f32; 5],
    /// Status byte.
    pub status: u8,
    /// `[by_depth, by_x, by_z]`, each `[fx, fy, fz, mx, my, mz]` (N/mm, N·mm/mm).
    pub rates: [[f32; 6]; 3],
}

/// Parse golden-stiffness-f32.csv text; `path` is only used in messages.
///
/// # Errors
/// Wrong header, a row without 24 fields, a malformed hex field or status (`path:line`).
pub fn parse_csv(text: &str, path: &Path) -> Result<Vec<StiffnessRow>> {
    super::golden::parse_rows(text, path, &header(), |field, at| {
        let value = |s: &str| parse_hex32(s).ok_or_else(|| anyhow::anyhow!("{at}: field {s:?} is not 0x + 8 hex digits"));
        let mut pose = [0.0f32; 5];
        for (dst, s) in pose.iter_mut().zip(field) {
            *dst = value(s)?;
        }
        let mut rates = [[0.0f32; 6]; 3];
        for (dst, s) in rates.iter_mut().flatten().zip(field.iter().skip(6)) {
            *dst = value(s)?;
        }
        Ok((pose, rates))
    })
    .map(|rows| rows.into_iter().map(|(pose, status, rates)| StiffnessRow { pose, status, rates }).collect())
}
