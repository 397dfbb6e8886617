//! One FEBio attempt at a pose ([`FebioBackend::solve_attempt`]), in its steps:
//! - [`Setup::decide`]: the ladder's plan from its state (or the plan of the attempt a
//!   killed campaign left running), the contact it changes, the stepping, the `.feb`;
//! - [`Setup::start`]: going on from the interrupted run's dump, or from the furthest
//!   attempt's ([`ladder::FURTHEST_DUMP`]), or a clean folder for a fresh run;
//! - [`Setup::run_segments`]: FEBio's processes, each continuing from the last must point
//!   when the solver gave up ([`restart`]), until one ends the attempt ([`Ended`]);
//! - [`Setup::settings`], [`Setup::keep_for_ladder`]: the manifest's settings line, the
//!   ladder's record of a failed attempt and its dump;
//! - [`Setup::failure`] or [`Setup::solved`]: what the campaign gets.

use super::{
    feb, interrupted_run, keep_failed_attempt, ladder, logs, pick_steps, remove_if_exists, restart, running, segment_results, settings_line,
};
use super::{FebioBackend, JOB, REACTION_SIGN};
use crate::backend::{Job, SolveFailure, Solved};
use crate::process::{self, ExitKind, LOG_TAIL_LINES};
use crate::spec::{Campaign, FebioSettings, Loading, MeshLevel};
use crate::wrench::expand_mirrors;
use anyhow::{Context, Result};
use needle_contract::COMPONENT_COUNT;
use std::borrow::Cow;
use std::path::{Path, PathBuf};
use std::process::Command;

impl FebioBackend {
    /// [`Backend::solve`](crate::backend::Backend::solve) of one attempt: from the
    /// interrupted run's dump when `may_resume` and the work folder holds one for this
    /// attempt; `unreadable` is set (and the attempt returns at once) when FEBio's restart
    /// could not read that dump; `note` goes into the settings line.
    pub(super) fn solve_attempt(
        &self,
        job: &Job<'_>,
        may_resume: bool,
        unreadable: &mut Option<String>,
        note: Option<String>,
    ) -> std::result::Result<Solved, SolveFailure> {
        let exe = self.exe.as_deref().context("FebioBackend::solve before prepare")?;
        let mut setup = Setup::decide(job, may_resume)?;
        let mut progress = setup.start(note)?;
        let Some(ended) = setup.run_segments(exe, self.threads, &mut progress, unreadable)? else {
            let why = unreadable.clone().unwrap_or_default();
            return Err(SolveFailure { message: why, log_tail: progress.log_tail, reached: Vec::new() });
        };
        // the attempt ended: nothing to go on from, whatever its bookkeeping below; one
        // stopped by Ctrl-C or kill keeps its record and dump, which the rerun goes on from
        let stopped = process::interrupted();
        if !stopped {
            running::remove(job.work_dir);
        }
        let line = setup.settings(self.threads, &progress);
        let failed = ended.done.exit != ExitKind::Code(0) || !ended.run.normal_termination || ended.done_steps < job.steps as usize;
        if failed && !process::interrupted() {
            setup.keep_for_ladder(&ended, &line)?;
        }
        // the dumps are large (tens of MB) and only needed while the run goes on
        for f in [restart::DUMP, restart::DUMP_FROM].into_iter().filter(|_| !stopped) {
            let _ = std::fs::remove_file(job.work_dir.join(f));
        }
        if failed {
            return Err(setup.failure(ended, &progress));
        }
        let _ = std::fs::remove_file(job.work_dir.join(ladder::FURTHEST_DUMP));
        Ok(setup.solved(ended, line, &progress))
    }
}

/// What an attempt runs with, decided before FEBio starts.
struct Setup<'j, 'a> {
    job: &'j Job<'a>,
    /// The ladder's state: what the earlier attempts at this pose did.
    state: ladder::State,
    plan: ladder::Plan,
    /// The furthest attempt this one continues from its dump.
    resume: Option<ladder::Furthest>,
    /// The record of this attempt as a killed campaign left it running.
    interrupted: Option<running::Running>,
    /// The campaign with the plan's contact.
    campaign: Cow<'a, Campaign>,
    first_contact: Option<feb::FirstContact>,
    /// The written `.feb` (its mesh summary and mirror planes).
    feb: feb::Feb,
}

/// Where an attempt's processes are: the segments so far and how the next one starts.
#[derive(Default)]
struct Progress {
    /// The rigid-body records of the segments before the running process.
    segments: Vec<logs::RigidRecord>,
    cont: restart::Continuations,
    /// The next process restarts from `pose-from.dmp`.
    restarting: bool,
    /// Segment logs kept so far (a continuation or a resumed run keeps the one before).
    segment: u32,
    /// The must point a resumed run goes on from, mm, and whether its first process runs.
    resumed_at_mm: Option<f64>,
    resumed_first: bool,
    notes: Vec<String>,
    totals: logs::RunLog,
    /// The last process's log tail.
    log_tail: String,
    /// When the first process started.
    started: Option<std::time::Instant>,
}

impl Progress {
    /// Seconds since the first process started.
    fn elapsed_s(&self) -> f64 {
        self.started.map(|s| s.elapsed().as_secs_f64()).unwrap_or(0.0)
    }
}

