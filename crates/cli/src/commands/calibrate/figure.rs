//! The calibration figure of `needle calibrate --curve`: the measured curve, the
//! calibrated stack's force through the library's insertion model, the punctures, the
//! residuals; and the first boundary's shape (issue 64): the measured rise before the
//! first puncture, the model with its family member, scale and softening, and the
//! residual, against depth from the fitted contact.
use needle_calibrate::Calibration;
use needle_plot::panel::{render, tick_label, Panel, RGBColor, Series, Style, COMPONENT_COLOURS};

/// Most reference points the figure draws.
const FIGURE_POINTS: usize = 600;

/// The colour of the measured points and the residuals in the calibration figures.
pub(super) const MEASURED_GREY: RGBColor = RGBColor(90, 90, 90);

/// A residual panel of the calibration figures: `data` as grey points against `x_label`.
pub(super) fn residual_panel(title: String, x_label: &str, data: Vec<(f64, f64)>) -> Panel {
    Panel {
        title,
        x_label: x_label.into(),
        y_label: "residual, N".into(),
        series: vec![Series { label: "residual".into(), colour: MEASURED_GREY, style: Style::Points, data }],
        y_min_span: 0.0,
    }
}

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
    let grey = MEASURED_GREY;
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
    let residual = residual_panel(format!("residual: {reference} - model"), "needle position, mm", residuals);
    let mut panels = vec![force, residual];
    panels.extend(pre_puncture(c, reference));
    let cols = if panels.len() > 2 { 2 } else { 1 };
    render(&format!("needle calibrate: {name}"), &panels, cols, (900, 420))
}

/// The first boundary's shape, when the calibration fitted it (`needle calibrate`; a
/// published model's layers have none): the measured rise from contact to the first
/// puncture and the calibrated model (its member, scale and softening in the title)
/// against depth from the fitted contact, and their residual.
fn pre_puncture(c: &Calibration, reference: &str) -> Vec<Panel> {
    let (Some(layer), Some(first)) = (c.fit.layers.first(), c.events.first()) else { return Vec::new() };
    if layer.family_weight_range.is_none() {
        return Vec::new();
    }
    let onset = c.fit.onset_mm;
    let Some(peak) = c.points.get(first.peak).map(|p| p.position_mm) else { return Vec::new() };
    let pre: Vec<_> = c.points.iter().take(first.peak + 1).filter(|p| p.position_mm >= onset).collect();
    let every = pre.len().div_ceil(FIGURE_POINTS).max(1);
    let measured: Vec<(f64, f64)> = pre.iter().step_by(every).map(|p| (p.position_mm - onset, p.force_n)).collect();
    let model: Vec<(f64, f64)> =
        c.replay.samples.iter().filter(|(x, _)| *x >= onset && *x <= peak).step_by(10).map(|&(x, f)| (x - onset, f)).collect();
    // the pre-puncture comparison's rule (the model's state when the stage reaches the point)
    let residuals: Vec<(f64, f64)> =
        pre.iter().step_by(every).map(|p| (p.position_mm - onset, p.force_n - c.replay.before(p.position_mm))).collect();
    let soft = &layer.softening;
    let softening = if soft.fraction > 0.0 {
        format!("softening {} from {} of the puncture's elastic force", tick_label(soft.fraction), tick_label(soft.onset_ratio))
    } else {
        "no softening".into()
    };
    let grey = MEASURED_GREY;
    let shape = Panel {
        title: format!(
            "before the first puncture: member w = {}, scale s = {}, {softening}",
            tick_label(layer.family_weight),
            tick_label(layer.scale)
        ),
        x_label: "depth from the fitted contact, mm".into(),
        y_label: "axial force, N".into(),
        series: vec![
            Series { label: reference.into(), colour: grey, style: Style::Points, data: measured },
            Series { label: "calibrated model".into(), colour: COMPONENT_COLOURS[1], style: Style::Line, data: model },
        ],
        y_min_span: 0.0,
    };
    let residual =
        residual_panel(format!("before the first puncture: residual, {reference} - model"), "depth from the fitted contact, mm", residuals);
    vec![shape, residual]
}
