//! `needle calibrate-published`: the stack of a published piecewise force-depth model
//! ([`published`] has the rules), written in the tissue format, run
//! through the library's insertion model along the published curve and compared with it
//! like a calibration.
use crate::ramp::RampResponse;
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
    /// `source`): where the values come from and the measured values beside them; and,
    /// optionally, a layer's published relaxation function (`prony_g_instantaneous`,
    /// `prony_tau_s`, `prony_source`: [`Cited`]).
    pub layer_sources: &'a Path,
    /// The stack's name (the tissue file's stem).
    pub name: String,
    /// One line saying what the stack is.
    pub description: String,
    /// Diameter of the stack's needle, mm.
    pub needle_diameter_mm: f64,
    /// Speed of the replay along the published curve, mm/s (the published model has none),
    /// and with `with_prony` the speed at which a layer with Prony terms is fitted to it
    /// (`crate::ramp`).
    pub replay_speed_mm_per_s: f64,
    /// Write the layers' published Prony terms into the stack (fitted at the replay speed);
    /// without, a layer's terms are named in its `prony_source` only ([`NOT_COMPILED_IN`])
    /// and the stack is elastic (as the firmware's build without the `viscoelastic`
    /// feature requires of a compiled-in stack: docs/firmware.md, "Features").
    pub with_prony: bool,
    /// The FE tissue's initial shear modulus `mu0`, N/mm², for the track stiffness.
    pub fe_shear_modulus_n_per_mm2: f64,
}

/// The cheap checks of `opts`, before any file is read: every number within its range
/// of [`crate::limits`] (the unit in the message).
///
/// # Errors
/// A value outside its range.
pub fn check_model_options(opts: &ModelOptions<'_>) -> Result<()> {
    use crate::limits::{check_range, NEEDLE_DIAMETER_MM, SPEED_MM_PER_S};
    check_range("--needle-diameter-mm", opts.needle_diameter_mm, &NEEDLE_DIAMETER_MM, "mm", "the needles there are")?;
    check_range("--replay-speed-mm-per-s", opts.replay_speed_mm_per_s, &SPEED_MM_PER_S, "mm/s", "a slow robot to a fast hand")?;
    let v = opts.fe_shear_modulus_n_per_mm2;
    if !(v.is_finite() && v > 0.0) {
        bail!("FE shear modulus {v} N/mm^2: must be finite and > 0");
    }
    Ok(())
}