/// How the attempt's last process ended, with the must points of all its segments.
struct Ended {
    done: process::Finished,
    run: logs::RunLog,
    at_steps: Vec<Option<[f64; COMPONENT_COUNT]>>,
    done_steps: usize,
}

impl<'j, 'a> Setup<'j, 'a> {
    fn decide(job: &'j Job<'a>, may_resume: bool) -> Result<Self> {
        // an attempt a killed campaign left running, with its dump, goes on from there
        let interrupted = if may_resume { interrupted_run(job) } else { None };
        let mut state = ladder_state(job, interrupted.is_some())?;
        let symmetry = job.pose.symmetry();
        let full_block = !symmetry.plane_x && !symmetry.plane_z;
        let mut plan = ladder::next(&state, full_block);
        let resume = match plan {
            ladder::Plan::Continue { .. } => match &state.furthest {
                Some(f) if job.work_dir.join(ladder::FURTHEST_DUMP).is_file() => Some(f.clone()),
                // the dump is gone (a folder cleared by hand): the fresh ladder
                _ => {
                    state.furthest = None;
                    plan = ladder::next(&state, full_block);
                    None
                }
            },
            ladder::Plan::Fresh(_) => None,
        };
        // the interrupted attempt's own plan (the ladder's state has not changed since)
        let (plan, resume) = match &interrupted {
            Some(r) => (r.plan, r.continued.clone()),
            None => (plan, resume),
        };
        let campaign = campaign_for(job.campaign, plan.contact(), job.mesh);
        let fs = &campaign.solver.febio;
        let contact_steps = first_contact_steps(fs, &job.campaign.loading, job.steps);
        let first_contact = (!plan.retry_tolerances() && ladder::failed_at_first_contact(&state, contact_steps))
            .then_some(feb::FirstContact { depth_mm: fs.first_contact_depth_mm, step_fraction: fs.first_contact_step_fraction });
        let stepping = stepping(&plan, job.mesh, first_contact);
        // a continuation writes the model too: the record of its contact, kept with its logs
        let feb = feb::write_stepped(&campaign, job.pose, job.mesh, job.steps, &stepping).context("writing the FEBio input")?;
        let input = job.work_dir.join(format!("{JOB}.feb"));
        std::fs::write(&input, &feb.text).with_context(|| format!("{}: cannot write", input.display()))?;
        Ok(Self { job, state, plan, resume, interrupted, campaign, first_contact, feb })
    }

    fn fs(&self) -> &FebioSettings {
        &self.campaign.solver.febio
    }

    /// Whether the attempt converges with the retry tolerances ([`with_retry_tolerances`]).
    fn retry_tolerances(&self) -> bool {
        with_retry_tolerances(&self.plan, self.job.mesh)
    }

