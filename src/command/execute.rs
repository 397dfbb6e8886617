//! [`execute`]: a [`Command`] applied to a [`LoopCore`], and the reply line.
use super::{mode_word, Command, FrameError, REPLY_MAX};
use crate::control::LoopCore;
use crate::model_info;
use core::fmt::Write;

/// A reply line, `\n` included.
pub type Reply = heapless::String<REPLY_MAX>;

/// Runs `cmd` on the loop `core` (`dropped`: the telemetry overflow count for `STATUS`)
/// and returns its reply. Only `LIMIT <mN>` (when in range) and `MODE SAT|RAMP` change
/// the loop; a refused command changes nothing.
pub fn execute<const N: usize>(cmd: Command, core: &mut LoopCore<N>, dropped: u32) -> Reply {
    let mut r = Reply::new();
    let written = match cmd {
        Command::Ping => r.write_str("OK PONG\n"),
        Command::Status => {
            let s = core.last();
            let c = core.config();
            writeln!(
                r,
                "OK STATUS tick={} flags={:#06x} model={:#04x} limit_mn={} mode={} dropped={}",
                s.tick,
                s.flags.bits(),
                s.model.bits(),
                millinewtons(c.force_limit_n),
                mode_word(c.over_limit),
                dropped
            )
        }
        Command::Model => writeln!(
            r,
            "OK MODEL set={} fitted={} fe_sha256={} x_mm={} z_mm={} theta_deg={} depth_mm={}",
            model_info::SET.get(..32).unwrap_or(model_info::SET),
            u8::from(model_info::FITTED),
            model_info::FE_SHA256.get(..16).unwrap_or(model_info::FE_SHA256),
            model_info::X_MAX_MM as u32,
            model_info::Z_MAX_MM as u32,
            model_info::THETA_MAX_DEG as u32,
            model_info::DEPTH_MAX_MM as u32
        ),
        Command::GetLimit => limit_reply(&mut r, core),
        Command::SetLimit { limit_mn } => {
            #[allow(clippy::cast_precision_loss)] // <= 9 digits: exact below 2^24, else nearest
            let limit_n = limit_mn as f32 / 1000.0;
            if limit_mn == 0 || core.set_force_limit_n(limit_n).is_err() {
                return range_reply(core);
            }
            limit_reply(&mut r, core)
        }
        Command::GetMode => writeln!(r, "OK MODE {}", mode_word(core.config().over_limit)),
        Command::SetMode(m) => {
            core.set_over_limit(m);
            writeln!(r, "OK MODE {}", mode_word(m))
        }
    };
    if written.is_err() {
        return fixed("ERR INTERNAL reply too long\n");
    }
    r
}

/// The reply to a refused frame: `ERR <CODE> <text>`.
#[must_use]
pub fn error_reply(e: FrameError) -> Reply {
    let mut r = Reply::new();
    let text = match e {
        FrameError::Oversize => "frame longer than 32 bytes",
        FrameError::Malformed(why) => why,
        FrameError::Unknown => "no such command",
        FrameError::Range => "value out of range",
    };
    if writeln!(r, "ERR {} {}", e.code(), text).is_err() {
        return fixed("ERR INTERNAL reply too long\n");
    }
    r
}

/// The reply to what a [`FrameReader`](super::FrameReader) or [`parse`](super::parse)
/// returned: [`execute`] for a command, [`error_reply`] for a refused frame.
pub fn respond<const N: usize>(frame: Result<Command, FrameError>, core: &mut LoopCore<N>, dropped: u32) -> Reply {
    match frame {
        Ok(cmd) => execute(cmd, core, dropped),
        Err(e) => error_reply(e),
    }
}

fn limit_reply<const N: usize>(r: &mut Reply, core: &LoopCore<N>) -> core::fmt::Result {
    writeln!(r, "OK LIMIT limit_mn={}", millinewtons(core.config().force_limit_n))
}

fn range_reply<const N: usize>(core: &LoopCore<N>) -> Reply {
    let mut r = Reply::new();
    let max = millinewtons(core.config().force_limit_max_n);
    if writeln!(r, "ERR RANGE limit_mn must be 1..={max}").is_err() {
        return fixed("ERR RANGE\n");
    }
    r
}

/// `n` N in mN, rounded half up (saturating).
fn millinewtons(n: f32) -> u32 {
    (n * 1000.0 + 0.5) as u32
}

fn fixed(s: &str) -> Reply {
    let mut r = Reply::new();
    let _ = r.push_str(s);
    r
}
