//! `/stacks.json` of the explorer: tissue files given on the command line (`needle
//! explore --stack FILE`) and tissues drawn within each one's spread, for the page's
//! insertion player (issue 65 item 3: a plausible tissue drawn in the explorer).
//!
//! Each stack is loaded and checked as every run-time stack is
//! ([`needle_calibrate::runtime_stack::OwnedStack::load`]: the format's messages,
//! `FILE:LINE`); its draws are `needle stack sample`'s
//! ([`needle_calibrate::sample::sample_file`], seeds 1 to `draws`: the same tissue as
//! `needle stack sample --seed K`). Layers go to the page as the module's words
//! ([`needle_wasm::layer_words`]), so the page plays the very layers the host's
//! insertion would.

use anyhow::{Context, Result};
use needle_calibrate::runtime_stack::OwnedStack;
use needle_calibrate::{sample, spread};
use serde_json::{json, Value};
use std::path::Path;

/// The layers of `s` as the module's words, and their thicknesses (mm).
fn layers(s: &OwnedStack) -> Value {
    json!({
        "needle_diameter_mm": s.needle_diameter_mm,
        "thickness_mm": s.layers.iter().map(|l| l.thickness_mm).collect::<Vec<_>>(),
        "words": s.layers.iter().map(|l| needle_wasm::layer_words::to_words(l).to_vec()).collect::<Vec<_>>(),
    })
}

/// One tissue file and, when its spread file lies beside it, `draws` tissues drawn
/// within the spread: name, file, layers (needle diameter, thicknesses and
/// each layer's wasm words), and per draw its seed, its layers
/// and each drawn value beside the stack's (layer, key, from, to, sd).
///
/// # Errors
/// The file is refused (`FILE:LINE`), its spread is refused, or a drawn stack is.
pub fn stack_json(path: &Path, draws: u64) -> Result<Value> {
    let stack = OwnedStack::load(path)?;
    let spread_path = spread::beside(path);
    let mut drawn = Vec::new();
    if spread_path.is_file() {
        for seed in 1..=draws {
            let d = sample::sample_file(path, Some(&spread_path), &stack.name, seed)?;
            let owned = OwnedStack::from_file(&d.drawn).with_context(|| format!("the tissue drawn with seed {seed}"))?;
            let values: Vec<Value> = d
                .rows
                .iter()
                .map(|r| json!({ "layer": r.layer, "key": r.key, "from": sample::value(&d.stack, r), "to": sample::value(&d.drawn, r), "sd": r.sd }))
                .collect();
            drawn.push(json!({ "seed": seed, "stack": layers(&owned), "values": values }));
        }
    }
    Ok(json!({
        "name": stack.name,
        "file": path.display().to_string(),
        "spread": spread_path.is_file().then(|| spread_path.display().to_string()),
        "stack": layers(&stack),
        "drawn": drawn,
    }))
}

/// `/stacks.json`: [`stack_json`] of each file, in order.
///
/// # Errors
/// As [`stack_json`], naming the option.
pub fn stacks_json(paths: &[impl AsRef<Path>], draws: u64) -> Result<Value> {
    let all: Result<Vec<Value>> =
        paths.iter().map(|p| stack_json(p.as_ref(), draws).with_context(|| format!("--stack {}", p.as_ref().display()))).collect();
    Ok(Value::Array(all?))
}
