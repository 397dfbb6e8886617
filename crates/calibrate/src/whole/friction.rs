//! Shaft friction per layer from the withdrawals: where the withdrawing needle is pulled
//! back (the measured force below zero, the tip still in the tissue) the model's force is
//! friction alone, `-sum_j f_j L_j(d)` with `L_j` the shaft's length in layer `j`; each
//! trial gives `f_j` at its withdrawal speed (non-negative least squares). Several
//! speeds give Coulomb and viscous levels (`f = C + V |v|`, least squares over the
//! trials); one speed gives the level at that speed, all Coulomb. The static level is the
//! sliding level at the stick band's edge (continuous: the data cannot show a break).
//! With the shaft's presliding ([`Turnover`]) the model's shaft force turns over after the
//! stage reverses: its relaxing share (`1 - long`, the arms) at once, its long-term share
//! linearly over twice the presliding distance `p`, so at travel `Δ` it pulls
//! `s(Δ) = (1 - long) + long clamp(Δ / p - 1, -1, 1)` of its sliding level: each
//! pulled-back row's lengths are weighted by it (rows where the model does not pull yet,
//! `s <= 0`, left out).
use super::stats::{Normal, Spread};
use super::trials::Trial;

/// The shaft's length in each layer for the tip at depth `d_mm` (the layers' upper
/// boundaries `bounds`, the first 0; nothing below `next_mm`, the boundary the tip
/// deflects).
#[must_use]
pub fn lengths(bounds: &[f64], next_mm: f64, d_mm: f64) -> Vec<f64> {
    let top = d_mm.min(next_mm);
    (0..bounds.len())
        .map(|j| {
            let lo = bounds[j];
            let hi = bounds.get(j + 1).copied().unwrap_or(f64::INFINITY).min(top);
            (hi - lo).max(0.0)
        })
        .collect()
}

/// One layer's friction over the speeds.
#[derive(Debug, Clone, PartialEq)]
pub struct LayerFriction {
    /// Coulomb level, N/mm.
    pub coulomb_n_per_mm: f64,
    /// Its standard error, N/mm (`None`: one trial).
    pub coulomb_se: Option<f64>,
    /// Viscous term, N s/mm² (0 when one speed was measured).
    pub viscous_n_s_per_mm2: f64,
    /// Its standard error (`None`: one speed or too few trials).
    pub viscous_se: Option<f64>,
    /// The per-trial levels at their speeds, N/mm, and the speeds, mm/s.
    pub levels: Spread,
}

impl LayerFriction {
    /// The level at speed `v` (mm/s, either sign), N/mm.
    #[must_use]
    pub fn at(&self, v_mm_per_s: f64) -> f64 {
        self.coulomb_n_per_mm + self.viscous_n_s_per_mm2 * v_mm_per_s.abs()
    }
}

/// Whether the trials' withdrawal speeds differ enough (by more than 20 %) to tell a
/// viscous term from a Coulomb level.
pub const SPEED_RATIO_FOR_VISCOUS: f64 = 1.2;

/// The shaft's presliding as the withdrawal's fit needs it (module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Turnover {
    /// The presliding distance `p`, mm (> 0).
    pub presliding_mm: f64,
    /// The long-term share of the held force, `1 / (1 + sum g)` of the shaft's terms.
    pub long_term: f64,
}

impl Turnover {
    /// The share of its sliding pull the model's shaft has reached at `travel_mm` after
    /// the reversal.
    #[must_use]
    pub fn share(&self, travel_mm: f64) -> f64 {
        (1.0 - self.long_term) + self.long_term * (travel_mm / self.presliding_mm - 1.0).clamp(-1.0, 1.0)
    }
}

/// The friction of the `bounds.len()` punctured layers from the trials' withdrawals (the
/// trials' onsets; no shaft below `next_mm`, the boundary the model deflects there and
/// never punctures; with `turnover`, each row weighted by the model's turn-over); `None`
/// when no trial has a withdrawal with the needle pulled back.
#[must_use]
pub fn fit(trials: &[Trial], bounds: &[f64], next_mm: f64, turnover: Option<&Turnover>) -> Option<Vec<LayerFriction>> {
    let n = bounds.len();
    // per trial: (speed, levels of each layer)
    let mut per_trial: Vec<(f64, Vec<f64>)> = Vec::new();
    for t in trials {
        let mut normal = Normal::new(n);
        let mut rows = 0;
        let reversal = t.samples.get(t.phases.withdrawal.start).map_or(f64::INFINITY, |s| s.position_mm);
        for s in &t.samples[t.phases.withdrawal.clone()] {
            let d = s.position_mm - t.onset_mm();
            let share = turnover.map_or(1.0, |tv| tv.share(reversal - s.position_mm));
            if s.force_n < 0.0 && d > 0.0 && share > 0.0 {
                let row: Vec<f64> = lengths(bounds, next_mm, d).iter().map(|l| l * share).collect();
                normal.add(&row, -s.force_n);
                rows += 1;
            }
        }
        if rows > n {
            per_trial.push((t.phases.withdrawal_speed_mm_per_s.abs(), normal.non_negative().0));
        }
    }
    if per_trial.is_empty() {
        return None;
    }
    let (lo, hi) = per_trial.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), (v, _)| (lo.min(*v), hi.max(*v)));
    let viscous = hi > SPEED_RATIO_FOR_VISCOUS * lo;
    Some((0..n).map(|j| layer(&per_trial, j, viscous)).collect())
}

fn layer(per_trial: &[(f64, Vec<f64>)], j: usize, viscous: bool) -> LayerFriction {
    let levels = Spread::of(per_trial.iter().map(|(_, f)| f.get(j).copied().unwrap_or(0.0)).collect());
    if !viscous {
        return LayerFriction { coulomb_n_per_mm: levels.mean, coulomb_se: levels.se, viscous_n_s_per_mm2: 0.0, viscous_se: None, levels };
    }
    let mut normal = Normal::new(2);
    for ((v, _), f) in per_trial.iter().zip(&levels.values) {
        normal.add(&[1.0, *v], *f);
    }
    let (x, sse) = normal.non_negative();
    let m = per_trial.len() as f64;
    // the regression's standard errors (both terms free): sigma^2 (X^T X)^-1
    let (s1, sv, svv) = per_trial.iter().fold((0.0, 0.0, 0.0), |(a, b, c), (v, _)| (a + 1.0, b + v, c + v * v));
    let det = s1 * svv - sv * sv;
    let free = x.iter().all(|v| *v > 0.0);
    let se = |k: f64| (free && m > 2.0 && det > 0.0).then(|| (sse / (m - 2.0) * k / det).sqrt());
    LayerFriction { coulomb_n_per_mm: x[0], coulomb_se: se(svv), viscous_n_s_per_mm2: x[1], viscous_se: se(s1), levels }
}
