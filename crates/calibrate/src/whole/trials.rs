//! The trials of one calibration, each read, screened, cut into its phases, its
//! punctures found on the insertion and today's single-curve fit run on the insertion
//! (its contact onset and the pre-puncture shape), and the checks across the trials:
//! one needle, one puncture count.
use crate::events::{self, EventRule, Puncture};
use crate::fit::{self, Fit};
use crate::measured::Point;
use crate::trial::{self, Phases, Sample};
use anyhow::{bail, Result};
use std::path::{Path, PathBuf};

/// One trial, ready to fit.
#[derive(Debug, Clone)]
pub struct Trial {
    /// Its file.
    pub path: PathBuf,
    /// Every sample, its force from the sensor's zero at rest ([`trial::remove_tare`]) and
    /// its position from the stage's start ([`trial::zero_travel`]).
    pub samples: Vec<Sample>,
    /// Its phases.
    pub phases: Phases,
    /// The insertion phase as a curve (position, force), from the stage's start.
    pub points: Vec<Point>,
    /// The punctures found on `points` (indices into `points`).
    pub events: Vec<Puncture>,
    /// Today's single-curve fit on `points`: its onset is the trial's contact (depth 0).
    pub fit: Fit,
}

impl Trial {
    /// Stage travel at contact (depth 0), mm.
    #[must_use]
    pub fn onset_mm(&self) -> f64 {
        self.fit.onset_mm
    }

    /// The sample index of point `i` of the insertion.
    #[must_use]
    pub fn sample_of(&self, point: usize) -> usize {
        self.phases.insertion.start + point
    }

    /// The measured peak (position mm, force N) of puncture `k`.
    #[must_use]
    pub fn peak(&self, k: usize) -> Option<(f64, f64)> {
        let e = self.events.get(k)?;
        self.points.get(e.peak).map(|p| (p.position_mm, p.force_n))
    }

    /// The file's name, for messages.
    #[must_use]
    pub fn name(&self) -> String {
        self.path.display().to_string()
    }
}

/// Reads, screens and prepares the trial at `path` (its forces from the sensor's zero at
/// rest, its positions from the stage's start: [`trial::remove_tare`],
/// [`trial::zero_travel`]); `surrogate` is the boundary's axial
/// force at an indentation with scale 1 (the library's, for the needle). Without a
/// puncture the onset is today's fit over the whole insertion (for a replay).
///
/// # Errors
/// The reader's and the screen's refusals (`FILE:LINE`), a trial the phases cannot cut,
/// or (with `need_puncture`) one without a puncture.
pub fn prepare(path: &Path, rule: EventRule, surrogate: &dyn Fn(f64) -> f64, similarity: f64, need_puncture: bool) -> Result<Trial> {
    let what = path.display().to_string();
    let mut samples = trial::read_trial(path)?;
    crate::trial_screen::screen(&samples, &what)?;
    let mut phases = trial::phases(&samples, &what)?;
    trial::remove_tare(&mut samples, &mut phases, &what);
    trial::zero_travel(&mut samples, &mut phases, &what);
    let points: Vec<Point> =
        samples[phases.insertion.clone()].iter().map(|s| Point { position_mm: s.position_mm, force_n: s.force_n, line: s.line }).collect();
    let events = events::punctures(&points, rule);
    if events.is_empty() && need_puncture {
        bail!(
            "{what}: no puncture found in the insertion (lines {} to {}): a trial without a puncture cannot calibrate a stack",
            points.first().map_or(0, |p| p.line),
            points.last().map_or(0, |p| p.line)
        );
    }
    let fit = fit::fit(&points, &events, surrogate, similarity);
    Ok(Trial { path: path.to_path_buf(), samples, phases, points, events, fit })
}

/// The needle number of a rig file name (`..._needle<n>_...`), if it has one.
#[must_use]
pub fn named_needle(path: &Path) -> Option<String> {
    let stem = path.file_stem()?.to_str()?;
    stem.split('_').find(|f| f.starts_with("needle") && f.len() > 6).map(str::to_string)
}

/// One needle diameter for all of `paths`: `diameters` has one value for all, or one per
/// trial, all equal; files named by the rig's convention must name one needle.
///
/// # Errors
/// A count other than 1 or one per trial; two different diameters (naming both files);
/// two different needles in the file names.
pub fn one_needle(paths: &[PathBuf], diameters: &[f64]) -> Result<f64> {
    let Some(&first) = diameters.first() else { bail!("--needle-diameter-mm: give the measured needle's diameter, mm") };
    if diameters.len() != 1 && diameters.len() != paths.len() {
        bail!("--needle-diameter-mm: {} values for {} trials: one for all, or one per trial", diameters.len(), paths.len());
    }
    for (k, d) in diameters.iter().enumerate() {
        if *d != first {
            let (a, b) = (paths.first().map(|p| p.display().to_string()), paths.get(k).map(|p| p.display().to_string()));
            bail!(
                "{}: needle {d} mm, but {}: needle {first} mm: trials of different needle diameters cannot calibrate one stack (calibrate each needle on its own)",
                b.unwrap_or_default(),
                a.unwrap_or_default()
            );
        }
    }
    let named: Vec<(&PathBuf, String)> = paths.iter().filter_map(|p| named_needle(p).map(|n| (p, n))).collect();
    if let Some((p0, n0)) = named.first() {
        if let Some((p, n)) = named.iter().find(|(_, n)| n != n0) {
            bail!(
                "{}: its name says {n}, but {}: {n0}: trials of different needles cannot calibrate one stack (calibrate each needle on its own)",
                p.display(),
                p0.display()
            );
        }
    }
    Ok(first)
}

/// The puncture count of the calibration: the most common of the trials' (the smaller on
/// a tie), and a note for each trial with another count (its extra or missing punctures
/// are not fitted; the checks show them).
#[must_use]
pub fn puncture_count(trials: &[Trial]) -> (usize, Vec<String>) {
    let mut counts: Vec<usize> = trials.iter().map(|t| t.events.len()).collect();
    counts.sort_unstable();
    let mut best = (0usize, 0usize);
    for &c in &counts {
        let n = counts.iter().filter(|&&x| x == c).count();
        if n > best.1 {
            best = (c, n);
        }
    }
    let notes = trials
        .iter()
        .filter(|t| t.events.len() != best.0)
        .map(|t| {
            format!(
                "{}: {} punctures, the other trials {}: fitted on its first {} only",
                t.name(),
                t.events.len(),
                best.0,
                best.0.min(t.events.len())
            )
        })
        .collect();
    (best.0, notes)
}
