//! The material family's figure (`family.svg`, issue 64): the centre runs of `[family]`
//! (`fe/family/`: the paper's tissue and each member, a partial run with the must points
//! it reached), their force against depth, their local power-law exponent, and their
//! ratio to the paper's tissue with the fitted law `g(d, w)` of `family.toml` when there
//! is one ([`needle_fit::family`]); with measured curves (`needle plot --measured`,
//! [`figure_with`]), their pre-puncture local exponents among the members'
//! (`family-measured.svg`, issue 64 item 6).
use super::figures::Figure;
use super::panel::{Panel, Series, Style, COMPONENT_COLOURS};
use anyhow::Result;
use needle_fit::family::{fit, ratio, read_runs, FamilyFit, MemberRun};
use needle_set::set_folder::SetFolder;
use plotters::style::RGBColor;

/// One colour per member, in `family.weight`'s order (the reference is black): the
/// components' colours, then two more.
const PALETTE: [RGBColor; 8] = {
    let [a, b, c, d, e, f] = COMPONENT_COLOURS;
    [a, b, c, d, e, f, RGBColor(140, 86, 75), RGBColor(227, 119, 194)]
};
const BLACK: RGBColor = RGBColor(0, 0, 0);
/// The measured curves' colours (greys and browns: not a member's).
const MEASURED_GREYS: [RGBColor; 4] = [RGBColor(60, 60, 60), RGBColor(150, 150, 150), RGBColor(120, 80, 40), RGBColor(200, 160, 100)];

/// The family figure's file with measured curves placed among the members.
pub const MEASURED_FILE: &str = "family-measured.svg";

/// Depths below this are left out of the exponent and ratio panels: forces there are
/// below 1 % of the peak and their ratios are the solver's noise.
pub const MIN_DEPTH_MM: f64 = 0.5;

fn label(m: &MemberRun) -> String {
    let deepest = m.deepest_mm();
    let w = if m.weight >= 1.0 { "paper (w = 1)".to_string() } else { format!("w = {}", m.weight) };
    if m.complete {
        w
    } else {
        format!("{w}, partial to {deepest:.1} mm")
    }
}

/// `d ln F / d ln d` by central differences over the run's must points past [`MIN_DEPTH_MM`].
fn exponents(m: &MemberRun) -> Vec<(f64, f64)> {
    let pts: Vec<(f64, f64)> = m.fy.iter().copied().filter(|&(d, f)| d >= MIN_DEPTH_MM && f > 0.0).collect();
    pts.windows(3).map(|w| (w[1].0, (w[2].1.ln() - w[0].1.ln()) / (w[2].0.ln() - w[0].0.ln()))).collect()
}

/// A measured curve before its first puncture, to be placed among the members: its
/// label and its (depth from contact, axial force), carried to the FE needle by
/// geometric similarity (depth / λ; the force's scale does not change a shape).
#[derive(Debug, Clone)]
pub struct MeasuredShape {
    /// Legend text (the file's name).
    pub label: String,
    /// (depth from contact at the FE needle mm, force N), depth increasing.
    pub depth_force: Vec<(f64, f64)>,
}

/// Half width of the window of a measured curve's local exponent, as a factor on depth:
/// the slope of ln F against ln d over `d / WINDOW ..= d * WINDOW` (least squares), so
/// a measurement's noise does not make the exponent of neighbouring points.
pub const WINDOW: f64 = 1.25;

/// Fewest points of a window (fewer: no exponent there).
pub const WINDOW_POINTS: usize = 5;

/// The local power-law exponent `d ln F / d ln d` of a measured curve (`depth_force`),
/// at each of its depths past [`MIN_DEPTH_MM`]: the least-squares slope over
/// [`WINDOW`], points with a positive force only.
#[must_use]
pub fn measured_exponents(depth_force: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let logs: Vec<(f64, f64)> = depth_force.iter().filter(|&&(d, f)| d > 0.0 && f > 0.0).map(|&(d, f)| (d.ln(), f.ln())).collect();
    let half = WINDOW.ln();
    let (Some(first), Some(last)) = (logs.first(), logs.last()) else { return Vec::new() };
    let (lo, hi) = (MIN_DEPTH_MM.ln().max(first.0 + half), last.0 - half);
    logs.iter()
        .filter(|p| p.0 >= lo && p.0 <= hi)
        .filter_map(|&(x0, _)| {
            let w: Vec<&(f64, f64)> = logs.iter().filter(|p| (p.0 - x0).abs() <= half).collect();
            let n = w.len() as f64;
            if w.len() < WINDOW_POINTS {
                return None;
            }
            let (mx, my) = (w.iter().map(|p| p.0).sum::<f64>() / n, w.iter().map(|p| p.1).sum::<f64>() / n);
            let sxx: f64 = w.iter().map(|p| (p.0 - mx).powi(2)).sum();
            let sxy: f64 = w.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
            (sxx > 0.0).then(|| (x0.exp(), sxy / sxx))
        })
        .collect()
}

