//! Continuing a failed FEBio run from its last converged load step instead of from zero.
//!
//! Every run dumps its state at each must point (`-dump=3 pose.dmp`: the end of each load
//! step, where the rigid-body log also writes). When the Newton iterations fail somewhere
//! inside a step (an element inverted in an iterate, or contact chattering between two
//! states at a time step near `dtmin`), the run restarts from that dump with a
//! `febio_restart` input whose first time step is a fraction of a load step
//! ([`CONTINUE_STEP_FRACTION`]; how it is set: below), the time stepper's lower limit a
//! tenth of the run's, and
//! otherwise the same model and settings; a run continues again only from a later must
//! point. Measured on the default set (needle8, one thread): `t2-b` with the campaign's last
//! attempt stopped at 3.79 mm, continued from its dump at 3.6 mm it passed that point
//! and reached 4.95 mm; but in the campaign the continuations of `t2-b` (attempts 2, 3)
//! and `tx+15` (attempts 1, 2) stopped again at the same depth (1.78, 1.47, 0.80,
//! 5.82 mm) with first steps asked of 1/16 and 1/64 of a load step (taken: the dump's own
//! step, below): those were read as limit points of the static equilibrium path, which no
//! step size passes, and a second continuation from the same point is not tried.
//!
//! **A continuation's first time step.** FEBio's first step after a restart is its time
//! stepper's (`FEAnalysis::Solve` calls `AutoTimeStep(niter)` when the step has time
//! steps behind it; `niter` is 0 after a restart): the dump's own last step (`m_dtp`, not
//! the input's `<step_size>`, which only sets `m_dt`), at least `dtmin`, at most `dtmax`,
//! which with a must-point curve is the curve's value at the current time
//! (`FETimeStepController::AutoTimeStep`, FEBio 4.11; `dtn = MIN(dtn, dtmax)` whatever
//! `niter`). So the restart input redefines the must-point curve (`<LoadData>`, load
//! controller [`feb::MUST_POINT_LC`]: FEBio's restart creates a new controller and
//! replaces the dump's, `FEModel::ReplaceLoadController`, its points not appended) with
//! the load step after the must point capped at the first step ([`continuation_curve`]).
//! The guarantee: no time step of that load step is longer than the first step, and the
//! first one is the first step when the dump's step is longer (otherwise the dump's
//! step, or `dtmin` when that is longer). The cap holds for the whole load step, not only its first time step
//! (the stepper cannot grow past it there); from the next must point on, the curve's own
//! values (a whole load step, or a first-contact cap) and the stepper grows as usual.
//! That is intended: the load step the run failed in is crossed in small steps.
//! Measured on the smoke mesh (centre, 10 load steps of 0.6 mm, restart from must point
//! 3 at 1.8 mm, 1/16 of a load step asked: `tests/febio_restart_first_step.rs`): 1.8 ->
//! 1.8375 mm with the curve; 1.8 -> 2.4 mm, the dump's step, without it. Before this
//! fix (docs/measurement-notebook.md) the input set only `<step_size>`: every continuation and resumed run so far
//! started with the dump's own step (e.g. 9.6 -> 9.66704 mm), and the manifests' settings
//! lines of those runs ("first time step 1/16" or "0.25 of a load step") overstate it.
//!
//! The equilibrium at each must point is the same problem's: only the path between must
//! points (the time step sizes) changes, as it does between the campaign's attempts.
//! The manifest's `solver_settings` says how often and from where a run was continued.
//! Each segment's rigid-body log is kept (`needle-rb-<n>.txt`), since FEBio starts the
//! log afresh on a restart; the must points are read from all of them. The restart of an
//! attempt interrupted by a killed campaign (`running.rs`) is a segment too, not a
//! continuation: it starts with the attempt's own first step and does not count against
//! [`MAX_CONTINUATIONS`].

use super::feb::{self, MustPoint};
use anyhow::{bail, Result};
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
/// Segments (processes) of one attempt whose logs are kept at most: its continuations
/// and the restarts of an attempt interrupted by a killed campaign (`running.rs`).
pub const MAX_SEGMENTS: u32 = 64;
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

