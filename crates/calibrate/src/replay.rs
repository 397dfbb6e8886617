//! The calibrated stack run through the library's own insertion model along the
//! measured insertion (constant speed), and the figures that hold it against the
//! measured curve.
use crate::events::Puncture;
use crate::measured::Point;
use needle_haptics::insertion::{Insertion, InsertionConfig, Stack};
use needle_haptics::Pose;

/// Contact onset as a threshold crossing: the first position where the force exceeds
/// this fraction of the first puncture force (the same rule for both curves).
pub const ONSET_FRACTION: f64 = 0.05;

/// The model along the insertion: one sample per tick.
#[derive(Debug, Clone, PartialEq)]
pub struct Replay {
    /// (needle position mm, axial force N) per tick.
    pub samples: Vec<(f64, f64)>,
    /// (position mm, axial force N just before) of each puncture.
    pub punctures: Vec<(f64, f64)>,
}

/// Runs `stack` from `start_mm` to `end_mm` of needle position at `speed_mm_per_s`
/// (contact at `onset_mm`), centred vertical needle, 1 kHz.
#[must_use]
pub fn replay(stack: &Stack<'_>, onset_mm: f64, start_mm: f64, end_mm: f64, speed_mm_per_s: f64) -> Replay {
    let config = InsertionConfig::DEFAULT_1KHZ;
    let mut insertion = match Insertion::new(stack, config) {
        Ok(i) => i,
        Err(e) => {
            needle_stdx::noteln!("replay: {e}: {stack:?}");
            return Replay { samples: Vec::new(), punctures: Vec::new() };
        }
    };
    let step_mm = speed_mm_per_s * f64::from(config.period_s);
    let ticks = ((end_mm - start_mm) / step_mm).ceil().max(0.0) as usize;
    let mut samples = Vec::with_capacity(ticks + 1);
    let mut punctures = Vec::new();
    let mut last_force = 0.0;
    for k in 0..=ticks {
        let position = start_mm + step_mm * k as f64;
        let pose = Pose { depth_mm: (position - onset_mm) as f32, ..Pose::default() };
        let e = insertion.step(&pose);
        let force = f64::from(e.wrench.fy_n);
        // two boundaries punctured in one tick are two punctures
        for _ in 0..e.punctures {
            punctures.push((position, last_force));
        }
        samples.push((position, force));
        last_force = force;
    }
    Replay { samples, punctures }
}

impl Replay {
    /// The model's force at needle position `p` (the tick nearest it).
    #[must_use]
    pub fn at(&self, p: f64) -> f64 {
        let i = self.samples.partition_point(|(x, _)| *x < p);
        let near = [i.checked_sub(1), Some(i)].into_iter().flatten().filter_map(|j| self.samples.get(j));
        near.min_by(|a, b| (a.0 - p).abs().total_cmp(&(b.0 - p).abs())).map_or(f64::NAN, |s| s.1)
    }

    /// The model's force at the last tick at or before needle position `p` (the state
    /// the model is in when the stage reaches `p`): the pre-puncture comparison's rule, so
    /// that a measured point at the peak is not held against a tick just after a puncture
    /// that lands there; the first tick's force before the first tick.
    #[must_use]
    pub fn before(&self, p: f64) -> f64 {
        let i = self.samples.partition_point(|(x, _)| *x <= p);
        self.samples.get(i.saturating_sub(1)).map_or(f64::NAN, |s| s.1)
    }

    /// The first position where the force exceeds `threshold_n`.
    #[must_use]
    pub fn onset(&self, threshold_n: f64) -> Option<f64> {
        self.samples.iter().find(|s| s.1 > threshold_n).map(|s| s.0)
    }
}

/// The first measured position (interpolated) where the force exceeds `threshold_n` and
/// stays above it until the first puncture's peak.
#[must_use]
pub fn measured_onset(points: &[Point], first_peak: usize, threshold_n: f64) -> Option<f64> {
    let pre = points.get(..=first_peak)?;
    let last_below = pre.iter().rposition(|p| p.force_n <= threshold_n)?;
    let (a, b) = (pre.get(last_below)?, pre.get(last_below + 1)?);
    let t = (threshold_n - a.force_n) / (b.force_n - a.force_n);
    Some(a.position_mm + t * (b.position_mm - a.position_mm))
}

