//! One figure of several panels, each a chart of model curves and FE points, rendered
//! to SVG text with plotters. The output depends on the data only (no fonts are read:
//! plotters' built-in text metrics, no dates), so the same data gives the same bytes.

use anyhow::{anyhow, Result};
use plotters::prelude::*;
/// The colour type of a [`Series`] (plotters'), for callers that build panels.
pub use plotters::style::RGBColor;

/// The six components' colours, in contract order (fx, fy, fz, mx, my, mz).
pub const COMPONENT_COLOURS: [RGBColor; 6] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(148, 103, 189),
    RGBColor(255, 127, 14),
    RGBColor(23, 190, 207),
];

/// How a series is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Style {
    /// A line through the points (model curves).
    Line,
    /// A marker per point (FE results).
    Points,
    /// A dashed line (references: theory, y = x).
    Dashed,
}

/// One series of a panel.
#[derive(Debug, Clone)]
pub struct Series {
    /// Legend text.
    pub label: String,
    /// Colour.
    pub colour: RGBColor,
    /// How it is drawn.
    pub style: Style,
    /// (x, y) in the panel's units.
    pub data: Vec<(f64, f64)>,
}

/// One chart.
#[derive(Debug, Clone)]
pub struct Panel {
    /// Title above the chart.
    pub title: String,
    /// x-axis label, with its unit.
    pub x_label: String,
    /// y-axis label, with its unit.
    pub y_label: String,
    /// The series, drawn in order.
    pub series: Vec<Series>,
    /// The y axis spans at least this much (in the panel's unit; 0: autoscale to the
    /// data): a component that is 0, or round-off, over the whole panel is drawn as a
    /// flat line on the component's scale, never autoscaled into a curve.
    pub y_min_span: f64,
}

/// The share of a component's scale (`needle_contract::error_scales`) that a panel of
/// model curves spans at least ([`Panel::y_min_span`]): 1 %.
pub const MIN_SPAN_OF_SCALE: f64 = 0.01;

/// A tick value as people read it: `0`, `0.6`, `2.5`, `14`, `120` (at most four
/// significant digits, no trailing zeros); below 0.001 or from 10,000 on, `5e-4`, `1.5e4`.
#[must_use]
pub fn tick_label(v: f64) -> String {
    let a = v.abs();
    if a < 1e-12 {
        return "0".to_string();
    }
    if !(1e-3..1e4).contains(&a) {
        let s = format!("{v:.2e}");
        let (mantissa, exponent) = s.split_once('e').unwrap_or((&s, "0"));
        let mantissa = mantissa.trim_end_matches('0').trim_end_matches('.');
        return format!("{mantissa}e{exponent}");
    }
    let decimals = (3 - a.log10().floor() as i32).max(0) as usize;
    let s = format!("{v:.decimals$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// The axis range of `values`, padded by 6 % of their span, and at least `min_span` wide
/// (centred on the values' midpoint).
fn range(values: impl Iterator<Item = f64>, min_span: f64) -> std::ops::Range<f64> {
    let (lo, hi) = values.filter(|v| v.is_finite()).fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)));
    if !lo.is_finite() {
        return 0.0..1.0;
    }
    let span = hi - lo;
    if min_span > 0.0 && span < min_span {
        let mid = 0.5 * (lo + hi);
        let half = 0.5 * min_span * 1.12;
        return (mid - half)..(mid + half);
    }
    let pad = if span > 0.0 { 0.06 * span } else { lo.abs().max(1e-6) * 0.1 };
    (lo - pad)..(hi + pad)
}

fn err<E: std::fmt::Debug>(what: &str) -> impl FnOnce(E) -> anyhow::Error + '_ {
    move |e| anyhow!("plotting {what}: {e:?}")
}

/// Render `panels` in a grid of `cols` columns, each panel `panel_px` pixels, under
/// `caption`, as SVG text.
///
/// # Errors
/// plotters fails to lay out a chart (not expected for finite data).
pub fn render(caption: &str, panels: &[Panel], cols: usize, panel_px: (u32, u32)) -> Result<String> {
    let cols = cols.max(1);
    let rows = panels.len().div_ceil(cols).max(1);
    let size = (panel_px.0 * cols as u32, panel_px.1 * rows as u32 + 40);
    let mut svg = String::new();
    {
        let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
        root.fill(&WHITE).map_err(err(caption))?;
        let root = root.titled(caption, ("sans-serif", 22)).map_err(err(caption))?;
        let areas = root.split_evenly((rows, cols));
        for (panel, area) in panels.iter().zip(areas.iter()) {
            draw_panel(panel, area)?;
        }
        root.present().map_err(err(caption))?;
    }
    Ok(svg)
}

fn draw_panel(p: &Panel, area: &DrawingArea<SVGBackend<'_>, plotters::coord::Shift>) -> Result<()> {
    let xs = range(p.series.iter().flat_map(|s| s.data.iter().map(|d| d.0)), 0.0);
    let ys = range(p.series.iter().flat_map(|s| s.data.iter().map(|d| d.1)), p.y_min_span);
    let mut chart = ChartBuilder::on(area)
        .caption(&p.title, ("sans-serif", 15))
        .margin(8)
        .x_label_area_size(38)
        .y_label_area_size(72)
        .build_cartesian_2d(xs, ys)
        .map_err(err(&p.title))?;
    chart
        .configure_mesh()
        .x_desc(&p.x_label)
        .y_desc(&p.y_label)
        .x_labels(7)
        .y_labels(7)
        .x_label_formatter(&|v| tick_label(*v))
        .y_label_formatter(&|v| tick_label(*v))
        .label_style(("sans-serif", 11))
        .draw()
        .map_err(err(&p.title))?;
    for s in &p.series {
        let colour = s.colour;
        match s.style {
            Style::Line => {
                chart
                    .draw_series(LineSeries::new(s.data.iter().copied(), colour.stroke_width(2)))
                    .map_err(err(&p.title))?
                    .label(&s.label)
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], colour.stroke_width(2)));
            }
            Style::Dashed => {
                chart
                    .draw_series(DashedLineSeries::new(s.data.iter().copied(), 6, 4, colour.stroke_width(1)))
                    .map_err(err(&p.title))?
                    .label(&s.label)
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], colour.stroke_width(1)));
            }
            Style::Points => {
                chart
                    .draw_series(s.data.iter().map(|&(x, y)| Circle::new((x, y), 3, colour.filled())))
                    .map_err(err(&p.title))?
                    .label(&s.label)
                    .legend(move |(x, y)| Circle::new((x + 9, y), 3, colour.filled()));
            }
        }
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperLeft)
        .label_font(("sans-serif", 11))
        .border_style(BLACK.mix(0.3))
        .background_style(WHITE.mix(0.85))
        .draw()
        .map_err(err(&p.title))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::tick_label;

    #[test]
    fn tick_labels_read_as_people_write_numbers() {
        let cases = [
            (0.0, "0"),
            (1e-15, "0"),
            (0.6, "0.6"),
            (2.5, "2.5"),
            (5.0, "5"),
            (14.0, "14"),
            (-0.125, "-0.125"),
            (0.0005, "5e-4"),
            (15000.0, "1.5e4"),
            (0.1 + 0.2, "0.3"),
        ];
        for (v, want) in cases {
            assert_eq!(tick_label(v), want, "{v}");
        }
    }
}