    fn loading(&self) -> &'a Loading {
        &self.job.campaign.loading
    }

    fn rb_path(&self) -> PathBuf {
        self.job.work_dir.join(feb::RIGID_LOG)
    }

    fn log_path(&self) -> PathBuf {
        self.job.work_dir.join(format!("{JOB}.log"))
    }

    /// The load step after must point k, in the solver's time (mm of depth, or s).
    fn step_after(&self, k: u32) -> f64 {
        self.loading().step_time((k + 1).min(self.job.steps.max(1)))
    }

    /// The restarts' smallest time step.
    fn dtmin(&self) -> f64 {
        let loading = self.loading();
        let shortest = (1..=self.job.steps.max(1)).map(|k| loading.step_time(k)).fold(f64::INFINITY, f64::min);
        shortest * self.fs().dtmin_fraction * restart::CONTINUE_DTMIN_SCALE
    }

    /// A continuation's restarts set the retry tolerances and residual floor
    /// ([`feb::residual_floor_n`]): the dump carries the run's own.
    fn tolerances(&self) -> Option<restart::Tolerances> {
        let fs = self.fs();
        self.retry_tolerances().then(|| restart::Tolerances {
            dtol: fs.retry_dtol,
            rtol: fs.retry_rtol,
            min_residual_n: feb::residual_floor_n(fs, self.loading(), true),
        })
    }

    /// The first-contact caps of the run whose dump this attempt's restarts read: this
    /// attempt's own, or for a continuation of another attempt that attempt's (its dump
    /// carries its must-point curve; a restart redefines the curve, `restart.rs`).
    fn dump_first_contact(&self) -> Option<feb::FirstContact> {
        match self.plan {
            ladder::Plan::Fresh(_) => self.first_contact,
            ladder::Plan::Continue { from_attempt, .. } => {
                let fs = self.fs();
                ladder::had_first_contact_steps(&self.state, from_attempt, first_contact_steps(fs, self.loading(), self.job.steps))
                    .then_some(feb::FirstContact { depth_mm: fs.first_contact_depth_mm, step_fraction: fs.first_contact_step_fraction })
            }
        }
    }

    /// Copy `dump` (the state at must point `from`) to `pose-from.dmp` and write the
    /// restart input with a first time step of `fraction` of the load step after it.
    fn restart_from(&self, dump: &Path, from: u32, fraction: f64) -> Result<()> {
        let from_dump = self.job.work_dir.join(restart::DUMP_FROM);
        std::fs::copy(dump, &from_dump).with_context(|| format!("{}: cannot copy to {}", dump.display(), from_dump.display()))?;
        let restart_in = self.job.work_dir.join(restart::RESTART_INPUT);
        let must_points = feb::must_points(self.loading(), self.job.steps, self.dump_first_contact());
        let r = restart::Restart {
            must_points: &must_points,
            from,
            first_step: self.step_after(from) * fraction,
            dtmin: self.dtmin(),
            tolerances: self.tolerances(),
        };
        let text = restart::restart_input(&r).with_context(|| format!("{}", restart_in.display()))?;
        std::fs::write(&restart_in, text).with_context(|| format!("{}: cannot write", restart_in.display()))
    }

    /// Keep the running process's logs as segment `n`.
    fn keep_segment_logs(&self, n: u32) -> Result<()> {
        let wd = self.job.work_dir;
        for (from, to) in [(self.rb_path(), restart::segment_log(wd, n)), (self.log_path(), wd.join(restart::segment_solver_log_name(n)))] {
            if from.exists() {
                std::fs::rename(&from, &to).with_context(|| format!("{}: cannot keep as {}", from.display(), to.display()))?;
            }
        }
        Ok(())
    }

    /// How the first process starts: from the interrupted run's dump when it can go on
    /// from there, else from the furthest attempt's dump (a continuation), else fresh in
    /// a folder without an earlier attempt's files.
    fn start(&mut self, note: Option<String>) -> Result<Progress> {
        let job = self.job;
        let loading = self.loading();
        let mut progress =
            Progress { notes: note.map(|n| format!("{n}: rerun from its start")).into_iter().collect(), ..Progress::default() };
        let resumed = self.interrupted.take().and_then(|r| match self.resume_point(&r) {
            Ok(p) => Some((r, p)),
            Err(why) => {
                needle_stdx::noteln!(
                    "{}: attempt {}: the interrupted run cannot go on from its dump ({why}); the attempt starts again from its start",
                    job.pose.name,
                    job.attempt + 1
                );
                progress.notes.push(format!("an interrupted run could not go on from its dump ({why}): rerun from its start"));
                None
            }
        });
        if let Some((r, p)) = &resumed {
            self.keep_segment_logs(r.segments)?;
            progress.segment = r.segments + 1;
            progress.segments = p.records.clone();
            progress.cont = restart::Continuations { from_mm: r.continued_from.clone() };
            self.restart_from(&job.work_dir.join(restart::DUMP), p.steps, self.plan.first_increment())?;
            progress.resumed_at_mm = Some(loading.depth_at(p.steps));
            progress.resumed_first = true;
            needle_stdx::noteln!(
                "{}: attempt {}: going on from its dump at {} {} ({})",
                job.pose.name,
                job.attempt + 1,
                loading.time_at(p.steps),
                loading.time_unit(),
                self.plan.describe(loading.depth_mm, job.steps)
            );
            progress.restarting = true;
            return Ok(progress);
        }
        // files of an earlier attempt in this folder would be taken for this one's
        for n in 0..=restart::MAX_SEGMENTS {
            remove_if_exists(&restart::segment_log(job.work_dir, n))?;
            remove_if_exists(&job.work_dir.join(restart::segment_solver_log_name(n)))?;
        }
        for f in [self.rb_path(), self.log_path(), job.work_dir.join(restart::DUMP), job.work_dir.join(restart::DUMP_FROM)] {
            remove_if_exists(&f)?;
        }
        if let Some(f) = &self.resume {
            self.restart_from(&job.work_dir.join(ladder::FURTHEST_DUMP), f.steps, self.plan.first_increment())?;
            progress.segments = f.rigid_records(loading);
            needle_stdx::noteln!("{}: attempt {}: {}", job.pose.name, job.attempt + 1, self.plan.describe(loading.depth_mm, job.steps));
            progress.restarting = true;
        }
        Ok(progress)
    }

    /// The must point the interrupted run `r` can go on from (`running::resume_point`,
    /// and room for one more segment).
    fn resume_point(&self, r: &running::Running) -> std::result::Result<running::ResumePoint, String> {
        let current = std::fs::read_to_string(self.rb_path()).ok().and_then(|t| logs::parse_rigid_log(&t).ok()).unwrap_or_default();
        let dump = self.job.work_dir.join(restart::DUMP);
        let p = running::resume_point(&dump, &r.earlier, &current, self.loading(), self.job.steps)?;
        if r.segments + 1 < restart::MAX_SEGMENTS {
            Ok(p)
        } else {
            Err(format!("{} segments run already", r.segments))
        }
    }

    /// FEBio's processes until one ends the attempt; `None` (with `unreadable` set) when
    /// a resumed run's restart could not read its dump.
    fn run_segments(&self, exe: &Path, threads: usize, p: &mut Progress, unreadable: &mut Option<String>) -> Result<Option<Ended>> {
        let job = self.job;
        let loading = self.loading();
        let started = *p.started.get_or_insert_with(std::time::Instant::now);
        loop {
            let (done, run, log_text) = self.run_process(exe, threads, p, started)?;
            p.totals.time_steps += run.time_steps;
            p.totals.iterations += run.iterations;
            p.totals.retries += run.retries;
            p.totals.floor_accepted += run.floor_accepted;
            let tail_src = if log_text.trim().is_empty() { &done.log_text } else { &log_text };
            p.log_tail = process::tail(tail_src, LOG_TAIL_LINES);
            let records = std::fs::read_to_string(self.rb_path())
                .map_err(anyhow::Error::from)
                .and_then(|t| logs::parse_rigid_log(&t))
                .with_context(|| format!("{}", self.rb_path().display()));
            let mut all = p.segments.clone();
            if let Ok(r) = &records {
                all.extend(segment_results(&p.segments, r, loading.time_at(job.steps)));
            }
            let at_steps = pick_steps(&all, loading, job.steps);
            let done_steps = at_steps.iter().take_while(|w| w.is_some()).count();
            let solved = done.exit == ExitKind::Code(0) && run.normal_termination && done_steps >= job.steps as usize;
            // a resumed run whose restart exited without reading its dump: from the start
            let restart_failed = matches!(done.exit, ExitKind::Code(c) if c != 0)
                && !done.log_text.contains(running::RESTARTED)
                && !log_text.contains(running::RESTARTED);
            if std::mem::take(&mut p.resumed_first) && restart_failed && !process::interrupted() {
                running::remove(job.work_dir);
                *unreadable =
                    Some(format!("FEBio's restart could not read the interrupted run's dump ({})", process::tail(&p.log_tail, 2).trim()));
                return Ok(None);
            }
            let Some(fraction) = self.next_continuation(p, &done, solved, done_steps) else {
                p.segments = all;
                return Ok(Some(Ended { done, run, at_steps, done_steps }));
            };
            // the must point reached, in the solver's time (mm of depth, or s)
            let last_mm = loading.time_at(done_steps as u32);
            needle_stdx::noteln!(
                "{}: febio4 stopped at t = {} {unit} ({}); continuing from the must point at {last_mm} {unit} with a first time step of {} {unit}",
                job.pose.name,
                run.last_time,
                run.cause.as_deref().unwrap_or("no stated cause"),
                self.step_after(done_steps as u32) * fraction,
                unit = loading.time_unit()
            );
            self.keep_segment_logs(p.segment)?;
            p.segment += 1;
            p.segments = all;
            self.restart_from(&job.work_dir.join(restart::DUMP), done_steps as u32, fraction)?;
            p.cont.from_mm.push(last_mm);
            p.restarting = true;
        }
    }

    /// One FEBio process (recorded in `running.toml` first); its end, parsed log and
    /// log text.
    fn run_process(
        &self,
        exe: &Path,
        threads: usize,
        p: &Progress,
        started: std::time::Instant,
    ) -> Result<(process::Finished, logs::RunLog, String)> {
        let job = self.job;
        let mut cmd = Command::new(exe);
        cmd.arg("-nosplash");
        if p.restarting {
            cmd.arg("-r").arg(restart::RESTART_INPUT).arg("-noappend").arg("-p").arg(format!("{JOB}.xplt"));
        } else {
            cmd.arg("-i").arg(format!("{JOB}.feb")).arg("-p").arg(format!("{JOB}.xplt"));
        }
        cmd.arg("-o")
            .arg(format!("{JOB}.log"))
            .arg("-dump=3")
            .arg(restart::DUMP)
            .env("OMP_NUM_THREADS", threads.to_string())
            .env("MKL_NUM_THREADS", threads.to_string());
        let now = running::Running {
            attempt: job.attempt,
            plan: self.plan,
            continued: self.resume.clone(),
            earlier: p.segments.clone(),
            continued_from: p.cont.from_mm.clone(),
            segments: p.segment,
        };
        if let Err(e) = running::write(job.work_dir, &now) {
            needle_stdx::noteln!("{}: {e:#} (a killed campaign would rerun this attempt from its start)", job.pose.name);
        }
        let timeout = job.timeout.map(|t| t.saturating_sub(started.elapsed()));
        let out_path = job.work_dir.join("febio.out");
        let done = process::run(cmd, job.work_dir, &out_path, &[self.log_path(), self.rb_path()], timeout, job.stall)?;
        let log_text = std::fs::read_to_string(self.log_path()).unwrap_or_default();
        let run = logs::parse_run_log(if log_text.is_empty() { &done.log_text } else { &log_text });
        Ok((done, run, log_text))
    }

    /// The first time step (fraction of a load step) of a continuation from the last
    /// must point: when the solver gave up (not on a timeout, stall or stop) and a dump of
    /// a converged must point exists; the must point a continuation of another attempt
    /// started from counts as one.
    fn next_continuation(&self, p: &Progress, done: &process::Finished, solved: bool, done_steps: usize) -> Option<f64> {
        let loading = self.loading();
        let last_mm = loading.time_at(done_steps as u32);
        let mut tried_from = p.cont.clone();
        if let Some(f) = &self.resume {
            tried_from.from_mm.insert(0, loading.time_at(f.steps));
        }
        (!solved && matches!(done.exit, ExitKind::Code(_)) && done_steps > 0 && !process::interrupted())
            .then(|| tried_from.next_fraction(last_mm))
            .flatten()
            .filter(|_| self.job.work_dir.join(restart::DUMP).is_file())
    }

    /// The manifest's settings line of the attempt.
    fn settings(&self, threads: usize, p: &Progress) -> String {
        let loading = self.loading();
        let mut line = settings_line(self.fs(), self.campaign.contact.friction, threads, self.retry_tolerances());
        if let Some(fc) = self.first_contact {
            line.push_str(&format!("; time steps <= {} of a load step to {} mm (first contact)", fc.step_fraction, fc.depth_mm));
        }
        if let Some(f) = &self.resume {
            line.push_str(&format!(
                "; continued attempt {}'s last converged must point ({} mm; to there: {})",
                f.attempt,
                loading.depth_at(f.steps),
                f.settings
            ));
        }
        let continued = p.cont.describe_in(loading.time_unit());
        if !continued.is_empty() {
            line.push_str(&format!("; {continued}"));
        }
        if let Some(at) = p.resumed_at_mm {
            line.push_str(&format!("; resumed after an interruption at {at} mm"));
        }
        if p.totals.floor_accepted > 0 && self.retry_tolerances() && self.fs().retry_min_residual_n > 0.0 {
            line.push_str(&format!("; the residual floor accepted {} iteration(s)", p.totals.floor_accepted));
        }
        for n in &p.notes {
            line.push_str(&format!("; {n}"));
        }
        line
    }

    /// The ladder's record of this failed attempt, with its dump kept when it got further
    /// than any before it.
    fn keep_for_ladder(&mut self, e: &Ended, line: &str) -> Result<()> {
        let job = self.job;
        let steps = e.done_steps as u32;
        let dump = job.work_dir.join(restart::DUMP);
        let mut kept_dump = false;
        if self.state.is_further(steps) && dump.is_file() {
            let furthest = job.work_dir.join(ladder::FURTHEST_DUMP);
            std::fs::rename(&dump, &furthest).with_context(|| format!("{}: cannot keep as {}", dump.display(), furthest.display()))?;
            let records = e.at_steps.iter().take(e.done_steps).map_while(|v| *v).collect();
            self.state.furthest = Some(ladder::Furthest { attempt: job.attempt + 1, steps, records, settings: line.to_string() });
            kept_dump = true;
        }
        self.state.tried.push(ladder::Tried { attempt: job.attempt + 1, plan: self.plan, reached_steps: steps });
        self.state.write(job.work_dir)?;
        if kept_dump {
            needle_stdx::noteln!(
                "{}: attempt {}'s dump at {} mm kept for the next attempt",
                job.pose.name,
                job.attempt + 1,
                self.loading().depth_at(steps)
            );
        }
        Ok(())
    }

    /// The failure of the attempt: how FEBio ended, how far, after what; the must points
    /// reached.
    fn failure(&self, e: Ended, p: &Progress) -> SolveFailure {
        let job = self.job;
        let loading = self.loading();
        let how = match e.done.exit {
            ExitKind::Code(0) if e.run.error_termination => "ended with ERROR TERMINATION".to_string(),
            ExitKind::Code(0) => "exited 0".to_string(),
            x => x.to_string(),
        };
        let kept = keep_failed_attempt(job);
        let continued = p.cont.describe_in(loading.time_unit());
        let resumed = self.resume.as_ref().map(|f| format!(", continuing attempt {} from {} mm", f.attempt, loading.depth_at(f.steps)));
        let resumed =
            resumed.into_iter().chain(p.resumed_at_mm.map(|at| format!(", resumed after an interruption at {at} mm"))).collect::<String>();
        let symmetry = self.feb.symmetry;
        SolveFailure {
            message: format!(
                "febio4 {how} after {} of {} steps (t = {} {}), {} time steps, {} retries, {:.1} s{}{}{}{kept}",
                e.done_steps,
                job.steps,
                // a continuation that failed before converging a step logs no time: the
                // must points done are reached
                e.run.last_time.max(loading.time_at(e.done_steps as u32)),
                loading.time_unit(),
                p.totals.time_steps,
                p.totals.retries,
                p.elapsed_s(),
                resumed,
                if continued.is_empty() { String::new() } else { format!(", {continued}") },
                e.run.cause.as_deref().map(|c| format!(": {c}")).unwrap_or_default(),
            ),
            log_tail: p.log_tail.clone(),
            reached: e.at_steps.iter().map_while(|v| v.map(|v| expand_mirrors(v.map(|x| REACTION_SIGN * x), symmetry))).collect(),
        }
    }

    /// The solved attempt's wrenches at every must point and its record.
    fn solved(self, e: Ended, line: String, p: &Progress) -> Solved {
        let symmetry = self.feb.symmetry;
        let wrenches = e
            .at_steps
            .into_iter()
            .map(|v| {
                let v = v.unwrap_or([f64::NAN; COMPONENT_COUNT]);
                expand_mirrors(v.map(|x| REACTION_SIGN * x), symmetry)
            })
            .collect();
        Solved {
            wrenches,
            summary: self.feb.summary,
            increments: p.totals.time_steps,
            iterations: p.totals.iterations,
            first_increment: self.plan.first_increment(),
            retry: None,
            element: "hex8, three-field (u-p-J) for the uncoupled Ogden tissue; rigid-body needle".into(),
            peak_rss_mib: e.done.peak_rss_mib,
            settings: line,
        }
    }
}

