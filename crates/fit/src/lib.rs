//! The fitter: FE sweeps -> `model.toml` and the golden vectors (`golden-f32.csv`,
//! `golden-fixed.csv`, `golden-stiffness-f32.csv`, `golden-stiffness-fixed.csv`;
//! coeffs/README.md), and the
//! validation of a fitted model against the FE runs it was not fitted on.
//!
//! Pipeline: [`data::load_fit_data`] reads the centre and sweep runs, [`model::fit`] fits
//! the paper model by least squares ([`lsq`]) in normalised variables,
//! [`model_file::to_toml`] writes it, [`golden::float32::to_csv`] evaluates it with this
//! crate's own f32 implementation of the contract ([`eval::float32`]),
//! [`golden::fixed::to_csv`] with its own fixed-point implementation ([`fixed_formats`],
//! [`eval::fixed`]). [`validate`] compares the model ([`eval::float64`],
//! [`eval::float32`]) with the validation runs, and [`error_trend`] tells
//! whether its errors follow the tilt or the offset.
#![forbid(unsafe_code)]

pub mod contract;
pub mod coupled;
pub mod coupled_report;
pub mod cross_terms;
pub mod data;
pub mod depth_extension;
pub mod depth_floor;
pub mod error_trend;
pub mod eval;
pub mod family;
pub mod family_poses;
pub mod fixed_formats;
pub mod golden;
pub mod lsq;
pub mod model;
pub mod model_file;
pub mod model_file_error;
pub mod poly;
pub mod run_error;
pub mod unsolved;
pub mod validate;

use anyhow::Result;
use needle_set::set_folder::SetFolder;
use std::fmt::Write as _;

/// Name of the model file inside a set folder (the generator's, which reads it).
pub use needle_codegen::MODEL_FILE;
/// Name of the golden-vector file inside a set folder.
pub const GOLDEN_FILE: &str = "golden-f32.csv";
/// Name of the fixed-point golden-vector file inside a set folder.
pub const GOLDEN_FIXED_FILE: &str = "golden-fixed.csv";
/// Name of the stiffness golden-vector file inside a set folder.
pub const GOLDEN_STIFFNESS_FILE: &str = "golden-stiffness-f32.csv";
/// Name of the fixed-point stiffness golden-vector file inside a set folder.
pub const GOLDEN_STIFFNESS_FIXED_FILE: &str = "golden-stiffness-fixed.csv";

/// What `needle fit` produces for a set, in memory.
#[derive(Debug, Clone)]
pub struct FitOutput {
    /// The fitted model.
    pub model: model::Model,
    /// The text of `model.toml`.
    pub model_toml: String,
    /// The text of `golden-f32.csv`.
    pub golden_csv: String,
    /// The text of `golden-fixed.csv`.
    pub golden_fixed_csv: String,
    /// The text of `golden-stiffness-f32.csv`.
    pub golden_stiffness_csv: String,
    /// The text of `golden-stiffness-fixed.csv`.
    pub golden_stiffness_fixed_csv: String,
    /// The text of `depth-extension.toml`, when the set has a deep centre run.
    pub depth_extension_toml: Option<String>,
    /// The text of `family.toml`, when the family's law is fitted.
    pub family_toml: Option<String>,
    /// The extension's law against the set's other deep runs (none without the
    /// extension).
    pub depth_law: Vec<depth_extension::LawCheck>,
    /// The material family's law (`family.toml` when fitted).
    pub family: family::FamilyFit,
    /// The law at the family's check poses (empty without a fitted law).
    pub family_poses: family_poses::PoseChecks,
    /// The unsolved region, from the set's FE records.
    pub unsolved: unsolved::Region,
    /// The text of `unsolved.toml`.
    pub unsolved_toml: String,
}

impl FitOutput {
    /// Every file `needle fit` writes into the set folder (name, text), model first.
    pub fn files(&self) -> Vec<(&'static str, &str)> {
        let mut files = vec![
            (MODEL_FILE, self.model_toml.as_str()),
            (GOLDEN_FILE, &self.golden_csv),
            (GOLDEN_FIXED_FILE, &self.golden_fixed_csv),
            (GOLDEN_STIFFNESS_FILE, &self.golden_stiffness_csv),
            (GOLDEN_STIFFNESS_FIXED_FILE, &self.golden_stiffness_fixed_csv),
            (unsolved::FILE, &self.unsolved_toml),
        ];
        if let Some(text) = &self.depth_extension_toml {
            files.push((depth_extension::FILE, text));
        }
        if let Some(text) = &self.family_toml {
            files.push((family::FILE, text));
        }
        files
    }
}

