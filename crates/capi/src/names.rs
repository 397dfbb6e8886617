//! Names for C: `needle_strerror`, `needle_status_name`, `needle_insertion_flag_name`,
//! `needle_loop_flag_name`.
//! Static, NUL-terminated strings; the flag names are the library's (`Status::FLAGS`,
//! `LoopFlags::FLAGS`), checked by this crate's tests.
use core::ffi::{c_char, CStr};

/// What an `NEEDLE_OK` / `NEEDLE_E_*` return code means, e.g. "NULL pointer argument".
/// Unknown codes give "unknown needle error code". Never NULL.
#[no_mangle]
pub extern "C" fn needle_strerror(code: i32) -> *const c_char {
    let s: &CStr = match code {
        crate::types::NEEDLE_OK => c"success",
        crate::types::NEEDLE_E_NULL => c"NULL pointer argument",
        crate::types::NEEDLE_E_CONFIG => c"configuration or force limit refused; nothing changed",
        crate::types::NEEDLE_E_UNINIT => c"loop not initialised with needle_loop_init",
        crate::types::NEEDLE_E_ARG => c"enumeration argument out of range",
        _ => c"unknown needle error code",
    };
    s.as_ptr()
}

/// The name of one `NEEDLE_STATUS_*` bit ("SAT_X", ..., "ERROR"), "OK" for 0; NULL for a
/// value that is not 0 or exactly one known bit (test the bits one by one).
#[no_mangle]
pub extern "C" fn needle_status_name(bit: u8) -> *const c_char {
    let s: Option<&CStr> = match bit {
        0 => Some(c"OK"),
        crate::types::NEEDLE_STATUS_SAT_X => Some(c"SAT_X"),
        crate::types::NEEDLE_STATUS_SAT_Z => Some(c"SAT_Z"),
        crate::types::NEEDLE_STATUS_SAT_THETA_X => Some(c"SAT_THETA_X"),
        crate::types::NEEDLE_STATUS_SAT_THETA_Z => Some(c"SAT_THETA_Z"),
        crate::types::NEEDLE_STATUS_SAT_DEPTH => Some(c"SAT_DEPTH"),
        crate::types::NEEDLE_STATUS_FE_UNSOLVED => Some(c"FE_UNSOLVED"),
        crate::types::NEEDLE_STATUS_NO_MODEL => Some(c"NO_MODEL"),
        crate::types::NEEDLE_STATUS_ERROR => Some(c"ERROR"),
        _ => None,
    };
    s.map_or(core::ptr::null(), CStr::as_ptr)
}

/// The name of one `NEEDLE_INSERTION_*` flag ("FAST_MOTION", "OUT_OF_DOMAIN",
/// "NOT_FINITE", "WRENCH_LIMITED"), "OK" for 0; NULL for a value that is not 0 or
/// exactly one known flag.
#[no_mangle]
pub extern "C" fn needle_insertion_flag_name(flag: u8) -> *const c_char {
    let s: Option<&CStr> = match flag {
        0 => Some(c"OK"),
        crate::types::NEEDLE_INSERTION_FAST_MOTION => Some(c"FAST_MOTION"),
        crate::types::NEEDLE_INSERTION_OUT_OF_DOMAIN => Some(c"OUT_OF_DOMAIN"),
        crate::types::NEEDLE_INSERTION_NOT_FINITE => Some(c"NOT_FINITE"),
        crate::types::NEEDLE_INSERTION_WRENCH_LIMITED => Some(c"WRENCH_LIMITED"),
        _ => None,
    };
    s.map_or(core::ptr::null(), CStr::as_ptr)
}

/// The name of one `NEEDLE_LOOP_*` flag ("POSE_STALE", ..., "POSE_GLITCH"), "OK" for 0; NULL
/// for a value that is not 0 or exactly one known flag.
#[no_mangle]
pub extern "C" fn needle_loop_flag_name(flag: u16) -> *const c_char {
    let s: Option<&CStr> = match flag {
        0 => Some(c"OK"),
        crate::types::NEEDLE_LOOP_POSE_STALE => Some(c"POSE_STALE"),
        crate::types::NEEDLE_LOOP_POSE_MISSING => Some(c"POSE_MISSING"),
        crate::types::NEEDLE_LOOP_EVAL_ERROR => Some(c"EVAL_ERROR"),
        crate::types::NEEDLE_LOOP_OVER_LIMIT => Some(c"OVER_LIMIT"),
        crate::types::NEEDLE_LOOP_FORCE_SATURATED => Some(c"FORCE_SATURATED"),
        crate::types::NEEDLE_LOOP_RAMPING => Some(c"RAMPING"),
        crate::types::NEEDLE_LOOP_DUTY_CLIPPED => Some(c"DUTY_CLIPPED"),
        crate::types::NEEDLE_LOOP_OUTPUT_ERROR => Some(c"OUTPUT_ERROR"),
        crate::types::NEEDLE_LOOP_DISABLED => Some(c"DISABLED"),
        crate::types::NEEDLE_LOOP_STIFFNESS_LIMITED => Some(c"STIFFNESS_LIMITED"),
        crate::types::NEEDLE_LOOP_POSE_GLITCH => Some(c"POSE_GLITCH"),
        _ => None,
    };
    s.map_or(core::ptr::null(), CStr::as_ptr)
}

