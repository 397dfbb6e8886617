//! The check that a `--set DIR` is the coefficient set compiled into this build of the
//! library (`needle eval`, `needle fixed-error`, `needle calibrate`, `needle
//! calibrate-published`). The library has one coefficient set compiled in (chosen by
//! `NEEDLE_COEFFS` at build time).
use anyhow::bail;
use needle_haptics::model_info;
use std::path::Path;

/// Checks that the set folder `dir` is the one compiled into the library: same
/// `fe_sha256` and the same f32 coefficient bits as its `model.toml`, and the same
/// unsolved region (`unsolved.toml`, or none).
///
/// # Errors
/// The library has no fitted model, `dir` has no valid model.toml, or it is another set
/// (or another fit of the same FE data) than the one compiled in.
pub fn check_compiled_set(dir: &Path) -> anyhow::Result<()> {
    check_compiled_set_except(dir, None)
}

/// [`check_compiled_set`], and the set's tissue stacks (`tissue/*.toml`) are the
/// compiled-in ones, but for the stack `replaced` (the one `needle calibrate` writes;
/// it may differ from the compiled-in one, or be new).
///
/// # Errors
/// As [`check_compiled_set`]; a tissue file is refused by the format, differs from the
/// compiled-in stack of its name, is not compiled in, or a compiled-in stack has no file.
pub fn check_compiled_set_except(dir: &Path, replaced: Option<&str>) -> anyhow::Result<()> {
    let model_path = dir.join(needle_codegen::MODEL_FILE);
    let rebuild = format!(
        "rebuild with NEEDLE_COEFFS={} (e.g. `NEEDLE_COEFFS={} cargo build --release -p needle-cli`)",
        dir.display(),
        dir.display()
    );
    if !model_info::FITTED {
        bail!(
            "this build of needle-haptics has no fitted model: it was built from {}, which had no model.toml (run `needle fit --set {}`, then rebuild); {rebuild}",
            model_info::SET_DIR,
            model_info::SET_DIR
        );
    }
    if !model_path.is_file() {
        bail!("{}: no such file: --set names a coefficient set folder holding model.toml", model_path.display());
    }
    let model = needle_codegen::parse_model(&model_path).map_err(anyhow::Error::new)?;
    let built =
        format!("this build has set {:?} compiled in, from {} (fe_sha256 {})", model_info::SET, model_info::SET_DIR, model_info::FE_SHA256);
    if model.fe_sha256 != model_info::FE_SHA256 {
        bail!(
            "{} is fitted on other FE data (fe_sha256 {}) than the compiled-in model: {built}; {rebuild}",
            model_path.display(),
            model.fe_sha256
        );
    }
    let same_bits = |a: &[f32], b: &[f32]| a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits());
    let base_same = model.baseline_f32().iter().zip(model_info::BASELINE.iter()).all(|(a, b)| same_bits(a, b));
    let dev_same = model
        .deviation_f32()
        .iter()
        .flatten()
        .flatten()
        .zip(model_info::DEVIATION.iter().flatten().flatten())
        .all(|(a, b)| same_bits(a, b));
    if !(base_same && dev_same) {
        bail!("{} has other coefficients than the compiled-in model (same FE data, refitted?): {built}; {rebuild}", model_path.display());
    }
    // the unsolved region beside it (FE_UNSOLVED): the compiled-in one, or none for both
    let region_path = dir.join(needle_codegen::unsolved::FILE);
    let region = if region_path.is_file() {
        needle_codegen::unsolved::parse(&region_path).map_err(anyhow::Error::new)?
    } else {
        needle_codegen::unsolved::Region::default()
    };
    if needle_codegen::unsolved::render(&region) != model_info::UNSOLVED_RS {
        bail!(
            "{} is another unsolved region than the compiled-in one ({} balls compiled in; refitted after new FE records?): {built}; {rebuild}",
            region_path.display(),
            model_info::UNSOLVED_BALLS
        );
    }
    check_tissue(dir, replaced, &rebuild)
}

/// The tissue stacks of `dir` against the compiled-in ones (their generated source, stack
/// by stack), but for `replaced`.
fn check_tissue(dir: &Path, replaced: Option<&str>, rebuild: &str) -> anyhow::Result<()> {
    let tissue = dir.join(needle_codegen::tissue::TISSUE_DIR);
    let stacks = needle_codegen::tissue::read_stacks(dir)
        .map_err(|e| anyhow::anyhow!("{e}: a broken tissue file in the set (the build would refuse it); {rebuild}"))?;
    let needle = needle_codegen::tissue::read_fe_needle(dir).map_err(anyhow::Error::new)?;
    let in_files = stack_blocks(&needle_codegen::tissue::render_rust_stacks(&stacks, needle));
    let compiled = stack_blocks(model_info::TISSUE_RS);
    let skip = |name: &str| replaced.is_some_and(|r| r == name);
    for (name, block) in &in_files {
        if skip(name) {
            continue;
        }
        let file = tissue.join(format!("{name}.toml"));
        match compiled.iter().find(|(n, _)| n == name) {
            None => bail!(
                "{}: stack {name:?} is not compiled into this build (it has: {}); {rebuild}",
                file.display(),
                compiled.iter().map(|(n, _)| n.as_str()).collect::<Vec<_>>().join(", ")
            ),
            Some((_, built)) if built != block => bail!(
                "{}: other values than the compiled-in stack {name:?} (edited, or calibrated since the build?); {rebuild}",
                file.display()
            ),
            Some(_) => {}
        }
    }
    for (name, _) in &compiled {
        if !skip(name) && !in_files.iter().any(|(n, _)| n == name) {
            bail!(
                "{}: missing: stack {name:?} is compiled into this build from it; {rebuild}",
                tissue.join(format!("{name}.toml")).display()
            );
        }
    }
    Ok(())
}

/// The stacks of a generated `tissue_stacks.rs`: (name, its constant's text, from
/// `pub const NAME: Stack` to its closing `};`).
fn stack_blocks(text: &str) -> Vec<(String, String)> {
    const OPEN: &str = ": Stack<'static> = Stack {";
    let mut out = Vec::new();
    for (at, _) in text.match_indices(OPEN) {
        let start = text[..at].rfind("pub const ").unwrap_or(at);
        let tail = &text[start..];
        let block = tail.find("\n};").map_or(tail, |e| &tail[..e + 4]);
        // the stack's own name (the constant is its upper case)
        let name = block.split("name: \"").nth(1).and_then(|r| r.split('"').next()).unwrap_or_default();
        out.push((name.to_string(), block.to_string()));
    }
    out
}
