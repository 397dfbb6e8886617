//! The figure of `needle fe verify --qlv`: per pose and friction, the axial force Fy
//! against time of the FEBio ramp-and-hold runs (points: must points) and the library's
//! QLV filter on the elastic run (lines), one colour per speed; beside it the first
//! seconds (the ramps and the early hold).
use needle_contract::FY;
use needle_fe::visco::qlv::QlvCase;
use needle_plot::panel::{render, Panel, Series, Style, COMPONENT_COLOURS};

/// File name of the figure in `<set>/figures/`.
pub const FILE: &str = "qlv-ramp-hold.svg";

/// Filter samples per second of the drawn lines.
const LINE_SAMPLES_PER_S: f64 = 50.0;

/// Seconds shown by the zoomed panel.
const ZOOM_S: f64 = 8.0;

/// The SVG text of the figure for `cases` (grouped by pose, in order).
///
/// # Errors
/// The filter refuses a case's Prony series, or a chart cannot be laid out.
pub fn svg(cases: &[QlvCase]) -> anyhow::Result<String> {
    let mut groups: Vec<(&str, f64)> = Vec::new();
    for c in cases {
        if !groups.contains(&(c.pose.as_str(), c.friction)) {
            groups.push((&c.pose, c.friction));
        }
    }
    let mut panels = Vec::new();
    for (pose, friction) in groups {
        let mut full = Vec::new();
        let mut zoom = Vec::new();
        for (i, c) in cases.iter().filter(|c| c.pose == pose && c.friction == friction).enumerate() {
            let colour = COMPONENT_COLOURS[i % COMPONENT_COLOURS.len()];
            let speed = c.loading.ramp_hold.as_ref().map_or(0.0, |r| r.speed_mm_per_s);
            let times = c.times_s();
            let end = times.last().copied().unwrap_or(0.0);
            let n = (end * LINE_SAMPLES_PER_S).ceil() as usize;
            let grid: Vec<f64> = (0..=n).map(|k| end * k as f64 / n.max(1) as f64).collect();
            let line: Vec<(f64, f64)> = grid.iter().zip(super::filtered::filtered_at(c, &grid)?).map(|(t, w)| (*t, w[FY])).collect();
            let fe: Vec<(f64, f64)> = times.iter().zip(&c.fe).map(|(t, r)| (*t, r.fy_n())).collect();
            let within = |v: &[(f64, f64)]| v.iter().copied().filter(|(t, _)| *t <= ZOOM_S).collect::<Vec<_>>();
            for (set, l, f) in [(&mut full, line.clone(), fe.clone()), (&mut zoom, within(&line), within(&fe))] {
                set.push(Series { label: format!("{speed} mm/s filter"), colour, style: Style::Line, data: l });
                set.push(Series { label: format!("{speed} mm/s FEBio"), colour, style: Style::Points, data: f });
            }
        }
        let pose = format!("{pose}, friction {friction}");
        for (title, series) in [(format!("{pose}: ramp to 6 mm, 30 s hold"), full), (format!("{pose}: first {ZOOM_S} s"), zoom)] {
            panels.push(Panel { title, x_label: "time, s".into(), y_label: "Fy, N".into(), series, y_min_span: 0.0 });
        }
    }
    render("FEBio uncoupled viscoelastic (points) against the library's QLV filter on the elastic run (lines)", &panels, 2, (640, 400))
}
