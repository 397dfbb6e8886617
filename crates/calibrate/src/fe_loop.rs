//! The loop closed (issue 64, item 5): the FEBio run of a calibrated layer's material
//! (`[family.fitted]` of the set's `campaign.toml`: the layer's family member with every
//! modulus times its stiffness scale, solved at the centre by `needle fe run --family`)
//! against the measured pre-puncture curve the layer was calibrated on. The FE needle is
//! carried to the measured one by geometric similarity (depth x `λ`, force x `λ²`, `λ` the
//! calibration's [`Calibration::similarity`]) from the calibration's contact onset. The FE
//! has no failure model, so the comparison is given over the whole rise and over the part
//! below the softening's onset (where the calibrated law is purely elastic).

use crate::Calibration;
use anyhow::{bail, Result};

/// The FE run against the measured rise, in % of the measured puncture force.
#[derive(Debug, Clone, PartialEq)]
pub struct LoopCheck {
    /// RMS of `FE - measured` over the measured points from the contact onset to the first
    /// puncture's peak, % of the puncture force.
    pub rms_pct: f64,
    /// The largest `|FE - measured|` over those points, % of the puncture force.
    pub max_pct: f64,
    /// Their count.
    pub points: usize,
    /// RMS over the points whose FE force is at most the softening's onset ratio times the
    /// FE force at the peak (all of them without softening), % of the puncture force.
    pub rms_below_softening_pct: f64,
    /// Their count.
    pub points_below_softening: usize,
    /// RMS over every point of the rise with the layer's fitted softening applied to the
    /// FE force (`1 - D(ρ)`, ρ = FE force over the FE force at the peak: the calibrated
    /// failure law on top of the FE material), % of the puncture force.
    pub rms_softened_pct: f64,
    /// The measured force at the first puncture, N.
    pub puncture_force_n: f64,
    /// The FE depth the comparison needs, mm of the FE needle (the peak's).
    pub fe_depth_needed_mm: f64,
}

/// `fe`'s axial force (N, against the FE needle's depth in mm, from depth 0, in order)
/// carried to the measured needle and compared with `c`'s pre-puncture curve
/// ([`LoopCheck`]); linear between the FE's must points.
///
/// # Errors
/// `c` has no puncture or no point past its contact onset, the similarity is not > 0, or
/// `fe` does not reach the depth of the measured puncture (the depths named, mm).
pub fn compare(c: &Calibration, fe: &[(f64, f64)]) -> Result<LoopCheck> {
    let Some(first) = c.events.first() else { bail!("the calibrated curve has no puncture to compare up to") };
    let lambda = c.similarity;
    if !(lambda.is_finite() && lambda > 0.0) {
        bail!("geometric similarity {lambda}: must be > 0");
    }
    let onset = c.fit.onset_mm;
    let rise: Vec<_> = c.points.iter().take(first.peak + 1).filter(|p| p.position_mm > onset).collect();
    let (Some(peak), false) = (c.points.get(first.peak), rise.is_empty()) else {
        bail!("no measured point between the contact onset ({onset:.3} mm) and the first puncture")
    };
    let needed = (peak.position_mm - onset) / lambda;
    let reached = fe.last().map_or(0.0, |p| p.0);
    if reached + 1e-9 < needed {
        bail!("the FE run reaches {reached:.3} mm of the FE needle's depth; the measured puncture needs {needed:.3} mm");
    }
    let fe_at = |d: f64| interpolate(fe, d) * lambda * lambda;
    let at_peak = fe_at(needed);
    let softening = c.fit.layers.first().map_or(crate::shape::Softening::NONE, |l| l.softening);
    let r0 = if softening.fraction > 0.0 { softening.onset_ratio } else { 1.0 };
    let f_p = peak.force_n;
    let (mut sum, mut sum_below, mut below, mut max, mut sum_soft) = (0.0, 0.0, 0usize, 0.0f64, 0.0);
    for p in &rise {
        let model = fe_at((p.position_mm - onset) / lambda);
        let rho = if at_peak > 0.0 { model / at_peak } else { 0.0 };
        sum_soft += (model * softening.factor(rho) - p.force_n).powi(2);
        let e = model - p.force_n;
        sum += e * e;
        max = max.max(e.abs());
        if model <= r0 * at_peak {
            sum_below += e * e;
            below += 1;
        }
    }
    let pct = |ss: f64, n: usize| if n > 0 && f_p > 0.0 { 100.0 * (ss / n as f64).sqrt() / f_p } else { f64::NAN };
    Ok(LoopCheck {
        rms_pct: pct(sum, rise.len()),
        max_pct: if f_p > 0.0 { 100.0 * max / f_p } else { f64::NAN },
        points: rise.len(),
        rms_below_softening_pct: pct(sum_below, below),
        points_below_softening: below,
        rms_softened_pct: pct(sum_soft, rise.len()),
        puncture_force_n: f_p,
        fe_depth_needed_mm: needed,
    })
}

/// `curve` (x in order, x > 0, the force at x = 0 being 0: the contact) at `x`, linear
/// between its points and from (0, 0) to the first; 0 before contact, its last value past
/// the end.
fn interpolate(curve: &[(f64, f64)], x: f64) -> f64 {
    if x <= 0.0 {
        return 0.0;
    }
    let i = curve.partition_point(|p| p.0 < x);
    let a = i.checked_sub(1).and_then(|k| curve.get(k)).copied().unwrap_or((0.0, 0.0));
    match curve.get(i) {
        Some(&b) if b.0 > a.0 => a.1 + (b.1 - a.1) * (x - a.0) / (b.0 - a.0),
        Some(&b) => b.1,
        None => a.1,
    }
}

#[cfg(test)]
mod tests {
    use super::interpolate;

    #[test]
    fn interpolation_is_linear_between_points_and_zero_before_contact() {
        let c = [(1.0, 2.0), (3.0, 6.0)];
        assert_eq!(interpolate(&c, 0.5), 1.0);
        assert_eq!(interpolate(&c, 2.0), 4.0);
        assert_eq!(interpolate(&c, -1.0), 0.0);
        assert_eq!(interpolate(&c, 3.0), 6.0);
        assert_eq!(interpolate(&c, 5.0), 6.0);
    }
}
