//! The tissue's tent (`tent_n_per_mm`, the library's `Presliding::tent_n_per_mm`): the
//! tissue around the shaft a spring in series with its friction, so that a reversal
//! turns over over millimetres and a withdrawing shaft lifts the tissue, lengthening the
//! shaft in it (`docs/insertion.md`, "Presliding").
//!
//! Fitted last, on the stack the other steps made: one stiffness `k` for every layer
//! with a presliding and one factor on their sliding friction (static and Coulomb: with
//! a tent the shaft slips at `c L / (1 - c / k)` with the lift, so the level the
//! withdrawals read without it is refitted with it), both from a grid (`k` then refined
//! between its grid neighbours by a parabola through their costs), by the replays'
//! least squares over every trial from its contact to its end (each trial's sum of
//! squares over its rows and its peak force squared, so that each trial weighs the
//! same), among the grid points whose mean pull over the withdrawals stays within
//! [`LEVEL_TOLERANCE`] of the measured one (read where the goals read the withdrawal,
//! 10-20 mm of stage travel: the level there, not only its sign's rows, is what the tent
//! and the friction together must give) and the points between two grid neighbours where
//! that level crosses the measured one (`level_crossings`). Without a tent (`k` none)
//! is a grid point: a stack keeps none when no tent lowers the sum of squares. (A tent
//! had to lower it by 10 %: skin on muscle's 1 mm/s trials 3 and 4, 0.0143 -> 0.0129,
//! kept one before their tares were subtracted and not after; a threshold makes nearly
//! equal trials give a stack with and without a tent.)
use super::goals::{HOLD_AVERAGE_SAMPLES, WITHDRAWAL_WINDOW_MM};
use super::trials::Trial;
use crate::trial::Sample;
use crate::trial_replay::replay;
use anyhow::Result;
use needle_codegen::tissue as file;
use needle_haptics::insertion;

/// The tent stiffnesses tried, N/mm (0: none), a factor of about 1.6 apart over the
/// range the rig's withdrawals span (`withdrawal_tent` example: 0.18-0.68).
pub const TENT_GRID_N_PER_MM: [f64; 10] = [0.0, 0.04, 0.063, 0.1, 0.16, 0.25, 0.4, 0.63, 1.0, 1.6];
/// The factors tried on the static level over the Coulomb one with a tent (the level at
/// which the stuck shaft holds the lifted tissue).
pub const STATIC_FACTORS: [f64; 10] = [1.0, 1.2, 1.45, 1.75, 2.1, 2.5, 3.0, 3.6, 4.3, 5.2];
/// A tent is kept only when the model's pull over the withdrawals (the mean over each
/// one's rows within the goals' window, [`WITHDRAWAL_WINDOW_MM`]) stays within this share
/// of the measured one.
pub const LEVEL_TOLERANCE: f64 = 0.05;

/// What the fit chose: the tent (N/mm; `None`: none), the static level's factor, and the
/// sums of squares without a tent and with the choice.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TentFit {
    /// The tent's stiffness, N/mm (`None`: none fitted better).
    pub tent_n_per_mm: Option<f64>,
    /// The static level over the Coulomb one (1 without a tent).
    pub static_factor: f64,
    /// The trials' normalised sum of squares without a tent and with the choice.
    pub cost: (f64, f64),
}

/// `stack` with the tent `k` (N/mm, 0: none) on every layer with a presliding and their
/// static level `factor` times their Coulomb one.
fn with_tent(stack: &file::Stack, k: f64, factor: f64) -> file::Stack {
    let mut s = stack.clone();
    for l in s.layers.iter_mut().filter(|l| l.presliding_mm.is_some()) {
        l.tent_n_per_mm = (k > 0.0).then_some(k);
        l.friction_static_n_per_mm = l.friction_coulomb_n_per_mm * factor;
    }
    s
}

