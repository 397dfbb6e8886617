//! Solving one pose inside a campaign: its work folder, where it starts (a resumed
//! attempt or attempt 1), the retry ladder's attempts, and the CSV and manifest entry of
//! a solved run.

use super::lock_manifest;
use super::Ctx;
use crate::backend::{Backend, Job, SolveFailure, Solved};
use crate::manifest::{manifest_text, read_manifest, rfc3339_utc, Manifest, ManifestEntry, MANIFEST};
use crate::partial;
use crate::process;
use crate::report::{PoseReport, Status};
use crate::results::{self, Row};
use crate::resume;
use crate::spec::PoseSpec;
use anyhow::{bail, Context, Result};
use needle_contract::COMPONENT_COUNT;
use std::path::{Path, PathBuf};
use std::time::{Instant, SystemTime};

/// `<out_dir>/.work/<pose>/`
pub(super) fn work_dir(out_dir: &Path, pose: &str) -> PathBuf {
    out_dir.join(".work").join(pose)
}

pub(super) fn failed_report(pose: &PoseSpec, ctx: &Ctx<'_>, message: String, log_tail: String) -> PoseReport {
    unsolved_report(pose, ctx, Status::Failed { message, log_tail })
}

/// The report of a pose left unsolved (failed or interrupted): its work folder is kept.
fn unsolved_report(pose: &PoseSpec, ctx: &Ctx<'_>, status: Status) -> PoseReport {
    PoseReport {
        pose: pose.name.clone(),
        status,
        wall_s: None,
        increments: None,
        fy_final_n: None,
        work_dir: Some(work_dir(ctx.out_dir, &pose.name)),
    }
}

/// Solve one pose and write its results; never returns an error, a failure is a report.
pub(super) fn solve_pose(ctx: &Ctx<'_>, pose: &PoseSpec) -> PoseReport {
    let start = Instant::now();
    let wd = work_dir(ctx.out_dir, &pose.name);
    let fail = |message: String, log_tail: String| failed_report(pose, ctx, message, log_tail);
    let run = resume::Identity {
        spec_hash: ctx.campaign.run_hash(pose, ctx.mesh_name),
        engine: ctx.backend.engine().to_string(),
        engine_version: ctx.solver_version.clone(),
        mesh: ctx.mesh_name.to_string(),
        steps: ctx.steps,
    };
    let attempts = ctx.backend.attempts().max(1);
    let from = match starting_point(ctx, pose, &wd, &run, attempts) {
        Ok(Begin::At(from)) => from,
        Ok(Begin::FailedBefore(failures)) => return fail(failed_before(attempts, &failures), String::new()),
        Err(e) => return fail(format!("{e:#}"), String::new()),
    };
    let job = Job {
        campaign: ctx.campaign,
        pose,
        mesh_name: ctx.mesh_name,
        mesh: ctx.mesh,
        steps: ctx.steps,
        work_dir: &wd,
        timeout: ctx.timeout,
        stall: ctx.stall,
        first_increment: 1.0,
        attempt: 0,
    };
    // the furthest failed attempt so far is kept as the pose's partial record at once, so
    // that it is there while the later attempts run
    let mut keep = |reached: &[[f64; COMPONENT_COUNT]], failure: &str| {
        let failed = partial::Failed {
            campaign: ctx.campaign,
            pose,
            mesh: ctx.mesh_name,
            engine: (ctx.backend.engine(), &ctx.solver_version),
            failure,
        };
        match partial::write(ctx.out_dir, &failed, reached) {
            Ok(()) => format!(" (the {} must point(s) reached are kept in {}.partial.csv)", reached.len(), pose.name),
            Err(e) => format!(" (the partial record could not be written: {e:#})"),
        }
    };
    // a record that cannot be written costs the resumability only, not the run
    let mut record = |at: &resume::Start| {
        if let Err(e) = resume::write(&wd, &run, attempts, at) {
            needle_stdx::noteln!("{}: {e:#} (an interruption would restart this pose from attempt 1)", pose.name);
        }
    };
    let solved = match solve_with_retry(ctx.backend, &job, from, &mut keep, &mut record) {
        // solved: nothing to resume, even if its results cannot be written below
        Ok(s) => {
            resume::remove(&wd);
            s
        }
        Err(f) => {
            let kept = if f.reached.is_empty() { String::new() } else { keep(&f.reached, &f.message) };
            if process::interrupted() {
                return unsolved_report(pose, ctx, Status::Interrupted { message: format!("{}{kept}", f.message) });
            }
            return fail(format!("{}{kept}", f.message), f.log_tail);
        }
    };
    let wall_s = (start.elapsed().as_secs_f64() * 1000.0).round() / 1000.0;
    solved_report(ctx, pose, &wd, &solved, wall_s)
}

