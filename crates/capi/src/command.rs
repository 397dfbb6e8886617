//! The host-link commands on the C loop: `needle_loop_command`.
use crate::control::loop_core;
use crate::types::needle_loop_t;
use needle_haptics::command::{parse, respond};

/// Answers one request frame (the bytes of one line, without its `\n`; frame format in
/// `needle_haptics::command`) on the loop `l`, with `dropped` reported by `STATUS`.
/// Copies the reply line (with its `\n`) and a NUL into `reply` (truncated to
/// `reply_cap - 1` bytes) and returns the reply's full length without the NUL; 0 when a
/// pointer is NULL, `reply_cap` is 0 or the loop is not initialised. A refused frame gets
/// an `ERR` reply and leaves the loop unchanged.
///
/// # Safety
/// `l` NULL or valid; `frame` NULL or `len` readable bytes; `reply` NULL or `reply_cap`
/// writable bytes.
#[no_mangle]
pub unsafe extern "C" fn needle_loop_command(
    l: *mut needle_loop_t,
    frame: *const u8,
    len: usize,
    dropped: u32,
    reply: *mut u8,
    reply_cap: usize,
) -> usize {
    if frame.is_null() || reply.is_null() || reply_cap == 0 {
        return 0;
    }
    // SAFETY: the caller's contract.
    let Ok(core) = (unsafe { loop_core(l) }) else {
        return 0;
    };
    // SAFETY: `frame` is non-NULL with `len` readable bytes; `reply` non-NULL with
    // `reply_cap` writable bytes (the caller's contract).
    let (frame, out) = unsafe { (core::slice::from_raw_parts(frame, len), core::slice::from_raw_parts_mut(reply, reply_cap)) };
    let r = respond(parse(frame), core, dropped);
    let n = r.len().min(reply_cap - 1);
    for (d, b) in out.iter_mut().zip(r.as_bytes().iter().take(n).chain(core::iter::once(&0))) {
        *d = *b;
    }
    r.len()
}
