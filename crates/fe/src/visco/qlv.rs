//! The viscoelastic check of `needle fe verify --qlv` (issue 39, item 3): each
//! ramp-and-hold run of `[viscoelastic]` (FEBio's `uncoupled viscoelastic` around the
//! set's Ogden, `crate::visco`) against the library's QLV filter applied to the ELASTIC
//! wrench of the same motion. The elastic wrench is the committed elastic FE run of the
//! same pose on the same mesh (`fe/<pose>.csv`), interpolated linearly in depth along the
//! run's depth-time path and sampled at the library's tick: the comparison then measures
//! the filter against FEBio's solution of the same constitutive law, not the surrogate's
//! fit error (which `needle validate` reports on its own).
//!
//! This module pairs the runs and scores them; the filter itself is the library's, run by
//! the caller (the CLI: this crate does not depend on the library) through
//! [`QlvCase::elastic_at_time`] and handed back to [`score`].
//! Scores per component over every must point (ramp and hold, 0 included): RMS and
//! largest |filter - FE| in % of the viscoelastic run's peak |Fy| (moments: x the hub's
//! lever arm, the contract's [`error_scales`]).

use super::{run_name, Friction, Prony};
use crate::campaign::runs::{read_current, solve_and_read, PoseRows};
use crate::campaign::RunOptions;
use crate::results::{peak_fy_n, Row};
use crate::set_folder::SetFolder;
use crate::spec::Loading;
use anyhow::{Context, Result};
use needle_contract::{error_scales, COMPONENTS, COMPONENT_COUNT, FY};
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::PathBuf;

/// Goal of the RMS error of every component, % of peak |Fy| (issue 39).
pub const QLV_GOAL_RMS_PERCENT: f64 = 3.0;
/// Bound the RMS error must stay within, % of peak |Fy| (issue 39: "must").
pub const QLV_MUST_RMS_PERCENT: f64 = 5.0;
/// Bound of the largest error, % of peak |Fy| (issue 39).
pub const QLV_MAX_PERCENT: f64 = 6.0;

/// What the check runs on.
#[derive(Debug, Clone)]
pub struct QlvOptions {
    /// The set folder.
    pub set_dir: PathBuf,
    /// Must points on the ramp of the viscoelastic runs and load steps of the elastic
    /// ones (`None`: `loading.steps`; CI's smoke runs use fewer).
    pub steps: Option<u32>,
    /// Mesh level of both (`None`: `viscoelastic.mesh`).
    pub mesh: Option<String>,
    /// Poses among `viscoelastic.poses` (empty: all of them).
    pub poses: Vec<String>,
    /// Solver threads of each run.
    pub threads: usize,
    /// Solve the runs that are not up to date (false: compare what is there).
    pub solve: bool,
}

/// One ramp-and-hold run and the elastic run of its pose.
#[derive(Debug, Clone)]
pub struct QlvCase {
    /// Pose name.
    pub pose: String,
    /// Run name (`<pose>_<speed>mm-s`).
    pub run: String,
    /// The run's loading (speed, ramp and hold must points).
    pub loading: Loading,
    /// The Prony series of the FE tissue (FEBio's normalisation, the library's too).
    pub prony: Prony,
    /// The viscoelastic FE run, one row per must point (0 included).
    pub fe: Vec<Row>,
    /// The elastic FE run of the pose, one row per depth.
    pub elastic: Vec<Row>,
    /// Coulomb friction of both runs: the campaign's `contact.friction`, or 0 for the
    /// frictionless runs of `[viscoelastic] frictionless` (their elastic run is the
    /// frictionless companion `fe/visco/<pose>_mu0.csv`).
    pub friction: f64,
    /// The viscoelastic run failed every attempt: `fe` is its partial record (the must
    /// points of its furthest attempt, `fe/visco/<run>.partial.csv`), compared as far as
    /// it goes and reported as such; a miss of the check.
    pub partial: bool,
}

impl QlvCase {
    /// The must points' times, s.
    pub fn times_s(&self) -> Vec<f64> {
        (0..self.fe.len() as u32).map(|k| self.loading.time_at(k)).collect()
    }

