//! The figures of a set, after the paper's: Fig 4 (the centred needle against depth),
//! Figs 6 and 7 (forces and moments at full depth against each swept input), Fig 8 (FE
//! against model at the Table 2 poses), a parity plot of every validation point, and
//! the FE verification (flat punch, mesh study) when `fe/verify.toml` exists.
//!
//! Model curves are the f64 evaluation of the set's `model.toml`
//! ([`needle_fit::eval::float64`]), FE points its current runs.

use super::panel::{Panel, Series, Style, COMPONENT_COLOURS, MIN_SPAN_OF_SCALE};
use anyhow::Result;
use needle_fit::contract::{unit, Sweep, COMPONENTS, DEPTH_MAX_MM};
use needle_fit::data::{load_fit_data, load_validation_runs, Run};
use needle_fit::eval::float64::eval;
use needle_fit::model::Model;
use needle_set::set_folder::SetFolder;
use needle_set::spec::Role;
use plotters::style::RGBColor;

const GREY: RGBColor = RGBColor(90, 90, 90);

fn depth_grid() -> Vec<f64> {
    (0..=120).map(|i| DEPTH_MAX_MM * f64::from(i) / 120.0).collect()
}

fn pose_of(r: &Run) -> [f64; 4] {
    let p = &r.pose;
    [p.x_mm, p.z_mm, p.theta_x_deg, p.theta_z_deg]
}

fn axis_name(c: usize) -> String {
    format!("{} ({})", COMPONENTS[c], unit(c))
}

/// Fig 4: the six components against depth at the centred pose; each panel spans at
/// least [`MIN_SPAN_OF_SCALE`] of its component's scale `scales[c]` (the odd components
/// are exactly 0 there: a flat line, not round-off autoscaled into a curve).
fn fig4(model: &Model, centre: &Run, scales: [f64; 6]) -> Vec<Panel> {
    (0..6)
        .map(|c| Panel {
            title: format!("{}: centred vertical needle", COMPONENTS[c]),
            x_label: "depth (mm)".into(),
            y_label: axis_name(c),
            series: vec![
                Series {
                    label: "model".into(),
                    colour: COMPONENT_COLOURS[c],
                    style: Style::Line,
                    data: depth_grid().into_iter().map(|d| (d, eval(model, [0.0, 0.0, 0.0, 0.0, d]).0[c])).collect(),
                },
                Series {
                    label: "FE".into(),
                    colour: GREY,
                    style: Style::Points,
                    data: centre.rows.iter().map(|r| (r.depth_mm, r.wrench[c])).collect(),
                },
            ],
            y_min_span: MIN_SPAN_OF_SCALE * scales[c],
        })
        .collect()
}

/// Figs 6 and 7: components `comps` (of one unit) at full depth against each swept input;
/// each panel spans at least [`MIN_SPAN_OF_SCALE`] of their scale.
fn sweeps(model: &Model, sweep_runs: &[Vec<&Run>; 4], comps: [usize; 3], scales: [f64; 6]) -> Vec<Panel> {
    Sweep::ALL
        .iter()
        .map(|&k| {
            let m = k.half_range();
            let mut series = Vec::new();
            for c in comps {
                let line = (0..=120)
                    .map(|i| {
                        let v = -m + 2.0 * m * f64::from(i) / 120.0;
                        let mut pose = [0.0; 5];
                        pose[k.index()] = v;
                        pose[4] = DEPTH_MAX_MM;
                        (v, eval(model, pose).0[c])
                    })
                    .collect();
                series.push(Series {
                    label: format!("{} model", COMPONENTS[c]),
                    colour: COMPONENT_COLOURS[c],
                    style: Style::Line,
                    data: line,
                });
                let points = sweep_runs[k.index()]
                    .iter()
                    .filter_map(|r| r.rows.last().map(|last| (pose_of(r)[k.index()], last.wrench[c])))
                    .collect();
                series.push(Series {
                    label: format!("{} FE", COMPONENTS[c]),
                    colour: COMPONENT_COLOURS[c],
                    style: Style::Points,
                    data: points,
                });
            }
            let unit = needle_contract::UNITS[comps[0]];
            Panel {
                title: format!("sweep in {} (others 0), depth {DEPTH_MAX_MM} mm", k.name()),
                x_label: format!("{} ({})", k.name(), k.unit()),
                y_label: format!("{} ({unit})", if needle_contract::is_force(comps[0]) { "force" } else { "moment about the hub" }),
                series,
                y_min_span: MIN_SPAN_OF_SCALE * scales[comps[0]],
            }
        })
        .collect()
}

