//! Whether a puncture's force depends on the insertion speed (issue 65: "the puncture
//! force's dependence on speed if the data show one"). Per puncture of the calibration,
//! over the trials that make it: the least-squares line of their measured peak forces
//! against their insertion speeds, its slope's standard error, and whether the slope
//! differs from zero by more than [`T_SHOWN`] of them. Asked only of trials at distinct
//! speeds (the fastest at least [`DISTINCT_SPEED_RATIO`] times the slowest) and at least
//! [`MIN_TRIALS`] of them. The library's puncture is a force threshold without a speed
//! term: the stack keeps the trials' mean force either way, and the calibration says
//! which ([`SpeedDependence::note`]); the checks show the error at each speed.
use super::trials::Trial;

/// A slope this many standard errors from zero is a dependence the data show.
pub const T_SHOWN: f64 = 2.0;
/// The fastest trial's speed over the slowest's, at least: otherwise one speed.
pub const DISTINCT_SPEED_RATIO: f64 = 1.2;
/// Trials a line needs (a standard error needs one more than the line's two values).
pub const MIN_TRIALS: usize = 3;

/// One puncture's force against the insertion speed.
#[derive(Debug, Clone, PartialEq)]
pub struct SpeedDependence {
    /// The puncture, from 0.
    pub puncture: usize,
    /// The trials that make it.
    pub trials: usize,
    /// The slowest and the fastest of their insertion speeds, mm/s.
    pub speeds_mm_per_s: [f64; 2],
    /// The mean of their peak forces, N.
    pub mean_force_n: f64,
    /// The line's slope, N per mm/s.
    pub slope_n_s_per_mm: f64,
    /// Its standard error, N per mm/s.
    pub standard_error_n_s_per_mm: f64,
}

impl SpeedDependence {
    /// Whether the data show a dependence: `|slope| > T_SHOWN` standard errors.
    #[must_use]
    pub fn shown(&self) -> bool {
        self.slope_n_s_per_mm.abs() > T_SHOWN * self.standard_error_n_s_per_mm
    }

    /// What the calibration says about it.
    #[must_use]
    pub fn note(&self) -> String {
        let [lo, hi] = self.speeds_mm_per_s;
        let line = format!(
            "puncture {}: its force against the insertion speed over {} trials at {lo:.2}-{hi:.2} mm/s: slope {:+.3} +- {:.3} N per mm/s (standard error)",
            self.puncture + 1,
            self.trials,
            self.slope_n_s_per_mm,
            self.standard_error_n_s_per_mm
        );
        if self.shown() {
            format!(
                "{line}: a dependence the data show (more than {T_SHOWN} standard errors); the library's puncture has no speed term: the stack punctures at one force at every speed (these trials' mean peak {:.3} N), each trial's check shows its error",
                self.mean_force_n
            )
        } else {
            format!(
                "{line}: no dependence shown (within {T_SHOWN} standard errors of none): one puncture force for every speed (these trials' mean peak {:.3} N)",
                self.mean_force_n
            )
        }
    }
}

/// Per puncture `0..n`, its force against the insertion speed over `trials` (module
/// docs); a puncture whose trials are too few or at one speed has none.
#[must_use]
pub fn of_trials(trials: &[Trial], n: usize) -> Vec<SpeedDependence> {
    (0..n)
        .filter_map(|k| {
            let points: Vec<(f64, f64)> =
                trials.iter().filter_map(|t| t.peak(k).map(|(_, force)| (t.phases.insertion_speed_mm_per_s, force))).collect();
            line(k, &points)
        })
        .collect()
}

/// The least-squares line through `points` (speed, force) and its slope's standard error.
fn line(puncture: usize, points: &[(f64, f64)]) -> Option<SpeedDependence> {
    let m = points.len();
    let lo = points.iter().map(|p| p.0).fold(f64::INFINITY, f64::min);
    let hi = points.iter().map(|p| p.0).fold(f64::NEG_INFINITY, f64::max);
    if m < MIN_TRIALS || !(lo > 0.0 && hi >= DISTINCT_SPEED_RATIO * lo) {
        return None;
    }
    let n = m as f64;
    let (mv, mf) = (points.iter().map(|p| p.0).sum::<f64>() / n, points.iter().map(|p| p.1).sum::<f64>() / n);
    let sxx: f64 = points.iter().map(|p| (p.0 - mv).powi(2)).sum();
    let sxy: f64 = points.iter().map(|p| (p.0 - mv) * (p.1 - mf)).sum();
    // sxx > 0: the speeds differ (hi >= 1.2 lo > 0)
    let slope = sxy / sxx;
    let sse: f64 = points.iter().map(|p| (p.1 - mf - slope * (p.0 - mv)).powi(2)).sum();
    let standard_error = (sse / (n - 2.0) / sxx).sqrt();
    Some(SpeedDependence {
        puncture,
        trials: m,
        speeds_mm_per_s: [lo, hi],
        mean_force_n: mf,
        slope_n_s_per_mm: slope,
        standard_error_n_s_per_mm: standard_error,
    })
}
