//! What `needle fit` measures about the coupled form: the cross-validation of its size
//! on the training runs, the learning curve (held-out error against the number of
//! training runs) and the held-out errors of both forms side by side.
//!
//! Held-out runs are the validation runs (Table 2 and the Latin hypercube): never
//! fitted, never used by the cross-validation. Errors are `needle validate`'s: per run
//! and component, RMS over the run's depths in % of the run's peak |Fy| (moments: times
//! the lever arm), and for Table 2 the largest |Fy| error at depths >= 1 mm in % of FE.

use super::coupled::{self, Selection};
use super::data::{load_paper_data, load_training_runs, load_validation_runs, Run};
use super::model::{fit as fit_paper, Model};
use super::validate::TABLE2_MIN_DEPTH_MM;
use crate::contract::COMPONENT_COUNT;
use crate::eval::float64::{eval, eval_paper, Pose64};
use anyhow::Result;
use needle_set::set_folder::SetFolder;
use needle_set::spec::Role;
use serde::Serialize;
use std::fmt::Write as _;

/// Held-out errors of one form.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct HeldOut {
    /// Worst per-run, per-component RMS over the lhs runs, % of the run's peak |Fy|.
    pub lhs_worst_rms_pct: f64,
    /// Worst per-run, per-component RMS over the Table 2 runs, %.
    pub table2_worst_rms_pct: f64,
    /// Largest |Fy error| / |FE Fy| over the Table 2 runs at depths >= 1 mm, %.
    pub table2_fy_max_pct: f64,
    /// Largest error of any component at any depth of any held-out run, % of peak |Fy|.
    pub worst_max_pct: f64,
}

/// One point of the learning curve.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CurvePoint {
    /// Training runs used: the first `runs` of the design.
    pub runs: usize,
    /// Per component, the size chosen by cross-validation on them ([`coupled::Candidate::label`]).
    pub choices: Option<Vec<String>>,
    /// Held-out errors of the coupled form fitted on them; `None` if nothing could be fitted.
    pub held_out: Option<HeldOut>,
}

/// Everything measured.
#[derive(Debug, Clone)]
pub struct CoupledReport {
    /// Training runs found (and usable).
    pub training_runs: usize,
    /// Training runs missing or stale.
    pub unusable: Vec<String>,
    /// Held-out runs compared.
    pub held_out_runs: usize,
    /// Cross-validation of every candidate on all training runs, the paper form's error
    /// there and each component's choice; `None` when nothing could be fitted.
    pub selection: Option<Selection>,
    /// The coupled model fitted on all training runs.
    pub model: Option<Model>,
    /// The paper form's held-out errors.
    pub paper: HeldOut,
    /// The coupled form's held-out errors.
    pub coupled: Option<HeldOut>,
    /// Learning curve.
    pub curve: Vec<CurvePoint>,
}

/// Held-out errors of `model` on `runs` (module docs).
pub fn held_out(runs: &[&Run], lever_arm_mm: f64, model: impl Fn(Pose64) -> [f64; COMPONENT_COUNT]) -> HeldOut {
    let mut h = HeldOut::default();
    for r in runs {
        let scale = needle_contract::error_scales(needle_set::results::peak_fy_n(&r.rows), lever_arm_mm);
        let mut s = [0.0f64; COMPONENT_COUNT];
        for row in &r.rows {
            let w = model(r.pose_at(row.depth_mm));
            for c in 0..COMPONENT_COUNT {
                let e = w[c] - row.wrench[c];
                s[c] += e * e;
                if scale[c] > 0.0 {
                    h.worst_max_pct = h.worst_max_pct.max(100.0 * e.abs() / scale[c]);
                }
            }
            if r.pose.role == Role::Table2 && row.depth_mm >= TABLE2_MIN_DEPTH_MM - 1e-9 && row.fy_n() != 0.0 {
                h.table2_fy_max_pct = h.table2_fy_max_pct.max(100.0 * (w[needle_contract::FY] - row.fy_n()).abs() / row.fy_n().abs());
            }
        }
        let n = r.rows.len().max(1) as f64;
        let worst = (0..COMPONENT_COUNT).filter(|&c| scale[c] > 0.0).map(|c| 100.0 * (s[c] / n).sqrt() / scale[c]).fold(0.0, f64::max);
        match r.pose.role {
            Role::Lhs => h.lhs_worst_rms_pct = h.lhs_worst_rms_pct.max(worst),
            Role::Table2 => h.table2_worst_rms_pct = h.table2_worst_rms_pct.max(worst),
            _ => {}
        }
    }
    h
}