/// The rows of trial `t`'s withdrawal its pull is read on: those within the goal's window
/// of stage travel ([`WITHDRAWAL_WINDOW_MM`], where the checks read the
/// withdrawal) with the tip below the contact; or, for a trial with fewer than
/// [`HOLD_AVERAGE_SAMPLES`] such rows (a window outside its tissue: too few to average
/// the raw force's noise), its pulled-back rows (the measured force below zero, the tip
/// below the contact).
fn level_rows(t: &Trial) -> Vec<usize> {
    let (lo, hi) = WITHDRAWAL_WINDOW_MM;
    let in_tissue: Vec<(usize, &Sample)> =
        t.phases.withdrawal.clone().filter_map(|i| Some((i, t.samples.get(i)?))).filter(|(_, s)| s.position_mm > t.onset_mm()).collect();
    let window: Vec<usize> = in_tissue.iter().filter(|(_, s)| (lo..=hi).contains(&s.position_mm)).map(|(i, _)| *i).collect();
    if window.len() >= HOLD_AVERAGE_SAMPLES {
        return window;
    }
    in_tissue.iter().filter(|(_, s)| s.force_n < 0.0).map(|(i, _)| *i).collect()
}

/// The trials' sum of squares from each contact on, each over its rows and its peak
/// squared, and the mean over the trials of the model's pull over each withdrawal's
/// `rows` (its [`level_rows`]) over the measured one; `None` when the library refuses the
/// stack.
fn cost(stack: &file::Stack, diameter_mm: f64, trials: &[Trial], rows: &[Vec<usize>]) -> Option<(f64, f64)> {
    let layers: Vec<insertion::Layer> = stack.layers.iter().map(crate::to_layer).collect();
    let lib = insertion::Stack { name: &stack.name, needle_diameter_mm: diameter_mm as f32, layers: &layers };
    let (mut total, mut level, mut levels) = (0.0, 0.0, 0.0);
    for (t, rows) in trials.iter().zip(rows) {
        let r = replay(&lib, t.onset_mm(), &t.samples).ok()?;
        let (mut sum, mut n, mut peak) = (0.0, 0.0, 0.0f64);
        for (s, m) in t.samples.iter().zip(&r.rows).skip(t.phases.contact) {
            sum += (s.force_n - m.force_n).powi(2);
            n += 1.0;
            peak = peak.max(s.force_n.abs());
        }
        if n > 0.0 && peak > 0.0 {
            total += sum / n / (peak * peak);
        }
        let (mut measured, mut model) = (0.0, 0.0);
        for (s, m) in rows.iter().filter_map(|&i| Some((t.samples.get(i)?, r.rows.get(i)?))) {
            measured += s.force_n;
            model += m.force_n;
        }
        if measured < 0.0 {
            level += model / measured;
            levels += 1.0;
        }
    }
    Some((total, if levels > 0.0 { level / levels } else { 1.0 }))
}

/// Fits the tent and the friction's factor to `trials` (module docs) and writes them
/// into `stack`; a stack without a presliding layer is left as it is.
///
/// # Errors
/// The library refuses the stack as the other steps made it.
pub fn fit(stack: &mut file::Stack, diameter_mm: f64, trials: &[Trial]) -> Result<TentFit> {
    let rows: Vec<Vec<usize>> = trials.iter().map(level_rows).collect();
    let (none, _) =
        cost(stack, diameter_mm, trials, &rows).ok_or_else(|| anyhow::anyhow!("the calibrated stack is refused by the library"))?;
    let without = TentFit { tent_n_per_mm: None, static_factor: 1.0, cost: (none, none) };
    if !stack.layers.iter().any(|l| l.presliding_mm.is_some()) {
        return Ok(without);
    }
    let mut best = without;
    let keep = |k: f64, factor: f64, (c, level): (f64, f64), best: &mut TentFit| {
        if c < best.cost.1 && (level - 1.0).abs() <= LEVEL_TOLERANCE {
            *best = TentFit { tent_n_per_mm: Some(k), static_factor: factor, cost: (none, c) };
        }
    };
    let mut grid = vec![[None; STATIC_FACTORS.len()]; TENT_GRID_N_PER_MM.len()];
    for (ki, &k) in TENT_GRID_N_PER_MM.iter().enumerate().filter(|(_, &k)| k > 0.0) {
        for (fi, &factor) in STATIC_FACTORS.iter().enumerate() {
            let Some(at) = cost(&with_tent(stack, k, factor), diameter_mm, trials, &rows) else { continue };
            grid[ki][fi] = Some(at);
            keep(k, factor, at, &mut best);
        }
    }
    for (k, factor) in level_crossings(&grid) {
        if let Some(at) = cost(&with_tent(stack, k, factor), diameter_mm, trials, &rows) {
            keep(k, factor, at, &mut best);
        }
    }
    // `best` starts without a tent and takes a tent only at a lower sum of squares
    let best = refine(stack, diameter_mm, trials, &rows, &grid, best);
    if let Some(k) = best.tent_n_per_mm {
        *stack = with_tent(stack, k, best.static_factor);
    }
    Ok(best)
}