/// Writes the library's text of `status` (`Status`'s `Display`: the flag names joined by
/// " | ", e.g. "SAT_X | SAT_DEPTH"; "OK" for 0; bits no flag names in hex) into `buf`,
/// NUL-terminated and truncated to `len - 1` bytes. Returns the length of the whole text
/// without the NUL (as `snprintf`: a return >= `len` means it was truncated). `buf` may be
/// NULL when `len` is 0 (to ask for the length).
///
/// # Safety
/// `buf` is NULL or points to `len` writable bytes.
#[no_mangle]
pub unsafe extern "C" fn needle_status_str(status: u8, buf: *mut c_char, len: usize) -> usize {
    let out: &mut [u8] = if buf.is_null() || len == 0 {
        &mut []
    } else {
        // SAFETY: the caller passes `len` writable bytes at `buf`
        unsafe { core::slice::from_raw_parts_mut(buf.cast::<u8>(), len) }
    };
    let mut w = Truncating { out, written: 0, total: 0 };
    let _ = core::fmt::Write::write_fmt(&mut w, format_args!("{}", needle_haptics::Status::from_bits(status)));
    let end = w.written;
    if let Some(nul) = w.out.get_mut(end) {
        *nul = 0;
    }
    w.total
}

/// A `fmt::Write` into a byte buffer that keeps room for a NUL and counts what did not fit.
struct Truncating<'a> {
    out: &'a mut [u8],
    written: usize,
    total: usize,
}

impl core::fmt::Write for Truncating<'_> {
    fn write_str(&mut self, s: &str) -> core::fmt::Result {
        let room = self.out.len().saturating_sub(1).saturating_sub(self.written);
        let take = s.len().min(room);
        if let (Some(dst), Some(src)) = (self.out.get_mut(self.written..self.written + take), s.as_bytes().get(..take)) {
            dst.copy_from_slice(src);
            self.written += take;
        }
        self.total += s.len();
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use needle_haptics::control::LoopFlags;
    use needle_haptics::Status;

    fn name(p: *const c_char) -> Option<String> {
        // SAFETY: the functions return NULL or a static NUL-terminated string
        (!p.is_null()).then(|| unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned())
    }

    #[test]
    fn status_and_flag_constants_and_names_are_the_librarys() {
        for (flag, lib_name) in Status::FLAGS {
            assert_eq!(name(needle_status_name(flag.bits())).as_deref(), Some(lib_name), "status bit {:#04x}", flag.bits());
        }
        assert_eq!(Status::FLAGS.len(), 8, "a new Status flag needs its NEEDLE_STATUS_ constant and name");
        for (flag, lib_name) in LoopFlags::FLAGS {
            assert_eq!(name(needle_loop_flag_name(flag.bits())).as_deref(), Some(lib_name), "loop flag {:#06x}", flag.bits());
        }
        assert_eq!(LoopFlags::FLAGS.len(), 11, "a new loop flag needs its NEEDLE_LOOP_ constant and name");
        for (flag, lib_name) in needle_haptics::InsertionFlags::FLAGS {
            assert_eq!(name(needle_insertion_flag_name(flag.bits())).as_deref(), Some(lib_name), "insertion flag {:#04x}", flag.bits());
        }
        assert_eq!(needle_haptics::InsertionFlags::FLAGS.len(), 4, "a new insertion flag needs its NEEDLE_INSERTION_ constant and name");
        assert_eq!(name(needle_insertion_flag_name(0x03)), None, "two bits are not one name");
        assert_eq!(name(needle_status_name(0x11)), None, "two bits are not one name");
        assert_eq!(name(needle_loop_flag_name(0x0800)), None, "unknown flag");
        assert_eq!(name(needle_strerror(crate::types::NEEDLE_E_NULL)).as_deref(), Some("NULL pointer argument"));
        assert_eq!(name(needle_strerror(-99)).as_deref(), Some("unknown needle error code"));
        for (status, want) in [(0u8, "OK"), (0x11, "SAT_X | SAT_DEPTH"), (0x30, "SAT_DEPTH | FE_UNSOLVED")] {
            let mut buf = [0x55 as c_char; 32];
            // SAFETY: 32 writable bytes
            let n = unsafe { needle_status_str(status, buf.as_mut_ptr(), buf.len()) };
            assert_eq!((n, name(buf.as_ptr()).as_deref()), (want.len(), Some(want)), "{status:#04x}");
        }
        let mut small = [0x55 as c_char; 6];
        // SAFETY: 6 writable bytes
        let n = unsafe { needle_status_str(0x11, small.as_mut_ptr(), small.len()) };
        assert_eq!((n, name(small.as_ptr()).as_deref()), (17, Some("SAT_X")), "truncated, NUL-terminated");
        // SAFETY: NULL with len 0 asks for the length
        assert_eq!(unsafe { needle_status_str(0x11, core::ptr::null_mut(), 0) }, 17);
    }
}
