//! Issue 65's repeats goal: a group's trials (one sample, one speed, one needle) differ
//! from each other by the group's own spread; a stack calibrated on some of them predicts
//! each other trial within [`RATIO_GOAL`] times that spread.
//!
//! Both are the same measure, the RMS of a force against a trial's measured force over
//! the whole trial, each phase aligned by its own coordinate:
//! - the insertion by depth from the trial's measured contact (stage travel from the
//!   first sample where the force leaves the tare's noise, [`crate::trial::Phases::contact`]),
//! - the hold by time from its start (the stage at its furthest travel),
//! - the withdrawal by stage travel back from the hold's end;
//!
//! over the group's common window (the depth, hold time and travel back that every trial
//! of the group reaches: a row beyond it has no partner in a shallower or shorter trial),
//! in % of the group's mean peak force (each trial's largest measured force in the
//! window). Between two measured trials A and B: A's force interpolated at the coordinate
//! of each row of B against B's, and B's at each row of A against A's, pooled; the
//! group's spread is the RMS over its pairs' rows pooled ([`GroupSpread::rms`]). A model replayed
//! along trial B (the library's insertion driven by B's measured position against time,
//! [`crate::trial_replay`]) is read at B's own rows, so its coordinate is B's: its error
//! is the RMS over B's rows in the window ([`GroupSpread::model_rms`]).
//!
//! Nothing here depends on a tissue: the coordinates come from the stage and the
//! contact from the tare's noise, as the phases are cut ([`crate::trial::phases`]).
use super::trials::Trial;
use crate::trial_replay::TrialReplay;

/// The goal: a predicted trial's RMS error at most this many times its group's spread.
pub const RATIO_GOAL: f64 = 1.5;

/// The phases of a whole trial, each aligned by its own coordinate (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stage {
    /// From the measured contact to the hold: depth from the contact, mm.
    Insertion,
    /// The stage at rest at its furthest travel: time from the hold's start, s.
    Hold,
    /// The stage returning: travel back from the hold's end, mm.
    Withdrawal,
}

/// The stages in their order.
pub const STAGES: [Stage; 3] = [Stage::Insertion, Stage::Hold, Stage::Withdrawal];

/// One phase of a trial as (coordinate, measured force, sample index) rows, the
/// coordinate from 0 at the phase's first row and never decreasing (a running maximum:
/// an encoder's jitter backwards keeps the last coordinate).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Curve {
    /// The rows, in the trial's order.
    pub rows: Vec<(f64, f64, usize)>,
}

impl Curve {
    fn of(t: &Trial, range: std::ops::Range<usize>, coordinate: &dyn Fn(&crate::trial::Sample) -> f64) -> Self {
        let mut rows = Vec::with_capacity(range.len());
        let mut last = f64::NEG_INFINITY;
        for i in range {
            let Some(s) = t.samples.get(i) else { break };
            last = last.max(coordinate(s));
            rows.push((last, s.force_n, i));
        }
        Self { rows }
    }

    /// The largest coordinate reached (`None`: no rows).
    #[must_use]
    pub fn reach(&self) -> Option<f64> {
        self.rows.last().map(|r| r.0)
    }

    /// The force at coordinate `x`, linear between rows (`None` outside the rows).
    #[must_use]
    pub fn at(&self, x: f64) -> Option<f64> {
        let i = self.rows.partition_point(|r| r.0 < x);
        let b = self.rows.get(i)?;
        match i.checked_sub(1).and_then(|k| self.rows.get(k)) {
            Some(a) if b.0 > a.0 => Some(a.1 + (x - a.0) / (b.0 - a.0) * (b.1 - a.1)),
            _ => (x >= b.0 - 1e-12 && x <= b.0 + 1e-12).then_some(b.1),
        }
    }
}

/// A trial cut into its aligned phases.
#[derive(Debug, Clone, PartialEq)]
pub struct Aligned {
    /// Insertion, hold and withdrawal, in [`STAGES`]' order (a phase the trial lacks is
    /// empty).
    pub curves: [Curve; 3],
}

