//! The insertion model: `needle_insertion_init`, `needle_insertion_step`,
//! `needle_insertion_set_scales`, `needle_insertion_reset`, and `needle_loop_set_insertion`
//! (the control loop renders an insertion).
//!
//! The state is `needle_haptics::insertion::Insertion` kept in the opaque storage of a
//! [`needle_insertion_t`]; the stack is one of the compiled-in ones, by name (on a host, a
//! tissue file loaded at run time: `needle_insertion_init_file`).
use crate::control::loop_core;
use crate::eval::{pose_in, wrench_out_of};
use crate::types::*;
use core::ffi::{c_char, CStr};
use core::mem::{align_of, size_of};
use needle_haptics::insertion::{stacks, Insertion, InsertionConfig};

const _: () = assert!(size_of::<Insertion>() <= size_of::<[u64; NEEDLE_INSERTION_STORAGE_WORDS]>());
const _: () = assert!(align_of::<Insertion>() <= align_of::<u64>());

/// # Safety
/// `i` is NULL or valid and aligned; if its magic is set, `needle_insertion_init` wrote
/// an `Insertion` into its storage (or C copied such a `needle_insertion_t`).
unsafe fn state_mut<'a>(i: *mut needle_insertion_t) -> Result<&'a mut Insertion, i32> {
    // SAFETY: the caller passes NULL or a valid pointer.
    let i = unsafe { i.as_mut() }.ok_or(NEEDLE_E_NULL)?;
    if i.magic != NEEDLE_INSERTION_MAGIC {
        return Err(NEEDLE_E_UNINIT);
    }
    // SAFETY: the magic says init wrote an Insertion here; size and alignment checked above.
    Ok(unsafe { &mut *i.storage.as_mut_ptr().cast::<Insertion>() })
}

/// Starts a needle path through the compiled-in tissue stack named `stack` (a
/// NUL-terminated name, e.g. `"liver"`), ticked every `period_s` seconds, the velocity
/// low-passed with `velocity_time_constant_s` (0.005 is the library's default).
///
/// Returns `NEEDLE_OK`, `NEEDLE_E_NULL` (a NULL pointer), `NEEDLE_E_ARG` (no stack of
/// that name) or `NEEDLE_E_CONFIG` (a period or time constant out of range); on an error
/// `*insertion` is unchanged.
///
/// # Safety
/// `insertion` is NULL or points to a writable `needle_insertion_t`; `stack` is NULL or a
/// NUL-terminated string.
#[no_mangle]
pub unsafe extern "C" fn needle_insertion_init(
    insertion: *mut needle_insertion_t,
    stack: *const c_char,
    period_s: f32,
    velocity_time_constant_s: f32,
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
    let config = InsertionConfig { period_s, velocity_time_constant_s, ..InsertionConfig::DEFAULT_1KHZ };
    let Ok(state) = Insertion::new(s, config) else {
        return NEEDLE_E_CONFIG;
    };
    // SAFETY: non-NULL, valid and writable (the caller's contract).
    unsafe { install(insertion, state) };
    NEEDLE_OK
}

/// Writes `state` into `insertion`'s storage and marks it set up.
///
/// # Safety
/// `insertion` is non-NULL, valid and writable.
pub(crate) unsafe fn install(insertion: *mut needle_insertion_t, state: Insertion) {
    // SAFETY: non-NULL, valid and writable (the caller's contract).
    let i = unsafe { &mut *insertion };
    // SAFETY: size and alignment checked at compile time; the storage is plain u64s.
    unsafe { i.storage.as_mut_ptr().cast::<Insertion>().write(state) };
    i.magic = NEEDLE_INSERTION_MAGIC;
}

