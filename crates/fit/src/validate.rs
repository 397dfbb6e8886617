//! `needle validate`: the fitted model against every FE run it was not fitted on
//! (roles table2 and lhs; the mirror runs are reported on their own), at every depth.
//!
//! Per run and component: RMS and max error in N or N·mm, and the same in % of the run's
//! peak |Fy| (over its depths). A moment error (N·mm) is given in % of peak |Fy| times the
//! lever arm `needle.reference_from_tip_mm` (the hub, 60 mm for the default set), so that
//! forces and moments are compared on the same scale.
//!
//! Goals, checked on both the f64 and the f32 model (the worse counts), by form
//! ([`Goals::of`]):
//! - paper form (issue 3): table2: at every depth >= 1 mm, |Fy_model - Fy_FE| <= 5 % of
//!   |Fy_FE| at that depth; table2 and lhs: for every run and component, RMS error <= 2 %
//!   of the run's peak |Fy| (on table2 since issue 18: a run with a wrong Fz or moment
//!   fails, not only one with a wrong Fy);
//! - coupled form (issue 16): table2: Fy within 2.5 % at every depth >= 1 mm; table2 and
//!   lhs: every component's RMS error <= 2 % of peak |Fy| (the 1 % goal is reported, the
//!   2 % limit decides) and its largest error <= 3 %.
//!
//! For the coupled form the paper form of the same set (fitted here on its centre and
//! sweep runs, as `form = "paper"` fits it) is compared on the same runs and printed
//! beside it (no goal).
//!
//! Validation poses are never tuned, dropped or refitted on: a missing or stale run is
//! a missed goal.
//!
//! Beside each run's errors: its floor ([`crate::depth_floor`]), the smallest Table 2 Fy
//! error and RMS errors any model of the contract's form could have on it (no goal: it
//! says whether a missed goal is the model's or the FE curve's); [`validate`] takes the
//! floor's depth degree, to ask what a contract of another degree could reach.

use super::contract::{unit, COMPONENTS};
use super::data::{fitted_fe_sha256, fitted_poses, load_paper_data, load_validation_runs, run_path, Run};
use super::depth_floor::{depth_floor, DepthFloor};
use super::error_trend::{trend, ErrorTrend};
use super::model::{rms_max, Model};
use super::model_file;
use crate::contract::COMPONENT_COUNT;
use crate::eval::float32::{eval as eval32, Tables32};
use crate::eval::float64::{eval as eval64, eval_paper};
use anyhow::Result;
use needle_set::set_folder::SetFolder;
use needle_set::spec::Role;
use serde::Serialize;
use std::fmt::Write as _;
use std::path::Path;

/// Table 2 goal: largest |Fy error| over |FE Fy| at depths >= [`TABLE2_MIN_DEPTH_MM`], %.
pub const TABLE2_GOAL_PCT: f64 = 5.0;
/// Smallest depth at which the Table 2 goal applies, mm.
pub const TABLE2_MIN_DEPTH_MM: f64 = 1.0;
/// LHS goal: largest RMS error of any component in % of peak |Fy| (moments: of peak |Fy|
/// times the lever arm).
pub const LHS_GOAL_PCT: f64 = 2.0;

/// The goals of one model form (module docs).
#[derive(Debug, Clone, Copy, Serialize, PartialEq)]
pub struct Goals {
    /// `paper` or `coupled`.
    pub form: &'static str,
    /// Table 2: largest |Fy error| / |FE Fy| at depths >= 1 mm, %.
    pub table2_fy_pct: f64,
    /// Largest RMS error of any component, % of peak |Fy| (lhs and table2).
    pub rms_pct: f64,
    /// The stricter RMS goal reported beside the limit (coupled form: 1 %).
    pub rms_stretch_pct: Option<f64>,
    /// Largest error of any component at any depth, % of peak |Fy|.
    pub max_pct: Option<f64>,
}

impl Goals {
    /// The goals of the form of `model`.
    pub fn of(model: &Model) -> Goals {
        if model.cross.is_some() {
            Goals { form: "coupled", table2_fy_pct: 2.5, rms_pct: 2.0, rms_stretch_pct: Some(1.0), max_pct: Some(3.0) }
        } else {
            Goals { form: "paper", table2_fy_pct: TABLE2_GOAL_PCT, rms_pct: LHS_GOAL_PCT, rms_stretch_pct: None, max_pct: None }
        }
    }

