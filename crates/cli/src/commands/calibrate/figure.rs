//! The calibration figure of `needle calibrate`: the measured curve, the calibrated
//! stack's force through the library's insertion model, the punctures, the residuals.
use needle_calibrate::Calibration;
use needle_plot::panel::{render, Panel, RGBColor, Series, Style, COMPONENT_COLOURS};

/// Most reference points the figure draws.
const FIGURE_POINTS: usize = 600;

/// The SVG text of the figure for `c` (stack `name`), its curve labelled `reference`
/// ("measured", or "published model (sampled)" for `needle calibrate-published`).
///
/// # Errors
/// A chart cannot be laid out.
pub fn svg(c: &Calibration, name: &str, reference: &str) -> anyhow::Result<String> {
    // at most about FIGURE_POINTS reference points drawn (a sampled published curve has
    // thousands; a digitised one fewer, all drawn)
    let every = c.points.len().div_ceil(FIGURE_POINTS).max(1);
    let measured: Vec<(f64, f64)> = c.points.iter().step_by(every).map(|p| (p.position_mm, p.force_n)).collect();
    let model: Vec<(f64, f64)> = c.replay.samples.iter().step_by(10).copied().collect();
    let measured_peaks: Vec<(f64, f64)> =
        c.events.iter().filter_map(|e| c.points.get(e.peak)).map(|p| (p.position_mm, p.force_n)).collect();
    let residuals: Vec<(f64, f64)> =
        c.points.iter().step_by(every).map(|p| (p.position_mm, p.force_n - c.replay.at(p.position_mm))).collect();
    let grey = RGBColor(90, 90, 90);
    let force = Panel {
        title: format!("{name}: axial force against needle position"),
        x_label: "needle position, mm".into(),
        y_label: "axial force, N".into(),
        series: vec![
            Series { label: reference.into(), colour: grey, style: Style::Points, data: measured },
            Series { label: "calibrated stack (insertion model)".into(), colour: COMPONENT_COLOURS[1], style: Style::Line, data: model },
            Series { label: format!("{reference} punctures"), colour: COMPONENT_COLOURS[0], style: Style::Points, data: measured_peaks },
            Series {
                label: "model punctures".into(),
                colour: COMPONENT_COLOURS[2],
                style: Style::Points,
                data: c.replay.punctures.clone(),
            },
        ],
        y_min_span: 0.0,
    };
    let residual = Panel {
        title: format!("residual: {reference} - model"),
        x_label: "needle position, mm".into(),
        y_label: "residual, N".into(),
        series: vec![Series { label: "residual".into(), colour: grey, style: Style::Points, data: residuals }],
        y_min_span: 0.0,
    };
    render(&format!("needle calibrate: {name}"), &[force, residual], 1, (900, 420))
}
