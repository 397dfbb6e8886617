//! The figure of a whole-trial calibration (`needle calibrate --trials`, issue 65) or of a
//! trial replayed through a stack (`needle replay --figure`): per trial, the measured
//! axial force and the model's against time over the insertion, the hold and the
//! withdrawal (the phases' starts marked), the measured and the model punctures, the
//! residual, and the rise before the first puncture against depth from the contact. The
//! model's force is the replay's, per measured row
//! ([`needle_calibrate::trial_replay`]): the same numbers `--json` prints.
use needle_calibrate::trial_replay::TrialReplay;
use needle_calibrate::whole::trials::Trial;
use needle_plot::panel::{render, Panel, Series, Style, COMPONENT_COLOURS};

/// Most points of one measured series (the rows are thinned evenly beyond).
const MEASURED_POINTS: usize = 600;
/// Most points of one model line.
const MODEL_POINTS: usize = 1_500;
/// One panel's size, pixels.
const PANEL_PX: (u32, u32) = (760, 340);

/// The panels of one trial: its force against time, its residual, and the rise before
/// its first puncture against depth with its residual.
#[must_use]
pub fn panels(t: &Trial, r: &TrialReplay) -> [Panel; 3] {
    let s = &t.samples;
    let every = s.len().div_ceil(MEASURED_POINTS).max(1);
    let line_every = s.len().div_ceil(MODEL_POINTS).max(1);
    let measured: Vec<(f64, f64)> = s.iter().step_by(every).map(|x| (x.time_s, x.force_n)).collect();
    let model: Vec<(f64, f64)> =
        s.iter().zip(&r.rows).step_by(line_every).filter(|(_, m)| m.force_n.is_finite()).map(|(x, m)| (x.time_s, m.force_n)).collect();
    let measured_punctures: Vec<(f64, f64)> =
        t.events.iter().filter_map(|e| s.get(t.sample_of(e.peak))).map(|x| (x.time_s, x.force_n)).collect();
    let model_punctures: Vec<(f64, f64)> = r.punctures.iter().filter(|p| p.force_n.is_finite()).map(|p| (p.time_s, p.force_n)).collect();
    let residual: Vec<(f64, f64)> = s
        .iter()
        .zip(&r.rows)
        .step_by(every)
        .filter(|(_, m)| m.force_n.is_finite())
        .map(|(x, m)| (x.time_s, x.force_n - m.force_n))
        .collect();
    let (lo, hi) = measured.iter().chain(&model).fold((0.0f64, 0.0f64), |(a, b), p| (a.min(p.1), b.max(p.1)));
    let grey = super::figure::MEASURED_GREY;
    let mut series = vec![
        Series { label: "measured".into(), colour: grey, style: Style::Points, data: measured },
        Series { label: "model (calibrated stack)".into(), colour: COMPONENT_COLOURS[1], style: Style::Line, data: model },
        Series { label: "measured punctures".into(), colour: COMPONENT_COLOURS[0], style: Style::Points, data: measured_punctures },
        Series { label: "model punctures".into(), colour: COMPONENT_COLOURS[2], style: Style::Points, data: model_punctures },
    ];
    // the phases' starts as vertical dashes across the force's range
    let phases = [("hold starts", &t.phases.hold), ("withdrawal starts", &t.phases.withdrawal)];
    for (k, (label, range)) in phases.into_iter().enumerate() {
        if let Some(x) = (!range.is_empty()).then(|| s.get(range.start)).flatten() {
            let colour = COMPONENT_COLOURS[3 + k];
            series.push(Series { label: label.into(), colour, style: Style::Dashed, data: vec![(x.time_s, lo), (x.time_s, hi)] });
        }
    }
    let name = t.path.file_name().map_or_else(|| t.name(), |n| n.to_string_lossy().into_owned());
    let force = Panel {
        title: format!("{name}: axial force against time (insertion, hold, withdrawal)"),
        x_label: "time, s".into(),
        y_label: "axial force, N".into(),
        series,
        y_min_span: 0.0,
    };
    let residual = super::figure::residual_panel(format!("{name}: residual, measured - model"), "time, s", residual);
    [force, residual, pre_puncture(t, r, &name)]
}

/// The rise before the first puncture against depth from the trial's contact (the
/// insertion's rows up to the first measured peak): measured, model and residual.
fn pre_puncture(t: &Trial, r: &TrialReplay, name: &str) -> Panel {
    let onset = t.onset_mm();
    let end = t.events.first().map_or(t.points.len(), |e| e.peak + 1);
    let rows: Vec<(f64, f64, f64)> = (0..end)
        .filter_map(|i| Some((t.samples.get(t.sample_of(i))?, r.rows.get(t.sample_of(i))?)))
        .filter(|(x, m)| x.position_mm >= onset && m.force_n.is_finite())
        .map(|(x, m)| (x.position_mm - onset, x.force_n, m.force_n))
        .collect();
    let every = rows.len().div_ceil(MEASURED_POINTS).max(1);
    let grey = super::figure::MEASURED_GREY;
    Panel {
        title: format!("{name}: before the first puncture, against depth"),
        x_label: "depth from the fitted contact, mm".into(),
        y_label: "axial force, N".into(),
        series: vec![
            Series {
                label: "measured".into(),
                colour: grey,
                style: Style::Points,
                data: rows.iter().step_by(every).map(|p| (p.0, p.1)).collect(),
            },
            Series {
                label: "model".into(),
                colour: COMPONENT_COLOURS[1],
                style: Style::Line,
                data: rows.iter().map(|p| (p.0, p.2)).collect(),
            },
            Series {
                label: "residual, measured - model".into(),
                colour: COMPONENT_COLOURS[4],
                style: Style::Points,
                data: rows.iter().step_by(every).map(|p| (p.0, p.1 - p.2)).collect(),
            },
        ],
        y_min_span: 0.0,
    }
}

/// The SVG text of the figure: one row per trial ([`panels`]), under `caption`.
///
/// # Errors
/// A chart cannot be laid out.
pub fn svg(caption: &str, trials: &[(&Trial, &TrialReplay)]) -> anyhow::Result<String> {
    let panels: Vec<Panel> = trials.iter().flat_map(|(t, r)| panels(t, r)).collect();
    render(caption, &panels, 3, PANEL_PX)
}