/// Fit the opened set `set` and render its output files ([`FitOutput::files`]), without
/// writing anything.
///
/// # Errors
/// As [`data::load_fit_data`] (missing or malformed runs, bad spec) and [`model::fit`]
/// (rank-deficient fits); a model too large for the fixed-point evaluator.
pub fn fit_set(set: &SetFolder) -> Result<FitOutput> {
    let set_dir = set.dir();
    let data = data::load_fit_data(set)?;
    let mut model = model::fit(&data)?;
    if data.campaign.fit.form == needle_set::spec::ModelForm::Coupled {
        model = coupled::fit_coupled(&data, &model, data.campaign.needle.reference_from_tip_mm)?;
    }
    // replaced training runs (campaign.train_replaced) are not fitted either: named with
    // their replacement
    let mut left_out = data.campaign.campaign.fit_without.clone();
    left_out.extend(
        data.campaign
            .campaign
            .train_replaced
            .iter()
            .map(|r| format!("{} (replaced by {})", r.pose, data.campaign.replacement_of(&r.pose).unwrap_or_default())),
    );
    let model_toml = model_file::to_toml(&model, &left_out);
    let region = unsolved::region(set)?;
    let unsolved_toml = unsolved::to_toml(&model.set, &region);
    let tables = eval::float32::Tables32::from_model(&model).with_unsolved(region.entries());
    let golden_csv = golden::float32::to_csv(&tables);
    let golden_stiffness_csv = golden::stiffness_float32::to_csv(&tables);
    let fixed = fixed_formats::TablesFixed::from_model(&model)?.with_unsolved(region.entries());
    let golden_fixed_csv = golden::fixed::to_csv(&fixed)?;
    let golden_stiffness_fixed_csv = golden::stiffness_fixed::to_csv(&fixed)?;
    let extension = depth_extension::fit(set_dir)?;
    let depth_law = match &extension {
        Some(e) => depth_extension::law_checks(set, e)?,
        None => Vec::new(),
    };
    let depth_extension_toml = extension.as_ref().map(depth_extension::to_toml);
    let family = family::fit(set)?;
    let family_poses = match &family {
        family::FamilyFit::Law(law) => family_poses::checks(set, &model, &law.coeffs, law.depth_max_mm)?,
        _ => family_poses::PoseChecks::default(),
    };
    let family_toml = match &family {
        family::FamilyFit::Law(law) => Some(family::to_toml(law) + &family_poses::to_toml(&family_poses)),
        _ => None,
    };
    Ok(FitOutput {
        family,
        family_poses,
        family_toml,
        model,
        model_toml,
        golden_csv,
        golden_fixed_csv,
        golden_stiffness_csv,
        golden_stiffness_fixed_csv,
        depth_extension_toml,
        depth_law,
        unsolved: region,
        unsolved_toml,
    })
}

/// A plain-text table of the fit residuals (RMS and max, in N or N·mm).
pub fn summary(m: &model::Model) -> String {
    use contract::{unit, Sweep, COMPONENTS};
    let mut s = String::new();
    let _ = writeln!(s, "fit residuals (model - FE over the fitted runs and all depths)");
    let _ = writeln!(s, "{:<10} {:<8} {:>12} {:>12}  unit", "sweep", "comp", "rms", "max");
    for (c, b) in m.baseline.iter().enumerate() {
        let _ = writeln!(s, "{:<10} {:<8} {:>12.4e} {:>12.4e}  {}", "baseline", COMPONENTS[c], b.residual_rms, b.residual_max, unit(c));
    }
    for k in Sweep::ALL {
        for (c, d) in m.matrices[k.index()].iter().enumerate() {
            let _ = writeln!(s, "{:<10} {:<8} {:>12.4e} {:>12.4e}  {}", k.name(), COMPONENTS[c], d.residual_rms, d.residual_max, unit(c));
        }
    }
    s
}