/// Write a solved pose's results and report it done (or failed, if they cannot be
/// written); the work folder `wd` goes unless `--keep-work`.
fn solved_report(ctx: &Ctx<'_>, pose: &PoseSpec, wd: &Path, solved: &Solved, wall_s: f64) -> PoseReport {
    match write_results(ctx, pose, solved, wall_s) {
        Ok(fy) => {
            partial::remove(ctx.out_dir, &pose.name);
            // the work folder is only for debugging failed runs; a leftover is harmless
            if !ctx.keep_work {
                let _ = std::fs::remove_dir_all(wd);
            }
            PoseReport {
                pose: pose.name.clone(),
                status: Status::Done,
                wall_s: Some(wall_s),
                increments: Some(solved.increments),
                fy_final_n: Some(fy),
                work_dir: None,
            }
        }
        Err(e) => failed_report(pose, ctx, format!("{e:#}"), String::new()),
    }
}

/// Where a pose's attempts begin.
enum Begin {
    /// At this attempt, with the failures before it.
    At(resume::Start),
    /// Nowhere: every attempt of exactly this run failed before (their messages).
    FailedBefore(Vec<String>),
}

/// The failure message of a pose not run again ([`resume::Decision::Finished`]).
fn failed_before(attempts: u32, failures: &[String]) -> String {
    format!("not run again (--skip-failed): all {attempts} attempts of this spec failed in an earlier run: {}", failures.join("; "))
}

/// Where `pose` starts: an interrupted run of the same pose resumes at its attempt
/// ([`resume`]); with `--skip-failed` a run of the same spec whose attempts all failed
/// is not run again (its work folder stays); anything else starts afresh in an empty
/// work folder `wd`. The earlier result and its entry stay until the new ones replace
/// them: a failed or interrupted rerun (`--force`) costs nothing (module docs).
///
/// # Errors
/// The work folder cannot be cleared or made.
fn starting_point(ctx: &Ctx<'_>, pose: &PoseSpec, wd: &Path, run: &resume::Identity, attempts: u32) -> Result<Begin> {
    let decision = if wd.exists() { resume::decide(wd, run, attempts, ctx.force) } else { resume::Decision::Fresh(None) };
    match decision {
        resume::Decision::Finished(failures) if ctx.skip_failed => Ok(Begin::FailedBefore(failures)),
        resume::Decision::Finished(_) => {
            needle_stdx::noteln!(
                "{}: starting afresh: all {attempts} attempts of this spec failed in an earlier run (--skip-failed leaves it)",
                pose.name
            );
            fresh_folder(wd)
        }
        resume::Decision::Resume(start) => {
            let reached = ctx.backend.steps_done(wd);
            needle_stdx::noteln!(
                "{}: resuming attempt {} of {attempts} (interrupted at {} mm)",
                pose.name,
                start.attempt + 1,
                ctx.campaign.loading.depth_at(reached.min(ctx.steps))
            );
            Ok(Begin::At(start))
        }
        resume::Decision::Fresh(why) => {
            if let Some(why) = why {
                needle_stdx::noteln!("{}: starting afresh: {why}", pose.name);
            }
            fresh_folder(wd)
        }
    }
}