    fn met(&self, role: Role, fy_rel_pct: f64, worst_rms_pct: f64, worst_max_pct: f64) -> Option<bool> {
        let rms_ok = worst_rms_pct <= self.rms_pct && self.max_pct.is_none_or(|m| worst_max_pct <= m);
        match role {
            Role::Table2 => Some(fy_rel_pct <= self.table2_fy_pct && rms_ok),
            Role::Lhs => Some(rms_ok),
            _ => None,
        }
    }
}

/// The paper part's errors on one run, beside the coupled form's (f64).
#[derive(Debug, Clone, Copy, Serialize, Default)]
pub struct PaperPart {
    /// Largest |Fy error| / |FE Fy| at depths >= 1 mm, %.
    pub fy_rel_max_pct: f64,
    /// Largest RMS error of any component, % of scale.
    pub worst_rms_pct: f64,
    /// Largest error of any component at any depth, % of scale.
    pub worst_max_pct: f64,
}

/// Errors of one component over one run's depths.
#[derive(Debug, Clone, Copy, Serialize, Default)]
pub struct CompError {
    /// RMS of model - FE, N or N·mm.
    pub rms: f64,
    /// Largest |model - FE|, N or N·mm.
    pub max: f64,
    /// `rms` in % of the run's peak |Fy| (moments: of peak |Fy| x lever arm).
    pub rms_pct: f64,
    /// `max` in % of the same scale.
    pub max_pct: f64,
}

/// The comparison of one FE run with the model.
#[derive(Debug, Clone, Serialize)]
pub struct RunReport {
    /// Pose name (`fe/<name>.csv`).
    pub name: String,
    /// `table2`, `lhs` or `mirror`.
    pub role: String,
    /// `[x_mm, z_mm, theta_x_deg, theta_z_deg]`.
    pub pose: [f64; 4],
    /// Largest |Fy| of the FE run over its depths, N.
    pub peak_fy_n: f64,
    /// Errors of the f64 model, component order.
    pub f64_errors: [CompError; COMPONENT_COUNT],
    /// Errors of the f32 model, component order.
    pub f32_errors: [CompError; COMPONENT_COUNT],
    /// Largest |Fy_model - Fy_FE| / |Fy_FE| at depths >= 1 mm, %, worse of f64 and f32.
    pub fy_rel_max_pct: f64,
    /// Largest RMS error of any component in % of scale, worse of f64 and f32.
    pub worst_rms_pct: f64,
    /// Largest error of any component at any depth in % of scale, worse of f64 and f32.
    pub worst_max_pct: f64,
    /// The paper part of a coupled model on the same run; `None` for the paper form.
    pub paper_part: Option<PaperPart>,
    /// The errors no model of the contract's form can beat on this run
    /// ([`crate::depth_floor`]); `None` when they cannot be computed (fewer than five
    /// depths >= 1 mm, Fy = 0 at one of them).
    pub floor: Option<DepthFloor>,
    /// Whether this run meets its role's goal (None for mirror runs: no goal).
    pub goal_met: Option<bool>,
}

/// The whole validation.
#[derive(Debug, Clone, Serialize)]
pub struct Report {
    /// The set folder.
    pub set_dir: String,
    /// Lever arm used to scale moment errors, mm.
    pub lever_arm_mm: f64,
    /// Whether model.toml's fe_sha256 matches the fitted FE files now in the set.
    pub model_matches_fe: bool,
    /// The goals of the model's form.
    pub goals: Goals,
    /// Validation runs (table2, lhs, mirror) in spec order.
    pub runs: Vec<RunReport>,
    /// Validation poses without a usable result, as `name (role, why)`: no result file, or
    /// a stale one (solved from another spec, see `data::stale_reason`).
    pub missing: Vec<String>,
    /// The held-out poses (table2, lhs) without a result, each with whether the FE could
    /// not solve it (a partial record: every attempt failed) and whether the model's
    /// unsolved region (`unsolved.toml`) holds its pose; every one counts as missed.
    pub unsolved: Vec<UnsolvedRun>,
    /// Largest |f32 - f64| model difference at the validation points, in % of the run's
    /// peak |Fy| scale.
    pub f32_vs_f64_max_pct: f64,
    /// Table 2 goal met (every table2 run present and within 5 %).
    pub table2_goal_met: bool,
    /// LHS goal met (every lhs run present and within 2 %).
    pub lhs_goal_met: bool,
    /// Both goals met.
    pub passed: bool,
    /// Whether the errors of the table2 and lhs runs follow the tilt or the offset
    /// (diagnostic, no goal); `None` below 3 runs.
    pub error_trend: Option<ErrorTrend>,
    /// The depth degree of the runs' floors (the contract's, 4, unless asked otherwise).
    pub floor_degree: usize,
}