/// The learning curve's verdict on the design's size: if the held-out LHS worst RMS
/// still falls by more than this fraction of itself per 8 added training runs between
/// the curve's last two points, more runs still pay and the design stays as large as it
/// is (`train_count`); below it the curve is flat (2 % of a 1 % error is 0.02 % of peak
/// |Fy|, a tenth of the FE data's pose-to-pose scatter, coeffs/README.md).
pub const CURVE_STILL_FALLING: f64 = 0.02;

/// The verdict line of the learning curve (see [`CURVE_STILL_FALLING`]): `None` with
/// fewer than two measured points.
pub fn curve_verdict(curve: &[CurvePoint]) -> Option<String> {
    let measured: Vec<(usize, HeldOut)> = curve.iter().filter_map(|p| p.held_out.map(|h| (p.runs, h))).collect();
    let [.., (n0, h0), (n1, h1)] = measured.as_slice() else {
        return None;
    };
    let added = n1.checked_sub(*n0).filter(|&a| a > 0)?;
    let per8 = |a: f64, b: f64| if a > 0.0 { (a - b) / a * 8.0 / added as f64 } else { 0.0 };
    let fall = per8(h0.lhs_worst_rms_pct, h1.lhs_worst_rms_pct);
    let fall_max = per8(h0.worst_max_pct, h1.worst_max_pct);
    let verdict = if fall > CURVE_STILL_FALLING {
        "still falling: more training runs pay, the design keeps its size"
    } else {
        "flat: more training runs no longer pay"
    };
    Some(format!(
        "learning curve, {n0} -> {n1} runs: lhs worst rms {:.3} -> {:.3} % ({:+.1} % of itself per 8 runs), worst max {:.3} -> {:.3} % ({:+.1} %): {verdict} (threshold {:.0} % per 8 runs)",
        h0.lhs_worst_rms_pct,
        h1.lhs_worst_rms_pct,
        -100.0 * fall,
        h0.worst_max_pct,
        h1.worst_max_pct,
        -100.0 * fall_max,
        100.0 * CURVE_STILL_FALLING
    ))
}

/// Sizes of the learning curve: 8, 16, 24, ... up to all `n` training runs.
pub fn curve_sizes(n: usize) -> Vec<usize> {
    let mut v: Vec<usize> = (1..).map(|k| 8 * k).take_while(|&k| k < n).collect();
    v.push(n);
    v
}

/// Held-out errors of the paper part of `model` alone (its cross terms, if any, left
/// out).
pub fn paper_held_out(runs: &[&Run], lever_arm_mm: f64, model: &Model) -> HeldOut {
    held_out(runs, lever_arm_mm, |p| eval_paper(model, p).0)
}

/// Measure the coupled form of the opened set `set` against its paper form (fitted here
/// on the centre and sweep runs, as `form = "paper"` does), whichever form the set
/// ships: the coupled form is fitted on the training runs present.
///
/// # Errors
/// The spec, the manifest or a run cannot be read; the paper form cannot be fitted.
pub fn measure(set: &SetFolder) -> Result<CoupledReport> {
    let data = load_paper_data(set)?;
    let paper = fit_paper(&data)?;
    let (campaign, train, unusable) = load_training_runs(set)?;
    let (_, validation, _) = load_validation_runs(set)?;
    let lever = campaign.needle.reference_from_tip_mm;
    let held: Vec<&Run> = validation.iter().filter(|r| r.pose.role.is_validation()).collect();
    let train_refs: Vec<&Run> = train.iter().collect();
    let paper_errors = paper_held_out(&held, lever, &paper);
    let mut report = CoupledReport {
        training_runs: train.len(),
        unusable: unusable.iter().map(|u| format!("{} ({})", u.pose.name, u.why)).collect(),
        held_out_runs: held.len(),
        selection: None,
        model: None,
        paper: paper_errors,
        coupled: None,
        curve: Vec::new(),
    };
    if train.len() < 2 {
        return Ok(report);
    }
    let scale = coupled::scales(&train_refs, lever);
    for n in curve_sizes(train.len()) {
        let got = coupled::select_and_fit(&paper, &data, &train_refs[..n], scale).ok();
        let point = CurvePoint {
            runs: n,
            choices: got.as_ref().map(|g| g.0.choices.iter().map(coupled::Candidate::label).collect()),
            held_out: got.as_ref().map(|g| held_out(&held, lever, |p| eval(&g.1, p).0)),
        };
        if n == train.len() {
            if let Some((selection, model)) = got {
                report.coupled = point.held_out;
                report.selection = Some(selection);
                report.model = Some(model);
            }
        }
        report.curve.push(point);
    }
    Ok(report)
}

