//! `needle firmware golden`: the golden vectors on each core under QEMU, bit for bit.
use super::FirmwareArgs;
use needle_firmware_host::{self as firmware, golden};
use std::process::ExitCode;

/// `needle firmware golden`: exit 1 when a bit differs.
pub fn run(a: &FirmwareArgs) -> anyhow::Result<ExitCode> {
    let set = firmware::fitted_set(&a.set())?;
    let cores = firmware::cores(&a.cores)?;
    let mut failed = false;
    for c in &cores {
        let run = golden::run(c, &set)?;
        let m = &run.comparison.mismatches;
        println!(
            "{} ({}, QEMU {}): {} of {} golden rows differ ({:.1} s)",
            c.core,
            c.target,
            c.machine,
            m.len(),
            run.comparison.rows,
            run.run_time.as_secs_f64()
        );
        for line in m.iter().take(10) {
            println!("  {line}");
        }
        let sections = [("fixed-point", &run.fixed), ("stiffness", &run.stiffness), ("fixed-point stiffness", &run.stiffness_fixed)];
        for (what, comparison) in sections {
            let ms = &comparison.mismatches;
            println!("{} ({}): {} of {} {what} golden rows differ", c.core, c.target, ms.len(), comparison.rows);
            for line in ms.iter().take(10) {
                println!("  {line}");
            }
            failed |= !ms.is_empty();
        }
        failed |= !m.is_empty();
    }
    Ok(if failed { ExitCode::from(1) } else { ExitCode::SUCCESS })
}