/// Clear (or make) the work folder `wd` for attempt 1.
fn fresh_folder(wd: &Path) -> Result<Begin> {
    if wd.exists() {
        std::fs::remove_dir_all(wd).with_context(|| format!("{}: cannot clear", wd.display()))?;
    }
    std::fs::create_dir_all(wd).with_context(|| format!("{}: cannot create", wd.display()))?;
    Ok(Begin::At(resume::Start::default()))
}

/// Solve `job`; when that fails, again with [`RETRY_FIRST_INCREMENT`](crate::backend::RETRY_FIRST_INCREMENT), up to the
/// backend's [`Backend::attempts`] (module docs), starting at `start` (attempt 0 with no
/// failures, or where an interrupted run was: [`resume`]). The failures so far go into
/// the result's `retry` (or the final failure's message). `keep` gets the must points of
/// each failed attempt that reached further than the ones before, with the failures so
/// far (the final failure carries the furthest in `reached`). `record` gets where the
/// pose stands at the start of each attempt and after each failed one (the attempt to
/// run next; `attempts` once all failed).
pub(crate) fn solve_with_retry(
    backend: &dyn Backend,
    job: &Job<'_>,
    start: resume::Start,
    keep: &mut dyn FnMut(&[[f64; COMPONENT_COUNT]], &str) -> String,
    record: &mut dyn FnMut(&resume::Start),
) -> std::result::Result<Solved, SolveFailure> {
    let resume::Start { attempt: first, mut failures, mut furthest } = start;
    let attempts = backend.attempts().max(1);
    let sym = job.pose.symmetry();
    let full_block = !sym.plane_x && !sym.plane_z;
    for attempt in first..attempts {
        let r = backend.first_increment_in(job.work_dir, attempt, full_block);
        let this = Job { first_increment: r, attempt, ..*job };
        record(&resume::Start { attempt, failures: failures.clone(), furthest: furthest.clone() });
        match backend.solve(&this) {
            Ok(s) => return Ok(Solved { retry: (!failures.is_empty()).then(|| failures.join("; ")), ..s }),
            Err(f) => {
                let message = if attempt == 0 { f.message } else { format!("retry {attempt} (first increment {r}): {}", f.message) };
                failures.push(message);
                if f.reached.len() > furthest.len() {
                    furthest = f.reached;
                    if attempt + 1 < attempts {
                        let _ = keep(&furthest, &failures.join("; "));
                    }
                }
                // an interrupted attempt (Ctrl-C) is not finished: a rerun runs it again
                if !process::interrupted() {
                    record(&resume::Start { attempt: attempt + 1, failures: failures.clone(), furthest: furthest.clone() });
                }
                if attempt + 1 == attempts || process::interrupted() {
                    return Err(SolveFailure { message: failures.join("; "), log_tail: f.log_tail, reached: furthest });
                }
                needle_stdx::noteln!(
                    "{}: {}; retry {} of {} {}",
                    job.pose.name,
                    failures.last().map(String::as_str).unwrap_or_default(),
                    attempt + 1,
                    attempts - 1,
                    backend.describe_attempt(job.work_dir, attempt + 1, full_block, job.campaign.loading.depth_mm, job.steps)
                );
            }
        }
    }
    Err(SolveFailure { message: failures.join("; "), log_tail: String::new(), reached: furthest })
}

/// Why training pose `r.pose` was replaced: the spec's words, then the record of its
/// furthest failed attempt (`<out>/<pose>.partial.toml`) when there is one.
fn replaced_because(out_dir: &Path, r: &crate::spec::TrainReplacement) -> String {
    match crate::partial::read_record(out_dir, &r.pose) {
        Some(p) => format!("{} (its record: reached {} mm of {}; {})", r.why, p.reached_depth_mm, p.depth_mm, p.failure),
        None => r.why.clone(),
    }
}

