//! `needle calibrate-published`: the stack of a published piecewise force-depth model
//! ([`published`](crate::published) has the rules), written in the tissue format, run
//! through the library's insertion model along the published curve and compared with it
//! like a calibration.
use crate::{published, replay, to_layer, Calibration, STICK_BAND_MM_PER_S, WINKLER_E_PER_MU};
use anyhow::{bail, Context, Result};
use needle_codegen::tissue as file;
use needle_haptics::insertion;
use needle_haptics::Pose;
use std::path::Path;

/// What to derive.
#[derive(Debug, Clone)]
pub struct ModelOptions<'a> {
    /// The published pieces (`pieces.csv`).
    pub pieces: &'a Path,
    /// Per-layer citations written into each layer's `source` (`layers.csv`: `layer`,
    /// `source`): where the values come from and the measured values beside them.
    pub layer_sources: &'a Path,
    /// The stack's name (the tissue file's stem).
    pub name: String,
    /// One line saying what the stack is.
    pub description: String,
    /// Diameter of the stack's needle, mm.
    pub needle_diameter_mm: f64,
    /// Speed of the replay along the published curve, mm/s (the published model has none).
    pub replay_speed_mm_per_s: f64,
    /// The FE tissue's initial shear modulus `mu0`, N/mm², for the track stiffness.
    pub fe_shear_modulus_n_per_mm2: f64,
}

/// Derives the stack of `opts` and replays it along the sampled published curve (the
/// [`Calibration`]'s `points`).
///
/// # Errors
/// A file cannot be read or a row is refused (with its line), a layer has no citation,
/// the stack has more layers than the format allows, a value is out of range, or the
/// library has no fitted model.
pub fn calibrate_published(opts: &ModelOptions<'_>) -> Result<Calibration> {
    for (what, v) in [
        ("--needle-diameter-mm", opts.needle_diameter_mm),
        ("--replay-speed-mm-per-s", opts.replay_speed_mm_per_s),
        ("FE shear modulus", opts.fe_shear_modulus_n_per_mm2),
    ] {
        if !(v.is_finite() && v > 0.0) {
            bail!("{what} {v}: must be finite and > 0");
        }
    }
    if !needle_haptics::model_info::FITTED {
        bail!("the library was built without a fitted model: run `needle fit` first");
    }
    let pieces = published::read_pieces(opts.pieces)?;
    let sources = read_sources(opts.layer_sources)?;
    let similarity = opts.needle_diameter_mm / f64::from(insertion::FE_NEEDLE_DIAMETER_MM);
    let surrogate = |depth_mm: f64| f64::from(insertion::deflection(&Pose::default(), depth_mm as f32, 1.0, similarity as f32).wrench.fy_n);
    let derived = published::derive(&pieces, &surrogate)?;
    if derived.len() > file::MAX_LAYERS {
        bail!("{}: {} layers; a stack has at most {}", opts.pieces.display(), derived.len(), file::MAX_LAYERS);
    }
    let mut layers = Vec::with_capacity(derived.len());
    for d in &derived {
        let cited =
            sources.iter().find(|(layer, _)| *layer == d.name).map(|(_, s)| s.clone()).with_context(|| {
                format!("{}: no row for layer {:?}: every layer needs its citation", opts.layer_sources.display(), d.name)
            })?;
        let f = &d.fit;
        layers.push(file::Layer {
            name: d.name.clone(),
            thickness_mm: d.thickness_mm,
            stiffness_scale: f.scale,
            puncture_force_n: f.puncture_force_n,
            cutting_force_n: f.cutting_force_n,
            friction_static_n_per_mm: f.friction_n_per_mm,
            friction_coulomb_n_per_mm: f.friction_n_per_mm,
            friction_viscous_n_s_per_mm2: 0.0,
            stick_band_mm_per_s: STICK_BAND_MM_PER_S,
            track_stiffness_n_per_mm2: WINKLER_E_PER_MU * f.scale * opts.fe_shear_modulus_n_per_mm2,
            source: cited,
            prony: Vec::new(),
            prony_source: None,
        });
    }
    let stack = file::Stack {
        format: file::TISSUE_FORMAT,
        name: opts.name.clone(),
        description: opts.description.clone(),
        needle_diameter_mm: opts.needle_diameter_mm,
        layers,
    };
    let text = stack.to_toml("");
    file::parse_stack_str(&text, Path::new(&format!("{}.toml", stack.name)))
        .map_err(|e| anyhow::anyhow!("the derived stack is refused by the tissue format: {e}"))?;
    let points = published::sample(&pieces);
    let events = published::events(&points, &derived);
    let lib_layers: Vec<insertion::Layer> = stack.layers.iter().map(to_layer).collect();
    let lib_stack = insertion::Stack { name: &stack.name, needle_diameter_mm: opts.needle_diameter_mm as f32, layers: &lib_layers };
    let end = points.last().map_or(0.0, |p| p.position_mm);
    let replay = replay::replay(&lib_stack, 0.0, 0.0, end, opts.replay_speed_mm_per_s);
    let checks = replay::checks(&points, &events, &replay);
    Ok(Calibration { points, events, fit: published::as_fit(&derived), stack, replay, checks, similarity })
}

/// `(layer, source)` rows of a citations file.
fn read_sources(path: &Path) -> Result<Vec<(String, String)>> {
    let mut reader =
        csv::ReaderBuilder::new().trim(csv::Trim::All).from_path(path).with_context(|| format!("{}: cannot read", path.display()))?;
    let header = reader.headers().with_context(|| format!("{}:1: cannot read the header", path.display()))?.clone();
    let column = |name: &str| header.iter().position(|h| h == name).with_context(|| format!("{}:1: no column {name:?}", path.display()));
    let (il, is) = (column("layer")?, column("source")?);
    let mut rows = Vec::new();
    for record in reader.records() {
        let record = record.with_context(|| format!("{}: malformed CSV", path.display()))?;
        let line = record.position().map_or(0, |p| p.line());
        let (layer, source) = (record.get(il).unwrap_or(""), record.get(is).unwrap_or(""));
        if layer.is_empty() || source.is_empty() {
            bail!("{}:{line}: a row needs a layer and its source", path.display());
        }
        rows.push((layer.to_string(), source.to_string()));
    }
    Ok(rows)
}