impl Aligned {
    /// The phases of `t` (module docs): the insertion from the measured contact to the
    /// hold's start, the hold to the withdrawal's start, the withdrawal to the trial's end.
    #[must_use]
    pub fn of(t: &Trial) -> Self {
        let p = &t.phases;
        let s = |i: usize| t.samples.get(i).copied();
        let contact_mm = s(p.contact).map_or(0.0, |x| x.position_mm);
        let hold_start = if p.hold.is_empty() { p.insertion.end } else { p.hold.start };
        let insertion = Curve::of(t, p.contact..hold_start, &|x| x.position_mm - contact_mm);
        let hold_end = if p.withdrawal.is_empty() { p.hold.end } else { p.withdrawal.start.min(p.hold.end) };
        let t0 = s(hold_start).map_or(0.0, |x| x.time_s);
        let hold = if p.hold.is_empty() { Curve::default() } else { Curve::of(t, hold_start..hold_end, &|x| x.time_s - t0) };
        let back_from = s(p.withdrawal.start).map_or(0.0, |x| x.position_mm);
        let withdrawal = Curve::of(t, p.withdrawal.clone(), &|x| back_from - x.position_mm);
        Self { curves: [insertion, hold, withdrawal] }
    }

    /// The rows inside `window` (per stage, the coordinate at most the window's reach).
    fn rows<'a>(&'a self, window: &'a Window) -> impl Iterator<Item = (usize, &'a (f64, f64, usize))> + 'a {
        self.curves
            .iter()
            .enumerate()
            .flat_map(move |(k, c)| c.rows.iter().filter(move |r| window.reach[k].is_some_and(|w| r.0 <= w)).map(move |r| (k, r)))
    }
}

/// The group's common window: per stage the coordinate every trial reaches (`None`: a
/// trial lacks that phase, which is left out of every RMS).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Window {
    /// Insertion depth (mm), hold time (s), withdrawal travel (mm), in [`STAGES`]' order.
    pub reach: [Option<f64>; 3],
}

impl Window {
    /// The smallest reach of each stage over `trials`.
    #[must_use]
    pub fn common(trials: &[Aligned]) -> Self {
        let mut reach = [None; 3];
        for (k, r) in reach.iter_mut().enumerate() {
            *r = trials.iter().map(|a| a.curves[k].reach()).try_fold(f64::INFINITY, |m, x| x.map(|x| m.min(x)));
            if r.is_some_and(|x| !x.is_finite()) {
                *r = None;
            }
        }
        Self { reach }
    }
}

/// Two measured trials' RMS difference over the window.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PairRms {
    /// The two trials (indices into the group).
    pub trials: (usize, usize),
    /// Their RMS difference, % of the group's mean peak force.
    pub rms: Rms,
}

/// An RMS over the window and its part in each phase (each the RMS over that phase's
/// rows), % of the group's mean peak force.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Rms {
    /// Over every row of the window.
    pub all_pct: f64,
    /// Over the rows of each phase, in [`STAGES`]' order (NaN: no rows).
    pub stage_pct: [f64; 3],
    /// The rows of each phase.
    pub stage_rows: [usize; 3],
}

impl Rms {
    /// The RMS over the rows of the phases `keep` says (in [`STAGES`]' order), %; NaN
    /// without rows.
    #[must_use]
    pub fn over(&self, keep: [bool; 3]) -> f64 {
        let (mut s, mut n) = (0.0, 0usize);
        for ((pct, rows), k) in self.stage_pct.iter().zip(self.stage_rows).zip(keep) {
            if k && rows > 0 {
                s += pct * pct * rows as f64;
                n += rows;
            }
        }
        if n == 0 {
            f64::NAN
        } else {
            (s / n as f64).sqrt()
        }
    }
}

/// Sums of squares and counts, per stage.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
struct Sums([(f64, usize); 3]);

impl Sums {
    fn add(&mut self, k: usize, e: f64) {
        if let Some(s) = self.0.get_mut(k) {
            s.0 += e * e;
            s.1 += 1;
        }
    }

    fn merge(&mut self, o: &Self) {
        for (a, b) in self.0.iter_mut().zip(o.0) {
            a.0 += b.0;
            a.1 += b.1;
        }
    }

    fn total(&self) -> (f64, usize) {
        self.0.iter().fold((0.0, 0), |(s, n), x| (s + x.0, n + x.1))
    }

