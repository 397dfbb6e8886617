//! The real-board example (examples/nucleo-f401re: NUCLEO-F401RE, stm32f4xx-hal, RTIC 2,
//! defmt over RTT, probe-rs runner) builds for thumbv7em-none-eabihf with no warning
//! and fits the STM32F401RE (512 KiB flash, 96 KiB RAM); its flash and RAM are printed.
//! It needs the board to run, so CI builds it only.
use needle_firmware_host::{self as firmware, board};

/// STM32F401RE memories (examples/nucleo-f401re/memory.x).
const FLASH_BYTES: u64 = 512 * 1024;
const RAM_BYTES: u64 = 96 * 1024;

#[test]
fn nucleo_f401re_example_builds_without_warnings_and_fits() {
    let set = firmware::fitted_set(&firmware::compiled_set()).unwrap_or_else(|e| panic!("{e:#}"));
    let elf = board::NUCLEO_F401RE.build(&set).unwrap_or_else(|e| panic!("{e:#}"));
    let size = board::image_size(&elf).unwrap_or_else(|e| panic!("{e:#}"));
    println!(
        "nucleo-f401re: flash {} B of {FLASH_BYTES} ({:.1} %), static RAM {} B of {RAM_BYTES} ({:.1} %): {}",
        size.flash,
        100.0 * size.flash as f64 / FLASH_BYTES as f64,
        size.ram,
        100.0 * size.ram as f64 / RAM_BYTES as f64,
        elf.display()
    );
    assert!(size.flash > 0 && size.flash <= FLASH_BYTES, "flash {} B", size.flash);
    assert!(size.ram > 0 && size.ram <= RAM_BYTES, "RAM {} B", size.ram);
}
