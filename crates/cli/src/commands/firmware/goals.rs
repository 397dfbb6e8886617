//! The firmware goals `needle firmware size` and `bench` check: per model form, and of
//! the insertion and the viscoelastic filter.

/// Flash of the model with the whole insertion (issue 41): the `insertion` and
/// `fixed-insertion` rows (the elastic build: the viscoelastic filter is a feature).
pub const INSERTION_FLASH_BYTES: u64 = 24 * 1024;

/// Stack of one insertion step (issue 41), beside the evaluators' 512 B.
pub const INSERTION_STACK_BYTES: u64 = 1024;

/// Instructions of one fixed-point insertion step on the Cortex-M0 (issue 41).
pub const INSERTION_FIXED_M0_INSTRUCTIONS: f64 = 20_000.0;
/// Extra instructions of the viscoelastic filter per f32 insertion step on the
/// Cortex-M4F, three Prony terms on all six components (issue 39).
pub const QLV_M4F_EXTRA_INSTRUCTIONS: f64 = 120.0;

/// The firmware goals of a model form: f32 instructions per wrench on the M4F, fixed-point
/// instructions on the M0, model flash (paper form: issues 4 and 5; coupled form: issue 16).
pub struct Goals {
    pub form: &'static str,
    pub m4f_f32_instructions: f64,
    pub m0_fixed_instructions: f64,
    pub model_flash_bytes: u64,
}

impl Goals {
    /// The goals of the form of `set`'s model.toml.
    pub fn of(set: &std::path::Path) -> anyhow::Result<Goals> {
        let model = needle_fit::model_file::read(&set.join(needle_fit::MODEL_FILE))?;
        Ok(if model.cross.is_some() {
            Goals { form: "coupled", m4f_f32_instructions: 1500.0, m0_fixed_instructions: 15_000.0, model_flash_bytes: 16 * 1024 }
        } else {
            Goals { form: "paper", m4f_f32_instructions: 900.0, m0_fixed_instructions: 10_000.0, model_flash_bytes: 8 * 1024 }
        })
    }
}
