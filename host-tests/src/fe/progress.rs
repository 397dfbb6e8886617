//! The progress display of `needle fe run`: runs done, running (with their load step)
//! and left, with an ETA; an indicatif bar on a terminal, plain lines otherwise (CI).

use crate::fe::report::{PoseReport, Status};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::collections::BTreeMap;
use std::io::IsTerminal;
use std::time::{Duration, Instant};

/// Progress display: an indicatif bar on a terminal, plain lines otherwise (CI).
pub(crate) struct Progress {
    names: Vec<String>,
    steps: u32,
    running: BTreeMap<usize, u32>,
    done: usize,
    failed: usize,
    bar: Option<ProgressBar>,
    start: Instant,
    last_plain: Instant,
    last_line: String,
}

impl Progress {
    pub(crate) fn new(names: Vec<String>, steps: u32) -> Self {
        let total_steps = names.len() as u64 * u64::from(steps);
        let bar = std::io::stderr().is_terminal().then(|| {
            let bar = ProgressBar::with_draw_target(Some(total_steps), ProgressDrawTarget::stderr_with_hz(4));
            let style = ProgressStyle::with_template(
                "[{elapsed_precise}] {bar:30.cyan/blue} {percent:>3}% ETA {eta_precise} | {prefix}\n  {wide_msg}",
            )
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("=> ");
            bar.set_style(style);
            bar
        });
        let now = Instant::now();
        let mut p = Progress {
            names,
            steps,
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

    fn counts(&self) -> String {
        let finished = self.done + self.failed;
        let left = self.names.len().saturating_sub(finished + self.running.len());
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
        self.running
            .iter()
            .map(|(&i, &k)| format!("{} step {k}/{}", self.name(i), self.steps))
            .collect::<Vec<_>>()
            .join(", ")
    }

    fn steps_done_total(&self) -> u64 {
        (self.done + self.failed) as u64 * u64::from(self.steps) + self.running.values().map(|&k| u64::from(k)).sum::<u64>()
    }

    fn line(&self, text: &str) {
        let t = self.start.elapsed().as_secs();
        match &self.bar {
            Some(b) => b.println(format!("[{t:>5}s] {text}")),
            None => eprintln!("[{t:>5}s] {text}"),
        }
    }

    fn redraw(&mut self) {
        if let Some(b) = &self.bar {
            b.set_position(self.steps_done_total());
            b.set_prefix(self.counts());
            b.set_message(format!("running: {}", self.running_text()));
        }
    }

    pub(crate) fn started(&mut self, i: usize) {
        self.running.insert(i, 0);
        self.line(&format!("start {}", self.name(i)));
        self.redraw();
    }

    pub(crate) fn finished(&mut self, i: usize, r: &PoseReport) {
        self.running.remove(&i);
        match &r.status {
            Status::Failed { message, .. } => {
                self.failed += 1;
                self.line(&format!("FAILED {}: {message}", r.pose));
            }
            _ => {
                self.done += 1;
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
            self.running.insert(i, k);
        }
        if self.bar.is_some() {
            self.redraw();
            return;
        }
        if self.last_plain.elapsed() >= Duration::from_secs(30) && !self.running.is_empty() {
            let done_steps = self.steps_done_total();
            let total = self.names.len() as u64 * u64::from(self.steps);
            let eta = if done_steps > 0 {
                let per_step = self.start.elapsed().as_secs_f64() / done_steps as f64;
                format!("ETA {:.0} s", per_step * total.saturating_sub(done_steps) as f64)
            } else {
                "ETA ?".into()
            };
            let line = format!("{}; {eta}; running: {}", self.counts(), self.running_text());
            if line != self.last_line {
                self.line(&line);
                self.last_line = line;
            }
            self.last_plain = Instant::now();
        }
    }

    pub(crate) fn finish(&mut self) {
        if let Some(b) = self.bar.take() {
            b.finish_and_clear();
        }
    }
}
