//! Running one FE solver process (any engine): a wall-clock timeout, a stall limit on its
//! output files, and the process-wide stop on SIGINT/SIGTERM/SIGHUP that kills every
//! running solver. The engines (`ccx`, `febio`) build the command; this runs it.

use anyhow::{Context, Result};
use std::fmt;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

/// Number of lines of a solver's output kept for failure reports.
pub const LOG_TAIL_LINES: usize = 25;

/// How a solver process ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ExitKind {
    /// Exited with this code (ccx exits 201 on input and convergence errors).
    Code(i32),
    /// Killed by this signal.
    Signal(i32),
    /// Killed by the runner because the process was asked to stop (SIGINT, SIGTERM).
    Interrupted,
    /// Killed by the runner after the wall-clock timeout.
    TimedOut,
    /// Killed by the runner: none of its output files grew for this long.
    Stalled(Duration),
}

impl fmt::Display for ExitKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ExitKind::Code(c) => write!(f, "exit code {c}"),
            ExitKind::Signal(s) => write!(f, "killed by signal {s}"),
            ExitKind::Interrupted => write!(f, "interrupted (killed)"),
            ExitKind::TimedOut => write!(f, "timed out (killed)"),
            ExitKind::Stalled(d) => write!(f, "stalled: no output for {:.1} s (killed)", d.as_secs_f64()),
        }
    }
}

/// Set once the process was asked to stop ([`stop_jobs_on_termination`]): every running
/// [`run`] kills its solver at its next poll (within 50 ms) and any new one is killed at
/// once.
static STOP: AtomicBool = AtomicBool::new(false);

/// How long the termination handler waits for the campaign to wind down (its jobs kill
/// their solvers within 50 ms, no new job starts) before it exits the process itself.
const STOP_GRACE: Duration = Duration::from_secs(3);

/// `true` once the process was asked to stop: callers start no new job, retry nothing,
/// and exit with [`EXIT_INTERRUPTED`].
pub fn interrupted() -> bool {
    STOP.load(Ordering::SeqCst)
}

/// Exit status of a process stopped by SIGINT, SIGTERM or SIGHUP (128 + SIGINT, as a shell
/// reports an interrupted command).
pub const EXIT_INTERRUPTED: u8 = 130;

/// On SIGINT, SIGTERM or SIGHUP: kill every running solver job, then exit with
/// [`EXIT_INTERRUPTED`]. Without it a `kill PID` of `needle fe run` (not of its process
/// group) left its solver children running as orphans for hours, writing into the work
/// folders that a resumed campaign reuses. What was written before stays: finished poses
/// keep their CSV and manifest entry; the interrupted pose keeps its earlier result, if
/// any, and is solved again by a rerun.
///
/// Installs the handler once per process: a second call (a second command run in the same
/// process, as the tests do) is a no-op.
///
/// # Errors
/// Another handler is already installed in this process.
pub fn stop_jobs_on_termination() -> Result<()> {
    static INSTALLED: std::sync::OnceLock<std::result::Result<(), String>> = std::sync::OnceLock::new();
    INSTALLED
        .get_or_init(|| {
            ctrlc::set_handler(|| {
                STOP.store(true, Ordering::SeqCst);
                needle_stdx::noteln!("needle: interrupted: stopping the running solver jobs; finished poses are kept, a rerun resumes");
                std::thread::sleep(STOP_GRACE);
                std::process::exit(i32::from(EXIT_INTERRUPTED));
            })
            .map_err(|e| e.to_string())
        })
        .clone()
        .map_err(anyhow::Error::msg)
        .context("cannot install the SIGINT/SIGTERM handler")
}

/// The outcome of one solver process.
#[derive(Debug, Clone)]
pub struct Finished {
    /// How the process ended.
    pub exit: ExitKind,
    /// Wall-clock time of the process.
    pub wall: Duration,
    /// The file holding the process's stdout and stderr.
    pub log_path: PathBuf,
    /// The whole log (lossy UTF-8).
    pub log_text: String,
    /// The process's peak resident memory (Linux `VmHWM`, read at every poll), MiB; 0
    /// when it could not be read (a process that ended before the first poll).
    pub peak_rss_mib: f64,
}