/// Derives the stack of `opts` and replays it along the sampled published curve (the
/// [`Calibration`]'s `points`).
///
/// # Errors
/// A file cannot be read or a row is refused (with its line), a layer has no citation,
/// the stack has more layers than the format allows, a value is out of range, or the
/// library has no fitted model.
pub fn calibrate_published(opts: &ModelOptions<'_>) -> Result<Calibration> {
    check_model_options(opts)?;
    if !needle_haptics::model_info::FITTED {
        bail!("the library was built without a fitted model: run `needle fit` first");
    }
    let pieces = published::read_pieces(opts.pieces)?;
    let sources = read_sources(opts.layer_sources)?;
    let similarity = opts.needle_diameter_mm / f64::from(insertion::FE_NEEDLE_DIAMETER_MM);
    let elastic = |depth_mm: f64| f64::from(insertion::deflection(&Pose::default(), depth_mm as f32, 1.0, similarity as f32).wrench.fy_n);
    // a layer with Prony terms against its response at the replay speed (`crate::ramp`)
    let total_mm = total_thickness_mm(opts, &pieces)?;
    let period_s = f64::from(insertion::InsertionConfig::DEFAULT_1KHZ.period_s);
    crate::limits::check_replay(total_mm, opts.replay_speed_mm_per_s, period_s, "--replay-speed-mm-per-s")?;
    let responses: Vec<(String, RampResponse)> = sources
        .iter()
        .filter(|c| opts.with_prony && !c.prony.is_empty())
        .map(|c| Ok((c.layer.clone(), RampResponse::new(&elastic, &c.prony, opts.replay_speed_mm_per_s, total_mm)?)))
        .collect::<Result<_>>()?;
    let surrogate = |layer: &str, depth_mm: f64| match responses.iter().find(|(name, _)| name == layer) {
        Some((_, r)) => r.at(depth_mm),
        None => elastic(depth_mm),
    };
    let derived = published::derive(&pieces, &surrogate)?;
    if derived.len() > file::MAX_LAYERS {
        bail!("{}: {} layers; a stack has at most {}", opts.pieces.display(), derived.len(), file::MAX_LAYERS);
    }
    let mut layers = Vec::with_capacity(derived.len());
    for d in &derived {
        let cited =
            sources.iter().find(|c| c.layer == d.name).cloned().with_context(|| {
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
            source: cited.source,
            prony: if opts.with_prony { cited.prony.clone() } else { Vec::new() },
            prony_source: match cited.prony_source {
                Some(s) if !opts.with_prony && !cited.prony.is_empty() => Some(format!("{NOT_COMPILED_IN} {s}")),
                other => other,
            },
            family_weight: 1.0,
            family_weight_range: None,
            softening_fraction: 0.0,
            softening_onset_ratio: 0.0,
            softening_fraction_range: None,
            presliding_mm: None,
            relaxation_slip_mm: None,
            tent_n_per_mm: None,
            shaft_prony: Vec::new(),
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

/// The layers' total thickness, mm.
///
/// # Errors
/// NaN, or more than [`crate::limits::MAX_SPAN_MM`] (no needle insertion is this long).
fn total_thickness_mm(opts: &ModelOptions<'_>, pieces: &[published::Piece]) -> Result<f64> {
    let total_mm: f64 = pieces.iter().map(|p| p.thickness_mm).sum();
    if total_mm.is_nan() || total_mm > crate::limits::MAX_SPAN_MM {
        bail!(
            "{}: the layers are {total_mm} mm thick in all, more than {} mm: no needle insertion is this long (thickness_mm in micrometres?)",
            opts.pieces.display(),
            crate::limits::MAX_SPAN_MM
        );
    }
    Ok(total_mm)
}

/// The start of a layer's `prony_source` when its published terms are left out (without
/// `with_prony`).
pub const NOT_COMPILED_IN: &str = "Published terms not in this stack (elastic; `needle calibrate-published --with-prony` writes them, for a build with the `viscoelastic` feature):";

/// One row of a citations file (`layers.csv`).
#[derive(Debug, Clone, PartialEq)]
pub struct Cited {
    /// The layer's name.
    pub layer: String,
    /// Where its values come from.
    pub source: String,
    /// Its published relaxation function in the tissue files' long-term normalisation,
    /// converted from the columns `prony_g_instantaneous` (the weights `g'_i` normalised
    /// by the instantaneous response, as relaxation tests publish them: `G(t) / G_0 = 1 -
    /// sum g'_i (1 - exp(-t / tau_i))`; a one-term QLV fit's `G_inf` gives `g'_1 = 1 -
    /// G_inf`) and `prony_tau_s` (s), `;`-separated, by
    /// [`needle_contract::prony_long_term_from_instantaneous`]; empty: elastic.
    pub prony: Vec<file::PronyTerm>,
    /// Where the terms come from (`prony_source`; required with terms).
    pub prony_source: Option<String>,
}

/// The rows of a citations file: `layer`, `source`, and the optional columns of
/// [`Cited`].
///
/// # Errors
/// The file cannot be read, a column is missing, a row has no layer or source, or its
/// Prony columns are refused (`file:line: column ...`).
fn read_sources(path: &Path) -> Result<Vec<Cited>> {
    let mut reader =
        csv::ReaderBuilder::new().trim(csv::Trim::All).from_path(path).with_context(|| format!("{}: cannot read", path.display()))?;
    let header = reader.headers().with_context(|| format!("{}:1: cannot read the header", path.display()))?.clone();
    let column = |name: &str| header.iter().position(|h| h == name).with_context(|| format!("{}:1: no column {name:?}", path.display()));
    let optional = |name: &str| header.iter().position(|h| h == name);
    let (il, is) = (column("layer")?, column("source")?);
    let (ig, it, ip) = (optional("prony_g_instantaneous"), optional("prony_tau_s"), optional("prony_source"));
    let mut rows = Vec::new();
    for record in reader.records() {
        let record = record.with_context(|| format!("{}: malformed CSV", path.display()))?;
        let line = record.position().map_or(0, |p| p.line());
        let get = |i: Option<usize>| i.and_then(|i| record.get(i)).unwrap_or("");
        let (layer, source) = (get(Some(il)), get(Some(is)));
        if layer.is_empty() || source.is_empty() {
            bail!("{}:{line}: a row needs a layer and its source", path.display());
        }
        let at = format!("{}:{line}", path.display());
        let prony = prony_terms(&at, get(ig), get(it))?;
        let prony_source = Some(get(ip).to_string()).filter(|s| !s.is_empty());
        if !prony.is_empty() && prony_source.is_none() {
            bail!("{at}: column prony_source: the layer's Prony terms need the published measurement they come from");
        }
        rows.push(Cited { layer: layer.to_string(), source: source.to_string(), prony, prony_source });
    }
    Ok(rows)
}

/// The long-term-normalised terms of one row's `prony_g_instantaneous` and `prony_tau_s`
/// (`at`: `file:line`).
fn prony_terms(at: &str, weights: &str, taus: &str) -> Result<Vec<file::PronyTerm>> {
    let numbers = |column: &str, text: &str| -> Result<Vec<f64>> {
        text.split(';')
            .map(str::trim)
            .filter(|t| !t.is_empty())
            .map(|t| t.parse::<f64>().map_err(|_| anyhow::anyhow!("{at}: column {column}: {t:?} is not a number")))
            .collect()
    };
    let (g, tau) = (numbers("prony_g_instantaneous", weights)?, numbers("prony_tau_s", taus)?);
    if g.len() != tau.len() {
        bail!("{at}: columns prony_g_instantaneous and prony_tau_s: {} weights, {} time constants", g.len(), tau.len());
    }
    if let Some(t) = tau.iter().find(|t| !(t.is_finite() && **t > 0.0)) {
        bail!("{at}: column prony_tau_s: {t} s: must be finite and > 0");
    }
    if g.len() > file::MAX_PRONY_TERMS {
        bail!("{at}: column prony_g_instantaneous: {} terms; a layer has at most {}", g.len(), file::MAX_PRONY_TERMS);
    }
    // unused slots weigh 0: they add nothing to the sum and convert to 0
    let mut padded = [0.0; file::MAX_PRONY_TERMS];
    padded.iter_mut().zip(&g).for_each(|(p, w)| *p = *w);
    let long_term = needle_contract::prony_long_term_from_instantaneous(padded).with_context(|| {
        format!("{at}: column prony_g_instantaneous: {weights:?}: each weight must be finite and >= 0, their sum below 1")
    })?;
    Ok(long_term.into_iter().zip(tau).map(|(g, tau_s)| file::PronyTerm { g, tau_s }).collect())
}
