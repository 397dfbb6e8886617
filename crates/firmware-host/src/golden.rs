//! The `golden` firmware's output against the set's `golden-f32.csv`, bit for bit.
//!
//! The firmware holds the golden file's *inputs* only (parsed at compile time) and prints
//! every row in the golden file's format with its own status and wrench bits; here each
//! printed row is compared with the file: inputs and status exactly, each wrench
//! component by its bits (so `+0.0` and `-0.0` differ), except that a NaN matches any
//! NaN (the contract fixes NaN by class, not payload).
use super::{build, qemu, Core};
use anyhow::{bail, Context};
use std::path::Path;
use std::time::Duration;

/// The golden file's header line (the fitter's, from the contract's columns).
pub use needle_fit::golden::float32::header;

use needle_contract::GOLDEN_COLUMNS as COLUMNS;

pub use super::comparison::{same_f32, Comparison};

fn bits(field: &str) -> Option<u32> {
    needle_codegen::parse_bits(field)
}

/// Compares the `golden` firmware's stdout `output` with the golden file's text `csv`
/// of the set whose `model.toml` has `fe_sha256`.
///
/// # Errors
/// The output is not a complete run of the golden firmware for that set (wrong set
/// compiled in, truncated output, malformed lines); differing values are not errors but
/// [`Comparison::mismatches`].
pub fn compare(output: &str, csv: &str, fe_sha256: &str) -> anyhow::Result<Comparison> {
    let mut want = csv.lines();
    let header = header();
    if want.next() != Some(header.as_str()) {
        bail!("golden-f32.csv: the first line is not the header {header:?}");
    }
    let want: Vec<&str> = want.collect();
    let mut got = output.lines();
    let banner = got.next().unwrap_or_default().to_string();
    if !banner.starts_with("needle-golden ") {
        bail!("the firmware did not start the golden run; its output begins with {banner:?}");
    }
    if !banner.split(' ').any(|w| w == format!("fe_sha256={fe_sha256}")) {
        bail!(
            "the firmware was built from another set than the golden file's (its banner: {banner:?}; \
             the golden file's model.toml has fe_sha256={fe_sha256})"
        );
    }
    if !banner.split(' ').any(|w| w == format!("rows={}", want.len())) {
        bail!("the firmware holds another number of poses than the golden file's {} (banner {banner:?})", want.len());
    }
    if got.next() != Some(header.as_str()) {
        bail!("the firmware's second line is not the golden header");
    }
    let mut mismatches = Vec::new();
    for (i, w) in want.iter().enumerate() {
        let line = i + 2;
        let Some(g) = got.next() else {
            bail!("the firmware's output stops before golden line {line} (of {})", want.len() + 1);
        };
        let wf: Vec<&str> = w.split(',').collect();
        let gf: Vec<&str> = g.split(',').collect();
        if wf.len() != 12 {
            bail!("golden-f32.csv:{line}: {} fields, expected 12", wf.len());
        }
        if gf.len() != 12 {
            bail!("firmware row for golden line {line}: {} fields, expected 12: {g:?}", gf.len());
        }
        if wf[..5] != gf[..5] {
            bail!("firmware row for golden line {line} has other inputs: {g:?} (golden {w:?}): the pose table is wrong");
        }
        let mut diffs = Vec::new();
        if wf[5] != gf[5] {
            diffs.push(format!("status want {} got {}", wf[5], gf[5]));
        }
        for c in 6..12 {
            let (Some(a), Some(b)) = (bits(wf[c]), bits(gf[c])) else {
                bail!("golden line {line}, {}: {:?} / firmware {:?} is not 0x and 8 hex digits", COLUMNS[c], wf[c], gf[c]);
            };
            if !same_f32(a, b) {
                diffs.push(format!("{} want {} ({:e}) got {} ({:e})", COLUMNS[c], wf[c], f32::from_bits(a), gf[c], f32::from_bits(b)));
            }
        }
        if !diffs.is_empty() {
            mismatches.push(format!("line {line} (pose {}): {}", wf[..5].join(","), diffs.join("; ")));
        }
    }
    let end = got.next().unwrap_or_default();
    if end != format!("needle-golden end rows={}", want.len()) {
        bail!("the firmware's output does not end with the end line after {} rows: {end:?}", want.len());
    }
    Ok(Comparison { banner, rows: want.len(), mismatches })
}