/// What a restart input says ([`restart_input`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Restart<'a> {
    /// The must-point curve of the run whose dump is read ([`feb::must_points`], with the
    /// first-contact caps that run had).
    pub must_points: &'a [MustPoint],
    /// The must point the dump holds: the number of must points reached (1-based).
    pub from: u32,
    /// The first time step, in the solver's time (mm of depth, or s of a ramp-and-hold run).
    pub first_step: f64,
    /// The time stepper's lower limit, same unit.
    pub dtmin: f64,
    /// Newton's tolerances, when they change.
    pub tolerances: Option<Tolerances>,
}

/// The must-point curve a restart from must point `from` redefines: the load step after
/// it (point `from` + 1) capped at `first_step`, and the must point itself too (FEBio
/// evaluates the curve at the restart time, which is point `from`'s value at the first
/// must point and whenever the dump's time is a rounding below the must point; the curve
/// is never read again at an earlier time). A cap only lowers a value: a smaller
/// first-contact cap stays. The other points are unchanged.
pub fn continuation_curve(must_points: &[MustPoint], from: u32, first_step: f64) -> Vec<MustPoint> {
    let from = from as usize;
    let mut curve = must_points.to_vec();
    for p in curve.iter_mut().take(from + 1).skip(from.saturating_sub(1)) {
        p.dtmax = p.dtmax.min(first_step);
    }
    curve
}

