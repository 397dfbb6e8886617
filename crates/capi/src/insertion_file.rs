//! `needle_insertion_init_file`: a needle path through a tissue file loaded at run time
//! (issue 65), on hosted targets only: the file is checked by the format's one reader and
//! the library, as the build checks a compiled-in stack (`needle_calibrate::runtime_stack`,
//! the same messages with `FILE:LINE`). The firmware keeps its stacks compiled in; a
//! bare-metal build has no such function.
use crate::insertion::install;
use crate::types::*;
use core::ffi::{c_char, CStr};
use needle_calibrate::runtime_stack::OwnedStack;
use needle_haptics::insertion::{Insertion, InsertionConfig};
use std::path::Path;

/// Starts a needle path through the tissue file at `path` (a NUL-terminated file name,
/// e.g. `"coeffs/default/calibrated/rig_skin_2mmps_t1.toml"`), loaded now and checked as
/// the build checks a compiled-in stack, ticked every `period_s` seconds, the velocity
/// low-passed with `velocity_time_constant_s`. The state is a `needle_insertion_t` as
/// `needle_insertion_init` makes it: step, reset and render it with the same functions.
///
/// Returns `NEEDLE_OK`, `NEEDLE_E_NULL` (`insertion` or `path` NULL), `NEEDLE_E_ARG` (the
/// file cannot be read or is refused: why, with `FILE:LINE`, in `message`) or
/// `NEEDLE_E_CONFIG` (a period or time constant out of range). Unless `message` is NULL
/// or `message_len` is 0, `message` receives a NUL-terminated text (empty on
/// `NEEDLE_OK`), cut to `message_len - 1` bytes. On an error `*insertion` is unchanged.
///
/// # Safety
/// `insertion` is NULL or points to a writable `needle_insertion_t`; `path` is NULL or a
/// NUL-terminated string; `message` is NULL or points to `message_len` writable bytes.
#[no_mangle]
pub unsafe extern "C" fn needle_insertion_init_file(
    insertion: *mut needle_insertion_t,
    path: *const c_char,
    period_s: f32,
    velocity_time_constant_s: f32,
    message: *mut c_char,
    message_len: usize,
) -> i32 {
    let (rc, text) = init_file(insertion, path, period_s, velocity_time_constant_s);
    // SAFETY: the caller's contract for `message`.
    unsafe { write_message(message, message_len, &text) };
    rc
}

fn init_file(insertion: *mut needle_insertion_t, path: *const c_char, period_s: f32, tau_s: f32) -> (i32, String) {
    if insertion.is_null() || path.is_null() {
        return (NEEDLE_E_NULL, "insertion and path must not be NULL".into());
    }
    // SAFETY: non-NULL and NUL-terminated (the caller's contract).
    let name = unsafe { CStr::from_ptr(path) }.to_string_lossy().into_owned();
    let stack = match OwnedStack::load(Path::new(&name)) {
        Ok(s) => s,
        Err(e) => return (NEEDLE_E_ARG, format!("{e:#}")),
    };
    let config = InsertionConfig { period_s, velocity_time_constant_s: tau_s, ..InsertionConfig::DEFAULT_1KHZ };
    match Insertion::new(&stack.as_stack(), config) {
        // SAFETY: `insertion` is non-NULL, valid and writable (the caller's contract).
        Ok(state) => unsafe { install(insertion, state) },
        Err(e) => return (NEEDLE_E_CONFIG, format!("{name}: {e}")),
    }
    (NEEDLE_OK, String::new())
}

/// # Safety
/// `out` is NULL or points to `len` writable bytes.
unsafe fn write_message(out: *mut c_char, len: usize, text: &str) {
    if out.is_null() || len == 0 {
        return;
    }
    let bytes = text.as_bytes();
    let n = bytes.len().min(len - 1);
    // SAFETY: `out` has `len` > n bytes (the caller's contract); the regions do not overlap.
    unsafe {
        core::ptr::copy_nonoverlapping(bytes.as_ptr().cast::<c_char>(), out, n);
        *out.add(n) = 0;
    }
}