/// A held-out run without a result.
#[derive(Debug, Clone, Serialize)]
pub struct UnsolvedRun {
    /// Pose name.
    pub name: String,
    /// `table2` or `lhs`.
    pub role: String,
    /// `[x_mm, z_mm, theta_x_deg, theta_z_deg]`.
    pub pose: [f64; 4],
    /// Every attempt failed: the campaign kept a partial record (`fe/<pose>.partial.toml`).
    pub failed_every_attempt: bool,
    /// Why there is no result: the depth reached and the failures by class, or `no
    /// result file`, or why the result is stale.
    pub why: String,
    /// The shallowest depth (0, 0.3, ..., 6 mm) at which the model flags the pose
    /// `FE_UNSOLVED` (its unsolved region holds it), `None` when it never does.
    pub flagged_from_mm: Option<f64>,
}

fn role_name(r: Role) -> &'static str {
    match r {
        Role::Table2 => "table2",
        Role::Lhs => "lhs",
        Role::Mirror => "mirror",
        _ => "other",
    }
}

/// Per component, the RMS and largest `model_w - run` over the run's rows (`model_w` row by
/// row), in N or N·mm and in % of `scale` ([`needle_contract::error_scales`]).
pub(crate) fn errors(model_w: &[[f64; COMPONENT_COUNT]], run: &Run, scale: [f64; COMPONENT_COUNT]) -> [CompError; COMPONENT_COUNT] {
    let mut out = [CompError::default(); COMPONENT_COUNT];
    for (c, e) in out.iter_mut().enumerate() {
        let (rms, max) = rms_max(model_w.iter().zip(&run.rows).map(|(w, r)| w[c] - r.wrench[c]));
        *e = CompError { rms, max, rms_pct: 100.0 * rms / scale[c], max_pct: 100.0 * max / scale[c] };
    }
    out
}

/// Largest |Fy_model - Fy_FE| / |Fy_FE| at depths >= 1 mm over `models`' rows, %.
fn fy_rel_max(models: &[&[[f64; COMPONENT_COUNT]]], run: &Run) -> f64 {
    let mut fy_rel = 0.0f64;
    for w in models {
        for (m, r) in w.iter().zip(&run.rows) {
            if r.depth_mm >= TABLE2_MIN_DEPTH_MM - 1e-9 {
                let fe = r.fy_n();
                let rel = if fe == 0.0 { f64::INFINITY } else { 100.0 * (m[1] - fe).abs() / fe.abs() };
                fy_rel = fy_rel.max(rel);
            }
        }
    }
    fy_rel
}