    /// The elastic wrench along the run's depth-time path at time `t_s`: the elastic
    /// run linearly interpolated in depth (N, N·mm).
    pub fn elastic_at_time(&self, t_s: f64) -> [f64; COMPONENT_COUNT] {
        let depth = self.loading.ramp_hold.as_ref().map_or(0.0, |r| r.depth_at_time_mm(self.loading.depth_mm, t_s));
        elastic_at_depth(&self.elastic, depth)
    }
}

/// `rows` (increasing depths) linearly interpolated at `depth_mm`, clamped to their range.
pub fn elastic_at_depth(rows: &[Row], depth_mm: f64) -> [f64; COMPONENT_COUNT] {
    let Some(first) = rows.first() else { return [0.0; COMPONENT_COUNT] };
    let i = rows.partition_point(|r| r.depth_mm < depth_mm);
    if i == 0 {
        return first.wrench;
    }
    let Some(b) = rows.get(i) else { return rows.last().map_or([0.0; COMPONENT_COUNT], |r| r.wrench) };
    let a = &rows[i - 1];
    let f = (depth_mm - a.depth_mm) / (b.depth_mm - a.depth_mm);
    std::array::from_fn(|c| a.wrench[c] + f * (b.wrench[c] - a.wrench[c]))
}

/// Each run of `[viscoelastic]` (the campaign's friction, then frictionless when asked;
/// pose by speed in the spec's order) with its elastic run, solved first when
/// `opts.solve`, or why it is missing.
///
/// # Errors
/// The spec has no `[viscoelastic]`, or as [`crate::campaign::run`].
pub fn cases(set: &SetFolder, opts: &QlvOptions) -> Result<Vec<std::result::Result<QlvCase, (String, String)>>> {
    let (c, path) = (set.campaign(), set.spec_path());
    let v = c.viscoelastic.clone().with_context(|| format!("{}: --qlv: the spec has no [viscoelastic] section", path.display()))?;
    let mesh = opts.mesh.clone().unwrap_or_else(|| v.mesh.clone());
    let base = RunOptions { steps: opts.steps, mesh: Some(mesh), threads: opts.threads, ..RunOptions::new(&opts.set_dir) };
    let read = |o: &RunOptions| -> Result<PoseRows> {
        if opts.solve {
            solve_and_read(set, o)
        } else {
            read_current(set, o)
        }
    };
    let poses: Vec<String> = if opts.poses.is_empty() { v.poses.clone() } else { opts.poses.clone() };
    if let Some(p) = poses.iter().find(|p| !v.poses.contains(p)) {
        anyhow::bail!("{}: --qlv-poses {p:?}: not in viscoelastic.poses ({})", path.display(), v.poses.join(", "));
    }
    let mut out = Vec::new();
    for friction in Friction::cases(&v) {
        let frictionless = friction == Friction::None;
        let only = poses.iter().map(|p| friction.name(p)).collect::<Vec<_>>().join(",");
        let elastic = read(&RunOptions { only: Some(only), visco_frictionless: frictionless, ..base.clone() })?;
        for &speed in &v.speeds_mm_per_s {
            let only = poses.iter().map(|p| friction.name(&run_name(p, speed))).collect::<Vec<_>>().join(",");
            let o = RunOptions { visco_speed_mm_per_s: Some(speed), visco_frictionless: frictionless, only: Some(only), ..base.clone() };
            let visco = read(&o)?;
            let plan = crate::campaign::plan(set, &o)?;
            for pose in &poses {
                let run = friction.name(&run_name(pose, speed));
                let fe = visco.get(&run).cloned().unwrap_or_else(|| Err("not selected".into()));
                let partial = fe.as_ref().err().and_then(|_| read_partial(&plan, &run));
                let el = elastic.get(&friction.name(pose)).cloned().unwrap_or_else(|| Err("not selected".into()));
                let case = |fe: Vec<Row>, elastic: Vec<Row>, partial: bool| QlvCase {
                    pose: pose.clone(),
                    run: run.clone(),
                    loading: plan.campaign.loading.clone(),
                    prony: plan.campaign.tissue.prony.clone().unwrap_or(Prony { g: Vec::new(), tau_s: Vec::new() }),
                    friction: plan.campaign.contact.friction,
                    fe,
                    elastic,
                    partial,
                };
                out.push(match (fe, el) {
                    (Ok(fe), Ok(el)) => Ok(case(fe.rows, el.rows, false)),
                    (Err(_), Ok(el)) if partial.is_some() => Ok(case(partial.unwrap_or_default(), el.rows, true)),
                    (Err(why), _) => Err((run.clone(), why)),
                    (_, Err(why)) => Err((run.clone(), format!("the elastic run {}: {why}", friction.name(pose)))),
                });
            }
        }
    }
    Ok(out)
}

