//! The CalculiX engine: the deck ([`deck`]), the `.dat` reader ([`dat`]), the reduction of
//! the needle's reactions ([`reactions`]) and [`CcxBackend`] behind the campaign's
//! `Backend` trait; here, running `ccx`: finding the binary, its version, one job in a
//! work folder with one thread, a wall-clock timeout, and the job's `.sta` status file
//! (increments, iterations, and the last completed step while the job runs).

pub mod backend;
pub mod dat;
pub mod deck;
pub mod reactions;

pub use backend::CcxBackend;

use crate::process;
use anyhow::{bail, Context, Result};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Duration;

/// Environment variable that names the `ccx` binary to use instead of the one on `PATH`.
pub const CCX_ENV: &str = "NEEDLE_CCX";

/// Find the `ccx` binary: `$NEEDLE_CCX` if set, else the first `ccx` on `PATH`.
///
/// # Errors
/// `$NEEDLE_CCX` names a file that does not exist, or there is no `ccx` on `PATH`
/// ("ccx not found: apt-get install calculix-ccx").
pub fn find_ccx() -> Result<PathBuf> {
    if let Some(p) = std::env::var_os(CCX_ENV).filter(|p| !p.is_empty()) {
        let p = PathBuf::from(p);
        if p.is_file() {
            return Ok(p);
        }
        // a bare name: look it up on PATH
        if p.components().count() == 1 {
            if let Some(found) = which(&p) {
                return Ok(found);
            }
        }
        bail!("ccx not found: {CCX_ENV}={} is not a file", p.display());
    }
    which(Path::new("ccx")).context("ccx not found: apt-get install calculix-ccx (or set NEEDLE_CCX to the binary)")
}

/// The version of a `ccx` binary, e.g. `"2.20"`, from `ccx -v` ("This is Version 2.20").
/// `ccx -v` exits with a non-zero status; only its output is read.
///
/// # Errors
/// The binary cannot be started, or its output has no "Version" word.
pub fn ccx_version(ccx: &Path) -> Result<String> {
    let out =
        Command::new(ccx).arg("-v").stdin(Stdio::null()).output().with_context(|| format!("{}: cannot run `ccx -v`", ccx.display()))?;
    let text = format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    parse_version(&text).with_context(|| format!("{} -v: no version in its output {:?}", ccx.display(), text.trim()))
}

/// The version number in `ccx -v` output ("This is Version 2.20" -> "2.20").
pub fn parse_version(text: &str) -> Option<String> {
    let mut words = text.split_whitespace();
    while let Some(w) = words.next() {
        if w.eq_ignore_ascii_case("version") {
            return words.next().map(|v| v.trim_end_matches([',', '.']).to_string());
        }
    }
    None
}

use crate::process::which;
pub use crate::process::{interrupted, stop_jobs_on_termination, tail, ExitKind, EXIT_INTERRUPTED, LOG_TAIL_LINES};

/// Increments and iterations of a job, from its `.sta` file.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct StaSummary {
    /// Converged increments, all steps.
    pub increments: u32,
    /// Newton iterations, all attempts (cut-back attempts included).
    pub iterations: u32,
    /// Attempts that did not converge and were cut back (lines marked `U`).
    pub cutbacks: u32,
    /// Total time at the end of the last converged increment.
    pub total_time: f64,
}

impl StaSummary {
    /// Steps completed when step k ends at total time k (as in the campaign's decks).
    pub fn steps_done(&self) -> u32 {
        let t = self.total_time + 1e-6;
        if t.is_finite() && t >= 1.0 {
            t.floor().min(f64::from(u32::MAX)) as u32
        } else {
            0
        }
    }
}

/// Read a `.sta` file's text. Each data line is
/// `STEP INC ATT ITRS TOT_TIME STEP_TIME INC_TIME`; an attempt that did not converge has
/// its ATT suffixed with `U`. Lines that are not data (headers, a line being written) are
/// skipped.
pub fn parse_sta(text: &str) -> StaSummary {
    let mut s = StaSummary::default();
    for line in text.lines() {
        let f: Vec<&str> = line.split_whitespace().collect();
        let [step, inc, att, itrs, tot, _step_time, _inc_time] = f.as_slice() else {
            continue;
        };
        if step.parse::<u32>().is_err() || inc.parse::<u32>().is_err() {
            continue;
        }
        let (att, failed) = match att.strip_suffix(['U', 'u']) {
            Some(a) => (a, true),
            None => (*att, false),
        };
        let (Ok(_), Ok(itrs), Some(tot)) = (att.parse::<u32>(), itrs.parse::<u32>(), dat::parse_fortran(tot)) else {
            continue;
        };
        s.iterations += itrs;
        if failed {
            s.cutbacks += 1;
        } else {
            s.increments += 1;
            s.total_time = tot;
        }
    }
    s
}