/// Where the withdrawals' level crosses the measured one between two neighbouring grid
/// points (`grid`: per stiffness and factor, the sum of squares and the model's pull over
/// the measured one): along the factors at each stiffness (linear in the factor) and
/// along the stiffnesses at each factor (linear in `ln k`), as `(k, factor)`. The level
/// moves by 5-50 % from one grid point to the next (the rig's skin on muscle at 1 mm/s,
/// trials 4 and 5: 0.73, 1.055 and 1.48 at 0.063, 0.1 and 0.16 N/mm), so a grid point
/// within [`LEVEL_TOLERANCE`] of the level is a matter of where the grid's steps fall;
/// these points are (nearly) on it, and the fit does not hinge on the steps.
fn level_crossings(grid: &[[Option<(f64, f64)>; STATIC_FACTORS.len()]]) -> Vec<(f64, f64)> {
    // the x where the level, linear from (x0, l0) to (x1, l1), is 1; l0 != l1 where they
    // lie on either side of 1: no division by zero
    let crossing =
        |(x0, l0): (f64, f64), (x1, l1): (f64, f64)| ((l0 - 1.0) * (l1 - 1.0) < 0.0).then(|| x0 + (1.0 - l0) * (x1 - x0) / (l1 - l0));
    let level = |ki: usize, fi: usize| grid.get(ki)?.get(fi).copied()?.map(|(_, l)| l);
    let mut out = Vec::new();
    for (ki, &k) in TENT_GRID_N_PER_MM.iter().enumerate().filter(|(_, &k)| k > 0.0) {
        for (fi, pair) in STATIC_FACTORS.windows(2).enumerate() {
            let (Some(l0), Some(l1), [f0, f1]) = (level(ki, fi), level(ki, fi + 1), pair) else { continue };
            out.extend(crossing((*f0, l0), (*f1, l1)).map(|f| (k, f)));
        }
        let Some(&k1) = TENT_GRID_N_PER_MM.get(ki + 1) else { continue };
        for (fi, &f) in STATIC_FACTORS.iter().enumerate() {
            let (Some(l0), Some(l1)) = (level(ki, fi), level(ki + 1, fi)) else { continue };
            out.extend(crossing((k.ln(), l0), (k1.ln(), l1)).map(|x| (x.exp(), f)));
        }
    }
    out
}

/// The grid's best `k` refined at its factor: the vertex, in `ln k`, of the parabola
/// through the costs of the best grid point and its two neighbours, when it opens
/// upwards; kept when it costs less and keeps the withdrawals' level. A stiffness between
/// two grid points is then found as such, not snapped to one of them: on trials that
/// differ a little (another sampling rate, a trial more) the fit moves a little (the
/// muscle's 0.4 and 0.25 N/mm grid points at 100 Hz and 1 kHz:
/// `crates/calibrate/tests/trials_sampling_rate.rs`).
fn refine(
    stack: &file::Stack,
    diameter_mm: f64,
    trials: &[Trial],
    rows: &[Vec<usize>],
    grid: &[[Option<(f64, f64)>; STATIC_FACTORS.len()]],
    best: TentFit,
) -> TentFit {
    let Some(k0) = best.tent_n_per_mm else { return best };
    // a stiffness between the grid's (a level crossing) is on the level already
    let Some(ki) = TENT_GRID_N_PER_MM.iter().position(|&k| k == k0) else { return best };
    let fi = STATIC_FACTORS.iter().position(|&f| f == best.static_factor);
    // the grid's cost at stiffness i and the best's factor (replayed for a factor between
    // the grid's, a level crossing)
    let at = |i: usize| {
        let k = TENT_GRID_N_PER_MM.get(i).copied().filter(|k| *k > 0.0)?;
        let c = match fi {
            Some(fi) => grid.get(i)?.get(fi).copied()??.0,
            None if i == ki => best.cost.1,
            None => cost(&with_tent(stack, k, best.static_factor), diameter_mm, trials, rows)?.0,
        };
        Some((k.ln(), c))
    };
    let (Some(lo), Some(mid), Some(hi)) = (ki.checked_sub(1).and_then(at), at(ki), at(ki + 1)) else { return best };
    let Some(k) = vertex(lo, mid, hi).map(f64::exp) else { return best };
    match cost(&with_tent(stack, k, best.static_factor), diameter_mm, trials, rows) {
        Some((c, level)) if c < best.cost.1 && (level - 1.0).abs() <= LEVEL_TOLERANCE => {
            TentFit { tent_n_per_mm: Some(k), cost: (best.cost.0, c), ..best }
        }
        _ => best,
    }
}