/// One line of the comparison: what was measured, what the model gives, the goal.
#[derive(Debug, Clone, PartialEq)]
pub struct Check {
    /// What is compared.
    pub what: String,
    /// Measured value.
    pub measured: f64,
    /// Model value.
    pub model: f64,
    /// The error in the goal's unit (mm or %).
    pub error: f64,
    /// The goal on |error|.
    pub goal: f64,
    /// Unit of error and goal.
    pub unit: &'static str,
}

impl Check {
    /// Whether the goal is met.
    #[must_use]
    pub fn met(&self) -> bool {
        self.error.abs() <= self.goal
    }
}

/// The checks of issue-grade calibration goals: onset and puncture positions within
/// 0.5 mm, puncture forces within 5 %, pre-puncture RMS within 5 % of the puncture force,
/// mean force over each interval between punctures within 10 %.
#[must_use]
pub fn checks(points: &[Point], events: &[Puncture], model: &Replay) -> Vec<Check> {
    let mut out = Vec::new();
    let Some(first) = events.first() else { return out };
    let peak0 = points.get(first.peak).map_or(f64::NAN, |p| p.force_n);
    let threshold = ONSET_FRACTION * peak0;
    if let (Some(m), Some(p)) = (measured_onset(points, first.peak, threshold), model.onset(threshold)) {
        out.push(Check {
            what: format!("contact onset ({:.0} % of the first puncture force)", 100.0 * ONSET_FRACTION),
            measured: m,
            model: p,
            error: p - m,
            goal: 0.5,
            unit: "mm",
        });
    }
    puncture_checks(points, events, model, &mut out);
    let onset = measured_onset(points, first.peak, threshold).unwrap_or(f64::NEG_INFINITY);
    let pre: Vec<&Point> = points.iter().take(first.peak + 1).filter(|p| p.position_mm >= onset).collect();
    let rms = (pre.iter().map(|p| (model.before(p.position_mm) - p.force_n).powi(2)).sum::<f64>() / pre.len().max(1) as f64).sqrt();
    out.push(Check {
        what: "pre-puncture RMS (onset to puncture 1), % of its force".into(),
        measured: 0.0,
        model: rms,
        error: 100.0 * rms / peak0,
        goal: 5.0,
        unit: "%",
    });
    interval_checks(points, events, model, &mut out);
    out
}

/// Position and force of every puncture against the model's.
fn puncture_checks(points: &[Point], events: &[Puncture], model: &Replay, out: &mut Vec<Check>) {
    for (k, e) in events.iter().enumerate() {
        let Some(peak) = points.get(e.peak) else { continue };
        let Some(&(mp, mf)) = model.punctures.get(k) else {
            out.push(Check {
                what: format!("puncture {} position", k + 1),
                measured: peak.position_mm,
                model: f64::NAN,
                error: f64::NAN,
                goal: 0.5,
                unit: "mm",
            });
            continue;
        };
        out.push(Check {
            what: format!("puncture {} position", k + 1),
            measured: peak.position_mm,
            model: mp,
            error: mp - peak.position_mm,
            goal: 0.5,
            unit: "mm",
        });
        out.push(Check {
            what: format!("puncture {} force", k + 1),
            measured: peak.force_n,
            model: mf,
            error: 100.0 * (mf - peak.force_n) / peak.force_n,
            goal: 5.0,
            unit: "%",
        });
    }
}

/// The mean force over each interval between punctures (and after the last).
fn interval_checks(points: &[Point], events: &[Puncture], model: &Replay, out: &mut Vec<Check>) {
    for (k, e) in events.iter().enumerate() {
        let end = events.get(k + 1).map_or(points.len() - 1, |n| n.peak);
        let span: Vec<&Point> = points.get(e.bottom..=end).map(|s| s.iter().collect()).unwrap_or_default();
        if span.is_empty() {
            continue;
        }
        let mean_m = span.iter().map(|p| p.force_n).sum::<f64>() / span.len() as f64;
        let mean_p = span.iter().map(|p| model.at(p.position_mm)).sum::<f64>() / span.len() as f64;
        let label = if k + 1 < events.len() {
            format!("mean force, puncture {} to {}", k + 1, k + 2)
        } else {
            format!("mean force after puncture {}", k + 1)
        };
        // a zero mean (a space: no force) is met only by zero
        let error = if mean_m == 0.0 {
            if mean_p == 0.0 {
                0.0
            } else {
                f64::INFINITY
            }
        } else {
            100.0 * (mean_p - mean_m) / mean_m
        };
        out.push(Check { what: label, measured: mean_m, model: mean_p, error, goal: 10.0, unit: "%" });
    }
}
