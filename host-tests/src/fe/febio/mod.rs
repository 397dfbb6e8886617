//! The FEBio engine: finding `febio4`, writing the `.feb` input ([`feb`]), running it
//! and reading the rigid needle's reaction back ([`logs`]), behind the campaign's
//! [`Backend`] trait.
//!
//! `febio4` is found, in order: `$FEBIO` (must be an executable; a bad path is an
//! error, not a silent fallback), the build of `.ci/install-febio` in the cache folder
//! (`$NEEDLE_CACHE`, default `~/.cache/needle-haptics`, `febio-4.11/bin/febio4`), a
//! `febio4` on `PATH`.

pub mod feb;
pub mod logs;

use crate::fe::backend::{Backend, Job, Solved, SolveFailure};
use crate::fe::process::{self, ExitKind, LOG_TAIL_LINES};
use crate::fe::wrench::expand_mirrors;
use anyhow::{bail, Context, Result};
use std::path::{Path, PathBuf};
use std::process::Command;

/// Version of the FEBio input generator; part of every FEBio run's spec hash.
pub const GENERATOR_VERSION: u32 = 1;

/// Environment variable naming the `febio4` to use.
pub const FEBIO_ENV: &str = "FEBIO";

/// The FEBio release `.ci/install-febio` builds (the cache folder is keyed by it).
pub const FEBIO_RELEASE: &str = "4.11";

/// The input file's stem in a pose's work folder (`pose.feb`, `pose.log`).
pub const JOB: &str = "pose";

/// The cache folder of `.ci/install-febio`: `$NEEDLE_CACHE`, else
/// `$XDG_CACHE_HOME/needle-haptics`, else `$HOME/.cache/needle-haptics`.
pub fn cache_dir() -> Option<PathBuf> {
    let var = |k: &str| std::env::var_os(k).filter(|v| !v.is_empty()).map(PathBuf::from);
    var("NEEDLE_CACHE")
        .or_else(|| var("XDG_CACHE_HOME").map(|d| d.join("needle-haptics")))
        .or_else(|| var("HOME").map(|d| d.join(".cache").join("needle-haptics")))
}

/// Find `febio4` (module docs for the order).
///
/// # Errors
/// `$FEBIO` is set but is not an executable file; or no `febio4` anywhere, with how to
/// get one.
pub fn find_febio() -> Result<PathBuf> {
    if let Some(p) = std::env::var_os(FEBIO_ENV).filter(|p| !p.is_empty()) {
        let p = PathBuf::from(p);
        if process::is_executable(&p) {
            return Ok(p);
        }
        if p.components().count() == 1 {
            if let Some(found) = process::which(&p) {
                return Ok(found);
            }
        }
        bail!("{FEBIO_ENV}={}: not an executable file (unset it to use the build of .ci/install-febio)", p.display());
    }
    if let Some(c) = cache_dir().map(|d| d.join(format!("febio-{FEBIO_RELEASE}")).join("bin").join("febio4")) {
        if process::is_executable(&c) {
            return Ok(c);
        }
    }
    process::which(Path::new("febio4")).context(
        "febio4 not found: run .ci/install-febio (builds FEBio 4.11 into ~/.cache/needle-haptics), or set FEBIO to your febio4",
    )
}

/// The version `febio4 -info -norun` prints ("FEBio version  = 4.11.0"; with stdin
/// closed it then exits).
///
/// # Errors
/// It cannot be started, or prints no version (then it is not FEBio, or broken).
pub fn febio_version(exe: &Path) -> Result<String> {
    let out = Command::new(exe)
        .args(["-nosplash", "-info", "-norun"])
        .stdin(std::process::Stdio::null())
        .output()
        .with_context(|| format!("{}: cannot start", exe.display()))?;
    let text = format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    parse_version(&text).with_context(|| {
        format!("{} -info: no FEBio version in its output ({}): is it febio4?", exe.display(), process::tail(&text, 5))
    })
}

/// The version in FEBio's banner or `-info` output: the word after "version".
pub fn parse_version(text: &str) -> Option<String> {
    let mut words = text.split_whitespace();
    while let Some(w) = words.next() {
        if w.trim_end_matches(':').eq_ignore_ascii_case("version") {
            let mut v = words.next()?;
            if v == "=" || v == ":" {
                v = words.next()?;
            }
            let v = v.trim_end_matches([',', '.']);
            if v.chars().next().is_some_and(|c| c.is_ascii_digit()) {
                return Some(v.to_string());
            }
        }
    }
    None
}

/// The FEBio backend: `threads` OpenMP threads per job (Pardiso and assembly).
#[derive(Debug)]
pub struct FebioBackend {
    exe: Option<PathBuf>,
    threads: usize,
}

impl FebioBackend {
    /// A backend whose jobs each run on `threads` threads (0 counts as 1).
    pub fn new(threads: usize) -> Self {
        FebioBackend { exe: None, threads: threads.max(1) }
    }
}

