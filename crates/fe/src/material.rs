//! Material check run before any solve: is the Ogden tissue of a campaign stable?
//!
//! # Convention
//!
//! The tissue is an Ogden material in the Abaqus/CalculiX form
//!
//! ```text
//! W = sum_i 2 mu_i / alpha_i^2 (l1^alpha_i + l2^alpha_i + l3^alpha_i - 3) + (J - 1)^2 / D1
//! ```
//!
//! with the principal stretches `l1, l2, l3` of the isochoric deformation. In this form
//! the initial shear modulus is `mu0 = sum_i mu_i` and the initial bulk modulus is
//! `K0 = 2 / D1`; the spec gives `K0 = bulk_to_shear * mu0`. (Ogden's original form
//! `sum_i mu_i / alpha_i (...)` has `mu0 = 1/2 sum_i mu_i alpha_i`; its `mu_i` are not the
//! numbers here.)
//!
//! # Checks, in this order
//!
//! 1. `mu0 = sum_i mu_i > 0`. The terms with `mu_i < 0` are listed in the message, for
//!    information only: in this convention a term contributes `2 mu_i l^alpha_i` to the
//!    tangent, so the sign of `mu_i` (not of `mu_i alpha_i`) says whether a term softens;
//!    a single negative term is not by itself unstable if the sum stays stable.
//! 2. `K0 = bulk_to_shear * mu0 > 0`.
//! 3. Drucker stability of the incompressible (isochoric) part, as the "material
//!    stability" check of Abaqus does it (Abaqus Theory Manual, hyperelastic material
//!    behavior): at every state of the test, the change of Kirchhoff stress `dtau` caused
//!    by a change of logarithmic strain `deps` must satisfy `dtau : deps > 0` for every
//!    isochoric `deps` (trace zero; the pressure then drops out). In principal axes,
//!    with `t_j = l_j dW/dl_j`, the Ogden form gives a diagonal tangent
//!    `h_j = dt_j / d(ln l_j) = sum_i 2 mu_i l_j^alpha_i`, and the condition is that the
//!    quadratic form `sum_j h_j deps_j^2` is positive on the plane `sum_j deps_j = 0`.
//!    Its smallest eigenvalue there (with `|deps| = 1`) is the *Drucker modulus*
//!    reported below. The states tested are those of the three standard tests over the
//!    spec's stretch range `[stretch_min, stretch_max]`, sampled at [`SAMPLES`]
//!    log-spaced stretches:
//!    - uniaxial: `l1 = l, l2 = l3 = l^-1/2`;
//!    - equibiaxial: `l1 = l2 = l, l3 = l^-2`;
//!    - pure shear (planar): `l1 = l, l2 = 1, l3 = 1/l`.
//!
//!    For each test the report also gives the *tangent* along the test's own loading path:
//!    the derivative of the true (Cauchy, here equal to Kirchhoff) stress in the loaded
//!    direction with respect to the logarithmic strain `ln l` (uniaxial `h1 + h2/2`,
//!    equibiaxial `h1 + 2 h3`, planar `h1 + h3`). A negative tangent always makes the
//!    Drucker modulus negative; the converse does not hold (the loss can be transverse to
//!    the path, e.g. in the lateral directions of a uniaxial test), so the criterion is
//!    the Drucker modulus. Note that `d(sigma)/d(ln l) > 0` is *not* the same as
//!    `dT/dl > 0` for the nominal stress `T = sigma / l` (`d(sigma)/d(ln l) = l T + l^2
//!    dT/dl`); the Abaqus criterion used here is the former.
//!
//! The volumetric term `(J - 1)^2 / D1` is convex in `J` for `D1 > 0` and adds no
//! instability, so check 2 covers it. As in Abaqus, only principal strain increments
//! are tested.

use crate::spec::Tissue;
use anyhow::{bail, Result};
use serde::Serialize;
use std::fmt;

/// Number of log-spaced stretches sampled over `[stretch_min, stretch_max]` per test.
pub const SAMPLES: usize = 2000;

/// One of the three standard homogeneous tests of the Drucker check.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Mode {
    /// Uniaxial: `l1 = l, l2 = l3 = l^-1/2`.
    Uniaxial,
    /// Equibiaxial: `l1 = l2 = l, l3 = l^-2`.
    Equibiaxial,
    /// Pure shear (planar): `l1 = l, l2 = 1, l3 = 1/l`.
    Planar,
}

impl Mode {
    /// The three tests, in the order they are checked.
    pub const ALL: [Mode; 3] = [Mode::Uniaxial, Mode::Equibiaxial, Mode::Planar];

    /// Principal stretches of the test at stretch `l`.
    pub fn stretches(self, l: f64) -> [f64; 3] {
        match self {
            Mode::Uniaxial => {
                let s = l.powf(-0.5);
                [l, s, s]
            }
            Mode::Equibiaxial => [l, l, l.powi(-2)],
            Mode::Planar => [l, 1.0, 1.0 / l],
        }
    }

