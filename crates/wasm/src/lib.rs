//! The f32 evaluator of `needle-haptics` as a WebAssembly module, for `needle explore`.
//!
//! Built with `cargo build --release -p needle-wasm --target wasm32-unknown-unknown`
//! and `NEEDLE_COEFFS` naming the set: the same `no_std` library and the same generated
//! tables as the firmware, so the browser shows what the device will render, bit for bit
//! (`tests/explore_wasm.rs` replays `golden-f32.csv` through the module under Node).
//!
//! The exports use only numbers (no allocator, no bindings generator):
//! - [`needle_eval`] evaluates one pose and returns the status bits; the wrench
//!   components (fx, fy, fz in N; mx, my, mz in N*mm) are left, as f32 bit patterns, in
//!   the buffer of [`needle_component_count`] words at [`needle_out`];
//! - [`needle_domain`] the model's domain, [`needle_coupled`] its form.
#![cfg_attr(target_arch = "wasm32", no_std)]
#![deny(missing_docs)]

use core::sync::atomic::{AtomicU32, Ordering};
use needle_contract::COMPONENT_COUNT;
use needle_haptics::{model_info, wrench, Pose};

/// The last evaluation: fx, fy, fz (N), mx, my, mz (N*mm) as f32 bits.
static OUT: [AtomicU32; COMPONENT_COUNT] = [const { AtomicU32::new(0) }; COMPONENT_COUNT];

/// Evaluates the wrench at `x_mm`, `z_mm` (entry point), `theta_x_deg`, `theta_z_deg`
/// (tilt) and `depth_mm`, exactly as the firmware's `needle_haptics::wrench`; stores it
/// at [`needle_out`] and returns the status bits (`Status`: saturation flags 0x1f,
/// `NO_MODEL` 0x40, `ERROR` 0x80).
#[no_mangle]
pub extern "C" fn needle_eval(x_mm: f32, z_mm: f32, theta_x_deg: f32, theta_z_deg: f32, depth_mm: f32) -> u32 {
    let e = wrench(&Pose::new(x_mm, z_mm, theta_x_deg, theta_z_deg, depth_mm));
    for (slot, v) in OUT.iter().zip(e.wrench.to_array()) {
        slot.store(v.to_bits(), Ordering::Relaxed);
    }
    u32::from(e.status.bits())
}

/// Number of wrench components, the words at [`needle_out`] (the contract's
/// `COMPONENT_COUNT`; the page checks its component list against it).
#[no_mangle]
pub extern "C" fn needle_component_count() -> u32 {
    COMPONENT_COUNT as u32
}

/// Address of the result buffer of [`needle_eval`] in the module's memory.
#[no_mangle]
pub extern "C" fn needle_out() -> *const AtomicU32 {
    OUT.as_ptr()
}

/// The model's domain: `k` = 0 `X_MAX_MM`, 1 `Z_MAX_MM`, 2 `THETA_MAX_DEG` (both tilts),
/// 3 `DEPTH_MAX_MM`; positions and tilts range over [-max, max], depth over [0, max].
/// Any other `k`: NaN.
#[no_mangle]
pub extern "C" fn needle_domain(k: u32) -> f32 {
    match k {
        0 => model_info::X_MAX_MM,
        1 => model_info::Z_MAX_MM,
        2 => model_info::THETA_MAX_DEG,
        3 => model_info::DEPTH_MAX_MM,
        _ => f32::NAN,
    }
}

/// 1 when the compiled model is the coupled form (cross terms), 0 for the paper's
/// superposition; 2 when no model is fitted (every evaluation returns `NO_MODEL`).
#[no_mangle]
pub extern "C" fn needle_coupled() -> u32 {
    if !model_info::FITTED {
        2
    } else {
        u32::from(model_info::COUPLED)
    }
}

/// A wasm module has no one to report a panic to; the library cannot panic (its
/// link-time check), so this is never reached.
#[cfg(target_arch = "wasm32")]
#[panic_handler]
fn panic(_: &core::panic::PanicInfo<'_>) -> ! {
    core::arch::wasm32::unreachable()
}
