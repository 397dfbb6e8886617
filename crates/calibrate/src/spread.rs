//! The spread of a calibrated stack's values over the trials it was fitted on (issue 65
//! item 3), machine-readable beside its tissue file: `<name>.spread.csv` next to
//! `<name>.toml` (written by `needle calibrate --trials`, read by `needle stack
//! sample`). Format (coeffs/README.md, "Spread over the trials"): a header
//! `layer,key,trials,mean,sd`, then one row per value fitted on each trial: the layer's
//! index in the stack (0 the surface's), the tissue file's key, how many trials, their
//! mean and sample standard deviation (in the key's unit).
use crate::whole::stats::Spread;
use anyhow::{bail, Context, Result};
use std::path::{Path, PathBuf};

/// The file's header line.
pub const HEADER: &str = "layer,key,trials,mean,sd";

/// The keys a spread may name: the values fitted per trial.
pub const KEYS: [&str; 4] = ["stiffness_scale", "puncture_force_n", "cutting_force_n", "friction_coulomb_n_per_mm"];

/// One row.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    /// The layer's index in the stack.
    pub layer: usize,
    /// The tissue file's key ([`KEYS`]).
    pub key: &'static str,
    /// Trials the value was fitted on.
    pub trials: usize,
    /// Their mean, in the key's unit.
    pub mean: f64,
    /// Their sample standard deviation (0 for one trial).
    pub sd: f64,
    /// The row's line in its file (1-based).
    pub line: usize,
}

/// The spread file beside the tissue file `stack` (`x.toml` -> `x.spread.csv`).
#[must_use]
pub fn beside(stack: &Path) -> PathBuf {
    let stem = stack.file_stem().map_or_else(String::new, |s| s.to_string_lossy().into_owned());
    stack.with_file_name(format!("{stem}.spread.csv"))
}

/// The file's text for `spread` (per layer, `(key, spread)`), rows in the layers' order.
#[must_use]
pub fn to_csv(spread: &[Vec<(&'static str, Spread)>]) -> String {
    let mut out = format!("{HEADER}\n");
    for (k, layer) in spread.iter().enumerate() {
        for (key, s) in layer {
            out.push_str(&format!("{k},{key},{},{:?},{:?}\n", s.values.len(), s.mean, s.sd));
        }
    }
    out
}

/// Reads a spread file.
///
/// # Errors
/// The file cannot be read, or [`parse`] refuses it (`FILE:LINE`).
pub fn read(path: &Path) -> Result<Vec<Row>> {
    let text = std::fs::read_to_string(path).with_context(|| format!("{}: cannot read the spread file", path.display()))?;
    parse(&text, path)
}

/// The rows of `text` (the file `path`, for messages).
///
/// # Errors
/// Another header, a row of another column count, a layer that is not an index, a key
/// not among [`KEYS`], a count below 1, a mean or sd not finite, a negative sd, a
/// (layer, key) given twice: `FILE:LINE: ...`, naming the column and the value.
pub fn parse(text: &str, path: &Path) -> Result<Vec<Row>> {
    let file = path.display();
    let mut lines = text.lines().enumerate().map(|(i, l)| (i + 1, l.trim_end_matches('\r')));
    match lines.next() {
        Some((_, h)) if h == HEADER => {}
        Some((n, h)) => bail!("{file}:{n}: header {h:?}: a spread file starts with {HEADER:?}"),
        None => bail!("{file}: empty: a spread file starts with {HEADER:?}"),
    }
    let mut rows: Vec<Row> = Vec::new();
    for (n, l) in lines.filter(|(_, l)| !l.trim().is_empty()) {
        let cols: Vec<&str> = l.split(',').map(str::trim).collect();
        let [layer, key, trials, mean, sd] = cols[..] else { bail!("{file}:{n}: {} columns: a row has 5 ({HEADER})", cols.len()) };
        let layer: usize = layer.parse().map_err(|_| anyhow::anyhow!("{file}:{n}: layer {layer:?}: not a layer index (0, 1, ...)"))?;
        let Some(key) = KEYS.iter().copied().find(|k| *k == key) else {
            bail!("{file}:{n}: key {key:?}: not one of the values fitted per trial ({})", KEYS.join(", "))
        };
        let trials: usize =
            trials.parse().ok().filter(|t| *t >= 1).ok_or_else(|| anyhow::anyhow!("{file}:{n}: trials {trials:?}: a count, at least 1"))?;
        let number = |name: &str, v: &str| -> Result<f64> {
            v.parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| anyhow::anyhow!("{file}:{n}: {name} {v:?}: not a finite number (the key's unit)"))
        };
        let (mean, sd) = (number("mean", mean)?, number("sd", sd)?);
        if sd < 0.0 {
            bail!("{file}:{n}: sd {sd}: a standard deviation is not negative");
        }
        if let Some(first) = rows.iter().find(|r| r.layer == layer && r.key == key) {
            bail!("{file}:{n}: layer {layer} {key}: given twice (first on line {})", first.line);
        }
        rows.push(Row { layer, key, trials, mean, sd, line: n });
    }
    Ok(rows)
}
