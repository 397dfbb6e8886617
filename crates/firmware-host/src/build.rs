//! Nested `cargo build`s of the library and its firmware examples for a core.
use super::Core;
use anyhow::{bail, Context};
pub use needle_stdx::cargo::{check_target, nested_cargo};
use needle_stdx::workspace_root;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The undefined symbol the `no_panic` example's panic handler calls.
pub const NO_PANIC_SYMBOL: &str = "needle_haptics_panic_path_not_optimised_away";

/// Target folder of the firmware builds: `firmware/` inside the workspace's target folder
/// ([`needle_stdx::cargo::target_dir`]).
#[must_use]
pub fn target_dir() -> PathBuf {
    needle_stdx::cargo::target_dir().join("firmware")
}

/// Folder of the release examples of `core` in [`target_dir`].
#[must_use]
pub fn examples_dir(core: &Core) -> PathBuf {
    target_dir().join(core.target).join("release").join("examples")
}

/// Runs a nested cargo build in the workspace root; on failure the error holds the end
/// of cargo's output.
///
/// # Errors
/// cargo cannot be started or exits with an error (`what` names the build).
pub fn run_cargo(cmd: Command, what: &str) -> anyhow::Result<()> {
    run_cargo_in(cmd, &workspace_root(), what).map(drop)
}

/// [`run_cargo`] in `dir` ([`needle_stdx::cargo::run_cargo_in`] with the hint of a
/// panic path left in the evaluator); returns cargo's stderr.
///
/// # Errors
/// As [`run_cargo`].
pub fn run_cargo_in(cmd: Command, dir: &Path, what: &str) -> anyhow::Result<String> {
    needle_stdx::cargo::run_cargo_in(cmd, dir, "firmware", what, &|stderr| {
        if stderr.contains(NO_PANIC_SYMBOL) {
            format!(
                "\nThe link failed on `{NO_PANIC_SYMBOL}`: a panic path (index, unwrap, overflow or \
                 division check) is left in the evaluator. Find it with arm-none-eabi-objdump -d on the \
                 golden example (whose panic handler is defined)."
            )
        } else {
            String::new()
        }
    })
}

/// The library features of a firmware example build.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Features {
    /// The product's: `viscoelastic` (the filter inside both insertions). Every
    /// check (no panic, goldens, bench) runs on this build.
    Viscoelastic,
    /// None of the optional features: the elastic insertions, the build the flash
    /// budget of the insertion holds for (issue 41). Its own target folder
    /// (`firmware-elastic/` beside [`target_dir`]), so the two builds do not replace
    /// each other's files.
    Elastic,
    /// `viscoelastic` and `tissue-shape` (a layer's material family member and its
    /// pre-puncture softening, issue 64): the shaped stacks compiled in. Its own target
    /// folder (`firmware-shape/`).
    Shape,
    /// `tissue-shape` alone: the elastic insertions with the shaped stacks (the flash
    /// budget's build with the feature). Its own target folder (`firmware-shape-elastic/`).
    ShapeElastic,
}

impl Features {
    /// The target folder of this build.
    #[must_use]
    pub fn target_dir(self) -> PathBuf {
        match self {
            Self::Viscoelastic => target_dir(),
            Self::Elastic => target_dir().with_file_name("firmware-elastic"),
            Self::Shape => target_dir().with_file_name("firmware-shape"),
            Self::ShapeElastic => target_dir().with_file_name("firmware-shape-elastic"),
        }
    }

    fn cargo_args(self) -> &'static [&'static str] {
        match self {
            Self::Viscoelastic => &["--features", "viscoelastic"],
            Self::Elastic => &[],
            Self::Shape => &["--features", "viscoelastic,tissue-shape"],
            Self::ShapeElastic => &["--features", "tissue-shape"],
        }
    }

    /// Whether this build has the `viscoelastic` feature.
    #[must_use]
    pub fn viscoelastic(self) -> bool {
        matches!(self, Self::Viscoelastic | Self::Shape)
    }

    /// Whether this build has the `tissue-shape` feature.
    #[must_use]
    pub fn tissue_shape(self) -> bool {
        matches!(self, Self::Shape | Self::ShapeElastic)
    }

    /// Whether this build compiles `stack` in (the generator's rule,
    /// `needle_codegen::tissue::render_rust_stacks`): a stack with a Prony term needs
    /// `viscoelastic`, one with a family member other than the paper's tissue or a
    /// softening needs `tissue-shape`. For a host that lists the stacks of a firmware
    /// build from its own `stacks::ALL` (the host crates turn both features on).
    #[must_use]
    #[allow(clippy::float_cmp)]
    pub fn compiles(self, stack: &needle_haptics::insertion::Stack<'_>) -> bool {
        let prony = stack.layers.iter().any(|l| !l.prony.is_empty());
        let shaped = stack.layers.iter().any(|l| l.family.weight() != 1.0 || l.softening.fraction != 0.0);
        (self.viscoelastic() || !prony) && (self.tissue_shape() || !shaped)
    }
}

