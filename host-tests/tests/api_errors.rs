//! Every public error of the library says what is wrong in words (`Display`) and is a
//! `core::error::Error`, so `?` works into `Box<dyn Error>` / anyhow on the host (issue 18).

use needle_haptics::command::FrameError;
use needle_haptics::control::{ConfigError, PoseFault};

fn as_error<E: core::error::Error + 'static>(e: E) -> Box<dyn core::error::Error> {
    Box::new(e)
}

#[test]
fn public_errors_display_what_is_wrong() {
    let cases: Vec<(Box<dyn core::error::Error>, &str)> = vec![
        (as_error(ConfigError::Gain), "gain"),
        (as_error(ConfigError::ForceLimit), "force_limit_n"),
        (as_error(ConfigError::RampStep), "ramp_step_n"),
        (as_error(PoseFault::Stale), "stale"),
        (as_error(PoseFault::Missing), "missing"),
        (as_error(FrameError::Oversize), "32 bytes"),
        (as_error(FrameError::Malformed("no '='")), "MALFORMED: no '='"),
        (as_error(FrameError::Unknown), "no such command"),
        (as_error(FrameError::Range), "outside its range"),
    ];
    for (e, want) in cases {
        let text = e.to_string();
        assert!(text.contains(want), "{text:?} does not say {want:?}");
    }
}
