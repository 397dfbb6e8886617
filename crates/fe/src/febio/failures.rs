//! Why a pose could not be solved, by class, from the logs its failed FEBio attempts
//! left in its work folder (`failed-attempt-<n>.log`, kept by the campaign; issue 42:
//! the failed attempts by class, where and at which depth). `needle fe status` shows the
//! summary in its cause column. The classes and the summary are the set's
//! (`needle_set::failures`): the fitter reads them from a pose's partial record.

use super::logs::parse_run_log;
pub use needle_set::failures::{class_of, failures_from_record, summary, AttemptFailure};
use std::path::Path;

/// The smallest "residual" norm (the current one, rooted) of the last time step of `log`
/// that failed to converge.
fn least_residual_of_last_failure(log: &str) -> Option<f64> {
    let end = log.rfind("failed to converge at time")?;
    let step = log.get(..end)?;
    let start = step.rfind("===== beginning time step").unwrap_or(0);
    step.get(start..)?
        .lines()
        .filter_map(|l| {
            let mut w = l.split_whitespace();
            (w.next() == Some("residual")).then(|| w.nth(1).and_then(|v| v.parse::<f64>().ok())).flatten()
        })
        .filter(|v| v.is_finite() && *v >= 0.0)
        .reduce(f64::min)
        .map(f64::sqrt)
}

/// Read `failed-attempt-<n>.log` (n = 1, 2, ...) in `work_dir`.
pub fn read_failures(work_dir: &Path) -> Vec<AttemptFailure> {
    let mut out = Vec::new();
    for attempt in 1..=32u32 {
        let Ok(text) = std::fs::read_to_string(work_dir.join(format!("failed-attempt-{attempt}.log"))) else { continue };
        let run = parse_run_log(&text);
        let failed_at = text
            .lines()
            .rev()
            .find_map(|l| l.trim().strip_prefix("------- failed to converge at time :"))
            .and_then(|t| t.trim().parse::<f64>().ok());
        out.push(AttemptFailure {
            attempt,
            class: class_of(run.cause.as_deref()),
            depth_mm: failed_at.unwrap_or(run.last_time),
            cause: run.cause,
            least_residual_n: least_residual_of_last_failure(&text),
        });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    const BOX: &str = " *************************************************************************\n *                                ERROR                                  *\n";

    #[test]
    fn failed_attempts_are_classed_with_their_depths() {
        let d = tempfile::tempdir().expect("tempdir");
        let log = |n: u32, body: &str| std::fs::write(d.path().join(format!("failed-attempt-{n}.log")), body).expect("write");
        log(1, &format!(" ------- converged at time : 0.6\n{BOX} * 2 negative jacobians detected.  *\n ***\n\n ------- failed to converge at time : 0.863\n E R R O R   T E R M I N A T I O N\n"));
        let newton = "===== beginning time step 9 : 5.22 =====\n\t   residual            8.5e-08    4.0e-12    8.5e-11 \n\t   residual            8.5e-08    2.5e-11    8.5e-11 \n";
        log(2, &format!(" ------- converged at time : 5.1\n\t   residual  1 1e-20 1\n{newton}{BOX} * Max nr of reformations reached.  *\n ***\n\n ------- failed to converge at time : 5.22\n E R R O R   T E R M I N A T I O N\n"));
        log(4, " ------- converged at time : 1.5\n");
        let f = read_failures(d.path());
        let got: Vec<(u32, &str, f64)> = f.iter().map(|f| (f.attempt, f.class, f.depth_mm)).collect();
        assert_eq!(got, [(1, "negative jacobian", 0.863), (2, "max reformations", 5.22), (4, "stopped", 1.5)]);
        let s = summary(&f, "mm");
        assert_eq!(
            s,
            "3 failed attempt(s), furthest 5.22 mm: max reformations x1 (5.22 mm; least residual 2.0e-6 N); negative jacobian x1 (0.86 mm); stopped x1 (1.5 mm)"
        );
        // the failing step's own iterations only (not the converged step's 1e-20 before it)
        assert_eq!(f.iter().map(|f| f.least_residual_n.map(|r| (r * 1e6).round())).collect::<Vec<_>>(), [None, Some(2.0), None]);
        assert_eq!(summary(&[], "mm"), "");
        assert!(summary(&f, "s").starts_with("3 failed attempt(s), furthest 5.22 s: max reformations x1 (5.22 s; least residual 2.0e-6 N)"));
    }

    #[test]
    fn a_partial_record_is_classed_like_the_logs() {
        // the record of fe/mesh/fine/centre.partial.toml's kind, two attempts
        let record = "febio4 exit code 1 after 16 of 20 steps (t = 5.04373 mm), 45 time steps, 31 retries, 478.4 s, continued 1 time(s) from the last converged must point (4.8 mm): Negative jacobian detected. (failed to converge at time : 5.04374) (kept as failed-attempt-1.*); retry 1 (first increment 1): febio4 exit code 1 after 13 of 20 steps (t = 4.18753 mm), 30 time steps, 23 retries, 322.7 s: Max nr of reformations reached. (failed to converge at time : 4.18754) (kept as failed-attempt-2.*); retry 2 (first increment 0.25): febio4 interrupted (killed) after 16 of 20 steps (t = 4.8 mm), 42 time steps (kept as failed-attempt-3.*)";
        let f = failures_from_record(record);
        let got: Vec<(u32, &str, f64)> = f.iter().map(|f| (f.attempt, f.class, f.depth_mm)).collect();
        assert_eq!(got, [(1, "negative jacobian", 5.04374), (2, "max reformations", 4.18754), (3, "stopped", 4.8)]);
        assert!(failures_from_record("").is_empty());
    }
}