    /// The RMS, % of `peak`.
    fn rms(&self, peak: f64) -> Rms {
        let pct = |(s, n): (f64, usize)| if n == 0 { f64::NAN } else { 100.0 * (s / n as f64).sqrt() / peak };
        Rms { all_pct: pct(self.total()), stage_pct: self.0.map(pct), stage_rows: self.0.map(|x| x.1) }
    }
}

/// A group's own spread (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct GroupSpread {
    /// The common window.
    pub window: Window,
    /// Mean over the trials of each one's largest measured force in the window, N.
    pub mean_peak_n: f64,
    /// Every pair of the group.
    pub pairs: Vec<PairRms>,
    /// The group's spread: the RMS over every pair's rows pooled (each pair has the
    /// window's rows of its two trials, so the pairs weigh alike), % of the mean peak
    /// force (`all_pct`), and the same within each phase.
    pub rms: Rms,
}

/// `other`'s force against `of`'s rows in the window.
fn against(of: &Aligned, other: &Aligned, w: &Window) -> Sums {
    let mut s = Sums::default();
    for (k, r) in of.rows(w) {
        if let Some(f) = other.curves[k].at(r.0) {
            s.add(k, f - r.1);
        }
    }
    s
}

impl GroupSpread {
    /// The spread of a group's trials (`None`: fewer than two, or a window with no rows).
    #[must_use]
    pub fn of(trials: &[Trial]) -> Option<Self> {
        let aligned: Vec<Aligned> = trials.iter().map(Aligned::of).collect();
        let window = Window::common(&aligned);
        let peaks: Vec<f64> = aligned.iter().map(|a| a.rows(&window).map(|(_, r)| r.1).fold(f64::NEG_INFINITY, f64::max)).collect();
        let mean_peak_n = peaks.iter().sum::<f64>() / peaks.len() as f64;
        if trials.len() < 2 || !(mean_peak_n.is_finite() && mean_peak_n > 0.0) {
            return None;
        }
        let (mut pairs, mut pooled) = (Vec::new(), Sums::default());
        for a in 0..aligned.len() {
            for b in a + 1..aligned.len() {
                let mut s = against(&aligned[a], &aligned[b], &window);
                s.merge(&against(&aligned[b], &aligned[a], &window));
                if s.total().1 == 0 {
                    return None;
                }
                pairs.push(PairRms { trials: (a, b), rms: s.rms(mean_peak_n) });
                pooled.merge(&s);
            }
        }
        let rms = pooled.rms(mean_peak_n);
        Some(Self { window, mean_peak_n, pairs, rms })
    }

    /// The RMS of the model `r` (replayed along `t`, one row per sample) against `t`'s
    /// measured force over the window, % of the group's mean peak force (NaN: no rows).
    #[must_use]
    pub fn model_rms(&self, t: &Trial, r: &TrialReplay) -> Rms {
        let mut s = Sums::default();
        for (k, row) in Aligned::of(t).rows(&self.window) {
            if let Some(m) = r.rows.get(row.2) {
                s.add(k, m.force_n - row.1);
            }
        }
        s.rms(self.mean_peak_n)
    }

    /// A prediction's error over the group's spread: the model's RMS over the window
    /// ([`Self::model_rms`]) over the group's, met at most [`RATIO_GOAL`].
    #[must_use]
    pub fn ratio(&self, model: &Rms) -> f64 {
        model.all_pct / self.rms.all_pct
    }
}

#[cfg(test)]
mod tests {
    use super::Curve;

    #[test]
    fn a_curve_interpolates_inside_and_refuses_outside() {
        let c = Curve { rows: vec![(0.0, 1.0, 0), (1.0, 3.0, 1), (1.0, 5.0, 2), (2.0, 7.0, 3)] };
        assert_eq!(c.at(0.0), Some(1.0));
        assert_eq!(c.at(0.5), Some(2.0));
        assert_eq!(c.at(1.5), Some(6.0));
        assert_eq!(c.at(2.0), Some(7.0));
        assert_eq!(c.at(2.1), None);
        assert_eq!(c.at(-0.1), None);
    }
}
