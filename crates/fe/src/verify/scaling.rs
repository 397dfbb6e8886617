//! The scaling-law check of `needle fe verify --scaling` (issue 41, item 6): with the
//! loading displacement-controlled and quasi-static, Coulomb friction and the bulk
//! modulus a fixed multiple of the shear modulus, scaling every Ogden mu_i by s scales
//! the whole wrench by s. Each pose is solved with the tissue scaled by each s (work files
//! under `<work>/scaling-s<s>/`, resumable: the campaign's manifest there) and compared
//! with s times the committed s = 1 run (`fe/<pose>.csv`, same mesh level and settings)
//! at every must point: the largest |difference| per component as % of s x peak |Fy|
//! (moments: x the hub's lever arm), goal [`SCALING_GOAL_PERCENT`].

use crate::campaign::runs::{read_current, same_depths, solve_and_read};
use crate::campaign::RunOptions;
use crate::results::{peak_fy_n, Row};
use crate::set_folder::SetFolder;
use crate::spec::Campaign;
use anyhow::Result;
use needle_contract::{error_scales, COMPONENTS, COMPONENT_COUNT, FY};
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::PathBuf;

/// Goal of the check: largest |wrench(s) - s wrench(1)| of any component at any must
/// point, % of s x peak |Fy| (issue 41).
pub const SCALING_GOAL_PERCENT: f64 = 0.5;
/// The stiffness scales solved.
pub const SCALES: [f64; 2] = [0.5, 2.0];
/// The poses of the check: the quarter model and a half model.
pub const SCALING_POSES: [&str; 2] = ["centre", "x+04"];

/// What the check runs on.
#[derive(Debug, Clone)]
pub struct ScalingOptions {
    /// The set folder.
    pub set_dir: PathBuf,
    /// Folder of the scaled runs (one sub-folder per scale).
    pub work_dir: PathBuf,
    /// Poses by exact name.
    pub poses: Vec<String>,
    /// Mesh level of the scaled runs and of the s = 1 runs read from `fe/`; `None`:
    /// `campaign.mesh`.
    pub mesh: Option<String>,
    /// Load steps of both; `None`: `loading.steps`.
    pub steps: Option<u32>,
    /// Solver threads of each run.
    pub threads: usize,
    /// Solve the scaled runs that are not up to date (false: compare what is there).
    pub solve: bool,
}

/// One pose at one scale.
#[derive(Debug, Clone, Serialize)]
pub struct ScalingRun {
    /// Pose name.
    pub pose: String,
    /// The stiffness scale s.
    pub scale: f64,
    /// Largest |wrench(s) - s wrench(1)| over the must points per component, % of
    /// s x peak |Fy| of the s = 1 run (moments: x the hub's lever arm); absent when a run
    /// is missing.
    #[serde(skip_serializing_if = "BTreeMap::is_empty")]
    pub percent_of_peak_fy: BTreeMap<String, f64>,
    /// The largest of them, %.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub worst_percent: Option<f64>,
    /// Its component.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub worst_component: Option<String>,
    /// Its depth, mm.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub worst_depth_mm: Option<f64>,
    /// Fy(s) / Fy(1) at full depth (s when the law holds).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fy_ratio_at_full_depth: Option<f64>,
    /// Why there is no comparison (a run failed or is not current).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub failure: Option<String>,
}

/// The whole check.
#[derive(Debug, Clone, Serialize)]
pub struct ScalingReport {
    /// Engine of the runs.
    pub engine: String,
    /// Mesh level.
    pub mesh: String,
    /// Goal on every `worst_percent`, %.
    pub goal_percent: f64,
    /// Every pose at every scale.
    pub runs: Vec<ScalingRun>,
}

impl ScalingReport {
    /// Every comparison made and within the goal.
    pub fn ok(&self) -> bool {
        self.runs.iter().all(|r| r.worst_percent.is_some_and(|w| w <= self.goal_percent))
    }
}

/// Solve the scaled runs (resuming) and compare them with the s = 1 runs of `fe/`.
///
/// # Errors
/// The spec, an option or a manifest (failed solves are the runs' `failure`).
pub fn scaling_check(set: &SetFolder, c: &Campaign, o: &ScalingOptions) -> Result<ScalingReport> {
    let base = RunOptions {
        only: Some(o.poses.join(",")),
        mesh: o.mesh.clone(),
        steps: o.steps,
        threads: o.threads,
        ..RunOptions::new(&o.set_dir)
    };
    let ones = read_current(set, &base)?;
    let lever_mm = c.needle.reference_from_tip_mm;
    let mut runs = Vec::new();
    for s in SCALES {
        let out_dir = o.work_dir.join(format!("scaling-s{s}"));
        needle_stdx::outln!("scaling s = {s}: {} with every Ogden mu_i x {s}, runs in {}", o.poses.join(", "), out_dir.display());
        let opts = RunOptions { tissue_scale: Some(s), out_dir: Some(out_dir), ..base.clone() };
        let scaled = if o.solve { solve_and_read(set, &opts)? } else { read_current(set, &opts)? };
        for pose in &o.poses {
            let one = ones.get(pose).cloned().unwrap_or_else(|| Err(format!("{pose}: not selected")));
            let one = one.map_err(|e| format!("the s = 1 run: {e}"));
            let this = scaled.get(pose).cloned().unwrap_or_else(|| Err(format!("{pose}: not selected")));
            let run = match (one, this) {
                (Ok(a), Ok(b)) => compare(pose, s, &a.rows, &b.rows, lever_mm),
                (Err(e), _) | (_, Err(e)) => failed(pose, s, e),
            };
            needle_stdx::outln!("{run}");
            runs.push(run);
        }
    }
    let mesh = o.mesh.clone().unwrap_or_else(|| c.campaign.mesh.clone());
    Ok(ScalingReport { engine: c.solver.engine.name().into(), mesh, goal_percent: SCALING_GOAL_PERCENT, runs })
}