/// The ladder's state of `job`'s pose: none on a first attempt that does not resume (its
/// files removed), else the work folder's without attempts from this one on (an attempt
/// rerun after a kill in its bookkeeping is not one of the earlier ones).
fn ladder_state(job: &Job<'_>, resuming: bool) -> Result<ladder::State> {
    if job.attempt == 0 && !resuming {
        remove_if_exists(&job.work_dir.join(ladder::STATE_FILE))?;
        remove_if_exists(&job.work_dir.join(ladder::FURTHEST_DUMP))?;
        return Ok(ladder::State::default());
    }
    let mut s = ladder::State::read(job.work_dir)?;
    s.tried.retain(|t| t.attempt <= job.attempt);
    Ok(s)
}

/// The campaign with the contact `contact` asks for (`retry_seg_up`, the softer penalty)
/// and the mesh level's own energy and residual tolerances and retry residual floor
/// (`[mesh.<level>] etol`, `rtol`, `retry_rtol`, `retry_min_residual_n`; the level's
/// `rtol` replaces the retries' `retry_rtol` too, unless the level has its own).
fn campaign_for<'c>(campaign: &'c Campaign, contact: ladder::Fresh, mesh: &MeshLevel) -> Cow<'c, Campaign> {
    let own_tolerances = mesh.etol.is_some() || mesh.rtol.is_some() || mesh.retry_rtol.is_some() || mesh.retry_min_residual_n.is_some();
    if contact.seg_up == ladder::SegUp::Spec && !contact.softer && !own_tolerances {
        return Cow::Borrowed(campaign);
    }
    let mut c = campaign.clone();
    let s = &mut c.solver.febio;
    if let Some(etol) = mesh.etol {
        s.etol = etol;
    }
    if let Some(rtol) = mesh.rtol {
        s.rtol = rtol;
        s.retry_rtol = rtol;
    }
    if let Some(rtol) = mesh.retry_rtol {
        s.retry_rtol = rtol;
    }
    if let Some(floor_n) = mesh.retry_min_residual_n {
        s.retry_min_residual_n = floor_n;
    }
    if contact.seg_up == ladder::SegUp::Retry {
        s.seg_up = s.retry_seg_up;
    }
    if contact.softer {
        s.penalty *= s.last_attempt_penalty_scale;
    }
    Cow::Owned(c)
}