/// The sign that turns FEBio's rigid-body reaction (`m_Fr`, `m_Mr`: minus the sum of the
/// contact forces the needle's nodes receive in the residual) into the wrench the tissue
/// exerts on the needle. Checked by `tests/fe_febio.rs` (Fy > 0: the tissue pushes the
/// needle back up).
pub const REACTION_SIGN: f64 = -1.0;

impl Backend for FebioBackend {
    fn prepare(&mut self) -> Result<String> {
        let exe = find_febio()?;
        let v = febio_version(&exe)?;
        self.exe = Some(exe);
        Ok(v)
    }

    fn engine(&self) -> &'static str {
        "febio"
    }

    /// Five attempts, each changing one thing that was seen to decide convergence:
    /// 1. the spec's settings;
    /// 2. the contact projections updated by the other rule (`retry_seg_up` instead of
    ///    `seg_up`: freezing them stops a node chattering between two facets, x+02 on
    ///    needle8, but lets other poses, tx+04 and z+10, invert elements at 0.6 mm);
    /// 3. each load step starting at a quarter step, convergence on energy and residual
    ///    (`retry_dtol`, `retry_rtol`), `seg_up`;
    /// 4. as 3 with `retry_seg_up`;
    /// 5. as 3 with the penalty scaled by `last_attempt_penalty_scale`.
    ///
    /// A converged run's equilibrium does not depend on the path (the centred run is bit
    /// for bit the same with `seg_up` 0 and 5); the manifest records the settings used.
    fn attempts(&self) -> u32 {
        5
    }

    fn first_increment(&self, attempt: u32) -> f64 {
        if attempt < 2 {
            1.0
        } else {
            crate::fe::deck::RETRY_FIRST_INCREMENT
        }
    }

    fn solve(&self, job: &Job<'_>) -> std::result::Result<Solved, SolveFailure> {
        let exe = self.exe.as_deref().context("FebioBackend::solve before prepare")?;
        let changed;
        let campaign = if job.attempt == 0 || job.attempt == 2 {
            job.campaign
        } else {
            let mut c = job.campaign.clone();
            let s = &mut c.solver.febio;
            if job.attempt % 2 == 1 {
                s.seg_up = s.retry_seg_up;
            } else {
                s.penalty *= s.last_attempt_penalty_scale;
            }
            changed = c;
            &changed
        };
        let feb = feb::write(campaign, job.pose, job.mesh, job.steps, job.first_increment).context("writing the FEBio input")?;
        let input = job.work_dir.join(format!("{JOB}.feb"));
        std::fs::write(&input, &feb.text).with_context(|| format!("{}: cannot write", input.display()))?;
        let rb_path = job.work_dir.join(feb::RIGID_LOG);
        if rb_path.exists() {
            std::fs::remove_file(&rb_path).with_context(|| format!("{}: cannot remove the earlier attempt's", rb_path.display()))?;
        }
        let log_path = job.work_dir.join(format!("{JOB}.log"));
        let mut cmd = Command::new(exe);
        cmd.arg("-nosplash")
            .arg("-i")
            .arg(format!("{JOB}.feb"))
            .arg("-o")
            .arg(format!("{JOB}.log"))
            .arg("-p")
            .arg(format!("{JOB}.xplt"))
            .env("OMP_NUM_THREADS", self.threads.to_string())
            .env("MKL_NUM_THREADS", self.threads.to_string());
        let out_path = job.work_dir.join("febio.out");
        let done = process::run(cmd, job.work_dir, &out_path, &[log_path.clone(), rb_path.clone()], job.timeout, job.stall)?;
        let log_text = std::fs::read_to_string(&log_path).unwrap_or_default();
        let run = logs::parse_run_log(if log_text.is_empty() { &done.log_text } else { &log_text });
        let tail_src = if log_text.trim().is_empty() { &done.log_text } else { &log_text };
        let log_tail = process::tail(tail_src, LOG_TAIL_LINES);
        let records = std::fs::read_to_string(&rb_path)
            .map_err(anyhow::Error::from)
            .and_then(|t| logs::parse_rigid_log(&t))
            .with_context(|| format!("{}", rb_path.display()));
        let depth = job.campaign.loading.depth_mm;
        let at_steps = records.as_ref().ok().map(|r| pick_steps(r, depth, job.steps));
        let done_steps = at_steps.as_ref().map(|v| v.iter().take_while(|w| w.is_some()).count()).unwrap_or(0);
        if done.exit != ExitKind::Code(0) || !run.normal_termination || done_steps < job.steps as usize {
            let how = match done.exit {
                ExitKind::Code(0) if run.error_termination => "ended with ERROR TERMINATION".to_string(),
                ExitKind::Code(0) => "exited 0".to_string(),
                e => e.to_string(),
            };
            let kept = keep_failed_attempt(job);
            return Err(SolveFailure {
                message: format!(
                    "febio4 {how} after {done_steps} of {} steps (t = {} mm), {} time steps, {} retries, {:.1} s{}{kept}",
                    job.steps,
                    run.last_time,
                    run.time_steps,
                    run.retries,
                    done.wall.as_secs_f64(),
                    run.cause.as_deref().map(|c| format!(": {c}")).unwrap_or_default(),
                ),
                log_tail,
            });
        }
        let wrenches = at_steps
            .unwrap_or_default()
            .into_iter()
            .map(|v| {
                let v = v.unwrap_or([f64::NAN; 6]);
                expand_mirrors(v.map(|x| REACTION_SIGN * x), feb.symmetry)
            })
            .collect();
        Ok(Solved {
            wrenches,
            summary: feb.summary,
            increments: run.time_steps,
            iterations: run.iterations,
            first_increment: job.first_increment,
            retry: None,
            element: "hex8, three-field (u-p-J) for the uncoupled Ogden tissue; rigid-body needle".into(),
            peak_rss_mib: done.peak_rss_mib,
            settings: settings_line(&campaign.solver.febio, campaign.contact.friction, self.threads, job.first_increment < 1.0),
        })
    }

    fn steps_done(&self, work_dir: &Path) -> u32 {
        std::fs::read_to_string(work_dir.join(feb::RIGID_LOG))
            .ok()
            .and_then(|t| logs::parse_rigid_log(&t).ok())
            .map(|r| r.len() as u32)
            .unwrap_or(0)
    }
}

