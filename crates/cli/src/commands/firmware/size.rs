//! `needle firmware size`: flash and RAM of the model per core and evaluator, with the goals.
use super::goals::{Goals, INSERTION_FLASH_BYTES};
use super::{banner, goal, FirmwareArgs};
use needle_firmware_host::{self as firmware, size};
use std::process::ExitCode;

/// `needle firmware size`.
pub fn run(a: &FirmwareArgs) -> anyhow::Result<ExitCode> {
    let set = firmware::fitted_set(&a.set())?;
    let cores = firmware::cores(&a.cores)?;
    let mut reports = Vec::new();
    for c in &cores {
        reports.extend(size::run(c, &set)?);
    }
    let goals = Goals::of(&set)?;
    banner("needle firmware size", &set)?;
    println!("model form: {} (its goals below)", goals.form);
    println!(
        "release profile; f32: `no_panic` example ELF, fixed: `no_panic_fixed`, insertion: `no_panic_insertion` (model, depth extension, insertion, stacks, loop), fixed-insertion: `no_panic_fixed_insertion`, built without optional features; +qlv: the same with the `viscoelastic` feature; text/data/bss from size -B, tables = .rodata, symbols from nm -S -C\n"
    );
    print!("{}", size::table(&reports));
    println!();
    for r in &reports {
        if let Some(elastic) = r.evaluator.strip_suffix("+qlv") {
            let base = reports.iter().find(|b| b.core.core == r.core.core && b.evaluator == elastic);
            let extra = base.map_or_else(|| "?".to_string(), |b| size::bytes(r.model_flash().saturating_sub(b.model_flash())));
            println!(
                "{} {}: model flash {} (the viscoelastic filter: {extra} over `{elastic}`; no flash goal); static RAM {} B == 0: {}",
                r.core.core,
                r.evaluator,
                size::bytes(r.model_flash()),
                r.static_ram(),
                goal(r.static_ram() == 0)
            );
            continue;
        }
        let limit = if r.evaluator.ends_with("insertion") { INSERTION_FLASH_BYTES } else { goals.model_flash_bytes };
        println!(
            "goals {} {}: model flash {} <= {} KiB: {}; static RAM {} B == 0: {}",
            r.core.core,
            r.evaluator,
            size::bytes(r.model_flash()),
            limit / 1024,
            goal(r.model_flash() <= limit),
            r.static_ram(),
            goal(r.static_ram() == 0)
        );
    }
    Ok(ExitCode::SUCCESS)
}
