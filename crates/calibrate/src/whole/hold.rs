//! After the last puncture, and the hold: the tip cuts the last punctured layer (cutting
//! `c`, the shaft's friction known from the withdrawals) and deflects the boundary
//! below (`b`, scale `s`), which the trials never puncture; at rest (the hold) cutting
//! and friction are gone and the deflected boundary relaxes through its Prony terms (the
//! library's quasi-linear viscoelastic filter, FEBio's long-term normalisation:
//! `G(t) = 1 + sum g_i exp(-t / tau_i)`, at most three terms).
//!
//! The filter is linear in its input, so with `x = (c, s, s g_1, s g_2, s g_3)` the
//! model is linear: `F - friction = c [moving] + s u(d - b) + sum (s g_i) y_i`, where
//! `y_i` is the filter's response with `g = 1` to the unit-scale deflection `u` along
//! the trial's measured depth against time (FEBio's recursion, exact for an input
//! linear between samples: the library's). The boundary `b` is scanned, the time
//! constants chosen among [`TAU_COUNT`] log-spaced values from three sampling periods to
//! three holds, and `x >= 0` is the least squares of all the trials together.
//!
//! **With the shaft's presliding** ([`ShaftGuess`]: the library's `shaft-presliding`),
//! at rest the shaft keeps its friction and the tip its cutting force, relaxing through
//! the shaft's own Prony terms: the friction is subtracted in the hold too (at rest: its
//! Coulomb level), the cutting column covers the hold, and per time constant a column
//! `(friction at rest + c) (z_i - 1)` with `z_i` the library's arm along the trial
//! ([`super::presliding::arms`]) takes the weight `beta_i = g_i / (1 + sum g)` of the
//! shaft's relaxation (`g_i = beta_i / (1 - sum beta)`); the boundary is the one found
//! without it, its scale fitted again and its terms the shaft's ([`super::tied`]: one
//! relaxation function for the tissue; [`fit_with_shaft`]). Each arm is loaded within
//! `v tau_i` of travel (`v` the stick band's edge, below every measured speed; at most
//! the presliding distance), so it slips while the needle slides at any speed above the
//! stick band: the held force relaxes by the same share at every sliding speed (as the
//! rig's trials do, at 1, 2 and 3 mm/s) and the sliding force is the friction and
//! cutting the trials show. The stack's relaxation slip distance is the shortest term's;
//! the library loads each longer term within it times `tau_i / tau_min`, at most the
//! presliding distance: the distances fitted here.
//!
//! The boundary's filter starts from rest at the last puncture's peak (the library
//! resets it there and steps it to the deflection at once when the boundary lies above
//! the tip).
use super::friction::LayerFriction;
use super::intervals::{friction_n, indent, BOUNDARY_STEP_MM};
use super::stats::{Normal, Spread};
use super::trials::Trial;

/// Candidate time constants of the Prony terms.
pub const TAU_COUNT: usize = 7;

/// How far above the last puncture the boundary below may lie, mm (it deflects at once
/// when it lies above the depth where the layer above punctures).
pub const ABOVE_LAST_PUNCTURE_MM: f64 = 3.0;

/// The shaft's presliding for a joint fit: its distance, the cutting force of the fit
/// before (the relaxation's column carries it) and the speed its arms slip at.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShaftGuess {
    /// The presliding distance, mm.
    pub presliding_mm: f64,
    /// The cutting force of the last punctured layer, N.
    pub cutting_n: f64,
    /// The speed the arms slip at, mm/s: the stick band's edge (below every measured
    /// speed, [`super::stack::stick_band`]).
    pub slip_speed_mm_per_s: f64,
}

