//! Running a firmware ELF under `qemu-system-arm` with semihosting.
use super::Core;
use anyhow::{bail, Context};
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

/// What a QEMU run printed and how it ended.
#[derive(Debug)]
pub struct Run {
    /// Semihosting output (the firmware's stdout).
    pub stdout: String,
    /// QEMU's own messages.
    pub stderr: String,
    /// QEMU's exit status: the firmware's semihosting exit (0 success, 1 failure).
    pub status: ExitStatus,
    /// Wall-clock time of the run.
    pub elapsed: Duration,
}

/// A program on `PATH`.
#[must_use]
pub fn find_on_path(name: &str) -> Option<PathBuf> {
    let path = std::env::var_os("PATH")?;
    std::env::split_paths(&path).map(|d| d.join(name)).find(|p| p.is_file())
}

/// `qemu-system-arm` on `PATH`.
///
/// # Errors
/// QEMU is not installed, with the command that installs it.
pub fn qemu() -> anyhow::Result<PathBuf> {
    find_on_path("qemu-system-arm").ok_or_else(|| {
        anyhow::anyhow!(
            "qemu-system-arm is not on PATH: the firmware tests need it (`apt-get install qemu-system-arm`; \
             .ci/run installs it). They never skip."
        )
    })
}

/// Runs `elf` on `core`'s QEMU board with semihosting, `-icount shift=0` when `icount`
/// (1 ns of virtual time per instruction: SysTick counts instructions). Kills QEMU after
/// `timeout`.
///
/// # Errors
/// QEMU is missing or cannot start, or the run times out (a firmware that faults spins in
/// its fault handler).
pub fn run(core: &Core, elf: &Path, icount: bool, timeout: Duration) -> anyhow::Result<Run> {
    let qemu = qemu()?;
    let mut cmd = Command::new(&qemu);
    cmd.args(["-machine", core.machine, "-cpu", core.cpu])
        .args(["-display", "none", "-monitor", "none", "-serial", "null"])
        .args(["-semihosting-config", "enable=on,target=native"]);
    if icount {
        cmd.args(["-icount", "shift=0"]);
    }
    cmd.arg("-kernel").arg(elf).stdin(Stdio::null()).stdout(Stdio::piped()).stderr(Stdio::piped());
    let shown = format!("{} -machine {} -kernel {}", qemu.display(), core.machine, elf.display());
    let start = Instant::now();
    let mut child = cmd.spawn().with_context(|| format!("cannot start {shown}"))?;
    let mut out = child.stdout.take().context("no stdout pipe")?;
    let mut err = child.stderr.take().context("no stderr pipe")?;
    let out_thread = std::thread::spawn(move || {
        let mut b = Vec::new();
        let _ = out.read_to_end(&mut b);
        b
    });
    let err_thread = std::thread::spawn(move || {
        let mut b = Vec::new();
        let _ = err.read_to_end(&mut b);
        b
    });
    let status = loop {
        if let Some(s) = child.try_wait().context("waiting for QEMU")? {
            break s;
        }
        if start.elapsed() > timeout {
            let _ = child.kill();
            let _ = child.wait();
            let stdout = out_thread.join().unwrap_or_default();
            let text = String::from_utf8_lossy(&stdout);
            let tail: Vec<&str> = text.lines().rev().take(5).collect();
            bail!(
                "{shown}: no exit after {:.0} s (the firmware hung or faulted); killed. Last lines:\n{}",
                timeout.as_secs_f64(),
                tail.into_iter().rev().collect::<Vec<_>>().join("\n")
            );
        }
        std::thread::sleep(Duration::from_millis(10));
    };
    let elapsed = start.elapsed();
    let stdout = String::from_utf8_lossy(&out_thread.join().unwrap_or_default()).into_owned();
    let stderr = String::from_utf8_lossy(&err_thread.join().unwrap_or_default()).into_owned();
    Ok(Run { stdout, stderr, status, elapsed })
}