/// Check the wrenches, write the CSV, then the manifest entry. Returns Fy at the final depth.
fn write_results(ctx: &Ctx<'_>, pose: &PoseSpec, s: &Solved, wall_s: f64) -> Result<f64> {
    if s.wrenches.len() != ctx.steps as usize {
        bail!("the solver returned {} wrenches for {} steps", s.wrenches.len(), ctx.steps);
    }
    let mut rows = vec![Row { depth_mm: 0.0, wrench: [0.0; COMPONENT_COUNT] }];
    for (k, w) in (1u32..).zip(&s.wrenches) {
        if w.iter().any(|v| !v.is_finite()) {
            bail!("step {k}: the wrench is not finite: {w:?}");
        }
        rows.push(Row { depth_mm: ctx.campaign.loading.depth_at(k), wrench: *w });
    }
    let csv = ctx.out_dir.join(format!("{}.csv", pose.name));
    let text = match ctx.campaign.loading.ramp_hold {
        Some(_) => results::to_timed_csv(&(0..=ctx.steps).map(|k| ctx.campaign.loading.time_at(k)).collect::<Vec<_>>(), &rows),
        None => results::to_csv(&rows),
    };
    needle_stdx::fs::write_atomic(&csv, text.as_bytes())?;
    let entry = ManifestEntry {
        spec_hash: ctx.campaign.run_hash(pose, ctx.mesh_name),
        first_attempt_hash: s.retry.is_none().then(|| ctx.campaign.first_attempt_hash(pose, ctx.mesh_name)),
        engine: ctx.backend.engine().to_string(),
        engine_version: ctx.solver_version.clone(),
        element: s.element.clone(),
        solver_settings: s.settings.clone(),
        mesh: ctx.mesh_name.to_string(),
        csv_sha256: Some(results::content_sha256(text.as_bytes())),
        model: s.summary.model.clone(),
        tissue_mesh: s.summary.tissue_mesh.clone(),
        tissue_nodes: s.summary.tissue_nodes as u64,
        tissue_elements: s.summary.tissue_elements as u64,
        needle_nodes: s.summary.needle_nodes as u64,
        needle_elements: s.summary.needle_elements as u64,
        steps: ctx.steps,
        depth_mm: ctx.campaign.loading.depth_mm,
        increments: s.increments,
        iterations: s.iterations,
        wall_s,
        peak_rss_mib: (s.peak_rss_mib > 0.0).then(|| (s.peak_rss_mib * 10.0).round() / 10.0),
        date: rfc3339_utc(SystemTime::now()),
        role: pose.role,
        x_mm: pose.x_mm,
        z_mm: pose.z_mm,
        theta_x_deg: pose.theta_x_deg,
        theta_z_deg: pose.theta_z_deg,
        first_increment: (s.first_increment != 1.0).then_some(s.first_increment),
        retry: s.retry.clone(),
        launcher: Some(ctx.launcher.name().to_string()),
        batch_job: ctx.launcher.batch_job(),
        replaces: ctx.campaign.replaced_by(&pose.name).map(|r| r.pose.clone()),
        replaced_because: ctx.campaign.replaced_by(&pose.name).map(|r| replaced_because(ctx.out_dir, r)),
        viscoelastic: crate::spec::visco::describe(ctx.campaign),
    };
    update_manifest(ctx, |m| {
        m.pose.insert(pose.name.clone(), entry);
    })?;
    Ok(rows.last().map(Row::fy_n).unwrap_or(0.0))
}

/// Read the manifest from disk (another `needle fe run` may have written it), change it,
/// write it back atomically; under the campaign's manifest lock.
fn update_manifest(ctx: &Ctx<'_>, f: impl FnOnce(&mut Manifest)) -> Result<()> {
    let _guard = ctx.manifest_lock.lock().unwrap_or_else(|p| p.into_inner());
    let _lock = lock_manifest(ctx.out_dir)?;
    let path = ctx.out_dir.join(MANIFEST);
    let mut m = read_manifest(&path)?;
    let before = m.clone();
    f(&mut m);
    if m == before && path.exists() {
        return Ok(());
    }
    needle_stdx::fs::write_atomic(&path, manifest_text(&m)?.as_bytes())
}