/// The restart input: the archive to read, the first time step, the time stepper's limits,
/// the redefined must-point curve ([`continuation_curve`]) and, when given, the Newton
/// solver's displacement and residual tolerances (`dtol`, `rtol`: a continuation of
/// another attempt with the retry tolerances, `ladder.rs`; FEBio's restart reads
/// `<solver>` parameters).
///
/// The first time step is what the curve sets (module docs): FEBio's first step after a
/// restart is `AutoTimeStep`'s, from the dump's own step and capped by the curve's value
/// at the restart time. `<step_size>` is written too: without effect on the step, it is
/// the time step FEBio's log compares the first one with ("AUTO STEPPER: decreasing time
/// step" is not printed when they are equal).
///
/// # Errors
/// A first step or `dtmin` that is not a positive finite number.
pub fn restart_input(r: &Restart<'_>) -> Result<String> {
    let (first_step, dtmin) = (r.first_step, r.dtmin);
    if !(first_step.is_finite() && first_step > 0.0 && dtmin.is_finite() && dtmin > 0.0) {
        bail!("restart from must point {}: first time step {first_step}, dtmin {dtmin}: both must be positive and finite", r.from);
    }
    let mut s = String::new();
    let _ = writeln!(s, r#"<?xml version="1.0" encoding="ISO-8859-1"?>"#);
    let _ = writeln!(s, "<!-- needle-haptics: continue the run from its last converged must point (fe/febio/restart.rs) -->");
    let _ = writeln!(s, r#"<febio_restart version="4.0">"#);
    let _ = writeln!(s, "  <Archive>{DUMP_FROM}</Archive>");
    let _ = writeln!(s, "  <Control>");
    let _ = writeln!(s, "    <step_size>{first_step:e}</step_size>");
    let _ = writeln!(s, "    <time_stepper>");
    let _ = writeln!(s, "      <max_retries>{CONTINUE_MAX_RETRIES}</max_retries>");
    let _ = writeln!(s, "      <dtmin>{dtmin:e}</dtmin>");
    let _ = writeln!(s, "    </time_stepper>");
    if let Some(t) = r.tolerances {
        let _ = writeln!(s, "    <solver>");
        let _ = writeln!(s, "      <dtol>{:e}</dtol>", t.dtol);
        let _ = writeln!(s, "      <rtol>{:e}</rtol>", t.rtol);
        if t.min_residual_n > 0.0 {
            let _ = writeln!(s, "      <min_residual>{:e}</min_residual>", t.min_residual_n * t.min_residual_n);
        }
        let _ = writeln!(s, "    </solver>");
    }
    let _ = writeln!(s, "  </Control>");
    let _ = writeln!(s, "  <!-- must points: the load step after the restart's capped at its first time step -->");
    let _ = writeln!(s, "  <LoadData>");
    s.push_str(&feb::must_point_controller(&continuation_curve(r.must_points, r.from, first_step)));
    let _ = writeln!(s, "  </LoadData>");
    let _ = writeln!(s, "</febio_restart>");
    Ok(s)
}

/// Newton's convergence tolerances a restart sets.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tolerances {
    /// Displacement (`dtol`; 0: off).
    pub dtol: f64,
    /// Residual (`rtol`; 0: off).
    pub rtol: f64,
    /// Absolute residual floor, N (`min_residual`, written squared; 0: the dump's own).
    pub min_residual_n: f64,
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
    use crate::febio::feb::FirstContact;
    use crate::spec::visco::RampHold;
    use crate::spec::Loading;

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
    }

    fn quasi_static(depth_mm: f64, steps: u32) -> Loading {
        Loading { depth_mm, steps, ramp_hold: None }
    }

    fn input(points: &[MustPoint], from: u32, first_step: f64, tolerances: Option<Tolerances>) -> String {
        restart_input(&Restart { must_points: points, from, first_step, dtmin: 3e-5, tolerances }).expect("restart input")
    }

    /// The `<pt>` values of the restart input's must-point curve, in order.
    fn curve_in(text: &str) -> Vec<(f64, f64)> {
        let data = &text[text.find("<LoadData>").expect("LoadData")..];
        data.lines()
            .filter_map(|l| l.trim().strip_prefix("<pt>")?.strip_suffix("</pt>"))
            .map(|p| {
                let (t, v) = p.split_once(',').expect("t,v");
                (t.parse().expect("t"), v.parse().expect("v"))
            })
            .collect()
    }

    #[test]
    fn the_restart_input_sets_archive_limits_and_tolerances() {
        let points = feb::must_points(&quasi_static(6.0, 10), 10, None);
        let r = input(&points, 3, 0.6 / 16.0, None);
        assert!(r.contains("<Archive>pose-from.dmp</Archive>") && r.contains("<step_size>3.75e-2</step_size>"), "{r}");
        assert!(r.contains("<max_retries>12</max_retries>") && r.contains("<dtmin>3e-5</dtmin>"), "{r}");
        assert!(!r.contains("<solver>"), "the run's own tolerances: {r}");
        // the curve is load controller 2, as the .feb's: FEBio replaces it (ReplaceLoadController)
        assert!(
            r.contains("  <LoadData>\n    <load_controller id=\"2\" name=\"must_points\" type=\"loadcurve\">\n      <interpolate>STEP</interpolate>\n      <extend>CONSTANT</extend>\n"),
            "{r}"
        );
        assert!(r.ends_with("    </load_controller>\n  </LoadData>\n</febio_restart>\n"), "{r}");
        let r = input(&points, 3, 0.075, Some(Tolerances { dtol: 0.0, rtol: 1e-3, min_residual_n: 0.0 }));
        assert!(r.contains("<solver>\n      <dtol>0e0</dtol>\n      <rtol>1e-3</rtol>\n    </solver>\n  </Control>"), "{r}");
        // the floor, squared as FEBio compares it
        let r = input(&points, 3, 0.075, Some(Tolerances { dtol: 0.0, rtol: 1e-3, min_residual_n: 1e-4 }));
        assert!(r.contains("<rtol>1e-3</rtol>\n      <min_residual>1e-8</min_residual>\n    </solver>"), "{r}");
        for bad in [0.0, -0.1, f64::NAN, f64::INFINITY] {
            let e = restart_input(&Restart { must_points: &points, from: 3, first_step: bad, dtmin: 3e-5, tolerances: None })
                .expect_err("a bad first step");
            assert!(e.to_string().contains(&format!("first time step {bad}")) && e.to_string().contains("must point 3"), "{e}");
        }
    }

    /// Whole load steps of 0.6 mm: the must point restarted from and the load step after
    /// it take the first step as their dtmax, every other point keeps its load step.
    #[test]
    fn a_restart_caps_the_load_step_after_its_must_point() {
        let points = feb::must_points(&quasi_static(6.0, 10), 10, None);
        let first = 0.6 / 16.0;
        let got = curve_in(&input(&points, 4, first, None));
        assert_eq!(got.len(), 10, "{got:?}");
        for (k, &(t, v)) in (1u32..).zip(&got) {
            assert!((t - 0.6 * f64::from(k)).abs() < 1e-12, "must point {k} at {t}");
            let want = if k == 4 || k == 5 { first } else { 0.6 };
            assert!((v - want).abs() < 1e-12, "point {k}: dtmax {v}, want {want}");
        }
        // from the first must point: it and the second
        let got = curve_in(&input(&points, 1, first, None));
        let caps: Vec<u32> = (1u32..).zip(got.iter().zip(&points)).filter(|(_, (g, p))| g.1 != p.dtmax).map(|(k, _)| k).collect();
        assert_eq!(caps, [1, 2]);
        // at the last must point there is no load step after it: only the point itself
        let got = continuation_curve(&points, 10, first);
        assert_eq!(got[..9], points[..9]);
        assert_eq!(got[9].dtmax, first);
    }

    /// First-contact caps (0.1 of a load step to 0.6 mm, 20 steps of 0.3 mm: must points 1
    /// and 2) stay where the restart is past them, and win when they are smaller than the
    /// first step.
    #[test]
    fn first_contact_caps_stay() {
        let fc = FirstContact { depth_mm: 0.6, step_fraction: 0.1 };
        let points = feb::must_points(&quasi_static(6.0, 20), 20, Some(fc));
        let capped: Vec<f64> = points.iter().map(|p| p.dtmax).collect();
        assert!((capped[0] - 0.03).abs() < 1e-15 && (capped[1] - 0.03).abs() < 1e-15 && (capped[2] - 0.3).abs() < 1e-15, "{capped:?}");
        let first = 0.3 / 16.0;
        let got = curve_in(&input(&points, 5, first, None));
        let want: Vec<f64> = (1..=20)
            .map(|k| {
                if k <= 2 {
                    0.03
                } else if k == 5 || k == 6 {
                    first
                } else {
                    0.3
                }
            })
            .collect();
        let v: Vec<f64> = got.iter().map(|p| p.1).collect();
        assert!(v.iter().zip(&want).all(|(a, b)| (a - b).abs() < 1e-15), "{v:?}\nwant {want:?}");
        // from must point 1 with a quarter step (0.075 mm): the first-contact cap 0.03 is smaller
        let got = continuation_curve(&points, 1, 0.075);
        assert_eq!((got[0].dtmax, got[1].dtmax), (points[0].dtmax, points[1].dtmax), "the smaller cap stays");
        assert_eq!(got[2..], points[2..]);
        // with 1/16 (0.01875 mm) the first step is below the cap: it is the dtmax
        let got = continuation_curve(&points, 1, first);
        assert_eq!((got[0].dtmax, got[1].dtmax), (first, first));
        assert_eq!(got[2..], points[2..]);
    }

    /// A ramp-and-hold run's uneven must points: the cap is the fraction of the load step
    /// after the must point, not of the first one; the times are the run's own.
    #[test]
    fn ramp_and_hold_caps_the_uneven_step_after() {
        let r = RampHold { speed_mm_per_s: 10.0, ramp_steps: 20, hold_s: 30.0, hold_steps: 5, hold_first_s: 0.03, min_residual_n: 1e-5 };
        let loading = Loading { depth_mm: 6.0, steps: 25, ramp_hold: Some(r) };
        let points = feb::must_points(&loading, 25, None);
        for (from, fraction) in [(20u32, 0.25), (22, 1.0 / 16.0), (3, 0.25)] {
            let first = loading.step_time(from + 1) * fraction;
            let got = curve_in(&input(&points, from, first, None));
            assert_eq!(got.len(), 25);
            for (k, &(t, v)) in (1u32..).zip(&got) {
                assert_eq!(t, loading.time_at(k), "must point {k}: the run's time");
                let step = loading.step_time(k);
                let want = if k == from + 1 || k == from { step.min(first) } else { step };
                assert_eq!(v, want, "from {from}: point {k} ({t} s): dtmax {v}, want {want} (step {step} s, first {first} s)");
            }
        }
        // the hold's steps are uneven: from 22 the cap is 1/16 of step 23, not of step 1
        assert!(loading.step_time(23) > 10.0 * loading.step_time(1));
    }
}