/// The measured curves' shapes among the members: the local exponent of each complete
/// member's FE run and of each measured curve, by the same windowed least squares
/// ([`measured_exponents`]), the measured ones only where the force is at least
/// [`MEASURED_MIN_FRACTION`] of the curve's largest (below, the tare's noise is the
/// exponent).
fn shapes(runs: &[(&MemberRun, RGBColor)], measured: &[MeasuredShape]) -> Panel {
    let mut series: Vec<Series> = runs
        .iter()
        .filter(|(m, _)| m.complete)
        .map(|(m, c)| Series { label: format!("{} (FE)", label(m)), colour: *c, style: Style::Line, data: measured_exponents(&m.fy) })
        .collect();
    for (k, m) in measured.iter().enumerate() {
        let largest = m.depth_force.iter().map(|p| p.1).fold(0.0, f64::max);
        let kept: Vec<(f64, f64)> = m.depth_force.iter().copied().filter(|p| p.1 >= MEASURED_MIN_FRACTION * largest).collect();
        let colour = MEASURED_GREYS[k % MEASURED_GREYS.len()];
        series.push(Series { label: format!("measured: {}", m.label), colour, style: Style::Points, data: measured_exponents(&kept) });
    }
    Panel {
        title: "shapes: local exponent d ln F / d ln d, members and measured".into(),
        x_label: "depth at the FE needle (mm): measured depth / similarity".into(),
        y_label: "exponent (1)".into(),
        series,
        y_min_span: 0.5,
    }
}

/// The smallest force of a measured curve that enters its exponent, as a fraction of its
/// largest before the puncture.
pub const MEASURED_MIN_FRACTION: f64 = 0.05;

/// The family's figure, `None` when the set has no reference run yet.
///
/// # Errors
/// The family's runs cannot be read ([`read_runs`], [`fit`]).
pub fn figure(set: &SetFolder) -> Result<Option<Figure>> {
    figure_with(set, &[])
}

/// [`figure`] with the measured curves `measured` placed among the members: a fourth
/// panel of local exponents, the members' and the measured curves' by the same
/// estimator ([`measured_exponents`]); the file is then `family-measured.svg` (the set's
/// `family.svg` stays the FE's alone).
///
/// # Errors
/// As [`figure`].
pub fn figure_with(set: &SetFolder, measured: &[MeasuredShape]) -> Result<Option<Figure>> {
    let Some((reference, members)) = read_runs(set)? else { return Ok(None) };
    let law = match fit(set)? {
        FamilyFit::Law(law) => Some(law),
        _ => None,
    };
    let runs: Vec<(&MemberRun, RGBColor)> =
        std::iter::once((&reference, BLACK)).chain(members.iter().zip(PALETTE.iter().cycle().copied())).collect();
    let line = |m: &MemberRun, colour, data| Series { label: label(m), colour, style: Style::Line, data };
    let force = Panel {
        title: "Fy against depth, centred vertical needle (FE, full model)".into(),
        x_label: "depth (mm)".into(),
        y_label: "fy_n (N)".into(),
        series: runs.iter().map(|(m, c)| line(m, *c, m.fy.clone())).collect(),
        y_min_span: 0.0,
    };
    let exponent = Panel {
        title: "local power-law exponent d ln Fy / d ln d".into(),
        x_label: "depth (mm)".into(),
        y_label: "exponent (1)".into(),
        series: runs.iter().map(|(m, c)| line(m, *c, exponents(m))).collect(),
        y_min_span: 0.5,
    };
    let mut ratio_series = Vec::new();
    for (m, c) in runs.iter().skip(1) {
        let fe: Vec<(f64, f64)> =
            m.fy.iter()
                .filter(|p| p.0 >= MIN_DEPTH_MM)
                .filter_map(|&(d, f)| reference.fy_at(d).filter(|&r| r > 0.0).map(|r| (d, f / r)))
                .collect();
        ratio_series.push(Series { label: format!("{} (FE)", label(m)), colour: *c, style: Style::Points, data: fe });
        if let Some(law) = &law {
            let data = (0..=100)
                .map(|i| MIN_DEPTH_MM + (law.depth_max_mm - MIN_DEPTH_MM) * f64::from(i) / 100.0)
                .map(|d| (d, ratio(&law.coeffs, law.depth_max_mm, d, m.weight)))
                .collect();
            ratio_series.push(Series { label: format!("w = {} (law)", m.weight), colour: *c, style: Style::Line, data });
        }
    }
    let ratio_panel = Panel {
        title: "ratio to the paper's tissue F_w / F_paper (points: FE; lines: family.toml's law)".into(),
        x_label: "depth (mm)".into(),
        y_label: "g (1)".into(),
        series: ratio_series,
        y_min_span: 0.2,
    };
    let mut panels = vec![force, exponent, ratio_panel];
    if !measured.is_empty() {
        panels.push(shapes(&runs, measured));
    }
    let name = &set.campaign().set.name;
    Ok(Some(Figure {
        file: if measured.is_empty() { "family.svg" } else { MEASURED_FILE },
        caption: if measured.is_empty() {
            format!("Set {name}: the material family (campaign.toml [family], fe/family/)")
        } else {
            format!("Set {name}: the material family and measured shapes among its members")
        },
        // four panels in two rows of two, three in one row
        cols: if panels.len() == 4 { 2 } else { 3 },
        panels,
    }))
}

#[cfg(test)]
mod tests {
    use super::{measured_exponents, MIN_DEPTH_MM, WINDOW};

    /// A power law's local exponent is its exponent at every depth the window fits in
    /// (and nowhere nearer the ends).
    #[test]
    fn a_power_law_s_exponent_is_its_power() {
        for k in [1.4, 2.0, 2.6] {
            let curve: Vec<(f64, f64)> = (1..=200).map(|i| f64::from(i) * 0.05).map(|d| (d, 0.3 * d.powf(k))).collect();
            let e = measured_exponents(&curve);
            assert!(!e.is_empty(), "{k}");
            for (d, x) in &e {
                assert!((x - k).abs() < 1e-9, "exponent {x} at {d} mm for d^{k}");
                assert!(*d >= MIN_DEPTH_MM && *d <= 10.0 / WINDOW + 1e-12, "{d} mm");
            }
        }
    }
}
