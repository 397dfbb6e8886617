//! `needle plot`: the figures of a set as SVG ([`figures`] says which, [`panel`] draws
//! them). Rendering is deterministic, so committed figures can be checked for staleness
//! by rendering again and comparing bytes.
#![forbid(unsafe_code)]

pub mod family;
pub mod figures;
pub mod panel;

use anyhow::{Context, Result};
use needle_fit::{model_file, MODEL_FILE};
use needle_set::set_folder::SetFolder;

/// Width and height of one panel, pixels.
pub const PANEL_PX: (u32, u32) = (520, 360);

/// Render every figure of the set `set`: (file name, SVG text).
///
/// # Errors
/// model.toml or the set's runs cannot be read; a chart cannot be laid out.
pub fn render_set(set: &SetFolder) -> Result<Vec<(&'static str, String)>> {
    let model = model_file::read(&set.file(MODEL_FILE))?;
    let mut out = Vec::new();
    for f in figures::figures(set, &model)?.into_iter().chain(family::figure(set)?) {
        let svg = panel::render(&f.caption, &f.panels, f.cols, PANEL_PX).with_context(|| f.file.to_string())?;
        out.push((f.file, svg));
    }
    Ok(out)
}

/// The family figure with `measured` curves placed among its members
/// ([`family::figure_with`]): (file name, SVG text), `None` when the set has no family
/// runs.
///
/// # Errors
/// The family's runs cannot be read; the chart cannot be laid out.
pub fn render_family_measured(set: &SetFolder, measured: &[family::MeasuredShape]) -> Result<Option<(&'static str, String)>> {
    let Some(f) = family::figure_with(set, measured)? else { return Ok(None) };
    let svg = panel::render(&f.caption, &f.panels, f.cols, PANEL_PX).with_context(|| f.file.to_string())?;
    Ok(Some((f.file, svg)))
}
