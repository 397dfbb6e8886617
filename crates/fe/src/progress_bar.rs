//! The progress display of `needle fe run`: runs done, running (with their load step)
//! and left, with an ETA; an indicatif bar on a terminal, plain lines otherwise (CI).
//!
//! The ETA comes from measured run times when there are any: each run is expected to
//! take the median wall time of the runs of its model (quarter, half or full block) on
//! the same mesh and step count, from the manifest and from this campaign's finished
//! runs, and the runs are scheduled over the jobs. Without them it comes from the load
//! steps done so far, which underestimates: the deeper steps take more increments.

use crate::report::{PoseReport, Status};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::collections::BTreeMap;
use std::io::IsTerminal;
use std::time::{Duration, Instant};

/// Progress display: an indicatif bar on a terminal, plain lines otherwise (CI).
pub(crate) struct Progress {
    names: Vec<String>,
    /// Model of each run (`mesh::summary::model_name`), the key of `walls_s`.
    models: Vec<String>,
    /// Runs finished (done or failed).
    finished: Vec<bool>,
    steps: u32,
    jobs: usize,
    /// Wall times of finished runs by model, s: the manifest's, then this campaign's.
    walls_s: BTreeMap<String, Vec<f64>>,
    /// Running jobs: load steps done and start time.
    running: BTreeMap<usize, (u32, Instant)>,
    done: usize,
    failed: usize,
    bar: Option<ProgressBar>,
    start: Instant,
    last_plain: Instant,
    /// Counts and running steps of the last plain line (printed again when they change).
    last_line: String,
}

impl Progress {
    /// `runs`: (pose name, model) in queue order; `earlier_walls_s`: measured wall times
    /// by model ([`Manifest::wall_times_s`](crate::manifest::Manifest::wall_times_s)).
    pub(crate) fn new(runs: Vec<(String, String)>, steps: u32, jobs: usize, earlier_walls_s: BTreeMap<String, Vec<f64>>) -> Self {
        let (names, models): (Vec<String>, Vec<String>) = runs.into_iter().unzip();
        let total_steps = names.len() as u64 * u64::from(steps);
        let bar = std::io::stderr().is_terminal().then(|| {
            let bar = ProgressBar::with_draw_target(Some(total_steps), ProgressDrawTarget::stderr_with_hz(4));
            let style = ProgressStyle::with_template("[{elapsed_precise}] {bar:30.cyan/blue} {percent:>3}% | {prefix}\n  {wide_msg}")
                .unwrap_or_else(|_| ProgressStyle::default_bar())
                .progress_chars("=> ");
            bar.set_style(style);
            bar
        });
        let now = Instant::now();
        let mut p = Progress {
            finished: vec![false; names.len()],
            names,
            models,
            steps,
            jobs: jobs.max(1),
            walls_s: earlier_walls_s,
            running: BTreeMap::new(),
            done: 0,
            failed: 0,
            bar,
            start: now,
            last_plain: now,
            last_line: String::new(),
        };
        p.redraw();
        p
    }

    fn name(&self, i: usize) -> &str {
        self.names.get(i).map(String::as_str).unwrap_or("?")
    }