    /// Name of the test at stretch `l`, e.g. "uniaxial tension", "planar compression".
    pub fn name_at(self, l: f64) -> String {
        let base = match self {
            Mode::Uniaxial => "uniaxial",
            Mode::Equibiaxial => "equibiaxial",
            Mode::Planar => "planar (pure shear)",
        };
        let sense = if l > 1.0 {
            "tension"
        } else if l < 1.0 {
            "compression"
        } else {
            "at rest"
        };
        format!("{base} {sense}")
    }
}

impl fmt::Display for Mode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Mode::Uniaxial => "uniaxial",
            Mode::Equibiaxial => "equibiaxial",
            Mode::Planar => "planar",
        })
    }
}

/// The stretch where a test first loses Drucker stability (closest to the undeformed
/// state, in `|ln l|`), with the values there.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Failure {
    /// Stretch `l` of the test.
    pub stretch: f64,
    /// Tangent `d(sigma)/d(ln l)` along the test path there, N/mm^2.
    pub tangent_n_per_mm2: f64,
    /// Drucker modulus there, N/mm^2 (<= 0).
    pub drucker_n_per_mm2: f64,
}

/// What one test gave over the stretch range.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ModeReport {
    /// The test.
    pub mode: Mode,
    /// Smallest tangent `d(sigma)/d(ln l)` along the test path, N/mm^2.
    pub min_tangent_n_per_mm2: f64,
    /// Stretch where that smallest tangent is found.
    pub min_tangent_at_stretch: f64,
    /// Smallest Drucker modulus (smallest eigenvalue of `dtau : deps` on isochoric unit
    /// `deps`), N/mm^2; the test is stable when it is > 0 at every sample.
    pub min_drucker_n_per_mm2: f64,
    /// Stretch where that smallest Drucker modulus is found.
    pub min_drucker_at_stretch: f64,
    /// First loss of stability, if any.
    pub failure: Option<Failure>,
}

/// Result of the material check: the initial moduli and, per test, the smallest tangent
/// and Drucker modulus over the stretch range.
#[derive(Debug, Clone, Serialize)]
pub struct StabilityReport {
    /// Initial shear modulus `mu0 = sum mu_i`, N/mm^2.
    pub mu0_n_per_mm2: f64,
    /// Initial bulk modulus `K0 = bulk_to_shear * mu0`, N/mm^2.
    pub k0_n_per_mm2: f64,
    /// Compressibility `D1 = 2 / K0`, mm^2/N.
    pub d1_mm2_per_n: f64,
    /// Initial Poisson's ratio `nu0 = (3 K0 - 2 mu0) / (2 (3 K0 + mu0))`.
    pub nu0: f64,
    /// Smallest stretch checked.
    pub stretch_min: f64,
    /// Largest stretch checked.
    pub stretch_max: f64,
    /// Stretches sampled per test.
    pub samples: usize,
    /// Indices (0-based) of the terms with `mu_i < 0`.
    pub negative_terms: Vec<usize>,
    /// Uniaxial, equibiaxial, planar, in this order.
    pub modes: Vec<ModeReport>,
}

impl StabilityReport {
    /// Whether every check passes (what [`check`] requires).
    pub fn is_stable(&self) -> bool {
        self.mu0_n_per_mm2 > 0.0 && self.k0_n_per_mm2 > 0.0 && self.modes.iter().all(|m| m.failure.is_none())
    }

    /// The report of one test.
    pub fn mode(&self, mode: Mode) -> Option<&ModeReport> {
        self.modes.iter().find(|m| m.mode == mode)
    }
}

impl fmt::Display for StabilityReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "mu0 = {} N/mm^2, K0 = {} N/mm^2 (D1 = {} mm^2/N), nu0 = {:.4}",
            num(self.mu0_n_per_mm2),
            num(self.k0_n_per_mm2),
            num(self.d1_mm2_per_n),
            self.nu0
        )?;
        write!(
            f,
            "Drucker check over stretch {} .. {} ({} samples per test):",
            num(self.stretch_min),
            num(self.stretch_max),
            self.samples
        )?;
        for m in &self.modes {
            write!(
                f,
                "\n  {:<12} min tangent {} N/mm^2 at {:.3}, min Drucker modulus {} N/mm^2 at {:.3}: {}",
                m.mode.to_string(),
                num(m.min_tangent_n_per_mm2),
                m.min_tangent_at_stretch,
                num(m.min_drucker_n_per_mm2),
                m.min_drucker_at_stretch,
                match &m.failure {
                    None => "stable".to_string(),
                    Some(x) => format!("UNSTABLE from stretch {:.3}", x.stretch),
                }
            )?;
        }
        Ok(())
    }
}