/// `[qlv]` of verify.toml: the bounds, every run's comparison, the runs without one.
#[derive(Debug, Clone, Serialize)]
pub struct QlvReport {
    /// [`QLV_GOAL_RMS_PERCENT`].
    pub goal_rms_percent: f64,
    /// [`QLV_MUST_RMS_PERCENT`].
    pub must_rms_percent: f64,
    /// [`QLV_MAX_PERCENT`].
    pub max_percent: f64,
    /// How the elastic input was made and sampled.
    pub elastic_input: String,
    /// Runs without a comparison and why (a miss).
    pub missing: Vec<String>,
    /// One per run compared.
    pub runs: Vec<QlvRun>,
}

impl QlvReport {
    /// One line per friction case: runs whole and within the bounds, of those compared.
    pub fn summary(&self) -> Vec<String> {
        let mut frictions: Vec<f64> = Vec::new();
        for r in &self.runs {
            if !frictions.contains(&r.friction) {
                frictions.push(r.friction);
            }
        }
        frictions
            .iter()
            .map(|f| {
                let of: Vec<&QlvRun> = self.runs.iter().filter(|r| r.friction == *f).collect();
                let whole = of.iter().filter(|r| !r.partial).count();
                let ok = of.iter().filter(|r| r.ok()).count();
                let worst = |g: fn(&QlvRun) -> f64| of.iter().filter(|r| !r.partial).map(|r| g(r)).fold(0.0, f64::max);
                format!(
                    "qlv friction {f}: {whole} of {} runs solved whole, {ok} within the bounds; worst RMS {:.2}%, largest {:.2}% of peak |Fy| over the whole runs",
                    of.len(),
                    worst(|r| r.worst_rms_percent),
                    worst(|r| r.worst_max_percent)
                )
            })
            .collect()
    }

    /// Every run of the spec compared and within the bounds.
    pub fn ok(&self) -> bool {
        self.missing.is_empty() && !self.runs.is_empty() && self.runs.iter().all(QlvRun::ok)
    }
}

/// The report of `runs` and `missing`, with the bounds.
pub fn report(runs: Vec<QlvRun>, missing: Vec<String>) -> QlvReport {
    QlvReport {
        goal_rms_percent: QLV_GOAL_RMS_PERCENT,
        must_rms_percent: QLV_MUST_RMS_PERCENT,
        max_percent: QLV_MAX_PERCENT,
        elastic_input: "the elastic FE run of the same pose, mesh and friction (fe/<pose>.csv; frictionless: fe/visco/<pose>_mu0.csv), linearly interpolated in depth along the run's depth-time path, at every tick of the filter".into(),
        missing,
        runs,
    }
}

/// The rows of `run`'s partial record in the plan's folder when it is of the current spec
/// (a failed run: its furthest attempt's must points from 0 on).
fn read_partial(plan: &crate::campaign::Plan, run: &str) -> Option<Vec<Row>> {
    let pose = plan.selected.iter().find(|p| p.name == run)?;
    let (csv, _) = crate::partial::paths(&plan.out_dir, run);
    crate::partial::read_current_record(&plan.out_dir, run, &plan.campaign.run_hash(pose, &plan.mesh_name))?;
    let text = std::fs::read_to_string(&csv).ok()?;
    // timed since the record keeps the times; earlier ones have the depth only
    let mut rows = crate::results::parse_timed_csv(&text, &csv).map(|(_, r)| r).or_else(|_| crate::results::parse_csv(&text, &csv)).ok()?;
    // a continuation that failed at once logs its start must point with a zero reaction
    // (x+04_1mm-s and centre_10mm-s: an exact zero wrench at 6 mm after
    // 0.083 N): not a state of the tissue, left out
    while rows.len() > 1 && rows.last().is_some_and(|r| r.depth_mm > 0.0 && r.wrench.iter().all(|v| *v == 0.0)) {
        rows.pop();
    }
    Some(rows)
}

