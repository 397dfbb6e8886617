//! The host link's commands: a line-based ASCII frame format, a fixed-capacity frame
//! reader and parser on `heapless` buffers, and replies.
//!
//! # Frame format
//!
//! A request is one line: printable ASCII (`0x20..=0x7e`), at most [`FRAME_MAX`] bytes,
//! ended by `\n` (a `\r` just before it is ignored). Words are separated by exactly one
//! space; no leading or trailing space. The first word is the command, upper case:
//!
//! | request | reply | effect |
//! | --- | --- | --- |
//! | `PING` | `OK PONG` | none |
//! | `STATUS` | `OK STATUS tick=<u32> flags=0x<hhhh> model=0x<hh> limit_mn=<u32> mode=<SAT\|RAMP> dropped=<u32>` | none |
//! | `MODEL` | `OK MODEL set=<name> fitted=<0\|1> fe_sha256=<16 hex> x_mm=<n> z_mm=<n> theta_deg=<n> depth_mm=<n>` | none |
//! | `LIMIT` | `OK LIMIT limit_mn=<u32>` | none |
//! | `LIMIT <mN>` | `OK LIMIT limit_mn=<u32>` | sets the force limit to `<mN>` / 1000 N |
//! | `MODE` | `OK MODE <SAT\|RAMP>` | none |
//! | `MODE SAT` / `MODE RAMP` | `OK MODE <SAT\|RAMP>` | sets [`OverLimit`] |
//!
//! `flags` are the last tick's [`LoopFlags`](crate::control::LoopFlags), `model` its
//! model [`Status`](crate::Status), `dropped` the telemetry overflow count; `set` is the
//! compiled-in coefficient set (at most 32 characters shown), `fe_sha256` the first 16
//! hex digits of its FE data hash, the domain in whole mm and degrees. `<mN>` is a
//! decimal integer of 1 to 9 digits (no sign).
//!
//! Every reply is one line `OK ...\n` or `ERR <CODE> <text>\n`, at most [`REPLY_MAX`]
//! bytes. A request that fails gets an `ERR` reply and changes nothing:
//!
//! | code | when |
//! | --- | --- |
//! | `OVERSIZE` | more than [`FRAME_MAX`] bytes before the `\n` (the rest of the line is discarded) |
//! | `MALFORMED` | empty line, a byte outside printable ASCII, bad spacing, wrong number of words, a number that is not 1-9 decimal digits, an unknown `MODE` value |
//! | `UNKNOWN` | a well-formed line whose command is not in the table |
//! | `RANGE` | `LIMIT` outside `1..=force_limit_max_n * 1000` mN |
mod execute;
mod parse;
mod reader;

pub use execute::{error_reply, execute, respond, Reply};
pub use parse::{parse, Command};
pub use reader::FrameReader;

use crate::control::OverLimit;

/// Longest request, in bytes before the `\n`.
pub const FRAME_MAX: usize = 32;
/// Longest reply, in bytes including the `\n`.
pub const REPLY_MAX: usize = 128;

/// Why a request was refused (the `ERR` code of its reply).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum FrameError {
    /// Longer than [`FRAME_MAX`].
    Oversize,
    /// Not in the frame format, with what is wrong.
    Malformed(&'static str),
    /// Well-formed, but no such command.
    Unknown,
    /// A value outside its range.
    Range,
}

impl core::fmt::Display for FrameError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::Oversize => write!(f, "OVERSIZE: request longer than {FRAME_MAX} bytes"),
            Self::Malformed(why) => write!(f, "MALFORMED: {why}"),
            Self::Unknown => f.write_str("UNKNOWN: no such command"),
            Self::Range => f.write_str("RANGE: a value outside its range"),
        }
    }
}

impl core::error::Error for FrameError {}

impl FrameError {
    /// The reply's code word.
    #[must_use]
    pub const fn code(self) -> &'static str {
        match self {
            Self::Oversize => "OVERSIZE",
            Self::Malformed(_) => "MALFORMED",
            Self::Unknown => "UNKNOWN",
            Self::Range => "RANGE",
        }
    }
}

/// The word of an [`OverLimit`] mode in the frame format.
#[must_use]
pub const fn mode_word(mode: OverLimit) -> &'static str {
    match mode {
        OverLimit::Saturate => "SAT",
        OverLimit::RampToZero => "RAMP",
    }
}