/// Compare one run with the model (f64 and f32; for the coupled form also its paper part).
/// `paper`: the paper form fitted on the same set, printed beside a coupled model (`None`
/// for a paper-form model); `floor_degree`: the depth degree of the run's floor.
pub fn compare_run(
    model: &Model,
    paper: Option<&Model>,
    tables: &Tables32,
    run: &Run,
    lever_arm_mm: f64,
    floor_degree: usize,
) -> (RunReport, f64) {
    let p = &run.pose;
    let pose4 = [p.x_mm, p.z_mm, p.theta_x_deg, p.theta_z_deg];
    let w64: Vec<[f64; COMPONENT_COUNT]> = run.rows.iter().map(|r| eval64(model, run.pose_at(r.depth_mm)).0).collect();
    let w32: Vec<[f64; COMPONENT_COUNT]> =
        run.rows.iter().map(|r| eval32(tables, run.pose_at(r.depth_mm).map(|v| v as f32)).0.map(f64::from)).collect();
    let peak = needle_set::results::peak_fy_n(&run.rows);
    let scale = needle_contract::error_scales(peak, lever_arm_mm);
    let e64 = errors(&w64, run, scale);
    let e32 = errors(&w32, run, scale);
    let fy_rel = fy_rel_max(&[&w64, &w32], run);
    let paper_part = paper.map(|paper| {
        let wp: Vec<[f64; COMPONENT_COUNT]> = run.rows.iter().map(|r| eval_paper(paper, run.pose_at(r.depth_mm)).0).collect();
        let ep = errors(&wp, run, scale);
        PaperPart {
            fy_rel_max_pct: fy_rel_max(&[&wp], run),
            worst_rms_pct: ep.iter().map(|e| e.rms_pct).fold(0.0, f64::max),
            worst_max_pct: ep.iter().map(|e| e.max_pct).fold(0.0, f64::max),
        }
    });
    let mut diff = 0.0f64;
    for (a, b) in w64.iter().zip(&w32) {
        for c in 0..COMPONENT_COUNT {
            diff = diff.max(100.0 * (a[c] - b[c]).abs() / scale[c]);
        }
    }
    let worst_rms_pct = e64.iter().chain(&e32).map(|e| e.rms_pct).fold(0.0, f64::max);
    let worst_max_pct = e64.iter().chain(&e32).map(|e| e.max_pct).fold(0.0, f64::max);
    let goal_met = Goals::of(model).met(p.role, fy_rel, worst_rms_pct, worst_max_pct);
    (
        RunReport {
            name: p.name.clone(),
            role: role_name(p.role).to_string(),
            pose: pose4,
            peak_fy_n: peak,
            f64_errors: e64,
            f32_errors: e32,
            fy_rel_max_pct: fy_rel,
            worst_rms_pct,
            worst_max_pct,
            paper_part,
            floor: depth_floor(&run.rows, scale, TABLE2_MIN_DEPTH_MM, floor_degree).ok(),
            goal_met,
        },
        diff,
    )
}

/// Validate the model of the opened set `set` (its `model.toml`) against the set's
/// validation runs, each run's floor computed for models of depth degree `floor_degree`
/// (the contract's is [`DEGREE`](crate::contract::DEGREE); the goals and errors do not depend on it).
///
/// # Errors
/// The model.toml cannot be read or is malformed; a present run is malformed.
pub fn validate(set: &SetFolder, floor_degree: usize) -> Result<Report> {
    let set_dir = set.dir();
    let model = model_file::read(&set.file(super::MODEL_FILE))?;
    let tables = Tables32::from_model(&model);
    let (campaign, runs, missing) = load_validation_runs(set)?;
    let lever = campaign.needle.reference_from_tip_mm;

    let fitted = fitted_poses(&campaign);
    let all_present = fitted.iter().all(|p| run_path(set_dir, p).is_file());
    let model_matches_fe = all_present && fitted_fe_sha256(set_dir, &fitted)? == model.fe_sha256;

    // A coupled model is shown beside the paper form of the same set, fitted here on its
    // centre and sweep runs exactly as `form = "paper"` fits it; when those runs are
    // missing or stale there is nothing to compare with, and the coupled model is still
    // validated (its goals then fail on the missing runs, not here).
    let paper = match model.cross {
        Some(_) => load_paper_data(set).and_then(|d| super::model::fit(&d)).ok(),
        None => None,
    };
    let mut reports = Vec::new();
    let mut diff = 0.0f64;
    for run in &runs {
        let (r, d) = compare_run(&model, paper.as_ref(), &tables, run, lever, floor_degree);
        diff = diff.max(d);
        reports.push(r);
    }
    let goal = |role: Role| {
        !missing.iter().any(|u| u.pose.role == role)
            && reports.iter().filter(|r| r.role == role_name(role)).all(|r| r.goal_met == Some(true))
    };
    let table2_goal_met = goal(Role::Table2);
    let lhs_goal_met = goal(Role::Lhs);
    // the tables of the comparison, now with the set's unsolved region (built once)
    let flag_tables = tables.with_unsolved(read_region(set_dir)?);
    let unsolved = missing
        .iter()
        .filter(|u| u.pose.role.is_validation())
        .map(|u| {
            let p = &u.pose;
            let at = [p.x_mm, p.z_mm, p.theta_x_deg, p.theta_z_deg];
            let flagged_from_mm = (0..=20).map(|k| 0.3 * f64::from(k)).find(|&d| {
                let pose = [at[0] as f32, at[1] as f32, at[2] as f32, at[3] as f32, d as f32];
                eval32(&flag_tables, pose).1 & crate::contract::STATUS_FE_UNSOLVED != 0
            });
            UnsolvedRun {
                name: p.name.clone(),
                role: role_name(p.role).to_string(),
                pose: at,
                failed_every_attempt: u.why.starts_with(super::data::FAILED_PREFIX),
                why: u.why.clone(),
                flagged_from_mm,
            }
        })
        .collect();
    let judged: Vec<&RunReport> = reports.iter().filter(|r| r.goal_met.is_some()).collect();
    let error_trend =
        trend(&judged.iter().map(|r| r.pose).collect::<Vec<_>>(), &judged.iter().map(|r| r.worst_rms_pct).collect::<Vec<_>>());
    Ok(Report {
        set_dir: set_dir.display().to_string(),
        lever_arm_mm: lever,
        model_matches_fe,
        goals: Goals::of(&model),
        runs: reports,
        missing: missing.iter().map(|u| format!("{} ({}, {})", u.pose.name, role_name(u.pose.role), u.why)).collect(),
        unsolved,
        f32_vs_f64_max_pct: diff,
        table2_goal_met,
        lhs_goal_met,
        passed: table2_goal_met && lhs_goal_met,
        error_trend,
        floor_degree,
    })
}

