//! The fixed-point insertion model: `needle_fixed_insertion_init`,
//! `needle_fixed_insertion_step`, `needle_fixed_insertion_set_scales`,
//! `needle_fixed_insertion_reset` (integer arithmetic only, for cores without an FPU).
//!
//! The state is `needle_haptics::fixed::insertion::Insertion` kept in the opaque storage
//! of a [`needle_fixed_insertion_t`]; the stack is one of the compiled-in ones, by name.
use crate::eval_fixed::{pose_in, wrench_out_of};
use crate::types::*;
use core::ffi::{c_char, CStr};
use core::mem::{align_of, size_of};
use needle_haptics::fixed::insertion::{stacks, Insertion, InsertionConfig};

const _: () = assert!(size_of::<Insertion<'static>>() <= size_of::<[u64; NEEDLE_FIXED_INSERTION_STORAGE_WORDS]>());
const _: () = assert!(align_of::<Insertion<'static>>() <= align_of::<u64>());

/// # Safety
/// `i` is NULL or valid and aligned; if its magic is set, `needle_fixed_insertion_init`
/// wrote an `Insertion` into its storage (or C copied such a `needle_fixed_insertion_t`).
unsafe fn state_mut<'a>(i: *mut needle_fixed_insertion_t) -> Result<&'a mut Insertion<'static>, i32> {
    // SAFETY: the caller passes NULL or a valid pointer.
    let i = unsafe { i.as_mut() }.ok_or(NEEDLE_E_NULL)?;
    if i.magic != NEEDLE_FIXED_INSERTION_MAGIC {
        return Err(NEEDLE_E_UNINIT);
    }
    // SAFETY: the magic says init wrote an Insertion here; size and alignment checked above.
    Ok(unsafe { &mut *i.storage.as_mut_ptr().cast::<Insertion<'static>>() })
}

/// Starts a needle path through the compiled-in tissue stack named `stack` (a
/// NUL-terminated name, e.g. `"liver"`), in integers, ticked every `period_us`
/// microseconds, the velocity low-passed with `velocity_time_constant_us` (5000 is the
/// library's default).
///
/// Returns `NEEDLE_OK`, `NEEDLE_E_NULL` (a NULL pointer), `NEEDLE_E_ARG` (no stack of
/// that name) or `NEEDLE_E_CONFIG` (a zero period); on an error `*insertion` is unchanged.
///
/// # Safety
/// `insertion` is NULL or points to a writable `needle_fixed_insertion_t`; `stack` is
/// NULL or a NUL-terminated string.
#[no_mangle]
pub unsafe extern "C" fn needle_fixed_insertion_init(
    insertion: *mut needle_fixed_insertion_t,
    stack: *const c_char,
    period_us: u32,
    velocity_time_constant_us: u32,
) -> i32 {
    if insertion.is_null() || stack.is_null() {
        return NEEDLE_E_NULL;
    }
    // SAFETY: non-NULL and NUL-terminated (the caller's contract).
    let name = unsafe { CStr::from_ptr(stack) }.to_bytes();
    // a name that is not UTF-8 names no stack (as the byte comparison found none)
    let Some(s) = core::str::from_utf8(name).ok().and_then(stacks::by_name) else {
        return NEEDLE_E_ARG;
    };
    let Ok(state) = Insertion::new(s, InsertionConfig { period_us, velocity_time_constant_us, ..InsertionConfig::DEFAULT_1KHZ }) else {
        return NEEDLE_E_CONFIG;
    };
    // SAFETY: non-NULL, valid and writable (the caller's contract).
    let i = unsafe { &mut *insertion };
    // SAFETY: size and alignment checked at compile time; the storage is plain u64s.
    unsafe { i.storage.as_mut_ptr().cast::<Insertion<'static>>().write(state) };
    i.magic = NEEDLE_FIXED_INSERTION_MAGIC;
    NEEDLE_OK
}

/// One tick: the Q16.16 pose in; the wrench (µN, µN·mm), status, phase code (as
/// `needle_insertion_step`'s), punctures and the filtered velocity (mm/s × 65536) out.
/// Returns `NEEDLE_OK`, `NEEDLE_E_NULL` or `NEEDLE_E_UNINIT`.
///
/// # Safety
/// Each pointer is NULL or valid; `insertion` was set up by `needle_fixed_insertion_init`.
#[no_mangle]
pub unsafe extern "C" fn needle_fixed_insertion_step(
    insertion: *mut needle_fixed_insertion_t,
    pose: *const needle_fixed_pose_t,
    out: *mut needle_fixed_insertion_result_t,
) -> i32 {
    // SAFETY: the caller's contract.
    let (state, pose, out) = match (unsafe { state_mut(insertion) }, unsafe { pose.as_ref() }, unsafe { out.as_mut() }) {
        (Ok(s), Some(p), Some(o)) => (s, p, o),
        (Err(e), _, _) => return e,
        _ => return NEEDLE_E_NULL,
    };
    let e = state.step(&pose_in(pose));
    *out = needle_fixed_insertion_result_t {
        wrench: wrench_out_of(&e.wrench),
        status: e.status.bits(),
        punctures: e.punctures,
        phase: e.phase.code(),
        velocity_mm_per_s_q16: e.velocity_mm_per_s_q16,
        flags: e.flags.bits(),
    };
    NEEDLE_OK
}

/// Replaces the layers' stiffness scales (`count` values in Q16.16, one per layer).
/// Returns `NEEDLE_OK`, `NEEDLE_E_NULL`, `NEEDLE_E_UNINIT` or `NEEDLE_E_ARG` (a count
/// other than the stack's layers, or a scale <= 0 or above 16384; nothing changed).
///
/// # Safety
/// `insertion` is NULL or set up by `needle_fixed_insertion_init`; `scales_q16` is NULL
/// or points to `count` integers.
#[no_mangle]
pub unsafe extern "C" fn needle_fixed_insertion_set_scales(
    insertion: *mut needle_fixed_insertion_t,
    scales_q16: *const i32,
    count: u32,
) -> i32 {
    // SAFETY: the caller's contract.
    let state = match unsafe { state_mut(insertion) } {
        Ok(s) => s,
        Err(e) => return e,
    };
    if scales_q16.is_null() {
        return NEEDLE_E_NULL;
    }
    // SAFETY: non-NULL, `count` integers (the caller's contract).
    let values = unsafe { core::slice::from_raw_parts(scales_q16, count as usize) };
    match state.set_scales(values) {
        Ok(()) => NEEDLE_OK,
        Err(_) => NEEDLE_E_ARG,
    }
}

/// Forgets the path (the needle above the surface). Returns `NEEDLE_OK`,
/// `NEEDLE_E_NULL` or `NEEDLE_E_UNINIT`.
///
/// # Safety
/// `insertion` is NULL or set up by `needle_fixed_insertion_init`.
#[no_mangle]
pub unsafe extern "C" fn needle_fixed_insertion_reset(insertion: *mut needle_fixed_insertion_t) -> i32 {
    // SAFETY: the caller's contract.
    match unsafe { state_mut(insertion) } {
        Ok(s) => {
            s.reset();
            NEEDLE_OK
        }
        Err(e) => e,
    }
}