impl ShaftGuess {
    /// The slip distance of an arm of time constant `tau_s` (module docs), mm: the slip
    /// speed times `tau_s`, at most the presliding distance, at least the least
    /// relaxation slip distance a stack may hold. A stack whose `relaxation_slip_mm` is
    /// its shortest term's gives the library the same distance for every term
    /// (`needle_haptics::insertion::Presliding::term_slip_mm`) whenever the shortest
    /// term's is above that least one (1e-4 mm: a speed of 0.1 mm/s over 1 ms).
    #[must_use]
    pub fn slip_mm(&self, tau_s: f64) -> f64 {
        let (lo, _) = needle_codegen::tissue::RELAXATION_SLIP_MM_RANGE;
        (self.slip_speed_mm_per_s * tau_s).clamp(lo, self.presliding_mm.max(lo))
    }
}

/// What the joint fit gave.
#[derive(Debug, Clone, PartialEq)]
pub struct HoldFit {
    /// The boundary below the last puncture, mm of depth (`None`: no deflection helps).
    pub boundary_mm: Option<f64>,
    /// Its scale (joint least squares), and per trial.
    pub scale: f64,
    /// The last punctured layer's cutting force, N (joint), and per trial.
    pub cutting_n: f64,
    /// The Prony terms `(g, tau_s)`, from the shortest time constant.
    pub prony: Vec<(f64, f64)>,
    /// Per-trial refits at the chosen boundary and time constants: scale, cutting, and
    /// each term's `g`.
    pub per_trial: PerTrial,
    /// How many trials had a hold.
    pub holds: usize,
    /// The shaft's Prony terms `(g, tau_s)` (with a [`ShaftGuess`]; else empty).
    pub shaft_prony: Vec<(f64, f64)>,
    /// Each shaft term's weight `g` refitted on each trial alone.
    pub shaft_g: Vec<Spread>,
    /// The relaxation's slip distance, mm (the smallest of the shaft terms'; `None`
    /// without terms).
    pub shaft_slip_mm: Option<f64>,
}

/// The per-trial refits of [`HoldFit`].
#[derive(Debug, Clone, PartialEq)]
pub struct PerTrial {
    /// Scale.
    pub scale: Spread,
    /// Cutting, N.
    pub cutting_n: Spread,
    /// Each term's weight.
    pub g: Vec<Spread>,
}

/// The candidate time constants for trials whose shortest sampling period is `dt_s` and
/// longest hold `hold_s`.
#[must_use]
pub fn tau_grid(dt_s: f64, hold_s: f64) -> Vec<f64> {
    let (lo, hi) = (3.0 * dt_s.max(1e-4), 3.0 * hold_s.max(dt_s));
    (0..TAU_COUNT).map(|k| lo * (hi / lo).powf(k as f64 / (TAU_COUNT - 1) as f64)).collect()
}

/// The normal equations of trial `t` for the boundary at `b_mm` (columns: cutting,
/// deflection, one per `taus`).
#[allow(clippy::too_many_arguments)]
fn normal(
    t: &Trial,
    n: usize,
    bounds: &[f64],
    friction: &[LayerFriction],
    b_mm: f64,
    taus: &[f64],
    u: &dyn Fn(f64) -> f64,
    shaft: Option<&ShaftGuess>,
) -> Option<Normal> {
    let e = t.events.get(n.checked_sub(1)?)?;
    let start = t.sample_of(e.bottom);
    let end = if t.phases.hold.is_empty() { t.phases.insertion.end } else { t.phases.hold.end };
    let v = t.phases.insertion_speed_mm_per_s;
    let columns = if shaft.is_some() { 2 + 2 * taus.len() } else { 2 + taus.len() };
    let arms = shaft.map(|g| super::presliding::arms(t, taus, &taus.iter().map(|tau| g.slip_mm(*tau)).collect::<Vec<_>>()));
    let mut out = Normal::new(columns);
    let mut h = vec![0.0; taus.len()];
    // the library resets the filter at the puncture and steps it to the boundary's
    // deflection there: the filter starts from rest at the puncture's peak
    let mut last: Option<(f64, f64)> = t.samples.get(t.sample_of(e.peak)).map(|s| (s.time_s, 0.0));
    let mut row = vec![0.0; columns];
    for i in start..end {
        let s = t.samples.get(i)?;
        let d = s.position_mm - t.onset_mm();
        let moving = i + 1 < t.phases.insertion.end;
        let ue = indent(u, d - b_mm);
        if let Some((t0, u0)) = last {
            let dt = s.time_s - t0;
            for (hk, tau) in h.iter_mut().zip(taus) {
                let a = (-dt / tau).exp();
                *hk = a * *hk + (1.0 - a) / (dt / tau) * (ue - u0);
            }
        }
        last = Some((s.time_s, ue));
        row[1] = ue;
        row[2..2 + taus.len()].copy_from_slice(&h);
        let r = if let (Some(g), Some(z)) = (shaft, arms.as_ref().and_then(|a| a.get(i))) {
            // held at rest: the friction's Coulomb level, the cutting; both relax
            let at_rest = friction_n(friction, bounds, b_mm, d, 0.0);
            row[0] = 1.0;
            for (c, zi) in row[2 + taus.len()..].iter_mut().zip(z) {
                *c = (at_rest + g.cutting_n) * (zi - 1.0);
            }
            s.force_n - if moving { friction_n(friction, bounds, b_mm, d, v) } else { at_rest }
        } else {
            row[0] = if moving { 1.0 } else { 0.0 };
            s.force_n - if moving { friction_n(friction, bounds, b_mm, d, v) } else { 0.0 }
        };
        out.add(&row, r);
    }
    Some(out)
}

