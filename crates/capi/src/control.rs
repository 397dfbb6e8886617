//! The control loop: `needle_loop_init`, `needle_loop_tick`, `needle_loop_set_force_limit_n`,
//! `needle_loop_set_passivity`.
//!
//! The C loop is `needle_haptics::control::LoopCore<3>` kept in the opaque storage of a
//! [`needle_loop_t`]: C reads the pose itself, passes it to the tick, and applies the
//! duties and pin levels the tick returns to its own PWM and GPIO.
use crate::eval::{pose_in, pose_out, wrench_out_of};
use crate::types::*;
use core::mem::{align_of, size_of};
use needle_haptics::control::{ChannelMap, LoopConfig, LoopCore, OverLimit, Passivity, PoseFault};

type Core = LoopCore<NEEDLE_CHANNELS>;

// The loop must fit the opaque storage, at an alignment the storage guarantees.
const _: () = assert!(size_of::<Core>() <= size_of::<[u64; NEEDLE_LOOP_STORAGE_WORDS]>());
const _: () = assert!(align_of::<Core>() <= align_of::<u64>());

/// The initialised loop in `l`, or the error code.
///
/// # Safety
/// `l` is NULL or valid and aligned; if its magic is set, `needle_loop_init` wrote a
/// `Core` into its storage (or C copied such a `needle_loop_t`).
unsafe fn core_mut<'a>(l: *mut needle_loop_t) -> Result<&'a mut Core, i32> {
    // SAFETY: the caller passes NULL or a valid pointer.
    let l = unsafe { l.as_mut() }.ok_or(NEEDLE_E_NULL)?;
    if l.magic != NEEDLE_LOOP_MAGIC {
        return Err(NEEDLE_E_UNINIT);
    }
    // SAFETY: the magic says init wrote a Core here; size and alignment are checked above.
    Ok(unsafe { &mut *l.storage.as_mut_ptr().cast::<Core>() })
}

fn config_in(c: &needle_loop_config_t) -> Result<LoopConfig<NEEDLE_CHANNELS>, i32> {
    let over_limit = match c.over_limit {
        NEEDLE_OVER_LIMIT_SATURATE => OverLimit::Saturate,
        NEEDLE_OVER_LIMIT_RAMP => OverLimit::RampToZero,
        _ => return Err(NEEDLE_E_ARG),
    };
    Ok(LoopConfig {
        channels: c.channels.map(|ch| ChannelMap { gains_per_n: ch.gains_per_n, direction_inverted: ch.direction_inverted }),
        force_limit_n: c.force_limit_n,
        force_limit_max_n: c.force_limit_max_n,
        over_limit,
        ramp_step_n: c.ramp_step_n,
    })
}

/// Initialises `*l` with `*config`: tick 0, zero command, outputs disabled.
///
/// Returns `NEEDLE_OK`; `NEEDLE_E_NULL` for a NULL pointer; `NEEDLE_E_ARG` for an
/// unknown `over_limit`; `NEEDLE_E_CONFIG` when the configuration is invalid (a gain not
/// finite, not `0 < force_limit_n <= force_limit_max_n`, `ramp_step_n` not finite and > 0). On an
/// error `*l` is left as it was.
///
/// # Safety
/// `l` and `config` are NULL or valid, aligned pointers.
#[no_mangle]
pub unsafe extern "C" fn needle_loop_init(l: *mut needle_loop_t, config: *const needle_loop_config_t) -> i32 {
    // SAFETY: the caller passes NULL or valid pointers.
    let (Some(l), Some(c)) = (unsafe { l.as_mut() }, unsafe { config.as_ref() }) else {
        return NEEDLE_E_NULL;
    };
    let core = match config_in(c).map(|c| Core::new(c).map_err(|_| NEEDLE_E_CONFIG)) {
        Ok(Ok(core)) => core,
        Ok(Err(e)) | Err(e) => return e,
    };
    // SAFETY: the storage is large and aligned enough (checked at compile time) and
    // owned by `l`; `write` does not read the old contents.
    unsafe { l.storage.as_mut_ptr().cast::<Core>().write(core) };
    l.magic = NEEDLE_LOOP_MAGIC;
    NEEDLE_OK
}