/// The `.sta` file of job `job` in `work_dir`.
pub fn sta_path(work_dir: &Path, job: &str) -> PathBuf {
    work_dir.join(format!("{job}.sta"))
}

/// Steps completed so far by a running (or finished) job: for progress display. 0 when
/// the `.sta` file does not exist yet or cannot be read.
pub fn steps_done(work_dir: &Path, job: &str) -> u32 {
    std::fs::read_to_string(sta_path(work_dir, job)).map(|t| parse_sta(&t).steps_done()).unwrap_or(0)
}

/// The outcome of one ccx job.
#[derive(Debug, Clone)]
pub struct JobResult {
    /// How the process ended.
    pub exit: ExitKind,
    /// Wall-clock time of the process.
    pub wall: Duration,
    /// Increments and iterations from the `.sta` file.
    pub sta: StaSummary,
    /// The file holding ccx's stdout and stderr.
    pub log_path: PathBuf,
    /// The last [`LOG_TAIL_LINES`] lines of the log.
    pub log_tail: String,
    /// Why ccx stopped, in its own words, when it said so: the last line of SPOOLES's
    /// `spooles.out` (e.g. "matrix found to be singular") or the last `*ERROR` line of
    /// the log.
    pub cause: Option<String>,
    /// ccx's peak resident memory, MiB ([`process::Finished::peak_rss_mib`]).
    pub peak_rss_mib: f64,
}

impl JobResult {
    /// Whether ccx exited with status 0 (the caller still checks the output).
    pub fn success(&self) -> bool {
        self.exit == ExitKind::Code(0)
    }
}

/// Run `ccx -i <job>` in `work_dir` (which holds `<job>.inp`) on one thread
/// (`OMP_NUM_THREADS=1`, `CCX_NPROC_*=1`), stdout and stderr to `<job>.log` in the same
/// folder. With a `timeout`, the process is killed when it runs longer (wall clock); with
/// a `stall` limit, when none of its log, `.sta` and `.cvg` files has grown for that long
/// (ccx 2.20 can spin without output at the start of a step: on `tz+15` a profile of the
/// spinning process showed SPOOLES's pivot search, `Chv_maxabsInColumn11` and
/// `Chv_maxabsInRow11`, taking all the time; that is the known endless loop of SPOOLES's
/// threshold pivoting on a matrix holding NaN, so a stall is a failed run, not a slow one).
///
/// # Errors
/// The log file cannot be created, or ccx cannot be started or waited for. A job that
/// starts and then fails is not an error: see [`JobResult::exit`].
pub fn run_job(ccx: &Path, work_dir: &Path, job: &str, timeout: Option<Duration>, stall: Option<Duration>) -> Result<JobResult> {
    let log_path = work_dir.join(format!("{job}.log"));
    // the files of an earlier attempt in this folder (a failed one, or the same attempt of
    // a campaign killed while it ran: `crate::resume` reruns it from its start) would be
    // taken for this one's if ccx stopped before rewriting them
    let spooles_path = work_dir.join("spooles.out");
    for p in [spooles_path.clone(), sta_path(work_dir, job), work_dir.join(format!("{job}.dat")), work_dir.join(format!("{job}.cvg"))] {
        match std::fs::remove_file(&p) {
            Ok(()) => {}
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
            Err(e) => return Err(e).with_context(|| format!("{}: cannot remove the earlier attempt's", p.display())),
        }
    }
    let mut cmd = Command::new(ccx);
    cmd.arg("-i")
        .arg(job)
        .env("OMP_NUM_THREADS", "1")
        .env("CCX_NPROC_EQUATION_SOLVER", "1")
        .env("CCX_NPROC_STIFFNESS", "1")
        .env("CCX_NPROC_RESULTS", "1");
    let progress_files = [sta_path(work_dir, job), work_dir.join(format!("{job}.cvg"))];
    let done = process::run(cmd, work_dir, &log_path, &progress_files, timeout, stall)?;
    let (exit, wall, log_text, log_path, peak_rss_mib) = (done.exit, done.wall, done.log_text, done.log_path, done.peak_rss_mib);
    let sta = std::fs::read_to_string(sta_path(work_dir, job)).map(|t| parse_sta(&t)).unwrap_or_default();
    let mut log_tail = tail(&log_text, LOG_TAIL_LINES);
    // SPOOLES reports a singular matrix in its own file, not on stdout (ccx then exits 255)
    let spooles = std::fs::read_to_string(&spooles_path).unwrap_or_default();
    if !spooles.trim().is_empty() {
        log_tail.push_str("\nspooles.out: ");
        log_tail.push_str(&tail(&spooles, 3).trim_start().replace('\n', " / "));
    }
    let cause = stated_cause(&log_text, &spooles);
    Ok(JobResult { exit, wall, sta, log_tail, log_path, cause, peak_rss_mib })
}