/// Every choice of at most three of `count` time constants (as indices), the empty one
/// first.
fn combos(count: usize) -> Vec<Vec<usize>> {
    let mut out = vec![Vec::new()];
    for a in 0..count {
        out.push(vec![a]);
        for b in a + 1..count {
            out.push(vec![a, b]);
            for c in b + 1..count {
                out.push(vec![a, b, c]);
            }
        }
    }
    out
}

/// A scanned candidate: sum of squares, boundary, chosen time constants, unknowns.
type Candidate = (f64, Option<f64>, Vec<usize>, Vec<f64>);

/// The joint fit (module docs) over the trials with `n` punctures; `bounds` the
/// punctured layers' upper boundaries, `friction` theirs.
#[must_use]
pub fn fit(trials: &[Trial], n: usize, bounds: &[f64], friction: &[LayerFriction], u: &dyn Fn(f64) -> f64) -> HoldFit {
    let used: Vec<&Trial> = trials.iter().filter(|t| t.events.len() >= n).collect();
    let holds = used.iter().filter(|t| !t.phases.hold.is_empty()).count();
    let dt = used.iter().flat_map(|t| t.samples.windows(2).map(|w| w[1].time_s - w[0].time_s)).fold(f64::INFINITY, f64::min);
    let longest = used.iter().map(|t| t.phases.hold_s).fold(0.0, f64::max);
    let taus = if holds > 0 { tau_grid(dt, longest) } else { Vec::new() };
    let choices = combos(taus.len());
    let top = bounds.last().copied().unwrap_or(0.0);
    let peak = |t: &&Trial| t.peak(n - 1).map_or(f64::INFINITY, |p| p.0 - t.onset_mm());
    let lo = used.iter().map(peak).fold(f64::INFINITY, f64::min) - ABOVE_LAST_PUNCTURE_MM;
    let hi = used.iter().map(|t| t.phases.travel_mm + t.samples.first().map_or(0.0, |s| s.position_mm) - t.onset_mm()).fold(0.0, f64::max);
    let lo = lo.max(top + BOUNDARY_STEP_MM);
    // (sse, b, choice, x)
    let mut best: Option<Candidate> = None;
    let steps = ((hi - lo) / BOUNDARY_STEP_MM).floor().max(0.0) as usize;
    for i in 0..=steps {
        // the last candidate: no boundary within reach (only cutting)
        let b = if i == steps { None } else { Some(lo + BOUNDARY_STEP_MM * i as f64) };
        let mut all = Normal::new(2 + taus.len());
        for t in &used {
            if let Some(nm) = normal(t, n, bounds, friction, b.unwrap_or(f64::INFINITY), &taus, u, None) {
                all.merge(&nm);
            }
        }
        let tries: &[Vec<usize>] = if b.is_some() { &choices } else { &choices[..1] };
        for choice in tries {
            let keep: Vec<usize> = [0, 1].into_iter().chain(choice.iter().map(|k| k + 2)).collect();
            let (x, sse) = all.select(&keep).non_negative();
            let scale = x.get(1).copied().unwrap_or(0.0);
            let g_sum: f64 = x.iter().skip(2).map(|c| c / scale.max(f64::MIN_POSITIVE)).sum();
            if (b.is_some() && scale <= 0.0) || g_sum > needle_codegen::tissue::PRONY_G_SUM_MAX {
                continue;
            }
            if best.as_ref().is_none_or(|(s, ..)| sse < *s) {
                best = Some((sse, b, choice.clone(), x));
            }
        }
    }
    let (_, b, choice, x) = best.unwrap_or((0.0, None, Vec::new(), vec![0.0; 2]));
    let scale = x.get(1).copied().unwrap_or(0.0);
    // the terms the fit kept (a zero weight is no term)
    let kept: Vec<(f64, f64)> = choice
        .iter()
        .filter_map(|&k| taus.get(k).copied())
        .zip(x.iter().skip(2))
        .filter(|(_, c)| **c > 0.0 && scale > 0.0)
        .map(|(tau, c)| (c / scale, tau))
        .collect();
    let chosen: Vec<f64> = kept.iter().map(|k| k.1).collect();
    let per_trial = refit(&used, n, bounds, friction, b, &chosen, u);
    let prony = kept;
    HoldFit {
        boundary_mm: b,
        scale,
        cutting_n: x.first().copied().unwrap_or(0.0),
        prony,
        per_trial,
        holds,
        shaft_prony: Vec::new(),
        shaft_g: Vec::new(),
        shaft_slip_mm: None,
    }
}