/// The FEBio settings of a run in one line, for the manifest.
pub fn settings_line(s: &crate::fe::spec::FebioSettings, friction: f64, threads: usize, retry: bool) -> String {
    let (dtol, rtol) = if retry { (s.retry_dtol, s.retry_rtol) } else { (s.dtol, s.rtol) };
    format!(
        "{} contact, primary {}, {} penalty {}{}{}, friction {friction}, projections updated {}; {}, max_refs {}, dtol {} etol {} rtol {}; Pardiso, {threads} thread(s)",
        s.contact,
        s.primary,
        if s.augmented { "augmented Lagrangian" } else { "pure" },
        s.penalty,
        if s.auto_penalty { " x auto" } else { " N/mm^3" },
        if s.augmented {
            format!(" (tolerance {}, gap tolerance {} mm, at most {} augmentations)", s.aug_tolerance, s.gap_tolerance_mm, s.max_aug)
        } else {
            String::new()
        },
        if s.seg_up == 0 { "every iteration".to_string() } else { format!("in the first {} iterations of each augmentation", s.seg_up) },
        if s.max_ups == 0 { "full Newton".to_string() } else { format!("BFGS {} updates", s.max_ups) },
        s.max_refs,
        dtol,
        s.etol,
        rtol,
    )
}

/// The record at each must point t_k = depth * k / steps, k = 1..=steps (None where the
/// log has none; FEBio logs must points only, but a retried step may log twice: the last
/// record at a time wins).
fn pick_steps(records: &[logs::RigidRecord], depth: f64, steps: u32) -> Vec<Option<[f64; 6]>> {
    (1..=steps)
        .map(|k| {
            let t = depth * f64::from(k) / f64::from(steps);
            records.iter().rev().find(|r| (r.time - t).abs() <= 1e-6 * depth).map(|r| r.values)
        })
        .collect()
}

/// Keep a failed FEBio attempt's logs (see [`process::keep_failed_attempt`]).
fn keep_failed_attempt(job: &Job<'_>) -> String {
    let files = [
        (format!("{JOB}.feb"), "feb"),
        (format!("{JOB}.log"), "log"),
        ("febio.out".to_string(), "out"),
        (feb::RIGID_LOG.to_string(), "rb.txt"),
    ];
    process::keep_failed_attempt(job.work_dir, &format!("attempt-{}", job.attempt + 1), &files)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn versions() {
        assert_eq!(parse_version("compiled on Nov 24 2026\nFEBio version  = 4.11.0\n").as_deref(), Some("4.11.0"));
        assert_eq!(parse_version("  Version  4.11.0  \n").as_deref(), Some("4.11.0"));
        assert_eq!(parse_version("version: unknown"), None);
    }

    #[test]
    fn must_points_are_picked_by_time() {
        let r = |t: f64, v: f64| logs::RigidRecord { time: t, values: [v; 6] };
        let recs = [r(3.0, 1.0), r(3.0, 2.0), r(6.0, 3.0)];
        let got = pick_steps(&recs, 6.0, 2);
        assert_eq!(got, vec![Some([2.0; 6]), Some([3.0; 6])]);
        assert_eq!(pick_steps(&recs[..1], 6.0, 2), vec![Some([1.0; 6]), None]);
    }
}