/// One run's comparison.
#[derive(Debug, Clone, Serialize)]
pub struct QlvRun {
    /// Pose name.
    pub pose: String,
    /// Run name.
    pub run: String,
    /// Feed speed, mm/s.
    pub speed_mm_per_s: f64,
    /// Coulomb friction of the runs ([`QlvCase::friction`]).
    pub friction: f64,
    /// The filter's tick, s.
    pub tick_s: f64,
    /// Must points compared (ramp and hold, 0 included).
    pub must_points: usize,
    /// The FE run failed every attempt: compared on its partial record only, to
    /// `reached_time_s` (a miss).
    pub partial: bool,
    /// Time of the last must point compared, s.
    pub reached_time_s: f64,
    /// Peak |Fy| of the viscoelastic FE run, N (the error scale).
    pub peak_fy_n: f64,
    /// Fy at the end of the ramp and of the hold: FE, filter, and the elastic run, N.
    pub fe_fy_end_of_ramp_n: f64,
    /// The filter's Fy at the end of the ramp, N.
    pub filter_fy_end_of_ramp_n: f64,
    /// The FE's Fy at the end of the hold, N.
    pub fe_fy_end_of_hold_n: f64,
    /// The filter's Fy at the end of the hold, N.
    pub filter_fy_end_of_hold_n: f64,
    /// The elastic run's Fy at full depth, N.
    pub elastic_fy_full_depth_n: f64,
    /// RMS |filter - FE| over the must points per component, % of peak |Fy|.
    pub rms_percent: BTreeMap<String, f64>,
    /// Largest |filter - FE| per component, % of peak |Fy|.
    pub max_percent: BTreeMap<String, f64>,
    /// The largest RMS and its component.
    pub worst_rms_percent: f64,
    /// Component of `worst_rms_percent`.
    pub worst_rms_component: String,
    /// The largest error of any component and where.
    pub worst_max_percent: f64,
    /// Component of `worst_max_percent`.
    pub worst_max_component: String,
    /// Time of `worst_max_percent`, s.
    pub worst_max_time_s: f64,
}

impl QlvRun {
    /// Within the bounds (RMS <= [`QLV_MUST_RMS_PERCENT`], largest <= [`QLV_MAX_PERCENT`]).
    pub fn ok(&self) -> bool {
        !self.partial && self.worst_rms_percent <= QLV_MUST_RMS_PERCENT && self.worst_max_percent <= QLV_MAX_PERCENT
    }
}

impl std::fmt::Display for QlvRun {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "qlv {:<20} {:>5} mm/s, friction {}: RMS {:.2}% ({}), largest {:.2}% ({} at {:.3} s) of peak |Fy| {:.5} N (goal RMS {}%, must {}%, largest {}%); Fy end of ramp FE {:.5} / filter {:.5} N, end of hold FE {:.5} / filter {:.5} N, elastic {:.5} N{}",
            self.run,
            self.speed_mm_per_s,
            self.friction,
            self.worst_rms_percent,
            self.worst_rms_component,
            self.worst_max_percent,
            self.worst_max_component,
            self.worst_max_time_s,
            self.peak_fy_n,
            QLV_GOAL_RMS_PERCENT,
            QLV_MUST_RMS_PERCENT,
            QLV_MAX_PERCENT,
            self.fe_fy_end_of_ramp_n,
            self.filter_fy_end_of_ramp_n,
            self.fe_fy_end_of_hold_n,
            self.filter_fy_end_of_hold_n,
            self.elastic_fy_full_depth_n,
            if self.partial {
                format!("  PARTIAL: the FE run failed every attempt, compared to {:.3} s only", self.reached_time_s)
            } else if self.ok() {
                String::new()
            } else {
                "  MISSED".to_string()
            }
        )
    }
}