/// The joint fit with the shaft's presliding (module docs) at the boundary of `before`
/// (the fit without it): the time constants chosen again, one set for the shaft and the
/// boundary ([`super::tied`]; the boundary's terms are this fit's `prony`); `before`
/// when no trial has a hold.
#[must_use]
pub fn fit_with_shaft(
    trials: &[Trial],
    n: usize,
    bounds: &[f64],
    friction: &[LayerFriction],
    u: &dyn Fn(f64) -> f64,
    before: &HoldFit,
    guess: &ShaftGuess,
) -> HoldFit {
    let used: Vec<&Trial> = trials.iter().filter(|t| t.events.len() >= n).collect();
    if before.holds == 0 {
        return before.clone();
    }
    let dt = used.iter().flat_map(|t| t.samples.windows(2).map(|w| w[1].time_s - w[0].time_s)).fold(f64::INFINITY, f64::min);
    let longest = used.iter().map(|t| t.phases.hold_s).fold(0.0, f64::max);
    let taus = tau_grid(dt, longest);
    let m = taus.len();
    let b = before.boundary_mm;
    let normals: Vec<Normal> =
        used.iter().filter_map(|t| normal(t, n, bounds, friction, b.unwrap_or(f64::INFINITY), &taus, u, Some(guess))).collect();
    let mut all = Normal::new(2 + 2 * m);
    for nm in &normals {
        all.merge(nm);
    }
    // unknowns: cutting, the boundary's scale, each chosen term's beta
    let keep_of = |choice: &[usize]| -> Vec<usize> { [0, 1].into_iter().chain(choice.iter().map(|k| k + 2 + m)).collect() };
    // one relaxation function: the boundary below relaxes through the shaft's terms
    let tie = b.is_some();
    let terms = |nm: &Normal, choice: &[usize]| {
        if tie {
            super::tied::fit(nm, choice, m)
        } else {
            nm.select(&keep_of(choice)).non_negative()
        }
    };
    let mut best: Option<(f64, Vec<usize>, Vec<f64>)> = None;
    for choice in combos(m) {
        let (x, sse) = terms(&all, &choice);
        if x.iter().skip(2).sum::<f64>() >= SHAFT_BETA_SUM_MAX {
            continue;
        }
        if best.as_ref().is_none_or(|(s, ..)| sse < *s) {
            best = Some((sse, choice, x));
        }
    }
    let Some((_, choice, x)) = best else { return before.clone() };
    let scale = x.get(1).copied().unwrap_or(0.0);
    // a zero scale: the held shaft explains the force, no boundary deflects
    let b = b.filter(|_| scale > 0.0);
    let chosen: Vec<f64> = choice.iter().filter_map(|&c| taus.get(c).copied()).collect();
    let betas: Vec<f64> = x.iter().skip(2).copied().collect();
    let shaft_prony = shaft_terms(&betas, &chosen);
    let shaft_slip_mm = shaft_prony.iter().map(|(_, tau)| guess.slip_mm(*tau)).reduce(f64::min);
    // per trial: each alone at the chosen terms, each kept term's weight g
    let per: Vec<Vec<f64>> = normals.iter().map(|nm| terms(nm, &choice).0).collect();
    let shaft_g = (0..choice.len())
        .filter(|&i| betas.get(i).is_some_and(|b| *b > 0.0))
        .map(|i| {
            let g = |x: &Vec<f64>| {
                let total = 1.0 - x.iter().skip(2).sum::<f64>();
                x.get(2 + i).copied().unwrap_or(0.0) / total.max(1.0 - SHAFT_BETA_SUM_MAX)
            };
            Spread::of(per.iter().map(g).collect())
        })
        .collect();
    let spread = |k: usize| Spread::of(per.iter().map(|x| x.get(k).copied().unwrap_or(0.0)).collect());
    let per_trial = PerTrial { scale: spread(1), cutting_n: spread(0), g: Vec::new() };
    let prony = if b.is_some() { shaft_prony.clone() } else { Vec::new() };
    HoldFit {
        boundary_mm: b,
        scale,
        cutting_n: x.first().copied().unwrap_or(0.0),
        prony,
        per_trial,
        holds: before.holds,
        shaft_prony,
        shaft_g,
        shaft_slip_mm,
    }
}

