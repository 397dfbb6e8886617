//! [`parse`]: one request line to a [`Command`].
use super::FrameError;
use crate::control::OverLimit;

/// A parsed request (see the frame format in [`crate::command`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum Command {
    /// `PING`.
    Ping,
    /// `STATUS`.
    Status,
    /// `MODEL`.
    Model,
    /// `LIMIT`.
    GetLimit,
    /// `LIMIT <mN>`.
    SetLimit {
        /// The new force limit, mN.
        limit_mn: u32,
    },
    /// `MODE`.
    GetMode,
    /// `MODE SAT` or `MODE RAMP`.
    SetMode(OverLimit),
}

/// Parses one request line, without its `\n` (a final `\r` is ignored).
///
/// # Errors
/// [`FrameError::Oversize`] when longer than [`FRAME_MAX`](super::FRAME_MAX),
/// [`FrameError::Malformed`] when not in the frame format, [`FrameError::Unknown`] for a
/// well-formed line with an unknown command. Never panics, for any bytes.
pub fn parse(line: &[u8]) -> Result<Command, FrameError> {
    let line = line.strip_suffix(b"\r").unwrap_or(line);
    if line.len() > super::FRAME_MAX {
        return Err(FrameError::Oversize);
    }
    if line.is_empty() {
        return Err(FrameError::Malformed("empty frame"));
    }
    if !line.iter().all(|b| (0x20..=0x7e).contains(b)) {
        return Err(FrameError::Malformed("byte outside printable ASCII"));
    }
    if line.first() == Some(&b' ') || line.last() == Some(&b' ') || line.windows(2).any(|w| w == b"  ") {
        return Err(FrameError::Malformed("words must be separated by one space"));
    }
    let mut words = line.split(|b| *b == b' ');
    let verb = words.next().unwrap_or_default();
    let arg = words.next();
    if words.next().is_some() {
        return Err(FrameError::Malformed("too many words"));
    }
    match (verb, arg) {
        (b"PING", None) => Ok(Command::Ping),
        (b"STATUS", None) => Ok(Command::Status),
        (b"MODEL", None) => Ok(Command::Model),
        (b"LIMIT", None) => Ok(Command::GetLimit),
        (b"LIMIT", Some(a)) => Ok(Command::SetLimit { limit_mn: decimal(a)? }),
        (b"MODE", None) => Ok(Command::GetMode),
        (b"MODE", Some(b"SAT")) => Ok(Command::SetMode(OverLimit::Saturate)),
        (b"MODE", Some(b"RAMP")) => Ok(Command::SetMode(OverLimit::RampToZero)),
        (b"MODE", Some(_)) => Err(FrameError::Malformed("MODE takes SAT or RAMP")),
        (b"PING" | b"STATUS" | b"MODEL", Some(_)) => Err(FrameError::Malformed("this command takes no argument")),
        _ => Err(FrameError::Unknown),
    }
}

/// A decimal integer of 1 to 9 digits.
fn decimal(word: &[u8]) -> Result<u32, FrameError> {
    if word.is_empty() || word.len() > 9 || !word.iter().all(u8::is_ascii_digit) {
        return Err(FrameError::Malformed("a number is 1 to 9 decimal digits"));
    }
    Ok(word.iter().fold(0u32, |n, d| n.wrapping_mul(10).wrapping_add(u32::from(d - b'0'))))
}