/// How an attempt with `plan` on level `mesh` steps and converges: the plan's first
/// increment, the retry tolerances for the ladder's retries and for every attempt on a
/// level that asks for them first ([`MeshLevel::retry_tolerances_first`]).
fn stepping(plan: &ladder::Plan, mesh: &MeshLevel, first_contact: Option<feb::FirstContact>) -> feb::Stepping {
    feb::Stepping { first_step_fraction: plan.first_increment(), retry_tolerances: with_retry_tolerances(plan, mesh), first_contact }
}

/// Whether an attempt with `plan` on level `mesh` converges with the retry tolerances.
fn with_retry_tolerances(plan: &ladder::Plan, mesh: &MeshLevel) -> bool {
    plan.retry_tolerances() || mesh.retry_tolerances_first()
}

/// The load steps that start within the first-contact depth.
fn first_contact_steps(fs: &FebioSettings, loading: &Loading, steps: u32) -> u32 {
    if loading.ramp_hold.is_some() {
        // uneven must points: the steps that start within the first-contact depth
        (1..=steps).take_while(|&k| loading.depth_at(k - 1) < fs.first_contact_depth_mm - 1e-9 * loading.depth_mm).count() as u32
    } else {
        ladder::first_contact_steps(fs.first_contact_depth_mm, loading.depth_mm, steps)
    }
}