/// The report as plain text.
pub fn to_table(r: &CoupledReport) -> String {
    let mut s = String::new();
    write_runs(&mut s, r);
    write_selection(&mut s, r);
    write_learning_curve(&mut s, r);
    write_held_out(&mut s, r);
    s
}

/// The training and held-out run counts, with the unusable runs.
fn write_runs(s: &mut String, r: &CoupledReport) {
    let _ = writeln!(
        s,
        "coupled form: {} training runs{}; held out: {} validation runs (table2, lhs)",
        r.training_runs,
        match r.unusable.as_slice() {
            [] => String::new(),
            [a, b, c, _, ..] => format!(" ({} unusable: {a}, {b}, {c}, ...)", r.unusable.len()),
            all => format!(" ({} unusable: {})", all.len(), all.join(", ")),
        },
        r.held_out_runs
    );
}

/// The cross-validation of the candidate forms and the choice per component.
fn write_selection(s: &mut String, r: &CoupledReport) {
    if let Some(sel) = &r.selection {
        let _ = writeln!(
            s,
            "{}-fold cross-validation on the sweep and training runs (RMS, % of the training runs' peak |Fy|; moments x lever arm);",
            coupled::FOLDS
        );
        let _ = writeln!(s, "  form: sweep degree / cross degree / depth degree of the cross terms (- none):");
        let _ = writeln!(s, "  {:>10}  {:>6} {:>6} {:>6} {:>6} {:>6} {:>6}", "form", "fx", "fy", "fz", "mx", "my", "mz");
        let _ = writeln!(
            s,
            "  {:>10} {}  (paper form on the training runs, out of sample; reference)",
            "paper",
            (0..COMPONENT_COUNT).map(|c| format!(" {:>6.3} ", sel.paper_rms_pct[c])).collect::<String>()
        );
        for score in &sel.cv {
            let cells: String = (0..COMPONENT_COUNT)
                .map(|c| match score.rms_pct[c] {
                    Some(e) => format!(" {:>6.3}{}", e, if sel.choices[c] == score.candidate { "*" } else { " " }),
                    None => format!(" {:>6} ", "-"),
                })
                .collect();
            let why = match (&score.failure, score.rms_pct.iter().any(Option::is_none)) {
                (Some(f), true) => format!("  not fitted: {}", f.chars().take(160).collect::<String>()),
                _ => String::new(),
            };
            let _ = writeln!(s, "  {:>10} {cells}{why}", score.candidate.label());
        }
        let names: Vec<String> =
            sel.choices.iter().zip(crate::contract::COMPONENTS).map(|(f, name)| format!("{name} {}", f.label())).collect();
        let _ = writeln!(s, "  chosen per component (*): {}", names.join(", "));
    }
}

/// Held-out errors of the coupled form fitted on the first n training runs.
fn write_learning_curve(s: &mut String, r: &CoupledReport) {
    let _ = writeln!(s, "learning curve (held-out errors of the coupled form fitted on the first n training runs):");
    let _ = writeln!(
        s,
        "  {:>4}  {:>12} {:>12} {:>12} {:>10}  chosen (fx fy fz mx my mz)",
        "n", "lhs rms %", "t2 rms %", "t2 Fy max %", "max %"
    );
    for p in &r.curve {
        match (&p.choices, p.held_out) {
            (Some(f), Some(h)) => {
                let _ = writeln!(
                    s,
                    "  {:>4}  {:>12.3} {:>12.3} {:>12.3} {:>10.3}  {}",
                    p.runs,
                    h.lhs_worst_rms_pct,
                    h.table2_worst_rms_pct,
                    h.table2_fy_max_pct,
                    h.worst_max_pct,
                    f.join(" ")
                );
            }
            _ => {
                let _ = writeln!(s, "  {:>4}  (too few runs for any candidate)", p.runs);
            }
        }
    }
    if let Some(v) = curve_verdict(&r.curve) {
        let _ = writeln!(s, "  {v}");
    }
}