fn failed(pose: &str, s: f64, why: String) -> ScalingRun {
    ScalingRun {
        pose: pose.into(),
        scale: s,
        percent_of_peak_fy: BTreeMap::new(),
        worst_percent: None,
        worst_component: None,
        worst_depth_mm: None,
        fy_ratio_at_full_depth: None,
        failure: Some(why),
    }
}

/// `scaled` against `s` x `one`, must point by must point.
pub fn compare(pose: &str, s: f64, one: &[Row], scaled: &[Row], lever_mm: f64) -> ScalingRun {
    if !same_depths(one, scaled) {
        return failed(pose, s, format!("the s = 1 run has {} rows, the s = {s} run {}, at other depths", one.len(), scaled.len()));
    }
    let scales = error_scales(s * peak_fy_n(one), lever_mm);
    let mut pct = [0.0f64; COMPONENT_COUNT];
    let (mut worst, mut at) = ((0usize, -1.0f64), 0.0);
    for (a, b) in one.iter().zip(scaled) {
        for c in 0..COMPONENT_COUNT {
            let p = 100.0 * (b.wrench[c] - s * a.wrench[c]).abs() / scales[c];
            pct[c] = pct[c].max(p);
            if p > worst.1 {
                (worst, at) = ((c, p), a.depth_mm);
            }
        }
    }
    let last = |r: &[Row]| r.last().map(|r| r.wrench[FY]).unwrap_or(f64::NAN);
    ScalingRun {
        pose: pose.into(),
        scale: s,
        percent_of_peak_fy: COMPONENTS.iter().zip(pct).map(|(n, p)| (n.to_string(), p)).collect(),
        worst_percent: Some(worst.1),
        worst_component: Some(COMPONENTS[worst.0].into()),
        worst_depth_mm: Some(at),
        fy_ratio_at_full_depth: Some(last(scaled) / last(one)),
        failure: None,
    }
}

impl std::fmt::Display for ScalingRun {
    /// The run's line in `needle fe verify`'s table.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match (&self.failure, self.worst_percent, &self.worst_component) {
            (Some(why), ..) => write!(f, "scaling {:>6} s = {}: no comparison: {why}", self.pose, self.scale),
            (None, Some(w), Some(c)) => {
                let all: Vec<String> = self.percent_of_peak_fy.iter().map(|(k, v)| format!("{k} {v:.2e}")).collect();
                write!(
                    f,
                    "scaling {:>6} s = {}: largest |W(s) - s W(1)| {w:.2e}% of s x peak |Fy| ({c} at {} mm; goal <= {SCALING_GOAL_PERCENT}%), Fy(s)/Fy(1) at full depth {:.6}; per component %: {}",
                    self.pose,
                    self.scale,
                    self.worst_depth_mm.unwrap_or(f64::NAN),
                    self.fy_ratio_at_full_depth.unwrap_or(f64::NAN),
                    all.join(", ")
                )
            }
            _ => write!(f, "scaling {:>6} s = {}: no comparison", self.pose, self.scale),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rows(f: impl Fn(f64) -> [f64; COMPONENT_COUNT]) -> Vec<Row> {
        (0..=4).map(|k| f64::from(k) * 1.5).map(|d| Row { depth_mm: d, wrench: f(d) }).collect()
    }

    #[test]
    fn an_exact_scaling_passes_and_a_defect_is_found_where_it_is() {
        let one = rows(|d| [0.01 * d, 0.002 * d * d, 0.0, 0.0, 0.3 * d, 0.0]);
        let exact = rows(|d| [0.02 * d, 0.004 * d * d, 0.0, 0.0, 0.6 * d, 0.0]);
        let r = compare("p", 2.0, &one, &exact, 60.0);
        assert!(r.worst_percent.is_some_and(|w| w < 1e-12), "{r}");
        assert_eq!(r.fy_ratio_at_full_depth, Some(2.0));
        // Fy 1 % of 2 x peak off at 3 mm: found there, in fy_n
        let mut off = exact.clone();
        off[2].wrench[1] += 0.01 * 2.0 * 0.072;
        let r = compare("p", 2.0, &one, &off, 60.0);
        assert_eq!((r.worst_component.as_deref(), r.worst_depth_mm), (Some("fy_n"), Some(3.0)), "{r}");
        assert!(r.worst_percent.is_some_and(|w| (w - 1.0).abs() < 1e-9), "{r}");
        // a moment off by 0.1 N*mm against 2 x 0.072 N x 60 mm: 1.157 %
        let mut m = exact.clone();
        m[4].wrench[4] += 0.1;
        let r = compare("p", 2.0, &one, &m, 60.0);
        assert!(r.percent_of_peak_fy.get("my_nmm").is_some_and(|p| (p - 100.0 * 0.1 / (0.144 * 60.0)).abs() < 1e-9), "{r}");
        // other depths: no comparison
        let r = compare("p", 2.0, &one, &exact[..4], 60.0);
        assert!(r.failure.is_some() && r.worst_percent.is_none(), "{r}");
    }
}