/// One tick: the pose in, the wrench, status, phase code (`0` approach, `0x100 | layer`
/// deflecting, `0x200 | layer` cutting, `0x300 | layer` in the track), punctures and the
/// filtered velocity out. Returns `NEEDLE_OK`, `NEEDLE_E_NULL` or `NEEDLE_E_UNINIT`.
///
/// # Safety
/// Each pointer is NULL or valid; `insertion` was set up by `needle_insertion_init`.
#[no_mangle]
pub unsafe extern "C" fn needle_insertion_step(
    insertion: *mut needle_insertion_t,
    pose: *const needle_pose_t,
    out: *mut needle_insertion_result_t,
) -> i32 {
    // SAFETY: the caller's contract.
    let (state, pose, out) = match (unsafe { state_mut(insertion) }, unsafe { pose.as_ref() }, unsafe { out.as_mut() }) {
        (Ok(s), Some(p), Some(o)) => (s, p, o),
        (Err(e), _, _) => return e,
        _ => return NEEDLE_E_NULL,
    };
    let e = state.step(&pose_in(pose));
    *out = needle_insertion_result_t {
        wrench: wrench_out_of(&e.wrench),
        status: e.status.bits(),
        punctures: e.punctures,
        phase: e.phase.code(),
        velocity_mm_per_s: e.velocity_mm_per_s,
        flags: e.flags.bits(),
    };
    NEEDLE_OK
}

/// Replaces the layers' stiffness scales (`count` values, one per layer of the stack).
/// Returns `NEEDLE_OK`, `NEEDLE_E_NULL`, `NEEDLE_E_UNINIT` or `NEEDLE_E_ARG` (a count other
/// than the stack's layers, or a scale that is not finite and > 0; nothing changed).
///
/// # Safety
/// `insertion` is NULL or set up by `needle_insertion_init`; `scales` is NULL or points to
/// `count` floats.
#[no_mangle]
pub unsafe extern "C" fn needle_insertion_set_scales(insertion: *mut needle_insertion_t, scales: *const f32, count: u32) -> i32 {
    // SAFETY: the caller's contract.
    let state = match unsafe { state_mut(insertion) } {
        Ok(s) => s,
        Err(e) => return e,
    };
    if scales.is_null() {
        return NEEDLE_E_NULL;
    }
    // SAFETY: non-NULL, `count` floats (the caller's contract).
    let values = unsafe { core::slice::from_raw_parts(scales, count as usize) };
    match state.set_scales(values) {
        Ok(()) => NEEDLE_OK,
        Err(_) => NEEDLE_E_ARG,
    }
}

/// Forgets the path (the needle above the surface). Returns `NEEDLE_OK`,
/// `NEEDLE_E_NULL` or `NEEDLE_E_UNINIT`.
///
/// # Safety
/// `insertion` is NULL or set up by `needle_insertion_init`.
#[no_mangle]
pub unsafe extern "C" fn needle_insertion_reset(insertion: *mut needle_insertion_t) -> i32 {
    // SAFETY: the caller's contract.
    match unsafe { state_mut(insertion) } {
        Ok(s) => {
            s.reset();
            NEEDLE_OK
        }
        Err(e) => e,
    }
}

/// Makes the loop `l` render the insertion `insertion` instead of the block surrogate:
/// its state is copied into the loop, whose ticks then step the copy (the needle path
/// goes on from where `*insertion` is; `*insertion` itself is not changed by them);
/// NULL goes back to the block surrogate. The passivity guard, if on, restarts without
/// history (`needle_haptics::control::LoopCore::set_insertion`).
///
/// Returns `NEEDLE_OK`, `NEEDLE_E_NULL` (a NULL loop) or `NEEDLE_E_UNINIT` (the loop or
/// the insertion not initialised; the loop is then unchanged).
///
/// # Safety
/// `l` is NULL or set up by `needle_loop_init`; `insertion` is NULL or set up by
/// `needle_insertion_init`.
#[no_mangle]
pub unsafe extern "C" fn needle_loop_set_insertion(l: *mut needle_loop_t, insertion: *const needle_insertion_t) -> i32 {
    // SAFETY: the caller's contract.
    let core = match unsafe { loop_core(l) } {
        Ok(c) => c,
        Err(e) => return e,
    };
    // SAFETY: the caller's contract: NULL or valid.
    let state = match unsafe { insertion.as_ref() } {
        None => None,
        Some(i) if i.magic == NEEDLE_INSERTION_MAGIC => {
            // SAFETY: the magic says init wrote an Insertion here; size and alignment
            // are checked at compile time.
            Some(unsafe { *i.storage.as_ptr().cast::<Insertion>() })
        }
        Some(_) => return NEEDLE_E_UNINIT,
    };
    core.set_insertion(state);
    NEEDLE_OK
}