/// The balls of the set's unsolved region (`unsolved.toml`; none without the file).
///
/// # Errors
/// The file is refused by the generator (with its line).
fn read_region(set_dir: &Path) -> Result<Vec<crate::unsolved::Entry>> {
    let path = set_dir.join(crate::unsolved::FILE);
    if !path.is_file() {
        return Ok(Vec::new());
    }
    let r = needle_codegen::unsolved::parse(&path)?;
    Ok(r.balls
        .iter()
        .map(|b| crate::unsolved::Entry { centre_q15: b.centre_q15, radius_q15: b.radius_q15, depth_q16: b.depth_q16 })
        .collect())
}

fn pass(b: bool) -> &'static str {
    if b {
        "PASS"
    } else {
        "FAIL"
    }
}

/// The report as a plain-text table.
pub fn to_table(r: &Report) -> String {
    let mut s = String::new();
    write_header(&mut s, r);
    write_component_errors(&mut s, r);
    write_run_summaries(&mut s, r);
    write_goals(&mut s, r);
    write_paper_form(&mut s, r);
    write_floor_and_trends(&mut s, r);
    let _ = writeln!(s, "result: {}", pass(r.passed));
    s
}

/// The table's title, units and the stale-model warning.
fn write_header(s: &mut String, r: &Report) {
    let _ = writeln!(s, "validation of {}/model.toml against the FE runs it was not fitted on", r.set_dir);
    let _ = writeln!(
        s,
        "errors: model (f64) - FE over all depths; % of the run's peak |Fy| (moments: of peak |Fy| x {} mm lever arm)",
        r.lever_arm_mm
    );
    if !r.model_matches_fe {
        let _ = writeln!(s, "WARNING: model.toml's fe_sha256 does not match the fitted FE files in the set (refit with `needle fit`)");
    }
}

/// Every run's RMS and largest error per component.
fn write_component_errors(s: &mut String, r: &Report) {
    let _ = writeln!(s);
    let _ = writeln!(s, "{:<8} {:<7} {:<7} {:>11} {:>11} {:<5} {:>8} {:>8}", "run", "role", "comp", "rms", "max", "unit", "rms %", "max %");
    for run in &r.runs {
        for (c, e) in run.f64_errors.iter().enumerate() {
            let _ = writeln!(
                s,
                "{:<8} {:<7} {:<7} {:>11.3e} {:>11.3e} {:<5} {:>8.3} {:>8.3}",
                run.name,
                run.role,
                COMPONENTS[c],
                e.rms,
                e.max,
                unit(c),
                e.rms_pct,
                e.max_pct
            );
        }
    }
}