    /// Runs neither finished nor running, in queue order.
    fn left(&self) -> impl Iterator<Item = usize> + '_ {
        (0..self.names.len()).filter(|i| !self.running.contains_key(i) && !self.finished.get(*i).copied().unwrap_or(true))
    }

    fn counts(&self) -> String {
        let finished = self.done + self.failed;
        let left = self.left().count();
        let mut s = format!("{finished}/{} runs done, {} running, {left} left", self.names.len(), self.running.len());
        if self.failed > 0 {
            s.push_str(&format!(", {} failed", self.failed));
        }
        s
    }

    fn running_text(&self) -> String {
        if self.running.is_empty() {
            return "-".into();
        }
        self.running.iter().map(|(&i, &(k, _))| format!("{} step {k}/{}", self.name(i), self.steps)).collect::<Vec<_>>().join(", ")
    }

    fn steps_done_total(&self) -> u64 {
        (self.done + self.failed) as u64 * u64::from(self.steps) + self.running.values().map(|&(k, _)| u64::from(k)).sum::<u64>()
    }

    fn line(&self, text: &str) {
        let t = self.start.elapsed().as_secs();
        match &self.bar {
            Some(b) => b.println(format!("[{t:>5}s] {text}")),
            None => needle_stdx::noteln!("[{t:>5}s] {text}"),
        }
    }

    fn redraw(&mut self) {
        if let Some(b) = &self.bar {
            b.set_position(self.steps_done_total());
            b.set_prefix(format!("{}; {}", self.counts(), self.eta_text()));
            b.set_message(format!("running: {}", self.running_text()));
        }
    }

    pub(crate) fn started(&mut self, i: usize) {
        self.running.insert(i, (0, Instant::now()));
        self.line(&format!("start {}", self.name(i)));
        self.redraw();
    }

    pub(crate) fn finished(&mut self, i: usize, r: &PoseReport) {
        self.running.remove(&i);
        if let Some(f) = self.finished.get_mut(i) {
            *f = true;
        }
        match &r.status {
            Status::Failed { message, .. } => {
                self.failed += 1;
                self.line(&format!("FAILED {}: {message}", r.pose));
            }
            Status::Interrupted { message } => self.line(&crate::report::interrupted_line(&r.pose, message)),
            _ => {
                self.done += 1;
                if let (Some(w), Some(model)) = (r.wall_s.filter(|w| w.is_finite() && *w > 0.0), self.models.get(i)) {
                    self.walls_s.entry(model.clone()).or_default().push(w);
                }
                self.line(&format!(
                    "done {}: {:.1} s, {} increments, fy = {} N at the final depth",
                    r.pose,
                    r.wall_s.unwrap_or(0.0),
                    r.increments.unwrap_or(0),
                    r.fy_final_n.map(|f| format!("{f:.6e}")).unwrap_or_else(|| "-".into())
                ));
            }
        }
        self.redraw();
    }

    /// Re-read the running jobs' steps; on a terminal redraw the bar, otherwise print a
    /// status line every 30 s when something changed.
    pub(crate) fn tick(&mut self, steps_of: impl Fn(usize) -> u32) {
        let keys: Vec<usize> = self.running.keys().copied().collect();
        for i in keys {
            let k = steps_of(i).min(self.steps);
            if let Some(slot) = self.running.get_mut(&i) {
                slot.0 = k;
            }
        }
        if self.bar.is_some() {
            self.redraw();
            return;
        }
        // a line every 30 s when a run moved on, at least every 5 min while runs are going
        let since = self.last_plain.elapsed();
        if since >= Duration::from_secs(30) && !self.running.is_empty() {
            let state = format!("{}; running: {}", self.counts(), self.running_text());
            if state != self.last_line || since >= Duration::from_secs(300) {
                let line = format!("{}; {}; running: {}", self.counts(), self.eta_text(), self.running_text());
                self.line(&line);
                self.last_line = state;
                self.last_plain = Instant::now();
            }
        }
    }

    /// Median wall time of run `i`'s model, s.
    fn typical_s(&self, i: usize) -> Option<f64> {
        self.models.get(i).and_then(|m| self.walls_s.get(m)).and_then(|w| median(w))
    }

    /// `ETA ~N s (median run times of each model)`, or from the load steps when a run's
    /// model has no measured time.
    fn eta_text(&self) -> String {
        let running: Option<Vec<(f64, f64, u32)>> =
            self.running.iter().map(|(&i, &(k, t))| self.typical_s(i).map(|typ| (typ, t.elapsed().as_secs_f64(), k))).collect();
        let left: Option<Vec<f64>> = self.left().map(|i| self.typical_s(i)).collect();
        if let (Some(running), Some(left)) = (running, left) {
            let eta = eta_s(self.jobs, &running, self.steps, &left);
            return format!("ETA ~{eta:.0} s (median run time of each model)");
        }
        let done_steps = self.steps_done_total();
        let total = self.names.len() as u64 * u64::from(self.steps);
        if done_steps == 0 {
            return "ETA ?".into();
        }
        let per_step = self.start.elapsed().as_secs_f64() / done_steps as f64;
        format!("ETA >{:.0} s (from load steps)", per_step * total.saturating_sub(done_steps) as f64)
    }

    pub(crate) fn finish(&mut self) {
        if let Some(b) = self.bar.take() {
            b.finish_and_clear();
        }
    }
}

/// Median of `v`, `None` when empty.
fn median(v: &[f64]) -> Option<f64> {
    let mut s: Vec<f64> = v.iter().copied().filter(|x| x.is_finite()).collect();
    s.sort_by(f64::total_cmp);
    let n = s.len();
    match n {
        0 => None,
        _ if n % 2 == 1 => s.get(n / 2).copied(),
        _ => Some((s.get(n / 2 - 1)? + s.get(n / 2)?) / 2.0),
    }
}

/// Seconds until a campaign ends over `jobs` jobs: the `running` runs (expected s,
/// elapsed s, load steps done of `steps`) first, then the `left` runs (expected s each)
/// in queue order, each given to the job that is free first. A running run past its
/// expected time is given the time its load steps so far suggest.
fn eta_s(jobs: usize, running: &[(f64, f64, u32)], steps: u32, left: &[f64]) -> f64 {
    let mut free_at: Vec<f64> = running
        .iter()
        .map(|&(typical, elapsed, k)| {
            if elapsed < typical {
                typical - elapsed
            } else if k > 0 {
                elapsed * f64::from(steps.saturating_sub(k)) / f64::from(k)
            } else {
                0.0
            }
        })
        .collect();
    free_at.resize(jobs.max(running.len()).max(1), 0.0);
    for &typical in left {
        if let Some(first) = free_at.iter_mut().min_by(|a, b| a.total_cmp(b)) {
            *first += typical;
        }
    }
    free_at.into_iter().fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::{eta_s, median};

    #[test]
    fn eta_schedules_left_runs_on_the_first_free_job() {
        // jobs free at 60 s and 90 s; three runs of 100 s: 60+100, 90+100, 160+100
        assert_eq!(eta_s(2, &[(100.0, 40.0, 5), (100.0, 10.0, 1)], 20, &[100.0; 3]), 260.0);
        // a job past the expected time: 150 s for 15 of 20 steps -> 50 s more
        assert_eq!(eta_s(1, &[(100.0, 150.0, 15)], 20, &[]), 50.0);
        // nothing running, one job, runs of two models
        assert_eq!(eta_s(1, &[], 20, &[100.0, 400.0]), 500.0);
        // two jobs: the long run goes to the job that is free first
        assert_eq!(eta_s(2, &[(100.0, 90.0, 19)], 20, &[400.0, 50.0]), 400.0);
    }

    #[test]
    fn median_of_odd_even_and_empty() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median(&[4.0, 1.0, 2.0, 3.0]), Some(2.5));
        assert_eq!(median(&[]), None);
    }
}