/// Peak resident set size of process `pid` so far (`VmHWM` of `/proc/<pid>/status`), KiB.
fn peak_rss_kib(pid: u32) -> Option<u64> {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

/// `setpriv` of util-linux, which sets the parent-death signal and then runs the solver.
const SETPRIV: &str = "setpriv";

/// `cmd` run through `setpriv --pdeathsig KILL`: the solver gets SIGKILL when the thread
/// that started it ends, even when `needle` itself is killed with SIGKILL (which no
/// handler sees: before, its solvers ran on as orphans). `setpriv` sets the signal and
/// `exec`s the solver, which keeps the process id (the peak-memory and kill logic
/// apply to the solver itself). Program, arguments, environment and folder are kept.
///
/// # Errors
/// `setpriv` (util-linux) is not on `PATH`.
fn dies_with_parent(cmd: &Command) -> Result<Command> {
    let setpriv = which(Path::new(SETPRIV)).with_context(|| {
        format!("{SETPRIV} (util-linux) is not on PATH: needed so a solver dies with needle (apt-get install util-linux)")
    })?;
    let mut w = Command::new(setpriv);
    w.args(["--pdeathsig", "KILL", "--"]).arg(cmd.get_program()).args(cmd.get_args());
    for (k, v) in cmd.get_envs() {
        match v {
            Some(v) => w.env(k, v),
            None => w.env_remove(k),
        };
    }
    if let Some(d) = cmd.get_current_dir() {
        w.current_dir(d);
    }
    Ok(w)
}

/// Run `cmd` (program, arguments, environment already set) in `work_dir`, stdin from
/// /dev/null, stdout and stderr to `log_path`; the solver dies with the thread that runs
/// this (`dies_with_parent`). With a `timeout` the process is killed when
/// it runs longer (wall clock); with a `stall` limit, when none of `log_path` and
/// `progress_files` has grown for that long (a solver spinning without output is a
/// failed run, not a slow one). Polls every 50 ms; kills the process on [`interrupted`].
///
/// # Errors
/// The log file cannot be created, or the process cannot be started or waited for. A
/// process that starts and then fails is not an error: see [`Finished::exit`].
pub fn run(
    cmd: Command,
    work_dir: &Path,
    log_path: &Path,
    progress_files: &[PathBuf],
    timeout: Option<Duration>,
    stall: Option<Duration>,
) -> Result<Finished> {
    let log = std::fs::File::create(log_path).with_context(|| format!("{}: cannot create", log_path.display()))?;
    let log_err = log.try_clone().with_context(|| format!("{}: cannot reopen", log_path.display()))?;
    let program = cmd.get_program().to_string_lossy().into_owned();
    let mut cmd = dies_with_parent(&cmd)?;
    let start = Instant::now();
    let mut child = cmd
        .current_dir(work_dir)
        .stdin(Stdio::null())
        .stdout(log)
        .stderr(log_err)
        .spawn()
        .with_context(|| format!("{program}: cannot start in {}", work_dir.display()))?;
    let mut watched = vec![log_path.to_path_buf()];
    watched.extend_from_slice(progress_files);
    let output_bytes = || -> u64 { watched.iter().filter_map(|p| std::fs::metadata(p).ok()).map(|m| m.len()).sum() };
    let (mut last_bytes, mut last_change) = (0u64, Instant::now());
    let mut peak_kib = 0u64;
    let exit = loop {
        peak_kib = peak_kib.max(peak_rss_kib(child.id()).unwrap_or(0));
        if let Some(status) = child.try_wait().with_context(|| format!("cannot wait for {program}"))? {
            use std::os::unix::process::ExitStatusExt;
            break match (status.code(), status.signal()) {
                (Some(c), _) => ExitKind::Code(c),
                (None, Some(s)) => ExitKind::Signal(s),
                (None, None) => ExitKind::Code(-1),
            };
        }
        if interrupted() {
            let _ = child.kill();
            let _ = child.wait();
            break ExitKind::Interrupted;
        }
        if timeout.is_some_and(|t| start.elapsed() > t) {
            // the process may have exited just now: kill errors are not interesting
            let _ = child.kill();
            let _ = child.wait();
            break ExitKind::TimedOut;
        }
        if let Some(limit) = stall {
            let bytes = output_bytes();
            if bytes != last_bytes {
                (last_bytes, last_change) = (bytes, Instant::now());
            } else if last_change.elapsed() > limit {
                let _ = child.kill();
                let _ = child.wait();
                break ExitKind::Stalled(limit);
            }
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    let wall = start.elapsed();
    let log_text = std::fs::read(log_path).map(|b| String::from_utf8_lossy(&b).into_owned()).unwrap_or_default();
    Ok(Finished { exit, wall, log_path: log_path.to_path_buf(), log_text, peak_rss_mib: peak_kib as f64 / 1024.0 })
}

/// Copy a failed attempt's files (`(name in work_dir, extension)`) to
/// `failed-<attempt>.<extension>` in `work_dir`, where the retry (which rewrites the
/// solver's files) leaves them; a copy an earlier campaign left there for a file this
/// attempt did not write is removed, so every kept file is this attempt's. Returns
/// ` (kept as failed-<attempt>.*)`, or nothing when no file could be copied.
pub fn keep_failed_attempt(work_dir: &Path, attempt: &str, files: &[(String, &str)]) -> String {
    let mut kept = 0;
    for (from, ext) in files {
        let src = work_dir.join(from);
        let dest = work_dir.join(format!("failed-{attempt}.{ext}"));
        if !src.is_file() {
            let _ = std::fs::remove_file(&dest);
        } else if std::fs::copy(&src, &dest).is_ok() {
            kept += 1;
        }
    }
    if kept > 0 {
        format!(" (kept as failed-{attempt}.*)")
    } else {
        String::new()
    }
}

/// The last `n` lines of `text`, trailing blank lines dropped.
pub fn tail(text: &str, n: usize) -> String {
    let lines: Vec<&str> = text.trim_end().lines().collect();
    lines[lines.len().saturating_sub(n)..].join("\n")
}

/// The first executable file called `name` on `PATH`.
pub fn which(name: &Path) -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path).map(|d| d.join(name)).find(|p| is_executable(p))
}

/// Whether `p` is a file with an execute bit.
pub fn is_executable(p: &Path) -> bool {
    use std::os::unix::fs::PermissionsExt;
    std::fs::metadata(p).is_ok_and(|m| m.is_file() && m.permissions().mode() & 0o111 != 0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tail_lines() {
        assert_eq!(tail("a\nb\nc\n\n", 2), "b\nc");
        assert_eq!(tail("a", 5), "a");
    }
}