/// Held-out errors of both forms.
fn write_held_out(s: &mut String, r: &CoupledReport) {
    let _ = writeln!(s, "held-out errors, both forms ({} runs):", r.held_out_runs);
    let _ = writeln!(s, "  {:<8} {:>12} {:>12} {:>12} {:>10}", "form", "lhs rms %", "t2 rms %", "t2 Fy max %", "max %");
    let mut row = |name: &str, h: &HeldOut| {
        let _ = writeln!(
            s,
            "  {:<8} {:>12.3} {:>12.3} {:>12.3} {:>10.3}",
            name, h.lhs_worst_rms_pct, h.table2_worst_rms_pct, h.table2_fy_max_pct, h.worst_max_pct
        );
    };
    row("paper", &r.paper);
    if let Some(c) = &r.coupled {
        row("coupled", c);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cross_terms::{CrossForm, CrossTerms};
    use crate::model::Coupled;
    use needle_set::results::Row;
    use needle_set::spec::{PoseSpec, Role};

    fn point(runs: usize, lhs: f64, max: f64) -> CurvePoint {
        let h = HeldOut { lhs_worst_rms_pct: lhs, table2_worst_rms_pct: 0.5, table2_fy_max_pct: 20.0, worst_max_pct: max };
        CurvePoint { runs, choices: Some(vec![]), held_out: Some(h) }
    }

    /// The verdict compares the last two measured points, per 8 added runs.
    #[test]
    fn the_curve_verdict_reads_the_last_step_per_8_runs() {
        // 16 -> 21 runs, 1.225 -> 1.114 %: -9.1 % over 5 runs, -14.5 % per 8
        let falling = [point(8, 1.252, 4.3), point(16, 1.225, 4.25), point(21, 1.114, 3.978)];
        let v = curve_verdict(&falling).expect("two points");
        assert!(v.contains("16 -> 21 runs") && v.contains("-14.5 % of itself per 8 runs") && v.contains("still falling"), "{v}");
        // 1 % per 8 runs: flat
        let flat = [point(16, 1.0, 3.0), point(24, 0.99, 3.0)];
        assert!(curve_verdict(&flat).expect("two points").contains("flat"));
        // a point that could not be fitted is skipped; one measured point says nothing
        let gap = [point(8, 1.0, 3.0), CurvePoint { runs: 16, choices: None, held_out: None }];
        assert_eq!(curve_verdict(&gap), None);
    }

    /// The paper row of the report is the paper part alone: with cross terms in the
    /// model (as `needle fit` passes the fitted coupled model), a run equal to the paper
    /// part has zero paper error and a nonzero coupled one. (It once evaluated the whole
    /// model, so both rows of `needle fit` showed the coupled form's errors.)
    #[test]
    fn the_paper_row_leaves_the_cross_terms_out() {
        let path = needle_stdx::workspace_root().join("coeffs/default/model.toml");
        let mut model = crate::model_file::read(&path).unwrap_or_else(|e| panic!("{e:#}"));
        let pose = PoseSpec { name: "lhs-test".into(), role: Role::Lhs, x_mm: 6.0, z_mm: 0.0, theta_x_deg: 0.0, theta_z_deg: 9.0 };
        let rows: Vec<Row> = (1..=20)
            .map(|i| {
                let depth_mm = 0.3 * f64::from(i);
                Row { depth_mm, wrench: eval_paper(&model, [pose.x_mm, pose.z_mm, pose.theta_x_deg, pose.theta_z_deg, depth_mm]).0 }
            })
            .collect();
        let run = Run { pose, file_name: "lhs-test.csv".into(), rows };
        // fy += 0.01 N * (x/12) * (theta_z/15): nonzero at this pose.
        let mut terms: [Vec<([u8; 4], Vec<f64>)>; COMPONENT_COUNT] = Default::default();
        terms[1].push(([1, 0, 0, 1], vec![0.01, 0.0, 0.0]));
        let terms = CrossTerms { form: CrossForm { max_degree: 2, depth_degree: 2 }, terms };
        model.cross =
            Some(Coupled { terms: terms.clone(), training_runs: 1, cv_rms_pct: [0.0; COMPONENT_COUNT], scale: [1.0; COMPONENT_COUNT] });
        let paper = paper_held_out(&[&run], 60.0, &model);
        let coupled = held_out(&[&run], 60.0, |p| crate::eval::float64::eval_with_cross(&model, &terms, p).0);
        assert_eq!(paper.lhs_worst_rms_pct, 0.0, "the paper row must not include the cross terms");
        assert!(coupled.lhs_worst_rms_pct > 1.0, "the cross term shows in the coupled row: {}", coupled.lhs_worst_rms_pct);
    }
}