/// One line per run: pose, peak |Fy|, worst errors, paper form, depth floor, goal.
fn write_run_summaries(s: &mut String, r: &Report) {
    let _ = writeln!(s);
    let coupled = r.goals.form == "coupled";
    let _ = writeln!(
        s,
        "{:<8} {:<7} {:>7} {:>7} {:>7} {:>7} {:>10} {:>14} {:>12} {:>12}{}  {:>12} {:>12}  goal",
        "run",
        "role",
        "x mm",
        "z mm",
        "tx deg",
        "tz deg",
        "peak|Fy| N",
        "Fy rel d>=1 %",
        "worst rms %",
        "worst max %",
        if coupled { format!("  {:>14} {:>12} {:>12}", "paper: Fy rel %", "rms %", "max %") } else { String::new() },
        "floor: Fy %",
        "rms %"
    );
    for run in &r.runs {
        let goal = match run.goal_met {
            Some(b) => pass(b),
            None => "-",
        };
        let paper = match run.paper_part {
            Some(pp) => format!("  {:>14.3} {:>12.3} {:>12.3}", pp.fy_rel_max_pct, pp.worst_rms_pct, pp.worst_max_pct),
            None => String::new(),
        };
        let floor = match run.floor {
            Some(f) => format!("  {:>12.3} {:>12.3}", f.fy_rel_pct, f.worst_rms_pct()),
            None => format!("  {:>12} {:>12}", "-", "-"),
        };
        let _ = writeln!(
            s,
            "{:<8} {:<7} {:>7.2} {:>7.2} {:>7.2} {:>7.2} {:>10.4e} {:>14.3} {:>12.3} {:>12.3}{paper}{floor}  {goal}",
            run.name,
            run.role,
            run.pose[0],
            run.pose[1],
            run.pose[2],
            run.pose[3],
            run.peak_fy_n,
            run.fy_rel_max_pct,
            run.worst_rms_pct,
            run.worst_max_pct
        );
    }
}

/// Missing runs and the goals of the set's form.
fn write_goals(s: &mut String, r: &Report) {
    let _ = writeln!(s);
    if !r.missing.is_empty() {
        let _ = writeln!(s, "missing or stale FE runs (goal cannot be met): {}", r.missing.join(", "));
    }
    write_unsolved(s, r);
    let g = &r.goals;
    let _ = writeln!(s, "goals of the {} form:", g.form);
    let _ = writeln!(
        s,
        "goal table2: Fy within {} % of FE at every depth >= {TABLE2_MIN_DEPTH_MM} mm, and the rms and max goals below: {} ({})",
        g.table2_fy_pct,
        pass(r.table2_goal_met),
        worst(r, "table2", |x| x.fy_rel_max_pct)
    );
    let _ = writeln!(
        s,
        "goal lhs: every component's RMS error <= {} % of peak |Fy|{}: {} ({}{})",
        g.rms_pct,
        g.max_pct.map(|m| format!(", largest error <= {m} %")).unwrap_or_default(),
        pass(r.lhs_goal_met),
        worst(r, "lhs", |x| x.worst_rms_pct),
        if g.max_pct.is_some() { format!("; max {}", worst(r, "lhs", |x| x.worst_max_pct)) } else { String::new() }
    );
    if let Some(stretch) = g.rms_stretch_pct {
        let all: Vec<f64> = r.runs.iter().filter(|x| x.goal_met.is_some()).map(|x| x.worst_rms_pct).collect();
        let w = all.iter().copied().fold(0.0, f64::max);
        let _ = writeln!(
            s,
            "goal (reported, not the exit code): every component's RMS <= {stretch} % on table2 and lhs: {} (worst {w:.3} % over {} runs)",
            pass(w <= stretch),
            all.len()
        );
    }
}

