//! Reading what `febio4` writes: the rigid body's reaction log (`rigid_body_data`) and
//! the run log (time steps, iterations, how it terminated).

use anyhow::{bail, Context, Result};
use needle_contract::COMPONENT_COUNT;

/// One record of the rigid-body log: the time and the six values of one body.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RigidRecord {
    /// Time t of the record (t = depth in mm in the campaign's inputs).
    pub time: f64,
    /// Fx, Fy, Fz (N), Mx, My, Mz (N·mm) as FEBio logs them.
    pub values: [f64; COMPONENT_COUNT],
}

/// Parse a `rigid_body_data` log with `data="Fx;Fy;Fz;Mx;My;Mz"`: blocks of `*Step`,
/// `*Time = t`, `*Data = ...` header lines, then one line `id<delim>v1<delim>...v6` per
/// body. A line cut short by a running solver at the end is ignored.
///
/// # Errors
/// A data line before any `*Time`, a number that does not parse (with the line number).
pub fn parse_rigid_log(text: &str) -> Result<Vec<RigidRecord>> {
    let mut out = Vec::new();
    let mut time: Option<f64> = None;
    let lines: Vec<&str> = text.lines().collect();
    for (i, raw) in lines.iter().enumerate() {
        let line = raw.trim();
        if line.is_empty() {
            continue;
        }
        if let Some(rest) = line.strip_prefix('*') {
            if let Some((key, value)) = rest.split_once('=') {
                if key.trim().eq_ignore_ascii_case("time") {
                    let t: f64 = value.trim().parse().with_context(|| format!("line {}: time {:?}", i + 1, value.trim()))?;
                    time = Some(t);
                }
            }
            continue;
        }
        let fields: Vec<&str> = line.split(|c: char| c == ',' || c.is_whitespace()).filter(|f| !f.is_empty()).collect();
        let last_line = i + 1 == lines.len() && !text.ends_with('\n');
        if fields.len() != 7 {
            if last_line {
                break;
            }
            bail!("line {}: {} fields, expected the body id and 6 values: {line:?}", i + 1, fields.len());
        }
        let Some(t) = time else { bail!("line {}: data before any *Time line", i + 1) };
        let mut values = [0.0f64; COMPONENT_COUNT];
        for (k, f) in fields.iter().skip(1).enumerate() {
            values[k] = match f.parse::<f64>() {
                Ok(v) => v,
                Err(_) if last_line => return Ok(out),
                Err(_) => bail!("line {}: value {} = {f:?} is not a number", i + 1, k + 1),
            };
        }
        out.push(RigidRecord { time: t, values });
    }
    Ok(out)
}

/// What the run log says.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RunLog {
    /// `N O R M A L   T E R M I N A T I O N` was printed.
    pub normal_termination: bool,
    /// `E R R O R   T E R M I N A T I O N` was printed.
    pub error_termination: bool,
    /// Converged time steps ("converged at time" lines).
    pub time_steps: u32,
    /// Equilibrium (Newton) iterations of the converged and failed attempts, from the
    /// "equilibrium iterations" summaries, else counted from the per-step reports.
    pub iterations: u32,
    /// Time steps retried with a smaller step ("Retrying time step" lines).
    pub retries: u32,
    /// Iterations FEBio declared converged by its absolute residual floor
    /// (`min_residual`; its warning "No force acting on the system", which a system
    /// without any force prints too).
    pub floor_accepted: u32,
    /// The last time reached ("converged at time : t").
    pub last_time: f64,
    /// FEBio's own words on why it stopped: the last `*** Error` / `ERROR` /
    /// "negative jacobian" / "max nr of reformations" / "Failed" line, when there is one.
    pub cause: Option<String>,
}