/// Builds the firmware `examples` for `core` (release profile, [`Features::Viscoelastic`])
/// with the coefficient set `set`, and returns their ELF paths in order.
///
/// # Errors
/// The target is not installed, or the build fails (the error holds cargo's output).
pub fn build_examples(core: &Core, examples: &[&str], set: &Path) -> anyhow::Result<Vec<PathBuf>> {
    build_examples_with(core, examples, set, Features::Viscoelastic)
}

/// [`build_examples`] with the library's `features`.
///
/// # Errors
/// As [`build_examples`].
pub fn build_examples_with(core: &Core, examples: &[&str], set: &Path, features: Features) -> anyhow::Result<Vec<PathBuf>> {
    check_target(core.target)?;
    let mut cmd = nested_cargo();
    cmd.args(["build", "--release", "-p", "needle-haptics", "--target", core.target])
        .args(features.cargo_args())
        .arg("--target-dir")
        .arg(features.target_dir())
        .env("NEEDLE_COEFFS", set);
    for e in examples {
        cmd.args(["--example", e]);
    }
    run_cargo(cmd, &format!("examples {} for {} ({}, {features:?})", examples.join(", "), core.core, core.target))?;
    let dir = features.target_dir().join(core.target).join("release").join("examples");
    examples
        .iter()
        .map(|e| {
            let elf = dir.join(e);
            if elf.is_file() {
                Ok(elf)
            } else {
                bail!("{}: cargo built no such file", elf.display())
            }
        })
        .collect()
}

/// The features of the `needle-haptics` package (root Cargo.toml `[features]`), without
/// `default`, sorted.
///
/// # Errors
/// Cargo.toml cannot be read or parsed.
pub fn library_features() -> anyhow::Result<Vec<String>> {
    let path = workspace_root().join("Cargo.toml");
    let text = std::fs::read_to_string(&path).with_context(|| format!("cannot read {}", path.display()))?;
    let doc: toml::Table = toml::from_str(&text).with_context(|| format!("{}: not valid TOML", path.display()))?;
    let mut features: Vec<String> = doc
        .get("features")
        .and_then(toml::Value::as_table)
        .map(|t| t.keys().filter(|k| *k != "default").cloned().collect())
        .unwrap_or_default();
    features.sort();
    Ok(features)
}

/// Every subset of `features` (the empty one first), each in the given order.
#[must_use]
pub fn feature_combinations(features: &[String]) -> Vec<Vec<String>> {
    (0..1usize << features.len())
        .map(|mask| features.iter().enumerate().filter(|(i, _)| mask & (1 << i) != 0).map(|(_, f)| f.clone()).collect())
        .collect()
}

/// Builds the library alone for `core`'s target with exactly `features` (no default
/// features), release profile.
///
/// # Errors
/// The target is not installed, or the build fails.
pub fn build_library(core: &Core, features: &[String], set: &Path) -> anyhow::Result<()> {
    check_target(core.target)?;
    let mut cmd = nested_cargo();
    cmd.args(["build", "--release", "-p", "needle-haptics", "--lib", "--no-default-features", "--target", core.target])
        .arg("--target-dir")
        .arg(target_dir())
        .env("NEEDLE_COEFFS", set);
    if !features.is_empty() {
        cmd.args(["--features", &features.join(",")]);
    }
    let shown = if features.is_empty() { "no features".to_string() } else { format!("features {}", features.join(",")) };
    run_cargo(cmd, &format!("the library for {} with {shown}", core.target))
}