/// The vertex of the parabola through three points `(x, y)` with `x` increasing,
/// clamped between the outer two; `None` when it does not open upwards.
fn vertex((x0, y0): (f64, f64), (x1, y1): (f64, f64), (x2, y2): (f64, f64)) -> Option<f64> {
    let (d01, d12) = ((y1 - y0) / (x1 - x0), (y2 - y1) / (x2 - x1));
    let curvature = (d12 - d01) / (x2 - x0);
    // the parabola a (x - v)^2 + b has the slope d01 at the middle of (x0, x1) and a = curvature
    let x = 0.5 * (x0 + x1) - d01 / (2.0 * curvature);
    (curvature > 0.0 && x.is_finite()).then(|| x.clamp(x0, x2))
}

/// The notes written beside the tent and the static level of each layer that has the
/// fitted tent (`uncertainty`: per layer, `(key, note)`, as [`super::stack::Fitted`]).
pub fn annotate(fit: &TentFit, stack: &file::Stack, uncertainty: &mut [Vec<(&'static str, String)>]) {
    let Some(k) = fit.tent_n_per_mm else { return };
    let tent = format!(
        "the replays' least squares over the trials from their contact (grid {TENT_GRID_N_PER_MM:?} N/mm refined between its neighbours, the static friction level {} times the Coulomb one with it; sum of squares {:.4} -> {:.4})",
        fit.static_factor, fit.cost.0, fit.cost.1
    );
    let level =
        format!("the level holding the tissue the tent lifts: {} times the Coulomb level, fitted with tent_n_per_mm", fit.static_factor);
    for (l, u) in stack.layers.iter().zip(uncertainty.iter_mut()) {
        if l.tent_n_per_mm == Some(k) {
            u.push(("tent_n_per_mm", tent.clone()));
            u.push(("friction_static_n_per_mm", level.clone()));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{level_crossings, vertex, STATIC_FACTORS, TENT_GRID_N_PER_MM};

    #[test]
    fn the_level_crosses_between_grid_neighbours() {
        // a level growing with ln k and flat in the factor: 1 at k = 0.08 N/mm only
        let level = |k: f64| 1.0 + (k / 0.08).ln();
        let grid: Vec<[Option<(f64, f64)>; STATIC_FACTORS.len()]> =
            TENT_GRID_N_PER_MM.iter().map(|&k| [(k > 0.0).then(|| (1.0, level(k))); STATIC_FACTORS.len()]).collect();
        let found = level_crossings(&grid);
        assert_eq!(found.len(), STATIC_FACTORS.len(), "one crossing per factor, along k: {found:?}");
        for ((k, f), g) in found.iter().zip(STATIC_FACTORS) {
            assert!((k - 0.08).abs() < 1e-12 && *f == g, "{k} N/mm at {f}");
        }
        // a level that never reaches 1 crosses nowhere
        let below: Vec<_> = grid.iter().map(|row| row.map(|at| at.map(|(c, l)| (c, l - 10.0)))).collect();
        assert!(level_crossings(&below).is_empty());
    }

    #[test]
    fn the_vertex_of_a_parabola_through_three_points() {
        let y = |x: f64| 2.0 * (x - 0.7) * (x - 0.7) + 1.0;
        let v = vertex((0.0, y(0.0)), (1.0, y(1.0)), (2.5, y(2.5))).expect("opens upwards");
        assert!((v - 0.7).abs() < 1e-12, "{v}");
        let far = |x: f64| (x - 9.0) * (x - 9.0);
        assert_eq!(vertex((0.0, far(0.0)), (1.0, far(1.0)), (2.0, far(2.0))), Some(2.0), "clamped to the outer points");
        assert_eq!(vertex((0.0, -y(0.0)), (1.0, -y(1.0)), (2.5, -y(2.5))), None, "opens downwards");
    }
}