/// One core's golden run.
#[derive(Debug)]
pub struct CoreRun {
    /// The core.
    pub core: Core,
    /// The comparison with the golden file.
    pub comparison: Comparison,
    /// The comparison of the fixed-point section with golden-fixed.csv.
    pub fixed: Comparison,
    /// The comparison of the stiffness section with golden-stiffness-f32.csv.
    pub stiffness: Comparison,
    /// The comparison of the fixed-point stiffness section with golden-stiffness-fixed.csv.
    pub stiffness_fixed: Comparison,
    /// Wall-clock time of the QEMU run.
    pub run_time: Duration,
}

/// Builds the `golden` example of the fitted set `set` (absolute path) for `core`, runs
/// it under QEMU and compares its output with `set/golden-f32.csv`, its fixed-point
/// section with `set/golden-fixed.csv`, its stiffness sections with
/// `set/golden-stiffness-f32.csv` and `set/golden-stiffness-fixed.csv`.
///
/// # Errors
/// Build, QEMU run or output structure failed (see [`compare`]); mismatching values are
/// returned in the [`Comparison`].
pub fn run(core: &Core, set: &Path) -> anyhow::Result<CoreRun> {
    let golden = set.join("golden-f32.csv");
    let csv = std::fs::read_to_string(&golden).with_context(|| format!("cannot read {}", golden.display()))?;
    let golden_stiffness = set.join(needle_fit::GOLDEN_STIFFNESS_FILE);
    let csv_stiffness =
        std::fs::read_to_string(&golden_stiffness).with_context(|| format!("cannot read {}", golden_stiffness.display()))?;
    let golden_stiffness_fixed = set.join(needle_fit::GOLDEN_STIFFNESS_FIXED_FILE);
    let csv_stiffness_fixed =
        std::fs::read_to_string(&golden_stiffness_fixed).with_context(|| format!("cannot read {}", golden_stiffness_fixed.display()))?;
    let golden_fixed = set.join("golden-fixed.csv");
    let csv_fixed = std::fs::read_to_string(&golden_fixed).with_context(|| format!("cannot read {}", golden_fixed.display()))?;
    let model_path = set.join(needle_codegen::MODEL_FILE);
    let model = needle_codegen::parse_model(&model_path).map_err(anyhow::Error::new)?;
    let elf = build::build_examples(core, &["golden"], set)?.remove(0);
    let run = qemu::run(core, &elf, false, Duration::from_secs(600))?;
    if !run.status.success() {
        let tail: Vec<&str> = run.stdout.lines().rev().take(5).collect();
        bail!(
            "golden firmware on {} ({}) exited with {}; last lines:\n{}\nQEMU: {}",
            core.core,
            core.machine,
            run.status,
            tail.into_iter().rev().collect::<Vec<_>>().join("\n"),
            run.stderr.trim()
        );
    }
    let comparison =
        compare(&run.stdout, &csv, &model.fe_sha256).with_context(|| format!("golden firmware on {} ({})", core.core, core.machine))?;
    let fixed = super::golden_fixed::compare(&run.stdout, &csv_fixed)
        .with_context(|| format!("golden firmware on {} ({}), fixed point", core.core, core.machine))?;
    let stiffness = super::golden_stiffness::compare(&run.stdout, &csv_stiffness)
        .with_context(|| format!("golden firmware on {} ({}), stiffness", core.core, core.machine))?;
    let stiffness_fixed = super::golden_fixed::compare_stiffness(&run.stdout, &csv_stiffness_fixed)
        .with_context(|| format!("golden firmware on {} ({}), fixed-point stiffness", core.core, core.machine))?;
    Ok(CoreRun { core: *core, comparison, fixed, stiffness, stiffness_fixed, run_time: run.elapsed })
}
