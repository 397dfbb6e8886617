//! The FEBio engine: finding `febio4`, writing the `.feb` input ([`feb`]), running it
//! and reading the rigid needle's reaction back ([`logs`]), behind the campaign's
//! [`Backend`] trait.
//!
//! Each FEBio process of an attempt is recorded in `running.toml` ([`running`]), so that
//! an attempt a killed campaign left running goes on from its last dump (`pose.dmp`, at
//! its last must point) when the campaign resumes the pose (`crate::resume`); nothing at
//! the start of an attempt removes that dump before the decision.
//!
//! `febio4` is found, in order: `$FEBIO` (must be an executable; a bad path is an
//! error, not a silent fallback), the build of `.ci/install-febio` in the cache folder
//! (`$NEEDLE_CACHE`, default `~/.cache/needle-haptics`, `febio-4.11/bin/febio4`), a
//! `febio4` on `PATH`.

mod attempt;
pub mod failures;
pub mod feb;
pub mod ladder;
pub mod logs;
pub mod restart;
pub mod running;

use crate::backend::{Backend, Job, SolveFailure, Solved};
use crate::process;
use anyhow::{bail, Context, Result};
use needle_contract::COMPONENT_COUNT;
use std::path::{Path, PathBuf};
use std::process::Command;

/// Version of the FEBio input generator ([`versions::FEBIO_INPUT`](crate::versions::FEBIO_INPUT)).
pub use crate::versions::FEBIO_INPUT as GENERATOR_VERSION;

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
    process::which(Path::new("febio4"))
        .context("febio4 not found: run .ci/install-febio (builds FEBio 4.11 into ~/.cache/needle-haptics), or set FEBIO to your febio4")
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
    parse_version(&text)
        .with_context(|| format!("{} -info: no FEBio version in its output ({}): is it febio4?", exe.display(), process::tail(&text, 5)))
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
/// exerts on the needle. Checked by `crates/cli/tests/fe_febio.rs` (Fy > 0: the tissue
/// pushes the needle back up).
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

    /// Five attempts, decided by the retry ladder (`ladder.rs`) from what the earlier
    /// attempts did. The attempts from depth 0, in order, each changing one thing that was
    /// seen to decide convergence:
    /// 1. the spec's settings (later whole-step attempts take the first-contact steps,
    ///    `first_contact_depth_mm`, once an attempt failed at first contact);
    /// 2. the contact projections updated by the other rule (`retry_seg_up` instead of
    ///    `seg_up`: freezing them stops a node chattering between two facets, x+02 on
    ///    needle8, but lets other poses, tx+04 and z+10, invert elements at 0.6 mm);
    /// 3. each load step starting at a quarter step, convergence on energy and residual
    ///    (`retry_dtol`, `retry_rtol`), `seg_up`;
    /// 4. as 3 with `retry_seg_up`;
    /// 5. as 3 with the penalty scaled by `last_attempt_penalty_scale`.
    ///
    /// After a whole-step attempt that got further than any before it, the next attempt
    /// continues it from its last converged must point with the retry tolerances instead
    /// (then the fresh ones go on where they were).
    ///
    /// On the full block (no mirror plane) attempts 1 and 2, and 3 and 4, swap their
    /// projection rules (`retry_seg_up` first, then `seg_up`): in the default set's rerun
    /// (rtol 1e-3, needle8) `seg_up` 5 with whole first increments failed on
    /// all seven full-block poses tried (lhs-01..03, t2-a..d) between 0.14 and 3.3 mm,
    /// each a deterministic repeat of 50-750 s, while `retry_seg_up` 0 solved lhs-01,
    /// t2-a and t2-c on attempt 2 and lhs-02, t2-d on attempt 4.
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
            crate::backend::RETRY_FIRST_INCREMENT
        }
    }

    /// One attempt as the ladder plans it (the trait's docs above). An attempt that a
    /// killed campaign left running (`running.toml`, `pose.dmp`: `running.rs`) goes on
    /// from its dump; when FEBio cannot read that dump the attempt is run again from its
    /// start, and the settings line says so.
    fn solve(&self, job: &Job<'_>) -> std::result::Result<Solved, SolveFailure> {
        let mut unreadable = None;
        let r = self.solve_attempt(job, true, &mut unreadable, None);
        match unreadable {
            Some(why) => {
                needle_stdx::noteln!("{}: attempt {}: {why}; the attempt starts again from its start", job.pose.name, job.attempt + 1);
                self.solve_attempt(job, false, &mut None, Some(why))
            }
            None => r,
        }
    }

    fn first_increment_in(&self, work_dir: &Path, attempt: u32, full_block: bool) -> f64 {
        self.plan_in(work_dir, attempt, full_block).first_increment()
    }

    fn describe_attempt(&self, work_dir: &Path, attempt: u32, full_block: bool, depth_mm: f64, steps: u32) -> String {
        self.plan_in(work_dir, attempt, full_block).describe(depth_mm, steps)
    }

    /// Must points logged so far, over the continued segments' logs too.
    fn steps_done(&self, work_dir: &Path) -> u32 {
        let count = |p: PathBuf| std::fs::read_to_string(p).ok().and_then(|t| logs::parse_rigid_log(&t).ok()).map(|r| r.len() as u32);
        let segments: u32 = (0..restart::MAX_SEGMENTS).map_while(|n| count(restart::segment_log(work_dir, n))).sum();
        segments + count(work_dir.join(feb::RIGID_LOG)).unwrap_or(0)
    }
}

