//! Continuing a failed FEBio run from its last converged load step instead of from zero.
//!
//! Every run dumps its state at each must point (`-dump=3 pose.dmp`: the end of each load
//! step, where the rigid-body log also writes). When the Newton iterations fail somewhere
//! inside a step (an element inverted in an iterate, or contact chattering between two
//! states at a time step near `dtmin`), the run restarts from that dump with a
//! `febio_restart` input whose first time step is a fraction of a load step
//! ([`CONTINUE_STEP_FRACTION`]), the time stepper's lower limit a tenth of the run's, and
//! otherwise the same model and settings; a run continues again only from a later must
//! point. Measured on the default set (needle8, one thread): `t2-b` with the campaign's last
//! attempt stopped at 3.79 mm, continued from its dump at 3.6 mm it passed that point
//! and reached 4.95 mm; but in the campaign the continuations of `t2-b` (attempts 2, 3)
//! and `tx+15` (attempts 1, 2) stopped again at the same depth (1.78, 1.47, 0.80,
//! 5.82 mm) with first steps of 1/16 and 1/64 of a load step: those are limit points of
//! the static equilibrium path, which no step size passes. A second continuation from
//! the same point is therefore not tried.
//!
//! The equilibrium at each must point is the same problem's: only the path between must
//! points (the time step sizes) changes, as it does between the campaign's attempts.
//! The manifest's `solver_settings` says how often and from where a run was continued.
//! Each segment's rigid-body log is kept (`needle-rb-<n>.txt`), since FEBio starts the
//! log afresh on a restart; the must points are read from all of them.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// First time step of a continuation, as a fraction of one load step.
pub const CONTINUE_STEP_FRACTION: f64 = 1.0 / 16.0;
/// The time stepper's lower limit in a continuation, as a fraction of the run's.
pub const CONTINUE_DTMIN_SCALE: f64 = 0.1;
/// Retries of a time step in a continuation (the run's deck has its own).
pub const CONTINUE_MAX_RETRIES: u32 = 12;
/// Continuations of one attempt at most.
pub const MAX_CONTINUATIONS: u32 = 12;
/// Continuations from the same must point at most: one (module docs).
pub const MAX_FROM_SAME_POINT: u32 = 1;

/// The dump file FEBio writes at each must point.
pub const DUMP: &str = "pose.dmp";
/// The copy of the dump a continuation reads (FEBio rewrites [`DUMP`] as it goes on).
pub const DUMP_FROM: &str = "pose-from.dmp";
/// The restart input of a continuation.
pub const RESTART_INPUT: &str = "pose-restart.feb";

/// The rigid-body log of segment `n` (0: the first run) once the next segment started.
pub fn segment_log(work_dir: &Path, n: u32) -> PathBuf {
    work_dir.join(segment_log_name(n))
}

/// File name of [`segment_log`].
pub fn segment_log_name(n: u32) -> String {
    format!("needle-rb-{n}.txt")
}

/// FEBio's own log of segment `n` once the next segment started (the restart writes
/// `pose.log` afresh).
pub fn segment_solver_log_name(n: u32) -> String {
    format!("pose-{n}.log")
}

