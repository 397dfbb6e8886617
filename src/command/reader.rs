//! [`FrameReader`]: request lines from a byte stream, in a fixed-capacity buffer.
use super::{parse, Command, FrameError, FRAME_MAX};
use heapless::Vec;

/// Assembles request lines byte by byte (from a UART interrupt or a USB packet) in a
/// `heapless::Vec` of [`FRAME_MAX`] + 1 bytes (room for a `\r`).
///
/// A line longer than that is not kept: its bytes are discarded up to its `\n`, which
/// then yields [`FrameError::Oversize`].
#[derive(Debug, Default)]
pub struct FrameReader {
    buf: Vec<u8, { FRAME_MAX + 1 }>,
    oversize: bool,
}

impl FrameReader {
    /// An empty reader.
    #[must_use]
    pub const fn new() -> Self {
        Self { buf: Vec::new(), oversize: false }
    }

    /// Takes one byte; at a `\n`, the parsed line (or why it was refused) and the reader is
    /// empty again. `None` while a line is incomplete. Never panics, never allocates.
    pub fn push(&mut self, byte: u8) -> Option<Result<Command, FrameError>> {
        if byte == b'\n' {
            let result = if self.oversize { Err(FrameError::Oversize) } else { parse(&self.buf) };
            self.buf.clear();
            self.oversize = false;
            return Some(result);
        }
        if !self.oversize && self.buf.push(byte).is_err() {
            self.oversize = true;
            self.buf.clear();
        }
        None
    }
}