impl FebioBackend {
    /// The ladder's plan for `attempt` (0-based) from the state in `work_dir`.
    fn plan_in(&self, work_dir: &Path, attempt: u32, full_block: bool) -> ladder::Plan {
        let state = if attempt == 0 { ladder::State::default() } else { ladder::State::read(work_dir).unwrap_or_default() };
        ladder::next(&state, full_block)
    }
}

/// The FEBio settings of a run in one line, for the manifest.
pub fn settings_line(s: &crate::spec::FebioSettings, friction: f64, threads: usize, retry: bool) -> String {
    let (dtol, rtol) = if retry { (s.retry_dtol, s.retry_rtol) } else { (s.dtol, s.rtol) };
    format!(
        "{} contact, primary {}, {} penalty {}{}{}, friction {friction}, projections updated {}; {}, max_refs {}, dtol {} etol {} rtol {}{}; Pardiso, {threads} thread(s)",
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
        if retry && s.retry_min_residual_n > 0.0 { format!(", residual floor {} N", s.retry_min_residual_n) } else { String::new() },
    )
}

/// The records of a segment that are its results: `current`, the records FEBio logged in
/// the segment, without those at or before the segment's start when it is a restart
/// (`before` holds the earlier segments' records; the restart goes on from the dump of
/// the last must point logged there, the latest of them). A restart's record at its own
/// start is a re-output of the dump's state, not a solution: FEBio 4.11 logged it with
/// an all-zero wrench when the continuation failed at once (the ramp-and-hold runs'
/// partial records at 6 mm, `fe/visco/`), and `pick_steps`, where the last record of a
/// time wins, took it over the earlier segment's converged one. `end` is the loading's
/// final time (the tolerance's scale, as in `pick_steps`).
fn segment_results<'a>(
    before: &[logs::RigidRecord],
    current: &'a [logs::RigidRecord],
    end: f64,
) -> impl Iterator<Item = logs::RigidRecord> + 'a {
    let start = before.iter().map(|r| r.time).fold(f64::NEG_INFINITY, f64::max);
    current.iter().filter(move |r| r.time > start + 1e-6 * end).copied()
}

/// The record at each must point t_k = depth * k / steps, k = 1..=steps (None where the
/// log has none; FEBio logs must points only, but a retried step may log twice: the last
/// record at a time wins).
fn pick_steps(records: &[logs::RigidRecord], loading: &crate::spec::Loading, steps: u32) -> Vec<Option<[f64; COMPONENT_COUNT]>> {
    let end = loading.time_at(steps);
    (1..=steps)
        .map(|k| {
            let t = loading.time_at(k);
            records.iter().rev().find(|r| (r.time - t).abs() <= 1e-6 * end).map(|r| r.values)
        })
        .collect()
}

/// The record of the attempt `job` as a killed campaign left it running, when its dump
/// is there too (`running.rs`); an unreadable record is reported and not resumed.
fn interrupted_run(job: &Job<'_>) -> Option<running::Running> {
    let r = match running::read(job.work_dir) {
        Ok(r) => r?,
        Err(e) => {
            needle_stdx::noteln!("{}: {e:#}; the attempt starts from its start", job.pose.name);
            return None;
        }
    };
    (r.attempt == job.attempt && job.work_dir.join(restart::DUMP).is_file()).then_some(r)
}

fn remove_if_exists(p: &Path) -> Result<()> {
    match std::fs::remove_file(p) {
        Ok(()) => Ok(()),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(()),
        Err(e) => Err(e).with_context(|| format!("{}: cannot remove the earlier attempt's", p.display())),
    }
}

