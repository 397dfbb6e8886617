//! [`CcxBackend`]: the campaign's [`Backend`] on CalculiX. It writes the deck
//! ([`deck`]), runs `ccx` ([`super::run_job`]), reads the `.dat` back ([`dat`]) and
//! reduces the needle's nodal reactions to the wrench ([`reactions`]).

use super::{dat, deck, reactions};
use crate::backend::{Backend, Job, SolveFailure, Solved};
use anyhow::{bail, Context, Result};
use std::path::{Path, PathBuf};

/// The ccx job name inside a pose's work folder (`pose.inp`, `pose.dat`, `pose.sta`...).
pub const JOB: &str = "pose";

/// The real backend: the project's deck writer, CalculiX, the `.dat` reader and the
/// wrench reduction.
#[derive(Debug, Default)]
pub struct CcxBackend {
    ccx: Option<PathBuf>,
}

impl Backend for CcxBackend {
    fn prepare(&mut self) -> Result<String> {
        let path = super::find_ccx()?;
        let version = super::ccx_version(&path)?;
        self.ccx = Some(path);
        Ok(version)
    }

    fn engine(&self) -> &'static str {
        "ccx"
    }

    fn solve(&self, job: &Job<'_>) -> std::result::Result<Solved, SolveFailure> {
        let first_increment = job.first_increment;
        let ccx_path = self.ccx.as_deref().context("CcxBackend::solve before prepare")?;
        let deck =
            deck::write_deck_first_increment(job.campaign, job.pose, job.mesh, job.steps, first_increment).context("writing the deck")?;
        if deck.steps != job.steps {
            return Err(anyhow::anyhow!("the deck has {} steps, {} were asked for", deck.steps, job.steps).into());
        }
        let inp = job.work_dir.join(format!("{JOB}.inp"));
        std::fs::write(&inp, &deck.text).with_context(|| format!("{}: cannot write", inp.display()))?;
        let r = super::run_job(ccx_path, job.work_dir, JOB, job.timeout, job.stall)?;
        let done = r.sta.steps_done();
        if !r.success() || done < job.steps {
            let how = if r.success() { "finished (exit code 0)".to_string() } else { r.exit.to_string() };
            let kept = keep_failed_attempt(job);
            return Err(SolveFailure {
                message: format!(
                    "ccx {how} after {done} of {} steps, {} increments, {:.1} s{}{kept}",
                    job.steps,
                    r.sta.increments,
                    r.wall.as_secs_f64(),
                    r.cause.as_deref().map(|c| format!(": {c}")).unwrap_or_default(),
                ),
                log_tail: r.log_tail,
                reached: Vec::new(),
            });
        }
        let fail = |e: anyhow::Error| SolveFailure { message: format!("{e:#}"), log_tail: r.log_tail.clone(), reached: Vec::new() };
        let dat_path = job.work_dir.join(format!("{JOB}.dat"));
        let text = std::fs::read_to_string(&dat_path).with_context(|| format!("{}: cannot read", dat_path.display())).map_err(fail)?;
        let blocks = dat::parse_rf(&text, &deck.print_set).with_context(|| format!("{}", dat_path.display())).map_err(fail)?;
        check_step_times(&blocks, job.steps).with_context(|| format!("{}", dat_path.display())).map_err(fail)?;
        let wrenches = blocks
            .iter()
            .enumerate()
            .map(|(k, b)| {
                reactions::reduce(&deck, job.pose, job.campaign, &b.nodes)
                    .with_context(|| format!("reducing the reactions of step {}", k + 1))
            })
            .collect::<Result<Vec<_>>>()
            .map_err(fail)?;
        Ok(Solved {
            wrenches,
            summary: deck.summary,
            increments: r.sta.increments,
            iterations: r.sta.iterations,
            first_increment,
            retry: None,
            element: "C3D8 (fully integrated hexahedron)".into(),
            peak_rss_mib: r.peak_rss_mib,
            settings: format!(
                "surface-to-surface penalty contact {} N/mm^3, friction {} (stick slope {} N/mm^3); SPOOLES, 1 thread",
                job.campaign.contact.penalty_slope_n_per_mm3, job.campaign.contact.friction, job.campaign.contact.stick_slope_n_per_mm3
            ),
        })
    }

    fn steps_done(&self, work_dir: &Path) -> u32 {
        super::steps_done(work_dir, JOB)
    }
}

/// The deck prints the reactions once at the end of each step; step k ends at total
/// time k. Check that there is exactly one block per step, in order.
fn check_step_times(blocks: &[dat::StepRf], steps: u32) -> Result<()> {
    if blocks.len() != steps as usize {
        bail!(
            "{} reaction force blocks (times {}), expected one per step ({steps})",
            blocks.len(),
            blocks.iter().map(|b| b.total_time.to_string()).collect::<Vec<_>>().join(", ")
        );
    }
    for (k, b) in (1u32..).zip(blocks) {
        let want = f64::from(k);
        if (b.total_time - want).abs() > 1e-5 * want {
            bail!("reaction force block {k} is at time {}, expected {want} (end of step {k})", b.total_time);
        }
    }
    Ok(())
}

/// Keep a failed ccx attempt's log, status and SPOOLES files (see
/// [`process::keep_failed_attempt`](crate::process::keep_failed_attempt)).
fn keep_failed_attempt(job: &Job<'_>) -> String {
    let files = [(format!("{JOB}.log"), "log"), (format!("{JOB}.sta"), "sta"), ("spooles.out".to_string(), "spooles.out")];
    crate::process::keep_failed_attempt(job.work_dir, &format!("first-increment-{}", job.first_increment), &files)
}
