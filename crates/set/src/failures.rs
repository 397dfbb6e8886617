//! The failure classes an engine records for a pose it could not solve (issue 42): one
//! failed attempt, its class from the solver's words, the attempts of a pose's
//! `.partial.toml` record, the one-line summary `needle fe status` and the fitter show.
//! The engine (`needle_fe::febio::failures`) reads them from its logs; the fitter from the
//! record alone.

use std::collections::BTreeMap;

/// One failed attempt.
#[derive(Debug, Clone, PartialEq)]
pub struct AttemptFailure {
    /// Attempt number, 1-based (the ladder of `FebioBackend::attempts`).
    pub attempt: u32,
    /// The class: `negative jacobian`, `max reformations`, `diverged`, `stopped` (no
    /// error in the log: killed on a stall, timeout or Ctrl-C) or `other`.
    pub class: &'static str,
    /// Where it failed in the solver's time (depth in mm; s of a ramp-and-hold run,
    /// `Loading::time_unit`): FEBio's "failed to converge at time",
    /// else the last converged time.
    pub depth_mm: f64,
    /// FEBio's own words, when it gave any.
    pub cause: Option<String>,
    /// The smallest residual Newton reached in the time step that failed last, N (the
    /// root of FEBio's squared norm; from the log, `None` without one): where a stalled
    /// attempt stood against an absolute floor (`[solver.febio] retry_min_residual_n`).
    pub least_residual_n: Option<f64>,
}

/// The class of a failure from FEBio's words (`None`: no error stated).
pub fn class_of(cause: Option<&str>) -> &'static str {
    let Some(c) = cause.map(str::to_ascii_lowercase) else { return "stopped" };
    if c.contains("negative jacobian") {
        "negative jacobian"
    } else if c.contains("max nr of reformations") {
        "max reformations"
    } else if c.contains("diverg") {
        "diverged"
    } else {
        "other"
    }
}

/// The attempts of a pose's `.partial.toml` record (its `failure`: the campaign's
/// messages of every attempt, `"; retry "` between them), for a pose whose work folder
/// and its logs are gone: class from FEBio's words in each message (`stopped` when the
/// runner killed it: interrupted, timed out or stalled), depth from "failed to converge
/// at time" or else the message's `t = ... mm`.
pub fn failures_from_record(failure: &str) -> Vec<AttemptFailure> {
    failure
        .split("; retry ")
        .filter(|m| !m.trim().is_empty())
        .zip(1u32..)
        .map(|(m, attempt)| {
            let after = |key: &str| {
                m.rfind(key).and_then(|i| m.get(i + key.len()..)).and_then(|r| {
                    let num: String =
                        r.trim_start().chars().take_while(|c| c.is_ascii_digit() || *c == '.' || *c == 'e' || *c == '-').collect();
                    num.parse::<f64>().ok()
                })
            };
            let killed = m.contains("(killed)");
            AttemptFailure {
                attempt,
                class: if killed { "stopped" } else { class_of(Some(m)) },
                depth_mm: after("failed to converge at time :").or_else(|| after("(t =")).unwrap_or(0.0),
                cause: Some(m.trim().to_string()),
                least_residual_n: None,
            }
        })
        .collect()
}

/// One line: `5 failed attempt(s), furthest 5.22 mm: negative jacobian x3 (0.6, 0.86, 2.69 mm), max reformations x2 (...)`;
/// empty when there are none. `unit`: of the solver's time, `Loading::time_unit` (mm of
/// depth, s of a ramp-and-hold run).
pub fn summary(failures: &[AttemptFailure], unit: &str) -> String {
    if failures.is_empty() {
        return String::new();
    }
    let mut by_class: BTreeMap<&str, Vec<&AttemptFailure>> = BTreeMap::new();
    for f in failures {
        by_class.entry(f.class).or_default().push(f);
    }
    let furthest = failures.iter().map(|f| f.depth_mm).fold(0.0, f64::max);
    let classes: Vec<String> = by_class
        .iter()
        .map(|(c, fs)| {
            let depths = fs.iter().map(|f| format!("{}", (f.depth_mm * 100.0).round() / 100.0)).collect::<Vec<_>>().join(", ");
            let least: Vec<String> = fs.iter().filter_map(|f| f.least_residual_n).map(|r| format!("{r:.1e}")).collect();
            let stalled = if *c == "max reformations" && !least.is_empty() {
                format!("; least residual {} N", least.join(", "))
            } else {
                String::new()
            };
            format!("{c} x{} ({depths} {unit}{stalled})", fs.len())
        })
        .collect();
    format!("{} failed attempt(s), furthest {:.2} {unit}: {}", failures.len(), furthest, classes.join("; "))
}
