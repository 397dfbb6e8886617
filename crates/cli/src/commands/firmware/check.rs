//! `needle firmware check`: the library built for each core with every feature
//! combination, and the no-panic proofs linked.
use super::FirmwareArgs;
use needle_firmware_host::{self as firmware, build, Core};
use std::process::ExitCode;

/// `needle firmware check`.
pub fn run(a: &FirmwareArgs) -> anyhow::Result<ExitCode> {
    let set = a.set();
    let cores: Vec<Core> = firmware::cores(&a.cores)?;
    let features = build::library_features()?;
    for c in &cores {
        for combo in build::feature_combinations(&features) {
            build::build_library(c, &combo, &set)?;
        }
        build::build_examples(c, &["no_panic", "no_panic_fixed"], &set)?;
        println!(
            "{} ({}): library builds with all {} feature combinations; no_panic and no_panic_fixed link",
            c.core,
            c.target,
            1usize << features.len()
        );
    }
    Ok(ExitCode::SUCCESS)
}