/// ccx's own statement of why it stopped: the last non-blank line of `spooles.out`, else
/// the last line of the log holding `*ERROR`.
pub fn stated_cause(log_text: &str, spooles: &str) -> Option<String> {
    let last = |t: &str, want: fn(&str) -> bool| t.lines().map(str::trim).rfind(|l| want(l)).map(str::to_string);
    last(spooles, |l| !l.is_empty()).or_else(|| last(log_text, |l| l.contains("*ERROR")))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn version() {
        assert_eq!(parse_version("\nThis is Version 2.20\n\n").as_deref(), Some("2.20"));
        assert_eq!(parse_version("nothing"), None);
    }

    /// A stand-in for ccx (a shell script): `silent` writes a line then sleeps silently.
    fn fake_ccx(dir: &Path, body: &str) -> PathBuf {
        use std::os::unix::fs::PermissionsExt;
        let p = dir.join("fake-ccx");
        std::fs::write(&p, format!("#!/bin/sh\n{body}\n")).expect("write fake ccx");
        std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o755)).expect("chmod");
        p
    }

    #[test]
    fn a_silent_job_is_killed_as_stalled_and_a_talking_one_is_not() {
        let d = tempfile::tempdir().expect("tempdir");
        let silent = fake_ccx(d.path(), "echo started; sleep 30");
        let start = std::time::Instant::now();
        let r = run_job(&silent, d.path(), "job", None, Some(Duration::from_millis(700))).expect("run");
        assert_eq!(r.exit, ExitKind::Stalled(Duration::from_millis(700)));
        assert!(start.elapsed() < Duration::from_secs(10), "killed long before the script's 30 s");
        assert_eq!(r.log_tail, "started");

        // a solver failure reported in spooles.out reaches the log tail
        let singular = fake_ccx(d.path(), "echo factoring; printf '\\n\\n matrix found to be singular\\n' > spooles.out; exit 255");
        let r = run_job(&singular, d.path(), "job", None, None).expect("run");
        assert_eq!(r.exit, ExitKind::Code(255));
        assert_eq!(r.log_tail, "factoring\nspooles.out: matrix found to be singular");
        assert_eq!(r.cause.as_deref(), Some("matrix found to be singular"));

        // the next attempt in the same folder does not inherit that spooles.out
        let error = fake_ccx(d.path(), "echo ' *ERROR in checkslavedof: bad node'; echo done; exit 201");
        let r = run_job(&error, d.path(), "job", None, None).expect("run");
        assert_eq!(r.exit, ExitKind::Code(201));
        assert!(!d.path().join("spooles.out").exists());
        assert_eq!(r.cause.as_deref(), Some("*ERROR in checkslavedof: bad node"));

        // a campaign killed in the middle of an attempt left its .sta and .dat: the rerun
        // of the attempt (crate::resume) does not take them for its own
        std::fs::write(sta_path(d.path(), "job"), "  1  1  1  3  1.0  1.0  1.0\n").expect("the killed attempt's sta");
        std::fs::write(d.path().join("job.dat"), "the killed attempt's").expect("dat");
        assert_eq!(steps_done(d.path(), "job"), 1, "the killed attempt had done a step");
        let r = run_job(&fake_ccx(d.path(), "echo starting; exit 0"), d.path(), "job", None, None).expect("run");
        assert_eq!((r.exit, r.sta.steps_done()), (ExitKind::Code(0), 0));
        assert!(!d.path().join("job.dat").exists());

        // prints every 0.1 s for 1.5 s: never silent for 0.7 s, so it runs to its end
        let talking = fake_ccx(d.path(), "i=0; while [ $i -lt 15 ]; do echo $i; sleep 0.1; i=$((i+1)); done");
        let r = run_job(&talking, d.path(), "job", None, Some(Duration::from_millis(700))).expect("run");
        assert_eq!(r.exit, ExitKind::Code(0), "{}", r.log_tail);
        assert!(r.log_tail.ends_with("14"));
    }
}