/// Score `filtered` (the filter's wrench at each must point of `case`) against the FE.
///
/// # Errors
/// `filtered` has not one wrench per must point.
pub fn score(case: &QlvCase, filtered: &[[f64; COMPONENT_COUNT]], tick_s: f64, lever_arm_mm: f64) -> Result<QlvRun> {
    let times = case.times_s();
    if filtered.len() != case.fe.len() || times.len() != case.fe.len() {
        anyhow::bail!("{}: {} filtered wrenches, {} FE must points, {} times", case.run, filtered.len(), case.fe.len(), times.len());
    }
    let peak = peak_fy_n(&case.fe);
    let scales = error_scales(peak, lever_arm_mm);
    let mut rms = BTreeMap::new();
    let mut max = BTreeMap::new();
    let (mut worst_rms, mut worst_rms_c) = (0.0, String::new());
    let (mut worst_max, mut worst_max_c, mut worst_t) = (0.0, String::new(), 0.0);
    for (c, name) in COMPONENTS.iter().enumerate() {
        let errs: Vec<f64> = case.fe.iter().zip(filtered).map(|(r, w)| 100.0 * (w[c] - r.wrench[c]) / scales[c]).collect();
        let r = (errs.iter().map(|e| e * e).sum::<f64>() / errs.len().max(1) as f64).sqrt();
        let (k, m) = errs.iter().map(|e| e.abs()).enumerate().fold((0, 0.0), |a, (k, e)| if e > a.1 { (k, e) } else { a });
        if r > worst_rms || worst_rms_c.is_empty() {
            (worst_rms, worst_rms_c) = (r, name.to_string());
        }
        if m > worst_max || worst_max_c.is_empty() {
            (worst_max, worst_max_c, worst_t) = (m, name.to_string(), times[k]);
        }
        rms.insert(name.to_string(), r);
        max.insert(name.to_string(), m);
    }
    let ramp_end = case.loading.ramp_hold.as_ref().map_or(0, |r| r.ramp_steps as usize);
    let fy = |rows: &[[f64; COMPONENT_COUNT]], k: usize| rows.get(k).map_or(f64::NAN, |w| w[FY]);
    let fe: Vec<[f64; COMPONENT_COUNT]> = case.fe.iter().map(|r| r.wrench).collect();
    let last = fe.len().saturating_sub(1);
    Ok(QlvRun {
        pose: case.pose.clone(),
        run: case.run.clone(),
        speed_mm_per_s: case.loading.ramp_hold.as_ref().map_or(0.0, |r| r.speed_mm_per_s),
        friction: case.friction,
        tick_s,
        must_points: fe.len(),
        partial: case.partial,
        reached_time_s: times.last().copied().unwrap_or(0.0),
        peak_fy_n: peak,
        fe_fy_end_of_ramp_n: fy(&fe, ramp_end),
        filter_fy_end_of_ramp_n: fy(filtered, ramp_end),
        fe_fy_end_of_hold_n: fy(&fe, last),
        filter_fy_end_of_hold_n: fy(filtered, last),
        elastic_fy_full_depth_n: case.elastic.last().map_or(f64::NAN, Row::fy_n),
        rms_percent: rms,
        max_percent: max,
        worst_rms_percent: worst_rms,
        worst_rms_component: worst_rms_c,
        worst_max_percent: worst_max,
        worst_max_component: worst_max_c,
        worst_max_time_s: worst_t,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn elastic_wrench_is_interpolated_in_depth_and_clamped() {
        let row = |d: f64, fy: f64| Row { depth_mm: d, wrench: [0.0, fy, 0.0, 0.0, 0.0, 0.0] };
        let rows = [row(0.0, 0.0), row(1.0, 2.0), row(2.0, 6.0)];
        assert_eq!(elastic_at_depth(&rows, 0.5)[FY], 1.0);
        assert_eq!(elastic_at_depth(&rows, 1.5)[FY], 4.0);
        assert_eq!(elastic_at_depth(&rows, 3.0)[FY], 6.0);
        assert_eq!(elastic_at_depth(&rows, -1.0)[FY], 0.0);
    }
}