#[cfg(test)]
mod level_tolerance_tests {
    use super::*;

    /// The shipped spec and its `fine` level (the mesh study's reference).
    fn shipped_fine() -> (Campaign, MeshLevel) {
        let set = needle_stdx::workspace_root().join("coeffs/default");
        let (c, _) = crate::spec::load(&set).expect("the shipped spec");
        let own = c.mesh_level("fine").expect("fine").clone();
        (c, own)
    }

    /// `[mesh.<level>] etol` reaches the FEBio input of every attempt on that level, and
    /// only there (the mesh study's reference level, coeffs/README.md).
    #[test]
    fn a_levels_energy_tolerance_replaces_the_solvers() {
        let (c, own) = shipped_fine();
        let centre = c.pose.iter().find(|p| p.name == "centre").expect("centre");
        let etol = own.etol.expect("the shipped fine level has its own etol");
        assert_ne!(etol, c.solver.febio.etol, "the shipped fine level's etol differs from the solver's");
        let plain = MeshLevel { etol: None, ..own.clone() };
        for contact in [
            ladder::Fresh { seg_up: ladder::SegUp::Spec, softer: false, quarter: false },
            ladder::Fresh { seg_up: ladder::SegUp::Retry, softer: true, quarter: true },
        ] {
            assert_eq!(campaign_for(&c, contact, &own).solver.febio.etol, etol, "{contact:?}");
            assert_eq!(campaign_for(&c, contact, &plain).solver.febio.etol, c.solver.febio.etol, "{contact:?}");
            let text = |level: &MeshLevel| {
                let stepping = feb::Stepping { first_step_fraction: 1.0, retry_tolerances: false, first_contact: None };
                feb::write_stepped(&campaign_for(&c, contact, level), centre, level, 2, &stepping).expect("the FEBio input").text
            };
            assert!(text(&own).contains(&format!("<etol>{}</etol>", feb::num(etol))), "{contact:?}");
            assert!(text(&plain).contains(&format!("<etol>{}</etol>", feb::num(c.solver.febio.etol))), "{contact:?}");
        }
        assert_ne!(
            c.run_hash(centre, "fine"),
            crate::spec::Campaign { mesh: [("fine".to_string(), plain)].into_iter().collect(), ..c.clone() }.run_hash(centre, "fine"),
            "the level's etol is part of its runs' hash"
        );
    }