/// One tick: `pose_state` is `NEEDLE_POSE_FRESH` (then `pose` must not be NULL),
/// `NEEDLE_POSE_STALE` or `NEEDLE_POSE_MISSING` (`pose` is ignored); `max_duty` points
/// to `NEEDLE_CHANNELS` full-scale duties. Writes the tick's record, duties and pin levels
/// to `*out` (same control law, bit for bit, as `needle_haptics::control::ControlLoop`).
///
/// Returns `NEEDLE_OK`, `NEEDLE_E_NULL`, `NEEDLE_E_UNINIT`, or `NEEDLE_E_ARG` for an
/// unknown `pose_state` (the loop does not tick on an error).
///
/// # Safety
/// Pointers NULL or valid and aligned; `max_duty` to `NEEDLE_CHANNELS` values.
#[no_mangle]
pub unsafe extern "C" fn needle_loop_tick(
    l: *mut needle_loop_t,
    pose: *const needle_pose_t,
    pose_state: u8,
    max_duty: *const u16,
    out: *mut needle_tick_t,
) -> i32 {
    // SAFETY: the caller's contract.
    let core = match unsafe { core_mut(l) } {
        Ok(c) => c,
        Err(e) => return e,
    };
    // SAFETY: the caller's contract: NULL or NEEDLE_CHANNELS readable values.
    let (Some(max_duty), Some(out)) = (unsafe { max_duty.cast::<[u16; NEEDLE_CHANNELS]>().as_ref() }, unsafe { out.as_mut() }) else {
        return NEEDLE_E_NULL;
    };
    let reading = match pose_state {
        // SAFETY: the caller's contract.
        NEEDLE_POSE_FRESH => match unsafe { pose.as_ref() } {
            Some(p) => Ok(pose_in(p)),
            None => return NEEDLE_E_NULL,
        },
        NEEDLE_POSE_STALE => Err(PoseFault::Stale),
        NEEDLE_POSE_MISSING => Err(PoseFault::Missing),
        _ => return NEEDLE_E_ARG,
    };
    let s = core.step(reading);
    let commands = core.commands();
    let mut duty = [0u16; NEEDLE_CHANNELS];
    let mut direction_high = [false; NEEDLE_CHANNELS];
    for (((d, h), c), m) in duty.iter_mut().zip(direction_high.iter_mut()).zip(commands.iter()).zip(max_duty.iter()) {
        *d = c.duty(*m);
        *h = c.direction_high;
    }
    *out = needle_tick_t {
        tick: s.tick,
        pose: pose_out(&s.pose),
        wrench: wrench_out_of(&s.wrench),
        force_cmd_n: s.force_cmd_n,
        duty,
        flags: s.flags.bits(),
        model_status: s.model.bits(),
        direction_high,
        enable: core.enabled(),
    };
    NEEDLE_OK
}

/// Sets the device force limit, N. Returns `NEEDLE_OK`, `NEEDLE_E_NULL`,
/// `NEEDLE_E_UNINIT`, or `NEEDLE_E_CONFIG` (not `0 < limit_n <= force_limit_max_n`; the
/// limit is unchanged).
///
/// # Safety
/// `l` is NULL or valid and aligned.
#[no_mangle]
pub unsafe extern "C" fn needle_loop_set_force_limit_n(l: *mut needle_loop_t, limit_n: f32) -> i32 {
    // SAFETY: the caller's contract.
    match unsafe { core_mut(l) } {
        Ok(c) => c.set_force_limit_n(limit_n).map_or(NEEDLE_E_CONFIG, |()| NEEDLE_OK),
        Err(e) => e,
    }
}

/// Turns the loop's passivity guard on with `*passivity`, or off for NULL
/// (`needle_haptics::control::LoopCore::set_passivity`): while on, a tick whose model
/// stiffness along the insertion is above half of Colgate's bound `2 b / T` renders it at
/// that stiffness and sets `NEEDLE_LOOP_STIFFNESS_LIMITED`. Either way the guard starts
/// without history.
///
/// Returns `NEEDLE_OK`, `NEEDLE_E_NULL` (a NULL loop), `NEEDLE_E_UNINIT`, or
/// `NEEDLE_E_CONFIG` (a damping or period not finite and > 0; the guard is then unchanged).
///
/// # Safety
/// `l` is NULL or valid and aligned; `passivity` is NULL or a valid pointer.
#[no_mangle]
pub unsafe extern "C" fn needle_loop_set_passivity(l: *mut needle_loop_t, passivity: *const needle_passivity_t) -> i32 {
    // SAFETY: the caller's contract.
    let core = match unsafe { core_mut(l) } {
        Ok(c) => c,
        Err(e) => return e,
    };
    // SAFETY: the caller's contract: NULL or valid.
    let p = unsafe { passivity.as_ref() }.map(|p| Passivity { damping_n_s_per_mm: p.damping_n_s_per_mm, period_s: p.period_s });
    core.set_passivity(p).map_or(NEEDLE_E_CONFIG, |()| NEEDLE_OK)
}

/// The loop in `l` (for the command module).
///
/// # Safety
/// As [`core_mut`].
pub(crate) unsafe fn loop_core<'a>(l: *mut needle_loop_t) -> Result<&'a mut Core, i32> {
    // SAFETY: forwarded.
    unsafe { core_mut(l) }
}