/// Check that the tissue is stable before any solve (checks 1-3 of the module docs)
/// and return the report.
///
/// # Errors
/// - The tissue is malformed: no terms, `mu` and `alpha` of different lengths, a
///   non-finite value, an `alpha_i = 0`, or a stretch range that is not
///   `0 < stretch_min < stretch_max` (the message says which).
/// - The tissue is unstable; the message starts with "tissue is unstable:" and names the
///   first failed check with its values and units: the initial shear modulus
///   `mu0 <= 0` (with the terms that have `mu_i < 0`), the initial bulk modulus
///   `K0 <= 0`, or the Drucker check, with every test that fails, the first failing
///   stretch, and the tangent and Drucker modulus there.
pub fn check(t: &Tissue) -> Result<StabilityReport> {
    let r = evaluate(t)?;
    let mu0 = r.mu0_n_per_mm2;
    if mu0.is_nan() || mu0 <= 0.0 {
        let mut msg = format!("tissue is unstable: initial shear modulus mu0 = sum mu_i = {} N/mm^2 <= 0", num(mu0));
        msg.push_str(&negative_terms_note(t, &r.negative_terms));
        msg.push_str(
            " (Abaqus/CalculiX Ogden convention W = sum 2 mu_i / alpha_i^2 (l1^a_i + l2^a_i + l3^a_i - 3), \
             in which mu0 = sum mu_i must be > 0)",
        );
        bail!(msg);
    }
    let k0 = r.k0_n_per_mm2;
    if k0.is_nan() || k0 <= 0.0 {
        bail!(
            "tissue is unstable: initial bulk modulus K0 = bulk_to_shear * mu0 = {} * {} N/mm^2 = {} N/mm^2 <= 0",
            num(t.bulk_to_shear),
            num(mu0),
            num(k0)
        );
    }
    let failures: Vec<String> = r
        .modes
        .iter()
        .filter_map(|m| {
            m.failure.map(|x| {
                format!(
                    "{} at stretch {:.3} (tangent d(sigma)/d(ln l) = {} N/mm^2, Drucker modulus {} N/mm^2)",
                    m.mode.name_at(x.stretch),
                    x.stretch,
                    num(x.tangent_n_per_mm2),
                    num(x.drucker_n_per_mm2)
                )
            })
        })
        .collect();
    if !failures.is_empty() {
        let mut msg = format!("tissue is unstable: Drucker check fails in {}", failures.join("; also in "));
        msg.push_str(&format!(" (checked over stretch {} .. {}, mu0 = {} N/mm^2)", num(r.stretch_min), num(r.stretch_max), num(mu0)));
        msg.push_str(&negative_terms_note(t, &r.negative_terms));
        bail!(msg);
    }
    Ok(r)
}

/// Compute the moduli and the per-test tangents and Drucker moduli without refusing an
/// unstable tissue (what [`check`] refuses is in the report: see
/// [`StabilityReport::is_stable`]).
///
/// # Errors
/// The tissue is malformed, as in [`check`].
pub fn evaluate(t: &Tissue) -> Result<StabilityReport> {
    let n = t.mu_n_per_mm2.len();
    if n == 0 || n != t.alpha.len() {
        bail!("tissue: mu_n_per_mm2 has {} terms and alpha {}; they must match and be non-empty", n, t.alpha.len());
    }
    for (i, (&mu, &a)) in t.mu_n_per_mm2.iter().zip(&t.alpha).enumerate() {
        if !mu.is_finite() || !a.is_finite() || a == 0.0 {
            bail!("tissue: term {}: mu = {mu} N/mm^2, alpha = {a}: both must be finite and alpha != 0", i + 1);
        }
    }
    if !t.bulk_to_shear.is_finite() {
        bail!("tissue: bulk_to_shear = {}: must be finite", t.bulk_to_shear);
    }
    let (lo, hi) = (t.stretch_min, t.stretch_max);
    if !(lo.is_finite() && hi.is_finite() && lo > 0.0 && lo < hi) {
        bail!("tissue: stretch range {lo} .. {hi}: must be finite with 0 < stretch_min < stretch_max");
    }

    let mu0 = t.mu0_n_per_mm2();
    let k0 = t.k0_n_per_mm2();
    let stretches: Vec<f64> = (0..SAMPLES)
        .map(|k| if k + 1 == SAMPLES { hi } else { (lo.ln() + (hi / lo).ln() * k as f64 / (SAMPLES - 1) as f64).exp() })
        .collect();
    let modes = Mode::ALL.iter().map(|&m| scan(t, m, &stretches)).collect();
    Ok(StabilityReport {
        mu0_n_per_mm2: mu0,
        k0_n_per_mm2: k0,
        d1_mm2_per_n: 2.0 / k0,
        nu0: (3.0 * k0 - 2.0 * mu0) / (2.0 * (3.0 * k0 + mu0)),
        stretch_min: lo,
        stretch_max: hi,
        samples: SAMPLES,
        negative_terms: (0..n).filter(|&i| t.mu_n_per_mm2[i] < 0.0).collect(),
        modes,
    })
}