/// Fig 8: Fy against depth at the Table 2 poses.
fn fig8(model: &Model, table2: &[&Run]) -> Vec<Panel> {
    table2
        .iter()
        .map(|r| {
            let p = pose_of(r);
            Panel {
                title: format!("{}: x {} mm, z {} mm, theta_x {} deg, theta_z {} deg", r.pose.name, p[0], p[1], p[2], p[3]),
                x_label: "depth (mm)".into(),
                y_label: axis_name(1),
                series: vec![
                    Series {
                        label: "model".into(),
                        colour: COMPONENT_COLOURS[1],
                        style: Style::Line,
                        data: depth_grid().into_iter().map(|d| (d, eval(model, [p[0], p[1], p[2], p[3], d]).0[1])).collect(),
                    },
                    Series {
                        label: "FE".into(),
                        colour: GREY,
                        style: Style::Points,
                        data: r.rows.iter().map(|x| (x.depth_mm, x.fy_n())).collect(),
                    },
                ],
                y_min_span: 0.0,
            }
        })
        .collect()
}

/// Parity: model against FE at every depth of every validation run, forces and moments.
fn parity(model: &Model, held: &[&Run], lever_arm_mm: f64) -> Vec<Panel> {
    let scales = needle_contract::error_scales(needle_set::results::peak_fy_n(held.iter().flat_map(|r| r.rows.iter())), lever_arm_mm);
    [(0..3, "forces", "N"), (3..6, "moments about the hub", "N*mm")]
        .into_iter()
        .map(|(cs, what, u)| {
            let mut series = Vec::new();
            let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
            for c in cs {
                let pts: Vec<(f64, f64)> = held
                    .iter()
                    .flat_map(|r| {
                        let p = pose_of(r);
                        r.rows.iter().map(move |x| (x.wrench[c], eval(model, [p[0], p[1], p[2], p[3], x.depth_mm]).0[c]))
                    })
                    .collect();
                let scale = scales[c];
                let rms = (pts.iter().map(|(f, m)| (m - f).powi(2)).sum::<f64>() / pts.len().max(1) as f64).sqrt();
                for &(f, m) in &pts {
                    lo = lo.min(f.min(m));
                    hi = hi.max(f.max(m));
                }
                let pct = if scale > 0.0 { 100.0 * rms / scale } else { 0.0 };
                series.push(Series {
                    label: format!("{} (RMS {pct:.2} % of peak)", COMPONENTS[c]),
                    colour: COMPONENT_COLOURS[c],
                    style: Style::Points,
                    data: pts,
                });
            }
            if lo.is_finite() {
                series.insert(0, Series { label: "model = FE".into(), colour: GREY, style: Style::Dashed, data: vec![(lo, lo), (hi, hi)] });
            }
            Panel {
                title: format!("{what}: {} validation runs, every depth", held.len()),
                x_label: format!("FE ({u})"),
                y_label: format!("model ({u})"),
                series,
                y_min_span: 0.0,
            }
        })
        .collect()
}

fn num(t: &toml::Table, path: &[&str]) -> Option<f64> {
    let mut v = t.get(path[0])?;
    for k in &path[1..] {
        v = v.get(k)?;
    }
    v.as_float()
}

/// FE verification: flat punch against Sneddon and the mesh study, from `fe/verify.toml`.
fn verification(verify: &toml::Table) -> Vec<Panel> {
    let mut panels = Vec::new();
    if let (Some(f1), Some(f2), Some(fh), Some(fs)) = (
        num(verify, &["punch", "force_block_n"]),
        num(verify, &["punch", "force_block_2x_n"]),
        num(verify, &["punch", "force_half_space_n"]),
        num(verify, &["punch", "force_sneddon_n"]),
    ) {
        let element = verify.get("punch").and_then(|p| p.get("element")).and_then(|e| e.as_str()).unwrap_or("FE");
        panels.push(Panel {
            title: format!("flat punch ({element}): force against 1 / block size"),
            x_label: "block size ratio 1/s (0 = half-space)".into(),
            y_label: "punch force (N)".into(),
            series: vec![
                Series { label: "Sneddon (half-space)".into(), colour: GREY, style: Style::Dashed, data: vec![(0.0, fs), (1.0, fs)] },
                Series {
                    label: "FE, extrapolated to s -> inf".into(),
                    colour: COMPONENT_COLOURS[1],
                    style: Style::Points,
                    data: vec![(1.0, f1), (0.5, f2), (0.0, fh)],
                },
            ],
            y_min_span: 0.0,
        });
    }
    if let Some(levels) = verify.get("mesh").and_then(|m| m.get("levels")).and_then(|l| l.as_array()) {
        let pts: Vec<(f64, f64)> = levels
            .iter()
            .filter_map(|l| Some((l.get("element_mm")?.as_float()?, l.get("fy_n")?.as_float()?)))
            .filter(|p| p.1.is_finite())
            .collect();
        let mut series =
            vec![Series { label: "FE, centred needle".into(), colour: COMPONENT_COLOURS[1], style: Style::Points, data: pts.clone() }];
        if let Some(r) = num(verify, &["mesh", "richardson_fy_n"]) {
            series.push(Series { label: "Richardson estimate (h -> 0)".into(), colour: GREY, style: Style::Points, data: vec![(0.0, r)] });
        }
        series.insert(0, Series { label: "refinement path".into(), colour: COMPONENT_COLOURS[1], style: Style::Line, data: pts });
        panels.push(Panel {
            title: "mesh study: Fy at full depth against element size".into(),
            x_label: "fine element size h (mm)".into(),
            y_label: axis_name(1),
            series,
            y_min_span: 0.0,
        });
    }
    panels
}