/// Keeps a failed FEBio attempt's input, FEBio's output and, of a continued attempt,
/// every segment's logs (`failed-attempt-N.log-0`, `.rb-0.txt`, ...: the must points
/// before the last continuation), since the next attempt starts in the same folder
/// ([`process::keep_failed_attempt`], which also drops an earlier campaign's copies of
/// segments this attempt did not reach).
fn keep_failed_attempt(job: &Job<'_>) -> String {
    let mut files = vec![
        (format!("{JOB}.feb"), "feb".to_string()),
        (format!("{JOB}.log"), "log".to_string()),
        ("febio.out".to_string(), "out".to_string()),
        (feb::RIGID_LOG.to_string(), "rb.txt".to_string()),
    ];
    for n in 0..restart::MAX_SEGMENTS {
        files.push((restart::segment_solver_log_name(n), format!("log-{n}")));
        files.push((restart::segment_log_name(n), format!("rb-{n}.txt")));
    }
    let files: Vec<(String, &str)> = files.iter().map(|(f, e)| (f.clone(), e.as_str())).collect();
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

    /// How the fake febio4's restarts behave.
    #[derive(Clone, Copy, PartialEq)]
    enum Restarts {
        /// Every restart logs 4.5 and 6 mm.
        Pass,
        /// Every restart gives up again without a new must point.
        Stuck,
        /// Only a restart that sets Newton's tolerances (`<solver>`: the retry's) passes.
        PassWithRetryTolerances,
    }

    /// A stand-in for febio4 (a shell script; bookkeeping only, no physics): the first
    /// run logs the must points at 1.5 and 3 mm, dumps and gives up at 3.2 mm; a restart
    /// (`-r`) checks its input and archive, then logs 4.5 and 6 mm, or gives up again
    /// without a new must point ([`Restarts`]).
    fn fake_febio(dir: &Path, restarts: Restarts) -> PathBuf {
        use std::os::unix::fs::PermissionsExt;
        let rb = |ts: &[(f64, f64)]| -> String {
            ts.iter()
                .map(|(t, v)| format!("*Step  = 1\\n*Time  = {t}\\n*Data  = Fx;Fy;Fz;Mx;My;Mz\\n2,{v},{v},{v},{v},{v},{v}\\n"))
                .collect()
        };
        let stuck =
            "printf ' ------- failed to converge at time : 3.1\\n E R R O R   T E R M I N A T I O N\\n' > pose.log; exit 1".to_string();
        let pass = format!(
            "printf '{}' > needle-rb.txt; printf ' ------- converged at time : 4.5\\n ------- converged at time : 6\\n N O R M A L   T E R M I N A T I O N\\n' > pose.log; exit 0",
            rb(&[(4.5, 3.0), (6.0, 4.0)])
        );
        let restart = match restarts {
            Restarts::Pass => pass,
            Restarts::Stuck => stuck,
            Restarts::PassWithRetryTolerances => format!("if grep -q '<solver>' pose-restart.feb; then {pass}; else {stuck}; fi"),
        };
        let script = format!(
            "#!/bin/sh\n\
             case \" $* \" in *\" -r \"*)\n\
             grep -q '<Archive>pose-from.dmp</Archive>' pose-restart.feb && grep -q 'step_size' pose-restart.feb && [ -f pose-from.dmp ] || exit 3\n\
             {restart};;\n\
             esac\n\
             printf '{}' > needle-rb.txt; echo state > pose.dmp\n\
             printf ' ------- converged at time : 1.5\\n ------- converged at time : 3\\n ------- failed to converge at time : 3.2\\n E R R O R   T E R M I N A T I O N\\n' > pose.log\n\
             exit 1\n",
            rb(&[(1.5, 1.0), (3.0, 2.0)])
        );
        let p = dir.join("fake-febio4");
        std::fs::write(&p, script).expect("write the fake febio4");
        std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o755)).expect("chmod");
        p
    }

    #[test]
    fn a_run_that_gives_up_continues_from_its_last_must_point() {
        let d = tempfile::tempdir().expect("tempdir");
        let set = d.path().join("set");
        std::fs::create_dir_all(&set).expect("mkdir");
        std::fs::copy(needle_stdx::workspace_root().join("coeffs/default/campaign.toml"), set.join("campaign.toml")).expect("copy");
        let (mut c, _) = crate::spec::load(&set).expect("spec");
        c.loading.steps = 4;
        let pose = c.poses().into_iter().find(|p| p.name == "centre").expect("centre");
        let mesh = c.mesh_level("smoke").expect("smoke").clone();
        for stuck in [false, true] {
            let work = d.path().join(format!("work-{stuck}"));
            std::fs::create_dir_all(&work).expect("mkdir");
            // an earlier campaign's attempt 1 that was continued twice
            std::fs::write(work.join("failed-attempt-1.log-1"), "an earlier campaign's").expect("write");
            let restarts = if stuck { Restarts::Stuck } else { Restarts::Pass };
            let backend = FebioBackend { exe: Some(fake_febio(d.path(), restarts)), threads: 1 };
            let job = Job {
                campaign: &c,
                pose: &pose,
                mesh_name: "smoke",
                mesh: &mesh,
                steps: 4,
                work_dir: &work,
                timeout: None,
                stall: None,
                first_increment: 1.0,
                attempt: 0,
            };
            let r = backend.solve(&job);
            assert!(!work.join(restart::DUMP).exists() && !work.join(restart::DUMP_FROM).exists(), "dumps removed");
            if stuck {
                let f = r.expect_err("a continuation without progress: failed");
                assert!(
                    f.message.contains("after 2 of 4 steps (t = 3 mm)")
                        && f.message.contains("continued 1 time(s) from the last converged must point (3 mm)"),
                    "{}",
                    f.message
                );
                // the first segment's logs, with its must points, are kept beside the last's
                let first_rb = std::fs::read_to_string(work.join("failed-attempt-1.rb-0.txt")).unwrap_or_default();
                assert_eq!(logs::parse_rigid_log(&first_rb).map(|r| r.len()).ok(), Some(2), "{first_rb}");
                let first_log = std::fs::read_to_string(work.join("failed-attempt-1.log-0")).unwrap_or_default();
                assert!(first_log.contains("converged at time : 3\n"), "{first_log}");
                assert!(work.join("failed-attempt-1.log").is_file() && work.join("failed-attempt-1.feb").is_file());
                assert!(!work.join("failed-attempt-1.log-1").exists(), "an earlier campaign's segment log is not kept as this one's");
            } else {
                let s = r.unwrap_or_else(|f| panic!("continued run: {}", f.message));
                let fy: Vec<f64> = s.wrenches.iter().map(|w| w[1]).collect();
                // the fake's values 1, 2 (first run) and 3, 4 (continuation), through the
                // reaction sign and the quarter model's mirror expansion (x4 for Fy)
                assert_eq!(fy, vec![-4.0, -8.0, -12.0, -16.0]);
                assert!(s.settings.ends_with("continued 1 time(s) from the last converged must point (3 mm)"), "{}", s.settings);
                assert_eq!(backend.steps_done(&work), 4, "the must points of both segments");
                let restart = std::fs::read_to_string(work.join(restart::RESTART_INPUT)).expect("restart input");
                assert!(restart.contains(&format!("<step_size>{:e}</step_size>", 1.5 * restart::CONTINUE_STEP_FRACTION)), "{restart}");
            }
        }
    }

    /// The ladder's next attempt continues the furthest attempt from its dump with the
    /// retry tolerances (not from depth 0), keeps that attempt's must points and says so
    /// in the manifest's settings; the first attempt's first-contact steps are in its
    /// input. (Bookkeeping: the fake solves only a restart that sets the tolerances.)
    #[test]
    fn the_next_attempt_continues_the_furthest_from_its_dump() {
        let d = tempfile::tempdir().expect("tempdir");
        let set = d.path().join("set");
        std::fs::create_dir_all(&set).expect("mkdir");
        std::fs::copy(needle_stdx::workspace_root().join("coeffs/default/campaign.toml"), set.join("campaign.toml")).expect("copy");
        let (mut c, _) = crate::spec::load(&set).expect("spec");
        c.loading.steps = 4;
        let pose = c.poses().into_iter().find(|p| p.name == "centre").expect("centre");
        let mesh = c.mesh_level("smoke").expect("smoke").clone();
        let work = d.path().join("work");
        std::fs::create_dir_all(&work).expect("mkdir");
        let backend = FebioBackend { exe: Some(fake_febio(d.path(), Restarts::PassWithRetryTolerances)), threads: 1 };
        let job = |attempt: u32| Job {
            campaign: &c,
            pose: &pose,
            mesh_name: "smoke",
            mesh: &mesh,
            steps: 4,
            work_dir: &work,
            timeout: None,
            stall: None,
            first_increment: 1.0,
            attempt,
        };
        let f = backend.solve(&job(0)).expect_err("attempt 1: its own continuation has the run's tolerances and is stuck");
        assert!(f.message.contains("after 2 of 4 steps"), "{}", f.message);
        let feb1 = std::fs::read_to_string(work.join("failed-attempt-1.feb")).unwrap_or_default();
        // a first attempt has whole steps: no failure at first contact yet
        assert!(feb1.contains("<step_size>1.5</step_size>") && feb1.contains("<pt>1.5,1.5</pt>"), "{feb1}");
        let state = ladder::State::read(&work).expect("state");
        assert_eq!(state.furthest.as_ref().map(|f| (f.attempt, f.steps)), Some((1, 2)));
        assert!(work.join(ladder::FURTHEST_DUMP).is_file() && !work.join(restart::DUMP).exists());
        assert_eq!(backend.first_increment_in(&work, 1, false), crate::backend::RETRY_FIRST_INCREMENT);
        assert!(backend
            .describe_attempt(&work, 1, false, 6.0, 4)
            .starts_with("continuing attempt 1 from its last converged must point (3 mm"));
        let s = backend.solve(&job(1)).unwrap_or_else(|f| panic!("attempt 2 continues attempt 1: {}", f.message));
        let fy: Vec<f64> = s.wrenches.iter().map(|w| w[1]).collect();
        assert_eq!(fy, vec![-4.0, -8.0, -12.0, -16.0], "attempt 1's must points, then the continuation's");
        assert!(s.settings.contains("continued attempt 1's last converged must point (3 mm; to there: "), "{}", s.settings);
        assert!(s.settings.contains(&format!("dtol {} etol", c.solver.febio.retry_dtol)), "the retry tolerances: {}", s.settings);
        assert_eq!(s.first_increment, crate::backend::RETRY_FIRST_INCREMENT);
        let restart = std::fs::read_to_string(work.join(restart::RESTART_INPUT)).expect("restart input");
        assert!(restart.contains(&format!("<step_size>{:e}</step_size>", 1.5 * crate::backend::RETRY_FIRST_INCREMENT)), "{restart}");
        assert!(!work.join(ladder::FURTHEST_DUMP).exists(), "the kept dump goes once the pose solves");
        // a new campaign's first attempt starts from depth 0 whatever the folder holds
        assert_eq!(backend.first_increment_in(&work, 0, false), 1.0);
    }

    #[test]
    fn a_restart_does_not_replace_the_must_point_it_starts_from() {
        let r = |t: f64, v: f64| logs::RigidRecord { time: t, values: [v; COMPONENT_COUNT] };
        let loading = crate::spec::Loading { depth_mm: 9.0, steps: 3, ramp_hold: None };
        // segment 1 converged at 3 and 6; the restart from 6 logs 6 again (zeros) and 9
        let before = [r(3.0, 1.0), r(6.0, 2.0)];
        let restart = [r(6.0, 0.0), r(9.0, 3.0)];
        let mut all = before.to_vec();
        all.extend(segment_results(&before, &restart, 9.0));
        let want = vec![Some([1.0; COMPONENT_COUNT]), Some([2.0; COMPONENT_COUNT]), Some([3.0; COMPONENT_COUNT])];
        assert_eq!(pick_steps(&all, &loading, 3), want);
        // without the filter the restart's zeros would win (what the partial records had)
        let mut raw = before.to_vec();
        raw.extend_from_slice(&restart);
        assert_eq!(pick_steps(&raw, &loading, 3).get(1), Some(&Some([0.0; COMPONENT_COUNT])));
        // the first segment keeps all its records
        assert_eq!(segment_results(&[], &restart, 9.0).count(), 2);
    }

    #[test]
    fn must_points_are_picked_by_time() {
        let r = |t: f64, v: f64| logs::RigidRecord { time: t, values: [v; COMPONENT_COUNT] };
        let recs = [r(3.0, 1.0), r(3.0, 2.0), r(6.0, 3.0)];
        let loading = crate::spec::Loading { depth_mm: 6.0, steps: 2, ramp_hold: None };
        let got = pick_steps(&recs, &loading, 2);
        assert_eq!(got, vec![Some([2.0; COMPONENT_COUNT]), Some([3.0; COMPONENT_COUNT])]);
        assert_eq!(pick_steps(&recs[..1], &loading, 2), vec![Some([1.0; COMPONENT_COUNT]), None]);
    }
}