/// The held-out runs without a result, beside the goals: those the FE could not solve
/// (every attempt failed) and those not solved (yet), each with where the model's
/// unsolved region flags its pose; all count as missed.
fn write_unsolved(s: &mut String, r: &Report) {
    let line = |u: &UnsolvedRun| {
        let flag = match u.flagged_from_mm {
            Some(d) => format!("FE_UNSOLVED from {d:.1} mm"),
            None => "not in the unsolved region".to_string(),
        };
        format!("{} ({}; {flag})", u.name, u.role)
    };
    let failed: Vec<String> = r.unsolved.iter().filter(|u| u.failed_every_attempt).map(line).collect();
    let open: Vec<String> = r.unsolved.iter().filter(|u| !u.failed_every_attempt).map(line).collect();
    if !failed.is_empty() {
        let _ = writeln!(s, "held-out runs the FE cannot solve (every attempt failed; counted as missed): {}", failed.join(", "));
    }
    if !open.is_empty() {
        let _ = writeln!(
            s,
            "held-out runs without a result and no record of a failure (not solved yet; counted as missed): {}",
            open.join(", ")
        );
    }
}

/// The paper form of the same set, when the set is coupled.
fn write_paper_form(s: &mut String, r: &Report) {
    let coupled = r.goals.form == "coupled";
    if coupled && !r.runs.iter().any(|x| x.paper_part.is_some()) {
        let _ = writeln!(s, "paper form of the same set: not fitted (its centre or sweep runs are missing or stale)");
    } else if coupled {
        let pw = |role: &str, f: fn(&PaperPart) -> f64| -> f64 {
            r.runs.iter().filter(|x| x.role == role).filter_map(|x| x.paper_part.as_ref().map(f)).fold(0.0, f64::max)
        };
        let _ = writeln!(
            s,
            "paper form of the same set (fitted on its sweeps), same runs: table2 Fy worst {:.3} %, rms worst {:.3} %; lhs rms worst {:.3} %, max worst {:.3} %",
            pw("table2", |p| p.fy_rel_max_pct),
            pw("table2", |p| p.worst_rms_pct),
            pw("lhs", |p| p.worst_rms_pct),
            pw("lhs", |p| p.worst_max_pct)
        );
    }
}

/// The depth floor, the mirror runs, the error trend and the f32 check.
fn write_floor_and_trends(s: &mut String, r: &Report) {
    let g = &r.goals;
    let floor = |role: &str, f: fn(&DepthFloor) -> f64| -> f64 {
        r.runs.iter().filter(|x| x.role == role).filter_map(|x| x.floor.as_ref().map(f)).fold(0.0, f64::max)
    };
    let _ = writeln!(
        s,
        "floor (no goal; no model whose wrench at a pose is a degree-{} polynomial in depth does better on these FE runs): table2 Fy rel {:.3} % (goal {} %), rms {:.3} %; lhs rms {:.3} % (goal {} %)",
        r.floor_degree,
        floor("table2", |f| f.fy_rel_pct),
        g.table2_fy_pct,
        floor("table2", DepthFloor::worst_rms_pct),
        floor("lhs", DepthFloor::worst_rms_pct),
        g.rms_stretch_pct.unwrap_or(g.rms_pct)
    );
    let _ = writeln!(s, "mirror runs (symmetry check, no goal): rms {}", worst(r, "mirror", |x| x.worst_rms_pct));
    if let Some(t) = r.error_trend {
        let _ = writeln!(
            s,
            "error trend (no goal): Spearman rank correlation of a run's worst rms % over {} table2 and lhs runs: {:+.2} with its tilt |theta_x|+|theta_z|, {:+.2} with its offset |x|+|z|",
            t.runs, t.tilt_rho, t.offset_rho
        );
    }
    let _ = writeln!(s, "f32 model vs f64 model: largest difference {:.3e} % of scale", r.f32_vs_f64_max_pct);
}

