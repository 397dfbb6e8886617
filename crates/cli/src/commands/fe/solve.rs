//! How each pose is solved (`needle fe run` and the array tasks' `fe run-one`).
use clap::Args;
use needle_fe::campaign::{self, RunOptions};
use std::time::Duration;

/// How each pose is solved (shared by `fe run` and the array tasks' `fe run-one`).
#[derive(Args, Debug)]
// The fields' doc comments are the --help text, written for the terminal: <set>, <pose>
// and [section] are placeholders and campaign.toml sections there, not HTML or links.
#[allow(rustdoc::invalid_html_tags, rustdoc::broken_intra_doc_links)]
pub struct SolveArgs {
    /// Rerun the selected poses even when their results are up to date; an interrupted
    /// pose starts afresh instead of resuming.
    #[arg(long)]
    pub force: bool,
    /// Do not run again a pose whose attempts all failed with the same spec, engine and
    /// mesh (its <out>/.work/<pose>/progress.toml says so): report it failed with the
    /// recorded failures. For a long campaign resumed in pieces.
    #[arg(long, conflicts_with = "force")]
    pub skip_failed: bool,
    /// Keep the work folder (<out>/.work/<pose>: solver input and logs) of successful
    /// runs too; failed runs always keep theirs.
    #[arg(long)]
    pub keep_work: bool,
    /// Wall-clock limit of one solver attempt, seconds; a longer attempt is killed and counted failed.
    #[arg(long, value_name = "S", allow_negative_numbers = true, value_parser = positive_seconds)]
    pub timeout_s: Option<f64>,
    /// Seconds without solver output (log, result files) after which a job is killed as stalled.
    #[arg(long, value_name = "S", default_value_t = campaign::DEFAULT_STALL.as_secs_f64(), allow_negative_numbers = true, value_parser = positive_seconds)]
    pub stall_s: f64,
}

/// The solve options of `a` applied to `opts`.
pub fn with_solve(opts: RunOptions, a: &SolveArgs) -> RunOptions {
    RunOptions {
        force: a.force,
        skip_failed: a.skip_failed,
        keep_work: a.keep_work,
        timeout: a.timeout_s.map(Duration::from_secs_f64),
        stall: Some(Duration::from_secs_f64(a.stall_s)),
        ..opts
    }
}

/// A duration in seconds on the command line: finite and > 0 (at most 30 days).
fn positive_seconds(text: &str) -> Result<f64, String> {
    let v: f64 = text.trim().parse().map_err(|_| format!("{text:?} is not a number of seconds"))?;
    if v.is_finite() && v > 0.0 && v <= 30.0 * 86_400.0 {
        Ok(v)
    } else {
        Err(format!("{v} s: must be > 0 s and at most 30 days (2592000 s)"))
    }
}