/// One figure: its file name, caption, panels and grid columns.
pub struct Figure {
    /// File name inside the output folder.
    pub file: &'static str,
    /// Caption on top.
    pub caption: String,
    /// The panels.
    pub panels: Vec<Panel>,
    /// Columns of the panel grid.
    pub cols: usize,
}

/// Every figure of the set `set` with model `model`.
///
/// # Errors
/// The set's runs cannot be loaded (missing or stale fitted runs, malformed files).
pub fn figures(set: &SetFolder, model: &Model) -> Result<Vec<Figure>> {
    let data = load_fit_data(set)?;
    let (campaign, validation, _) = load_validation_runs(set)?;
    let fe_dir = set.fe_dir();
    let set = &campaign.set.name;
    let mut sweep_runs: [Vec<&Run>; 4] = Default::default();
    for k in Sweep::ALL {
        sweep_runs[k.index()] = data.sweeps[k.index()].iter().map(|p| &p.run).collect();
    }
    for r in validation.iter().filter(|r| r.pose.role == Role::Mirror) {
        let p = pose_of(r);
        let nonzero: Vec<usize> = (0..4).filter(|&i| p[i] != 0.0).collect();
        if let [i] = nonzero.as_slice() {
            sweep_runs[*i].push(r);
        }
    }
    let table2: Vec<&Run> = validation.iter().filter(|r| r.pose.role == Role::Table2).collect();
    let held: Vec<&Run> = validation.iter().filter(|r| r.pose.role.is_validation()).collect();
    // The model curves' scales: the centre run's peak |Fy|, times the lever arm for moments.
    let scales =
        needle_contract::error_scales(needle_set::results::peak_fy_n(data.centre.rows.iter()), campaign.needle.reference_from_tip_mm);
    let mut out = vec![
        Figure {
            file: "fig4-centre.svg",
            caption: format!("Set {set}: the six wrench components against depth, centred vertical needle (cf. the paper's Fig 4)"),
            panels: fig4(model, &data.centre, scales),
            cols: 3,
        },
        Figure {
            file: "fig6-forces.svg",
            caption: format!("Set {set}: forces at full depth against position and tilt (cf. Fig 6)"),
            panels: sweeps(model, &sweep_runs, [0, 1, 2], scales),
            cols: 2,
        },
        Figure {
            file: "fig7-moments.svg",
            caption: format!("Set {set}: moments about the hub at full depth against position and tilt (cf. Fig 7)"),
            panels: sweeps(model, &sweep_runs, [3, 4, 5], scales),
            cols: 2,
        },
        Figure {
            file: "fig8-validation.svg",
            caption: format!("Set {set}: Fy against depth at the Table 2 poses, FE and model (cf. Fig 8)"),
            panels: fig8(model, &table2),
            cols: 2,
        },
        Figure {
            file: "parity.svg",
            caption: format!("Set {set}: model against FE, held-out runs (Table 2 and Latin hypercube)"),
            panels: parity(model, &held, campaign.needle.reference_from_tip_mm),
            cols: 2,
        },
    ];
    let verify_path = fe_dir.join("verify.toml");
    if let Ok(text) = std::fs::read_to_string(&verify_path) {
        let t: toml::Table = text.parse().map_err(|e| anyhow::anyhow!("{}: {e}", verify_path.display()))?;
        let panels = verification(&t);
        if !panels.is_empty() {
            out.push(Figure {
                file: "fe-verification.svg",
                caption: format!("Set {set}: FE verification (fe/verify.toml)"),
                panels,
                cols: 2,
            });
        }
    }
    Ok(out)
}