/// Read FEBio's screen output or log file.
pub fn parse_run_log(text: &str) -> RunLog {
    let mut r = RunLog::default();
    let mut iters_summary: Option<u32> = None;
    let mut iters_counted = 0u32;
    let mut in_error_box = false;
    let mut boxed: Option<String> = None;
    let mut last_failed: Option<String> = None;
    for line in text.lines() {
        let l = line.trim();
        // inside FEBio's warning box
        if l.contains("No force acting on the system") {
            r.floor_accepted += 1;
        }
        // FEBio's error box: "*   ERROR   *", then "* <message> *" lines, then a row of '*'
        if l.starts_with('*') && l.ends_with('*') && l.len() > 2 {
            let inner = l.trim_matches('*').trim();
            if inner == "ERROR" {
                in_error_box = true;
            } else if in_error_box && !inner.is_empty() {
                boxed = Some(inner.to_string());
            } else if inner.is_empty() {
                in_error_box = false;
            }
            continue;
        }
        in_error_box = false;
        if l.starts_with("------- failed to converge at time") {
            last_failed = Some(l.trim_start_matches('-').trim().to_string());
        }
        if l.contains("N O R M A L   T E R M I N A T I O N") {
            r.normal_termination = true;
        } else if l.contains("E R R O R   T E R M I N A T I O N") {
            r.error_termination = true;
        } else if let Some(rest) = l.strip_prefix("------- converged at time :") {
            r.time_steps += 1;
            if let Ok(t) = rest.trim().parse::<f64>() {
                r.last_time = t;
            }
        } else if l.starts_with("Retrying time step") {
            r.retries += 1;
        } else if l.starts_with("Total number of equilibrium iterations") {
            if let Some(v) = l.rsplit(':').next().and_then(|v| v.trim().parse::<u32>().ok()) {
                iters_summary = Some(iters_summary.unwrap_or(0) + v);
            }
        } else if l.starts_with("stiffness updates") || l.starts_with("Nonlinear solution status") {
            // per-step reports; counted below via "equilibrium iterations"
        } else if l.starts_with("equilibrium iterations") {
            if let Some(v) = l.rsplit('=').next().and_then(|v| v.trim().parse::<u32>().ok()) {
                iters_counted += v;
            }
        }
        let lower = l.to_ascii_lowercase();
        if lower.contains("fatal error") || (lower.contains("error") && lower.contains("reading")) {
            r.cause = Some(l.to_string());
        }
    }
    // the last boxed error (e.g. "Max nr of reformations reached.") with where it failed
    if r.cause.is_none() {
        r.cause = match (boxed, last_failed) {
            (Some(b), Some(f)) => Some(format!("{b} ({f})")),
            (b, f) => b.or(f),
        };
    }
    r.iterations = iters_summary.unwrap_or(iters_counted);
    r
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rigid_log_blocks_and_a_cut_last_line() {
        let text = "*Title \n*Step  = 1\n*Time  = 0.3\n*Data  = Fx;Fy;Fz;Mx;My;Mz\n2,1,2,3,4,5,6\n*Step  = 2\n*Time  = 0.6\n*Data  = Fx;Fy;Fz;Mx;My;Mz\n2,-1e-3,2.5E-2,0,0,0,7\n*Step = 3\n*Time = 0.9\n2,1,2";
        let r = parse_rigid_log(text).expect("parse");
        assert_eq!(r.len(), 2);
        assert_eq!(r[0], RigidRecord { time: 0.3, values: [1.0, 2.0, 3.0, 4.0, 5.0, 6.0] });
        assert_eq!(r[1].time, 0.6);
        assert_eq!(r[1].values[1], 0.025);
        assert!(parse_rigid_log("2,1,2,3,4,5,6\n").is_err(), "data before *Time");
        assert!(parse_rigid_log("*Time = 1\n2,1,2,x,4,5,6\n*Time = 2\n").is_err(), "bad number inside the file");
    }

    #[test]
    fn run_log_termination_and_counts() {
        let text = " ===== beginning time step 1 : 0.3 =====\n ------- converged at time : 0.3\n Retrying time step. Retry attempt 1 of max 5\n ------- converged at time : 0.6\n Total number of equilibrium iterations ............ : 17\n N O R M A L   T E R M I N A T I O N\n";
        let r = parse_run_log(text);
        assert!(r.normal_termination && !r.error_termination);
        assert_eq!((r.time_steps, r.iterations, r.retries, r.last_time, r.floor_accepted), (2, 17, 1, 0.6, 0));
        let floor = " *                               WARNING                                 *\n * No force acting on the system.                                        *\n";
        assert_eq!(parse_run_log(&format!("{text}{floor}{floor}")).floor_accepted, 2, "each acceptance by the residual floor");
        let bad = parse_run_log(
            " *************************************************************************\n *                                ERROR                                  *\n * 2 negative jacobians detected.                                        *\n *************************************************************************\n\n------- failed to converge at time : 0.3\n E R R O R   T E R M I N A T I O N\n",
        );
        assert!(bad.error_termination);
        assert_eq!(bad.cause.as_deref(), Some("2 negative jacobians detected. (failed to converge at time : 0.3)"));
    }
}
