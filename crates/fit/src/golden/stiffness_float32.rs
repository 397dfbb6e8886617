//! `golden-stiffness-f32.csv` (coeffs/README.md, "Stiffness"): for every pose of
//! `golden-f32.csv`, in the same order, the status and the 18 rates of this crate's own
//! evaluator ([`crate::eval::rate_float32`]): by depth, by x, by z, each fx .. mz.

use crate::contract::COMPONENTS;
use crate::contract::COMPONENT_COUNT;
use crate::eval::float32::Tables32;
use crate::eval::rate_float32::eval_rates;
use crate::golden::float32::poses;
use crate::golden::GoldenCsvError;
use crate::model_file::{hex32, parse_hex32};
use anyhow::Result;
use std::fmt::Write as _;
use std::path::Path;

/// The inputs the rates are taken by, in column order.
const RATE_INPUTS: [&str; 3] = ["ddepth", "dx", "dz"];

/// Columns after the five inputs and the status: rate of each component (fx .. mz) by
/// depth, by x, by z (`dfx_ddepth_n_per_mm` .. `dmz_dz_nmm_per_mm`); N/mm for forces,
/// N·mm/mm for moments, or with `micro` µN/mm and µN·mm/mm (`dfx_ddepth_un_per_mm` ..).
pub fn rate_columns(micro: bool) -> Vec<String> {
    let prefix = if micro { "u" } else { "" };
    RATE_INPUTS
        .iter()
        .flat_map(|by| {
            COMPONENTS.iter().map(move |c| {
                let (name, unit) = c.split_once('_').unwrap_or((c, ""));
                format!("d{name}_{by}_{prefix}{unit}_per_mm")
            })
        })
        .collect()
}

/// The header line: the five inputs, `status`, then [`rate_columns`].
pub fn header() -> String {
    format!("x_mm,z_mm,theta_x_deg,theta_z_deg,depth_mm,status,{}", rate_columns(false).join(","))
}

/// The text of golden-stiffness-f32.csv for the f32 tables `t`.
pub fn to_csv(t: &Tables32) -> String {
    let poses = poses(&t.unsolved);
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
    pub rates: [[f32; COMPONENT_COUNT]; 3],
}

/// Parse golden-stiffness-f32.csv text; `path` is only used in messages.
///
/// # Errors
/// Wrong header, a row without 24 fields, a malformed hex field or status (`path:line`).
pub fn parse_csv(text: &str, path: &Path) -> Result<Vec<StiffnessRow>, GoldenCsvError> {
    crate::golden::parse_rows(text, path, &header(), |field, at| {
        let value = |s: &str| parse_hex32(s).ok_or_else(|| GoldenCsvError::hex32(at, s));
        let mut pose = [0.0f32; 5];
        for (dst, s) in pose.iter_mut().zip(field) {
            *dst = value(s)?;
        }
        let mut rates = [[0.0f32; COMPONENT_COUNT]; 3];
        for (dst, s) in rates.iter_mut().flatten().zip(field.iter().skip(6)) {
            *dst = value(s)?;
        }
        Ok((pose, rates))
    })
    .map(|rows| rows.into_iter().map(|(pose, status, rates)| StiffnessRow { pose, status, rates }).collect())
}