/// The largest sum of the shaft's relaxation weights `beta` (`1 - 1 / (1 + 9)`: the
/// format's largest sum of `g`, 9).
pub const SHAFT_BETA_SUM_MAX: f64 = 0.9;

/// The shaft's terms `(g, tau_s)` from the weights `beta` (`g_i = beta_i / (1 - sum beta)`),
/// the zero ones left out.
fn shaft_terms(betas: &[f64], taus: &[f64]) -> Vec<(f64, f64)> {
    let total = 1.0 - betas.iter().sum::<f64>();
    betas.iter().zip(taus).filter(|(b, _)| **b > 0.0 && total > 0.0).map(|(b, tau)| (b / total, *tau)).collect()
}

/// Each trial alone at the chosen boundary and time constants.
fn refit(
    used: &[&Trial],
    n: usize,
    bounds: &[f64],
    friction: &[LayerFriction],
    b: Option<f64>,
    taus: &[f64],
    u: &dyn Fn(f64) -> f64,
) -> PerTrial {
    let fits: Vec<Vec<f64>> = used
        .iter()
        .filter_map(|t| normal(t, n, bounds, friction, b.unwrap_or(f64::INFINITY), taus, u, None))
        .map(|nm| nm.non_negative().0)
        .collect();
    let col = |k: usize| fits.iter().map(|x| x.get(k).copied().unwrap_or(0.0)).collect::<Vec<f64>>();
    let scales = col(1);
    let g = (0..taus.len())
        .map(|k| {
            Spread::of(
                fits.iter().map(|x| x.get(2 + k).copied().unwrap_or(0.0) / x.get(1).copied().filter(|s| *s > 0.0).unwrap_or(1.0)).collect(),
            )
        })
        .collect();
    PerTrial { scale: Spread::of(scales), cutting_n: Spread::of(col(0)), g }
}
