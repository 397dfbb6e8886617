//! The types of the viscoelastic ramp-and-hold runs: `[viscoelastic]` of campaign.toml
//! ([`ViscoSettings`]), the Prony series the FE tissue is wrapped with ([`Prony`]) and
//! the time course of one run ([`RampHold`]). Plain data and its arithmetic only: `spec`
//! holds these in its `Tissue` and `Loading`, so nothing here depends on `spec`.

use serde::{Deserialize, Serialize};

/// Most Prony terms of one tissue: the contract's, as the library's filter (FEBio's
/// `uncoupled viscoelastic` takes up to 6).
pub use needle_contract::MAX_PRONY_TERMS;

/// The run name of `pose` at `speed_mm_per_s`: `centre_10mm-s`, `x+04_1p5mm-s`.
pub fn run_name(pose: &str, speed_mm_per_s: f64) -> String {
    format!("{pose}_{}mm-s", decimal_tag(speed_mm_per_s))
}

/// A number as it goes into a run or folder name: its shortest decimal form with `p` for
/// the point (`1.5` -> `1p5`, `10` -> `10`).
pub fn decimal_tag(x: f64) -> String {
    format!("{x}").replace('.', "p")
}

/// Suffix of the frictionless runs' names (`[viscoelastic] frictionless`): the
/// ramp-and-hold run `centre_10mm-s_mu0` and the elastic companion `centre_mu0`.
pub const FRICTIONLESS_SUFFIX: &str = "_mu0";

/// The name of a frictionless run (ramp-and-hold or elastic companion) of `name`.
pub fn frictionless_name(name: &str) -> String {
    format!("{name}{FRICTIONLESS_SUFFIX}")
}

/// `[viscoelastic]`: the Prony series and the ramp-and-hold loadings of
/// `needle fe run --visco` (module docs of `needle_fe::visco`, which applies them).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ViscoSettings {
    /// Prony weights g_i in FEBio's normalisation (`g0` = 1: the `[tissue]` Ogden is the
    /// long-term response, the instantaneous one is `1 + sum g_i` times stiffer); >= 0.
    pub g: Vec<f64>,
    /// Relaxation times tau_i, s; > 0, one per `g`.
    pub tau_s: Vec<f64>,
    /// Insertion speeds, mm/s: one run per pose and speed (to `loading.depth_mm`).
    pub speeds_mm_per_s: Vec<f64>,
    /// Hold after the ramp, s.
    pub hold_s: f64,
    /// Must points on the hold (the ramp has `loading.steps`, at the elastic runs' depths).
    pub hold_steps: u32,
    /// The first must point of the hold, s after the ramp's end; the others follow
    /// geometrically to `hold_s`.
    pub hold_first_s: f64,
    /// Newton's absolute floor on the residual, N (FEBio's `min_residual`, squared): below
    /// it an iteration is converged whatever the relative criteria say. In the hold the
    /// relaxation moves the tissue by round-off-sized steps and the relative criteria
    /// chase contact chatter (measured, coeffs/README.md).
    pub min_residual_n: f64,
    /// Mesh level of the runs.
    pub mesh: String,
    /// Pose names of the campaign, solved in this order (the centre first: quarter model).
    pub poses: Vec<String>,
    /// Solve every pose at every speed a second time with `contact.friction` 0
    /// (`<run>_mu0`), beside elastic companions with friction 0 (`<pose>_mu0`, the
    /// filter's input for them), all in `fe/visco/`. The QLV filter relaxes the elastic
    /// wrench as a whole; Coulomb slip during the hold is not part of it, and FEBio's
    /// hold with friction did not solve at every pose (coeffs/README.md).
    #[serde(default)]
    pub frictionless: bool,
}

/// The Prony series the FE tissue is wrapped with (FEBio's `uncoupled viscoelastic`,
/// normalisation of [`ViscoSettings::g`]). Part of the run hash through the tissue.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Prony {
    /// g_i (FEBio's, `g0` = 1).
    pub g: Vec<f64>,
    /// tau_i, s.
    pub tau_s: Vec<f64>,
}

/// The time course of one ramp-and-hold run: the needle fed at `speed_mm_per_s` to the
/// loading's depth in `ramp_steps` equal must points, then held for `hold_s` with
/// `hold_steps` must points growing geometrically from `hold_first_s`. FEBio's time is
/// then seconds (an elastic run's time is its depth in mm).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RampHold {
    /// Feed speed, mm/s.
    pub speed_mm_per_s: f64,
    /// Must points on the ramp (equal depth steps).
    pub ramp_steps: u32,
    /// Hold, s.
    pub hold_s: f64,
    /// Must points on the hold.
    pub hold_steps: u32,
    /// First hold must point, s after the ramp's end.
    pub hold_first_s: f64,
    /// Newton's absolute residual floor, N ([`ViscoSettings::min_residual_n`]).
    pub min_residual_n: f64,
}

impl RampHold {
    /// Duration of the ramp to `depth_mm`, s.
    pub fn ramp_s(&self, depth_mm: f64) -> f64 {
        depth_mm / self.speed_mm_per_s
    }

    /// Time of must point `k` (0 ..= ramp_steps + hold_steps), s.
    pub fn time_s(&self, depth_mm: f64, k: u32) -> f64 {
        let ramp = self.ramp_s(depth_mm);
        if k <= self.ramp_steps {
            return ramp * f64::from(k) / f64::from(self.ramp_steps.max(1));
        }
        let j = k - self.ramp_steps;
        if j >= self.hold_steps || self.hold_steps == 1 {
            return ramp + self.hold_s;
        }
        let frac = f64::from(j - 1) / f64::from(self.hold_steps - 1);
        ramp + self.hold_first_s * (self.hold_s / self.hold_first_s).powf(frac)
    }

    /// Depth of must point `k`, mm.
    pub fn depth_mm(&self, depth_mm: f64, k: u32) -> f64 {
        depth_mm * f64::from(k.min(self.ramp_steps)) / f64::from(self.ramp_steps.max(1))
    }

    /// Feed depth at time `t_s`, mm (the load curve FEBio is given).
    pub fn depth_at_time_mm(&self, depth_mm: f64, t_s: f64) -> f64 {
        (self.speed_mm_per_s * t_s).clamp(0.0, depth_mm)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn must_points_ramp_then_hold() {
        let r = RampHold { speed_mm_per_s: 10.0, ramp_steps: 20, hold_s: 30.0, hold_steps: 5, hold_first_s: 0.03, min_residual_n: 1e-5 };
        assert!((r.ramp_s(6.0) - 0.6).abs() < 1e-15);
        assert_eq!(r.time_s(6.0, 0), 0.0);
        assert!((r.time_s(6.0, 20) - 0.6).abs() < 1e-15);
        assert!((r.time_s(6.0, 21) - 0.63).abs() < 1e-12, "first hold point");
        assert_eq!(r.time_s(6.0, 25), 30.6, "the hold's end exactly");
        let t: Vec<f64> = (0..=25).map(|k| r.time_s(6.0, k)).collect();
        assert!(t.windows(2).all(|w| w[1] > w[0]), "increasing: {t:?}");
        assert_eq!(r.depth_mm(6.0, 10), 3.0);
        assert_eq!(r.depth_mm(6.0, 24), 6.0);
        assert_eq!(r.depth_at_time_mm(6.0, 0.3), 3.0);
        assert_eq!(r.depth_at_time_mm(6.0, 5.0), 6.0);
    }
}