    /// `[mesh.<level>] rtol` reaches the FEBio input of every attempt on that level, the
    /// first (in place of `rtol`) and the retries and their restarts (in place of
    /// `retry_rtol`), and is part of both hashes.
    #[test]
    fn a_levels_residual_tolerance_replaces_both_of_the_solvers() {
        let (c, shipped) = shipped_fine();
        let centre = c.pose.iter().find(|p| p.name == "centre").expect("centre");
        let fs = &c.solver.febio;
        let rtol = fs.rtol.min(fs.retry_rtol) / 100.0;
        let own = MeshLevel { rtol: Some(rtol), ..shipped.clone() };
        let plain = MeshLevel { rtol: None, ..shipped };
        let contact = ladder::Fresh { seg_up: ladder::SegUp::Spec, softer: false, quarter: false };
        let text = |level: &MeshLevel, retry_tolerances: bool| {
            let stepping = feb::Stepping { first_step_fraction: 1.0, retry_tolerances, first_contact: None };
            feb::write_stepped(&campaign_for(&c, contact, level), centre, level, 2, &stepping).expect("the FEBio input").text
        };
        let tag = |v: f64| format!("<rtol>{}</rtol>", feb::num(v));
        for retry in [false, true] {
            assert!(text(&own, retry).contains(&tag(rtol)), "retry tolerances {retry}");
        }
        assert!(text(&plain, false).contains(&tag(fs.rtol)) && text(&plain, true).contains(&tag(fs.retry_rtol)));
        assert_eq!(campaign_for(&c, contact, &own).solver.febio.retry_rtol, rtol, "a continuation's restart reads retry_rtol");
        let on = |level: MeshLevel| crate::spec::Campaign { mesh: [("fine".to_string(), level)].into_iter().collect(), ..c.clone() };
        let (with, without) = (on(own), on(plain));
        assert_ne!(with.run_hash(centre, "fine"), without.run_hash(centre, "fine"), "the level's rtol is part of the run hash");
        assert_ne!(with.first_attempt_hash(centre, "fine"), without.first_attempt_hash(centre, "fine"), "and of the first attempt's");
    }

    /// `[mesh.<level>] retry_min_residual_n` reaches the retries' FEBio input on that
    /// level (FEBio's `min_residual`, squared), not the first attempt's, and is part of
    /// the run hash but not of the first-attempt hash.
    #[test]
    fn a_levels_residual_floor_replaces_the_retrys_and_only_there() {
        let (c, own) = shipped_fine();
        let centre = c.pose.iter().find(|p| p.name == "centre").expect("centre");
        let floor_n = own.retry_min_residual_n.expect("the shipped fine level has its own residual floor");
        assert_ne!(floor_n, c.solver.febio.retry_min_residual_n, "the shipped fine level's floor differs from the solver's");
        let plain = MeshLevel { retry_min_residual_n: None, ..own.clone() };
        let contact = ladder::Fresh { seg_up: ladder::SegUp::Spec, softer: false, quarter: false };
        assert_eq!(campaign_for(&c, contact, &own).solver.febio.retry_min_residual_n, floor_n);
        assert_eq!(campaign_for(&c, contact, &plain).solver.febio.retry_min_residual_n, c.solver.febio.retry_min_residual_n);
        let text = |retry_tolerances: bool| {
            let stepping = feb::Stepping { first_step_fraction: 1.0, retry_tolerances, first_contact: None };
            feb::write_stepped(&campaign_for(&c, contact, &own), centre, &own, 2, &stepping).expect("the FEBio input").text
        };
        let squared = format!("<min_residual>{}</min_residual>", feb::num(floor_n * floor_n));
        assert!(text(true).contains(&squared), "the retry's input has {squared}");
        assert!(!text(false).contains(&squared), "the first attempt's input has FEBio's own floor");
        let without = crate::spec::Campaign { mesh: [("fine".to_string(), plain)].into_iter().collect(), ..c.clone() };
        assert_ne!(c.run_hash(centre, "fine"), without.run_hash(centre, "fine"), "the floor is part of the run hash");
        assert_eq!(c.first_attempt_hash(centre, "fine"), without.first_attempt_hash(centre, "fine"), "but not of the first attempt's");
    }

