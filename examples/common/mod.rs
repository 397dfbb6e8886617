//! Shared by the firmware examples (bare metal only): output through
//! ARM semihosting (QEMU writes it to its stdout), the semihosting exit, and a panic
//! handler that reports the panic and exits with a failure status. The `no_panic*`
//! examples do not use this module: they hold `panic_gate`, whose handler cannot link.
#![allow(dead_code)]
// Fixed-size buffers indexed within their bounds; a panic here is reported by the handler below.
#![allow(clippy::indexing_slicing)]

pub mod device;
pub mod icount;
pub mod insertion_paths;
pub mod script;
pub mod trace;

use core::panic::PanicInfo;
use cortex_m_semihosting::{debug, hio};

/// A line buffer written to the host's stdout when full or on [`Out::flush`], so a
/// semihosting call (a trap into QEMU) carries many lines.
pub struct Out {
    stream: Option<hio::HostStream>,
    buf: [u8; 1024],
    len: usize,
}

impl Out {
    /// Opens the host's stdout (`:tt`).
    pub fn new() -> Self {
        Self { stream: hio::hstdout().ok(), buf: [0; 1024], len: 0 }
    }

    /// Appends bytes, flushing first when they would not fit.
    pub fn bytes(&mut self, b: &[u8]) {
        if self.len + b.len() > self.buf.len() {
            self.flush();
        }
        if b.len() > self.buf.len() {
            if let Some(s) = self.stream.as_mut() {
                let _ = s.write_all(b);
            }
            return;
        }
        if let Some(dst) = self.buf.get_mut(self.len..self.len + b.len()) {
            dst.copy_from_slice(b);
            self.len += b.len();
        }
    }

    /// Appends a string.
    pub fn str(&mut self, s: &str) {
        self.bytes(s.as_bytes());
    }

    /// Appends `0x` and `digits` lower-case hex digits of `v` (the golden-file format).
    pub fn hex(&mut self, v: u32, digits: u32) {
        let mut b = [0u8; 10];
        b[0] = b'0';
        b[1] = b'x';
        let mut i = 0;
        while i < digits {
            let nibble = (v >> (4 * (digits - 1 - i))) & 0xf;
            b[2 + i as usize] = b"0123456789abcdef"[nibble as usize];
            i += 1;
        }
        self.bytes(&b[..2 + digits as usize]);
    }

    /// Appends a count in tenths as a decimal with one digit after the point (`17189`:
    /// `1718.9`), as the instruction counts print.
    pub fn tenths(&mut self, tenths: u64) {
        self.dec(tenths / 10);
        self.str(".");
        self.dec(tenths % 10);
    }

    /// Appends an unsigned decimal number.
    pub fn dec(&mut self, mut v: u64) {
        let mut b = [0u8; 20];
        let mut i = b.len();
        loop {
            i -= 1;
            b[i] = b'0' + (v % 10) as u8;
            v /= 10;
            if v == 0 {
                break;
            }
        }
        self.bytes(&b[i..]);
    }

    /// Appends a new line.
    pub fn nl(&mut self) {
        self.bytes(b"\n");
    }

    /// Writes the buffered bytes to the host.
    pub fn flush(&mut self) {
        if let (Some(s), Some(b)) = (self.stream.as_mut(), self.buf.get(..self.len)) {
            let _ = s.write_all(b);
        }
        self.len = 0;
    }
}

/// Ends the QEMU run: exit status 0 (`ok`) or 1.
pub fn exit(ok: bool) -> ! {
    debug::exit(if ok { debug::EXIT_SUCCESS } else { debug::EXIT_FAILURE });
    // Only reached under a debugger that resumes after the exit request.
    loop {
        cortex_m::asm::bkpt();
    }
}

/// The target this firmware was compiled for (`rustc --print cfg` shows no CPU features
/// for these targets, so it is told apart by float ABI and atomics).
pub fn target_name() -> &'static str {
    if cfg!(target_abi = "eabihf") {
        "thumbv7em-none-eabihf"
    } else if cfg!(target_has_atomic = "32") {
        "thumbv7m-none-eabi"
    } else {
        "thumbv6m-none-eabi"
    }
}

/// Prints the panic on the host's stdout and exits with status 1.
#[panic_handler]
fn panic(info: &PanicInfo) -> ! {
    if let Ok(mut s) = hio::hstdout() {
        use core::fmt::Write;
        let _ = writeln!(s, "\nneedle-firmware PANIC: {info}");
    }
    exit(false)
}