/// `worst X % over N runs` of `f` over the runs of `role` (`no runs` without one).
fn worst(r: &Report, role: &str, f: fn(&RunReport) -> f64) -> String {
    let v: Vec<f64> = r.runs.iter().filter(|x| x.role == role).map(f).collect();
    if v.is_empty() {
        "no runs".to_string()
    } else {
        format!("worst {:.3} % over {} runs", v.iter().copied().fold(0.0, f64::max), v.len())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::unsolved::{inside_f32, normalised, solved_inside, to_toml, FILE};
    use needle_set::spec;

    /// A copy of the default set's spec, FE runs and model in a temporary folder.
    fn temp_set(tag: &str) -> std::path::PathBuf {
        let root = needle_stdx::workspace_root().join("coeffs/default");
        let dir = std::env::temp_dir().join(format!("needle-fit-unsolved-{tag}-{}", std::process::id()));
        let fe = dir.join("fe");
        std::fs::create_dir_all(&fe).expect("temp set");
        for f in ["campaign.toml", "model.toml"] {
            std::fs::copy(root.join(f), dir.join(f)).expect("copy");
        }
        for e in std::fs::read_dir(root.join("fe")).expect("fe").flatten() {
            let p = e.path();
            if p.is_file() {
                std::fs::copy(&p, fe.join(e.file_name())).expect("copy a run");
            }
        }
        dir
    }

    /// Issue 42, item 4: a held-out pose that failed every attempt joins the region from
    /// its partial record (deeper than it reached), `needle validate` names it beside the
    /// goals as a run the FE cannot solve, and no solved run lies in any ball.
    #[test]
    fn a_partial_record_joins_the_region_and_validate_names_it() {
        let dir = temp_set("record");
        // the shipped t2-b is solved: without its result it stands for a held-out pose
        // whose every attempt failed
        std::fs::remove_file(dir.join("fe/t2-b.csv")).expect("t2-b's result in the copy");
        let (campaign, _) = spec::load(&dir).expect("spec");
        let pose = campaign.poses().into_iter().find(|p| p.name == "t2-b").expect("t2-b");
        let failed = needle_set::partial::Failed {
            campaign: &campaign,
            pose: &pose,
            mesh: &campaign.campaign.mesh,
            engine: ("febio", "4.11.0"),
            failure:
                "solver exit code 1 after 6 of 20 steps (t = 1.95 mm): Max nr of reformations reached. (failed to converge at time : 1.95)",
        };
        let reached: Vec<[f64; 6]> = (1..=6).map(|k| [0.0, 0.001 * f64::from(k), 0.0, 0.0, 0.0, 0.0]).collect();
        needle_set::partial::write(&dir.join("fe"), &failed, &reached).expect("partial record");
        let r = crate::unsolved::region(&SetFolder::open(&dir).expect("the set")).expect("region");
        let t2b = r.failed.iter().find(|f| f.pose == "t2-b").expect("t2-b is in the region").clone();
        assert_eq!((t2b.source.as_str(), t2b.reached_depth_mm, t2b.depth_q16), ("fe/t2-b.partial.toml", Some(1.8), 117_965));
        assert!(t2b.cause.contains("max reformations"), "{}", t2b.cause);
        assert!(r.failed.iter().all(|f| f.pose != "lhs-16"), "no record, not fitted without: not in the region");
        assert!(solved_inside(&r).is_empty(), "a ball reaches half way to the nearest solved run: {:?}", solved_inside(&r));
        let entries = r.entries();
        let n = normalised(t2b.at).map(|v| v as f32);
        assert!(!inside_f32(&entries, n, 1.8) && inside_f32(&entries, n, 2.1), "deeper than it reached only");
        // the model carries it once `needle fit` writes unsolved.toml; validate then says so
        std::fs::write(dir.join(FILE), to_toml("default", &r)).expect("unsolved.toml");
        let report = validate(&SetFolder::open(&dir).expect("the set"), crate::contract::DEGREE).expect("validate");
        let table = to_table(&report);
        let _ = std::fs::remove_dir_all(&dir);
        let u = report.unsolved.iter().find(|u| u.name == "t2-b").expect("t2-b reported");
        assert!(u.failed_every_attempt && u.flagged_from_mm == Some(2.1), "{u:?}");
        assert!(
            table.contains(
                "held-out runs the FE cannot solve (every attempt failed; counted as missed): t2-b (table2; FE_UNSOLVED from 2.1 mm)"
            ),
            "{table}"
        );
        assert!(!report.table2_goal_met, "an unsolved held-out run still counts as missed");
    }
}
