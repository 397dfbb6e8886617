//! The material family's figure (`family.svg`, issue 64): the centre runs of `[family]`
//! (`fe/family/`: the paper's tissue and each member, a partial run with the must points
//! it reached), their force against depth, their local power-law exponent, and their
//! ratio to the paper's tissue with the fitted law `g(d, w)` of `family.toml` when there
//! is one ([`needle_fit::family`]).
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

/// Depths below this are left out of the exponent and ratio panels: forces there are
/// below 1 % of the peak and their ratios are the solver's noise.
const MIN_DEPTH_MM: f64 = 0.5;

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

/// The family's figure, `None` when the set has no reference run yet.
///
/// # Errors
/// The family's runs cannot be read ([`read_runs`], [`fit`]).
pub fn figure(set: &SetFolder) -> Result<Option<Figure>> {
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
    let name = &set.campaign().set.name;
    Ok(Some(Figure {
        file: "family.svg",
        caption: format!("Set {name}: the material family (campaign.toml [family], fe/family/)"),
        panels: vec![force, exponent, ratio_panel],
        cols: 3,
    }))
}
