//! `sample_stack`: `needle stack sample` from Python (issue 65 item 3): a tissue drawn
//! within the spread a stack was fitted with, by the same draw as the command
//! (`needle_calibrate::sample::sample_file`): the same files and seed give the same
//! tissue file, byte for byte.
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use std::path::PathBuf;

/// Draws a tissue within the spread of `stack` (a tissue file written by `needle
/// calibrate --trials`; `spread` default `<stem>.spread.csv` beside it) and returns the
/// drawn tissue file's text, named `name` (default: `out`'s stem, else
/// `<stack's stem>_seed<seed>`). With `out`, also writes it there (atomically: nothing
/// written on error; an existing file is replaced); load it with `Insertion(out)`.
/// Raises ValueError naming the file and line of a refused stack or spread.
#[pyfunction]
#[pyo3(signature = (stack, /, *, seed, name = None, spread = None, out = None))]
pub fn sample_stack(stack: PathBuf, seed: u64, name: Option<String>, spread: Option<PathBuf>, out: Option<PathBuf>) -> PyResult<String> {
    let name = name
        .or_else(|| out.as_ref().and_then(|o| o.file_stem()).map(|s| s.to_string_lossy().into_owned()))
        .unwrap_or_else(|| format!("{}_seed{seed}", stack.file_stem().map_or_else(String::new, |s| s.to_string_lossy().into_owned())));
    let d = needle_calibrate::sample::sample_file(&stack, spread.as_deref(), &name, seed)
        .map_err(|e| PyValueError::new_err(format!("{e:#}")))?;
    let text = d.to_toml(&stack);
    if let Some(out) = out {
        needle_stdx::fs::write_all_atomic(&[(out.as_path(), text.as_bytes())]).map_err(|e| PyValueError::new_err(format!("{e:#}")))?;
    }
    Ok(text)
}