    /// `[mesh.<level>] retry_rtol` reaches the retries' FEBio input on that level (and a
    /// continuation's restart), not the first attempt's, and is part of the run hash but
    /// not of the first-attempt hash.
    #[test]
    fn a_levels_retry_residual_tolerance_replaces_the_retrys_and_only_there() {
        let set = needle_stdx::workspace_root().join("coeffs/default");
        let (c, _) = crate::spec::load(&set).expect("the shipped spec");
        let own = c.mesh_level("core6").expect("core6").clone();
        let centre = c.pose.iter().find(|p| p.name == "centre").expect("centre");
        let fs = &c.solver.febio;
        let rtol = own.retry_rtol.expect("the shipped core6 level has its own retry tolerance");
        assert!(rtol != fs.retry_rtol && rtol != fs.rtol, "core6's retry_rtol differs from the solver's rtol and retry_rtol");
        let plain = MeshLevel { retry_rtol: None, ..own.clone() };
        let contact = ladder::Fresh { seg_up: ladder::SegUp::Spec, softer: false, quarter: false };
        assert_eq!(campaign_for(&c, contact, &own).solver.febio.retry_rtol, rtol, "a continuation's restart reads retry_rtol");
        let text = |retry_tolerances: bool| {
            let stepping = feb::Stepping { first_step_fraction: 1.0, retry_tolerances, first_contact: None };
            feb::write_stepped(&campaign_for(&c, contact, &own), centre, &own, 2, &stepping).expect("the FEBio input").text
        };
        let tag = |v: f64| format!("<rtol>{}</rtol>", feb::num(v));
        assert!(text(true).contains(&tag(rtol)), "the retry's input has {}", tag(rtol));
        assert!(text(false).contains(&tag(fs.rtol)) && !text(false).contains(&tag(rtol)), "the first attempt's has the solver's rtol");
        let on = |level: MeshLevel| crate::spec::Campaign { mesh: [("core6".to_string(), level)].into_iter().collect(), ..c.clone() };
        let (with, without) = (on(own), on(plain));
        assert_ne!(with.run_hash(centre, "core6"), without.run_hash(centre, "core6"), "part of the run hash");
        assert_eq!(with.first_attempt_hash(centre, "core6"), without.first_attempt_hash(centre, "core6"), "not of the first attempt's");
    }

    /// `[mesh.<level>] first_attempt_retry_tolerances = true`: the first attempt's FEBio
    /// input on that level has the retries' dtol, the level's retry_rtol and its squared
    /// residual floor, with whole load steps; the flag is part of both hashes, and with it
    /// the retry settings are part of the first attempt's.
    #[test]
    fn a_level_may_give_its_first_attempt_the_retry_tolerances() {
        let set = needle_stdx::workspace_root().join("coeffs/default");
        let (c, _) = crate::spec::load(&set).expect("the shipped spec");
        let plain = MeshLevel { first_attempt_retry_tolerances: None, ..c.mesh_level("core6").expect("core6").clone() };
        let own = MeshLevel { first_attempt_retry_tolerances: Some(true), ..plain.clone() };
        let centre = c.pose.iter().find(|p| p.name == "centre").expect("centre");
        let fs = &c.solver.febio;
        let (rtol, floor_n) = (own.retry_rtol.expect("core6's retry_rtol"), own.retry_min_residual_n.expect("core6's floor"));
        assert!(fs.dtol != fs.retry_dtol && fs.rtol != rtol, "the shipped first and retry tolerances differ");
        let first = ladder::Plan::Fresh(ladder::Fresh { seg_up: ladder::SegUp::Spec, softer: false, quarter: false });
        let text = |level: &MeshLevel| {
            let st = stepping(&first, level, None);
            assert_eq!(st.first_step_fraction, 1.0, "whole load steps");
            feb::write_stepped(&campaign_for(&c, first.contact(), level), centre, level, 2, &st).expect("the FEBio input").text
        };
        let tags = |dtol: f64, rtol: f64| [format!("<dtol>{}</dtol>", feb::num(dtol)), format!("<rtol>{}</rtol>", feb::num(rtol))];
        let floor = format!("<min_residual>{}</min_residual>", feb::num(floor_n * floor_n));
        let (with, without) = (text(&own), text(&plain));
        assert!(tags(fs.retry_dtol, rtol).iter().all(|t| with.contains(t)) && with.contains(&floor), "the retries' tolerances");
        assert!(tags(fs.dtol, fs.rtol).iter().all(|t| without.contains(t)) && !without.contains(&floor), "the solver's");
        let on = |level: MeshLevel| crate::spec::Campaign { mesh: [("core6".to_string(), level)].into_iter().collect(), ..c.clone() };
        let first_hash = |level: &MeshLevel| on(level.clone()).first_attempt_hash(centre, "core6");
        assert_ne!(on(own.clone()).run_hash(centre, "core6"), on(plain.clone()).run_hash(centre, "core6"), "the flag: run hash");
        assert_ne!(first_hash(&own), first_hash(&plain), "the flag: first-attempt hash");
        let looser = MeshLevel { retry_rtol: Some(rtol * 10.0), ..own.clone() };
        assert_ne!(first_hash(&own), first_hash(&looser), "with the flag, retry_rtol is part of the first attempt's hash");
        let looser_plain = MeshLevel { retry_rtol: Some(rtol * 10.0), ..plain.clone() };
        assert_eq!(first_hash(&plain), first_hash(&looser_plain), "without it, not");
    }
}