/// Principal log-strain tangent `h(l) = sum_i 2 mu_i l^alpha_i`, N/mm^2.
fn principal_tangent(t: &Tissue, l: f64) -> f64 {
    t.mu_n_per_mm2.iter().zip(&t.alpha).map(|(&mu, &a)| 2.0 * mu * l.powf(a)).sum()
}

/// Tangent along the test path and Drucker modulus of test `mode` at stretch `l`.
fn tangents(t: &Tissue, mode: Mode, l: f64) -> (f64, f64) {
    let s = mode.stretches(l);
    let h = s.map(|x| principal_tangent(t, x));
    let path = match mode {
        Mode::Uniaxial => h[0] + 0.5 * h[1],
        Mode::Equibiaxial => h[0] + 2.0 * h[2],
        Mode::Planar => h[0] + h[2],
    };
    // The quadratic form sum h_j deps_j^2 on the plane sum deps_j = 0, in the orthonormal
    // basis b1 = (1, -1, 0)/sqrt 2, b2 = (1, 1, -2)/sqrt 6.
    let a = 0.5 * (h[0] + h[1]);
    let c = (h[0] + h[1] + 4.0 * h[2]) / 6.0;
    let b = (h[0] - h[1]) / 12f64.sqrt();
    let drucker = 0.5 * (a + c) - (0.25 * (a - c).powi(2) + b * b).sqrt();
    (path, drucker)
}

fn scan(t: &Tissue, mode: Mode, stretches: &[f64]) -> ModeReport {
    let mut r = ModeReport {
        mode,
        min_tangent_n_per_mm2: f64::INFINITY,
        min_tangent_at_stretch: f64::NAN,
        min_drucker_n_per_mm2: f64::INFINITY,
        min_drucker_at_stretch: f64::NAN,
        failure: None,
    };
    for &l in stretches {
        let (path, drucker) = tangents(t, mode, l);
        if path < r.min_tangent_n_per_mm2 || path.is_nan() {
            r.min_tangent_n_per_mm2 = path;
            r.min_tangent_at_stretch = l;
        }
        if drucker < r.min_drucker_n_per_mm2 || drucker.is_nan() {
            r.min_drucker_n_per_mm2 = drucker;
            r.min_drucker_at_stretch = l;
        }
        // NaN (overflow of l^alpha) counts as a failure.
        if drucker.is_nan() || drucker <= 0.0 {
            let closer = r.failure.is_none_or(|f| l.ln().abs() < f.stretch.ln().abs());
            if closer {
                r.failure = Some(Failure { stretch: l, tangent_n_per_mm2: path, drucker_n_per_mm2: drucker });
            }
        }
    }
    r
}

fn negative_terms_note(t: &Tissue, idx: &[usize]) -> String {
    if idx.is_empty() {
        return String::new();
    }
    let terms: Vec<String> = idx
        .iter()
        .map(|&i| {
            let (mu, a) = (t.mu_n_per_mm2[i], t.alpha[i]);
            format!("term {k}: mu_{k} = {} N/mm^2, alpha_{k} = {a}, mu_{k}*alpha_{k} = {} N/mm^2", num(mu), num(mu * a), k = i + 1)
        })
        .collect();
    format!("; terms with mu_i < 0 (informational: one negative term is not unstable by itself): {}", terms.join(", "))
}

/// Four significant digits, trailing zeros trimmed: plain decimals for
/// 1e-3 <= |x| < 1e4, otherwise `d.ddde-N`.
fn num(x: f64) -> String {
    if !x.is_finite() {
        return format!("{x}");
    }
    if x == 0.0 {
        return "0".to_string();
    }
    let ax = x.abs();
    if (1e-3..1e4).contains(&ax) {
        let decimals = (3 - ax.log10().floor() as i32).max(0) as usize;
        let s = format!("{x:.decimals$}");
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        }
    } else {
        let s = format!("{x:.3e}");
        match s.split_once('e') {
            Some((m, e)) if m.contains('.') => {
                format!("{}e{e}", m.trim_end_matches('0').trim_end_matches('.'))
            }
            _ => s,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::num;

    #[test]
    fn number_format() {
        assert_eq!(num(-0.288 + 0.162 + 0.067), "-0.059");
        assert_eq!(num(0.517e-3), "5.17e-4");
        assert_eq!(num(0.0517), "0.0517");
        assert_eq!(num(38.68), "38.68");
        assert_eq!(num(-1.3e-4), "-1.3e-4");
        assert_eq!(num(2.0), "2");
    }
}