/// The restart input: the archive to read, the first time step (mm of insertion: time is
/// depth), the time stepper's limits and, when given, the Newton solver's displacement
/// and residual tolerances (`dtol`, `rtol`: a continuation of another attempt with the
/// retry tolerances, `ladder.rs`; FEBio's restart reads `<solver>` parameters).
pub fn restart_input(first_step_mm: f64, dtmin_mm: f64, tolerances: Option<Tolerances>) -> String {
    let mut s = String::new();
    let _ = writeln!(s, r#"<?xml version="1.0" encoding="ISO-8859-1"?>"#);
    let _ = writeln!(s, "<!-- needle-haptics: continue the run from its last converged must point (fe/febio/restart.rs) -->");
    let _ = writeln!(s, r#"<febio_restart version="4.0">"#);
    let _ = writeln!(s, "  <Archive>{DUMP_FROM}</Archive>");
    let _ = writeln!(s, "  <Control>");
    let _ = writeln!(s, "    <step_size>{first_step_mm:e}</step_size>");
    let _ = writeln!(s, "    <time_stepper>");
    let _ = writeln!(s, "      <max_retries>{CONTINUE_MAX_RETRIES}</max_retries>");
    let _ = writeln!(s, "      <dtmin>{dtmin_mm:e}</dtmin>");
    let _ = writeln!(s, "    </time_stepper>");
    if let Some(t) = tolerances {
        let _ = writeln!(s, "    <solver>");
        let _ = writeln!(s, "      <dtol>{:e}</dtol>", t.dtol);
        let _ = writeln!(s, "      <rtol>{:e}</rtol>", t.rtol);
        let _ = writeln!(s, "    </solver>");
    }
    let _ = writeln!(s, "  </Control>");
    let _ = writeln!(s, "</febio_restart>");
    s
}

/// Newton's convergence tolerances a restart sets.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tolerances {
    /// Displacement (`dtol`; 0: off).
    pub dtol: f64,
    /// Residual (`rtol`; 0: off).
    pub rtol: f64,
}

/// What the continuations of one attempt did, for the manifest and failure messages.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Continuations {
    /// Depths (mm) the continuations started from, in order.
    pub from_mm: Vec<f64>,
}

impl Continuations {
    /// `continued 2 times from must points (3.6, 4.5 mm)`, or nothing.
    pub fn describe(&self) -> String {
        self.describe_in("mm")
    }

    /// As [`Continuations::describe`], the must points in `unit` (a ramp-and-hold run's
    /// time is seconds: `crate::visco`).
    pub fn describe_in(&self, unit: &str) -> String {
        if self.from_mm.is_empty() {
            return String::new();
        }
        let at: Vec<String> = self.from_mm.iter().map(|d| format!("{d}")).collect();
        format!("continued {} time(s) from the last converged must point ({} {unit})", self.from_mm.len(), at.join(", "))
    }

    /// The first step fraction of the next continuation from `from_mm`, or `None` when the
    /// limits are reached ([`MAX_CONTINUATIONS`], [`MAX_FROM_SAME_POINT`]).
    pub fn next_fraction(&self, from_mm: f64) -> Option<f64> {
        let n = self.from_mm.len() as u32;
        let same = self.from_mm.iter().filter(|&&d| (d - from_mm).abs() < 1e-9).count() as u32;
        if n >= MAX_CONTINUATIONS || same >= MAX_FROM_SAME_POINT {
            return None;
        }
        Some(CONTINUE_STEP_FRACTION)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn continuations_stop_at_the_limits() {
        let mut c = Continuations::default();
        assert_eq!(c.next_fraction(3.6), Some(CONTINUE_STEP_FRACTION));
        c.from_mm.push(3.6);
        assert_eq!(c.next_fraction(3.6), None, "no progress since the last continuation: the end");
        assert_eq!(c.next_fraction(3.9), Some(CONTINUE_STEP_FRACTION), "progress: continue again");
        c.from_mm = (0..MAX_CONTINUATIONS).map(f64::from).collect();
        assert_eq!(c.next_fraction(100.0), None);
        assert!(Continuations { from_mm: vec![3.6, 4.5] }.describe().contains("2 time(s)"));
        let r = restart_input(0.02, 3e-5, None);
        assert!(r.contains("<Archive>pose-from.dmp</Archive>") && r.contains("<step_size>2e-2</step_size>"), "{r}");
        assert!(!r.contains("<solver>"), "the run's own tolerances: {r}");
        let r = restart_input(0.075, 3e-5, Some(Tolerances { dtol: 0.0, rtol: 1e-3 }));
        assert!(r.contains("<solver>\n      <dtol>0e0</dtol>\n      <rtol>1e-3</rtol>\n    </solver>\n  </Control>"), "{r}");
    }
}
